"""Low-rank Gramian factors of ``M ẋ = −K x + B u, y = C x`` by ADI with a few cycled real shifts.

The controllability Gramian P and the observability Gramian Q solve

    −K P M − M P Kᵀ + B Bᵀ = 0,     −Kᵀ Q M − M Q K + Cᵀ C = 0,

and the low-rank ADI iteration (Penzl; Li and White) builds factors ``P ≈ Z Zᵀ`` one block per
shift q > 0: ``V = (K + q M)⁻¹ W``, ``Z ← [Z, √(2q) V]``, ``W ← W − 2q M V`` from ``W = B``
(``Kᵀ, Mᵀ`` for Q), until ``‖WᵀW‖`` has fallen by ``tol``. The heat operators have a real
spectrum (K is symmetric but for the small advective pump term), so real shifts log-spaced over
the spectrum of M⁻¹K, cycled, converge; each shift's matrix is factorised once and reused by
every iteration and every right-hand side, the controllability and the observability solves
alike (pyMOR's ADI factorises the shifted matrix afresh at every iteration: 282 sparse
factorisations for one 2-D reduction, measured).
"""
from __future__ import annotations

import logging

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import splu

log = logging.getLogger(__name__)


def spectrum_bounds(K: sp.spmatrix, M: sp.spmatrix, iterations: int = 30) -> tuple[float, float]:
    """(slowest, fastest) decay rate of M⁻¹K, 1/s: the Rayleigh quotient of the uniform field
    (the slowest mode of a body losing heat through its surface) and a power iteration."""
    one = np.ones(M.shape[0])
    slow = float(one @ (K @ one) / (one @ (M @ one)))
    lu = splu(sp.csc_matrix(M))
    x = np.random.default_rng(0).standard_normal(M.shape[0])
    fast = 0.0
    for _ in range(iterations):
        y = lu.solve(K @ x)
        fast = float(np.linalg.norm(y) / np.linalg.norm(x))
        x = y / np.linalg.norm(y)
    return slow, fast


class ShiftedSolves:
    """``(K + q M)⁻¹`` (or its transpose) for a fixed set of shifts q, each factorised on first use."""

    def __init__(self, K: sp.spmatrix, M: sp.spmatrix, per_decade: float = 2.0, margin: float = 4.0,
                 slowest: float | None = None):
        self.K, self.M = sp.csc_matrix(K), sp.csc_matrix(M)
        slow, fast = spectrum_bounds(K, M)
        slow = min(slow, slowest or slow)
        lo, hi = np.log10(slow / margin), np.log10(fast * margin)
        self.shifts = np.logspace(lo, hi, max(int(np.ceil((hi - lo) * per_decade)) + 1, 2))
        """Shifts q, 1/s: log-spaced from a ``margin`` below the slowest rate (or ``slowest``, if
        lower) to a ``margin`` above the fastest."""
        self._lu: dict[int, object] = {}
        log.info("ADI: %d shifts over %.3g .. %.3g 1/s", len(self.shifts), *self.shifts[[0, -1]])

    def solve(self, j: int, rhs: np.ndarray, trans: bool = False) -> np.ndarray:
        if j not in self._lu:
            self._lu[j] = splu(self.K + self.shifts[j] * self.M, permc_spec="COLAMD")
        return self._lu[j].solve(rhs, trans="T" if trans else "N")


def gramian_factor(solves: ShiftedSolves, B: np.ndarray, observability: bool = False, tol: float = 1e-10,
                   max_cycles: int = 30) -> np.ndarray:
    """Z (n × k) with ``Z Zᵀ`` the controllability Gramian for input matrix ``B`` (n × inputs), or
    the observability Gramian for ``B`` = Cᵀ (``observability=True``)."""
    W = np.array(B, float, copy=True)
    M = solves.M.T if observability else solves.M
    start = np.linalg.norm(W.T @ W, 2)
    blocks, res = [], start
    for cycle in range(max_cycles):
        for j, q in enumerate(solves.shifts):
            V = solves.solve(j, W, observability)
            blocks.append(np.sqrt(2 * q) * V)
            W = W - 2 * q * (M @ V)
        res = np.linalg.norm(W.T @ W, 2)
        if res <= tol * start:
            break
    else:
        log.warning("ADI: residual %.2g of the start after %d cycles", res / start, max_cycles)
    Z = compress(np.column_stack(blocks))
    log.debug("ADI: %d cycles, residual %.2g, rank %d", cycle + 1, res / start, Z.shape[1])
    return Z


def compress(Z: np.ndarray, rtol: float = 1e-12) -> np.ndarray:
    """A factor with the same ``Z Zᵀ`` up to ``rtol`` of its norm and fewer columns: ``Z U`` over the
    eigenvectors U of ``ZᵀZ`` whose eigenvalues exceed ``rtol`` of the largest."""
    lam, U = np.linalg.eigh(Z.T @ Z)
    keep = lam > rtol * lam[-1]
    return Z @ U[:, keep]
