"""Bad case input (issue 21): expressions, case values, results that must not be silently
wrong, reduced-model files and options that do not apply. The library raises one
:class:`~gatetherm.InputError` naming the file, the key and the fix; the command turns it
into one line on stderr and exit 2 (checked where the test is about that)."""
from __future__ import annotations

import logging
import shutil
import types
from pathlib import Path

import numpy as np
import pytest

from gatetherm import InputError
from gatetherm.checks import CELSIUS, check_linear_system
from gatetherm.solvers.expr import MAX_DEPTH, MAX_LENGTH, ExpressionError, Value
from gatetherm.studies.run import reduce
from gatetherm.studies.run.case import load_case
from gatetherm.studies.run.ccx import check_time
from gatetherm.studies.run.scenario import Schedule, run_scenario
from gatetherm.studies.run.timeseries import TimeSeries
from gatetherm.validation.report.drift import check_record
from test_bad_input import refused
from test_compensator import HAND

NAFEMS = Path(__file__).resolve().parents[1] / "validation" / "nafems"
T3 = (NAFEMS / "t3.toml").read_text()
HOT = 'temperature = "100 * sin(pi * t / 40)"'
KEY = "c.toml: thermal.a.temperature"


def t3(tmp_path: Path, old: str = "", new: str = "", extra: str = "") -> Path:
    """NAFEMS T3 with ``old`` replaced by ``new`` and ``extra`` appended (to its last table, [time])."""
    assert old in T3
    shutil.copy(NAFEMS / "t3.geo", tmp_path)
    path = tmp_path / "case.toml"
    path.write_text((T3.replace(old, new) if old else T3) + extra)
    return path


# ---- expressions -------------------------------------------------------------------------------

@pytest.mark.parametrize("text, error, needle", [
    ("1/0", InputError, f"{KEY}: '1/0' cannot be evaluated (division by zero)"),
    ("2**2000", InputError, "'2**2000' cannot be evaluated (overflow)"),
    ("exp(1000)", InputError, "'exp(1000)' cannot be evaluated (overflow)"),
    ("1" * 401, ExpressionError, "a number of 401 digits is beyond the floating-point range"),
    ("atan2(t)", ExpressionError, "atan2() takes 2 arguments, got 1"),
    ("sin(t, t)", ExpressionError, "sin() takes 1 argument, got 2"),
    ("min()", ExpressionError, "min() takes 2 or more arguments, got 0"),
    ("+".join(["1"] * 100_000), ExpressionError, f"the expression has 199999 characters, more than {MAX_LENGTH}"),
    ("-" * 900 + "1", ExpressionError, f"the expression is nested more than {MAX_DEPTH} deep"),
    ("sqrt(-1)", InputError, "'sqrt(-1)' cannot be evaluated (an argument outside a function's domain: the root of"),
    ("log(0)", InputError, "'log(0)' cannot be evaluated (an argument outside a function's domain"),
    ("(-8)**(1/3)", InputError, "cannot be evaluated (a negative number to a fractional power)"),
    ("abs((-8)**0.5)", InputError, "(a negative number to a fractional power)"),
    ("min(1/0, 3)", InputError, "'min(1/0, 3)' cannot be evaluated (division by zero)"),
    ("1e300 * 1e300", InputError, "'1e300 * 1e300' is inf, must be a number in"),
    ("2 * 2500", InputError, f"{KEY}: '2 * 2500' is 5000, must be a number in (-273.15, 1000] °C"),
])
def test_a_bad_expression_is_a_clean_error_where_it_is_read(text, error, needle):
    """Division by zero, overflow, huge literals, wrong arity, too long or too deep, a result
    outside a function's domain, a constant outside its key's range: one error when read."""
    with pytest.raises(error) as got:
        Value.of(text, KEY, CELSIUS)
    assert needle in str(got.value) and "\n" not in str(got.value)


def test_min_and_max_take_any_number_of_arguments():
    assert Value.of("max(t, 1, 2)")({"t": 5.0}) == 5.0 and Value.of("min(t, 1, 2)")({"t": 5.0}) == 1.0


