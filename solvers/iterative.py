"""Conjugate gradients preconditioned by smoothed-aggregation AMG, for the SPD systems of meshes
too large to factorise: memory grows linearly with the unknowns.

:class:`AMG` is one V-cycle of a pyamg smoothed-aggregation hierarchy (built once per matrix,
down to :func:`max_coarse` node blocks solved by sparse LU; near-null space the constants, or the
rigid-body modes with the DOFs of each node aggregated together for elasticity; forward
Gauss–Seidel before and backward after the coarse correction, so the cycle is a symmetric
preconditioner). :class:`PCG` solves with one matrix for any number
of right-hand sides, one after another (on a large system the later half of one call's in a
forked copy of the solver, beside: the second core), each started from the Galerkin projection
of its right-hand side onto the last solutions (``x₀ = X (XᵀAX)⁻¹ Xᵀ b``): for the heat steps of a
run this is at least as good as any extrapolation from the previous steps, for the fields at
the output times a warm start from the previous ones. A solve that does not reach its
tolerance raises :class:`~gatetherm.solvers.linsolve.SolverError`.
"""
from __future__ import annotations

import logging
import math

import numpy as np
import scipy.sparse as sp

from gatetherm.process import can_fork
from gatetherm.solvers.errors import SolverError

log = logging.getLogger(__name__)

RTOL = 1e-10
"""Relative residual ‖b − Ax‖ / ‖b‖ at which conjugate gradients stop."""
MAXITER = 400
"""Iterations after which conjugate gradients give up (and raise)."""
RECYCLE = 6
"""Solutions kept for the Galerkin start of the next right-hand side."""
SPLIT_UNKNOWNS = 50_000
"""From this many unknowns on, the right-hand sides of one call are solved in two processes
(the later half by a forked copy), where the process may fork (:func:`gatetherm.process.can_fork`)."""


def max_coarse(blocks: int) -> int:
    """The largest coarsest level (in node blocks) of a hierarchy of ``blocks`` node blocks: pyamg's
    500, or √blocks if more, solved exactly by sparse LU (whose cost then grows no faster than the
    unknowns). With 500, the 3-D frame's elastic hierarchy at 20 × the nodes went on from 594
    aggregates (3 564 unknowns) to 12, and conjugate gradients took 2.1 times the iterations of
    the 594 solved exactly (``benchmarks/amg_coarse.py``); up to 8 × no level changes."""
    return max(500, math.isqrt(blocks))


def _nbytes(A) -> int:
    if sp.issparse(A):
        return int(A.data.nbytes + getattr(A, "indices", np.zeros(0)).nbytes + getattr(A, "indptr", np.zeros(0)).nbytes)
    return int(getattr(A, "nbytes", 0))


