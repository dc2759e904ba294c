"""The API checks its arguments at the boundary (issue 55): one table of bad calls, each
raising TypeError (a wrong type) or InputError (a value out of range, or one that would mislead)
whose one line names the argument and the fix, before any numerics. Anything else (IndexError,
AttributeError, ZeroDivisionError, a SciPy or pyMOR error, a MemoryError, a silent default) was
the defect."""
from __future__ import annotations

import math
import shutil
from pathlib import Path

import pytest

import gatetherm as gt
from gatetherm import InputError

EXAMPLE = Path(__file__).parents[1] / "validation" / "examples" / "c_frame"
PLATE_GEO = """SetFactory("OpenCASCADE");
Rectangle(1) = {0, 0, 0, 1, 1};
Physical Surface("plate") = {1};
Physical Curve("edge") = {1};
"""
PLATE = '[mesh]\nfile = "a.geo"\nsize = 0.25\n[materials.plate]\nk = 50.0\n[thermal.edge]\ntemperature = 100.0\n'


@pytest.fixture(scope="module")
def cases(tmp_path_factory):
    """The C-frame example (transient, with elasticity) in a folder whose schedule is named
    ``timeseries.csv``, as a run writes one; a steady heat-only plate and a run of it."""
    d = tmp_path_factory.mktemp("cases")
    for f in EXAMPLE.iterdir():
        shutil.copy(f, d / ("timeseries.csv" if f.name == "schedule.csv" else f.name))
    text = (d / "case.toml").read_text()
    assert '"schedule.csv"' in text
    (d / "case.toml").write_text(text.replace('"schedule.csv"', '"timeseries.csv"'))
    (d / "a.geo").write_text(PLATE_GEO)
    (d / "plate.toml").write_text(PLATE)
    frame, plate = gt.load_case(d / "case.toml"), gt.load_case(d / "plate.toml")
    return {"dir": d, "frame": frame, "plate": plate, "plate_run": gt.run(plate)}


