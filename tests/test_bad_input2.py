"""The second bad-input audit (issue 55, cases it had not shown): one test per class it found,
each at the boundary where the input is read. A case-file value the physics cannot have (a
negative viscosity that Palmgren's |ν n| would hide), a relative displacement of a probe to
itself, a `[mesh.parameters]` name no script reads, an NC program that contradicts itself or
would take forever to sample, a model file's number that is a string, an error-model target
named twice or the time itself, and public functions called with the wrong object: each is one
line naming the key or argument and the fix (InputError, or TypeError for a wrong type)."""
from __future__ import annotations

import json
import logging
import math
import shutil
from pathlib import Path

import numpy as np
import pytest

import gatetherm as gt
from gatetherm import InputError
from gatetherm.studies.errormodel.model import check_leakage, load_model, save_model
from gatetherm.studies.run.timeseries import TimeSeries

EXAMPLES = Path(__file__).resolve().parents[1] / "validation" / "examples"
T3 = Path(__file__).resolve().parents[1] / "validation" / "nafems" / "t3.toml"


def spindle(tmp_path: Path, old: str, new: str) -> Path:
    """The spindle-unit example (bearing losses, a correlation film) with ``old`` replaced by ``new``."""
    d = tmp_path / "spindle"
    shutil.copytree(EXAMPLES / "spindle_unit", d)
    text = (d / "case.toml").read_text()
    assert old in text
    (d / "case.toml").write_text(text.replace(old, new, 1))
    return d / "case.toml"


@pytest.mark.parametrize("old, new, needle", [
    ("viscosity = 22.0", "viscosity = -22.0",
     "sources.front_bearing.viscosity: got -22, must be a finite number > 0 mm²/s"),
    ("viscosity = 22.0", 'viscosity = "22 - n_spindle/100"',  # a column: checked at the schedule's samples
     "sources.front_bearing.viscosity: '22 - n_spindle/100' is -18 at t = 0 s, n_spindle = 4000, must be a finite"),
    ("reference = 40.0", "reference = 0.0", "thermal.nose.film.reference: got 0, must be a finite number > 0"),
    ('load = 2000.0', 'load = 2000.0\nposition = 0.1\ndirection = [nan, 1]\nlength = 0.05',
     "sources.front_bearing.direction: expected 2 numbers, not all zero, got [nan, 1]"),
    ("[relative.growth]                # the tool's axial growth against the mount\na = \"tool\"\nb = \"mount_point\"",
     "[relative.growth]\na = \"tool\"\nb = \"tool\"", "relative.growth.b: is 'tool', the same probe as a"),
    ('delta = "growth"', 'delta = "growth"\ntheta_C = []', "signals.theta_C: [] is not a list of probes with T"),
    ('quantities = ["u"]', "quantities = []", "probes.mount_point.quantities: [] is not admissible"),
])
def test_a_case_value_the_physics_cannot_have_is_refused_where_read(tmp_path, old, new, needle):
    with pytest.raises(InputError) as info:
        gt.load_case(spindle(tmp_path, old, new))
    assert needle in str(info.value) and "\n" not in str(info.value), str(info.value)


def test_an_element_larger_than_the_body_is_read_with_a_warning(tmp_path, caplog):
    with caplog.at_level(logging.WARNING):
        gt.load_case(spindle(tmp_path, "dm = 0.0825", "dm = 82.5"))  # mm meant
    assert "sources.front_bearing.dm: 82.5 m is larger than the whole body (0.4 m)" in caplog.text