def test_a_time_varying_value_is_checked_where_it_is_evaluated():
    """Every evaluation is checked against the key's range: one line naming the key, the
    expression and the time (or the point of a field, and the inputs it read)."""
    ramp = Value.of("100 * t", KEY, CELSIUS)
    assert ramp({"t": 10.0}) == 1000.0  # the closed upper bound
    with pytest.raises(InputError) as got:
        ramp({"t": 10.5})
    assert str(got.value) == (f"{KEY}: '100 * t' is 1050 at t = 10.5 s, must be a number in (-273.15, 1000] °C; "
                              "change the expression or the inputs it reads")
    with pytest.raises(InputError, match=r"'oil \+ t' is nan at t = 3 s, oil = nan, must be a finite number"):
        Value.of("oil + t", "k")({"t": 3.0, "oil": np.nan})
    with pytest.raises(InputError, match=r"cannot be evaluated \(invalid value encountered in sqrt\) at x = -1, y = 3"):
        Value.of("sqrt(x) + y", "k")({"x": np.array([1.0, -1.0]), "y": np.array([0.0, 3.0])})


def test_an_expression_that_leaves_its_range_during_the_run_is_one_line(tmp_path, capsys):
    case = t3(tmp_path, HOT, 'temperature = "100 * t"')
    refused(capsys, 2, ["run", case, "--out", tmp_path / "o"],
            f"{case}: thermal.hot_end.temperature: '100 * t' is 1050 at t = 10.5 s, must be a number in (-273.15,")
    assert not (tmp_path / "o").exists()


# ---- case values -------------------------------------------------------------------------------

FLUID = ('\n[fluids.tank]\nboundary = "insulated"\ncapacity = 1000.0\nconductance = 10.0\nfilm_on = 100.0\n'
         'film_off = 10.0\nsupply = 6000.0\n')
SCHEDULE = "# format: gatetherm-timeseries/1\ntime_s,T\n"


@pytest.mark.parametrize("old, new, extra, schedule, needle", [
    (HOT, "temperature = 5000.0", "", None,
     "thermal.hot_end.temperature: got 5000, must be a number in (-273.15, 1000] °C"),
    ("[thermal.cold_end]\ntemperature = 0.0", "[thermal.cold_end]\nfilm = 5.0\nambient = -300.0", "", None,
     "thermal.cold_end.ambient: got -300, must be a number in (-273.15, 1000] °C"),
    ("", "", FLUID, None, "fluids.tank.supply: got 6000, must be a number in (-273.15, 1000] °C"),
    ("end = 32.0", "end = 1e9", "", None, "time.step: 1e+09 s are 2000000000 steps of 0.5 s, more than 1000000"),
    ("end = 32.0", "end = 1e300", "", None, "time.step: 1e+300 s are"),
    ("step = 0.5", "step = 1e-7", "", None, "time.step: 32 s are 320000000 steps of 1e-07 s, more than 1000000"),
    ("step = 0.5", "step = 40.0", "", None, "time.step: got 40, must be a number in (0, 32] s"),
    ("output = 1.0", "output = 100.0", "", None, "time.output: got 100, must be a number in (0, 32] s"),
    ("c = 440.5\n", "c = 440.5\nthickness = 1e30\n", "", None,
     "materials.bar.thickness: got 1e+30, must be a number in [1e-06, 1000] m"),
    ("", "", 'schedule = "s.csv"\n', "0,0\n20,0\n",
     "time.schedule: '{d}/s.csv' spans 20 s, less than the run (end = 32 s)"),
    ("", "", '[relative.d]\na = "p"\nb = "q"\naxis = "x"\n', None,  # a run crashed on δ = None
     "relative: a relative displacement needs [supports] (without them the body is not solved for displacements); "
     "hold the body with [supports.BOUNDARY] tables"),
    (HOT, 'temperature = "T"', 'schedule = "s.csv"\n', "0,0\n32,2000\n40,0\n",
     "thermal.hot_end.temperature: 'T' is 2000 at t = 32 s, T = 2000, must be a number in (-273.15, 1000] °C"),
])
def test_case_values_have_the_ranges_of_model_files(tmp_path, old, new, extra, schedule, needle):
    """Temperatures, sizes and times in their ranges; at most 10⁶ steps; no interval longer
    than the run; a schedule that covers the run, whose columns are checked when read."""
    case = t3(tmp_path, old, new, extra)
    if schedule is not None:
        (tmp_path / "s.csv").write_text(SCHEDULE + schedule)
    with pytest.raises(InputError) as got:
        load_case(case)
    assert str(got.value).startswith(f"{case}: ") and needle.format(d=tmp_path) in str(got.value), got.value


