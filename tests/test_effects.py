"""The effects catalogue: entries, parsing, the physics each effect switches on, and that
every effect is clearly above the sensor resolution at both ends of its range."""
from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest

from gatetherm import InputError
from gatetherm.frame.geometry import MeshParams
from gatetherm.geometry.measure import region_volume
from gatetherm.solvers.effects import (KINDS, ActiveEffects, apply_effects, catalogue_json, effects_from_table,
                                       effects_table, first_order_lag, parse_effect, resolve)
from gatetherm.solvers.fem import to_skfem
from gatetherm.frame.problem import EFFECTS, TARGETS, frame_problem
from gatetherm.solvers.model import region_fields
from gatetherm.frame.config import Config, load_config, parse_config
from gatetherm.frame.case import frame_case
from gatetherm.studies.run.scenario import run_scenario
from conftest import FIXED_MODEL, fixed_condition

COARSE = MeshParams(size=0.02)


def test_kinds_and_the_frames_catalogue():
    assert len(KINDS) == 8
    for e in KINDS.values():
        assert e.lo < e.hi and e.unit and e.acts_on in ("model", "observation") and e.doc and e.target
    listed = json.loads(json.dumps(catalogue_json(TARGETS, EFFECTS)))
    assert [d["name"] for d in listed] == list(EFFECTS)
    assert listed[0]["params"] == {"rate": {"unit": "K/h", "range": [-1.0, 1.0]}}
    piezo = resolve("piezo_heat", TARGETS)  # a name the frame declares: a heat source in the arm, its own range
    assert (piezo.effect.name, piezo.target, piezo.lo, piezo.hi) == ("heat_source", "arm_R", 0.5, 5.0)
    assert resolve("compliant_base", TARGETS).target == "mounting_face"
    assert resolve("heat_source@column_L", TARGETS).target == "column_L"


def test_parse_effect_and_table():
    assert parse_effect("piezo_heat:power=1.5", TARGETS) == ("piezo_heat", 1.5)
    assert parse_effect("stand_drift=2") == ("stand_drift", 2.0)
    assert parse_effect("heat_source@spindle:power=40") == ("heat_source@spindle", 40.0)
    for bad in ("nope:x=1", "piezo_heat:watts=1", "piezo_heat:power=lots", "joint_resistance=0",
                "ambient_drift=nan"):
        with pytest.raises(InputError):
            parse_effect(bad, TARGETS)
    with pytest.raises(InputError, match="acts on a region: name it"):
        parse_effect("heat_source:power=1")  # a case without defaults: the target must be named
    table = effects_table({"piezo_heat": 1.5, "ambient_drift": -0.25}, TARGETS)
    assert table == {"piezo_heat": {"power": 1.5}, "ambient_drift": {"rate": -0.25}}
    assert effects_from_table(table, TARGETS) == {"piezo_heat": 1.5, "ambient_drift": -0.25}
    for bad in ({"nope": {"x": 1}}, {"piezo_heat": {"watts": 1}}, {"piezo_heat": 1.5},
                {"piezo_heat": {"power": "high"}}, {"compliant_base": {"stiffness": -1e9}}):
        with pytest.raises(InputError):
            effects_from_table(bad, TARGETS)


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


def test_observation_effects_and_the_drifting_room(frame_2d):
    t = np.array([0.0, 60.0, 120.0])
    cols = {"time_s": t, "delta_um": np.array([0.0, 1.0, 2.0]), "T_base_degC": np.array([20.0, 21.0, 23.0]),
            "theta_A_degC": np.array([20.0, 25.0, 25.0]), "T_tank_oil_degC": np.array([20.0, 40.0, 40.0])}
    problem = frame_problem(FIXED_MODEL, frame_2d)
    out = ActiveEffects({"stand_drift": 1.5, "thermocouple_lag": 60.0}).observe(cols, problem)
    assert np.allclose(out["delta_um"], [0.0, 2.5, 6.5])
    assert out["T_tank_oil_degC"] is cols["T_tank_oil_degC"]  # the tank oil is not a thermocouple
    assert 20.0 < out["theta_A_degC"][1] < 25.0
    drifting = apply_effects(problem, ActiveEffects({"ambient_drift": 0.6}), lambda r: 1.0)
    env = {"t": 7200.0, "ambient_degC": 20.0}
    for v in (*[f.ambient for f in drifting.films], drifting.faces.ambient, drifting.fluids[0].ambient):
        assert v(env) == pytest.approx(21.2, abs=1e-12)  # every ambient of the room, 0.6 K/h for 2 h


