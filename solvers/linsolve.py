"""Sparse solvers for the symmetric positive definite systems: heat (the solid's block) and
elasticity.

A Cholesky factorisation in a nested-dissection order (METIS through pymetis) is the
workhorse. The backend is the first of :data:`BACKENDS` that is installed and works:

* ``pardiso``: Intel MKL PARDISO through py-mkl-pardiso (wheels for Linux x86_64 and
  Windows), with METIS ordering;
* ``cholmod``: CHOLMOD through cvxopt (GPL-3, not a dependency; used if installed), in the
  pymetis order;
* ``superlu``: scipy's SuperLU on the METIS-permuted matrix (symmetric mode, no column
  reordering), or its minimum degree without pymetis. Always there.

Which backend runs, and why a better one was skipped, is logged once (with the pip command);
``GATETHERM_SPD_BACKEND`` forces one (``amg``: the iterative elastic solve below). For
elasticity without pardiso or cholmod the 3-D systems use conjugate gradients preconditioned by smoothed-aggregation AMG (pyamg) on the
rigid-body modes instead of SuperLU: an iterative solve that does not converge raises
:class:`SolverError`. ``benchmarks/backends.py`` measures the backends on the 3-D frame
(medians of 3, s): heat factor 0.37 (PARDISO) against 1.1 (SuperLU); 300 heat steps 7.7
against 13.6; elastic set-up 5.7 (PARDISO) against 8.4 (AMG); the elastic solve 0.2 against 2.9.
"""
from __future__ import annotations

import logging
import os
from typing import Callable

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import splu

log = logging.getLogger(__name__)

Solve = Callable[[np.ndarray], np.ndarray]
"""``x = solve(b)`` for ``b`` of shape (n,) or (n, k): k right-hand sides at once."""
DIRECT_LIMIT_3D = 30_000
"""Largest 3-D elastic system (DOFs) solved by SuperLU when no Cholesky backend is installed."""
RTOL = 1e-9
"""Relative residual at which AMG-preconditioned CG stops."""
MAXITER = 500
"""Iterations after which AMG-preconditioned CG gives up (and raises)."""
SETTINGS = {"direct_limit_3d": DIRECT_LIMIT_3D, "rtol": RTOL, "maxiter": MAXITER}
"""What the solution depends on, for digests of the numerical scheme."""
BACKEND_ENV = "GATETHERM_SPD_BACKEND"
HINTS = {"pardiso": "pip install py-mkl-pardiso (Linux x86_64, Windows)", "cholmod": "pip install cvxopt (GPL-3)",
         "metis": "pip install pymetis"}


class SolverError(RuntimeError):
    """An iterative solve did not converge, or a matrix cannot be factorised."""


class NoBackend(SolverError):
    """No sparse Cholesky backend of those asked for is installed."""


def _say_once(key: str, level: int, msg: str, *args, _said: set = set()) -> None:  # noqa: B006
    """Log ``msg`` the first time ``key`` is seen in this process (backend choices)."""
    if key not in _said:
        _said.add(key)
        log.log(level, msg, *args)


