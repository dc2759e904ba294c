"""Nothing runs from a case: gmsh reads a user's geometry in a sandboxed child process.

Markers: a ``.geo`` whose ``System`` (directly, from an ``Include``d file, inside a
``Macro`` called with ``Call``, with a command built by ``StrCat``), ``Printf … >``,
``CreateDir`` or ``Save`` would create a file leaves none, and the run ends in one line,
exit 2, naming the file. ``Exit`` ends the child only. The text scan (the fallback where the
kernel has no seccomp) refuses the same scripts by line. Signals end a run inside gmsh at
once; a mesh too big for memory is refused before gmsh meshes.
"""
from __future__ import annotations

import logging
import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from gatetherm import InputError
from gatetherm.geometry import isolate, sandbox
from gatetherm.geometry.geoscan import scan
from gatetherm.geometry.gmshfile import MeshSpec, mesh_geometry
from gatetherm.cli import main

pytestmark = pytest.mark.skipif(not sandbox.available(), reason="seccomp sandbox: Linux x86_64/aarch64 only")

PLATE = """SetFactory("OpenCASCADE");
Rectangle(1) = {0, 0, 0, 1, 1};
Physical Surface("plate") = {1};
Physical Curve("edge") = {1};
Physical Curve("free") = {2, 3, 4};
"""
CASE = """[mesh]
file = "{geo}"
size = 0.25
[materials.plate]
k = 50.0
[thermal.edge]
temperature = 100.0
"""


def _evil(tmp: Path, marker: Path) -> dict[str, tuple[str, dict[str, str]]]:
    """Scripts that would create ``marker``: name -> (main file, {file: text})."""
    touch = f'System "touch {marker}";\n'
    return {
        "system": ("a.geo", {"a.geo": PLATE + touch}),
        "include": ("a.geo", {"a.geo": PLATE + 'Include "sub/b.geo";\n', "sub/b.geo": touch}),
        "macro_strcat": ("a.geo", {"a.geo": PLATE + 'Include "b.geo";\nCall Evil;\n',
                                   "b.geo": f'Macro Evil\n  System StrCat("tou", "ch ", "{marker}");\nReturn\n'}),
        "printf": ("a.geo", {"a.geo": PLATE + f'Printf("x = %g", 1) > "{marker}";\n'}),
        "createdir": ("a.geo", {"a.geo": PLATE + f'CreateDir "{marker}";\n'}),
        "save": ("a.geo", {"a.geo": PLATE + f'Mesh 2;\nSave "{marker}";\n'}),
    }


def _files(tmp: Path, files: dict[str, str]) -> None:
    for name, text in files.items():
        (tmp / name).parent.mkdir(parents=True, exist_ok=True)
        (tmp / name).write_text(text)


@pytest.mark.parametrize("kind", ["system", "include", "macro_strcat", "printf", "createdir", "save"])
def test_a_script_that_runs_a_program_or_writes_leaves_no_marker(tmp_path, kind):
    marker = tmp_path / "marker.msh"
    main_file, files = _evil(tmp_path, marker)[kind]
    _files(tmp_path, files)
    with pytest.raises(InputError, match="tried to run a program / write a file; gatetherm does not allow it") as err:
        mesh_geometry(MeshSpec(tmp_path / main_file, 0.25))
    assert err.value.field == str(tmp_path / main_file)
    assert not marker.exists()


@pytest.mark.parametrize("kind", ["system", "include", "macro_strcat", "printf", "createdir", "save"])
def test_the_text_scan_refuses_the_same_scripts_where_seccomp_is_missing(tmp_path, kind, monkeypatch, caplog):
    """The kernel refuses the filter: the parent scans the script (and what it includes) first."""
    def refuse(listen=True):
        raise OSError(38, "no seccomp here")
    monkeypatch.setattr(sandbox, "confine", refuse)  # inherited by the forked child
    marker = tmp_path / "marker.msh"
    main_file, files = _evil(tmp_path, marker)[kind]
    _files(tmp_path, files)
    with pytest.raises(InputError, match=r"line \d+: .*gatetherm does not allow it in a geometry script"):
        mesh_geometry(MeshSpec(tmp_path / main_file, 0.25))
    assert "without its sandbox here (no seccomp here)" in caplog.text
    assert not marker.exists()


