"""gatetherm: finite elements for the thermal deformation of machine-tool frames.

The package root holds what every layer shares and nothing else: the version, the one
user-facing error type and atomic file output (``gatetherm.checks``: admissible values,
``gatetherm.files``: reading input files, ``gatetherm.outdir``: output directories). The
layers, each a sub-package, depend only on those before them: ``gatetherm.geometry`` →
``gatetherm.solvers`` → ``gatetherm.studies`` → ``gatetherm.validation`` → ``gatetherm.cli``.

The public API (:mod:`gatetherm.api`: ``gt.load_case``, ``gt.gate_frame``, ``gt.run`` …, and
``gt.plot``) is reached through this package's names, imported on first use: importing it stays
cheap (no third-party or slow standard modules), so that the console command is inside its own
error handling almost at once, and a notebook pays only for what it uses.
"""
from __future__ import annotations

import contextlib
import errno
import os
from pathlib import Path

TEMP_PREFIX = ".gatetherm-tmp."
"""Name prefix of the temporary files of :func:`atomic_path`; a run removes those a killed
run left in its output directory (:mod:`gatetherm.outdir`)."""


def _api_modules(folders=None) -> dict[str, str]:
    """Where :mod:`gatetherm.api` finds each name it offers: name -> the module (of ``folders``,
    default the package's) whose ``PUBLIC`` offers it, read from the sources (importing the API
    costs seconds; this a few milliseconds). A name offered by two modules is an ImportError."""
    import ast

    where = {}
    for path in sorted(p for folder in folders or [Path(__file__).parent / "api"] for p in Path(folder).glob("*.py")):
        for node in ast.parse(path.read_text(encoding="utf-8")).body:
            if isinstance(node, ast.Assign) and any(getattr(t, "id", None) == "PUBLIC" for t in node.targets):
                for name in ast.literal_eval(node.value):
                    if name in where and where[name] != path.stem:
                        raise ImportError(f"gatetherm.api.{path.stem}: {name} is offered by gatetherm.api."
                                          f"{where[name]} too")
                    where[name] = path.stem
    return where


def _api(folders=None) -> tuple[str, ...]:
    """The names :mod:`gatetherm.api` offers: the ``PUBLIC`` of each of its modules (in ``folders``,
    default the package's), read from their sources (:func:`_api_modules`)."""
    return tuple(sorted(_api_modules(folders)))


def __getattr__(name: str):
    """``gatetherm.API``: the names of :mod:`gatetherm.api` offered here (imported on first use), and
    each of them, and ``plot``."""
    if name == "API":
        globals()["API"] = value = _api()
        return value
    here = Path(__file__).parent
    module = (here / f"{name}.py").exists() or (here / name / "__init__.py").exists()  # `from gatetherm import checks`
    if name == "plot" or (not name.startswith("_") and not module and name in __getattr__("API")):
        import importlib

        value = (importlib.import_module("gatetherm.validation.plots.api") if name == "plot"
                 else getattr(importlib.import_module("gatetherm.api"), name))
        globals()[name] = value
        return value
    if name == "__version__":  # looked up on first use: importlib.metadata is slow to import
        from importlib import metadata

        try:
            version = metadata.version("gatetherm")
        except metadata.PackageNotFoundError:  # a source tree that is not installed
            version = "0+unknown"
        globals()["__version__"] = version
        return version
    raise AttributeError(f"module 'gatetherm' has no attribute {name!r}")


def one_line(text: str, limit: int = 300) -> str:
    """``text`` as a terminal shows it safely: control characters escaped (a user's text may
    carry a terminal's escape sequences or a line break), and cut in the middle beyond ``limit``
    characters."""
    text = "".join(c if c.isprintable() else repr(c)[1:-1] for c in str(text))
    return text if len(text) <= limit else f"{text[:limit // 2]} … ({len(text)} characters) … {text[-limit // 4:]}"


class InputError(ValueError):
    """Bad user input. ``str(err)`` is one line naming the field and the fix (each part at most
    a few hundred characters, control characters escaped: :func:`one_line`)."""

    def __init__(self, field: str, problem: str, fix: str = ""):
        self.field, self.problem, self.fix = field, problem, fix
        msg = f"{one_line(field)}: {one_line(problem, 600)}"
        if fix:
            msg += f"; {one_line(fix, 600)}"
        super().__init__(msg)

    def __reduce__(self):  # picklable, so that a worker process can report it
        return type(self), (self.field, self.problem, self.fix)

    def at(self, where: str, sep: str = ": ") -> InputError:
        """The same error with ``where`` (a file, a table) put before the field."""
        if not where or self.field.startswith(f"{where}{sep}"):
            return self
        return type(self)(f"{where}{sep}{self.field}", self.problem, self.fix)


class UnknownName(InputError, KeyError):
    """A name that is not among those offered (a run's column, a field): an InputError naming
    them, and a KeyError for the code that looks names up."""

    __str__ = Exception.__str__


def _new_temporary(path: Path) -> Path:
    """Create an empty file beside ``path`` with a fresh name; the umask sets its mode."""
    while True:
        tmp = path.with_name(f"{TEMP_PREFIX}{path.stem}.{os.urandom(4).hex()}{path.suffix}")
        try:
            os.close(os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666))
            return tmp
        except FileExistsError:
            continue


@contextlib.contextmanager
def atomic_path(path: str | os.PathLike):
    """Yield a temporary path next to ``path``; rename it onto ``path`` on success.

    The suffix is kept so that writers that dispatch on the file extension
    (meshio, matplotlib) still work; the file gets the permissions of the umask,
    as a plain ``open`` would. On an exception (a full disk, Ctrl-C) the temporary
    file is removed and ``path`` keeps its previous content; an ``OSError`` is raised
    again naming ``path`` (writers do not always name the file).
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = _new_temporary(path)
    try:
        yield tmp
        os.replace(tmp, path)
    except BaseException as err:
        with contextlib.suppress(OSError):
            os.unlink(tmp)
        if isinstance(err, OSError) and err.errno is not None:
            raise OSError(err.errno, err.strerror, str(path)) from err
        if type(err) is OSError:  # numpy's short write names neither the file nor the cause
            raise OSError(errno.EIO, f"cannot write it all ({err}; is the disk full?)", str(path)) from err
        raise


def write_text_atomic(path: str | os.PathLike, text: str) -> None:
    """Write ``text`` to ``path`` atomically (UTF-8)."""
    with atomic_path(path) as tmp:
        Path(tmp).write_text(text, encoding="utf-8")
