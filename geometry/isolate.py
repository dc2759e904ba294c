"""gmsh in a child process: sandboxed, interruptible, its result back through a pipe.

:func:`run_isolated` forks: 0.01 to 0.15 s more than meshing in the process (the paper's 2-D frame,
medians of 7 interleaved runs on a loaded machine); a new interpreter costs 0.3 s more still, so one
is started only once gmsh has run threads in this process (:data:`THREADS_STARTED`). The child
imports and initialises gmsh, installs the seccomp sandbox (:mod:`gatetherm.geometry.sandbox`) and
only then, once the parent agrees, runs the work on the user's file; the result (a JSON header and
numpy arrays, :func:`~gatetherm.geometry.records.unpack`) comes back through a pipe opened before
the fork, never through a file. The parent holds the sandbox's listener: the first program run or
file written ends the child, and the run with one line. Where the kernel cannot report denials (or
refuses the filter), the parent checks the ``.geo`` by the text scan of
:mod:`gatetherm.geometry.geoscan` before the child reads it. A signal (Ctrl-C, SIGTERM) reaches the
parent at once, which kills the child on its way out; an ``Exit`` in a script ends the child only.
gmsh's messages are read from the child's output: every few seconds one is logged (``-v``), and the
last error names a failure.
"""
from __future__ import annotations

import json
import logging
import os
import pickle
import re
import select
import signal
import socket
import struct
import sys
import time
from collections import deque
from pathlib import Path

import numpy as np

from gatetherm import InputError
from gatetherm.geometry import sandbox
from gatetherm.geometry.records import _CRASH, _ERROR, _record, pack, unpack
from gatetherm.geometry.session import THREADS_STARTED, gmsh_session  # re-exported: isolate.THREADS_STARTED
from gatetherm.process import die_with_parent, fork

log = logging.getLogger(__name__)

FORBIDDEN = "the geometry script tried to run a program / write a file; gatetherm does not allow it"
PROGRESS_S = 3.0
"""Interval of the progress lines of gmsh's log (``-v``), s."""
STILL_S = 30.0
"""Without ``-v``: a line saying gmsh is still at work after this long, and every twice as long
since (a mesh of millions of elements takes minutes; nothing on the terminal looked like a hang)."""
READ_LIMIT_S = 30
"""Longest a geometry script may take to run (or gmsh to read a CAD file), before meshing, s: a
file that takes longer (an endless loop) is refused (the child ends on SIGALRM). Meshing itself has
no time limit."""


def _child(work, out: int, logfd: int, sock: socket.socket, go: int, verbose: bool, parent: int) -> None:
    """The child's life: never returns."""
    try:
        die_with_parent(signal.SIGKILL)
        if os.getppid() != parent:
            os._exit(1)
        null = os.open(os.devnull, os.O_RDONLY)
        os.dup2(null, 0)
        os.dup2(logfd, 1)
        os.dup2(logfd, 2)
        keep = {0, 1, 2, out, go, sock.fileno()}
        for fd in map(int, os.listdir("/proc/self/fd") if os.path.isdir("/proc/self/fd") else ()):
            if fd not in keep:
                try:
                    os.close(fd)
                except OSError:
                    pass
        sys.dont_write_bytecode = True  # a module first imported under the sandbox: no .pyc written
        # the process ends inside the session: gmsh.finalize would delete gmsh's temporary file
        with gmsh_session("model", 5 if verbose else 1) as gmsh:
            for sig in (signal.SIGINT, signal.SIGTERM):  # the parent kills: no handler that waits for Python
                if signal.getsignal(sig) is not signal.SIG_IGN:
                    signal.signal(sig, signal.SIG_DFL)
            try:
                listener, mode = sandbox.confine(listen=True), b"L"
                if listener is None:
                    mode = b"P"
            except OSError as err:
                listener, mode = None, b"U" + (err.strerror or str(err)).encode()[:200]
            socket.send_fds(sock, [mode], [listener] if listener is not None else [])
            if listener is not None:
                os.close(listener)
            if os.read(go, 1) != b"1":
                os._exit(0)
            scrub_environment()
            try:
                data = pack(*work(gmsh))
            except InputError as err:
                data = _record(_ERROR, json.dumps([err.field, err.problem, err.fix]).encode())
            except BaseException as err:  # noqa: BLE001 - reported to the parent, which raises
                data = _record(_CRASH, f"{type(err).__name__}: {err}".encode()[:4000])
            view = memoryview(data)
            while view:
                view = view[os.write(out, view):]
            os._exit(0)
    finally:
        os._exit(1)


