"""The sweep engine: study files, derived parameters, point keys, resumable and parallel runs."""
from __future__ import annotations

import csv
import dataclasses
import json
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

import gatetherm

from gatetherm import InputError
from gatetherm.frame import beam
from gatetherm.studies.sweeps import evaluate as sweep_evaluate, sweep
from gatetherm.cli import main
from gatetherm.studies.sweeps import runner as sweep_runner
from gatetherm.studies.sweeps.studyfile import parse_study
from gatetherm.frame import sweeppoint
from gatetherm.frame.config import parse_config

#: A fully specified frame (independent of the shipped paper model, which is recalibrated).
MODEL = {
    "geometry": dict(h=0.1, depth=0.12, column_height=0.63, l=0.6, l1=0.3, l4=0.3, l_C=0.4, A_C=1e-3,
                     t_C=0.04, arm_thickness=0.06, arm_depth=0.06, gap=0.02, tank_wall=0.01,
                     tank_width=0.03, tank_bottom=0.02, tank_height=0.2, tank_depth=0.08,
                     sensor_height=0.1),
    "mesh": {"size": 0.03},
    "material": dict(E=1.2e11, nu=0.26, alpha=1.05e-5, k=48.0, rho=7250.0, c=510.0),
}
BASE = parse_config(MODEL, "test model")
STUDY = """
[study]
name = "tiny"
config = "model.toml"
compute = ["coefficients"]
[set]
"derived.l1_over_l" = 0.5
[grid]
"derived.l_over_l4" = [0.6, 1.0, 2.0, 3.0]
"derived.beta" = [0.1]
[[plot]]
x = "derived.l_over_l4"
y = "Ki_norm_fe"
"""
#: K_i, K_C at E (um/K) of the tiny study's buildable points, measured with this code (P1, 3 cm mesh).
TINY_KI_KC = {0.6: (2.05574, 1.91121), 2.0: (5.64679, 7.46467), 3.0: (10.15041, 7.35936)}


def _toml(d: dict) -> str:
    return "\n".join(f"[{sec}]\n" + "\n".join(f"{k} = {v!r}" for k, v in tab.items()) for sec, tab in d.items())


@pytest.fixture
def study_dir(tmp_path):
    (tmp_path / "model.toml").write_text(_toml(MODEL))
    (tmp_path / "study.toml").write_text(STUDY)
    return tmp_path


def _stored(out: Path) -> list[Path]:
    return sorted((out / "points").glob("[!.]*.json"))


def _table(path: Path) -> list[dict]:
    with open(path, newline="") as fh:
        return list(csv.DictReader(fh))


@pytest.mark.parametrize("data, key", [
    ({"grid": {"geometry.l4": [0.2]}, "bogus": {}}, "bogus"),
    ({"study": {"dimm": 2}, "grid": {"geometry.l4": [0.2]}}, "study.dimm"),
    ({"study": {"dim": 4}, "grid": {"geometry.l4": [0.2]}}, "study.dim"),
    ({"study": {"compute": ["magic"]}, "grid": {"geometry.l4": [0.2]}}, "study.compute"),
    ({"grid": {"geometry.l4": 0.2}}, "grid.geometry.l4"),
    ({"grid": {"geometry.l4": []}}, "grid.geometry.l4"),
    ({"grid": {}}, "grid"),
    ({"set": {"geometry.l4": 0.3}, "grid": {"geometry.l4": [0.2]}}, "set.geometry.l4"),
    ({"grid": {"geometry.l4": [0.2]}, "plot": [{"x": "geometry.l4", "y": "nope"}]}, "plot[1].y"),
    ({"grid": {"geometry.l4": [[0.2]]}}, "grid.geometry.l4"),
])
def test_bad_study_files_raise_one_line_naming_the_key(data, key):
    with pytest.raises(InputError) as err:
        parse_study(data, "s.toml", BASE, frame=sweeppoint.FRAME)
    assert str(err.value).startswith(f"{key}:") and "\n" not in str(err.value)


