"""K sources, ``gatetherm compensate --condition``, the Fig. 5 plot and the compensation study.

Everything runs on a frame of its own, pinned in a small TOML file (so that recalibrating
the shipped paper model or the code defaults leaves these values alone) and meshed
coarsely with ``[mesh] size = 0.02``.
"""
import csv
import dataclasses
import io
import json

import numpy as np
import pytest

from gatetherm.frame import beam
from gatetherm.frame.problem import build_model
from gatetherm.frame.loadcases import fe_coefficients
from gatetherm import cli
from gatetherm.studies.control.actuator import ActuatorParams, dead_band_um
from gatetherm.studies.control.methods import Settings, coefficients
from gatetherm.frame.case import frame_case
from gatetherm.studies.run.scenario import run_scenario
from gatetherm.studies.run.timeseries import FORMAT
from gatetherm.frame.beam import theory_coefficients
from gatetherm.frame.conditions import CONDITIONS
from gatetherm.frame.loadcases import tip_coefficients_um
from gatetherm.frame.config import load_config
from gatetherm.studies.run.conditions import condition_drive
from gatetherm.studies.run.simulate import run_model, sample_times
from gatetherm.studies.run.timeseries import read_timeseries, write_timeseries
from gatetherm.validation import compensation_study
from gatetherm.validation.plots import save
from gatetherm.validation.plots.compensation import loop_widths, plot_piezo_loops


PINNED = """
[mesh]
size = 0.02

[geometry]
h = 0.18
depth = 0.12
column_height = 0.73
l = 0.70
l1 = 0.25
l4 = 0.30
l_C = 0.40
A_C = 6e-4
t_C = 0.04
tank_wall = 0.015
tank_width = 0.04
tank_height = 0.21
sensor_height = 0.125

[thermal]
h_air = 8.0
h_oil_on = 150.0
h_oil_off = 25.0

[supply]
tau_heat = 600.0
tau_cool = 600.0
"""


@pytest.fixture(scope="module")
def coarse_toml(tmp_path_factory):
    path = tmp_path_factory.mktemp("cfg") / "coarse.toml"
    path.write_text(PINNED)
    return path


@pytest.fixture(scope="module")
def cfg(coarse_toml):
    return load_config(coarse_toml)


@pytest.fixture(scope="module")
def model(cfg):
    return build_model(cfg.model, 2)


@pytest.fixture(scope="module")
def study(cfg):
    return compensation_study.study(cfg)


@pytest.fixture
def gatetherm(monkeypatch, capsys):
    monkeypatch.setattr(cli, "COMMAND_MODULES", ("compensate",))

    def run(*argv):
        code = cli.main([str(a) for a in argv])
        return code, capsys.readouterr()
    return run


# ---- K sources ---------------------------------------------------------------------------

def test_theory_coefficients_are_the_beam_theory_of_the_frame(cfg):
    f, m = cfg.model.frame, cfg.model.material
    by_hand = beam.BeamModel(l=f.l, l1=f.l1, l4=f.l4, h=f.h, EI=m.E * f.depth * f.h ** 3 / 12, alpha=m.alpha,
                             l_C=f.l_C, A_C=f.A_C, E_C=m.E, alpha_C=m.alpha)
    ki, kc = beam.coefficients(by_hand)
    assert theory_coefficients(cfg.model) == (float(ki) * 1e6, float(kc) * 1e6)
    case = frame_case(cfg, 2)
    assert coefficients(case, None, Settings(k_source="theory"))[:2] == theory_coefficients(cfg.model)
    # independent route for l1 = l/2, one material: the normalised eqs (27)-(29)
    half = dataclasses.replace(cfg.model, frame=dataclasses.replace(f, l1=f.l / 2))
    a, b = f.l / f.l4, beam.beta(f.depth * f.h ** 3 / 12, f.l_C, f.A_C, f.l)
    expected = beam.denormalise(*beam.normalised(a, b), m.alpha, f.l, f.h, f.l_C)
    np.testing.assert_allclose(theory_coefficients(half), np.array(expected) * 1e6, rtol=1e-12)
    # a different tie-bar material enters through E_C and alpha_C only
    steel = dataclasses.replace(m, E=2.1e11, alpha=1.2e-5)
    mixed = dataclasses.replace(cfg.model, tie_material=steel)
    ki, kc = beam.coefficients(dataclasses.replace(by_hand, E_C=steel.E, alpha_C=steel.alpha))
    assert theory_coefficients(mixed) == (float(ki) * 1e6, float(kc) * 1e6)