def test_the_read_limit_holds_under_a_callers_alarm_handler(tmp_path, monkeypatch):
    """A script that loops for ever is refused after READ_LIMIT_S even where the caller (a notebook,
    a service) has its own SIGALRM handler, which the forked child inherits and gmsh would never let run."""
    import signal
    from gatetherm.geometry import isolate
    monkeypatch.setattr(isolate, "READ_LIMIT_S", 2)
    monkeypatch.setattr("gatetherm.geometry.gmshfile.READ_LIMIT_S", 2)
    case = spindle(tmp_path, 'file = "spindle.geo"', 'file = "loop.geo"')
    (case.parent / "loop.geo").write_text("For i In {1:1000000000}\n  x = i;\nEndFor\n")
    old = signal.signal(signal.SIGALRM, lambda *a: None)
    try:
        with pytest.raises(InputError) as info:
            gt.load_case(case)
    finally:
        signal.signal(signal.SIGALRM, old)
    assert "gmsh was still reading it after 2 s" in str(info.value)


def test_a_temperature_in_kelvins_is_read_with_a_warning_once(tmp_path, caplog):
    """Said once: the case made again (the quadratic-element check, a sweep, a diagnosis) repeats
    none of its reading's warnings, but says what an override newly brings."""
    said = "thermal.jacket.ambient: 293.15 °C reads like a temperature in kelvins (20 °C)"
    with caplog.at_level(logging.WARNING):
        case = gt.load_case(spindle(tmp_path, "ambient = 20.0", "ambient = 293.15"))
        case.with_order(2).with_overrides({"materials.housing.k": 40.0})
    assert caplog.text.count(said) == 1
    with caplog.at_level(logging.WARNING):
        case.with_overrides({"thermal.jacket.ambient": 300.0})
    assert caplog.text.count(said) == 1 and "ambient: 300 °C reads like a temperature in kelvins" in caplog.text


def test_a_negative_constant_load_is_read_with_a_word(tmp_path, caplog):
    """A signed column's load or speed is read as its magnitude (a loss does not change sign);
    a negative number written by hand is read the same way, and said."""
    with caplog.at_level(logging.WARNING):
        case = gt.load_case(spindle(tmp_path, "load = 2000.0", "load = -2000.0"))
    assert "sources.front_bearing.load = -2000 N: its sign is ignored (a loss depends on the magnitude); " \
           "give 2000" in caplog.text
    assert case.name


def test_a_guide_friction_above_one_is_refused():
    from gatetherm.solvers.elements.guide import FRICTION
    assert FRICTION.admits(0.003) and not FRICTION.admits(3.0) and not FRICTION.admits(-0.001)


def test_a_mesh_parameter_the_script_never_reads_is_refused(tmp_path, caplog):
    shutil.copy(T3.with_name("t3.geo"), tmp_path)
    text = T3.read_text()
    (tmp_path / "case.toml").write_text(text.replace("h = 0.005", "hh = 0.005"))
    with pytest.raises(InputError) as info:
        gt.load_case(tmp_path / "case.toml")
    assert "mesh.parameters.hh: is not a variable of t3.geo: the geometry would not change" in str(info.value)
    (tmp_path / "case.toml").write_text(text.replace("[mesh.parameters]", "size = 0.01\n[[mesh.refine]]\n"
                                                     "near = \"hot_end\"\nsize = 0.02\ndistance = 0.01\n"
                                                     "[mesh.parameters]"))
    with caplog.at_level(logging.WARNING):
        gt.load_case(tmp_path / "case.toml")  # a refinement coarser than the mesh: read, with a word
    assert "mesh.refine[1].size 0.02 m is not finer than [mesh] size 0.01 m" in caplog.text


BOX_FIELD = """SetFactory("OpenCASCADE");
Rectangle(1) = {0, 0, 0, 1, 1};
Field[1] = Box; Field[1].VIn = 0.01; Field[1].VOut = 0.2;
Field[1].XMin = 0; Field[1].XMax = 0.2; Field[1].YMin = 0; Field[1].YMax = 1;
Background Field = 1;
Physical Surface("body") = {1};
Physical Curve("left") = {4};
"""


