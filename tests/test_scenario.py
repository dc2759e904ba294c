"""The one scenario path: effects of a model file act the same in every command; a mesh
and a configuration that disagree are refused; the model cache reuses what it may."""
from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest

from conftest import COARSE, FIXED, FIXED_MODEL, fixed_condition
from gatetherm import InputError
from gatetherm.frame.problem import build_model
from gatetherm.cli import main
from gatetherm.frame.config import config_toml, load_config
from gatetherm.frame.case import gate_frame
from gatetherm.studies.run.scenario import ScenarioCache, run_scenario

EFFECT = {"compliant_base": 3e10}


@pytest.fixture(scope="module")
def model_toml(tmp_path_factory):
    """The paper model on a coarse mesh with ``compliant_base`` switched on in ``[effects]``."""
    cfg = load_config()
    cfg = dataclasses.replace(cfg, model=dataclasses.replace(cfg.model, mesh=dataclasses.replace(
        cfg.model.mesh, size=0.016)), effects=EFFECT)
    path = tmp_path_factory.mktemp("m") / "M.toml"
    path.write_text(config_toml(cfg, "test: compliant base"), encoding="utf-8")
    return path


def test_simulate_and_compensate_see_the_model_files_effect(model_toml, tmp_path, capsys):
    assert main(["simulate", "--condition", "1", "--config", str(model_toml), "--out", str(tmp_path / "a"),
                 "--no-pictures", "--fields-every", "300"]) == 0
    assert main(["compensate", "--condition", "1", "--config", str(model_toml), "--out", str(tmp_path / "b"),
                 "--no-actuator"]) == 0
    a = json.loads((tmp_path / "a" / "summary.json").read_text())
    b = json.loads((tmp_path / "b" / "summary.json").read_text())
    assert a["effects"] == EFFECT
    assert b["swing_um"] == pytest.approx(a["swing_um"], rel=1e-6)
    # and the effect matters: without it the swing differs by far more than that
    base = run_scenario(gate_frame(2, dataclasses.replace(load_config(model_toml), effects={})))
    assert abs(np.ptp(base.columns["delta_um"]) - a["swing_um"]) > 1.0


def test_effects_of_the_file_and_of_the_caller_add_up():
    cfg, sched = fixed_condition(30, condition=2)
    cfg = dataclasses.replace(cfg, effects={"joint_resistance": 400.0})
    both = run_scenario(cfg, sched, {"stand_drift": 1.5})
    assert both.effects.values == {"joint_resistance": 400.0, "stand_drift": 1.5}
    explicit = run_scenario(dataclasses.replace(cfg, effects={}), sched,
                            {"joint_resistance": 400.0, "stand_drift": 1.5})
    np.testing.assert_array_equal(both.columns["delta_um"], explicit.columns["delta_um"])
    # the observation-side effect acts on what the sensors report, not on the model's own run
    assert not np.array_equal(both.columns["delta_um"], both.result.columns["delta_um"])


def test_cache_reuses_the_model_and_the_run():
    cfg, sched = fixed_condition(10)
    cache = ScenarioCache()
    a = run_scenario(cfg, sched, cache=cache)
    b = run_scenario(cfg, sched, {"thermocouple_lag": 60.0}, cache=cache)  # observation only: no rerun
    assert cache.runs == 1 and a.model is b.model
    run_scenario(cfg, sched, {"ambient_drift": 0.5}, cache=cache)  # the room changes: a new run
    assert cache.runs == 2


def test_a_mesh_of_another_frame_is_refused(frame_2d):
    with pytest.raises(InputError, match=r"^geometry\.A_C: the mesh was built with 0\.0024"):
        build_model(dataclasses.replace(FIXED_MODEL, frame=dataclasses.replace(FIXED, A_C=5.9e-4)), 2, frame_2d)
    build_model(dataclasses.replace(FIXED_MODEL, frame=dataclasses.replace(FIXED, l1=0.2)), 2, frame_2d)  # theory only


def test_a_mesh_read_from_a_file_is_checked_by_its_regions(frame_2d, tmp_path):
    from gatetherm.geometry.mesh import load_mesh, save_mesh

    save_mesh(frame_2d, tmp_path / "m.msh")
    loaded = load_mesh(tmp_path / "m.msh")
    assert not loaded.meta
    build_model(FIXED_MODEL, 2, loaded)
    wider = dataclasses.replace(FIXED_MODEL, frame=dataclasses.replace(FIXED, tank_width=0.03))
    with pytest.raises(InputError, match=r"^mesh region tank_wall: spans"):
        build_model(wider, 2, loaded)
    with pytest.raises(InputError, match=r"^--dim"):
        build_model(dataclasses.replace(FIXED_MODEL, mesh=COARSE), 3, loaded)
