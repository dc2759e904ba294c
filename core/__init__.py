"""gatetherm: finite elements for the thermal deformation of machine-tool frames.

The package root holds what every layer shares and nothing else: the version, the one
user-facing error type and atomic file output. The layers, each a sub-package, depend
only on those before them: ``gatetherm.geometry`` → ``gatetherm.solvers`` →
``gatetherm.studies`` → ``gatetherm.validation`` → ``gatetherm.studies.cli``.
"""
from __future__ import annotations

import contextlib
import os
import tempfile
from importlib import metadata
from pathlib import Path

try:
    __version__ = metadata.version("gatetherm")
except metadata.PackageNotFoundError:  # running from a source tree that is not installed
    __version__ = "0+unknown"


class InputError(ValueError):
    """Bad user input. ``str(err)`` is one line naming the field and the fix."""

    def __init__(self, field: str, problem: str, fix: str = ""):
        self.field = field
        msg = f"{field}: {problem}"
        if fix:
            msg += f"; {fix}"
        super().__init__(msg)


@contextlib.contextmanager
def atomic_path(path: str | os.PathLike):
    """Yield a temporary path next to ``path``; rename it onto ``path`` on success.

    The suffix is kept so that writers that dispatch on the file extension
    (meshio, matplotlib) still work. On an exception the temporary file is
    removed and ``path`` keeps its previous content.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.stem}.", suffix=path.suffix, dir=path.parent)
    os.close(fd)
    try:
        yield Path(tmp)
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)
        raise


def write_text_atomic(path: str | os.PathLike, text: str) -> None:
    """Write ``text`` to ``path`` atomically (UTF-8)."""
    with atomic_path(path) as tmp:
        Path(tmp).write_text(text, encoding="utf-8")
