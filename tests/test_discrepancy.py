"""The discrepancy workflow: phases, significance, verdict rules, replay, model files,
and a few representative blind diagnoses on a coarse mesh (the heavier ones are slow;
the full hidden-effect study is ``python -m validation.hidden_effects``).

The fast diagnoses make their "measured" data on the diagnosis mesh itself (an
inverse crime, for speed); the study uses a finer truth mesh."""
from __future__ import annotations

import dataclasses
from types import SimpleNamespace
import json

import numpy as np
import pytest

from gatetherm.frame.geometry import MeshParams
from gatetherm.studies.diagnosis.calibrate import Scored
from gatetherm.cli import main
from gatetherm.frame.problem import build_model
from gatetherm.frame.config import load_config
from gatetherm.studies.diagnosis.discrepancy import Settings, _verdict, adopted_case, diagnose
from gatetherm.frame.problem import TARGETS
from gatetherm.studies.diagnosis.hypotheses import effect_pieces
from gatetherm.studies.diagnosis.select import Selection
from gatetherm.studies.diagnosis.locate import Phase, locate, noise_sd, phases, significant, smooth, threshold
from gatetherm.frame.config import config_toml
from gatetherm.studies.run.simulate import run_model
from gatetherm.studies.diagnosis.replay import Replayer, compared_channels, residuals
from gatetherm.frame.case import frame_case
from gatetherm.frame.conditions import CONDITIONS, condition_schedule
from gatetherm.studies.run.conditions import condition_drive
from gatetherm.studies.run.scenario import measured_schedule, run_scenario
from gatetherm.studies.run.timeseries import TimeSeries, write_timeseries
from gatetherm.validation.truth import Case, measured, truth

COARSE = MeshParams(size=0.02)
HOUR = 3600.0


@pytest.fixture(scope="module")
def coarse_config():
    cfg = load_config()
    return dataclasses.replace(cfg, model=dataclasses.replace(cfg.model, mesh=COARSE))


def _measured(cfg, effect, strength, condition=1, seed=3):
    case = Case(effect, strength, condition, seed)
    return measured(truth(cfg, case, mesh_factor=1.0), seed, condition)


def test_phases_from_inputs():
    t = np.arange(0.0, 5 * HOUR + 1, 60.0)
    oil = np.interp(t, [0, HOUR, 2 * HOUR, 3 * HOUR, 4 * HOUR, 5 * HOUR], [20, 30, 30, 30, 20, 20])
    pump = np.where((t >= 2 * HOUR) & (t < 3 * HOUR), 0.0, 1.0)
    pump[(t >= 4.5 * HOUR) & (t < 4.5 * HOUR + 300)] = 0.0  # a 5-min blip joins its neighbour
    got = [(p.label, p.start_s / 60, p.end_s / 60) for p in phases(t, oil, pump)]
    assert got == [("heating", 0, 60), ("pump on, oil steady (30 °C)", 60, 120), ("pump off", 120, 180),
                   ("forced cooling", 180, 240), ("pump on, oil steady (20 °C)", 240, 300)]
    last = phases(t, oil, pump)[-1]
    assert last.closed and last.mask(t)[-1] and not phases(t, oil, pump)[0].mask(t)[60]


def test_smoothing_noise_and_threshold():
    t = np.arange(0.0, 300 * 60.0 + 1, 60.0)
    ramp = 0.01 * t / 60
    assert np.allclose(smooth(t, np.full_like(t, 2.5)), 2.5)
    assert np.allclose(smooth(t, ramp)[8:-8], ramp[8:-8])  # a centred average keeps a line
    assert noise_sd(ramp) == pytest.approx(0.0, abs=1e-12)
    rng = np.random.default_rng(0)
    assert noise_sd(rng.normal(0, 0.1, 20000)) == pytest.approx(0.1, rel=0.03)
    # 15-min window at 1-min sampling: 17 samples; noise-free -> rounding noise res/sqrt(12)
    assert threshold(t, ramp * 0, 0.1) == pytest.approx(0.1 * (1 + 3 / np.sqrt(12 * 17)), rel=1e-12)


