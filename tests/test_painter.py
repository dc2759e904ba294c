"""The painter: pictures drawn in processes of their own are the pictures drawn in turn, its
failures reach the caller, and it stops with the caller's block.

The painter forks only where no other thread runs (a sweep earlier in the session leaves its
pool's), so each check runs in a new interpreter."""
from __future__ import annotations

import json
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

import gatetherm as gt
from gatetherm.validation.plots.run import plot_channels

PRELUDE = f"""
import json, os, sys, time
sys.path.insert(0, {str(Path(__file__).parent)!r})
import numpy as np
import gatetherm as gt
from gatetherm.validation.plots.run import plot_channels
"""


def fresh(body: str, **values) -> dict:
    """What ``body`` (with ``values`` formatted in) prints as JSON, run in a new interpreter."""
    code = PRELUDE + textwrap.dedent(body).format(**{k: repr(v) for k, v in values.items()})
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=600)
    assert done.returncode == 0 and done.stderr == "", done.stderr  # quiet, whatever befell the pictures
    return json.loads(done.stdout.splitlines()[-1])


def test_a_run_written_with_a_painter_has_the_pictures_drawn_in_turn(tmp_path):
    out = fresh("""
        from conftest import fixed_condition
        case, schedule = fixed_condition(30)
        with gt.plot.Painter(2) as painter:  # before the run, as the command line makes it
            workers = painter.workers
            res = gt.run(case, schedule)
            res.write({painted}, painter=painter)
        res.write({here})
        print(json.dumps({{"workers": workers}}))
        """, painted=str(tmp_path / "painted"), here=str(tmp_path / "here"))
    assert out == {"workers": 2}
    names = sorted(p.name for p in (tmp_path / "here").glob("*.png"))
    assert names == ["channels.png", "deformed.png", "oil_temperatures.png", "response.png"]
    for name in names:
        assert (tmp_path / "painted" / name).read_bytes() == (tmp_path / "here" / name).read_bytes(), name


def test_a_failed_picture_is_raised_by_finish_naming_it(tmp_path):
    out = fresh("""
        def broken(cols):
            raise ValueError(f"no column {{sorted(cols)[0]!r}}")

        cols = {{"time_s": np.array([0.0, 60.0]), "a_degC": np.array([20.0, 21.0])}}
        with gt.plot.Painter(2) as painter:
            workers = painter.workers
            painter.draw(plot_channels, cols, path=os.path.join({tmp}, "fine.png"))
            painter.draw(broken, cols, path=os.path.join({tmp}, "broken.png"))
            try:
                painter.finish()
            except RuntimeError as err:
                print(json.dumps({{"workers": workers, "error": str(err)}}))
        """, tmp=str(tmp_path))
    assert out == {"workers": 2, "error": "broken.png: ValueError: no column 'a_degC'"}
    assert [p.name for p in tmp_path.iterdir()] == ["fine.png"]  # no temporary left


def test_a_picture_of_more_than_the_pipe_holds_is_drawn_while_the_caller_works(tmp_path):
    """``draw`` returns with megabytes not yet in the pipe (a thread writes them as the process
    reads), and the PNG appears while the caller works, before ``finish``: no wall-clock margin
    (a busy machine only makes the wait longer; the 300-s guard is for a hang)."""
    out = fresh("""
        def with_mesh(cols, mesh):  # a deformed picture's arguments: a mesh of some MB
            return plot_channels(cols, f"{{len(mesh)}} nodes")

        t = np.arange(1000.0)
        cols = {{"time_s": t, **{{f"T{{k}}_degC": np.sin(k * t) for k in range(19)}}}}
        mesh, big = np.zeros((400_000, 3)), os.path.join({tmp}, "big.png")
        with gt.plot.Painter(2) as painter:
            workers = painter.workers
            painter.draw(with_mesh, cols, mesh, path=big)
            left = sum(len(box) for box in painter._outbox)  # not yet taken by the pipe when draw returned
            deadline = time.monotonic() + 300
            while not os.path.exists(big) and time.monotonic() < deadline:  # the caller's work
                time.sleep(0.05)
            drawn = os.path.exists(big)
            painter.finish()
        print(json.dumps({{"workers": workers, "left_MB": left / 1e6, "drawn_before_finish": drawn}}))
        """, tmp=str(tmp_path))
    assert out["workers"] == 2 and out["drawn_before_finish"]
    assert out["left_MB"] > 5.0  # 10.6 MB given: far more than a pipe takes
    assert (tmp_path / "big.png").stat().st_size > 10_000


def test_closed_without_finish_it_draws_what_it_was_given(tmp_path):
    out = fresh("""
        def with_mesh(cols, mesh):
            return plot_channels(cols, f"{{len(mesh)}} nodes")

        cols = {{"time_s": np.array([0.0, 60.0]), "a_degC": np.array([20.0, 21.0])}}
        with gt.plot.Painter(2) as painter:
            workers = painter.workers
            painter.draw(with_mesh, cols, np.zeros((400_000, 3)), path=os.path.join({tmp}, "big.png"))
            painter.draw(plot_channels, cols, path=os.path.join({tmp}, "small.png"))
        print(json.dumps({{"workers": workers}}))
        """, tmp=str(tmp_path))
    assert out == {"workers": 2}
    assert sorted(p.name for p in tmp_path.iterdir()) == ["big.png", "small.png"]


