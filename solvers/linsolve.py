"""Sparse solvers for the symmetric positive definite systems: heat (the solid's block) and
elasticity.

A Cholesky factorisation in a nested-dissection order (METIS through pymetis) is the workhorse:
:mod:`gatetherm.solvers.cholesky` (its backends pardiso, cholmod and superlu, and the orders; their
names are importable from here too). Which backend runs, and why a better one was skipped, is logged
once (with the pip command); the solver option ``backend`` (``GATETHERM_SPD_BACKEND``) forces one
(``amg``: the iterative path for elasticity). Where a factor would not fit in memory or would cost
more than AMG-preconditioned conjugate gradients (:mod:`.iterative`) for the right-hand sides
expected, :class:`SPDSolver` takes the iterative path instead (:mod:`.plan` predicts both); so does
3-D elasticity without pardiso or cholmod.
"""
from __future__ import annotations

import logging
import os
from typing import Callable

import numpy as np
import scipy.sparse as sp

from gatetherm import options
from gatetherm.solvers.cholesky import (  # noqa: F401 (re-exported)
    BACKENDS, HINTS, NoBackend, Solve, expand_order, nd_order, restrict_order, spd_factor)
from gatetherm.solvers.helper import Pending, SolveHelper
from gatetherm.solvers.iterative import PCG, SolverError  # noqa: F401 (SolverError re-exported)
from gatetherm.solvers.plan import plan

log = logging.getLogger(__name__)

DIRECT_LIMIT_3D = 30_000
"""Largest 3-D elastic system (DOFs) solved by SuperLU when no Cholesky backend is installed."""
RTOL = 1e-8
"""Relative residual at which AMG-preconditioned CG stops on an elastic system: on the 3-D frame
δ within 2.6e-5 µm of the factor's, as at 1e-9 (tests/test_iterative.py), with a tenth fewer
iterations at 4 × the nodes."""
SETTINGS = {"direct_limit_3d": DIRECT_LIMIT_3D, "rtol": RTOL}
"""What the solution depends on, for digests of the numerical scheme."""
BACKEND_ENV = options.ENVIRONMENT["backend"]


def _say_once(key: str, level: int, msg: str, *args, _said: set = set()) -> None:  # noqa: B006
    """Log ``msg`` the first time ``key`` is seen in this process (backend choices)."""
    if key not in _said:
        _said.add(key)
        log.log(level, msg, *args)


class Bordered:
    """Solves with ``[[S, U], [V, D]]``: ``S`` SPD (the solid), a few unknowns last (lumped
    fluids, which make the whole matrix nonsymmetric). ``inner`` solves with ``S`` (a factor
    or AMG-CG, set up once), ``Z = S⁻¹U`` and the small Schur complement ``D − V Z`` are
    formed, and a solve costs one solve with ``S`` and one with the Schur complement."""

    def __init__(self, A: sp.spmatrix, n_inner: int, inner: Solve):
        A = A.tocsr()
        self.n, self.inner = n_inner, inner
        U = A[:n_inner, n_inner:].toarray()
        self.V = A[n_inner:, :n_inner].toarray()
        self.Z = self.inner(U).reshape(n_inner, -1) if U.size else np.zeros((n_inner, 0))
        self.schur = A[n_inner:, n_inner:].toarray() - self.V @ self.Z

    def __call__(self, b: np.ndarray) -> np.ndarray:
        y = self.inner(np.array(b[:self.n], dtype=float))
        if not self.schur.size:
            return y
        last = np.linalg.solve(self.schur, b[self.n:] - self.V @ y)
        return np.concatenate([y - self.Z @ last, last])


def planned_solver(A: sp.spmatrix, dim: int, rhs: int, what: str, block: int = 1, near_null=None,
                   order: np.ndarray | Callable[[], np.ndarray | None] | None = None, rtol: float = RTOL,
                   held: float | None = None,
                   allow=("pardiso", "cholmod", "superlu"), amg_block: int = 1,
                   warm: bool = False, amg=None, shared=None) -> tuple[Solve, str]:
    """A solver of the SPD matrix ``A`` (``block`` DOFs per node of a ``dim``-D mesh) for
    ``rhs`` right-hand sides by the path :func:`.plan.plan` chooses (logged in one line as
    ``what``; ``held``: bytes held already, default this process's): a Cholesky factor of the first
    backend of ``allow`` that installs (``order``: a fill-reducing order, or a function giving it,
    called only then), else AMG-CG to
    ``rtol`` (``near_null``: the rigid-body modes, aggregated by nodes of ``amg_block`` DOFs;
    ``warm``: the right-hand sides are a sequence, each close to the last; ``amg``: the
    :class:`~gatetherm.solvers.iterative.AMG` hierarchy of a nearby matrix to precondition with,
    instead of one of ``A``'s own; ``shared``: the analyses a factor of the same pattern shares,
    :func:`spd_factor`). ``(solve, path)``."""
    A = A.tocsr()
    p = plan(A.shape[0], A.nnz, block, dim, rhs, held, warm=warm)
    log.info("%s", p.describe(f"{what} ({A.shape[0]} unknowns)", rhs))
    if p.path == "direct":
        try:
            return spd_factor(A, order() if callable(order) else order, allow, shared)[0], "direct"
        except NoBackend:
            _say_once(f"amg {what}", logging.INFO, "no Cholesky backend for the %s: AMG-CG; %s", what, HINTS["pardiso"])
    return PCG(A, near_null, amg_block, rtol, amg=amg), "iterative"