KEPT_ENVIRONMENT = ("OMP_", "OPENBLAS_", "MKL_", "GOTO_", "LANG", "LC_", "TZ")
"""Prefixes of the environment variables gmsh's process keeps while it reads a user's file
(threads and locale); every other one is removed, so that a script's ``GetEnv`` reads nothing."""
_PLACE = re.compile(r"'([^']*)', line (\d+)")
_WORDS = re.compile(r"[A-Za-z][A-Za-z ]{0,60}")


def scrub_environment() -> None:
    """Remove the environment variables but :data:`KEPT_ENVIRONMENT` from this process (the C
    library's environment too), before a user's script runs in it: a ``.geo`` cannot read a
    secret of the environment (``GetEnv("TOKEN")``) into a message."""
    for key in list(os.environ):
        if not key.startswith(KEPT_ENVIRONMENT):
            del os.environ[key]


def quiet(message: str, script: bool = True) -> str:
    """What gatetherm repeats of a message of gmsh's: the place it names (file name and line)
    and gmsh's words for the kind of error, without the quoted, bracketed or parenthesised
    text (the user's). While a ``script`` runs, a message without a place is not repeated: an
    ``Error`` of the script's own could say anything, a variable's value included; after it
    (meshing), gmsh's words are."""
    place = _PLACE.search(message)
    if place is None and script:
        return "gmsh's message is not repeated: it names no line; open the file in gmsh to read it"
    rest = re.sub(r"'[^']*'|\"[^\"]*\"|\([^)]*\)|\[[^\]]*\]|\{[^}]*\}", "",
                  message[place.end():] if place else message.removeprefix("Error").lstrip(" :"))
    rest = " ".join(rest.split()).lstrip(" :")
    words = _WORDS.match(rest)
    kind = words.group(0).strip() if words and words.end() == len(rest.rstrip()) else ""
    if place is None:
        return kind or "gmsh's message is not repeated; open the file in gmsh to read it"
    return f"{Path(place.group(1)).name}, line {place.group(2)}" + (f": {kind}" if kind else "")


