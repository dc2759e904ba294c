"""`gatetherm diagnose --case`: the discrepancy workflow on a case file's frame (the C-frame
example), its hypotheses, its discretisation check and its bad input."""
from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest

from gatetherm import InputError
from gatetherm.solvers.problem import inputs
from gatetherm.cli import main
from gatetherm.studies.diagnosis.discrepancy import diagnose
from gatetherm.studies.diagnosis.hypotheses import catalogue, configure
from gatetherm.studies.diagnosis.locate import input_phases
from gatetherm.studies.run.case import load_case
from gatetherm.studies.run.scenario import run_scenario
from gatetherm.studies.run.timeseries import OUTPUT_COLUMNS, write_timeseries
from gatetherm.validation.case_diagnosis import (MESH_FACTOR, SCENARIOS, SPINDLE, hidden, measured_run,
                                                  write_case_diagnosis)
from gatetherm.validation.truth import recorded
from test_bad_input import refused

CASE = Path(__file__).resolve().parents[1] / "validation" / "examples" / "c_frame" / "case.toml"


@pytest.fixture(scope="module")
def case():
    return load_case(CASE)


def _measured(case, labels: dict, path: Path, seed: int = 3, keep=None) -> Path:
    """A P1 run of ``case`` with the hidden pieces ``labels``, as a rig records it."""
    schedule = case.schedule
    cols = run_scenario(configure(case, hidden(case, labels)), schedule).columns
    keep = keep or ("time_s", *schedule.drive.columns, *OUTPUT_COLUMNS)
    write_timeseries(path, recorded(cols, keep, OUTPUT_COLUMNS, seed, {"source": "test"}))
    return path


def test_the_case_hypotheses_act_on_what_they_name(case):
    pieces = {p.label: p for p in catalogue(case, OUTPUT_COLUMNS)}
    assert {"film_free", "faces_film", "source_spindle", "initial_offset", "conductivity", "expansion",
            "heat_capacity", "thermocouple_lag", "sensor_offset(delta_um)"} <= set(pieces)
    assert {"heat_source@arm", "heat_source@table", "compliant_base@feet_fixed", "base_conduction@feet_sliding",
            "ambient_drift"} <= set(pieces)  # effects by the case's own names
    assert not {"joint_resistance", "stand_drift", "air_film", "piezo_heat", "heat_source@spindle"} & set(pieces)
    c = configure(case, {pieces["film_free"]: 12.5, pieces["source_spindle"]: 1.5, pieces["expansion"]: 1.1,
                         pieces["initial_offset"]: 21.0, pieces["sensor_offset(delta_um)"]: 0.3})
    film = {f.boundary: f.h for f in c.problem.films}
    assert film["free"] == 12.5 and c.problem.faces.h == case.problem.faces.h
    env = {"spindle_W": 100.0, "t": 0.0}
    assert c.problem.sources[0].density(env) == pytest.approx(1.5 * case.problem.sources[0].density(env), rel=1e-14)
    for r, m in c.problem.materials.items():
        assert m.alpha == pytest.approx(1.1 * case.problem.materials[r].alpha, rel=1e-14)
        assert m.k == case.problem.materials[r].k
    assert c.problem.T0 == 21.0 and c.problem.T_ref == case.problem.T_ref
    assert c.sensors == {"delta_um": {"offset": 0.3}} and case.sensors == {}
    assert inputs(case.problem) == {"spindle_W", "ambient_degC"}


def test_phases_of_a_case_are_cut_where_an_input_steps():
    t = np.arange(0.0, 6 * 3600.0 + 1, 60.0)
    power = np.where(t < 7200, 120.0, np.where(t < 10800, 0.0, 200.0))
    ph = input_phases(t, {"spindle_W": power, "ambient_degC": 20.0 + t / 3600 * 0.25})
    assert [(p.label, p.start_s, p.end_s) for p in ph] == [
        ("spindle_W 120", 0.0, 7200.0), ("spindle_W 0", 7200.0, 10800.0), ("spindle_W 200", 10800.0, t[-1])]
    assert ph[-1].closed and input_phases(t, {"ambient_degC": 20.0 + 0 * t})[0].label == "whole run"