def test_a_refinement_keeps_the_scripts_own_background_field(tmp_path, caplog):
    """A case's ``[[mesh.refine]]`` used to replace the script's ``Background Field``: the
    0.01-m strip of the script became 0.17-m elements (4 563 elements → 50), without a word."""
    from gatetherm.geometry.gmshfile import MeshSpec, Refinement, mesh_geometry
    (tmp_path / "box.geo").write_text(BOX_FIELD)

    def strip(fm):  # mean first-edge length of the elements in the script's fine strip x < 0.2
        p, c = fm.points, fm.cells
        inside = p[c].mean(axis=1)[:, 0] < 0.2
        return len(c), float(np.linalg.norm(p[c[inside, 0]] - p[c[inside, 1]], axis=1).mean())

    n0, h0 = strip(mesh_geometry(MeshSpec(tmp_path / "box.geo")))
    with caplog.at_level(logging.WARNING):
        n1, h1 = strip(mesh_geometry(MeshSpec(tmp_path / "box.geo", refine=(Refinement("left", 0.05, 0.1),))))
    assert h0 == pytest.approx(0.0102, abs=5e-4) and h1 == pytest.approx(0.0104, abs=5e-4)  # band: < 0.02
    assert n1 == pytest.approx(n0, rel=0.2)  # 4163 against 4563 (the rest of the body: gmsh's own extension)
    assert ("mesh.refine[1] (near left): size = 0.05 m, but the file's own sizes give 0.01 m there already, "
            "so it changes nothing") in caplog.text


@pytest.mark.parametrize("program, kwargs, needle", [
    ("G21 G90\nM3\nG4 P1000\n", {}, "line 2: M3 starts the spindle without a speed"),
    ("G21 G90\nM3 S-1000\nG4 P1000\n", {}, "line 2: S-1000 is negative"),
    ("G21 G90\nG1 X100 F-100\n", {}, "line 2: F-100 is negative"),
    ("G20 G21 G90\nG1 X1 F10\n", {}, "line 1: G20 and G21 in one block contradict"),
    ("G21 G90\nG1 X100 F1000\nG4 X3600\n", {"repeat": 10**9}, "steps of 1 s, more than 1000000"),
    ("G21 G90\nG1 X100 F1000\n", {"step_s": "1"}, "step_s: got str '1', expected a number"),
    ("G21 G90\nG1 X100 F1000\n", {"out": "SELF"}, "is the program itself: writing the schedule would destroy it"),
])
def test_an_nc_program_that_would_mislead_or_hang_is_one_line(tmp_path, program, kwargs, needle):
    path = tmp_path / "p.nc"
    path.write_text(program)
    kwargs = {k: (path if v == "SELF" else v) for k, v in kwargs.items()}
    with pytest.raises((InputError, TypeError)) as info:
        gt.nc_schedule(path, **kwargs)
    assert needle in str(info.value) and "\n" not in str(info.value), str(info.value)
    assert path.read_text() == program


def test_a_model_file_number_that_is_a_string_is_refused_on_load(tmp_path):
    t = [60.0 * i for i in range(200)]
    a = 20 + 5 * (1 - np.exp(-np.array(t) / 3600))
    b = 20 + 2 * (1 - np.exp(-np.array(t) / 7000))
    data = TimeSeries({"time_s": np.array(t), "t1_degC": a, "t2_degC": b,
                       "x_um": 3 * (a - 20) - 1.5 * (b - 20) + 0.01 * np.sin(np.arange(200))}, {})
    save_model(tmp_path / "m.json", gt.errormodel_fit(data, ["x_um"]).model)
    d = json.loads((tmp_path / "m.json").read_text())
    d["fit_span"]["start_s"] = "abc"
    (tmp_path / "m.json").write_text(json.dumps(d))
    with pytest.raises(InputError) as info:
        load_model(tmp_path / "m.json")
    assert "m.json: fit_span: start_s and end_s must be numbers (s), start_s <= end_s" in str(info.value)