NAN = math.nan
#: id: (call(cases), exception, the start of its message)
BAD = {
    "gate_frame(dim=4)": (lambda c: gt.gate_frame(dim=4), InputError, "dim: got 4, must be 2 or 3; gate_frame(dim=2)"),
    "gate_frame(dim='2')": (lambda c: gt.gate_frame(dim="2"), TypeError, "dim: got str '2', expected a whole number"),
    "gate_frame(dim=2.5)": (lambda c: gt.gate_frame(dim=2.5), InputError, "dim: got 2.5, must be a whole number"),
    "gate_frame(config=1)": (lambda c: gt.gate_frame(config=1), TypeError, "config: got int 1, expected a Config, a str or path or None; give a model"),
    "gate_frame(condition=0)": (lambda c: gt.gate_frame(condition=0), InputError, "condition: got 0, must be"),
    "run('case.toml')": (lambda c: gt.run("case.toml"), TypeError,
                         "case: got str 'case.toml', expected a Case; make one with gt.load_case(path)"),
    "run(schedule=1)": (lambda c: gt.run(c["frame"], schedule=1), TypeError, "schedule: got int 1, expected a Sch"),
    "run(effects=[])": (lambda c: gt.run(c["frame"], effects=["x"]), TypeError, "effects: got list ['x'], expected"),
    "run(effects nan)": (lambda c: gt.run(c["frame"], effects={"ambient_drift": NAN}), InputError,
                         "effects['ambient_drift']: got nan, must be a finite number"),
    "run(effects 1e300)": (lambda c: gt.run(c["frame"], effects={"ambient_drift": 1e300}), InputError,
                           "effects['ambient_drift']: ambient_drift.rate = 1e+300 is not physical"),
    "run(effects unknown)": (lambda c: gt.run(c["frame"], effects={"nosuch": 1.0}), InputError,
                             "effects['nosuch']: unknown effect 'nosuch'"),
    "run(keep=[nan])": (lambda c: gt.run(c["frame"], keep=[NAN]), InputError, "keep[0]: got nan, must be a number in"),
    "run(keep=[-1])": (lambda c: gt.run(c["frame"], keep=[-1.0]), InputError, "keep[0]: got -1, must be a number in"),
    "run(keep='0')": (lambda c: gt.run(c["frame"], keep="0"), TypeError, "keep: got str '0', expected a list of number or None"),
    "run(on_step=1)": (lambda c: gt.run(c["frame"], on_step=1), TypeError, "on_step: got int 1, expected a function"),
    "run(fields_every=0)": (lambda c: gt.run(c["frame"], fields_every=0), InputError,
                            "fields_every: got 0, must be a finite number > 0"),
    "run(fields_every=-1)": (lambda c: gt.run(c["frame"], fields_every=-1), InputError, "fields_every: got -1"),
    "run(check_order=1)": (lambda c: gt.run(c["frame"], check_order=1), TypeError, "check_order: got int 1"),
    "condition(step_s=0)": (lambda c: gt.condition(1, step_s=0), InputError, "step_s: got 0, must be a finite number"),
    "condition(True)": (lambda c: gt.condition(True), TypeError, "number: got bool True, expected a whole number"),
    "condition(4)": (lambda c: gt.condition(4), InputError, "number: got 4, must be a whole number in [1, 3]"),
    "compensate_run(data and condition)": (lambda c: gt.compensate_run("run.csv", condition=1), InputError,
                                           "data: and condition are both given; give one"),
    "sensor_study(mesh_factor=0)": (lambda c: gt.sensor_study(c["frame"], mesh_factor=0), InputError,
                                    "mesh_factor: got 0, must be a finite number > 0"),
    "sensor_study(Case, mesh_factor=2)": (lambda c: gt.sensor_study(c["frame"], mesh_factor=2), InputError,
                                          "mesh_factor: goes with a case file's path only"),
    "place_sensors(duration_s=-3600)": (lambda c: gt.place_sensors(c["frame"], duration_s=-3600.0), InputError,
                                        "duration_s: -3600 s is not two or more"),
    "diagnose_run(steady)": (lambda c: gt.diagnose_run(c["plate"], "m.csv"), InputError,
                             "model: 'plate' is steady (no [time]): a diagnosis compares a transient run"),
    "condition(case=file)": (lambda c: gt.condition(1, case=c["frame"]), InputError,
                             "case: 'C-frame machining centre' has no oil supply unit of the paper's model"),
    "condition(1, step_s=7)": (lambda c: gt.condition(1, step_s=7), InputError,
                               "step_s: 7 s does not divide the condition's 18000 s"),
    "reduce(states=0)": (lambda c: gt.reduce(c["frame"], 0), InputError,
                         "states: got 0, must be a whole number in [2, 200]"),
    "reduce(states=10**6)": (lambda c: gt.reduce(c["frame"], 10**6), InputError, "states: got 1e+06, must be"),
    "reduce(a steady case)": (lambda c: gt.reduce(c["plate"]), InputError, "case: "),
    "reduce('x')": (lambda c: gt.reduce("x"), TypeError, "case: got str 'x', expected a Case"),
    "load_case(mesh_factor=nan)": (lambda c: gt.load_case(c["dir"] / "case.toml", mesh_factor=NAN), InputError,
                                   "mesh_factor: got nan, must be a finite number"),
    "load_case(overrides=[])": (lambda c: gt.load_case(c["dir"] / "case.toml", overrides=[("a", 1)]), TypeError,
                                "overrides: got list"),
    "load_case(1)": (lambda c: gt.load_case(1), TypeError, "path: got int 1, expected a str or path"),
    "field('T', t=nan)": (lambda c: c["plate_run"].field("T", t=NAN), InputError, "t: got nan, must be a finite"),
    "field(1)": (lambda c: c["plate_run"].field(1), TypeError, "name: got int 1, expected a field's name"),
    "field('Tx')": (lambda c: c["plate_run"].field("Tx"), gt.UnknownName, "name: 'Tx' is not a field of the run; fields: T"),
    "run['nosuch']": (lambda c: c["plate_run"]["nosuch_um"], gt.UnknownName,
                      "name: 'nosuch_um' is not a column of the run; columns: time_s"),
    "write(fields_every=0)": (lambda c: c["plate_run"].write(c["dir"] / "o", fields_every=0), InputError,
                              "fields_every: got 0"),
    "Run.write into the case's folder": (lambda c: gt.Run(c["frame"], None, 0.0).write(c["dir"]), InputError,
                                         "out: writing into"),
    "place_sensors(count=0)": (lambda c: gt.place_sensors(c["frame"], 0), InputError, "count: got 0, must be"),
    "place_sensors(exclude nan)": (lambda c: gt.place_sensors(c["frame"], 2, exclude=[((0, 0), (NAN, 1))]),
                                   InputError, "exclude[0]: got nan, must be a finite number"),
    "place_sensors(ranges 1e300)": (lambda c: gt.place_sensors(c["frame"], 2, ranges={"spindle_W": (0, 1e300)}),
                                    InputError, "ranges['spindle_W']: got 1e+300, must be a number in"),
    "diagnose(measured=1)": (lambda c: gt.diagnose(c["frame"], 1), TypeError, "measured: got int 1"),
    "compensate(case='x')": (lambda c: gt.compensate(c["plate_run"], "x"), TypeError, "case: got str 'x', expected a Case or None; make one"),
    "plot.deformed(heat-only)": (lambda c: gt.plot.deformed(c["plate_run"]), InputError,
                                 "run: plate has no displacements (a heat-only case)"),
    "plot.series(ax='x')": (lambda c: gt.plot.series(c["plate_run"], ax="x"), TypeError,
                            "ax: got str 'x', expected a matplotlib Axes or None"),
    "plot.field('x')": (lambda c: gt.plot.field("x"), TypeError, "run: got str 'x', expected a Run"),
    "plot.save(dpi=1e6)": (lambda c: gt.plot.save(gt.plot.series(c["plate_run"], "time_s"), c["dir"] / "p.png",
                                                  dpi=1e6), InputError, "dpi: got 1e+06, must be a number in [1, 2400]"),
    "plot.save(dpi=2000)": (lambda c: gt.plot.save(gt.plot.series(c["plate_run"], "time_s"), c["dir"] / "p.png",
                                                   dpi=2000), InputError, "dpi: 2000 dots per inch make a picture of"),
}


@pytest.mark.parametrize("call, kind, start", BAD.values(), ids=BAD)
def test_a_bad_argument_is_named_in_one_line(cases, call, kind, start):
    with pytest.raises(kind) as info:
        call(cases)
    assert type(info.value) is kind  # not a subclass that names nothing
    message = str(info.value)
    assert message.startswith(start) and "\n" not in message, message


def test_run_write_never_overwrites_the_schedule(cases):
    """The CLI refused it; the API wrote timeseries.csv over the schedule of the same name."""
    before = (cases["dir"] / "timeseries.csv").read_bytes()
    with pytest.raises(InputError, match=f"would overwrite the case's input '{cases['dir'] / 'timeseries.csv'}'"):
        gt.Run(cases["frame"], None, 0.0).write(cases["dir"])
    assert (cases["dir"] / "timeseries.csv").read_bytes() == before


def test_a_step_that_divides_the_condition_ends_at_its_end():
    assert gt.condition(1, step_s=7.5).times[-1] == 18000.0  # 2400 steps
