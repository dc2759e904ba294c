"""The output directory of a run: a transaction, made ready before anything is computed.

:func:`output_dir` checks that the directory can be created and written (not a file, no
file above it, not read-only), takes a lock on it so that a second run into it is refused
at once, and yields a *stage*: a hidden folder inside it (named :data:`gatetherm.TEMP_PREFIX`...)
that the command writes its files into. Only when the command succeeds do the staged files
replace the previous run's (the files the command owns, its output set, that this run did not
write again are removed then), so that the directory holds exactly the files of this run. A
refusal, an error, Ctrl-C or SIGTERM removes the stage and leaves the previous results as they
were; a kill -9 leaves them too, and its stage is removed by the next command into the
directory. Every command that writes files runs inside it.
"""
from __future__ import annotations

import contextlib
import logging
import os
import shutil
import signal
import threading
from pathlib import Path

from gatetherm import TEMP_PREFIX, InputError, _new_temporary

try:
    import fcntl
except ImportError:  # not POSIX: no lock
    fcntl = None

log = logging.getLogger(__name__)

LOCK = ".gatetherm.lock"
"""The lock file a run holds in its output directory; removed when the run ends."""


class OutputError(OSError):
    """The output directory cannot be used (cannot be created or written, or another run
    is writing into it). ``str(err)`` is one line; the command exits with 1."""


def check_path(out: Path, option: str = "--out") -> list[Path]:
    """The directories that must be created for ``out``, deepest last; InputError for a file in the way
    (a command whose folder is not an :func:`output_dir` transaction, as ``live``'s, checks it here too)."""
    missing = []
    for p in (out, *out.parents):
        if p.is_dir():
            break
        if p.exists() or p.is_symlink():
            what = "exists and is not a directory" if p == out else f"lies below '{p}', which is not a directory"
            raise InputError(option, f"'{out}' {what}", "give a directory path")
        missing.append(p)
    return missing[::-1]


def _lock(out: Path) -> int | None:
    if fcntl is None:
        return None
    path = out / LOCK
    while True:
        fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o666)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            pid = os.read(fd, 32).decode(errors="replace").strip() or "?"
            os.close(fd)
            raise OutputError(f"{out}: another gatetherm run (pid {pid}) is writing into this directory; "
                              "wait for it to end or choose another --out") from None
        try:  # a run that ended between our open and flock removed the file: lock the new one
            if os.stat(path).st_ino == os.fstat(fd).st_ino:
                break
        except FileNotFoundError:
            pass
        os.close(fd)
    os.ftruncate(fd, 0)
    os.write(fd, f"{os.getpid()}\n".encode())
    return fd


def _unlock(out: Path, fd: int | None) -> None:
    if fd is not None:
        with contextlib.suppress(OSError):
            os.unlink(out / LOCK)
        os.close(fd)


def _clean(out: Path) -> None:
    """Remove the temporaries (files and stages) that a killed or failed run left in ``out``."""
    removed = 0
    for p in [*out.glob(f"{TEMP_PREFIX}*"), *out.glob(f"*/{TEMP_PREFIX}*")]:
        if p.is_dir() and not p.is_symlink():
            shutil.rmtree(p, ignore_errors=True)
            removed += 1
        elif p.is_file() or p.is_symlink():
            with contextlib.suppress(FileNotFoundError):
                p.unlink()
            removed += 1
    if removed:
        log.info("%s: removed %d temporaries of a previous run", out, removed)


def _stage(out: Path, stage: Path) -> None:
    """Remove what killed runs left in ``out``, then make the new run's empty ``stage``."""
    _clean(out)
    stage.mkdir()


def _commit(stage: Path, out: Path, owns, keep) -> None:
    """Move the staged files into ``out`` (each by an atomic rename), then remove the files of
    the output set ``owns`` that this run did not write; keep the input files ``keep``."""
    keep = {Path(k).resolve() for k in keep if k is not None}
    staged = sorted(p.relative_to(stage) for p in stage.rglob("*") if not p.is_dir())
    for rel in staged:
        (out / rel).parent.mkdir(parents=True, exist_ok=True)
        os.replace(stage / rel, out / rel)
    written = {(out / rel).resolve() for rel in staged}
    removed = 0
    for p in (p for g in owns for p in out.glob(g)):
        if (p.is_file() or p.is_symlink()) and p.resolve() not in written | keep:
            p.unlink()
            removed += 1
    if removed:
        log.info("%s: removed %d files of the previous run", out, removed)
    shutil.rmtree(stage, ignore_errors=True)


