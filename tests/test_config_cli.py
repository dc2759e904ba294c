"""Model files, the mesh command and the simulate command, end to end."""
import dataclasses
import json

import meshio
import numpy as np
import pytest

from gatetherm.cli import main
from gatetherm.frame.config import Config, load_config, parse_config
from gatetherm import InputError
from gatetherm.studies.run.timeseries import read_timeseries

GROUPS = {"column_L", "column_R", "arm_L", "arm_R", "tie_bar", "tie_joint_L", "tie_joint_R",
          "mounting_face", "tank_wall", "free_surface", "A", "B", "E_L", "E_R", "F_L", "F_R",
          *(f"C{i}" for i in range(1, 11))}
COARSE = "[mesh]\nsize = 0.02\nsize_3d = 0.03\n"


def test_shipped_paper_model_is_the_defaults():
    cfg = load_config()
    assert dataclasses.replace(cfg, source="") == dataclasses.replace(Config(), source="")
    assert cfg.model.frame.l == 0.67 and cfg.model.thermal.h_oil_on == 260.0


def test_user_file_overlays_the_paper_model(tmp_path):
    f = tmp_path / "m.toml"
    f.write_text("[geometry]\nl4 = 0.2\n[thermal]\nh_air = 10\n[model]\norder = 2\n")
    cfg = load_config(f)
    assert cfg.model.frame.l4 == 0.2 and cfg.model.thermal.h_air == 10.0 and cfg.model.order == 2
    assert cfg.model.frame.l == load_config().model.frame.l


@pytest.mark.parametrize("doc, field", [
    ({"geometry": {"foo": 1}}, "geometry.foo"),
    ({"thermal": {"h_air": "high"}}, "thermal.h_air"),
    ({"thermal": {"out_of_plane": 1}}, "thermal.out_of_plane"),
    ({"model": {"order": 3}}, "model.order"),
    ({"geometry": {"l1": 0.9}}, "geometry.l1"),
    ({"colour": {}}, "colour"),
])
def test_bad_model_files_name_the_field(doc, field):
    with pytest.raises(InputError, match=f"^{field}: ") as err:
        parse_config(doc)
    assert "\n" not in str(err.value)


@pytest.mark.parametrize("dim", [2, 3])
def test_mesh_command_writes_readable_meshes(tmp_path, capsys, dim):
    cfg = tmp_path / "coarse.toml"
    cfg.write_text(COARSE)
    assert main(["mesh", "--dim", str(dim), "--config", str(cfg), "--out", str(tmp_path / "d")]) == 0
    out = capsys.readouterr().out
    assert "nodes" in out and "sensors (16)" in out
    msh = meshio.read(tmp_path / "d" / "mesh.msh", file_format="gmsh")
    assert GROUPS <= set(msh.field_data)
    vtu = meshio.read(tmp_path / "d" / "mesh.vtu")
    assert GROUPS <= {k[len("group:"):] for k in vtu.cell_data if k.startswith("group:")}


def test_bad_parameter_is_one_line_exit_2(tmp_path, capsys):
    cfg = tmp_path / "bad.toml"
    cfg.write_text("[geometry]\nl4 = 2.0\n")
    assert main(["mesh", "--dim", "2", "--config", str(cfg), "--out", str(tmp_path / "x")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith(f"gatetherm: error: {cfg}: geometry.l4: ") and "Traceback" not in err
    assert not (tmp_path / "x").exists()


def test_simulate_condition_1_coarse(tmp_path, capsys):
    """Regression values of a coarse 2-D condition-1 run (the default mesh is in docs/validation.md's paper table)."""
    cfg = tmp_path / "coarse.toml"
    cfg.write_text(COARSE)
    out = tmp_path / "c1"
    assert main(["simulate", "--condition", "1", "--config", str(cfg), "--out", str(out),
                 "--no-pictures"]) == 0
    ts = read_timeseries(out / "timeseries.csv")
    assert len(ts) == 301 and ts.time_s[-1] == 18000.0
    assert ts.metadata["condition"] == "1"
    assert {"T_C10_degC", "T_tank_oil_degC", "delta_E_um"} <= set(ts.names)
    s = json.loads((out / "summary.json").read_text())
    assert s["first_peak_um"] == pytest.approx(REGRESSION["first_peak_um"], abs=0.05)
    assert s["first_peak_min"] == REGRESSION["first_peak_min"]
    assert s["swing_um"] == pytest.approx(REGRESSION["swing_um"], abs=0.05)
    fields = sorted((out / "fields").glob("*.vtu"))
    assert len(fields) == 6
    m = meshio.read(fields[1])
    assert m.point_data["T"].max() > 30.0 and np.abs(m.point_data["u"]).max() > 1e-6


REGRESSION = {"first_peak_um": 48.00, "first_peak_min": 13.0, "swing_um": 51.07}  # measured 2026-11-22 (CN, hose)


@pytest.mark.parametrize("argv, needle", [
    (["simulate", "--condition", "4"], "--condition: no condition 4"),
    (["simulate", "--schedule", "SCHED"], "column oil_degC: missing: the case reads it"),
])
def test_simulate_bad_input(tmp_path, capsys, argv, needle):
    sched = tmp_path / "s.csv"
    sched.write_text("# format: gatetherm-timeseries/1\ntime_s,pump\n0,1\n60,1\n")
    argv = [a.replace("SCHED", str(sched)) for a in argv] + ["--out", str(tmp_path / "o")]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and needle in err
    assert not (tmp_path / "o").exists()


def test_simulate_applies_effects_of_the_model_file(tmp_path):
    """A model file written by 'diagnose' switches its effects on in 'simulate'."""
    cfg = tmp_path / "m.toml"
    cfg.write_text(COARSE + "[effects]\nstand_drift = {coefficient = 2.0}\n")
    assert main(["simulate", "--condition", "1", "--config", str(cfg), "--out", str(tmp_path / "e"),
                 "--no-pictures"]) == 0
    s = json.loads((tmp_path / "e" / "summary.json").read_text())
    assert s["effects"] == {"stand_drift": 2.0}
    assert s["first_peak_um"] > REGRESSION["first_peak_um"] + 1.0


def test_a_command_imports_only_its_own_command_module():
    """`gatetherm simulate` builds the parser of simulate alone: the other commands' libraries
    (the error models' scipy.signal, 1.3 s) are not imported; `gatetherm --help` lists all."""
    import subprocess
    import sys

    code = ("import sys; from gatetherm.cli import _command, build_parser; "
            "p = build_parser(_command(['-v', 'simulate', '--condition', '1'])); "
            "print(sorted(m for m in sys.modules if m.startswith('gatetherm.cli.')), 'scipy.signal' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out == "['gatetherm.cli.options', 'gatetherm.cli.simulate'] False\n"
    from gatetherm.cli import COMMAND_MODULES, build_parser

    listed = build_parser()._subparsers._group_actions[0].choices
    assert list(listed) == list(COMMAND_MODULES)


def test_the_program_ends_with_the_commands_code_its_objects_frozen(monkeypatch):
    """``gatetherm`` (:func:`gatetherm.cli.console`) exits with :func:`main`'s code, the
    objects made left out of the interpreter's collections on the way out (``gc.freeze``)."""
    import gc

    import gatetherm.cli as cli

    monkeypatch.setattr(cli, "main", lambda: 3)
    assert gc.get_freeze_count() == 0
    try:
        with pytest.raises(SystemExit) as done:
            cli.console()
        assert done.value.code == 3 and gc.get_freeze_count() > 10_000
    finally:
        gc.unfreeze()
