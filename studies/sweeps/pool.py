"""Local worker processes that leave Ctrl-C to their parent, die with it (even when it is
killed with SIGKILL) and are stopped when the block using them ends with an exception.

A worker would otherwise see the terminal's Ctrl-C and print its own traceback, and would
live on, orphaned, after its parent was killed. Signals are blocked while the workers start
(in :meth:`submit`), so that none arrives before a worker's initializer has set it up.
"""
from __future__ import annotations

import contextlib
import multiprocessing
import os
import signal
import threading
import time
from concurrent.futures import ProcessPoolExecutor

from gatetherm.process import die_with_parent

_SIGNALS = {signal.SIGINT, signal.SIGTERM}


def _mask(how: str, signals=_SIGNALS) -> set:
    """``signal.pthread_sigmask(signal.<how>, signals)`` where there is one (not on Windows)."""
    return signal.pthread_sigmask(getattr(signal, how), signals) if hasattr(signal, "pthread_sigmask") else set()


def _watch(parent: int) -> None:
    while os.getppid() == parent:
        time.sleep(0.5)
    os._exit(1)


def _die_with(parent: int | None) -> None:
    """Worker initializer: ignore Ctrl-C, end on SIGTERM, be killed when the parent dies."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    _mask("SIG_UNBLOCK")
    if not die_with_parent(signal.SIGKILL) and parent is not None:  # not Linux: poll the parent instead
        threading.Thread(target=_watch, args=(parent,), daemon=True).start()
    if parent is not None and os.getppid() != parent:  # the parent died before the above
        os._exit(1)


class _Pool(ProcessPoolExecutor):
    def submit(self, fn, /, *args, **kwargs):
        old = _mask("SIG_BLOCK")  # workers start here and inherit the mask
        try:
            return super().submit(fn, *args, **kwargs)
        finally:
            _mask("SIG_SETMASK", old)


@contextlib.contextmanager
def worker_pool(workers: int, mp_context=None):
    """A :class:`~concurrent.futures.ProcessPoolExecutor` of ``workers`` processes as above;
    on an exception (Ctrl-C included) its workers are killed at once (SIGKILL: a worker still
    starting has SIGTERM blocked; workers write no files, the parent does), then its manager thread
    is awaited (a signal's grace timer ends a command that hangs here)."""
    ctx = mp_context or multiprocessing.get_context()
    parent = os.getpid() if ctx.get_start_method() in ("fork", "spawn") else None  # else a server forks them
    pool = _Pool(workers, mp_context=ctx, initializer=_die_with, initargs=(parent,))
    try:
        yield pool
    except BaseException:
        procs = list((getattr(pool, "_processes", None) or {}).values())
        for proc in procs:
            proc.kill()
        for proc in procs:  # gone before the caller cleans up after them
            proc.join(timeout=2)
        # its manager thread ends now, its workers gone: left running, it raced the interpreter's exit
        # (closing its wake-up pipe while the exit wrote to it: "Exception ignored … Bad file descriptor")
        pool.shutdown(wait=True, cancel_futures=True)
        raise
    pool.shutdown(wait=True)


def run_pool(worker, items, workers: int, on_row=None) -> list[dict]:
    """``worker(item)`` for every item on ``workers`` processes (one BLAS thread each), in order."""
    for var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
        os.environ.setdefault(var, "1")
    rows = []
    with worker_pool(workers, mp_context=multiprocessing.get_context("spawn")) as pool:
        for row in pool.map(worker, items):
            rows.append(row)
            if on_row:
                on_row(row)
    return rows
