"""Issue 55's audit, part B (case files, the newest commands, the API): the classes it found, each
fixed where the input is read. Model files naming the entry that is wrong (NaN, kelvins, sensors
that disagree with the terms, long names); a refit whose correction column is the target; loads
beyond any machine; too few reduced states; the twin's and live's arguments; a STEP file of too
many solids; `-v` without the libraries' INFO; the API's callbacks of the wrong arity, plots of
what a run lacks."""
from __future__ import annotations

import json
import logging
import math
import shutil
from pathlib import Path

import numpy as np
import pytest

from gatetherm import InputError
from gatetherm.checks import parse_json
from gatetherm.studies.errormodel.fit import FitParams, fit_error_model
from gatetherm.studies.errormodel.model import check_leakage, from_dict, to_dict
from test_errormodel import synthetic

EXAMPLES = Path(__file__).resolve().parents[1] / "validation" / "examples"


@pytest.fixture(scope="module")
def model():
    ts = synthetic(n=400)
    return fit_error_model(ts, ["d_um"], ["s1_degC", "s3_degC"], (), FitParams(max_sensors=2, form="static"))


# ---- model files: the entry named ----------------------------------------------------------------

@pytest.mark.parametrize("text, where, held", [
    ('{"a": {"b": [1, NaN]}}', "m.json: a.b[1]", "NaN"),
    ('{"x": 1e999}', "m.json: x", "1e999"),
    ('{"a": -Infinity}', "m.json: a", "-Infinity"),
])
def test_a_non_finite_number_of_a_json_file_names_its_entry(text, where, held):
    with pytest.raises(InputError) as e:
        parse_json(text, "m.json", "fix it")
    assert str(e.value) == f"{where}: holds {held}, not a finite number; fix it"


def test_model_file_refuses_kelvins_disagreeing_sensors_and_long_names(model):
    d = to_dict(model)
    assert from_dict(json.loads(json.dumps(d)), "m.json").names == ("d_um",)
    bad = json.loads(json.dumps(d))
    bad["reference_degC"] = {"s1_degC": 295.15}
    with pytest.raises(InputError, match=r"m.json: reference_degC.s1_degC: is 295.15 °C: a temperature in kelvins"):
        from_dict(bad, "m.json")
    bad = json.loads(json.dumps(d))
    bad["targets"]["d_um"]["sensors"] = ["s3_degC"]
    with pytest.raises(InputError, match=r"targets.d_um.sensors: lists s3_degC but its terms read s1_degC, s3_degC"):
        from_dict(bad, "m.json")
    bad = json.loads(json.dumps(d))
    bad["targets"] = {"y" * 400 + "_um": bad["targets"]["d_um"]}
    with pytest.raises(InputError, match="is not a column name of at most 100 printable characters .403 characters"):
        from_dict(bad, "m.json")
    with pytest.raises(InputError, match="targets 'xxxx.*100 printable characters"):
        check_leakage(["x" * 300 + "_um"], ("t1_degC",))


def test_a_refit_whose_correction_column_is_the_target_is_refused(model):
    from gatetherm.studies.errormodel.refit import refit

    ts = synthetic(n=400, seed=3)
    with pytest.raises(InputError, match="applied correction of d_um: column d_um is a target or a column the model"):
        refit(model, ts, 3600.0, {"d_um": "d_um"})
    with pytest.raises(InputError, match="applied correction of nosuch_um: is not a target of the model"):
        refit(model, ts, 3600.0, {"nosuch_um": "s2_degC"})


# ---- case files: loads beyond any machine --------------------------------------------------------

def _joint(tmp_path: Path, old: str, new: str) -> Path:
    for f in ("case.toml", "two_blocks.geo"):
        shutil.copy(EXAMPLES / "joint" / f, tmp_path)
    path = tmp_path / "case.toml"
    text = path.read_text()
    assert old in text
    path.write_text(text.replace(old, new))
    return path