def test_model_effects_edit_the_named_parts(frame_2d):
    eff = ActiveEffects({"joint_resistance": 500.0, "joint_compliance": 2e11, "compliant_base": 1e10,
                         "base_conduction": 100.0, "piezo_heat": 2.0}, TARGETS)
    from gatetherm.frame.problem import frame_targets

    eff = dataclasses.replace(eff, targets=frame_targets(FIXED_MODEL, frame_2d.regions))
    problem = apply_effects(frame_problem(FIXED_MODEL, frame_2d), eff, lambda r: region_volume(frame_2d, r, 0.12))
    mesh = to_skfem(frame_2d)
    f = region_fields(problem, mesh)
    src, = problem.sources  # 2 W over the arm's volume (0.19 x 0.06 x depth 0.12 m³ on the FIXED frame)
    assert src.region == "arm_R" and src.density() == pytest.approx(2.0 / (0.19 * 0.06 * 0.12), rel=1e-12)
    cfg = FIXED_MODEL
    L, E, k = cfg.frame.joint_layer, cfg.material.E, cfg.material.k
    joint = mesh.subdomains["tie_joint_L"]
    assert np.allclose(f["E"].values[joint], L / (L / E + 1 / 2e11))
    assert np.allclose(f["k"].values[joint], L / (L / k + 1 / 500.0))
    assert np.allclose(f["E"].values[mesh.subdomains["tie_bar"]], E)
    assert [s.stiffness for s in problem.supports] == [1e10]
    assert [(fl.boundary, fl.h) for fl in problem.films][-1] == ("mounting_face", 100.0)
    with pytest.raises(InputError, match="no region 'spindle'"):
        apply_effects(problem, ActiveEffects({"heat_source@spindle": 1.0}), lambda r: 1.0)


@pytest.mark.parametrize("name, value, changes", [
    ("joint_resistance", 400.0, {"joint_conductance": 400.0}),
    ("joint_compliance", 3e11, {"joint_stiffness": 3e11}),
    ("compliant_base", 2e10, {"k_base": 2e10}),
    ("base_conduction", 120.0, {"thermal": dataclasses.replace(FIXED_MODEL.thermal, h_base=120.0)}),
    ("piezo_heat", 2.0, {"power": {"arm_R": 2.0}})])
def test_the_frames_effects_are_its_parameters_by_name(name, value, changes):
    """A named effect on the frame runs exactly as the frame made with the parameter it stands for."""
    case, sched = fixed_condition(20, condition=2)
    with_effect = run_scenario(case, sched, {name: value}).columns["delta_um"]
    made = frame_case(Config(model=dataclasses.replace(FIXED_MODEL, **changes)), 2, mesh=case.mesh)
    np.testing.assert_array_equal(with_effect, run_scenario(made, sched).columns["delta_um"])


def _ends(name):
    e = resolve(name, TARGETS)
    return (0.2 * e.hi, e.hi) if not e.log_scale else (e.lo, e.hi)


def _detectability(conditions):
    """Max |change| of θ_A/θ_B/θ_C (K) and held-out RMS change of δ (µm) per effect and range end."""
    from gatetherm.frame.conditions import condition_schedule

    cfg = load_config()
    case = frame_case(dataclasses.replace(cfg, model=dataclasses.replace(cfg.model, mesh=COARSE)), 2)
    out = {}
    for c in conditions:
        sched = condition_schedule(c, cfg.supply)
        held = sched.times > 3 * 3600.0
        base = run_scenario(case, sched).columns
        for name in EFFECTS:
            for v in _ends(name):
                cols = run_scenario(case, sched, {name: v}).columns
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
