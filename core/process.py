"""Process-wide settings a command makes before its numerics, each measured on the 3-D
frame (``benchmarks/blas_threads.py``, ``benchmarks/peer.py``; docs/performance.md):

* BLAS threads: half the cores, at least one (the solver option ``blas_threads``,
  ``GATETHERM_BLAS_THREADS``, overrides), through threadpoolctl;
* glibc's malloc keeps what is freed for the next arrays (no block mapped alone, the heap never
  trimmed: :func:`keep_freed`) where the host takes back the memory its guest frees (free page
  reporting: :func:`host_reclaims_freed_memory`), since each page of a new array is otherwise
  faulted in anew, at the host's cost, in system time. What a phase has freed goes back to the
  system where it ends (:func:`give_back`: before a fork, after a helper's set-up, before a run's
  files), so that the processes beside it do not hold it. Measured by ``benchmarks/blas_threads.py
  --malloc`` and ``benchmarks/scaling.py`` (docs/performance.md, "Process settings");
* numpy's advice of transparent huge pages for its arrays of 4 MiB and more off on a virtual
  machine (:func:`virtual_machine`), unless numpy's own ``NUMPY_MADVISE_HUGEPAGE`` is set: on a virtual machine whose host backs the
  guest's memory as it is first touched (this one) the faults of 2 MiB pages cost more system
  time than the 4 KiB pages' they replace. ``simulate --condition 1 --dim 3``: 15.48 s against
  19.03 s, 3.97 s of system time against 6.33 s (medians of 5 interleaved runs,
  ``benchmarks/blas_threads.py --huge-pages``, with the malloc settings before);

* a long-running service's heap frozen once it is set up (:func:`frozen_heap`: the objects alive
  then, a server's address space or the imported modules, left out of the collector's full passes,
  which otherwise stop the whole process for as long as they take to scan them all);

and, for the child processes gatetherm starts (gmsh's, a sweep's workers, the painter's, a
solve's helper), :func:`fork`, :func:`can_fork`, :func:`die_with_parent` and the messages of
their pipes (:func:`message`, :func:`send`, :func:`receive`: a pickle behind its length).
"""
from __future__ import annotations

import contextlib
import ctypes
import functools
import gc
import logging
import os
import pickle
import struct

from gatetherm import InputError
from gatetherm.options import SolverOptions

log = logging.getLogger(__name__)

HUGE_PAGES_ENV = "NUMPY_MADVISE_HUGEPAGE"
"""numpy's switch of its huge-page advice: where it is set, :func:`configure` leaves the advice
as numpy made it."""
_M_TRIM_THRESHOLD, _M_MMAP_THRESHOLD, _M_MMAP_MAX = -1, -3, -4
PR_SET_PDEATHSIG = 1
"""prctl(2) option: the signal a Linux process gets when its parent dies."""


def can_fork() -> bool:
    """Whether this process may fork a helper beside itself: POSIX, more than one core, no other
    thread running (a forked child would miss it, and any lock it holds), and not itself a
    worker of a pool (whose siblings have the other cores)."""
    import multiprocessing
    import threading

    return (hasattr(os, "fork") and (os.cpu_count() or 1) > 1 and threading.active_count() == 1
            and multiprocessing.parent_process() is None)


@functools.cache
def _libc():
    """glibc, or None (another C library: its malloc is left as it is)."""
    try:
        libc = ctypes.CDLL("libc.so.6")
        return libc if hasattr(libc, "mallopt") and hasattr(libc, "malloc_trim") else None
    except OSError:
        return None


def keep_freed(keep: bool) -> None:
    """Whether glibc's malloc keeps the memory freed in this process for its next arrays
    (:func:`configure` makes it so: no block mapped alone, the heap never trimmed), or returns
    blocks of 4 MiB and more to the system when they are freed and trims its heap past 64 MiB
    (a painting process's, which waits between pictures)."""
    libc = _libc()
    if libc is None:
        log.debug("no glibc: malloc settings left as they are")
    elif keep:
        libc.mallopt(_M_MMAP_MAX, 0)
        libc.mallopt(_M_TRIM_THRESHOLD, -1)
    else:
        libc.mallopt(_M_MMAP_MAX, 1 << 16)  # glibc's own
        libc.mallopt(_M_MMAP_THRESHOLD, 4 << 20)
        libc.mallopt(_M_TRIM_THRESHOLD, 64 << 20)


