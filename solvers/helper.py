"""A solver set up and run in a helper process beside the caller, and values still being made.

:class:`SolveHelper` forks a process that makes a solver (an AMG hierarchy: seconds of set-up) and
then solves each right-hand side it is given, in turn, while the caller goes on: on the 3-D frame
the elastic hierarchy, the adjoint read-out and the fields at the output times are solved on the
second core while the first marches the heat equation (``benchmarks/peer.py``).
:meth:`SolveHelper.submit` returns a :class:`Pending` (:mod:`gatetherm.solvers.pending`), whose
:meth:`~Pending.result` waits for the solution. :func:`forked` makes one value in a process of its
own (a mesh's METIS order beside the set-up before the first factor; the later half of an AMG-CG
call's right-hand sides).

The arrays go through files in a private temporary folder (``/dev/shm`` where there is one),
the pipes carry only their names: neither side ever waits on the other to read a large
message. The helper ends when the caller closes it (or is collected), and with the caller
(``PR_SET_PDEATHSIG``), the folder with it. A solve that fails in the helper raises
:class:`~gatetherm.solvers.iterative.SolverError` in the caller; so does a helper that ended
(killed: out of memory?).
"""
from __future__ import annotations

import logging
import os
import select
import shutil
import signal
import tempfile
import threading
import time
import weakref
from typing import Any, Callable

import numpy as np

from gatetherm.process import die_with_parent, end_with_parent, fork, give_back, receive, send
from gatetherm.solvers.errors import SolverError
from gatetherm.solvers.pending import Pending  # re-exported: helper.Pending

log = logging.getLogger(__name__)

ENDED = "the helper process ended without its solutions"


def forked(make: Callable[[], Any], what: str) -> Pending:
    """``make()`` computed in a forked process while the caller goes on (the caller must be able to
    fork: :func:`gatetherm.process.can_fork`): its :class:`Pending` value, sent back pickled
    through a pipe (widened to hold it where Linux allows, so that the process ends when done).
    A ``make`` that fails, or a process that ends without its value, raises
    :class:`~gatetherm.solvers.iterative.SolverError` from :meth:`Pending.result`."""
    r, w = os.pipe()
    try:
        import fcntl
        fcntl.fcntl(w, getattr(fcntl, "F_SETPIPE_SZ", 1031), 1 << 20)
    except (ImportError, OSError):  # not Linux, or above its limit: the process waits to be read
        pass
    pid = fork()
    if pid == 0:  # pragma: no cover - the child's coverage is not collected
        try:
            _close_others((w,))  # the caller's pipes: their readers see their end
            die_with_parent(signal.SIGKILL)
            try:
                reply = (make(), None)
            except Exception as err:  # noqa: BLE001 - raised in the caller
                reply = (None, f"{type(err).__name__}: {err}")
            send(w, reply)
        finally:
            os._exit(0)
    os.close(w)
    live, owner = [True], os.getpid()

    def end():  # once, in the caller: after the value is read, or when the Pending is dropped unread
        if live and os.getpid() == owner:
            live.clear()
            os.close(r)
            _kill(pid)

    def wait():
        if os.getpid() != owner:  # a forked copy of the caller: the pipe and the process are not its own
            raise SolverError(f"{what}: made for another process")
        try:
            reply = receive(r)
        finally:
            end()
        if reply is None:
            raise SolverError(f"{what}: {ENDED}")
        value, error = reply
        if error is not None:
            raise SolverError(f"{what}: {error}")
        return value
    pending = Pending(wait, lambda: bool(select.select([r], [], [], 0)[0]))
    weakref.finalize(pending, end)
    return pending


WAITING = (-1, None)
"""The message the caller sends when it waits for a solution: the helper then solves the jobs it
has together, their columns in two processes where the solver splits a call's right-hand sides
(AMG-CG's ``split``), the caller's core being idle."""


def _serve(make: Callable[[], Callable], jobs: int, replies: int) -> None:
    """The helper's life: make the solver, then answer each job ``(k, path of b)`` with
    ``(k, path of x, None)`` or ``(k, None, error text)``: one at a time while the caller works,
    those it has together once the caller waits (:data:`WAITING`), till the caller sends no more."""
    try:
        t0 = time.perf_counter()
        solve, error = make(), None
        give_back()  # the set-up's temporaries: not kept beside the caller
        log.debug("helper: solver made in %.2f s", time.perf_counter() - t0)
    except Exception as err:  # noqa: BLE001 - reported with every job
        solve, error = None, f"{type(err).__name__}: {err}"
    queue, waited, last = [], False, False
    while queue or not last:
        while not last and (not queue or select.select([jobs], [], [], 0)[0]):  # wait only with nothing to do
            job = receive(jobs)
            if job is None:  # no more jobs: those queued are answered, then the helper ends
                last = True
            elif job[0] < 0:
                waited = True
            else:
                queue.append(job)
        batch, both = (queue, True) if waited else (queue[:1], False)
        queue, waited = queue[len(batch):], False
        for reply in _answer(solve, error, batch, both):
            send(replies, reply)