def test_an_error_model_of_nothing_says_so(caplog):
    t = np.arange(0.0, 6 * 3600.0, 60.0)
    flat = TimeSeries({"time_s": t, "t1_degC": np.full(t.size, 20.0), "t2_degC": np.full(t.size, 20.0),
                       "x_um": np.sin(t / 3000.0)}, {})
    with caplog.at_level(logging.WARNING):
        model = gt.errormodel_fit(flat, ["x_um"]).model
    assert model.targets[0].terms == ()
    assert "x_um: no candidate column explains it" in caplog.text


@pytest.mark.parametrize("targets, needle", [(("x_um", "x_um"), "targets x_um: is named twice"),
                                             (("time_s",), "targets time_s: is the time, not a displacement")])
def test_an_error_model_target_named_twice_or_the_time_is_refused(targets, needle):
    with pytest.raises(InputError) as info:
        check_leakage(targets, ("t1_degC",))
    assert str(info.value).startswith(needle)


@pytest.fixture(scope="module")
def joint():
    return gt.load_case(EXAMPLES / "joint" / "case.toml")


NAN = math.nan
#: id: (call(case), exception, the start of its message); the case: the joint example (steady).
BAD = {
    "check_schedules('x')": (lambda c: gt.check_schedules("x"), TypeError, "case: got str 'x', expected a Case"),
    "check_rom(rom=None)": (lambda c: gt.check_rom(c, None), TypeError, "rom: got NoneType None, expected a Reduced"),
    "write_reduction(red=None)": (lambda c: gt.write_reduction("o", None, [], c, 30, 1.0), TypeError,
                                  "red: got NoneType None, expected a Reduction"),
    "check_placement(None)": (lambda c: gt.check_placement(c, None), TypeError, "placement: got NoneType None"),
    "write_placement(None)": (lambda c: gt.write_placement("o", None, c), TypeError, "placement: got NoneType"),
    "place_sensors(seed=-1)": (lambda c: gt.place_sensors(c, seed=-1), InputError, "seed: got -1, must be a whole"),
    "place_sensors(exclude ints)": (lambda c: gt.place_sensors(c, exclude=[(0, 0, 1)]), TypeError,
                                    "exclude: got [(0, 0, 1)], expected (low corner, high corner) pairs"),
    "place_sensors(nosuch=1)": (lambda c: gt.place_sensors(c, nosuch=1), TypeError,
                                "nosuch: is not a setting of place_sensors; settings: "),
    "diagnose(nosuch=1)": (lambda c: gt.diagnose(c, "x.csv", nosuch=1), TypeError,
                           "nosuch: is not a setting of diagnose"),
    "compensate(None)": (lambda c: gt.compensate(None, c), TypeError, "series: got NoneType None, expected a TimeSeries or a Run"),
    "errormodel_fit(None)": (lambda c: gt.errormodel_fit(None, ["x_um"]), TypeError, "data: got NoneType None"),
    "errormodel_fit(targets='x_um')": (lambda c: gt.errormodel_fit("d.csv", "x_um"), TypeError,
                                       "targets: got str 'x_um', expected a list of str"),
    "errormodel_predict(3)": (lambda c: gt.errormodel_predict(3, "d.csv"), TypeError, "model: got int 3, expected"),
    "errormodel_predict(data=5)": (lambda c: gt.errormodel_predict("m.json", 5), TypeError, "data: got int 5"),
    "errormodel_refit(window_s='1')": (lambda c: gt.errormodel_refit("m.json", "d.csv", "1"), TypeError,
                                       "window_s: got str '1', expected a number"),
    "errormodel_refit(applied=5)": (lambda c: gt.errormodel_refit("m.json", "d.csv", 3600.0, 5), TypeError,
                                    "applied: got int 5, expected a mapping of str to str"),
    "twin(5)": (lambda c: gt.twin(5, "opc.tcp://127.0.0.1:4840"), TypeError, "case: got int 5, expected a Case"),
    "validate_zoo(machines='c_frame')": (lambda c: gt.validate_zoo("o", machines="c_frame"), TypeError,
                                         "machines: got str 'c_frame', expected a list of str or None"),
    "validate_zoo(machines=[])": (lambda c: gt.validate_zoo("o", machines=[]), InputError, "machines: is empty"),
    "validate_zoo(timeout_s=nan)": (lambda c: gt.validate_zoo("o", timeout_s=NAN), InputError,
                                    "timeout_s: got nan, must be a finite number"),
    "validate_zoo(on_cell=3)": (lambda c: gt.validate_zoo("o", on_cell=3), TypeError, "on_cell: got int 3, expected a function or None"),
    "with_overrides('k=1')": (lambda c: c.with_overrides("k=1"), TypeError, "overrides: got str 'k=1', expected a dict"),
    "plot.series(None)": (lambda c: gt.plot.series(None, "delta_um"), TypeError, "run: got NoneType None"),
    "plot.series(unknown column)": (lambda c: gt.plot.series({"time_s": [0.0]}, "delta_um"), InputError,
                                    "columns: 'delta_um' not among the run's columns"),
    "export_ccx(title with a line break)": (lambda c: gt.export_ccx(c, "o", title="a\n*STEP"), InputError,
                                            "title: 'a\\n*STEP' is not one line of text"),
    "export_ccx(run='yes')": (lambda c: gt.export_ccx(c, "o", run="yes"), TypeError, "run: got str 'yes', expected"),
    "export_ccx(out=5)": (lambda c: gt.export_ccx(c, 5), TypeError, "out: got int 5, expected a str or path"),
    "export_ccx(schedule='s.csv')": (lambda c: gt.export_ccx(c, "o", schedule="s.csv"), TypeError,
                                     "schedule: got str 's.csv', expected a Schedule or None"),
    "export_ccx(None)": (lambda c: gt.export_ccx(None, "o"), TypeError, "case: got NoneType None, expected a Case"),
    "place_sensors(held_out='x.csv')": (lambda c: gt.place_sensors(c, held_out="x.csv"), TypeError,
                                        "held_out: got str 'x.csv', expected a list of Schedule or None"),
    "live(out=None)": (lambda c: gt.live(c, method="paper", endpoint="opc.tcp://127.0.0.1:4840", out=None), TypeError,
                       "out: got NoneType None, expected a str or path"),
    "plot.sweep(no file)": (lambda c: gt.plot.sweep("nosuch.csv", "x", "y"), InputError,
                            "rows: no such file 'nosuch.csv'"),
}


