"""A reduced basis for large heat models, at a cost that grows about linearly with the unknowns:
rational Krylov subspaces of the inputs and the outputs, then balanced truncation of the projection.

For the switched descriptor system ``M ẋ = −K_p x + B_p u``, ``y = C x`` (one ``(K_p, B_p)`` per
pump mode p) the transfer function of each mode is matched at real shifts s ≥ 0 by the columns of

    (K_p + s M)⁻¹ B_p,    (K_pᵀ + s M)⁻¹ Cᵀ,    (K_p + s M)⁻¹ M X_q

(inputs, outputs, and the states ``X_q`` the other mode q hands over at a switch: its static
responses), s = 0 included so that every static gain is exact, the other shifts log-spaced from
a quarter of the slowest rate (the uniform field cooling through its surface) to
:data:`FASTEST` (a mode faster than that has died within a sample). Each shift's matrix is set up
once for all its right-hand sides: a sparse Cholesky factor, or AMG-CG where that would not fit
or costs more (:func:`~gatetherm.solvers.linsolve.planned_solver`; the leading solid block is SPD,
the lumped fluids at the end border it). The columns are M-orthonormalised into ``W`` (a few
hundred), the model projected onto them (E = I), and each mode's projection reduced by balanced
truncation of its Gramians (dense Lyapunov equations), its inputs augmented by the other mode's
dominant reachable states as in :func:`gatetherm.solvers.rom.reduce`; the static responses and
the balanced directions of both modes, taken in turn, give the ``states`` directions ``T`` and the
basis ``V = W T``. Cost: one set-up per shift and mode and some 10 solves each, and O(n r²) for
the orthonormalisation; memory O(n r).
"""
from __future__ import annotations

import logging
import time

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp

from gatetherm.solvers.iterative import AMG, PCG
from gatetherm.solvers.linsolve import Bordered, planned_solver

log = logging.getLogger(__name__)

FASTEST = 0.05
"""Largest shift, 1/s (a decay time of 20 s, a third of the reduced model's 1-min sample)."""
PER_DECADE = 2.5
"""Shifts per decade of rate."""
RTOL = 1e-10
"""Relative residual of the iterative shifted solves."""


def solid_block(M: sp.spmatrix) -> int:
    """Leading unknowns before the trailing lumped ones (rows of ``M`` holding only a diagonal
    capacity: no P1 or P2 node of a solid's consistent mass matrix has a single entry)."""
    counts = np.diff(M.tocsr().indptr)
    n = M.shape[0]
    while n > 0 and counts[n - 1] == 1:
        n -= 1
    return n


def shifts(K: sp.spmatrix, M: sp.spmatrix) -> np.ndarray:
    """s = 0 and real shifts log-spaced from a quarter of the slowest rate to :data:`FASTEST`."""
    one = np.ones(M.shape[0])
    slow = float(one @ (K @ one) / (one @ (M @ one)))
    lo, hi = np.log10(max(slow, 1e-12) / 4), np.log10(FASTEST)
    return np.r_[0.0, np.logspace(lo, hi, max(int(np.ceil((hi - lo) * PER_DECADE)) + 1, 2))]


class _Sweep:
    """Solvers of ``K + s M`` and of its transpose for the shifts of one mode in turn, sharing the
    solid block's solver: a factor per shift, or AMG-CG with one hierarchy for all shifts (the
    conduction dominates every shift's matrix on a fine mesh) started from the Galerkin
    projection onto the previous shift's solutions; which, planned once for the whole sweep."""

    def __init__(self, K, M, n_inner: int, dim: int, rhs: int):
        self.K, self.M, self.n, self.dim, self.rhs = K.tocsr(), M.tocsr(), n_inner, dim, rhs
        self.amg: AMG | None = None
        self.prev: np.ndarray | None = None

    def solvers(self, s: float, count: int):
        """``(solve, solve with the transpose)`` at shift ``s``, ``count`` shifts to go."""
        A = (self.K + s * self.M).tocsr() if s else self.K
        S = A[:self.n, :self.n]
        if self.amg is None and self.prev is None:
            solve, path = planned_solver(S, self.dim, self.rhs * count, f"Krylov shifts ({count})", rtol=RTOL)
            if path == "direct":
                self.prev = np.zeros((self.n, 0))  # factor every shift
                return Bordered(A, self.n, solve), Bordered(A.T.tocsr(), self.n, solve)
            self.amg = solve.amg
            inner = solve
        elif self.amg is None:
            inner = planned_solver(S, self.dim, self.rhs, f"Krylov shift {s:.3g} 1/s", allow=("pardiso", "cholmod",
                                                                                               "superlu"))[0]
            return Bordered(A, self.n, inner), Bordered(A.T.tocsr(), self.n, inner)
        else:
            inner = PCG(S, rtol=RTOL, recycle=4 * self.rhs, amg=self.amg)
        inner.recycle = 4 * self.rhs
        if self.prev is not None and self.prev.size:
            inner.seed(self.prev)
        return Bordered(A, self.n, inner), Bordered(A.T.tocsr(), self.n, inner)

    def keep(self, *solutions: np.ndarray) -> None:
        """The solutions of this shift, to start the next one's (iterative path)."""
        if self.amg is not None:
            self.prev = np.column_stack([x[:self.n] for x in solutions])