@pytest.mark.parametrize("new, key", [
    ("force = [1e300, 0.0]", "loads.cold.force[1]: got 1e+300, must be a number in [-1e+12, 1e+12] N"),
    ("pressure = \"1e13 * (t >= 0)\"", "loads.cold.pressure"),
])
def test_a_load_beyond_any_machine_is_refused_naming_its_key(tmp_path: Path, new, key):
    from gatetherm.studies.run.case import load_case
    from gatetherm.studies.run.scenario import run_scenario

    path = _joint(tmp_path, "force = [1000.0, 0.0]", new)
    with pytest.raises(InputError) as e:
        run_scenario(load_case(path))
    assert key in str(e.value) and "\n" not in str(e.value)


# ---- twin and live -------------------------------------------------------------------------------

@pytest.mark.parametrize("endpoint", ["opc.tcp://127.0.0.1:99999", "opc.tcp://127.0.0.1:", "opc.tcp://:4840",
                                      "opc.tcp://a b:4840", "http://127.0.0.1:4840"])
def test_an_endpoint_needs_a_host_and_a_port_1_to_65535(endpoint):
    from gatetherm.validation.live.twin import endpoint_url

    with pytest.raises(InputError, match="--endpoint: .* is not opc.tcp://HOST:PORT"):
        endpoint_url(endpoint)
    assert endpoint_url("opc.tcp://127.0.0.1:4840") == "opc.tcp://127.0.0.1:4840"


def test_twin_faults_noise_and_start_named():
    from gatetherm.validation.live.twin import TwinParams

    with pytest.raises(InputError, match="--fault: .* with from_s <= to_s"):
        TwinParams(faults=(("spindle_W", 100.0, 10.0),))
    with pytest.raises(InputError, match="noise_K: must be a finite number >= 0, got -1.0"):
        TwinParams(noise_K=-1.0)
    p = TwinParams(faults=(("nosuch", 0.0, 10.0),), start_s=1e9)
    with pytest.raises(InputError, match="--fault nosuch: is not a column the twin publishes; choose one of a, b"):
        p.check_against({"a", "b"}, 7200.0)
    with pytest.raises(InputError, match=r"--start: 1e\+09 s is past the schedule's end \(7200 s\)"):
        TwinParams(start_s=1e9).check_against({"a"}, 7200.0)


def test_live_summary_of_a_run_stopped_before_its_first_period(tmp_path: Path):
    from gatetherm.validation.live.journal import lock, summarize

    (tmp_path / "live.csv").write_text("# format: gatetherm-timeseries/1\ntime_s,offset_um\n")
    out = summarize(tmp_path, {"periods": 0, "missed": 0})
    assert out["rows"] == 0 and out["monitor"] == "inactive (no period)"
    (tmp_path / "file").write_text("x")
    with pytest.raises(InputError, match="--out: '.*file' exists and is not a directory"):
        lock(tmp_path / "file")


# ---- geometry ------------------------------------------------------------------------------------

def test_a_step_file_of_too_many_solids_is_refused_before_gmsh_reads_it(tmp_path: Path):
    from gatetherm.geometry.gmshfile import MAX_PARTS, check_step_parts

    head = b"ISO-10303-21;\nDATA;\n"
    body = b"".join(b"#%d=MANIFOLD_SOLID_BREP('',#1);\n" % i for i in range(MAX_PARTS + 1))
    (tmp_path / "a.step").write_bytes(head + body * 1 + b"ENDSEC;\n")
    with pytest.raises(InputError, match=f"a.step: has {MAX_PARTS + 1} solids, more than the budget of {MAX_PARTS}"):
        check_step_parts(tmp_path / "a.step")
    (tmp_path / "b.step").write_bytes(head + body[: body.index(b"#5=")] + b"ENDSEC;\n")
    check_step_parts(tmp_path / "b.step")  # 5 solids: read


