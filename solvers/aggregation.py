"""The smoothed-aggregation hierarchy of :class:`~gatetherm.solvers.iterative.AMG`, built level by
level with pyamg's parts, its prolongators smoothed by energy minimisation in place.

Each level is what pyamg's ``smoothed_aggregation_solver(..., smooth="energy")`` makes: the
strength of connection, standard aggregation, the tentative prolongator ``T`` fitted to the
near-null space ``B``, then a few steps of conjugate gradients on ``A P = 0`` with ``P`` kept
within the pattern of ``C T`` and ``P B_c = B_f`` (pyamg's ``cg_prolongation_smoothing``,
Gershgorin-weighted). pyamg's steps make new sparse matrices at every update (the prolongator,
the residual, the search direction, their sums and products); here they are data arrays of one
pattern, updated in place. On the 3-D frame's elastic system the set-up's peak above its start
falls from 478 MB to 236 MB (tracemalloc), the set-up's median from 5.11 s to 3.49 s on shared
cores; the prolongators are the same to round-off (4.8e-12), the iterations the same
(``benchmarks/amg_setup.py``).
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from pyamg import amg_core
from pyamg.aggregation.aggregate import standard_aggregation
from pyamg.aggregation.smooth import satisfy_constraints
from pyamg.aggregation.tentative import fit_candidates
from pyamg.multilevel import MultilevelSolver
from pyamg.relaxation.smoothing import change_smoothers
from pyamg.relaxation.utils import relaxation_as_linear_operator
from pyamg.strength import symmetric_strength_of_connection
from pyamg.util.utils import compute_BtBinv, unamal
from scipy.linalg.blas import daxpy as axpy

TOL = 1e-8
"""pyamg's tolerance of the energy minimisation (its sums of squares)."""
IMPROVE = ("block_gauss_seidel", {"sweep": "symmetric", "iterations": 4})
"""Relaxation of the constant near-null space on the finest level (pyamg's default)."""


def hierarchy(A: sp.spmatrix, B: np.ndarray, max_coarse: int, maxiter: int, improve: bool,
              presmoother, postsmoother, coarse_solver="splu", max_levels: int = 10) -> MultilevelSolver:
    """The hierarchy of the symmetric ``A`` (CSR, or BSR of node blocks) with near-null space
    ``B`` (n, k), coarsened till a level has at most ``max_coarse`` blocks; ``maxiter`` energy
    steps per prolongator; ``improve``: relax ``B`` on the finest level first (:data:`IMPROVE`)."""
    levels = [MultilevelSolver.Level()]
    levels[0].A, levels[0].B = A, np.asarray(B, dtype=A.dtype).reshape(A.shape[0], -1)
    while len(levels) < max_levels and levels[-1].A.shape[0] // _block(levels[-1].A) > max_coarse:
        lv = levels[-1]
        C = symmetric_strength_of_connection(lv.A, theta=0.0)
        aggregates, _ = standard_aggregation(C)
        if improve and len(levels) == 1:
            lv.B = relaxation_as_linear_operator(IMPROVE, lv.A, np.zeros((lv.A.shape[0], 1), dtype=lv.A.dtype)) @ lv.B
        T, Bc = fit_candidates(aggregates, lv.B)
        lv.P = energy_smoothed(lv.A, T, C, Bc, maxiter)
        lv.R = lv.P.T
        coarse = MultilevelSolver.Level()
        coarse.A, coarse.B = lv.R @ lv.A @ lv.P, Bc
        coarse.A.symmetry = "symmetric"
        levels.append(coarse)
    ml = MultilevelSolver(levels, coarse_solver=coarse_solver)
    change_smoothers(ml, presmoother, postsmoother)
    return ml


def _block(A) -> int:
    return A.blocksize[0] if A.format == "bsr" else 1


