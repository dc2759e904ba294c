"""Sensor faults: what each does to a signal (exactly), the model file's ``[sensors]``
section, and that the scenario path applies them when it observes a run (no rerun)."""
from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from conftest import fixed_condition
from gatetherm import InputError
from gatetherm.solvers.effects import first_order_lag
from gatetherm.solvers.sensors import apply_fault, apply_faults, compose, faults_from_table, faults_of
from gatetherm.frame.config import config_toml, load_config, parse_config
from gatetherm.studies.run.scenario import ScenarioCache, run_scenario

T = np.arange(0.0, 7200.0 + 1, 60.0)
X = 20.0 + 5.0 * (1 - np.exp(-T / 900.0))


def test_each_fault_exactly():
    assert np.array_equal(apply_fault(T, X, "offset", 0.3), X + 0.3)
    np.testing.assert_allclose(apply_fault(T, X, "gain", 1.04), X[0] + 1.04 * (X - X[0]), rtol=0, atol=1e-12)
    np.testing.assert_allclose(apply_fault(T, X, "drift", 0.5), X + 0.5 * T / 3600.0, rtol=0, atol=1e-12)
    assert np.array_equal(apply_fault(T, X, "lag", 60.0), first_order_lag(T, X, 60.0))
    assert np.array_equal(apply_fault(T, X, "lag", 0.0), X)
    assert set(faults_of("theta_B_degC")) == {"offset", "gain", "lag"}
    assert set(faults_of("delta_um")) == {"offset", "gain", "drift"} and faults_of("pump") == {}


def test_faults_act_in_order_on_their_channel_only():
    cols = {"time_s": T, "theta_A_degC": X, "theta_B_degC": X.copy(), "delta_um": 3 * (X - 20)}
    out = apply_faults(cols, {"theta_B_degC": {"offset": 0.3, "lag": 90.0, "gain": 0.95},
                              "delta_um": {"drift": -0.4}, "T_missing_degC": {"offset": 1.0}})
    lagged = first_order_lag(T, X, 90.0)
    np.testing.assert_allclose(out["theta_B_degC"], lagged[0] + 0.95 * (lagged - lagged[0]) + 0.3, atol=1e-12)
    np.testing.assert_allclose(out["delta_um"], cols["delta_um"] - 0.4 * T / 3600, atol=1e-12)
    assert out["theta_A_degC"] is X and "T_missing_degC" not in out


def test_compose():
    both = compose({"theta_A_degC": {"offset": 0.2, "gain": 1.1}}, {"theta_A_degC": {"offset": 0.1, "gain": 0.9},
                                                                    "delta_um": {"drift": 1.0}})
    assert both["theta_A_degC"] == pytest.approx({"offset": 0.3, "gain": 0.99}) and both["delta_um"] == {"drift": 1.0}
    cols = {"time_s": T, "theta_A_degC": X}
    twice = apply_faults(apply_faults(cols, {"theta_A_degC": {"offset": 0.2, "gain": 1.1}}),
                         {"theta_A_degC": {"offset": 0.1, "gain": 0.9}})
    np.testing.assert_allclose(apply_faults(cols, both)["theta_A_degC"], twice["theta_A_degC"], atol=1e-12)
    with pytest.raises(ValueError):
        compose({"theta_A_degC": {"lag": 30.0}}, {"theta_A_degC": {"lag": 60.0}})


def test_model_file_sensors_section(tmp_path):
    cfg = parse_config({"sensors": {"theta_B_degC": {"offset": 0.3}, "delta_um": {"gain": 1.02, "drift": -0.5}}})
    assert cfg.sensors == {"theta_B_degC": {"offset": 0.3}, "delta_um": {"gain": 1.02, "drift": -0.5}}
    path = tmp_path / "m.toml"
    path.write_text(config_toml(dataclasses.replace(load_config(), sensors=cfg.sensors)), encoding="utf-8")
    assert load_config(path).sensors == cfg.sensors
    for table, field in (({"pump": {"offset": 1}}, "sensors.pump"), ({"delta_um": {"lag": 5.0}}, "sensors.delta_um.lag"),
                         ({"theta_A_degC": {"lag": -5.0}}, "sensors.theta_A_degC.lag"),
                         ({"theta_A_degC": {"offset": True}}, "sensors.theta_A_degC.offset"),
                         ({"theta_A_degC": 0.3}, "sensors.theta_A_degC")):
        with pytest.raises(InputError, match=f"^{field.replace('.', '[.]')}:"):
            faults_from_table(table)


def test_scenario_observes_the_sensor_faults_of_the_model_file():
    cfg, sched = fixed_condition(20)
    cache = ScenarioCache()
    plain = run_scenario(cfg, sched, cache=cache)
    faults = {"theta_B_degC": {"offset": 0.3, "lag": 60.0}, "delta_um": {"gain": 1.05}}
    faulty = run_scenario(dataclasses.replace(cfg, sensors=faults), sched, cache=cache)
    assert cache.runs == 1  # observation only: the kept run is observed again
    expect = apply_faults(plain.columns, faults)
    for c in ("theta_A_degC", "theta_B_degC", "delta_um"):
        np.testing.assert_array_equal(faulty.columns[c], expect[c])
    assert not np.array_equal(faulty.columns["theta_B_degC"], plain.columns["theta_B_degC"])