def test_a_schedule_column_without_values_names_the_file(tmp_path):
    case = t3(tmp_path, HOT, 'temperature = "T"', 'schedule = "s.csv"\n')
    (tmp_path / "s.csv").write_text(SCHEDULE + "0,\n40,\n")
    with pytest.raises(InputError, match=f"^{tmp_path / 's.csv'}, column T: has no values; fill it "
                                         f"\\({case}: thermal.hot_end.temperature reads it\\)"):
        load_case(case)


def test_the_final_state_is_the_end_of_the_run(tmp_path):
    """T3 with output every 5 s: the time series ends with t = 32 s (not 30 s) at the target."""
    case = load_case(t3(tmp_path, "output = 1.0", "output = 5.0"))
    cols = run_scenario(case).columns
    np.testing.assert_array_equal(cols["time_s"], [0, 5, 10, 15, 20, 25, 30, 32])
    assert cols["T_target_degC"][-1] == pytest.approx(36.5947, abs=1e-4)  # NAFEMS: 36.60


def test_a_steady_case_without_a_solution_is_refused(tmp_path, capsys):
    """Fluxes only (no boundary holds a temperature or a film): no silently huge temperatures."""
    shutil.copy(NAFEMS / "t4.geo", tmp_path)
    text = (NAFEMS / "t4.toml").read_text().replace("temperature = 100.0", "flux = 100.0")
    case = tmp_path / "t4.toml"
    case.write_text(text.replace("film = 750.0", "flux = 750.0").replace("ambient = 0.0", ""))
    refused(capsys, 2, ["run", case, "--out", tmp_path / "o"], "thermal: the steady temperature is undetermined", "give a boundary a film")


def test_out_never_overwrites_an_input_of_the_run(tmp_path, capsys):
    """A schedule named timeseries.csv, --out the case folder: refused, the schedule unchanged."""
    case = t3(tmp_path, HOT, 'temperature = "T"', 'schedule = "timeseries.csv"\n')
    schedule = SCHEDULE + "0,0\n40,10\n"
    (tmp_path / "timeseries.csv").write_text(schedule)
    refused(capsys, 2, ["run", case, "--out", tmp_path],
            f"the run would overwrite its input '{tmp_path / 'timeseries.csv'}'")
    assert (tmp_path / "timeseries.csv").read_text() == schedule


# ---- reduced models ----------------------------------------------------------------------------

def _system(n=3, m=2, p=4, seed=0):
    rng = np.random.default_rng(seed)
    return {"on": (-np.eye(n) - 0.1 * rng.random((n, n)), rng.random((n, m))),
            "off": (-2 * np.eye(n), rng.random((n, m)))}, rng.random((p, n))