@pytest.mark.parametrize("call, kind, start", BAD.values(), ids=BAD)
def test_a_wrong_object_is_named_in_one_line(joint, tmp_path, monkeypatch, call, kind, start):
    monkeypatch.chdir(tmp_path)
    with pytest.raises(kind) as info:
        call(joint)
    assert type(info.value) is kind
    message = str(info.value)
    assert message.startswith(start) and "\n" not in message, message
    assert not (tmp_path / "o").exists()  # refused before anything is written


class _Stopped(Exception):
    pass


def test_a_signal_during_the_commit_waits_for_it(tmp_path, monkeypatch):
    """A SIGTERM (or Ctrl-C) while the staged files move into --out is held until they all have:
    never half the new files beside half the old (a rerun killed near its end, issue 55)."""
    import os
    import signal
    from gatetherm import outdir

    real = outdir._commit

    def commit(stage, out, owns, keep):
        os.kill(os.getpid(), signal.SIGTERM)  # arrives as the files move
        real(stage, out, owns, keep)

    def stop(*_):
        raise _Stopped

    monkeypatch.setattr(outdir, "_commit", commit)
    old = signal.signal(signal.SIGTERM, stop)
    out = tmp_path / "o"
    out.mkdir()
    (out / "a.txt").write_text("old")
    try:
        with pytest.raises(_Stopped):
            with outdir.output_dir(out, ("a.txt", "b.txt")) as stage:
                (stage / "a.txt").write_text("new")
                (stage / "b.txt").write_text("new")
    finally:
        signal.signal(signal.SIGTERM, old)
    assert [(out / n).read_text() for n in ("a.txt", "b.txt")] == ["new", "new"]
    assert not [p.name for p in out.iterdir() if p.name.startswith(".gatetherm")]