class AMG:
    """One V-cycle of a smoothed-aggregation hierarchy of the SPD matrix ``A``: ``z = amg(r)``.
    ``near_null`` (n, m): the rigid-body modes of elasticity, with ``block`` DOFs per node
    (aggregated together when every node keeps all of them); None: the constants."""

    def __init__(self, A: sp.spmatrix, near_null: np.ndarray | None = None, block: int = 1, single: bool = True,
                 smooth=None, coarsest: int | None = None):
        """``single``: the cycle in single precision (``benchmarks/amg_precision.py`` measures both);
        ``smooth``: pyamg's prolongation smoother instead of the energy minimisation, the
        hierarchy made by pyamg's ``smoothed_aggregation_solver`` (``benchmarks/heat_amg.py``
        measures Jacobi's, ``benchmarks/amg_setup.py`` pyamg's energy minimisation against
        :mod:`.aggregation`'s); ``coarsest``: the largest level solved exactly, in node blocks,
        instead of :func:`max_coarse`'s."""
        A = A.tocsr()
        whole_nodes = block > 1 and A.shape[0] % block == 0
        blocks = A.shape[0] // block if whole_nodes else A.shape[0]  # pyamg counts a level's size in blocks
        smoothers = dict(presmoother=("gauss_seidel", {"sweep": "forward"}),
                         postsmoother=("gauss_seidel", {"sweep": "backward"}))
        top = A.tobsr(blocksize=(block, block)) if whole_nodes else A
        # heat: all connections strong; energy-minimising prolongation in two steps: on the 3-D
        # frame's heat steps at 8 × the nodes a quarter fewer iterations than Jacobi smoothing of
        # P, the set-up 1.1 s longer (benchmarks/heat_amg.py). Elasticity: energy minimisation in
        # pyamg's four steps, 25 iterations on the 3-D frame against 58 of Jacobi smoothing; the
        # rigid-body modes are exact, no relaxation improves them (40 % of the set-up)
        maxiter = 2 if near_null is None else 4
        if smooth is None:  # pyamg imported only where a hierarchy is made
            from gatetherm.solvers.aggregation import hierarchy

            B = np.ones((A.shape[0], 1)) if near_null is None else near_null
            self.ml = hierarchy(top, B, coarsest or max_coarse(blocks), maxiter, near_null is None, **smoothers)
        else:
            import pyamg

            kw = dict(symmetry="symmetric", max_coarse=coarsest or max_coarse(blocks), coarse_solver="splu",
                      smooth=smooth, **smoothers)
            if near_null is not None:
                kw.update(B=near_null, strength=("symmetric", {"theta": 0.0}), improve_candidates=None)
            self.ml = pyamg.smoothed_aggregation_solver(top, **kw)
        # the caller's CSR matrix on the finest level (no block copy): its point Gauss-Seidel sweeps
        # cost 2/3 of a block sweep for the same iterations; 1-by-1 block levels as CSR too
        self.ml.levels[0].A = A
        for level in self.ml.levels[1:]:
            if sp.issparse(level.A) and level.A.format == "bsr" and level.A.blocksize == (1, 1):
                level.A = level.A.tocsr()
        # the cycle in single precision, conjugate gradients in double: on the 3-D frame's elastic
        # system the same iterations and solutions, a quarter less time (half the memory traffic of
        # the sweeps; benchmarks/amg_precision.py); R = Pᵀ as a view of P (pyamg keeps a copy);
        # the coarsest level in double
        self.dtype = np.float32 if single else np.float64
        for level in self.ml.levels[:-1]:
            level.A, level.P = _cast(level.A, self.dtype), _cast(level.P.tocsr(), self.dtype)
            level.R = level.P.T
        self.A = A
        log.debug("AMG: %d levels %s, operator complexity %.2f", len(self.ml.levels),
                  [lv.A.shape[0] for lv in self.ml.levels], self.ml.operator_complexity())

    @property
    def nbytes(self) -> int:
        """Memory of the hierarchy beyond the caller's matrix (whose pattern the finest level
        shares, and in double precision its values too) and the transfer operators, bytes."""
        levels = self.ml.levels
        own = 0 if np.shares_memory(levels[0].A.data, self.A.data) else levels[0].A.data.nbytes
        return own + sum(_nbytes(lv.A) for lv in levels[1:]) + sum(_nbytes(lv.P) for lv in levels[:-1])  # R: P's view

    def __call__(self, b: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
        """``z = amg(b)``, into ``out`` (double precision, ``b``'s shape) where given."""
        if len(self.ml.levels) == 1:  # no coarser level (a small matrix): its coarse solve
            z = self.ml.coarse_solver(self.A, np.asarray(b, dtype=float))
        else:
            z = self._cycle(0, np.asarray(b, dtype=self.dtype))
        if out is None:
            return z.astype(float)
        np.copyto(out, z)
        return out

    def _cycle(self, k: int, b: np.ndarray) -> np.ndarray:
        levels = self.ml.levels
        lv = levels[k]
        x = np.zeros_like(b)
        lv.presmoother(lv.A, x, b)
        coarse = lv.R @ (b - lv.A @ x)
        x += lv.P @ (self.ml.coarse_solver(levels[-1].A, coarse.astype(float)).astype(self.dtype)
                     if k == len(levels) - 2 else self._cycle(k + 1, coarse))
        lv.postsmoother(lv.A, x, b)
        return x


def _cast(M: sp.spmatrix, dtype) -> sp.spmatrix:
    """``M`` (CSR or BSR) with values of ``dtype``, its index arrays shared."""
    return type(M)((M.data.astype(dtype, copy=False), M.indices, M.indptr), shape=M.shape)


class PCG:
    """Solves with the SPD matrix ``A`` by AMG-preconditioned conjugate gradients, ``x = pcg(b)``
    for ``b`` (n,) or (n, k), each solve started from the Galerkin projection onto the last
    :data:`RECYCLE` solutions. ``iterations`` counts them all."""

    def __init__(self, A: sp.spmatrix, near_null: np.ndarray | None = None, block: int = 1, rtol: float = RTOL,
                 recycle: int = RECYCLE, amg: AMG | None = None, split: bool = True):
        """``amg``: a hierarchy to precondition with instead of ``A``'s own (of a nearby matrix);
        ``split``: solve the later half of a large call's right-hand sides in a forked copy."""
        self.A = A.tocsr()
        self.amg = AMG(self.A, near_null, block) if amg is None else amg
        self.rtol, self.recycle, self.split = rtol, recycle, split
        # the kept solutions and their products, in place (a ring of columns): no copies per solve
        self._X, self._AX = (np.empty((self.A.shape[0], recycle), order="F") for _ in range(2))
        self._kept = self._next = 0
        self.iterations = 0
        self.solves = 0

    @property
    def nbytes(self) -> int:
        """Memory held: the matrix, the hierarchy and the kept solutions, bytes."""
        return _nbytes(self.A) + self.amg.nbytes + 16 * self.A.shape[0] * self._kept

    @property
    def kept(self) -> np.ndarray:
        """The solutions the Galerkin start projects onto (a copy, n × at most :attr:`recycle`)."""
        return self._X[:, :self._kept].copy()

    def seed(self, X: np.ndarray) -> None:
        """Start the Galerkin projection from the columns of ``X`` (solutions of a nearby
        problem), as many as :attr:`recycle` allows."""
        X = np.asarray(X, dtype=float).reshape(self.A.shape[0], -1)
        X = X[:, X.shape[1] - min(self.recycle, X.shape[1]):]
        k = X.shape[1]
        self._X[:, :k], self._AX[:, :k] = X, self.A @ X
        self._kept, self._next = k, k % max(self.recycle, 1)

    def _keep(self, x: np.ndarray, Ax: np.ndarray) -> None:
        """Keep the solution ``x`` (and ``A x``) in place of the oldest."""
        if self.recycle:
            self._X[:, self._next], self._AX[:, self._next] = x, Ax
            self._kept, self._next = min(self._kept + 1, self.recycle), (self._next + 1) % self.recycle

    def __call__(self, b: np.ndarray) -> np.ndarray:
        b = np.asarray(b, dtype=float)
        if b.ndim == 2:
            before = self.iterations
            x = (self._in_two(b) if self.split and b.shape[1] > 1 and self.A.shape[0] >= SPLIT_UNKNOWNS and can_fork()
                 else self._columns(b))
            log.debug("AMG-CG: %d right-hand sides in %d iterations", b.shape[1], self.iterations - before)
            return x
        return self._solve(b)

    def _columns(self, b: np.ndarray) -> np.ndarray:
        return np.column_stack([self._solve(col) for col in b.T]) if b.shape[1] else np.zeros(b.shape)

    def _in_two(self, b: np.ndarray) -> np.ndarray:
        """The columns of ``b``, the later half solved by a forked copy of this solver (its
        hierarchy shared, not copied: :func:`~gatetherm.solvers.helper.forked`) while this process
        solves the first."""
        from gatetherm.solvers.helper import forked

        k = (b.shape[1] + 1) // 2
        before = self.iterations, self.solves

        def later():
            return self._columns(b[:, k:]), self.iterations - before[0], self.solves - before[1]
        other = forked(later, "AMG-CG's second process")
        mine = self._columns(b[:, :k])
        x, iterations, solves = other.result()
        self.iterations += iterations
        self.solves += solves
        return np.column_stack([mine, x])

    def _start(self, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The Galerkin start ``x₀`` and its product ``A x₀``."""
        if not self._kept:
            return np.zeros_like(b), np.zeros_like(b)
        X, AX = self._X[:, :self._kept], self._AX[:, :self._kept]
        G = X.T @ AX
        c = np.linalg.lstsq(0.5 * (G + G.T), X.T @ b, rcond=1e-13)[0]  # the kept solutions may be near dependent
        return X @ c, AX @ c

    def _solve(self, b: np.ndarray) -> np.ndarray:
        nb = float(np.linalg.norm(b))
        if nb == 0.0:
            return np.zeros_like(b)
        x, Ax = self._start(b)
        r = b - Ax
        goal, k = self.rtol * nb, 0
        if np.linalg.norm(r) > goal:
            # the vectors of an iteration made once and updated in place, not made anew each time
            # (on a large mesh each new one could be memory faulted in: gatetherm.process.keep_freed)
            z = self.amg(r)
            p, rz, w = z.copy(), float(r @ z), np.empty_like(r)
            for k in range(1, MAXITER + 1):
                q = self.A @ p
                alpha = rz / float(p @ q)
                x += np.multiply(alpha, p, out=w)
                r -= np.multiply(alpha, q, out=w)
                if np.linalg.norm(r) <= goal:
                    break
                self.amg(r, out=z)
                rz, rz_old = float(r @ z), rz
                p *= rz / rz_old
                p += z
            else:
                raise SolverError(f"AMG-CG did not converge: relative residual {np.linalg.norm(r) / nb:.2e} after "
                                  f"{MAXITER} iterations (tolerance {self.rtol:g})")
        self.iterations += k
        self.solves += 1
        self._keep(x, b - r)  # A x, without a product
        return x