@pytest.mark.slow  # 198 s since room drift is a candidate when the record has the room (issue 51)
def test_diagnose_case_names_the_hidden_pieces(case, tmp_path, capsys):
    """A film of the case off by ×1.75 and a thermocouple offset, found blind through the command;
    the example's mesh is flagged by the discretisation check (P2 − P1 of δ: 1.23 resolutions), so the
    diagnosis replays with P2 elements."""
    data = _measured(case, {"film_free": 14.0, "sensor_offset(theta_A_degC)": 0.5}, tmp_path / "m.csv")
    assert main(["diagnose", "--case", str(CASE), "--data", str(data), "--out", str(tmp_path / "d")]) == 0
    out = capsys.readouterr().out
    d = json.loads((tmp_path / "d" / "diagnosis.json").read_text())
    assert d["verdict"] == "explained" and [p["name"] for p in d["pieces"]] == ["film_free", "sensor_offset"]
    assert d["fitted"]["film_free.h"] == pytest.approx(14.0, rel=0.02)
    assert d["fitted"]["sensor_offset(theta_A_degC).offset"] == pytest.approx(0.5, abs=0.02)
    assert d["rms_after_um"] < 0.13 < 4.0 < d["rms_before_um"]
    assert d["discretisation_p2_minus_p1_in_resolutions"]["delta_um"] == pytest.approx(1.229, abs=0.01)
    assert d["order"] == 2 and "warning: the model's discretisation error (P2 - P1) exceeds the resolution on " \
        "delta_um; the diagnosis replayed it with P2 elements" in out
    files = sorted(p.name for p in (tmp_path / "d").iterdir())
    assert files == ["before_after.png", "diagnosis.json", "report.md", "residuals.png", "scores.png"]
    report = (tmp_path / "d" / "report.md").read_text()
    assert "driven by the file's columns ambient_degC, spindle_W" in report and "spindle_W 200 3:00–5:00" in report


@pytest.fixture(scope="module")
def noise_only():
    """Noise only, recorded from P2 on a mesh twice as fine as the example's."""
    return measured_run(load_case(CASE, MESH_FACTOR), {}, 16, "noise-only, case mesh")


def test_a_residual_of_the_mesh_is_no_discrepancy(case, noise_only):
    """On the example's own mesh the P1 model's residual is significant (P2 − P1 of δ 1.23
    resolutions, achieved 1.229); replayed with P2 elements (:attr:`Settings.refine`) there is no
    discrepancy, and nothing is named."""
    d = diagnose(case, noise_only)
    assert (d.verdict, d.order, d.pieces, d.runs) == ("no-discrepancy", 2, (), 2)
    assert d.discretisation["delta_um"] == pytest.approx(1.229, abs=0.01) and d.too_coarse == ["delta_um"]
    assert d.reason.startswith("with P2 elements the baseline residual is within the sensor resolution")


def test_keep_order_diagnoses_with_p1_and_warns(noise_only, tmp_path, capsys):
    write_timeseries(tmp_path / "m.csv", noise_only)
    assert main(["diagnose", "--case", str(CASE), "--data", str(tmp_path / "m.csv"), "--out", str(tmp_path / "d"),
                 "--keep-order", "--effects", "none", "--parameters", "none", "--no-sensors"]) == 0
    d = json.loads((tmp_path / "d" / "diagnosis.json").read_text())
    assert (d["verdict"], d["order"]) == ("unexplained", 1)  # significant with P1, and nothing to try
    assert "exceeds the resolution on delta_um; refine the mesh (--mesh-factor) or set order = 2" in \
        capsys.readouterr().out


def test_bad_case_diagnosis_is_one_line_and_exit_2(case, tmp_path, capsys):
    data = _measured(case, {}, tmp_path / "m.csv")
    base = ["diagnose", "--case", CASE, "--data", data, "--out", tmp_path / "d"]
    refused(capsys, 2, base + ["--config", CASE], "--case/--config")
    refused(capsys, 2, base + ["--dim", "2"], "--case/--dim", "a case file gives its own model and mesh")
    refused(capsys, 2, ["diagnose", "--data", data, "--out", tmp_path / "d", "--mesh-factor", "0.5"],
            "--mesh-factor", "with --case only")
    refused(capsys, 2, base + ["--effects", "joint_resistance"], "--effects",
            "'joint_resistance' is not an effect this case can have; choose from ambient_drift, heat_source@base")
    refused(capsys, 2, base + ["--parameters", "air_film"], "--parameters", "unknown parameter air_film",
            "film_free")
    lacking = _measured(case, {}, tmp_path / "no_power.csv",
                        keep=("time_s", "ambient_degC", *OUTPUT_COLUMNS))
    refused(capsys, 2, ["diagnose", "--case", CASE, "--data", lacking, "--out", tmp_path / "d"],
            "no_power.csv, column spindle_W", "missing: the case reads it")
    steady = tmp_path / "t1"
    shutil.copytree(Path(__file__).resolve().parents[1] / "validation" / "nafems", steady)
    refused(capsys, 2, ["diagnose", "--case", steady / "t4.toml", "--data", data, "--out", tmp_path / "d"],
            "t4.toml: time", "needs [time]")
    assert not (tmp_path / "d").exists()


def test_a_case_geometry_meshes_finer_a_mesh_file_does_not(case, tmp_path):
    assert len(load_case(CASE, 0.5).mesh.points) == 7578 > len(case.mesh.points) == 2036
    assert main(["mesh", "--dim", "2", "--out", str(tmp_path / "m")]) == 0
    with pytest.raises(InputError, match="a mesh file cannot be refined"):
        load_case(tmp_path / "m" / "case.toml", 0.5)


