"""Which path solves an SPD system: a sparse Cholesky factor or AMG-preconditioned conjugate
gradients (:mod:`.iterative`), chosen by predicted time for the right-hand sides expected and
predicted memory (of the paths that fit the budget and are about as fast as the fastest, the
one needing less memory), and logged in one line.

The predictions are those of :mod:`gatetherm.geometry.sizing` (memory) and the time constants
below, measured on the 3-D frame at 1, 2 and 4 times its default nodes (52 812 to 177 283,
``benchmarks/scaling.py``): a factor's flops grow as nodes^2.05 and its entries as
nodes^1.46, a CG iteration as the matrix's entries. The solver options
(:class:`gatetherm.options.SolverOptions`: ``path`` = ``direct`` or ``iterative``, from the command
line, a ``[solver]`` file or ``GATETHERM_SOLVER``) force a path; ``memory_gb``
(``GATETHERM_MEMORY_GB``) sets the budget (default: three quarters of this machine's memory).
"""
from __future__ import annotations

import logging
import os
from dataclasses import dataclass

from gatetherm import options
from gatetherm.geometry import sizing

log = logging.getLogger(__name__)

PATH_ENV = options.ENVIRONMENT["path"]
BUDGET_ENV = options.ENVIRONMENT["memory_gb"]
PATHS = ("direct", "iterative")
FLOP_RATE = 22e9
"""Flops per second of the numerical factorisation (PARDISO, one thread)."""
SECONDS_PER_ENTRY = {"analysis": 2.5e-8, "solve": 2e-9}
"""Seconds per entry of the factor: the analysis and allocation of a factorisation, and one
forward and backward substitution."""
SECONDS_PER_NONZERO = {"setup": {1: 3e-7, 3: 5e-7}, "iteration": {1: 1e-8, 3: 9e-9}}
"""Seconds per matrix nonzero, by DOFs per node: the AMG set-up and one preconditioned CG
iteration (V-cycle and product): 6.6 and 48 ms on the heat matrices of 0.72 and 4.8 million
nonzeros, 56 ms on the elastic one of 6.3 million."""
ITERATIONS = {"warm": {1: 6, 3: 20}, "cold": {1: 15, 3: 25}}
"""CG iterations of a solve at the default mesh, by DOFs per node: started from the Galerkin
projection onto the previous solutions of a sequence (a heat step: 4.4 measured at the
default mesh, 5.8 at 8 times its nodes; 2.4 and 2.9 since 2026-12-06, left at 6 so that the
default mesh keeps its heat factors, whose δ the DOLFINx comparison needs to 1e-6 µm), or from
zero (a heat step matrix 13, elasticity 25)."""
ITERATION_GROWTH = 0.1
"""Iterations grow as nodes to this power: a heat step's 2.4, 2.6, 2.7, 2.9 and the first elastic
solve's 23, 27, 30, 22 at 1, 2, 4, 8 × the default 3-D nodes (fitted 0.10 and −0.01; 2026-12-06,
the run of ``benchmarks/scaling.py`` on the iterative path, counted). With 0.25 (from the elastic
iterations of 2026-12-01: 23, 30, 32 at 1, 2, 4 ×) the heat steps of 30 s at 2 to 8 × were
factored, and those runs took 1.25 to 1.43 times as long as on the iterative path
(docs/performance.md)."""
CLOSE = 1.25
"""A path predicted within this factor of the fastest's time counts as fast: of those, the one
needing less memory is taken (the elastic system of the 3-D frame for its two adjoint
solves: a factor 5.8 s and 0.88 GB, AMG-CG 6.0 s and 0.24 GB)."""


@dataclass(frozen=True)
class Plan:
    """The chosen path and what each path was predicted to cost."""

    path: str
    seconds: dict[str, float]
    bytes: dict[str, float]
    budget: float
    forced: bool = False

    def describe(self, what: str, rhs: int) -> str:
        costs = "; ".join(f"{p} {self.seconds[p]:.3g} s, {self.bytes[p] / 1e9:.3g} GB" for p in PATHS)
        why = f"forced by the solver option path ({PATH_ENV})" if self.forced else f"budget {self.budget / 1e9:.3g} GB"
        return f"{what}: {self.path} ({rhs} right-hand side{'s' if rhs != 1 else ''}: {costs}; {why})"


