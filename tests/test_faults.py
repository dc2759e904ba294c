"""Faults survived (issue 11): Ctrl-C at any moment, kill -9 and SIGTERM of a run and a rerun
into the same directory, Ctrl-C to a sweep's workers, a full disk. In subprocesses: signals
and limits act on whole processes. (The killed 2-worker sweep is in test_sweep.py.)"""
from __future__ import annotations

import os
import resource
import signal
import subprocess
import sys
import time
from pathlib import Path

from gatetherm.cli import main

GATETHERM = [sys.executable, "-m", "gatetherm.cli"]
INTERRUPTED = {130, -signal.SIGINT}
"""Exit statuses of an interrupted command: 130, or death by SIGINT after its line, which a shell
also reports as 130 (Python ends that way when a Ctrl-C passed through code that an extension
module ran while it loaded, even though gatetherm caught it)."""
COARSE = "[mesh]\nsize = 0.02\nsize_3d = 0.03\n"


def foreground() -> None:
    """preexec_fn: SIGINT as a terminal's foreground command has it (a test runner started in
    the background ignores it, and its children inherit that)."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def files(d: Path) -> list[str]:
    return sorted(str(p.relative_to(d)) for p in d.rglob("*") if p.is_file())


def wait_for(condition, proc, seconds: float = 60.0) -> None:
    deadline = time.monotonic() + seconds
    while not condition():
        assert proc.poll() is None, proc.communicate()
        assert time.monotonic() < deadline, "timed out"
        time.sleep(0.005)


def _stat(stat: Path) -> list[str]:
    """State, parent, process group, ... of a /proc/PID/stat file."""
    return stat.read_text().rsplit(")", 1)[1].split()


def _live(field: int, value: int) -> list[int]:
    """Live processes (zombies are dead) whose stat ``field`` (1: parent, 2: group) is ``value``."""
    out = []
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = _stat(stat)
        except OSError:
            continue
        if int(fields[field]) == value and fields[0] not in "ZX":
            out.append(int(stat.parent.name))
    return out


def children(pid: int) -> list[int]:
    return _live(1, pid)


def group(pgid: int) -> list[int]:
    return _live(2, pgid)


def alive(pid: int) -> bool:
    try:
        return _stat(Path(f"/proc/{pid}/stat"))[0] not in "ZX"
    except OSError:
        return False


def test_killed_runs_and_reruns_into_the_same_directory(tmp_path):
    """kill -9 and SIGTERM while a rerun writes its field files (more than the first run wrote,
    into its hidden stage): the first run's files are kept as they were; the next rerun leaves
    exactly its own files (issue 55: the output directory is a transaction)."""
    cfg = tmp_path / "c.toml"
    cfg.write_text(COARSE)
    run = ["simulate", "--condition", "1", "--config", str(cfg), "--no-pictures", "--out"]
    first = {}
    for sig in (signal.SIGKILL, signal.SIGTERM):
        assert main([*run, str(tmp_path / sig.name)]) == 0
        first[sig] = {f: (tmp_path / sig.name / f).read_bytes() for f in files(tmp_path / sig.name)}
    procs = {sig: subprocess.Popen([*GATETHERM, *run, str(tmp_path / sig.name), "--fields-every", "1"],
                                   stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
             for sig in (signal.SIGKILL, signal.SIGTERM)}
    for sig, proc in procs.items():
        out = tmp_path / sig.name
        wait_for(lambda: len(list(out.glob(".gatetherm-tmp.stage.*/fields/fields_*.vtu"))) >= 10, proc)
        proc.send_signal(sig)
    assert procs[signal.SIGKILL].wait() == -signal.SIGKILL and ".gatetherm.lock" in files(tmp_path / "SIGKILL")
    assert (procs[signal.SIGTERM].wait(), procs[signal.SIGTERM].stderr.read()) == (143, "gatetherm: terminated\n")
    rerun = ["fields/fields.h5", "fields/fields.pvd", "fields/fields.xdmf", *(f"fields/fields_{m:04d}min.vtu" for m in range(0, 301, 60)),
             "summary.json", "timeseries.csv"]
    for sig in procs:
        out = tmp_path / sig.name
        kept = {f: (out / f).read_bytes() for f in files(out) if not f.startswith(".gatetherm")}
        assert kept == first[sig], sig.name
        if sig == signal.SIGTERM:
            assert files(out) == rerun
        assert main([*run, str(out)]) == 0
        assert files(out) == rerun, sig.name


def test_ctrl_c_at_any_moment(tmp_path):
    """While the command modules are imported (numpy's extension just loaded), while gmsh
    meshes (its library loaded) and while the model runs: one line, exit 130, nothing left; had
    a fast machine reached the output files, still no hidden or partial file and no
    summary.json, which marks a finished run."""
    def mapped(name):
        """``name`` is loaded in the process or in one of its children (gmsh runs in a child)."""
        def fired(pid):
            kids = Path(f"/proc/{pid}/task/{pid}/children").read_text().split()
            for p in (pid, *kids):
                try:
                    if name in Path(f"/proc/{p}/maps").read_text():
                        return True
                except OSError:  # the child has ended meanwhile
                    pass
            return False
        return fired

    locked = {}

    def running(pid):
        """1 s after the output directory was locked: inside the 5-s run on the fine mesh."""
        if (tmp_path / "running" / ".gatetherm.lock").exists():
            locked.setdefault(pid, time.monotonic())
        return pid in locked and time.monotonic() - locked[pid] > 1.0

    (tmp_path / "fine.toml").write_text("[mesh]\nsize = 0.003\n")
    triggers = {"importing": mapped("_multiarray_umath"), "meshing": mapped("libgmsh"), "running": running}
    procs = {name: subprocess.Popen([*GATETHERM, "simulate", "--condition", "1", "--no-pictures", "--out",
                                     str(tmp_path / name), *(["--config", str(tmp_path / "fine.toml")]
                                                             if name == "running" else [])],
                                    stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                                    text=True, preexec_fn=foreground) for name in triggers}
    pending = dict(triggers)
    deadline = time.monotonic() + 60
    while pending and time.monotonic() < deadline:
        for name, fired in list(pending.items()):
            assert procs[name].poll() is None, f"{name}: ended before the signal"
            if fired(procs[name].pid):
                procs[name].send_signal(signal.SIGINT)
                del pending[name]
        time.sleep(0.002)
    assert not pending
    for name, proc in procs.items():
        err = proc.communicate()[1]
        assert proc.returncode in INTERRUPTED and err == "gatetherm: interrupted\n", name
        left = files(tmp_path / name) if (tmp_path / name).exists() else []
        if name == "running":
            assert "summary.json" not in left and not any(Path(f).name.startswith(".") for f in left), left
        else:
            assert not left, name


STUDY = """[study]
compute = ["coefficients"]
[set]
"mesh.size" = 0.03
[grid]
"geometry.l4" = [0.2, 0.25, 0.3, 0.35, 0.4, 0.45]
"""


def test_ctrl_c_to_a_sweep_and_its_workers(tmp_path):
    """The terminal's Ctrl-C reaches the whole process group: the sweep prints one line,
    its workers end quietly with it."""
    (tmp_path / "s.toml").write_text(STUDY)
    out = tmp_path / "o"
    proc = subprocess.Popen([*GATETHERM, "sweep", str(tmp_path / "s.toml"), "--out", str(out), "--workers", "2",
                             "--no-plots"], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
                            start_new_session=True, preexec_fn=foreground)
    try:
        wait_for(lambda: len(children(proc.pid)) >= 2 and any(out.glob("points/*.json")), proc)
        workers = children(proc.pid)
        os.killpg(proc.pid, signal.SIGINT)
        err = proc.communicate(timeout=30)[1]
    finally:
        left = group(proc.pid)
        for pid in left:
            os.kill(pid, signal.SIGKILL)
    assert not left
    assert proc.returncode in INTERRUPTED and err == "gatetherm: interrupted\n"
    assert not any(map(alive, workers))
    assert not [f for f in files(out) if f.startswith(".gatetherm") or "/.gatetherm" in f]


def test_a_full_disk_ends_in_one_line_and_leaves_nothing(tmp_path):
    """A file-size limit stands in for a full disk: the time series (27 kB) is written into the
    stage, the first field (60 kB) is not: exit 1, one line naming the file in --out, nothing left."""
    (tmp_path / "c.toml").write_text(COARSE)
    (tmp_path / "s.csv").write_text("time_s,oil_degC,pump\n0,40,1\n3600,40,1\n")
    out = tmp_path / "o"

    def limit():
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
        resource.setrlimit(resource.RLIMIT_FSIZE, (40_000, 40_000))

    r = subprocess.run([*GATETHERM, "simulate", "--schedule", str(tmp_path / "s.csv"), "--config",
                        str(tmp_path / "c.toml"), "--no-pictures", "--out", str(out)], preexec_fn=limit,
                       capture_output=True, text=True)
    assert (r.returncode, r.stderr) == (1, f"gatetherm: error: {out}/fields/fields_0000min.vtu: File too large\n")
    assert not out.exists()  # nothing of the failed run: the directory it made is removed again (issue 55)