class SPDSolver:
    """Solves with one SPD elastic matrix, one batch of right-hand sides at a time, by the
    path :func:`planned_solver` picks for the first batch: a factor or AMG-CG (its Galerkin
    start recycling the earlier solutions). :meth:`release` frees a factor (the 3-D frame's
    holds 0.81 GB): a run keeps the heat solvers, not this one, while it marches, and the
    next batch is planned again. AMG-CG is kept: its memory is a fraction of the matrix's and
    its set-up costs as much as ten solves. :meth:`start` sets AMG-CG up in a helper process
    (:class:`~gatetherm.solvers.helper.SolveHelper`) where the process may fork: then
    :meth:`submit` returns at once, and the caller goes on while the helper solves, till
    :meth:`retire` says no more will come."""

    def __init__(self, A: sp.spmatrix | Pending, dim: int, near_null: np.ndarray | None = None,
                 order: np.ndarray | Callable | None = None, nodal: bool = False, what: str = "elastic system",
                 size: tuple[int, int] | None = None):
        """``A``: the matrix, or a :class:`~gatetherm.solvers.helper.Pending` of it, made where
        first needed (in the helper, where :meth:`start` sets one up); ``size``: its (unknowns,
        nonzeros), for the plan without making it; ``near_null``: the rigid-body modes;
        ``order``: a fill-reducing order (or a function giving it, called when a factor is
        made); ``nodal``: the unknowns are whole nodes' ``dim`` DOFs in turn (then AMG
        aggregates nodes)."""
        self._A = A if isinstance(A, Pending) else Pending.of(A.tocsr())
        self.size = size or (self.A.shape[0], self.A.nnz)
        self.dim, self.near_null, self.order, self.what = dim, near_null, order, what
        self.block = dim if nodal else 1
        self._solve: Solve | None = None
        self._helper = None
        self.path: str | None = None
        """The path of the live solver (None: released)."""

    @property
    def A(self) -> sp.csr_matrix:
        return self._A.result()

    def start(self, rhs: int) -> bool:
        """Plan for a first batch of ``rhs`` right-hand sides and, where that is AMG-CG and this
        process may fork, set it up now in a helper process; whether it did."""
        from gatetherm.process import can_fork

        if self._solve is not None or self.background or not can_fork():
            return self.background
        if options.current().backend != "amg" or self.near_null is None:
            p = plan(*self.size, self.dim, self.dim, rhs)
            if p.path != "iterative":
                return False
            log.info("%s", p.describe(f"{self.what} ({self.size[0]} unknowns)", rhs))
        A, near_null, block = self._A, self.near_null, self.block  # the helper makes A if it is not made yet;
        # it solves one column at a time while the caller works (a core each), in two processes while it waits
        self._helper = SolveHelper(lambda: PCG(A.result(), near_null, block, RTOL, split=False), self.what)
        self.path = "iterative"
        return True

    @property
    def background(self) -> bool:
        """Whether :meth:`submit` solves in a helper process, beside the caller."""
        return self._helper is not None and self._helper.owner == os.getpid() and self._helper.open

    def retire(self) -> None:
        """The solves submitted so far are the last asked for: a helper process ends once it has
        answered them, its memory freed (a later solve is made here, set up anew)."""
        if self.background:
            self._helper.finish()
            self.path = None

    def submit(self, b: np.ndarray):
        """The solution of ``b`` (n,) or (n, k) as a :class:`~gatetherm.solvers.helper.Pending`:
        made in the helper where there is one (:meth:`start`), else here and now."""
        if self.background:
            return self._helper.submit(b)
        return Pending.of(self._here(b))

    def __call__(self, b: np.ndarray) -> np.ndarray:
        return self.submit(b).result()

    def _here(self, b: np.ndarray) -> np.ndarray:
        if self._solve is None:
            self._solve, self.path = self._make(1 if np.ndim(b) == 1 else np.shape(b)[1])
            if self.path == "iterative":  # kept for good (release() frees factors only): the modes are
                self.near_null = None     # in its hierarchy (7.5 MB on the 3-D frame)
        return self._solve(b)

    def _make(self, rhs: int) -> tuple[Solve, str]:
        small = self.dim == 2 or self.size[0] <= DIRECT_LIMIT_3D or self.near_null is None
        allow = ("pardiso", "cholmod") + (("superlu",) if small else ())
        if options.current().backend == "amg" and self.near_null is not None:
            return PCG(self.A, self.near_null, self.block, RTOL), "iterative"
        return planned_solver(self.A, self.dim, rhs, self.what, self.dim, self.near_null, self.order, allow=allow,
                              amg_block=self.block)

    def release(self) -> None:
        if self.path == "direct":
            self._solve, self.path = None, None

    def __getstate__(self) -> dict:  # another process has no access to the helper
        return {**self.__dict__, "_helper": None}


def rigid_body_modes(doflocs: np.ndarray, components: list[np.ndarray]) -> np.ndarray:
    """Translations and infinitesimal rotations as columns, (N, 3) in 2-D, (N, 6) in 3-D."""
    dim, N = doflocs.shape
    x = doflocs - doflocs.mean(axis=1, keepdims=True)
    modes = [np.zeros(N) for _ in range(3 if dim == 2 else 6)]
    for c, idx in enumerate(components):
        modes[c][idx] = 1.0
    rot = [(0, 1)] if dim == 2 else [(0, 1), (1, 2), (2, 0)]
    for r, (a, b) in enumerate(rot):
        m = modes[dim + r]
        m[components[a]] = -x[b, components[a]]
        m[components[b]] = x[a, components[b]]
    return np.column_stack(modes)