def test_fe_coefficients_are_the_load_cases_at_the_tips(cfg, model):
    c = fe_coefficients(model)
    assert tip_coefficients_um(model) == (c.Ki_F * 1e6, c.Kc_F * 1e6)
    assert coefficients(frame_case(cfg, 2, mesh=model.fmesh), None, Settings(k_source="fe"))[:2] == \
        tip_coefficients_um(model)
    ki, kc = tip_coefficients_um(model)
    assert ki > 0 and kc > 0  # heat-side bending approaches, a warmer tie bar pushes apart


# ---- gatetherm compensate --condition / --k-source -----------------------------------------

def test_cli_condition_simulates_and_compensates(tmp_path, coarse_toml, cfg, model, gatetherm):
    out = tmp_path / "out"
    code, io_ = gatetherm("compensate", "--condition", 2, "--config", coarse_toml, "--out", out)
    assert code == 0, io_.err
    assert sorted(p.name for p in out.iterdir()) == ["compensated.csv", "compensation.png", "piezo_loops.png",
                                                     "summary.json"]
    summary = json.loads((out / "summary.json").read_text())
    assert summary["k_source"] == "theory" and summary["condition"] == 2 and summary["data"] is None
    assert (summary["Ki_um_per_K"], summary["Kc_um_per_K"]) == theory_coefficients(cfg.model)
    assert summary["config"] == str(coarse_toml) and summary["dim"] == 2
    comp = read_timeseries(out / "compensated.csv")
    assert comp.metadata["condition"] == "2" and len(comp) == 301
    direct = run_model(model, condition_drive(CONDITIONS[2], cfg.supply), sample_times(5 * 3600))
    # the command meshes again and gmsh is not bit-reproducible: equal to ~1e-3 um, not to round-off
    np.testing.assert_allclose(comp["delta_um"], direct.columns["delta_um"], rtol=1e-3, atol=0.01)
    np.testing.assert_array_equal(comp["delta_comp_um"], comp["delta_um"] + comp["u_piezo_um"])
    assert summary["swing_um"] == pytest.approx(np.ptp(comp["delta_um"]), rel=1e-15)
    assert "condition 2: K_i" in io_.out and "residual band" in io_.out
    # the same run from the file with the FE coefficients of the same model
    code, io_ = gatetherm("compensate", "--data", out / "compensated.csv", "--config", coarse_toml,
                          "--k-source", "fe", "--out", tmp_path / "fe", "--no-actuator")
    assert code == 0, io_.err
    fe = json.loads((tmp_path / "fe" / "summary.json").read_text())
    assert fe["k_source"] == "fe"  # the command builds its own mesh: equal to ~1e-5
    assert (fe["Ki_um_per_K"], fe["Kc_um_per_K"]) == pytest.approx(tip_coefficients_um(model), rel=3e-4)
    assert fe["swing_um"] == summary["swing_um"] and fe["piezo_saturated_updates"] == 0


def test_cli_data_defaults_to_theory_of_the_paper_model(tmp_path, cfg, model, gatetherm):
    run = run_scenario(frame_case(cfg, 2, mesh=model.fmesh))
    write_timeseries(tmp_path / "run.csv", run.series({"format": FORMAT}))
    code, io_ = gatetherm("compensate", "--data", tmp_path / "run.csv", "--out", tmp_path / "o", "--no-actuator")
    assert code == 0, io_.err
    summary = json.loads((tmp_path / "o" / "summary.json").read_text())
    assert summary["k_source"] == "theory" and summary["config"] == "gatetherm:paper.toml"
    assert (summary["Ki_um_per_K"], summary["Kc_um_per_K"]) == theory_coefficients(load_config().model)


@pytest.mark.parametrize("args, message", [
    (("--condition", "7"), "--condition: no condition 7; choose one of 1, 2, 3"),
    (("--condition", "1", "--config", "nope.toml"), "--config: no such file 'nope.toml'"),
])
def test_cli_condition_errors(tmp_path, monkeypatch, gatetherm, args, message):
    monkeypatch.chdir(tmp_path)
    code, io_ = gatetherm("compensate", *args, "--out", tmp_path / "out")
    assert code == 2 and io_.err.count("\n") == 1 and message in io_.err
    assert not (tmp_path / "out").exists()


def test_cli_needs_exactly_one_source(tmp_path, gatetherm):
    for args, start in (((), "gatetherm: error: --data/--condition/--case: give what to compensate"),
                        (("--condition", "1", "--data", "x.csv"), "gatetherm compensate: error: ")):
        code, io_ = gatetherm("compensate", *args, "--out", tmp_path / "out")
        assert code == 2 and io_.err.startswith(start) and io_.err.count("\n") == 1