def energy_smoothed(A: sp.spmatrix, T: sp.bsr_array, C: sp.csr_array, B: np.ndarray, maxiter: int) -> sp.bsr_array:
    """pyamg's ``energy_prolongation_smoother(A, T, C, B, None, (False, {}), maxiter=maxiter)``
    (conjugate gradients, degree 1, weighting "local", no filters), in place on one pattern."""
    A = A.tobsr(blocksize=(1, 1), copy=False) if A.format == "csr" else A  # real, double: as AMG makes them
    T = T.tobsr(blocksize=(1, 1), copy=False) if T.format == "csr" else T
    rb, cb = T.blocksize
    T.sort_indices()
    shape = (T.shape[0] // rb, T.shape[1] // cb)
    pattern = unamal(C.copy() @ sp.csr_array((np.ones(T.indices.shape), T.indices, T.indptr), shape=shape), rb, cb)
    pattern.sort_indices()
    BtBinv = compute_BtBinv(B, pattern)
    indices, indptr = pattern.indices, pattern.indptr
    del pattern

    def on_pattern(data: np.ndarray) -> sp.bsr_array:
        return sp.bsr_array((data, indices, indptr), shape=T.shape)

    def times_A(Y: sp.bsr_array, out: sp.bsr_array) -> sp.bsr_array:
        """``out = (A Y)`` restricted to the pattern, then ``out B = 0`` enforced."""
        out.data[:] = 0.0
        amg_core.incomplete_mat_mult_bsr(A.indptr, A.indices, np.ravel(A.data), Y.indptr, Y.indices, np.ravel(Y.data),
                                         out.indptr, out.indices, np.ravel(out.data), shape[0], shape[1],
                                         A.blocksize[0], A.blocksize[1], cb)
        satisfy_constraints(out, B, BtBinv)
        return out

    blocks, rows = (len(indices), rb, cb), np.repeat(np.arange(shape[0]), np.diff(indptr))
    P = on_pattern(np.zeros(blocks, dtype=T.dtype))  # T on the pattern (which holds T's blocks)
    P.data[_positions(T, rows, indices, shape[1])] = T.data
    R = times_A(P, on_pattern(np.zeros(blocks, dtype=T.dtype)))
    R.data *= -1.0
    if not np.any(R.data):
        return T
    D = np.abs(A) @ np.ones(A.shape[0], dtype=A.dtype)
    weight = np.divide(1.0, np.abs(D), out=np.zeros_like(D), where=D != 0).reshape(shape[0], rb, 1)[rows]
    S, AS = (on_pattern(np.empty(blocks, dtype=T.dtype)) for _ in range(2))  # search direction, A S
    oldsum = None
    for _ in range(maxiter):
        Z = np.multiply(R.data, weight, out=AS.data)  # the scaled residual, in A S's place till it is made
        newsum = np.vdot(R.data, Z)
        if newsum < TOL:
            break
        if oldsum is None:
            S.data[:] = Z
        else:
            S.data *= newsum / oldsum
            S.data += Z
        oldsum = newsum
        times_A(S, AS)
        alpha = newsum / np.vdot(S.data, AS.data)
        axpy(S.data.ravel(), P.data.ravel(), a=alpha)  # in place: P += alpha S, R -= alpha A S
        axpy(AS.data.ravel(), R.data.ravel(), a=-alpha)
    keep = np.any(P.data != 0.0, axis=(1, 2))  # the blocks pyamg's sums keep
    if keep.all():
        return P
    counts = np.bincount(rows[keep], minlength=shape[0])
    return sp.bsr_array((P.data[keep], indices[keep], np.r_[0, np.cumsum(counts)]), shape=T.shape)


def _positions(T: sp.bsr_array, rows: np.ndarray, indices: np.ndarray, columns: int) -> np.ndarray:
    """Where ``T``'s blocks are among the blocks of a pattern (each block's row and column,
    sorted by row then column, holding ``T``'s)."""
    keys = rows.astype(np.int64) * columns + indices
    t_rows = np.repeat(np.arange(len(T.indptr) - 1, dtype=np.int64), np.diff(T.indptr))
    return np.searchsorted(keys, t_rows * columns + T.indices)