@pytest.mark.slow
def test_case_diagnosis_study(tmp_path):
    """`gatetherm validate case-diagnosis`: at half the element size (P2 truth, P1 diagnosis) the
    catalogue and parameter scenarios are found, and so is the spindle housing 3 cm longer where
    its length is marked uncertain; noise only on the example's own mesh (discretisation check 1.23
    resolutions) is replayed with P2 elements and is no discrepancy. Unmarked, the longer spindle
    is not `explained` but a conductivity is named for it, the other sets that fit in part listed as
    stand-ins: the one scenario missed."""
    line, rows = write_case_diagnosis(tmp_path)
    by = {r["scenario"]: r for r in rows}
    assert set(by) == set(SCENARIOS)
    assert [n for n in SCENARIOS if not by[n]["found"]] == ["spindle length, not marked"], line
    assert by["noise-only"]["verdict"] == by["noise-only, case mesh"]["verdict"] == "no-discrepancy"
    assert [by[n]["order"] for n in ("noise-only", "noise-only, case mesh")] == [1, 2]
    assert by["source+expansion"]["alternatives"] == ["sensor_gain(delta_um)"]
    fitted = by["spindle length, marked"]["fitted"][f"{SPINDLE}.spindle_length"]
    assert fitted == pytest.approx(0.3805, abs=0.001)  # hidden 0.38; achieved 0.38045
    unmarked = by["spindle length, not marked"]
    # A cause outside every hypothesis. Since source_REGION joined the hypotheses (issue 53), the third
    # selection (after ambient drift + θ_C gain, then δ gain + heat capacity, were rejected as stand-ins)
    # named source ×0.90 + expansion ×1.10 + conductivity ×0.85, holding on every phase but leaving a
    # significant residual: three wrong causes that look confirmed, where the geometry changed. A later
    # selection now replaces the first named set only where it explains the run (diagnosis/backtrack.py):
    # the first stays, conductivity ×0.885 failing all four phase checks (the verdict: something outside
    # the hypotheses), and the third's source and expansion are listed as stand-ins (achieved, scenario
    # alone: partly-explained, conductivity with film_free in its group, 6 stand-ins, 545 runs).
    assert unmarked["verdict"] == "partly-explained" and unmarked["wrong_names"] == ["parameter:conductivity"]
    assert {"parameter:source_spindle", "parameter:expansion"} <= set(unmarked["stand_ins"])
    assert by["noise-only, case mesh"]["p2_minus_p1_delta"] > 1.0 > by["noise-only"]["p2_minus_p1_delta"]
    assert line.startswith("8 of 9 scenarios found")


@pytest.mark.slow
def test_the_paper_frame_as_a_case_finds_its_tank_film(tmp_path, capsys):
    """`gatetherm mesh` writes the paper frame as a case (a fluid with a hose, 23 compared
    channels, one of them, the hose, unchanged: zero residual); a run with the tank film (pump
    on) at 150 instead of 260 W/(m² K) is explained by that fluid's film alone."""
    (tmp_path / "hot.toml").write_text("[thermal]\nh_oil_on = 150.0\n")
    assert main(["mesh", "--dim", "2", "--out", str(tmp_path / "m")]) == 0
    assert main(["simulate", "--condition", "1", "--config", str(tmp_path / "hot.toml"), "--out",
                 str(tmp_path / "s")]) == 0
    assert main(["diagnose", "--case", str(tmp_path / "m" / "case.toml"), "--data",
                 str(tmp_path / "s" / "timeseries.csv"), "--out", str(tmp_path / "d")]) == 0
    d = json.loads((tmp_path / "d" / "diagnosis.json").read_text())
    assert d["verdict"] == "explained" and list(d["fitted"]) == ["tank_oil_film_on.film_on"]
    assert d["fitted"]["tank_oil_film_on.film_on"] == pytest.approx(150.0, rel=0.005)
    assert d["rms_before"]["T_hose_degC"] == 0.0 and len(d["channels"]) == 23


def test_the_study_on_another_case_leaves_out_the_c_frames_own_scenarios(tmp_path, caplog):
    """`validate case-diagnosis --case` on a lathe headstock: the scenarios hiding the C-frame's spindle
    source and length are left out with a warning each, before any model run; none left: refused."""
    from gatetherm import InputError
    from gatetherm.validation.case_diagnosis import lacking, run_study

    other = Path(__file__).resolve().parent / "data" / "headstock" / "case.toml"
    hs = load_case(other, MESH_FACTOR)
    assert {n: lacking(hs, SCENARIOS[n][0]) for n in SCENARIOS if lacking(hs, SCENARIOS[n][0])} == {
        "source+expansion": "source_spindle", "spindle length, marked": SPINDLE, "spindle length, not marked": SPINDLE}
    with pytest.raises(InputError, match="no scenario of the study hides pieces this case has"):
        run_study(tmp_path, other, scenarios=("source+expansion", "spindle length, marked"))
    assert [r.message.split(":")[1].strip() for r in caplog.records if "left out" in r.message] == [
        "scenario 'source+expansion' left out", "scenario 'spindle length, marked' left out"]
    assert not list(tmp_path.iterdir())