def test_locate_flags_only_the_disturbed_phase():
    t = np.arange(0.0, 3 * HOUR + 1, 60.0)
    ph = [Phase("a", 0, HOUR), Phase("b", HOUR, 2 * HOUR), Phase("c", 2 * HOUR, 3 * HOUR, closed=True)]
    rng = np.random.default_rng(1)
    r = rng.normal(0, 0.1, len(t)) + np.where((t > 1.2 * HOUR) & (t < 1.8 * HOUR), 0.6, 0.0)
    found = {f.phase.label: f for f in locate(t, {"delta_um": r}, ph)}
    assert [k for k, f in found.items() if f.significant] == ["b"]
    assert "above the model" in found["b"].sentence() and "0.6" in found["b"].sentence()
    assert "within resolution" in found["a"].sentence()
    assert not significant(t, rng.normal(0, 0.1, len(t)), 0.1).any()


def test_verdict_rules():
    base = Scored({}, 900.0, 900.0, {"delta_um": 1.0}, False)
    piece = effect_pieces(SimpleNamespace(targets=TARGETS), ["piezo_heat"])[0]
    some = Scored({piece: 2.0}, 300.0, 306.0, {"delta_um": 0.4}, False)
    assert _verdict(False, Selection(base, base, []))[0] == "no-discrepancy"
    assert _verdict(True, Selection(base, base, []))[0] == "unexplained"
    assert _verdict(True, Selection(base, some, [piece]))[0] == "partly-explained"
    done = Scored({piece: 2.0}, 0.0, 6.0, {"delta_um": 0.1}, True)
    assert _verdict(True, Selection(base, done, [piece])) == ("explained", "piezo_heat leave no significant residual")


def test_replay_reproduces_a_simulation(coarse_config):
    ts = _measured(coarse_config, "none", 0.0, condition=3)
    rep = Replayer(frame_case(coarse_config, 2), ts.with_columns(ambient_degC=np.full(len(ts), 20.0)))
    model = build_model(coarse_config.model, 2, rep.config.mesh)  # the same mesh (gmsh may order nodes differently)
    clean = run_model(model, condition_drive(CONDITIONS[3], coarse_config.supply), ts.time_s).columns
    ts = ts.with_columns(**{c: clean[c] for c in ("theta_A_degC", "theta_B_degC", "theta_C_degC", "delta_um")})
    cols = rep.run()
    channels = compared_channels(ts, cols)
    assert channels == ("theta_A_degC", "theta_B_degC", "theta_C_degC", "delta_um")
    # the replay interpolates the recorded supply temperature linearly between the 1-min
    # samples, the simulation used the exact first-order response: 0.016 K/µm observed
    assert max(np.abs(r).max() for r in residuals(ts, cols, channels).values()) < 0.03
    assert rep.has_ambient and rep.run() is not cols and rep.runs == 1  # second run from the cache


def test_model_file_round_trip(tmp_path):
    cfg = dataclasses.replace(load_config(), effects={"joint_compliance": 2.5e11, "ambient_drift": -0.3})
    path = tmp_path / "model.toml"
    path.write_text(config_toml(cfg, "a test"), encoding="utf-8")
    back = load_config(path)
    assert back.model == cfg.model and back.supply == cfg.supply and back.effects == cfg.effects


def test_noise_only_is_no_discrepancy(coarse_config):
    d = diagnose(frame_case(coarse_config, 2), _measured(coarse_config, "none", 0.0, seed=11), Settings(p2_check=False))
    assert (d.verdict, d.pieces, d.named_effects, d.runs) == ("no-discrepancy", (), [], 1)
    assert d.summary()["rms_before_um"] == pytest.approx(0.1, rel=0.25)