@pytest.mark.parametrize("grid, key", [
    ({"geometry.l44": [0.2]}, "geometry.l44"),
    ({"geometry.l4": ["high"]}, "geometry.l4"),
    ({"derived.gamma": [1.0]}, "derived.gamma"),
    ({"derived.beta": [-1.0]}, "derived.beta"),
    ({"mesh.sise": [0.1]}, "mesh.sise"),
    ({"thermal.h_air": [True]}, "thermal.h_air"),
    ({"effect.magic": [1.0]}, "effect.magic"),
    ({"speed": [1.0]}, "speed"),
    ({"condition": [7]}, "condition"),
])
def test_bad_parameters_are_caught_before_any_point_runs(grid, key):
    study = parse_study({"grid": grid}, "s.toml", BASE, frame=sweeppoint.FRAME)
    with pytest.raises(InputError) as err:
        sweep.plan(study)
    assert str(err.value).startswith(f"{key}:") and "\n" not in str(err.value)


def test_run_needs_a_condition():
    study = parse_study({"study": {"compute": ["run"]}, "grid": {"geometry.l4": [0.2]}}, "s.toml", BASE, frame=sweeppoint.FRAME)
    with pytest.raises(InputError, match="^condition:"):
        sweep.plan(study)


def test_derived_parameters_follow_their_definitions():
    cfg, _, _, skip = sweeppoint.configure(BASE, {"derived.l_over_h": 8.0, "derived.l1_over_l": 0.5,
                                             "derived.l_over_l4": 2.5, "derived.beta": 0.03}, 2)
    p = cfg.model.frame
    assert skip == ""
    assert p.h == pytest.approx(0.6 / 8.0, rel=1e-15) and p.l1 == 0.3 and p.l4 == pytest.approx(0.24, rel=1e-15)
    assert p.tank_wall / p.h == pytest.approx(0.1, rel=1e-14) and p.tank_width / p.h == pytest.approx(0.3, rel=1e-14)
    assert float(beam.beta(p.depth * p.h ** 3 / 12, p.l_C, p.A_C, p.l)) == pytest.approx(0.03, rel=1e-14)
    cfg, *_ = sweeppoint.configure(BASE, {"derived.tank_cavity": False}, 2)
    assert cfg.model.frame.tank_width == cfg.model.frame.tank_height == sweeppoint.PINHOLE
    assert cfg.model.frame.tank_wall + sweeppoint.PINHOLE / 2 == pytest.approx(cfg.model.frame.h / 2)


def test_frame_is_fitted_to_the_tie_bars():
    cfg, _, _, skip = sweeppoint.configure(BASE, {"geometry.l4": 0.9}, 2)
    assert skip == "" and cfg.model.frame.column_height == pytest.approx(0.92)
    _, _, _, skip = sweeppoint.configure(BASE, {"geometry.l4": 0.9}, 2, fit=False)
    assert skip.startswith("l4:")
    _, _, _, skip = sweeppoint.configure(BASE, {"geometry.l4": 0.6}, 2)
    assert "overlaps the arms" in skip
    cfg, _, _, skip = sweeppoint.configure(BASE, {"geometry.l4": 0.6, "geometry.A_C": 6e-3}, 3)
    assert skip == "" and cfg.model.frame.A_C / cfg.model.frame.t_C <= 0.06 < 6e-3 / 0.04


def test_point_key_is_the_final_model():
    same = sweeppoint.configure(BASE, {"derived.l_over_l4": 2.0}, 2)[0]
    direct = sweeppoint.configure(BASE, {"geometry.l4": BASE.model.frame.l / 2.0}, 2)[0]
    assert sweeppoint.point_key(same, 2, ("coefficients",), None, ()) == \
        sweeppoint.point_key(direct, 2, ("coefficients",), None, ())
    warmer = dataclasses.replace(direct, model=dataclasses.replace(
        direct.model, thermal=dataclasses.replace(direct.model.thermal, h_air=20.0)))
    for compute, differs in ((("coefficients",), False), (("run",), True)):
        keys = {sweeppoint.point_key(c, 2, compute, 1, ()) for c in (direct, warmer)}
        assert (len(keys) == 2) is differs
    assert sweeppoint.point_key(direct, 3, ("coefficients",), None, ()) != sweeppoint.point_key(direct, 2, ("coefficients",), None, ())