def _answer(solve, error: str | None, batch: list, both: bool) -> list[tuple]:
    """The replies to the jobs of ``batch``: one-column right-hand sides of one length stacked
    into one call, others each alone; with ``both`` (the caller waits) the solver's ``split``
    on, so that a call's columns are solved in two processes."""
    if solve is None:
        return [(k, None, error) for k, _ in batch]
    try:
        t0 = time.perf_counter()
        bs = [np.load(path) for _, path in batch]
        for _, path in batch:
            os.unlink(path)
        stack = len(bs) > 1 and all(b.ndim == 1 and b.shape == bs[0].shape for b in bs)
        split = getattr(solve, "split", None)
        if split is not None:
            solve.split = both
        try:
            xs = list(solve(np.column_stack(bs)).T) if stack else [solve(b) for b in bs]
        finally:
            if split is not None:
                solve.split = split
        log.debug("helper: jobs %s in %.2f s", [k for k, _ in batch], time.perf_counter() - t0)
        out = []
        for (k, path), x in zip(batch, xs):
            np.save(path := path.replace(".b.npy", ".x.npy"), x)
            out.append((k, path, None))
        return out
    except Exception as err:  # noqa: BLE001 - reported to the caller, which raises
        return [(k, None, f"{type(err).__name__}: {err}") for k, _ in batch]


class SolveHelper:
    """A process beside the caller that makes a solver with ``make()`` (at once) and solves
    what :meth:`submit` gives it, in turn. The caller must be able to fork
    (:func:`gatetherm.process.can_fork`)."""

    def __init__(self, make: Callable[[], Callable[[np.ndarray], np.ndarray]], what: str = "solver"):
        self.what = what
        self._dir = tempfile.mkdtemp(prefix="gatetherm-", dir="/dev/shm" if os.path.isdir("/dev/shm") else None)
        if threading.current_thread() is threading.main_thread():  # Python's own setting (gmsh's start undoes
            signal.signal(signal.SIGPIPE, signal.SIG_IGN)  # it): a job sent to an ended helper raises, no signal
        (jobs_r, jobs_w), (replies_r, replies_w) = os.pipe(), os.pipe()
        pid = fork()
        if pid == 0:  # pragma: no cover - the child's coverage is not collected
            code = 1
            try:
                _close_others((jobs_r, replies_w))  # the caller's other pipes: their readers see their end
                end_with_parent()  # and its folder goes with it
                _serve(make, jobs_r, replies_w)
                code = 0  # its answers' files are the caller's to read and remove
            finally:
                signal.signal(signal.SIGTERM, signal.SIG_IGN)  # a SIGTERM here: no SystemExit out of the child
                if code:
                    shutil.rmtree(self._dir, ignore_errors=True)
                os._exit(code)
        os.close(jobs_r)
        os.close(replies_w)
        self.pid, self.owner = pid, os.getpid()
        self._fds = [jobs_w, replies_r]  # the jobs' end closed (None) once :meth:`finish` is called
        self._replies = replies_r
        self._next, self._answers = 0, {}
        self._finalize = weakref.finalize(self, _close, self.owner, pid, self._fds, self._dir)
        log.debug("%s: set up in helper process %d", what, pid)

    @property
    def open(self) -> bool:
        """Whether it takes jobs (not closed, not finished)."""
        return self._finalize.alive and self._fds[0] is not None

    def submit(self, b: np.ndarray) -> Pending:
        """Solve ``b`` (n,) or (n, k) in the helper, after what it was given before."""
        if not self.open:
            raise SolverError(f"{self.what}: the helper process is closed")
        k, self._next = self._next, self._next + 1
        path = os.path.join(self._dir, f"{k}.b.npy")
        np.save(path, np.asarray(b, dtype=float))
        try:
            send(self._fds[0], (k, path))
        except BrokenPipeError:
            raise SolverError(f"{self.what}: {ENDED}") from None
        return Pending(lambda: self._wait(k), lambda: self._collect(k, block=False))

    def _collect(self, k: int, block: bool) -> bool:
        """Read the answers that have come (waiting for one if ``block``); whether ``k``'s is in."""
        while k not in self._answers and select.select([self._replies], [], [], None if block else 0)[0]:
            reply = receive(self._replies)
            if reply is None:
                raise SolverError(f"{self.what}: {ENDED}")
            j, path, error = reply
            self._answers[j] = SolverError(f"{self.what}: {error}") if error else np.load(path)
            if path:
                os.unlink(path)
        return k in self._answers

    def _wait(self, k: int) -> np.ndarray:
        if not self._collect(k, block=False) and self.open:  # the caller waits: the helper may take both cores
            try:
                send(self._fds[0], WAITING)
            except BrokenPipeError:
                raise SolverError(f"{self.what}: {ENDED}") from None
        self._collect(k, block=True)
        x = self._answers.pop(k)
        if isinstance(x, SolverError):
            raise x
        return x

    def finish(self) -> None:
        """Give no more jobs: the helper answers those given, then ends, its memory freed (their
        :class:`Pending` values stay readable; :meth:`close` or collection removes the folder)."""
        if self.open:
            os.close(self._fds[0])
            self._fds[0] = None

    def close(self) -> None:
        """End the helper (at once: nothing it holds outlives it but its folder, removed here)."""
        self._finalize()


def _close_others(keep) -> None:
    """Close every file descriptor from 3 on but ``keep``."""
    low = 3
    for fd in sorted(keep):
        os.closerange(low, fd)
        low = fd + 1
    os.closerange(low, os.sysconf("SC_OPEN_MAX") if hasattr(os, "sysconf") else 4096)


def _kill(pid: int) -> None:
    """End the child ``pid`` and reap it."""
    try:
        os.kill(pid, signal.SIGKILL)
        os.waitpid(pid, 0)
    except (ProcessLookupError, ChildProcessError):  # ended and reaped already
        pass


def _close(owner: int, pid: int, fds: list, folder: str) -> None:
    if os.getpid() == owner:  # not in a forked copy of the owner
        for fd in fds:
            if fd is not None:
                os.close(fd)
        _kill(pid)
        shutil.rmtree(folder, ignore_errors=True)