def test_a_zoo_cell_ends_quietly_on_the_commands_signal():
    """A cell's child ends on SIGINT/SIGTERM by the default action: not by the command's handlers
    it inherited through the fork, whose exception multiprocessing printed as a traceback."""
    import multiprocessing
    import signal
    from gatetherm.validation import zoo

    saved = {s: signal.getsignal(s) for s in (signal.SIGINT, signal.SIGTERM)}
    here, there = multiprocessing.Pipe()
    try:
        zoo._child(there, lambda: (0.0, f"{signal.getsignal(signal.SIGINT)} {signal.getsignal(signal.SIGTERM)}"), ())
        cell = here.recv()
    finally:
        for s, h in saved.items():
            signal.signal(s, h)
    assert cell["text"] == f"{signal.SIG_DFL} {signal.SIG_DFL}"


@pytest.mark.parametrize("old, new, needle", [
    ("[probes.mount_point]", '[probes."mount,point"]',
     "probes.mount,point: cannot name a probe's columns (it holds a comma"),
    ("point = [0.07, 0.05]", "point = [1e300, 0.05]", "probes.mount_point.point: [1e+300, 0.05] lies outside the mesh"),
    ('quantities = ["u"]', 'quantities = ["u", "u"]', "probes.mount_point.quantities: ['u', 'u'] is not admissible; "
                                                      "choose each once from"),
    ('name = "spindle_unit"', 'name = "x\\u001b]0;pwned\\u0007"',
     "case.name: is not one printable line of at most 200 characters (11 characters)"),
    ('file = "spindle.geo"', f'file = "{"s" * 300}.geo"', "mesh.file: is not one printable line of at most 200"),
], ids=["comma in a probe", "a point 1e300 away", "a quantity twice", "escapes in the name", "a 300-character path"])
def test_a_name_or_point_that_would_fail_later_is_refused_at_reading(tmp_path, old, new, needle):
    """Each of these passed the reader (the third audit): a probe name with a comma failed only
    after the whole run, writing its column; a point 1e300 away raised an IndexError inside
    scikit-fem; terminal escapes in the name went raw into timeseries.csv."""
    with pytest.raises(InputError) as info:
        gt.load_case(spindle(tmp_path, old, new))
    assert needle in str(info.value) and "\x1b" not in str(info.value)


def test_a_material_value_outside_what_machines_have_is_read_with_a_word(tmp_path, caplog):
    with caplog.at_level(logging.WARNING):
        gt.load_case(spindle(tmp_path, "c = 460.0", "c = 0.46"))  # kJ/(kg K) meant
    assert "materials.shaft.c = 0.46 J/(kg K) is outside what the solids of machines have (50 to 5000): check its " \
           "unit (SI: J/(kg K))" in caplog.text


def test_an_error_line_is_bounded_and_escapes_control_characters():
    from gatetherm import one_line

    err = InputError("--targets", f"'{'x' * 100_000}' is not a column", "name a column")
    assert len(str(err)) < 1000 and "(100018 characters)" in str(err)
    assert one_line("a\x1b[2Jb\nc") == "a\\x1b[2Jb\\nc"


def test_a_mesh_size_larger_than_the_body_is_read_with_a_word(tmp_path, caplog):
    from gatetherm.geometry.gmshfile import MeshSpec, mesh_geometry
    (tmp_path / "box.geo").write_text(BOX_FIELD.replace("Background Field = 1;", ""))
    with caplog.at_level(logging.WARNING):
        mesh_geometry(MeshSpec(tmp_path / "box.geo", size=1e300))
    assert "mesh.size = 1e+300 m is larger than the body (1 m across)" in caplog.text