def give_back() -> None:
    """Return the memory this process has freed, and keeps for reuse since :func:`configure`,
    to the system (glibc's ``malloc_trim``): where a phase ends whose arrays will not be made
    again."""
    libc = _libc()
    if libc is not None:
        libc.malloc_trim(0)


def fork() -> int:
    """``os.fork()`` after :func:`give_back`: the child shares no freed pages, which either
    process would otherwise copy as it reuses them. SIGINT and SIGTERM are held during the fork:
    a handler that raises (the command's, a painter's) would raise inside the fork's hooks
    (``os.register_at_fork``: logging's), where the exception is printed and ignored, so that the
    signal were lost; held, it is raised in this process as the fork returns. The child starts
    with their default actions (end quietly), so that a signal that reaches it while Python sets
    it up (the parent ending its helpers at once) is no traceback from the parent's handler; a
    child that wants them sets its own."""
    import signal
    import threading

    give_back()
    if not hasattr(signal, "pthread_sigmask"):
        return os.fork()
    held = {signal.SIGINT, signal.SIGTERM}
    old = signal.pthread_sigmask(signal.SIG_BLOCK, held)
    try:
        pid = os.fork()
        if pid == 0 and threading.current_thread() is threading.main_thread():
            for sig in held:
                if signal.getsignal(sig) is not signal.SIG_IGN:
                    signal.signal(sig, signal.SIG_DFL)
        return pid
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, old)


NATIVE = ("numpy", "scipy.linalg", "scipy.sparse.linalg", "pymklpardiso._mkl_pardiso")
"""The libraries whose import starts native threads (their BLAS); optional ones may be missing."""


def start_libraries(signals=None) -> None:
    """Import :data:`NATIVE` with ``signals`` (default SIGINT, SIGTERM) blocked, so that the threads
    they start never take them: a signal then reaches the main thread only, which may defer it
    around C code that traps it (METIS: :func:`gatetherm.solvers.cholesky._signals_deferred`).
    The command line calls it first, with the signals already blocked while it imports
    :mod:`gatetherm.api` (which imports numpy); the API imports the rest when first used."""
    import importlib
    import signal

    if not hasattr(signal, "pthread_sigmask"):
        return
    held = signal.pthread_sigmask(signal.SIG_BLOCK, signals or {signal.SIGINT, signal.SIGTERM})
    try:
        for name in NATIVE:
            with contextlib.suppress(ImportError):
                importlib.import_module(name)
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, held)


@contextlib.contextmanager
def frozen_heap():
    """While the block runs, the objects alive at its start are left out of the garbage
    collector's passes (``gc.freeze`` after one full collection; ``gc.unfreeze`` after): for a
    service's loop, whose set-up (modules, a server's address space) would otherwise be scanned by
    every full collection: a pause of the whole process of ~65 CPU-ms for a ``live`` service, ~220
    for a ``twin`` of 100 machines (``benchmarks/live_gc.py``), 0 frozen."""
    gc.collect()
    gc.freeze()
    try:
        yield
    finally:
        gc.unfreeze()


def die_with_parent(sig: int) -> bool:
    """Have the kernel send ``sig`` to this process when its parent ends, even by SIGKILL
    (Linux ``prctl(PR_SET_PDEATHSIG)``); whether it could (False elsewhere)."""
    try:
        return ctypes.CDLL(None, use_errno=True).prctl(PR_SET_PDEATHSIG, int(sig), 0, 0, 0) == 0
    except (OSError, AttributeError, TypeError):
        return False


def end_with_parent() -> bool:
    """A helper process's signals: SIGTERM when its parent ends (:func:`die_with_parent`), and
    SIGTERM raises SystemExit, so that its ``finally`` blocks run (a temporary file removed);
    Ctrl-C is left to the parent, which ends its helpers. Whether the kernel will send it."""
    import signal

    def stop(*_):
        raise SystemExit(1)
    signal.signal(signal.SIGTERM, stop)
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    return die_with_parent(signal.SIGTERM)