def _refuse_overwriting(out: Path, owns, keep, option: str) -> None:
    """InputError if an input file of the run (``keep``) is one of the files it writes."""
    if not out.is_dir():
        return
    written = {p.resolve() for g in owns for p in out.glob(g)}
    for k in keep:
        if k is not None and Path(k).resolve() in written:
            raise InputError(option, f"the run would overwrite its input '{k}' in '{out}'",
                             "choose another output directory, or move the input out of it")


@contextlib.contextmanager
def output_dir(path: str | os.PathLike, owns=(), keep=(), option: str = "--out"):
    """Yield the stage of a run into ``path``: a new empty folder inside ``path`` (a
    :class:`~pathlib.Path`) to write this run's files into. ``path`` is created if needed,
    checked to be writable and locked against other runs; the temporaries of a killed run are
    removed. When the block ends without an exception, the staged files replace those in
    ``path`` and the files matching the glob patterns ``owns`` (the command's output set,
    relative to ``path``) that this run did not write are removed; on any exception (a
    refusal, Ctrl-C) the stage is removed and ``path`` keeps the previous run's files. The
    run's input files ``keep`` (None entries are skipped) are never removed or overwritten:
    one that is among the files the command writes is refused. A directory this call created
    is removed again if the run fails. Files a command keeps across runs (a cache, a sweep's
    points) are written into ``path`` itself, not the stage. Raises InputError (``option``
    names a file) or :class:`OutputError` (cannot write, locked)."""
    out = Path(path)
    created = check_path(out, option)
    _refuse_overwriting(out, owns, keep, option)
    try:
        out.mkdir(parents=True, exist_ok=True)
        os.unlink(_new_temporary(out / "probe"))
        fd = _lock(out)
    except OutputError:
        raise
    except OSError as err:
        raise OutputError(f"{out}: cannot write into this directory ({err.strerror or err})") from None
    stage = out / f"{TEMP_PREFIX}stage.{os.urandom(4).hex()}"
    try:
        _stage(out, stage)
        yield stage
        _refuse_staged_inputs(stage, out, keep, option)
        with _signals_held():  # a Ctrl-C now would leave half the new files beside half the old
            _commit(stage, out, owns, keep)
    except BaseException as err:
        with contextlib.suppress(OSError), _signals_held():  # a second signal cannot cut the cleanup short
            _clean(out)  # the stage, and temporaries of writers cut short (a worker terminated mid-write)
        _unlock(out, fd)
        fd = None
        for d in reversed(created):
            with contextlib.suppress(OSError):
                d.rmdir()  # only if empty
        if isinstance(err, OSError) and err.errno is not None and str(err.filename or "").startswith(f"{stage}/"):
            where = out / Path(err.filename).relative_to(stage)  # the file's name in the directory, not the stage's
            raise OSError(err.errno, err.strerror, str(where)) from err
        raise
    finally:
        _unlock(out, fd)


@contextlib.contextmanager
def _signals_held():
    """SIGINT and SIGTERM held until the block ends, then delivered to the handlers in force
    before it (a signal mask would not do: a process-directed signal goes to any thread not
    masking it, the BLAS threads). Only the main thread can; elsewhere nothing is held."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    got: list[int] = []
    old = {s: signal.signal(s, lambda n, _: got.append(n)) for s in (signal.SIGINT, signal.SIGTERM)}
    try:
        yield
    finally:
        for s, h in old.items():
            signal.signal(s, h if h is not None else signal.SIG_DFL)
        if got:
            signal.raise_signal(got[0])


def _refuse_staged_inputs(stage: Path, out: Path, keep, option: str) -> None:
    """InputError if a staged file would replace an input file of the run."""
    keep = {Path(k).resolve() for k in keep if k is not None}
    for p in stage.rglob("*"):
        if not p.is_dir() and (out / p.relative_to(stage)).resolve() in keep:
            raise InputError(option, f"the run would overwrite its input '{out / p.relative_to(stage)}'",
                             "choose another output directory, or move the input out of it")