@pytest.mark.parametrize("edit, needle", [
    (lambda d: d["targets"]["x_um"]["terms"][0].update(coefficient="2.9"), "terms[0].coefficient: must be a number"),
    (lambda d: d["targets"]["x_um"]["terms"][0].update(coefficient=1e308), "terms[0].coefficient: must be a number"),
    (lambda d: d["targets"]["x_um"].pop("intercept_um"), "targets.x_um.intercept_um: must be a number"),
    (lambda d: d["targets"]["x_um"].update(terms=[]), "targets.x_um.terms: must be a non-empty list of terms"),
    (lambda d: d["targets"]["x_um"]["terms"][0].update(unit="mm/K"), "terms[0].unit: is 'mm/K', but the coefficient"),
    (lambda d: d["targets"]["x_um"]["interval"].update(half_width_um=-1.0), "targets.x_um.interval: its widths must"),
    (lambda d: d.update(max_gap_s=-300), "max_gap_s: must be a number > 0 s"),
    (lambda d: d.update(targets=["x_um"]), "targets: must be a non-empty table"),
], ids=["coefficient a string", "coefficient 1e308", "no intercept", "no terms", "a unit of mm/K",
        "a negative interval", "a negative gap", "targets a list"])
def test_a_hand_edited_model_file_is_refused_by_its_entry(tmp_path, edit, needle):
    """Each was read without a word, or failed inside predict (the third audit, class D)."""
    t = np.arange(200) * 60.0
    a, b = 20 + 5 * (1 - np.exp(-t / 3600)), 20 + 2 * (1 - np.exp(-t / 7000))
    data = TimeSeries({"time_s": t, "t1_degC": a, "t2_degC": b,
                       "x_um": 3 * (a - 20) - 1.5 * (b - 20) + 0.01 * np.sin(np.arange(200))}, {})
    save_model(tmp_path / "m.json", gt.errormodel_fit(data, ["x_um"]).model)
    d = json.loads((tmp_path / "m.json").read_text())
    edit(d)
    (tmp_path / "m.json").write_text(json.dumps(d))
    with pytest.raises(InputError) as info:
        load_model(tmp_path / "m.json")
    assert needle in str(info.value)


def _em_record() -> TimeSeries:
    t = np.arange(200) * 60.0
    a, b = 20 + 5 * (1 - np.exp(-t / 3600)), 20 + 2 * (1 - np.exp(-t / 7000))
    return TimeSeries({"time_s": t, "t1_degC": a, "t2_degC": b,
                       "x_um": 3 * (a - 20) - 1.5 * (b - 20) + 0.01 * np.sin(np.arange(200))}, {})


@pytest.mark.parametrize("call, needle", [
    (lambda d: gt.errormodel_fit([d, d, d], ["x_um"]), "data[1]: is the same record as data[0]"),
    (lambda d: gt.errormodel_fit(d, ["x_um"], ["time_s", "t1_degC"]), "candidates time_s: is the time, not a sensor"),
    (lambda d: gt.errormodel_fit(d, ["x_um"], ["t1_degC", "t1_degC"]), "candidates t1_degC: is named twice"),
], ids=["a run three times", "time as a sensor", "a sensor twice"])
def test_an_error_model_fit_that_would_mislead_is_refused(call, needle):
    """The third audit (class C): a run given three times reported a leave-one-run-out error
    that was in-sample (0.127 µm, the interval narrowed from ±0.244 to ±0.186 µm)."""
    with pytest.raises(InputError) as info:
        call(_em_record())
    assert needle in str(info.value)


@pytest.mark.parametrize("entry, value", [("fit_span", [0, 1]), ("settings", []), ("ranges", 5)])
def test_a_model_file_entry_of_the_wrong_kind_is_named(tmp_path, entry, value):
    """A table where a list belongs (or the reverse) raised an AttributeError in the entry checks."""
    d = json.loads(json.dumps({"format": "gatetherm-errormodel/1", "reference_degC": {"t1_degC": 20.0},
                               "targets": {"x_um": {"form": "static", "intercept_um": 0.0, "terms": [
                                   {"kind": "sensor", "column": "t1_degC", "coefficient": 1.0}]}}}))
    (d["targets"]["x_um"] if entry == "ranges" else d)[entry] = value
    (tmp_path / "m.json").write_text(json.dumps(d))
    with pytest.raises(InputError, match=rf"m\.json: (targets\.x_um\.)?{entry}"):
        load_model(tmp_path / "m.json")


