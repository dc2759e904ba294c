"""The output directory of a run, made ready before anything is computed.

:func:`output_dir` checks that the directory can be created and written (not a file, no
file above it, not read-only), takes a lock on it so that a second run into it is refused
at once, and removes what a previous run left there: temporaries of a killed run (named
:data:`gatetherm.TEMP_PREFIX`...) and the files the command owns (its output set), so that
the directory then holds exactly the files of this run. Every command that writes files
runs inside it.
"""
from __future__ import annotations

import contextlib
import logging
import os
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


def _check_path(out: Path, option: str) -> list[Path]:
    """The directories that must be created for ``out``, deepest last; InputError for a file in the way."""
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


def _clean(out: Path, owns, keep) -> None:
    stale = [*out.glob(f"{TEMP_PREFIX}*"), *out.glob(f"*/{TEMP_PREFIX}*"), *(p for g in owns for p in out.glob(g))]
    keep = {Path(k).resolve() for k in keep if k is not None}
    removed = 0
    for p in stale:
        if (p.is_file() or p.is_symlink()) and p.resolve() not in keep:
            p.unlink()
            removed += 1
    if removed:
        log.info("%s: removed %d files of a previous run", out, removed)


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
    """Yield ``path`` as a :class:`~pathlib.Path`, ready for this run's files: created if
    needed, writable, locked against other runs, with stale temporaries and the files
    matching the glob patterns ``owns`` (the command's output set, relative to ``path``)
    removed. The run's input files ``keep`` (None entries are skipped) are never removed or
    overwritten: one that is among the files the command writes is refused. A directory
    this call created is removed again if the run fails before writing anything into it;
    temporaries left by a failed or interrupted run are removed at once. Raises InputError
    (``option`` names a file) or :class:`OutputError` (cannot write, locked)."""
    out = Path(path)
    created = _check_path(out, option)
    _refuse_overwriting(out, owns, keep, option)
    try:
        out.mkdir(parents=True, exist_ok=True)
        os.unlink(_new_temporary(out / "probe"))
        fd = _lock(out)
    except OutputError:
        raise
    except OSError as err:
        raise OutputError(f"{out}: cannot write into this directory ({err.strerror or err})") from None
    try:
        _clean(out, owns, keep)
        yield out
    except BaseException:
        with contextlib.suppress(OSError):
            _clean(out, (), ())  # temporaries of writers cut short (a worker terminated mid-write)
        _unlock(out, fd)
        fd = None
        for d in reversed(created):
            with contextlib.suppress(OSError):
                d.rmdir()  # only if empty
        raise
    finally:
        _unlock(out, fd)