@pytest.mark.parametrize("edit, needle", [
    (lambda M, C: M.update(on=(np.eye(2), M["on"][1])),
     "A_on has shape (2, 2), expected (3, 3) (3 states, 2 inputs, 4 outputs)"),
    (lambda M, C: M.update(off=(M["off"][0], M["off"][1][:2])), "B_off has shape (2, 2), expected (3, 2)"),
    (lambda M, C: M["on"][0].__setitem__((0, 1), np.nan), "A_on has entries that are not finite numbers"),
    (lambda M, C: C.__setitem__((0, 0), np.inf), "C has entries that are not finite numbers"),
    (lambda M, C: M.update(off=(2 * np.eye(3), M["off"][1])),
     "A_off is not stable (an eigenvalue with real part 2 >= 0)"),
    (lambda M, C: M.update(off=(np.diag([-1.0, -2.0, 0.0]), M["off"][1])), "A_off is not stable"),
    (lambda M, C: M.update(on=(np.zeros(3), M["on"][1])), "A_on is not a matrix (shape (3,))"),
    (lambda M, C: M.clear(), "no mode"),
])
def test_a_reduced_model_is_checked_in_every_mode(edit, needle):
    modes, C = _system()
    check_linear_system("rom.npz", modes, C)
    check_linear_system("rom.npz", {**modes, "third": modes["off"]}, C, D=np.zeros((4, 2)),
                        inputs=("a", "b"), outputs="wxyz")  # any number of modes
    edit(modes, C)
    with pytest.raises(InputError, match=f"^rom.npz: {needle}".replace("(", r"\(").replace(")", r"\)")):
        check_linear_system("rom.npz", modes, C)


def test_names_must_match_the_matrices():
    modes, C = _system()
    with pytest.raises(InputError, match="1 inputs named for 2 inputs of the matrices"):
        check_linear_system("rom.npz", modes, C, inputs=("oil_degC",))


def _rom(inputs=("oil_degC", "ambient_degC")):
    from gatetherm.solvers.rom import Input, ReducedModel

    modes, _ = _system(2, 2)
    outputs = ("delta_um", "theta_A_degC", "theta_B_degC", "theta_C_degC")
    return ReducedModel({m: a for m, (a, _) in modes.items()}, {m: b for m, (_, b) in modes.items()},
                        np.ones((4, 2)), np.zeros((4, 2)), np.full(4, 20.0), tuple(Input(n, 20.0) for n in inputs),
                        outputs, ("pump",), 20.0, {"ambient_degC": 20.0}, 1)


def test_a_corrupt_reduced_model_file_names_the_file(tmp_path):
    path = tmp_path / "rom.npz"
    reduce.write_rom(_rom(), path)
    assert reduce.load_rom(path).states == 2
    path.write_bytes(path.read_bytes()[:300])
    with pytest.raises(InputError, match=f"^{path}: not an .npz archive"):
        reduce.load_rom(path)


def test_a_corrupt_cached_reduced_model_is_built_again(tmp_path, monkeypatch, caplog):
    """A truncated rom.npz whose key still matches: a warning, and the model built again."""
    good = _rom()
    monkeypatch.setattr(reduce, "build_rom", lambda *a: types.SimpleNamespace(rom=good))
    monkeypatch.setattr(reduce, "rom_key", lambda *a: "key")
    reduce.save_rom(good, "key", tmp_path)
    (tmp_path / "rom.npz").write_bytes(b"PK\x03\x04 truncated")
    with caplog.at_level(logging.WARNING):
        rom = reduce.cached_rom(None, 2, tmp_path)
    assert rom.states == 2 and reduce.load_rom(tmp_path / "rom.npz").states == 2
    assert f"{tmp_path / 'rom.npz'}: not an .npz archive" in caplog.text
    assert "building the reduced model again" in caplog.text


def test_a_reduced_model_whose_input_the_data_lacks_is_refused(tmp_path, capsys):
    reduce.write_rom(_rom(inputs=("oil_degC", "spindle_W")), tmp_path / "r.npz")
    (tmp_path / "d.csv").write_text(HAND)
    refused(capsys, 2, ["compensate", "--data", tmp_path / "d.csv", "--method", "rom", "--rom", tmp_path / "r.npz",
                        "--out", tmp_path / "o"], f"{tmp_path / 'd.csv'}, column spindle_W: missing: the reduced model")


# ---- options that do not apply, and odd ends ---------------------------------------------------

