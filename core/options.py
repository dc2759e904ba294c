"""Solver options: one object for the choices a user may make about how gatetherm solves.

:class:`SolverOptions` holds which path solves an SPD system, the memory budget of that choice,
the sparse Cholesky backend and the BLAS threads of a process. It is made from, in order of
precedence, the command line (``gatetherm --solver iterative …``), a TOML file's ``[solver]``
table (``gatetherm --solver-options FILE.toml …``, :meth:`SolverOptions.from_file`) and the
environment variables below, read in one place (:meth:`SolverOptions.from_environment`);
anything left unset is the default, which adapts to the machine (docs/performance.md)::

    import gatetherm as gt
    with gt.SolverOptions(path="iterative", memory_gb=8).use():
        run = gt.run(case)

A command applies its options once as it starts (:func:`gatetherm.configure`); the solvers ask
:func:`current` which options are in force. Processes forked by a run (the elastic helper, a
sweep's workers, the painter) inherit them.
"""
from __future__ import annotations

import contextlib
import contextvars
import math
import os
from dataclasses import dataclass, fields, replace

from gatetherm import InputError

PATHS = ("auto", "direct", "iterative")
BACKENDS = ("auto", "pardiso", "cholmod", "superlu", "amg")
ENVIRONMENT = {"path": "GATETHERM_SOLVER", "memory_gb": "GATETHERM_MEMORY_GB",
               "backend": "GATETHERM_SPD_BACKEND", "blas_threads": "GATETHERM_BLAS_THREADS"}
"""The environment variable of each option."""


@dataclass(frozen=True)
class SolverOptions:
    """How gatetherm solves; every field ``None`` or ``"auto"`` leaves the choice to it."""

    path: str = "auto"
    """``"direct"`` (sparse Cholesky) or ``"iterative"`` (AMG-preconditioned CG) for every SPD
    system; ``"auto"``: per system, by predicted time and memory (:mod:`gatetherm.solvers.plan`)."""
    memory_gb: float | None = None
    """Memory the solvers may hold, GB; ``None``: three quarters of the machine's memory."""
    backend: str = "auto"
    """Sparse Cholesky backend of the direct path (``"pardiso"``, ``"cholmod"``, ``"superlu"``), or
    ``"amg"``: the iterative path for elasticity; ``"auto"``: the first one installed."""
    blas_threads: int | None = None
    """BLAS threads of a command's process; ``None``: half the machine's cores, at least one (a
    run keeps two processes busy: the heat march and the elastic helper)."""

    def __post_init__(self):
        for name, allowed in (("path", PATHS), ("backend", BACKENDS)):
            if getattr(self, name) not in allowed:
                raise InputError(f"solver option {name}", f"got {getattr(self, name)!r}",
                                 f"one of {', '.join(allowed)}")
        gb = self.memory_gb
        if gb is not None and (isinstance(gb, bool) or not isinstance(gb, (int, float)) or not math.isfinite(gb)
                               or gb <= 0):
            raise InputError("solver option memory_gb", f"got {gb!r}", "a number of gigabytes > 0, e.g. 8")
        n = self.blas_threads
        if n is not None and (isinstance(n, bool) or not isinstance(n, int) or not 1 <= n <= 4096):
            raise InputError("solver option blas_threads", f"got {n!r}", "a whole number of threads, at least 1")

    @classmethod
    def from_environment(cls, env: dict | None = None) -> SolverOptions:
        """The options the environment variables of :data:`ENVIRONMENT` set (``env``: a mapping
        instead of ``os.environ``); a bad value raises :class:`~gatetherm.InputError` naming the
        variable."""
        env = os.environ if env is None else env
        given = {}
        for name, var in ENVIRONMENT.items():
            text = env.get(var, "").strip()
            if not text:
                continue
            try:
                given[name] = _parse(name, text)
                cls(**{name: given[name]})
            except (InputError, ValueError):
                raise InputError(f"environment variable {var}", f"got {text!r}", _HELP[name]) from None
        return cls(**given)

    @classmethod
    def from_file(cls, path, base: SolverOptions | None = None) -> SolverOptions:
        """The options of the ``[solver]`` table of a TOML file (keys: the field names), the
        others those of ``base`` (default: the defaults)."""
        from gatetherm.files import parse_toml, read_text

        table = parse_toml(read_text(path, str(path), "give a readable TOML file"), str(path),
                           what="TOML").get("solver", {})
        names = {f.name for f in fields(cls)}
        if not isinstance(table, dict) or set(table) - names:
            raise InputError(f"{path}: [solver]", f"unknown keys {sorted(set(table) - names)}",
                             f"the keys are {', '.join(sorted(names))}")
        try:
            return replace(base or cls(), **table)
        except InputError as err:
            raise err.at(f"{path}: [solver]") from None

    def merged(self, **given) -> SolverOptions:
        """These options with those of ``given`` that are not ``None`` in their place."""
        return replace(self, **{k: v for k, v in given.items() if v is not None})

    def threads(self) -> int:
        """The BLAS threads these options give on this machine."""
        return self.blas_threads or max(1, (os.cpu_count() or 1) // 2)

    @contextlib.contextmanager
    def use(self):
        """These options in force for the solvers within the ``with`` block."""
        token = _CURRENT.set(self)
        try:
            yield self
        finally:
            _CURRENT.reset(token)


_HELP = {"path": "direct, iterative or auto", "memory_gb": "a number of gigabytes > 0, e.g. 8",
         "backend": ", ".join(BACKENDS), "blas_threads": "a whole number of at least 1, or unset it"}
_CURRENT: contextvars.ContextVar[SolverOptions | None] = contextvars.ContextVar("gatetherm_solver_options",
                                                                                default=None)


def _parse(name: str, text: str):
    if name == "memory_gb":
        return float(text)
    if name == "blas_threads":
        if not text.isdigit():
            raise ValueError(text)
        return int(text)
    return text


def current() -> SolverOptions:
    """The options in force: those of an enclosing :meth:`SolverOptions.use` (or of
    :func:`gatetherm.configure`), else the environment's."""
    return _CURRENT.get() or SolverOptions.from_environment()


def set_current(options: SolverOptions) -> None:
    """Put ``options`` in force for the rest of this context (a command, as it starts)."""
    _CURRENT.set(options)