def run_isolated(work, label: str, script: Path | None = None, scan=None) -> tuple[dict, dict[str, np.ndarray]]:
    """Run ``work(gmsh)`` (which returns ``(meta, arrays)``, see :func:`pack`) in a sandboxed
    child and return its result. ``label`` names the input in errors; ``scan`` (a callable
    refusing a dangerous ``script`` with InputError) runs where the sandbox cannot report
    what the script tries. An InputError of ``work`` is raised here."""
    verbose = log.isEnabledFor(logging.INFO)
    if not hasattr(os, "fork"):  # Windows: no child process; only the text scan guards the script
        log.warning("gmsh runs in this process here, without its sandbox: %s was checked by a text scan", label)
        if script is not None and scan is not None:
            scan(script)
        with gmsh_session("model", 5 if verbose else 0) as gmsh:
            return unpack(pack(*work(gmsh))[9:])
    out_r, out_w = os.pipe()
    log_r, log_w = os.pipe()
    go_r, go_w = os.pipe()
    mine, theirs = socket.socketpair()
    parent = os.getpid()
    if THREADS_STARTED["here"]:
        pid = _spawn(work, (out_w, log_w, go_r, theirs.fileno()), verbose)
    else:
        pid = fork()
        if pid == 0:  # pragma: no cover - the child's coverage is not collected
            mine.close()
            _child(work, out_w, log_w, theirs, go_r, verbose, parent)
    for fd in (out_w, log_w, go_r):
        os.close(fd)
    theirs.close()
    listener, data, lines, tried = None, bytearray(), deque(maxlen=20), None
    open_fds = {out_r, log_r, mine.fileno()}
    try:
        last, partial, start, still = -PROGRESS_S, b"", time.monotonic(), STILL_S
        while out_r in open_fds or log_r in open_fds:
            ready, _, _ = select.select(list(open_fds), [], [], 1.0)
            if not verbose and time.monotonic() - start >= still:
                log.warning("%s: gmsh is still at work after %.0f s (a large mesh; Ctrl-C stops it, a larger "
                            "[mesh] size or --mesh-factor makes it quicker)", label, time.monotonic() - start)
                still *= 2
            for fd in ready:
                if fd == mine.fileno():
                    mode, fds, _, _ = socket.recv_fds(mine, 256, 1)
                    open_fds.discard(fd)
                    if not mode:  # the child ended before its sandbox was in place
                        continue
                    listener = fds[0] if fds else None
                    if listener is not None:
                        open_fds.add(listener)
                    elif mode:
                        _unreported(mode, label, script, scan)
                    os.write(go_w, b"1")
                elif fd == listener:
                    tried = sandbox.answer(listener)
                    if tried is None:
                        open_fds.discard(fd)
                        continue
                    os.kill(pid, signal.SIGKILL)
                    raise InputError(label, FORBIDDEN, f"remove the command that did it (system call {tried}): "
                                     "System, Printf … >, Save, Print, CreateDir, Delete File, OnelabRun …")
                else:
                    chunk = os.read(fd, 1 << 20)
                    if not chunk:
                        open_fds.discard(fd)
                    elif fd == out_r:
                        data += chunk
                    else:
                        *full, partial = (partial + chunk).split(b"\n")
                        lines.extend(x.decode(errors="replace").strip() for x in full if x.strip())
                        if verbose and full and time.monotonic() - last >= PROGRESS_S and \
                                not lines[-1].startswith("Error"):  # said in the one line, quietly
                            last = time.monotonic()
                            log.info("gmsh: %s", lines[-1].removeprefix("Info").lstrip(" :"))
        _, status = os.waitpid(pid, 0)
        pid = 0
    finally:
        if pid:
            try:
                os.kill(pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
            os.waitpid(pid, 0)
        for fd in (out_r, log_r, go_w, *([listener] if listener is not None else [])):
            os.close(fd)
        mine.close()
    return _result(bytes(data), status, label, lines)


def _spawn(work, fds, verbose: bool) -> int:
    """Start the child as a new interpreter (see :data:`THREADS_STARTED`); its pid."""
    work_r, work_w = os.pipe()
    for fd in (*fds, work_r):
        os.set_inheritable(fd, True)
    code = "import gatetherm.geometry.isolate as m; m._spawned()"
    pid = os.posix_spawn(sys.executable, [sys.executable, "-c", code, *map(str, (*fds, work_r, os.getpid(),
                                                                                int(verbose)))], os.environ)
    os.close(work_r)
    with os.fdopen(work_w, "wb") as f:
        pickle.dump(work, f)
    return pid


def _spawned() -> None:  # pragma: no cover - runs in the child
    """The entry of a spawned child: its pipes' numbers and the parent's pid in ``sys.argv``."""
    out, logfd, go, sock, work_r, parent, verbose = map(int, sys.argv[1:])
    with os.fdopen(work_r, "rb") as f:
        work = pickle.load(f)  # from the parent, which trusts itself
    _child(work, out, logfd, socket.socket(fileno=sock), go, bool(verbose), parent)


def _unreported(mode: bytes, label: str, script, scan) -> None:
    """The sandbox cannot report attempts (``P``: it only refuses them) or is not there (``U``)."""
    if mode[:1] == b"U":
        log.warning("gmsh runs without its sandbox here (%s)%s", mode[1:].decode(errors="replace"),
                    f": {label} was checked by a text scan instead" if script is not None else "")
    if script is not None and scan is not None:
        scan(script)


def _result(data: bytes, status: int, label: str, lines) -> tuple[dict, dict[str, np.ndarray]]:
    errors = [x for x in lines if x.startswith("Error")]
    said = f": {quiet(errors[-1])}" if errors else ""
    if not data:
        if os.WIFSIGNALED(status) and os.WTERMSIG(status) == signal.SIGALRM:
            if str(label).lower().endswith(".geo"):
                raise InputError(label, f"gmsh was still reading it after {READ_LIMIT_S} s (an endless loop in "
                                 "the script?)", "end every loop of the script")
            raise InputError(label, f"gmsh was still reading it after {READ_LIMIT_S} s (a CAD file too large?)",
                             "simplify the geometry (a sub-assembly of the CAD model)")
        if os.WIFSIGNALED(status):
            sig = os.WTERMSIG(status)
            raise InputError(label, f"gmsh crashed on it ({signal.Signals(sig).name}){said}",
                             "check the file in gmsh" + ("; the machine's memory may be exhausted" if sig == 9 else ""))
        raise InputError(label, f"gmsh stopped before the mesh was made{said or ' (an Exit or Abort in the script?)'}",
                         "remove the Exit/Abort or fix the script")
    kind, (n,) = data[:1], struct.unpack_from("<Q", data, 1)
    payload = data[9:9 + n]
    if kind == _ERROR:
        raise InputError(*json.loads(payload))
    if kind == _CRASH:
        raise RuntimeError(f"gmsh's process failed on {label}: {payload.decode(errors='replace')}")
    return unpack(payload)