@pytest.mark.parametrize("argv, needle", [
    (["compensate", "--case", "c.toml", "--dim", "3"], "--case/--dim: a case file gives its own model and mesh"),
    (["compensate", "--case", "c.toml", "--dim", "2"], "--case/--dim"),
    (["compensate", "--case", "c.toml", "--config", "m.toml"], "--case/--config"),
    (["export", "ccx", "c.toml", "--dim", "3"], "CASE.toml/--dim"),
    (["export", "ccx", "c.toml", "--config", "m.toml"], "CASE.toml/--config"),
    (["report", "--data", "d.csv", "--section", "nafems"], "--data/--section: applies to the validation report"),
    (["report", "--data", "d.csv", "--full"], "--data/--full"),
    (["report", "--data", "d.csv", "--docs", "docs"], "--data/--docs"),
])
def test_options_that_do_not_apply_are_refused(tmp_path, capsys, argv, needle):
    refused(capsys, 2, [*argv, "--out", tmp_path / "o"], needle)
    assert not (tmp_path / "o").exists()


def test_report_docs_that_is_no_folder(tmp_path, capsys):
    (tmp_path / "README.md").write_text("x")
    refused(capsys, 2, ["report", "--docs", tmp_path / "README.md", "--out", tmp_path / "o"],
            f"--docs: '{tmp_path / 'README.md'}' is not a folder")


def test_report_docs_page_that_is_not_text(tmp_path, capsys):
    """The page whose other sections ``--docs`` keeps is read before anything is computed."""
    page = tmp_path / "docs" / "validation.md"
    page.parent.mkdir()
    page.write_bytes(b"# Validation results\n\xff\n")
    refused(capsys, 2, ["report", "--docs", page.parent, "--out", tmp_path / "o"],
            f"{page}, line 2: byte 0xff is not UTF-8 text")
    assert not (tmp_path / "o").exists() and page.read_bytes() == b"# Validation results\n\xff\n"


@pytest.mark.parametrize("columns, needle", [
    ({"time_s": [0.0], "delta_um": [1.0]}, "d.csv: 1 data row: a drift needs two samples or more"),
    ({"time_s": [0.0, 60.0]}, "d.csv: no displacement (*_um) or temperature (*_degC) column"),
    ({"time_s": [0.0, 60.0], "delta_um": [np.nan, np.nan]}, "d.csv, column delta_um: has no values"),
])
def test_a_record_without_a_drift_is_refused(columns, needle):
    with pytest.raises(InputError) as got:
        check_record(TimeSeries(columns), "d.csv")
    assert str(got.value).startswith(needle)


def test_an_export_time_is_a_step_of_the_run():
    """--time 1e-9 min is the initial step (it was a ValueError); between steps is refused."""
    s = Schedule(lambda t: {}, np.array([0.0, 60.0, 120.0]), "test")
    assert check_time(s, 6e-8) == 0.0 and check_time(s, 60.0 + 1e-7) == 60.0
    with pytest.raises(InputError, match="--time: 0.5 min is not a step of the run"):
        check_time(s, 30.0)


def test_equations_no_solver_can_solve_are_one_line(tmp_path, capsys, monkeypatch):
    """A factorisation that fails (PARDISO's zero pivot) is reported as bad input, exit 2."""
    from gatetherm.solvers.linsolve import SolverError
    import gatetherm.api

    def fail(*a, **k):
        raise SolverError("the matrix cannot be factorised (PARDISO phase 22 failed: zero pivot)")
    monkeypatch.setattr(gatetherm.api, "run_case", fail)
    refused(capsys, 2, ["run", "c.toml", "--out", tmp_path / "o"], "error: the matrix cannot be factorised")


def test_a_run_length_in_hours_is_said_to_be(tmp_path):
    """``end = 8.0`` meant 8 h: the output interval is refused as longer than the run, and the fix names
    the end in hours."""
    case = t3(tmp_path, "end = 32.0", "end = 0.25")
    with pytest.raises(InputError) as got:
        load_case(case)
    assert str(got.value) == f"{case}: time.output: got 1, must be a number in (0, 0.25] s; or end in s: 0.25 h is end = 900"