def message(obj) -> bytes:
    """``obj`` as one message of a pipe: its pickle behind its length."""
    data = pickle.dumps(obj, protocol=pickle.HIGHEST_PROTOCOL)
    return struct.pack("<Q", len(data)) + data


def send(fd: int, obj) -> None:
    """Write ``obj`` as one :func:`message` to ``fd`` (all of it)."""
    view = memoryview(message(obj))
    while view:
        view = view[os.write(fd, view):]


def receive(fd: int):
    """The next message's object on ``fd``, or None at its end (or where the pipe ends inside one)."""
    head = _read(fd, 8)
    body = None if head is None else _read(fd, struct.unpack("<Q", head)[0])
    return None if body is None else pickle.loads(body)


def _read(fd: int, n: int) -> bytes | None:
    buf = bytearray()
    while len(buf) < n:
        chunk = os.read(fd, n - len(buf))
        if not chunk:
            return None
        buf += chunk
    return bytes(buf)


def _huge_page_advice(on: bool) -> bool | None:
    """Set numpy's advice of huge pages for its large arrays; what it was (None: this numpy has
    no such switch)."""
    import numpy as np

    core = getattr(np, "_core", None) or np.core
    switch = getattr(core.multiarray, "_set_madvise_hugepage", None)
    if switch is None:
        log.debug("numpy has no huge-page switch: left as it is")
        return None
    return bool(switch(on))


def host_reclaims_freed_memory() -> bool:
    """Whether this (virtual) machine reports the memory its processes free to its host, which
    takes it back (free page reporting: ``page_reporting`` on the kernel's command line), so
    that a page touched again is faulted in anew at the host's cost."""
    try:
        with open("/proc/cmdline") as f:
            return "page_reporting" in f.read()
    except OSError:
        return False


def virtual_machine() -> bool:
    """Whether this process runs under a hypervisor (the CPU's ``hypervisor`` flag, Linux)."""
    try:
        with open("/proc/cpuinfo") as f:
            return any(line.startswith("flags") and " hypervisor" in line for line in f)
    except OSError:
        return False


def configure(options: SolverOptions | None = None):
    """Set up the running process for gatetherm's numerics, as every command does first.

    Each setting adapts to the machine it runs on (docs/performance.md has the measurement
    behind each):

    * BLAS threads: the solver option ``blas_threads`` (``GATETHERM_BLAS_THREADS``), by default
      half the machine's cores, at least one, so that a run's two busy processes (the heat march
      and the elastic helper) and a sweep's workers do not oversubscribe the cores;
    * glibc's malloc keeping freed memory, large arrays too, for the next arrays (:func:`keep_freed`;
      :func:`give_back` returns it) where the host takes back what its guest frees
      (:func:`host_reclaims_freed_memory`);
    * numpy's huge-page advice off on a virtual machine (:func:`virtual_machine`), unless
      ``NUMPY_MADVISE_HUGEPAGE`` is set.

    Optional in a script.

    Parameters
    ----------
    options : gatetherm.SolverOptions, optional
        The solver options; they stay in force for the rest of the caller's context. Default:
        those of the environment variables (:meth:`gatetherm.SolverOptions.from_environment`),
        which a bad value of is refused here, before any numerics.

    Returns
    -------
    gatetherm.SolverOptions
        The options in force.
    """
    from gatetherm.options import set_current

    if options is None:
        options = SolverOptions.from_environment()
    elif not isinstance(options, SolverOptions):
        raise TypeError(f"options: got {type(options).__name__}; give a gatetherm.SolverOptions")
    else:
        set_current(options)
    keep_freed(host_reclaims_freed_memory())
    if HUGE_PAGES_ENV not in os.environ and virtual_machine():
        _huge_page_advice(False)
    from threadpoolctl import threadpool_limits

    threads = options.threads()
    threadpool_limits(threads, user_api="blas")
    log.debug("BLAS threads: %d", threads)
    return options