@pytest.mark.parametrize("stop_s", [None, 1e-9], ids=["terminated", "killed"])
def test_an_error_in_the_block_stops_the_processes_at_once(tmp_path, stop_s):
    """Stopped by SIGTERM the process removes its PNG's temporary; killed (a rendering that does
    not return to Python within ``STOP_S``: forced here by ``STOP_S = 0``) the painter does."""
    out = fresh("""
        import gatetherm.validation.plots.painter as painting
        painting.STOP_S = {stop_s} or painting.STOP_S
        t = np.arange(60000.0)
        cols = {{"time_s": t, **{{f"T{{k}}_degC": np.sin(k * t) for k in range(19)}}}}  # ~30 s to draw
        try:
            with gt.plot.Painter(2) as painter:
                workers = painter.workers
                painter.draw(plot_channels, cols, path=os.path.join({tmp}, "slow.png"))
                time.sleep(2.0)  # matplotlib imported (about 1 s): the picture is being drawn
                t0 = time.perf_counter()
                raise KeyError("the run failed")
        except KeyError:
            stopped = time.perf_counter() - t0
        try:
            os.waitpid(-1, os.WNOHANG)
            left = True
        except ChildProcessError:  # none left running or unreaped
            left = False
        print(json.dumps({{"workers": workers, "stopped_s": stopped, "left": left}}))
        """, tmp=str(tmp_path), stop_s=stop_s)
    assert out["workers"] == 2 and not out["left"]
    assert out["stopped_s"] < 10.0  # achieved <1 s alone; without SIGTERM, the 30 s of the picture
    assert list(tmp_path.iterdir()) == []  # the PNG being written removed


def test_painter_0_draws_at_once(tmp_path):
    painter = gt.plot.Painter(0)
    painter.draw(plot_channels, {"time_s": np.array([0.0, 60.0]), "a_um": np.array([0.0, 1.0])}, "t",
                 path=tmp_path / "c.png")
    assert painter.workers == 0 and (tmp_path / "c.png").stat().st_size > 10_000


def test_prepare_runs_in_the_process_that_draws_the_picture_needing_it(tmp_path):
    """``prepare(work)`` is called by a painting process before the pictures given after it, and
    answers nothing; a failing one does not stop the picture; the same work is handed once. The
    picture drawn with ``needs=work`` goes to that process, others given meanwhile to the other
    one (the work counts as a picture). ``Painter(0)`` ignores it."""
    out = fresh("""
        def ready(path):
            with open(path, "w") as f:
                f.write(str(os.getpid()))

        def failing():
            raise RuntimeError("not ready")

        def drawn_by(cols, path):
            ready(path)
            return plot_channels(cols)

        def mark():
            with open(os.path.join({tmp}, "marks"), "a") as f:
                f.write("x")

        cols = {{"time_s": np.array([0.0, 60.0]), "a_degC": np.array([20.0, 21.0])}}
        with gt.plot.Painter(2) as painter:
            import functools
            painter.prepare(failing)
            painter.prepare(mark)
            painter.prepare(mark)
            painter.prepare(functools.partial(ready, os.path.join({tmp}, "ready")))
            painter.draw(plot_channels, cols, path=os.path.join({tmp}, "first.png"))
            painter.draw(plot_channels, cols, path=os.path.join({tmp}, "second.png"))
            painter.finish()
        with gt.plot.Painter(2) as painter:
            work = functools.partial(ready, os.path.join({tmp}, "renderer"))
            painter.prepare(work)
            painter.draw(drawn_by, cols, os.path.join({tmp}, "other"), path=os.path.join({tmp}, "third.png"))
            painter.draw(drawn_by, cols, os.path.join({tmp}, "needing"), path=os.path.join({tmp}, "fourth.png"),
                         needs=work)
            painter.finish()
        with gt.plot.Painter(0) as here:
            here.prepare(functools.partial(ready, os.path.join({tmp}, "here")))
        print(json.dumps({{"caller": os.getpid(), "ready": int(open(os.path.join({tmp}, "ready")).read()),
                           "renderer_s": os.path.getmtime(os.path.join({tmp}, "renderer")),
                           "fourth_s": os.path.getmtime(os.path.join({tmp}, "fourth.png")),
                           "marks": open(os.path.join({tmp}, "marks")).read(),
                           "renderer": int(open(os.path.join({tmp}, "renderer")).read()),
                           "needing": int(open(os.path.join({tmp}, "needing")).read()),
                           "other": int(open(os.path.join({tmp}, "other")).read())}}))
        """, tmp=str(tmp_path))
    assert out["ready"] != out["caller"] and out["marks"] == "x"
    assert out["needing"] == out["renderer"] != out["other"] and out["renderer_s"] <= out["fourth_s"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["first.png", "fourth.png", "marks", "needing", "other",
                                                          "ready", "renderer", "second.png", "third.png"]  # no "here"


def test_a_process_ended_inside_an_import_is_stopped_not_failed():
    """SIGTERM (SystemExit) while matplotlib's C extension was being imported came out as
    "ImportError: initialization failed" and was logged as a failure with its traceback, on the
    stderr of a command refused within its first second (the audit's STEP file of 2000 solids)."""
    from gatetherm.validation.plots.painter import _stopped

    def wrapped():
        try:
            try:
                raise SystemExit(1)
            except SystemExit as stop:
                raise ImportError("initialization failed") from stop
        except ImportError as err:
            return err

    assert _stopped(wrapped()) and _stopped(SystemExit(1))
    assert not _stopped(ImportError("initialization failed"))
    assert not _stopped(RuntimeError("a picture failed"))
