"""The effects catalogue: entries, parsing, the physics each effect switches on, and that
every effect is clearly above the sensor resolution at both ends of its range."""
from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest

from gatetherm import InputError
from gatetherm.solvers.effects import (CATALOGUE, ActiveEffects, apply_effects, catalogue_json, effects_from_table,
                             effects_table, first_order_lag, parse_effect)
from gatetherm.solvers.fem import to_skfem
from gatetherm.solvers.frame import AMBIENT, ModelConfig, build_model, frame_problem
from gatetherm.solvers.model import region_fields
from gatetherm.studies.run.conditions import CONDITIONS, condition_drive
from gatetherm.studies.run.config import load_config, parse_config
from gatetherm.studies.run.simulate import run_model, sample_times
from conftest import FIXED_MODEL

from gatetherm.geometry.frame import MeshParams

COARSE = MeshParams(size=0.02)


def test_catalogue_entries():
    assert len(CATALOGUE) >= 6
    for e in CATALOGUE.values():
        assert e.lo < e.hi and e.unit and e.acts_on in ("model", "drive", "observation") and e.doc
    listed = json.loads(json.dumps(catalogue_json()))
    assert [d["name"] for d in listed] == list(CATALOGUE)
    assert listed[0]["params"] == {"rate": {"unit": "K/h", "range": [-1.0, 1.0]}}
    assert all(set(d["params"][p]) == {"unit", "range"} for d in listed for p in d["params"])


def test_parse_effect_and_table():
    assert parse_effect("piezo_heat:power=1.5") == ("piezo_heat", 1.5)
    assert parse_effect("stand_drift=2") == ("stand_drift", 2.0)
    for bad in ("nope:x=1", "piezo_heat:watts=1", "piezo_heat:power=lots", "joint_resistance=0",
                "ambient_drift=nan"):
        with pytest.raises(InputError):
            parse_effect(bad)
    table = effects_table({"piezo_heat": 1.5, "ambient_drift": -0.25})
    assert table == {"piezo_heat": {"power": 1.5}, "ambient_drift": {"rate": -0.25}}
    assert effects_from_table(table) == {"piezo_heat": 1.5, "ambient_drift": -0.25}
    for bad in ({"nope": {"x": 1}}, {"piezo_heat": {"watts": 1}}, {"piezo_heat": 1.5},
                {"piezo_heat": {"power": "high"}}, {"compliant_base": {"stiffness": -1e9}}):
        with pytest.raises(InputError):
            effects_from_table(bad)


def test_model_file_effects_section():
    cfg = parse_config({"effects": {"joint_compliance": {"stiffness": 2e11}}})
    assert cfg.effects == {"joint_compliance": 2e11}
    with pytest.raises(InputError, match="effects.nope"):
        parse_config({"effects": {"nope": {"x": 1.0}}})


def test_first_order_lag_exact_for_a_ramp():
    t = np.linspace(0.0, 600.0, 11)
    tau = 45.0
    y = first_order_lag(t, 0.01 * t, tau)
    assert np.allclose(y, 0.01 * (t - tau * (1 - np.exp(-t / tau))), rtol=0, atol=1e-12)


def test_observation_and_drive_effects():
    t = np.array([0.0, 60.0, 120.0])
    cols = {"time_s": t, "delta_um": np.array([0.0, 1.0, 2.0]), "T_base_degC": np.array([20.0, 21.0, 23.0]),
            "theta_A_degC": np.array([20.0, 25.0, 25.0]), "T_tank_oil_degC": np.array([20.0, 40.0, 40.0])}
    out = ActiveEffects({"stand_drift": 1.5, "thermocouple_lag": 60.0}).observe(cols)
    assert np.allclose(out["delta_um"], [0.0, 2.5, 6.5])
    assert out["T_tank_oil_degC"] is cols["T_tank_oil_degC"]  # the tank oil is not a thermocouple
    assert 20.0 < out["theta_A_degC"][1] < 25.0
    drive = condition_drive(CONDITIONS[1], load_config().supply)
    _, d2 = apply_effects(ModelConfig(), drive, ActiveEffects({"ambient_drift": 0.6}))
    assert d2(7200.0)[AMBIENT] == pytest.approx(drive(7200.0)[AMBIENT] + 1.2, abs=1e-12)
    assert set(d2(0.0)) == set(drive(0.0))


def test_model_effects_map_to_model_fields(frame_2d):
    cfg = FIXED_MODEL
    eff = ActiveEffects({"joint_resistance": 500.0, "joint_compliance": 2e11, "compliant_base": 1e10,
                         "base_conduction": 100.0, "piezo_heat": 2.0})
    m, _ = apply_effects(cfg, condition_drive(CONDITIONS[1], load_config().supply), eff)
    assert (m.joint_conductance, m.joint_stiffness, m.k_base, m.thermal.h_base) == (500.0, 2e11, 1e10, 100.0)
    assert m.power == {"arm_R": 2.0}
    mesh = to_skfem(frame_2d)
    problem = frame_problem(m, frame_2d)
    f = region_fields(problem, mesh)
    src, = problem.sources  # 2 W over the arm's volume (0.19 x 0.06 x depth 0.12 m³ on the FIXED frame)
    assert src.region == "arm_R" and src.density() == pytest.approx(2.0 / (0.19 * 0.06 * 0.12), rel=1e-12)
    L, E, k = cfg.frame.joint_layer, cfg.material.E, cfg.material.k
    joint = mesh.subdomains["tie_joint_L"]
    assert np.allclose(f["E"].values[joint], L / (L / E + 1 / 2e11))
    assert np.allclose(f["k"].values[joint], L / (L / k + 1 / 500.0))
    assert np.allclose(f["E"].values[mesh.subdomains["tie_bar"]], E)


def _ends(name):
    e = CATALOGUE[name]
    return (0.2 * e.hi, e.hi) if not e.log_scale else (e.lo, e.hi)


def _detectability(conditions):
    """Max |change| of θ_A/θ_B/θ_C (K) and held-out RMS change of δ (µm) per effect and range end."""
    base_cfg = dataclasses.replace(load_config().model, mesh=COARSE)
    supply = load_config().supply
    times = sample_times(5 * 3600.0)
    held = times > 3 * 3600.0
    model0 = build_model(base_cfg, 2)
    out = {}
    for c in conditions:
        drive = condition_drive(CONDITIONS[c], supply)
        base = run_model(model0, drive, times).columns
        for name in CATALOGUE:
            for v in _ends(name):
                eff = ActiveEffects({name: v})
                mcfg, drv = apply_effects(base_cfg, drive, eff)
                model = model0 if mcfg == base_cfg else build_model(mcfg, 2, model0.fmesh)
                cols = eff.observe(run_model(model, drv, times).columns)
                dT = max(np.abs(cols[k] - base[k]).max() for k in ("theta_A_degC", "theta_B_degC", "theta_C_degC"))
                dd = float(np.sqrt(np.mean((cols["delta_um"] - base["delta_um"])[held] ** 2)))
                out[(c, name, v)] = (dT, dd)
    return out


def _check(found):
    weak = {k: v for k, v in found.items() if not (v[0] > 0.3 or v[1] > 0.4)}
    assert not weak, f"effects within a few resolutions at a range end: {weak}"


def test_effects_above_resolution_condition_1():
    _check(_detectability((1,)))


@pytest.mark.slow
def test_effects_above_resolution_conditions_2_3():
    _check(_detectability((2, 3)))