def budget() -> float:
    """Memory the solvers may hold, bytes: the solver option ``memory_gb``
    (:func:`gatetherm.options.current`) or 3/4 of this machine's."""
    gb = options.current().memory_gb
    return 0.75 * sizing.memory_bytes() if gb is None else gb * 1e9


def forced_path() -> str | None:
    """The path the solver option ``path`` forces, if any."""
    path = options.current().path
    return None if path == "auto" else path


def predict(n: int, nnz: int, block: int, dim: int, rhs: int, factored: bool = False,
            warm: bool = False) -> tuple[dict, dict]:
    """Predicted (seconds, bytes) of each path for ``rhs`` solves with an SPD matrix of ``n``
    unknowns (``block`` per node) and ``nnz`` nonzeros on a ``dim``-D mesh; ``factored``: the
    factor exists already; ``warm``: the solves are a sequence, each close to the last ones."""
    nodes = n / block
    entries = sizing.factor_entries(nodes, dim, block)
    direct = rhs * SECONDS_PER_ENTRY["solve"] * entries
    if not factored:
        direct += sizing.factor_flops(nodes, dim, block) / FLOP_RATE + SECONDS_PER_ENTRY["analysis"] * entries
    b = 3 if block > 1 else 1
    its = ITERATIONS["warm" if warm else "cold"][b] * max(nodes / sizing.REFERENCE_NODES, 1.0) ** ITERATION_GROWTH
    iterative = nnz * (SECONDS_PER_NONZERO["setup"][b] + rhs * its * SECONDS_PER_NONZERO["iteration"][b])
    return ({"direct": direct, "iterative": iterative},
            {"direct": sizing.factor_bytes(nodes, dim, block), "iterative": sizing.amg_bytes(n, nnz)})


def resident_bytes() -> float:
    """Memory this process holds now (resident set) and what its child processes hold of their
    own (private pages: a solver's helper, the painter's processes), bytes; 0 where the system
    does not say."""
    try:
        with open("/proc/self/statm") as f:
            own = float(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE")
    except (OSError, ValueError, IndexError, AttributeError):
        return 0.0
    return own + sum(_private_bytes(pid) for pid in _children())


def _children() -> list[str]:
    try:
        tasks = os.listdir("/proc/self/task")
    except OSError:
        return []
    out = []
    for tid in tasks:
        try:
            with open(f"/proc/self/task/{tid}/children") as f:
                out += f.read().split()
        except OSError:
            continue
    return out


def _private_bytes(pid: str) -> float:
    try:
        with open(f"/proc/{pid}/smaps_rollup") as f:
            return 1024.0 * sum(int(line.split()[1]) for line in f if line.startswith(("Private_Clean:", "Private_Dirty:")))
    except (OSError, ValueError):
        return 0.0


def plan(n: int, nnz: int, block: int, dim: int, rhs: int, held: float | None = None,
         factored: bool = False, warm: bool = False) -> Plan:
    """The path for ``rhs`` solves (see :func:`predict`): of those that fit the :func:`budget`
    beside ``held`` (bytes held already; default: this process's resident memory), the one
    needing less memory among those within :data:`CLOSE` of the fastest; if none fits, the
    smaller."""
    seconds, nbytes = predict(n, nnz, block, dim, rhs, factored, warm)
    room = budget()
    held = resident_bytes() if held is None else held
    forced = forced_path()
    if forced:
        return Plan(forced, seconds, nbytes, room, True)
    fits = [p for p in PATHS if nbytes[p] + held <= room]
    fast = [p for p in fits if seconds[p] <= CLOSE * min(seconds[q] for q in fits)]
    path = min(fast or PATHS, key=nbytes.get)
    if not fits:
        log.warning("no solver path fits the memory budget of %.3g GB: %s (%.3g GB)", room / 1e9, path,
                    nbytes[path] / 1e9)
    return Plan(path, seconds, nbytes, room)