def _solve(solve, X: np.ndarray) -> np.ndarray:
    return solve(X) if X.shape[1] else np.zeros(X.shape)


def m_orthonormal(M: sp.spmatrix, X: np.ndarray, first: int = 0, tol: float = 1e-9) -> np.ndarray:
    """An M-orthonormal basis of the span of the columns of ``X``, the first ``first`` of them
    spanned exactly (orthonormalised alone, then projected out of the others); twice: Gram
    matrix, its eigenvectors above ``tol`` of the largest eigenvalue (columns scaled to unit
    M-norm first)."""
    if first:
        Q = m_orthonormal(M, X[:, :first], tol=1e-14)
        R = X[:, first:]
        for _ in range(2):
            R = R - Q @ (Q.T @ (M @ R))
        return np.column_stack([Q, m_orthonormal(M, R, tol=tol)]) if R.shape[1] else Q
    X = X / np.sqrt(np.maximum(np.einsum("ij,ij->j", X, M @ X), 1e-300))
    for _ in range(2):
        lam, U = np.linalg.eigh(X.T @ (M @ X))
        keep = lam > tol * lam[-1]
        X = X @ (U[:, keep] / np.sqrt(lam[keep]))
    return X


def _gramian_factor(A: np.ndarray, B: np.ndarray) -> np.ndarray:
    """``Z`` with ``Z Zᵀ = P``, ``A P + P Aᵀ + B Bᵀ = 0`` (dense, A stable)."""
    P = sla.solve_continuous_lyapunov(A, -B @ B.T)
    lam, U = np.linalg.eigh(0.5 * (P + P.T))
    keep = lam > 1e-14 * lam[-1]
    return U[:, keep] * np.sqrt(lam[keep])