def test_a_point_off_the_body_names_the_parameters_that_shaped_it(tmp_path):
    """A [mesh.parameters] value that shrank the body left a point group outside it: the message
    named the point only, not the parameter that was the cause (audit B's cf-param-neg)."""
    (tmp_path / "p.geo").write_text('If (!Exists(w)) w = 1.0; EndIf\nSetFactory("OpenCASCADE");\nRectangle(1) = {0, 0, 0, w, 1};\n'
                                    'Point(10) = {0.9, 0.5, 0};\nPhysical Surface("body") = {1};\n'
                                    'Physical Curve("left") = {4};\nPhysical Point("table") = {10};\n')
    case = ('[mesh]\nfile = "p.geo"\nsize = 0.2\n[mesh.parameters]\nw = {w}\n[materials.body]\nk = 50.0\n'
            '[thermal.left]\ntemperature = 30.0\n')
    (tmp_path / "c.toml").write_text(case.format(w=1.0))
    gt.load_case(tmp_path / "c.toml")  # the point inside: read at its nearest node
    (tmp_path / "c.toml").write_text(case.format(w=0.2))
    with pytest.raises(InputError) as info:
        gt.load_case(tmp_path / "c.toml")
    assert "mesh point table: at (0.9, 0.5" in str(info.value) and \
        str(info.value).endswith("the geometry was made with [mesh.parameters] w = 0.2: check them")


def test_a_run_that_leaves_the_temperature_range_names_the_case_file(tmp_path):
    """A bearing's mean diameter in mm (82.5 for 0.0825 m): warned as larger than the body, then the
    run's temperatures leave the range; the refusal names the case file (a new user's ram: it named
    only 'temperature')."""
    case = gt.load_case(spindle(tmp_path, "dm = 0.0825", "dm = 82.5"))
    with pytest.raises(InputError, match=r"^.*spindle/case.toml: temperature: the solution reaches .* °C at t = "):
        gt.run(case, keep=())


def test_a_film_that_does_not_settle_names_the_case_file(tmp_path):
    """A bearing's mean diameter in dm (8.25 for 0.0825 m) heats a naturally cooled nose until its
    film's iterations do not settle: the refusal names the case file (a new user's read only "film of")."""
    nose = 'film = { correlation = "rotating_cylinder", length = 0.065, speed = "n_spindle", reference = 40.0, minimum = 5.0 }'
    path = spindle(tmp_path, nose, 'film = { correlation = "vertical_plate", length = 0.065, reference = 1.0 }\nemissivity = 0.9')
    text = path.read_text()
    path.write_text(text.replace("dm = 0.0825", "dm = 8.25", 1))
    with pytest.raises(InputError, match=r"^.*spindle/case.toml: film of 'nose': the coefficient's Picard iterations did "
                                         "not settle"), np.errstate(all="ignore"):
        gt.run(gt.load_case(path), keep=())


def test_a_case_without_the_signals_is_refused_compensation_with_the_error_model_offered():
    """The spindle maps no θ_A, θ_B, θ_C: its own run cannot be compensated by θ; the message says what
    would do it (the zoo's paper, mlr and rom cells give the same line)."""
    case = gt.load_case(EXAMPLES / "spindle_unit" / "case.toml")
    with pytest.raises(InputError) as info:
        gt.compensate_run(case=case, method="rom")
    assert str(info.value) == (f"{case.source}: signals: a compensated case needs [time] and [signals] with theta_A, "
                               "theta_B, theta_C and delta; map them to its probes and a relative displacement, or "
                               "compensate its δ with an error model of its temperatures (gatetherm errormodel fit, "
                               "then compensate --model)")