def test_names_a_hidden_effect(coarse_config):
    ts = _measured(coarse_config, "piezo_heat", 3.0)
    d = diagnose(frame_case(coarse_config, 2), ts, Settings(effects=("piezo_heat", "stand_drift"), parameters=(),
                                                       sensors=False, p2_check=False))
    s = d.summary()
    assert (d.verdict, d.named_effects, s["best_rejected"]) == ("explained", ["piezo_heat"], None)
    assert [p["kind"] for p in s["pieces"]] == ["effect"] and s["pieces"][0]["share_of_residual"] == pytest.approx(1)
    assert s["fitted"]["piezo_heat.power"] == pytest.approx(3.0, rel=0.05)
    assert s["uncertainty"]["piezo_heat.power"] < 0.1
    assert s["rms_after_um"] < 0.3 * s["rms_before_um"]
    assert adopted_case(frame_case(coarse_config, 2), d).effects == {"piezo_heat": s["fitted"]["piezo_heat.power"]}


def test_list_effects_json(capsys):
    assert main(["diagnose", "--list-effects", "--json"]) == 0
    listed = json.loads(capsys.readouterr().out)
    assert {"kind", "name", "params"} <= set(listed[0]) and {d["kind"] for d in listed} == {"effect", "parameter",
                                                                                             "geometry", "sensor"}
    geometry = {d["name"]: d["params"] for d in listed if d["kind"] == "geometry"}
    assert list(geometry) == ["geometry.l4", "geometry.l_C", "geometry.A_C", "geometry.h", "geometry.tank_wall"]
    assert geometry["geometry.l_C"]["l_C"] == {"unit": "m", "range": [pytest.approx(0.32), pytest.approx(0.5)]}
    k = next(d for d in listed if d["name"] == "conductivity")
    assert k["params"]["k"]["unit"] == "W/(m K)" and k["params"]["k"]["range"][0] < 48 < k["params"]["k"]["range"][1]
    offsets = [d for d in listed if d["name"] == "sensor_offset"]
    assert {d["channel"] for d in offsets} == {"theta_A_degC", "theta_B_degC", "theta_C_degC", "delta_um"}
    assert main(["diagnose", "--data", "x.csv"]) == 2
    assert main(["diagnose", "--list-effects", "--json", "--uncertain", "geometry.column_height"]) == 0
    more = [d for d in json.loads(capsys.readouterr().out) if d["kind"] == "geometry"]
    assert more[-1]["name"] == "geometry.column_height" and more[-1]["params"]["column_height"]["range"][1] == \
        pytest.approx(0.7 * 1.25)
    assert main(["diagnose", "--list-effects", "--uncertain", "geometry.l1"]) == 2  # beam theory only: no mesh
    assert "'geometry.l1' is not a dimension of the frame" in capsys.readouterr().err


def test_diagnose_in_3d(tmp_path):
    """``--dim 3`` replays the 3-D solid: a file made by the 3-D model from the file's own inputs
    is no discrepancy in 3-D (one model run), while the 2-D section model sees a significant residual."""
    cfg = load_config()
    cfg = dataclasses.replace(cfg, model=dataclasses.replace(cfg.model, mesh=dataclasses.replace(
        cfg.model.mesh, size_3d=0.03)))
    case = frame_case(cfg, 3)
    inputs = run_scenario(case, condition_schedule(1, cfg.supply, 300.0)).series({})
    cols = run_scenario(case, measured_schedule(case, inputs)).columns
    data = tmp_path / "run3d.csv"
    write_timeseries(data, TimeSeries({c: cols[c] for c in ("time_s", "oil_degC", "pump", "theta_A_degC",
                                                            "theta_B_degC", "theta_C_degC", "delta_um")}, {}))
    assert main(["diagnose", "--data", str(data), "--out", str(tmp_path / "d3"), "--dim", "3",
                 "--mesh-size", "0.03"]) == 0
    s = json.loads((tmp_path / "d3" / "diagnosis.json").read_text())
    assert (s["verdict"], s["dim"], s["model_runs"]) == ("no-discrepancy", 3, 2)  # P1, and the P2 check
    p2 = s["discretisation_p2_minus_p1_in_resolutions"]
    assert p2["delta_um"] == pytest.approx(7.69, abs=0.3)  # achieved 7.69 resolutions of δ: a 3-cm 3-D mesh is coarse
    assert "3-D FE" in (tmp_path / "d3" / "report.md").read_text()
    assert main(["diagnose", "--data", str(data), "--out", str(tmp_path / "d2"), "--effects", "none",
                 "--parameters", "none", "--no-sensors"]) == 0
    s = json.loads((tmp_path / "d2" / "diagnosis.json").read_text())
    assert (s["verdict"], s["dim"], s["pieces"], s["best_rejected"]) == ("unexplained", 2, [], None)