# ---- the command line's -v -----------------------------------------------------------------------

def test_verbose_logs_gatetherm_not_the_libraries_info():
    import subprocess
    import sys

    code = ("import logging; from gatetherm.cli import main; "
            "main(['-v', 'beam', '--l-over-l4', '1.5', '--beta', '0.1']); "
            "print(logging.getLogger('gatetherm.solvers').isEnabledFor(20), "
            "logging.getLogger('skfem.assembly').isEnabledFor(20))")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120).stdout
    assert out.splitlines()[-1] == "True False"  # the joint example with -v: 11 INFO lines of gatetherm, 68 of scikit-fem before


# ---- the API -------------------------------------------------------------------------------------

@pytest.mark.parametrize("hook", [lambda: None, lambda i: None, lambda i, n, x: None])
def test_a_callback_that_cannot_take_i_and_n_is_a_type_error_naming_it(hook):
    import gatetherm as gt

    with pytest.raises(TypeError, match="on_progress: .* cannot be called with 2 arguments"):
        gt.run_case("nosuch.toml", on_progress=hook)
    with pytest.raises(InputError, match="no such file"):  # (i, n), defaults and *args: checked no further
        gt.run_case("nosuch.toml", on_progress=lambda *a: None)


def test_beam_normalised_takes_infinity_for_beta_and_refuses_an_overflow():
    import gatetherm as gt

    r = gt.beam_normalised(1.5, math.inf)
    assert (r.ki_norm, r.kc_norm) == (1.0, 0.0)  # no tie bar: K_i at its free value, no K_C
    with pytest.raises(InputError, match="l_over_l4, beta: 1e\\+308 and 1e\\+308 overflow the closed form"):
        gt.beam_normalised(1e308, 1e308)
    with pytest.raises(InputError, match="beta"):
        gt.beam_normalised(1.5, math.nan)


def test_plots_of_what_a_run_lacks_name_it(tmp_path: Path):
    import matplotlib

    matplotlib.use("Agg")
    import gatetherm as gt

    run = gt.run(gt.load_case(_joint(tmp_path, "[loads.cold]", "[loads.cold]")))
    with pytest.raises(InputError, match="run: has no theta_A_degC, theta_B_degC, theta_C_degC, delta_um"):
        gt.plot.response(run)
    with pytest.raises(InputError, match=r"run: its case has no \[fluids\]"):
        gt.plot.fluids(run)
    with pytest.raises(InputError, match="columns: none given"):
        gt.plot.series(run)
    assert np.isfinite(run["T_a_degC"]).all()


@pytest.mark.parametrize("setting, needle", [
    ({"max_inputs": -2}, "max_inputs: -2 is not >= 0"), ({"max_sensors": 0}, "max_sensors: 0 is not >= 1"),
    ({"input_taus_s": (-60.0,)}, "input_taus_s: -60 is not > 0"), ({"max_gap_s": 0.0}, "max_gap_s: 0 is not > 0"),
])
def test_a_bad_fit_setting_is_named_alone(setting, needle):
    with pytest.raises(InputError, match=needle):
        FitParams(**setting)


def test_meshio_warnings_are_logged_naming_the_file_not_printed(tmp_path: Path, caplog, capfd):
    from gatetherm.geometry.mesh import load_mesh

    text = ("$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n3\n1 0 0 0\n2 1 0 0\n3 0 1 0\n$EndNodes\n"
            "$Elements\n1\n1 2 2 1 1 1 2 3\n")  # $Elements not closed
    (tmp_path / "m.msh").write_text(text)
    with caplog.at_level(logging.WARNING):
        fm = load_mesh(tmp_path / "m.msh")  # its one triangle read; the file's fault said
    assert fm.cells.shape[0] == 1
    assert "m.msh: meshio: $Elements not closed by $EndElements." in caplog.text
    assert "Warning" not in capfd.readouterr().err