def nd_order(A: sp.spmatrix, block: int = 1) -> np.ndarray | None:
    """METIS nested-dissection order of A's graph (``block`` > 1: the order of the graph
    of the ``block``-by-``block`` node blocks of interleaved vector DOFs, expanded to the
    DOFs); None without pymetis."""
    try:
        import pymetis
    except ImportError as err:
        _say_once("metis", logging.INFO, "pymetis not available (%s): minimum-degree orderings; %s", err,
                  HINTS["metis"])
        return None
    n = A.shape[0]
    if block > 1:
        C = A.tocoo()
        G = sp.csr_matrix((np.ones(C.nnz), (C.row // block, C.col // block)), shape=(n // block, n // block))
    else:
        G = A.tocsr(copy=True)
    G.setdiag(0)
    G.eliminate_zeros()
    G.sort_indices()
    perm, _ = pymetis.nested_dissection(pymetis.CSRAdjacency(G.indptr.astype(np.int32),
                                                             G.indices.astype(np.int32)))
    return expand_order(np.asarray(perm, dtype=np.int64), block)


def expand_order(order: np.ndarray | None, block: int) -> np.ndarray | None:
    """A node order as the order of ``block`` interleaved DOFs per node."""
    if order is None or block == 1:
        return order
    return (block * order[:, None] + np.arange(block)).ravel()


def restrict_order(order: np.ndarray | None, keep: np.ndarray, n: int) -> np.ndarray | None:
    """An order of ``n`` unknowns restricted to the subset ``keep`` (sorted), as indices
    into ``keep``: the order of ``A[keep][:, keep]``."""
    if order is None:
        return None
    position = -np.ones(n, dtype=np.int64)
    position[keep] = np.arange(len(keep))
    order = position[order]
    return order[order >= 0]


def _pardiso(A: sp.spmatrix, order) -> Solve:
    # the extension class itself: the package's wrapper checks the upper triangle row by
    # row in Python (1.4 s on the 3-D elastic matrix); our order skips PARDISO's own
    # reordering (its analysis 2.2 s → 1.0 s there)
    from pymklpardiso._mkl_pardiso import MTYPE_REAL_SYM_POSDEF, PardisoSolver

    U = sp.triu(A, format="csr")
    U.sort_indices()
    solver = PardisoSolver(MTYPE_REAL_SYM_POSDEF, 0)
    solver.set_pattern(ia=U.indptr.astype(np.int64), ja=U.indices.astype(np.int64), n=A.shape[0])
    if order is None:
        solver.set_iparm(1, 2)  # PARDISO's METIS
    else:
        solver.set_iparm(4, 1)  # the given order
        solver.set_perm(np.asarray(order, dtype=np.int64))
    try:
        solver.factor(U.data.astype(float))
    except RuntimeError as err:
        raise SolverError(f"the matrix cannot be factorised ({err}): material constants or thicknesses many "
                          "orders of magnitude apart?") from None
    return solver.solve


def _cholmod(A: sp.spmatrix, order) -> Solve:
    import cvxopt
    import cvxopt.cholmod as cholmod

    cholmod.options["supernodal"] = 2
    L = sp.tril(A).tocoo()
    Ac = cvxopt.spmatrix(L.data, L.row.astype(int).tolist(), L.col.astype(int).tolist(), L.shape)
    F = cholmod.symbolic(Ac, uplo="L") if order is None else \
        cholmod.symbolic(Ac, cvxopt.matrix(order.astype(int).tolist(), tc="i"), uplo="L")
    cholmod.numeric(Ac, F)

    def solve(b: np.ndarray) -> np.ndarray:
        x = cvxopt.matrix(np.asarray(b, dtype=float))
        cholmod.solve(F, x)
        return np.array(x).reshape(np.shape(b))
    return solve


def _superlu(A: sp.spmatrix, order) -> Solve:
    opts = {"diag_pivot_thresh": 0.0, "options": {"SymmetricMode": True}}
    if order is None:
        return splu(A.tocsc(), permc_spec="MMD_AT_PLUS_A", **opts).solve
    lu = splu(A.tocsr()[order][:, order].tocsc(), permc_spec="NATURAL", **opts)

    def solve(b: np.ndarray) -> np.ndarray:
        x = np.empty(np.shape(b))
        x[order] = lu.solve(np.asarray(b, dtype=float)[order])
        return x
    return solve


BACKENDS = {"pardiso": _pardiso, "cholmod": _cholmod, "superlu": _superlu}
"""Cholesky backends in order of preference."""


def spd_factor(A: sp.spmatrix, order: np.ndarray | None = None, allow=tuple(BACKENDS)) -> tuple[Solve, str]:
    """Factor the SPD matrix ``A`` (in ``order``, from :func:`nd_order`, where the backend
    takes one) with the first backend of ``allow`` that works (only the one forced by
    ``GATETHERM_SPD_BACKEND``, if that names one); ``(solve, backend name)``."""
    forced = os.environ.get(BACKEND_ENV)
    names = [forced] if forced in allow else [] if forced in BACKENDS else list(allow)
    for name in names:
        try:
            solve = BACKENDS[name](A, order)
        except ImportError as err:
            _say_once(f"missing {name}", logging.INFO, "solver backend %s not installed (%s): %s", name, err,
                      HINTS.get(name, ""))
            continue
        _say_once(f"use {name}", logging.INFO, "sparse Cholesky backend: %s", name)
        return solve, name
    raise NoBackend(f"no sparse Cholesky backend of {', '.join(names)} is installed")


class Bordered:
    """Solves with ``[[S, U], [V, D]]``: ``S`` SPD (the solid), a few unknowns last (lumped
    fluids, which make the whole matrix nonsymmetric). ``S`` is factored once, ``Z = S⁻¹U``
    and the small Schur complement ``D − V Z`` are formed, and a solve costs one solve with
    ``S`` and one with the Schur complement."""

    def __init__(self, A: sp.spmatrix, n_inner: int, order: np.ndarray | None = None):
        A = A.tocsr()
        self.n = n_inner
        self.inner, self.backend = spd_factor(A[:n_inner, :n_inner], order)
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


class Factor:
    """A solver set up by ``make`` now, which :meth:`release` frees (the 3-D frame's
    elastic factor holds 0.86 GB) and the next solve sets up again: a run keeps the heat
    factors, not this one, while it marches."""

    def __init__(self, make: Callable[[], Solve]):
        self._make = make
        self._solve: Solve | None = make()

    def __call__(self, b: np.ndarray) -> np.ndarray:
        if self._solve is None:
            log.debug("setting the released solver up again")
            self._solve = self._make()
        return self._solve(b)

    def release(self) -> None:
        self._solve = None


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


def spd_solver(A: sp.spmatrix, dim: int, near_null: np.ndarray | None = None, rtol: float = RTOL,
               order: np.ndarray | None = None) -> Solve:
    """Return ``solve(b)`` for the SPD elastic matrix ``A``, set up once: a Cholesky factor
    (pardiso or cholmod; ``order`` a fill-reducing order of A, as :func:`restrict_order` gives);
    else SuperLU for 2-D and small 3-D systems; else AMG-CG on the rigid-body modes ``near_null``."""
    A = A.tocsr()
    small = dim == 2 or A.shape[0] <= DIRECT_LIMIT_3D or near_null is None
    if os.environ.get(BACKEND_ENV) != "amg" or near_null is None:
        try:
            return spd_factor(A, order, ("pardiso", "cholmod") + (("superlu",) if small else ()))[0]
        except NoBackend:
            _say_once("amg", logging.INFO, "no Cholesky backend: elasticity by AMG-CG; %s", HINTS["pardiso"])
    import pyamg

    # energy-minimising prolongation smoothing halves the CG iterations on the frame
    # (28 against 53 at 53k DOFs) for about the same set-up time
    ml = pyamg.smoothed_aggregation_solver(A, B=near_null, symmetry="symmetric", smooth="energy",
                                           strength=("symmetric", {"theta": 0.0}), max_coarse=500)
    log.info("AMG hierarchy: %d levels, operator complexity %.2f", len(ml.levels), ml.operator_complexity())

    def solve(b: np.ndarray) -> np.ndarray:
        if np.ndim(b) == 2:
            return np.column_stack([solve(col) for col in b.T])
        res: list[float] = []
        x = ml.solve(b, tol=rtol, accel="cg", maxiter=MAXITER, residuals=res)
        rel = float(np.linalg.norm(b - A @ x) / max(np.linalg.norm(b), 1e-300))
        log.debug("AMG-CG: %d iterations, relative residual %.2e", len(res) - 1, rel)
        if not rel <= 10 * rtol:
            raise SolverError(f"AMG-CG did not converge: relative residual {rel:.2e} after {len(res) - 1} "
                              f"iterations (tolerance {rtol:g})")
        return x

    return solve