@pytest.mark.slow
def test_parameter_mismatch(coarse_config):
    th = coarse_config.model.thermal
    wrong = dataclasses.replace(coarse_config, model=dataclasses.replace(
        coarse_config.model, thermal=dataclasses.replace(th, h_oil_on=th.h_oil_on * 1.6)))
    # the data is this P1 model's own run (its discretisation error, 3 resolutions of δ, is in the
    # data too): replayed with P1, not refined to P2
    d = diagnose(frame_case(coarse_config, 2), _measured(wrong, "none", 0.0, condition=2), Settings(refine=False))
    assert (d.verdict, [r.piece.name for r in d.pieces], d.named_effects) == ("explained", ["oil_film_on"], [])
    r = d.pieces[0]
    assert abs(r.value - 1.6 * th.h_oil_on) < max(3 * r.sigma, 0.05 * th.h_oil_on)


@pytest.mark.slow
@pytest.mark.parametrize("effect, strength", [("tie_heat_leak", 1.5), ("sensor_height", 0.04)])
def test_outside_catalogue_names_no_effect(coarse_config, effect, strength):
    d = diagnose(frame_case(coarse_config, 2), _measured(coarse_config, effect, strength))
    assert d.verdict in ("unexplained", "partly-explained") and d.named_effects == []


@pytest.mark.slow
def test_cli_end_to_end(coarse_config, tmp_path):
    data = tmp_path / "run.csv"
    write_timeseries(data, _measured(coarse_config, "stand_drift", 1.0, condition=2))
    out = tmp_path / "diag"
    assert main(["diagnose", "--data", str(data), "--out", str(out), "--mesh-size", "0.02", "--keep-order",
                 "--effects", "stand_drift,piezo_heat,compliant_base", "--parameters", "air_film"]) == 0
    s = json.loads((out / "diagnosis.json").read_text())
    for key in ("verdict", "pieces", "named_effects", "best_rejected", "rms_before_um", "rms_after_um", "fitted"):
        assert key in s
    assert (s["verdict"], s["named_effects"]) == ("explained", ["stand_drift"])
    assert s["fitted"]["stand_drift.coefficient"] == pytest.approx(1.0, rel=0.05)
    assert load_config(out / "model.toml").effects == {"stand_drift": s["fitted"]["stand_drift.coefficient"]}
    report = (out / "report.md").read_text()
    assert "explained" in report and "before_after.png" in report and "Round 1" in report
    assert all((out / f).is_file() for f in ("residuals.png", "scores.png", "before_after.png"))


@pytest.mark.slow
def test_a_drifting_room_under_a_recorded_constant_room_is_named(coarse_config):
    """Issue 51: the room drifted 0.51 K/h while the file recorded a constant 20 °C. Room drift is a
    hypothesis with a recorded room too (it adds to the record), and stand-ins rejected by the
    model-form checks send the selection back to the next candidates; every default hypothesis.
    Measured at 523e280: explained, ambient_drift 0.5073 ± 0.0071 K/h, 106 model runs (before:
    unexplained, nothing named)."""
    ts = _measured(coarse_config, "ambient_drift", 0.51, condition=2)
    ts = ts.with_columns(ambient_degC=np.full(len(ts), 20.0))
    d = diagnose(frame_case(coarse_config, 2), ts, Settings(p2_check=False))
    s = d.summary()
    assert d.has_ambient and (d.verdict, d.named_effects) == ("explained", ["ambient_drift"])
    assert [p["name"] for p in s["pieces"]] == ["ambient_drift"]
    assert s["fitted"]["ambient_drift.rate"] == pytest.approx(0.5073, abs=0.005)  # band: 0.51 ± 10 %