def test_sweep_writes_one_row_per_point_and_resumes(study_dir, monkeypatch, capsys):
    out = study_dir / "out"
    assert main(["sweep", str(study_dir / "study.toml"), "--out", str(out), "--workers", "1"]) == 0
    printed = capsys.readouterr().out
    assert f"wrote {out / 'Ki_norm_fe_vs_derived.l_over_l4.png'}\n" in printed and ".gatetherm-tmp" not in printed, printed
    rows = _table(out / "table.csv")
    assert list(rows[0])[:4] == ["derived.l_over_l4", "derived.beta", "status", "note"]
    assert [r["status"] for r in rows] == ["ok", "skipped", "ok", "ok"]
    assert "overlaps the arms" in rows[1]["note"]
    for r in rows:
        if r["status"] == "ok":
            ki, kc = TINY_KI_KC[float(r["derived.l_over_l4"])]
            assert float(r["Ki_E_fe"]) == pytest.approx(ki, rel=2e-3)
            assert float(r["Kc_E_fe"]) == pytest.approx(kc, rel=2e-3)
            assert float(r["beta"]) == pytest.approx(0.1, rel=1e-12)
            assert float(r["Ki_norm_theory"]) == pytest.approx(
                float(beam.normalised(float(r["derived.l_over_l4"]), 0.1)[0]), rel=1e-12)
    assert (out / "Ki_norm_fe_vs_derived.l_over_l4.png").stat().st_size > 1000
    first = (out / "table.csv").read_text()
    points = _stored(out)
    assert len(points) == 4
    points[0].unlink()
    calls = []
    real = sweep_evaluate.evaluate
    monkeypatch.setattr(sweep_evaluate, "evaluate", lambda t: calls.append(t.key) or real(t))
    assert main(["sweep", str(study_dir / "study.toml"), "--out", str(out), "--workers", "1"]) == 0
    assert calls == [points[0].stem]
    assert (out / "table.csv").read_text() == first


def _recomputed(study_dir, monkeypatch, out) -> list[str]:
    calls = []
    real = sweep_evaluate.evaluate
    monkeypatch.setattr(sweep_evaluate, "evaluate", lambda t: calls.append(t.key) or real(t))
    assert main(["sweep", str(study_dir / "study.toml"), "--out", str(out), "--workers", "1", "--no-plots"]) == 0
    monkeypatch.setattr(sweep_evaluate, "evaluate", real)
    return calls


def test_a_new_scheme_or_version_recomputes_the_points(study_dir, monkeypatch):
    """Points made with one time scheme or gatetherm version are not reused by another:
    the key holds both, and the table says which made each row."""
    out = study_dir / "out"
    study = study_dir / "study.toml"
    study.write_text(STUDY.replace('compute = ["coefficients"]', 'compute = ["run"]')
                     .replace('"derived.l_over_l4" = [0.6, 1.0, 2.0, 3.0]', '"derived.l_over_l4" = [2.0]')
                     .replace("[set]", "[set]\ncondition = 1").replace('y = "Ki_norm_fe"', 'y = "swing_um"'))
    assert len(_recomputed(study_dir, monkeypatch, out)) == 1
    assert _recomputed(study_dir, monkeypatch, out) == []  # nothing changed: nothing recomputed
    before = _table(out / "table.csv")[0]
    assert before["version"] == gatetherm.__version__ and len(before["scheme"]) == 8
    model = study_dir / "model.toml"
    model.write_text(model.read_text() + "\n[model.scheme]\ntheta = 1.0\nrestart = 1\n")
    assert len(_recomputed(study_dir, monkeypatch, out)) == 1
    after = _table(out / "table.csv")[0]
    assert after["scheme"] != before["scheme"] and after["swing_um"] != before["swing_um"]
    monkeypatch.setattr(gatetherm, "__version__", "99.0")
    assert len(_recomputed(study_dir, monkeypatch, out)) == 1
    assert _table(out / "table.csv")[0]["version"] == "99.0"