def test_run_ends_in_one_line_exit_2_naming_the_script(tmp_path, capsys):
    marker = tmp_path / "marker.msh"
    _files(tmp_path, _evil(tmp_path, marker)["macro_strcat"][1])
    (tmp_path / "case.toml").write_text(CASE.format(geo="a.geo"))
    assert main(["run", str(tmp_path / "case.toml"), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err, err
    assert err.startswith(f"gatetherm: error: {tmp_path / 'a.geo'}: the geometry script tried to run a program / "
                          "write a file; gatetherm does not allow it; remove the command that did it "
                          "(system call clone)")
    assert not marker.exists() and not (tmp_path / "out").exists()


def test_exit_in_a_script_ends_only_gmsh(tmp_path):
    (tmp_path / "a.geo").write_text(PLATE + "Exit;\n")
    with pytest.raises(InputError, match=r"gmsh stopped before the mesh was made \(an Exit or Abort"):
        mesh_geometry(MeshSpec(tmp_path / "a.geo", 0.25))


def test_a_clean_script_meshes_as_before(tmp_path):
    """Comments and strings that name commands are no commands: this script meshes."""
    (tmp_path / "a.geo").write_text('// System "rm -rf /" in a comment\n/* Save "x" */\n' + PLATE
                                    + 'Printf("System Save Exit CreateDir");\n')
    scan(tmp_path / "a.geo", tmp_path, commands=True)
    fm = mesh_geometry(MeshSpec(tmp_path / "a.geo", 0.25))
    assert list(fm.regions) == ["plate"] and len(fm.cells) == 162  # as gmsh meshes it in-process


def test_the_filter_refuses_programs_and_writes_with_eperm(tmp_path):
    """Without a listener every denied call fails with EPERM; reading, threads and the own
    process's signals still work."""
    r, w = os.pipe()
    pid = os.fork()
    if pid == 0:  # pragma: no cover - the child
        out = []
        try:
            sandbox.confine(listen=False)
            out.append(os.system(f"touch {tmp_path / 'a'}") != 0)
            for attempt in (lambda: open(tmp_path / "b", "w"), lambda: os.mkdir(tmp_path / "c"),
                            lambda: os.kill(os.getppid(), 0), lambda: os.rename(__file__, tmp_path / "d"),
                            lambda: __import__("socket").socket()):
                try:
                    attempt()
                    out.append(False)
                except PermissionError:
                    out.append(True)
            out.append(len(Path(__file__).read_text()) > 0)
            os.kill(os.getpid(), 0)
            import threading
            t = threading.Thread(target=out.append, args=(True,))
            t.start()
            t.join()
        finally:
            os.write(w, bytes(int(x) for x in out))
            os._exit(0)
    os.close(w)
    os.waitpid(pid, 0)
    got = os.read(r, 100)
    os.close(r)
    assert got == bytes([1] * 8)
    assert not any((tmp_path / n).exists() for n in "abcd")


def test_includes_stay_in_the_case_folder_unless_named(tmp_path):
    (tmp_path / "common.geo").write_text(PLATE)
    case = tmp_path / "case"
    case.mkdir()
    (case / "a.geo").write_text('Include "../common.geo";\n')
    with pytest.raises(InputError, match=r'line 1: Include "../common.geo" reads a file outside the case\'s folder'):
        scan(case / "a.geo", case)
    assert scan(case / "a.geo", case, allowed=[tmp_path / "common.geo"]) == [case / "a.geo", tmp_path / "common.geo"]
    (case / "b.geo").write_text('f = "x";\nInclude StrCat(f, ".geo");\n')
    with pytest.raises(InputError, match="line 2: Include of a computed path"):
        scan(case / "b.geo", case)
    (case / "c.geo").write_text('Merge StrCat(CurrentDir, "../common.geo");\n')
    with pytest.raises(InputError, match="outside the case's folder"):
        scan(case / "c.geo", case)


def test_a_case_names_files_outside_its_folder_with_include(tmp_path, capsys):
    (tmp_path / "common.geo").write_text(PLATE)
    case = tmp_path / "case"
    case.mkdir()
    (case / "a.geo").write_text('Include "../common.geo";\n')
    (case / "case.toml").write_text(CASE.format(geo="a.geo"))
    assert main(["run", str(case / "case.toml"), "--out", str(tmp_path / "o1")]) == 2
    assert "outside the case's folder; copy it beside the case or name it" in capsys.readouterr().err
    (case / "case.toml").write_text(CASE.format(geo="a.geo").replace("size", 'include = ["../common.geo"]\nsize'))
    assert main(["run", str(case / "case.toml"), "--out", str(tmp_path / "o2")]) == 0


def test_a_tiny_element_size_is_refused_before_meshing(tmp_path, capsys):
    (tmp_path / "a.geo").write_text(PLATE)
    (tmp_path / "case.toml").write_text(CASE.format(geo="a.geo").replace("0.25", "1e-5"))
    t0 = time.perf_counter()
    assert main(["run", str(tmp_path / "case.toml"), "--out", str(tmp_path / "o")]) == 2
    took = time.perf_counter() - t0
    err = capsys.readouterr().err
    assert err.startswith(f"gatetherm: error: {tmp_path / 'case.toml'}: mesh.size: 1e-05 m gives about 2.3e+10 "
                          "triangles needing"), err
    assert "raise it to at least" in err and err.count("\n") == 1
    assert took < 60.0  # achieved 2.1-3.0 s at a load average of 17 (gmsh imported, the script
    #                     parsed); meshing it would take hours


def _endless(tmp_path: Path) -> Path:
    (tmp_path / "a.geo").write_text(PLATE + "For i In {1:1e15}\n  x = i;\nEndFor\n")
    (tmp_path / "case.toml").write_text(CASE.format(geo="a.geo"))
    return tmp_path / "case.toml"


def _children(pid: int) -> list[int]:
    path = Path(f"/proc/{pid}/task/{pid}/children")
    return [int(x) for x in path.read_text().split()] if path.exists() else []


def _sandboxed_child(pid: int) -> int | None:
    """The child of ``pid`` that runs under a seccomp filter: gmsh's process once it is in its
    sandbox, about to read the script (the painter's process, started first, has none)."""
    for child in _children(pid):
        try:
            status = Path(f"/proc/{child}/status").read_text()
        except OSError:  # ended meanwhile
            continue
        if any(line.split() == ["Seccomp:", "2"] for line in status.splitlines()):
            return child
    return None


#: The command, with the fallback that ends a command ignoring its signal after
#: ``_Signals.GRACE_S`` (5 s) pushed out of reach: the run must end by unwinding from the signal.
CLI = "from gatetherm import cli; cli._Signals.GRACE_S = 3600.0; cli.console()"


@pytest.mark.parametrize("sig, code, said", [(signal.SIGTERM, 143, "terminated"), (signal.SIGINT, 130, "interrupted")])
def test_a_signal_ends_a_run_inside_gmsh_at_once(tmp_path, sig, code, said):
    """An endless .geo loop: the run ends with the usual line and code, no output, no child left.

    The signal is sent once gmsh's process is in its sandbox (its seccomp filter is visible in
    /proc), never after a guessed sleep: on a busy machine the first child is the painter's and
    gmsh's starts seconds later (at a load average of 20: the painter's 0.8 s after the start,
    gmsh's 4.6 s), so a signal a second after "a child" hit the command still importing, not
    gmsh. No tight wall-clock margin: without the fallback timer, a signal the run did not
    unwind from would leave gmsh's loop to its 30-s read limit, 20 s beyond the 10 s allowed."""
    case = _endless(tmp_path)
    proc = subprocess.Popen([sys.executable, "-c", CLI, "run", str(case), "--out", str(tmp_path / "out")],
                            stderr=subprocess.PIPE, text=True,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    deadline = time.monotonic() + 300  # a hang guard, no margin: the loaded machine takes seconds
    while (gmsh := _sandboxed_child(proc.pid)) is None and proc.poll() is None and time.monotonic() < deadline:
        time.sleep(0.02)
    assert gmsh is not None, f"gmsh's process did not enter its sandbox: {proc.poll()}"
    children = _children(proc.pid)
    t0 = time.monotonic()
    proc.send_signal(sig)
    _, err = proc.communicate(timeout=300)
    took = time.monotonic() - t0
    assert proc.returncode == code and err == f"gatetherm: {said}\n", (proc.returncode, err)
    assert took < 10.0  # achieved 0.1-0.5 s; a run that went on would end at gmsh's 30-s read limit
    assert not (tmp_path / "out").exists()
    assert gmsh in children and not [c for c in children if Path(f"/proc/{c}").exists()]


def test_the_result_comes_back_through_the_pipe_checked():
    """The parent reads the child's arrays without pickle and refuses inconsistent ones."""
    import numpy as np

    meta, arrays = isolate.unpack(isolate.pack({"a": 1}, {"x": np.arange(6.0).reshape(2, 3)})[9:])
    assert meta == {"a": 1} and arrays["x"].tolist() == [[0, 1, 2], [3, 4, 5]]
    with pytest.raises(ValueError, match="bad array"):
        isolate.unpack(isolate.pack({}, {"x": np.array(["s"])})[9:])
    with pytest.raises(ValueError, match="truncated"):
        isolate.unpack(isolate.pack({}, {"x": np.arange(3.0)})[9:-1])


def test_after_gmsh_ran_here_its_processes_start_afresh(tmp_path):
    """A 3-D mesh made in this process leaves gmsh's threads behind: a forked child would wait
    for them for ever, so the next mesh is made by a new interpreter (in a subprocess here,
    not to leave the threads in the test session)."""
    code = ("from gatetherm.frame.build import _build, build_mesh, gmsh_session\n"
            "from gatetherm.frame.geometry import FrameParams, MeshParams\n"
            "from gatetherm.geometry.isolate import THREADS_STARTED\n"
            "m = MeshParams(size=0.04, size_3d=0.08)\n"
            "with gmsh_session() as g:\n    _build(FrameParams(), 3, m, g)\n"
            "print(THREADS_STARTED['here'], len(build_mesh(FrameParams(), 3, m).cells))\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    assert out.stdout.split()[0] == "True" and int(out.stdout.split()[1]) > 1000


def test_a_spawned_child_makes_the_same_mesh(monkeypatch):
    from gatetherm.frame.build import build_mesh

    from conftest import COARSE, FIXED

    forked = build_mesh(FIXED, 2, COARSE)
    monkeypatch.setitem(isolate.THREADS_STARTED, "here", True)
    spawned = build_mesh(FIXED, 2, COARSE)
    assert np.array_equal(forked.points, spawned.points) and np.array_equal(forked.cells, spawned.cells)


def test_an_endless_loop_in_a_script_is_refused_after_the_read_limit(tmp_path, monkeypatch, capsys):
    from gatetherm.geometry import gmshfile, isolate

    monkeypatch.setattr(gmshfile, "READ_LIMIT_S", 2)
    monkeypatch.setattr(isolate, "READ_LIMIT_S", 2)
    (tmp_path / "l.geo").write_text('SetFactory("OpenCASCADE");\nRectangle(1) = {0, 0, 0, 1, 1};\n'
                                    'Physical Surface("p") = {1};\nPhysical Curve("e") = {1, 2, 3, 4};\n'
                                    "For k In {1:1e15}\n  x = k;\nEndFor\n")
    (tmp_path / "c.toml").write_text('[mesh]\nfile = "l.geo"\n[materials.p]\nk = 1.0\n[thermal.e]\ntemperature = 20.0\n')
    assert main(["run", str(tmp_path / "c.toml"), "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "gmsh was still reading it after 2 s (an endless loop in the script?)" in err
    assert not (tmp_path / "o").exists()


def _slow(gmsh):
    import time

    time.sleep(1.5)
    return {"n": 1}, {}


def test_a_long_meshing_says_gmsh_is_still_at_work(monkeypatch, caplog):
    """Without -v, gmsh prints nothing: a mesh of millions of elements looked like a hang (the
    third audit: a STEP of 150 boxes at 0.5 mm, nothing in 180 s)."""
    from gatetherm.geometry import isolate

    monkeypatch.setattr(isolate, "STILL_S", 0.5)
    with caplog.at_level(logging.WARNING, logger="gatetherm.geometry.isolate"):
        meta, _ = isolate.run_isolated(_slow, "big.step")
    assert meta["n"] == 1
    assert re.search(r"big\.step: gmsh is still at work after \d+ s \(a large mesh; Ctrl-C stops it", caplog.text)
    assert caplog.text.count("gmsh is still at work") <= 1 + 5  # then at 1, 2, 4 … s: a handful, not a flood


def test_abort_in_a_script_is_refused_by_its_line(tmp_path):
    """gmsh's Abort ended the reading without a word and gmsh meshed what was read so far: the
    case's groups after it were reported missing ('materials.bed: unknown key'), the script unnamed."""
    (tmp_path / "a.geo").write_text('SetFactory("OpenCASCADE");\nRectangle(1) = {0, 0, 0, 1, 1};\nAbort;\n'
                                    'Physical Surface("plate") = {1};\n')
    with pytest.raises(InputError, match=r"a.geo: line 3: Abort ends gmsh's reading of the script there"):
        mesh_geometry(MeshSpec(tmp_path / "a.geo", 0.25))