def _balanced(A: np.ndarray, B: np.ndarray, C: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Balanced-truncation directions (columns, in the projected coordinates) of the mode
    ``(A, B, C)`` and its Hankel singular values."""
    Zc, Zo = _gramian_factor(A, B), _gramian_factor(A.T, C.T)
    _, hsv, Vt = np.linalg.svd(Zo.T @ Zc, full_matrices=False)
    keep = hsv > 1e-14 * hsv[0]
    return Zc @ (Vt[keep].T / np.sqrt(hsv[keep])), hsv[keep]


def _union(X: np.ndarray, count: int, tol: float = 1e-8) -> tuple[np.ndarray, list[int]]:
    """The first ``count`` orthonormal directions of the columns of ``X`` taken in order
    (twice-run Gram–Schmidt, a column adding less than ``tol`` of its norm skipped), and the
    indices of the columns used."""
    Q, used = np.zeros((X.shape[0], 0)), []
    for j, x in enumerate(X.T):
        norm = np.linalg.norm(x)
        if not norm > 0:
            continue
        v = x / norm
        for _ in range(2):
            v = v - Q @ (Q.T @ v)
        if np.linalg.norm(v) > tol:
            Q = np.column_stack([Q, v / np.linalg.norm(v)])
            used.append(j)
        if len(used) == count:
            break
    return Q, used


def basis(M: sp.spmatrix, modes: dict[str, tuple[sp.spmatrix, np.ndarray]], C: np.ndarray, states: int,
          dim: int = 3, handover: int = 12, horizon_s: float = 3600.0) -> tuple[np.ndarray, dict]:
    """An M-orthonormal basis ``V`` (n × ``states``) for the Galerkin projection of
    ``M ẋ = −K_p x + B_p u``, ``y = C x`` (``modes``: per mode name ``(K_p, B_p)``; ``C`` the
    weighted outputs to keep, outputs × n), built as the module docstring says; ``dim``: of
    the mesh (for the solvers' plans); ``handover``, ``horizon_s`` as in
    :func:`gatetherm.solvers.rom.reduce`. ``info``: the static responses per mode (n × inputs),
    the Hankel singular values of each mode's projection, its balanced-truncation bound
    (2 Σ of the discarded ones at the directions taken), the shifts, the projection's rank and
    the seconds."""
    t0 = time.perf_counter()
    n_inner = solid_block(M)
    s_all = shifts(next(iter(modes.values()))[0], M)
    B = {m: Bm[:, np.abs(Bm).sum(axis=0) > 0] for m, (_, Bm) in modes.items()}  # no dead input column
    Ct = np.ascontiguousarray(C.T)
    rhs = {m: B[m].shape[1] + sum(B[q].shape[1] for q in modes if q != m) + len(C) for m in modes}
    sweeps = {m: _Sweep(K, M, n_inner, dim, rhs[m]) for m, (K, _) in modes.items()}
    zero = {m: sweeps[m].solvers(0.0, len(s_all)) for m in modes}
    static = {m: _solve(zero[m][0], B[m]) for m in modes}  # the other modes' handover, and exact static gains
    cols = list(static.values())  # spanned exactly: exact static gains
    for m in modes:
        given = np.column_stack([M @ static[q] for q in modes if q != m] or [np.zeros((M.shape[0], 0))])
        for j, s in enumerate(s_all):
            direct, adjoint = zero.pop(m) if s == 0 else sweeps[m].solvers(s, len(s_all) - j)
            new = [static[m] if s == 0 else _solve(direct, B[m]), _solve(direct, given), adjoint(Ct)]
            sweeps[m].keep(*new)
            cols += new[1:] if s == 0 else new
        sweeps[m] = None  # its hierarchy
    seconds = {"krylov_solves": time.perf_counter() - t0}
    t1 = time.perf_counter()
    W = m_orthonormal(M, np.column_stack(cols), first=sum(x.shape[1] for x in static.values()))
    del cols
    A = {m: -(W.T @ (K @ W)) for m, (K, _) in modes.items()}
    Bw = {m: W.T @ B[m] for m in modes}
    Cw = C @ W
    seconds["projection"] = time.perf_counter() - t1
    t2 = time.perf_counter()
    reach = {}
    for m in modes:
        U, sv, _ = np.linalg.svd(_gramian_factor(A[m], Bw[m]), full_matrices=False)
        reach[m] = U[:, :handover] * (sv[:handover] / np.sqrt(horizon_s))
    directions, hankel = {}, {}
    for m in modes:
        aug = np.column_stack([Bw[m], *(reach[q] for q in modes if q != m)])
        directions[m], hankel[m] = _balanced(A[m], aug, Cw)
    static_r = [np.linalg.solve(-A[m], Bw[m]) for m in modes]
    labels = [None] * sum(x.shape[1] for x in static_r)
    order = [(m, j) for j in range(max(d.shape[1] for d in directions.values())) for m in modes
             if j < directions[m].shape[1]]
    T, used = _union(np.column_stack([*static_r, *(directions[m][:, j] for m, j in order)]), states)
    labels += [m for m, _ in order]
    taken = {m: sum(labels[j] == m for j in used) for m in modes}
    seconds["balancing"] = time.perf_counter() - t2
    V = W @ T
    bound = {m: float(2 * hankel[m][taken[m]:].sum()) for m in modes}
    log.info("Krylov basis: %d shifts per mode, projection rank %d, %d states in %.1f s", len(s_all), W.shape[1],
             V.shape[1], time.perf_counter() - t0)
    return V, {"static": static, "hankel": {m: [float(x) for x in h[:20]] for m, h in hankel.items()},
               "bound": bound, "shifts": [float(s) for s in s_all], "rank": int(W.shape[1]), "seconds": seconds}