def test_process_pool_gives_the_same_table(study_dir):
    assert main(["sweep", str(study_dir / "study.toml"), "--out", str(study_dir / "a"), "--workers", "1",
                 "--no-plots"]) == 0
    assert main(["sweep", str(study_dir / "study.toml"), "--out", str(study_dir / "b"), "--workers", "2",
                 "--no-plots"]) == 0
    assert (study_dir / "a" / "table.csv").read_text() == (study_dir / "b" / "table.csv").read_text()


def test_dask_cluster_on_loopback(study_dir):
    distributed = pytest.importorskip("distributed")
    assert main(["sweep", str(study_dir / "study.toml"), "--out", str(study_dir / "a"), "--workers", "1",
                 "--no-plots"]) == 0
    with distributed.LocalCluster(n_workers=1, threads_per_worker=2, processes=False, host="127.0.0.1",
                                  protocol="tcp://", dashboard_address=None) as cluster:
        assert main(["sweep", str(study_dir / "study.toml"), "--out", str(study_dir / "d"),
                     "--scheduler", cluster.scheduler_address, "--no-plots"]) == 0
    assert (study_dir / "a" / "table.csv").read_text() == (study_dir / "d" / "table.csv").read_text()


def test_unreachable_scheduler_is_an_input_error(study_dir, capsys, monkeypatch):
    pytest.importorskip("distributed")
    monkeypatch.setattr(sweep_runner, "SCHEDULER_TIMEOUT_S", 1.0)
    code = main(["sweep", str(study_dir / "study.toml"), "--out", str(study_dir / "x"),
                 "--scheduler", "tcp://127.0.0.1:9", "--no-plots"])
    assert code == 2 and capsys.readouterr().err.startswith("gatetherm: error: --scheduler:")


def test_killed_sweep_restarts_to_the_same_table(study_dir):
    """Kill a 2-worker sweep (SIGKILL) once two points are stored: its workers die with it;
    restart it, compare with a clean run."""
    from test_faults import alive, children, group

    study = study_dir / "study.toml"
    study.write_text(STUDY.replace('"derived.beta" = [0.1]', '"derived.beta" = [0.03, 0.3]'))
    out = study_dir / "killed"
    cmd = [sys.executable, "-m", "gatetherm.cli", "sweep", str(study), "--out", str(out), "--workers", "2",
           "--no-plots"]
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)
    deadline = time.monotonic() + 60
    while len(_stored(out)) < 2 and time.monotonic() < deadline and proc.poll() is None:
        time.sleep(0.01)
    workers = children(proc.pid)
    proc.send_signal(signal.SIGKILL)
    proc.wait()
    deadline = time.monotonic() + 10
    while (any(map(alive, workers)) or group(proc.pid)) and time.monotonic() < deadline:
        time.sleep(0.01)  # the workers, and gmsh's processes they started, die with the sweep
    left = group(proc.pid)
    for pid in left:
        os.kill(pid, signal.SIGKILL)
    assert len(workers) == 2 and not left
    assert 2 <= len(_stored(out)) < 8 and not (out / "table.csv").exists()
    for p in _stored(out):  # every stored result is whole (a stray temporary .name is never read)
        assert json.loads(p.read_text())["key"] == p.stem
    assert subprocess.run(cmd, capture_output=True).returncode == 0
    assert main(["sweep", str(study), "--out", str(study_dir / "clean"), "--workers", "1", "--no-plots"]) == 0
    assert (out / "table.csv").read_text() == (study_dir / "clean" / "table.csv").read_text()
    assert len(_stored(out)) == 8


@pytest.mark.parametrize("address, needle", [
    ("bogus://nowhere", "'bogus://nowhere' is not the address of a Dask scheduler"),
    ("tcp://127.0.0.1:9", "cannot connect to tcp://127.0.0.1:9 (Connection refused)")])
def test_a_refused_scheduler_leaves_no_thread_behind(address, needle):
    """A Dask client that failed to connect left its event-loop thread running: the next sweep in
    the process ran 5 times slower (the third audit: 122 s against 23 s)."""
    import threading

    from gatetherm.studies.sweeps.runner import executor

    before = {t.name for t in threading.enumerate()}
    with pytest.raises(InputError, match=re.escape(needle)):
        with executor(1, address, 3):
            pass
    assert {t.name for t in threading.enumerate()} <= before