# ---- Fig. 5 analogue ---------------------------------------------------------------------

def test_piezo_loop_plot_closes_with_reset_and_is_open_without(tmp_path):
    p = ActuatorParams()
    axes = plot_piezo_loops(p)
    save(axes, tmp_path / "loops.png")
    assert (tmp_path / "loops.png").stat().st_size > 10_000
    widths = loop_widths(p)
    assert [len(ax.lines) for ax in axes] == [3, 3]  # direct, reset and the bias voltage's line
    for preload in (0.0, p.preload_N):
        reset = widths[f"preload {preload:g} N, reset"]
        assert reset <= dead_band_um(dataclasses.replace(p, preload_N=preload)) and reset == 0.0
    # without the reset the loop stays open: hysteresis (3.04 um), plus the 3 um seating gap unloaded;
    # 3 x that at the cutting area with the default transmission
    assert widths["preload 580 N, direct"] == pytest.approx(3.04343, abs=1e-5)
    assert widths["preload 0 N, direct"] == pytest.approx(6.03435, abs=1e-5)


# ---- the study ---------------------------------------------------------------------------

def test_study_table_structure(cfg, model, study):
    rows = study.rows
    assert len(rows) == 18 and [r.condition for r in rows[::6]] == [1, 2, 3]
    by = {(r.condition, r.predictor): r for r in rows}
    assert (by[1, "paper, K theory"].Ki_um_per_K, by[1, "paper, K theory"].Kc_um_per_K) == \
        theory_coefficients(cfg.model)
    assert (by[1, "paper, K FE"].Ki_um_per_K, by[1, "paper, K FE"].Kc_um_per_K) == \
        pytest.approx(tip_coefficients_um(model), rel=3e-4)  # another build of the mesh
    for n in (1, 2, 3):
        same = [r for r in rows if r.condition == n]
        assert len({r.swing_um for r in same}) == 1
        for r in same:
            assert r.error_band_off_switch_um <= r.prediction_error_band_um
            assert r.residual_band_off_switch_um <= r.residual_band_um
            assert r.updates == 61
    parsed = list(csv.DictReader(io.StringIO(compensation_study.table_csv(study))))
    assert len(parsed) == 18 and float(parsed[0]["swing_um"]) == rows[0].swing_um
    text = compensation_study.markdown(study)
    assert text.count("| ±6–7 |") == 18 and "- condition 3: yes (" in text


# regression values on the pinned coarse frame: (swing, prediction-error band, residual band,
# residual band with 1-min updates, clipped updates). Two builds of one mesh differ by ~4e-5
# (gmsh is not bit-reproducible), hence rel=3e-4; the all-sensor regression is too
# ill-conditioned for regression values (its bands move by 10-50 % between builds).
EXPECTED = {
    (1, "paper, K theory"): (55.7106, 4.66092, 21.3687, 4.66092, 0),
    (2, "paper, K FE"): (47.1894, 4.79228, 22.1107, 4.79228, 0),
    (3, "paper, K fit (cond. 1)"): (61.3944, 4.60845, 20.7123, 4.60845, 0),
    (3, "MLR θA θB θC (cond. 1)"): (61.3944, 2.04152, 21.7875, 2.04152, 1),
    (2, "MLR θA θB θC (cond. 1), 1-min forecast"): (47.1894, 5.55267, 22.4095, 5.55267, 0),
}


@pytest.mark.parametrize("key", list(EXPECTED), ids=lambda k: f"{k[0]}-{k[1]}")
def test_study_regression_values(study, key):
    row = {(r.condition, r.predictor): r for r in study.rows}[key]
    got = (row.swing_um, row.prediction_error_band_um, row.residual_band_um, row.residual_band_1min_um,
           row.saturated_updates)
    assert got == pytest.approx(EXPECTED[key], rel=3e-4)


def test_study_main_writes_figures_and_tables(tmp_path, coarse_toml, study, monkeypatch, capsys):
    monkeypatch.setattr(compensation_study, "study", lambda cfg, dim: study)  # computed above already
    assert cli.main(["validate", "compensation", "--out", str(tmp_path), "--config", str(coarse_toml)]) == 0
    names = sorted(p.name for p in tmp_path.iterdir())
    assert names == ["compensation_table.csv", "compensation_table.md", "fig14_condition1.png",
                     "fig15_condition2.png", "fig16_condition3.png", "piezo_loops.png"]
    assert capsys.readouterr().out == (tmp_path / "compensation_table.md").read_text()
