"""MKL PARDISO factors of SPD matrices, those of one sparsity pattern sharing one analysis.

py-mkl-pardiso's extension module holds MKL PARDISO; its class gives every matrix a handle of
its own, with its own symbolic analysis. Called through the ``PARDISO_64`` entry point the
extension exports (``ctypes``), one handle keeps up to :data:`MAXFCT` numeric factors of
matrices of one pattern in one order (PARDISO's ``maxfct``/``mnum``), analysed once: the step
matrices of a heat march (one per step length and pump mode) differ in their values only. The
3-D frame's four heat factors add 277 MB against 387 MB with handles of their own, made in
0.96 s against 1.23 s, the solutions the same to the bit (``benchmarks/shared_analysis.py``). Where
the extension exports no ``PARDISO_64`` (a build that hides it), its class factors each
matrix alone.
"""
from __future__ import annotations

import ctypes
import functools
import logging
import weakref

import numpy as np
import scipy.sparse as sp

log = logging.getLogger(__name__)

MAXFCT = 8
"""Numeric factors one analysis holds at most at a time (PARDISO's ``maxfct``)."""
SPD = 2
"""PARDISO's matrix type: real symmetric positive definite."""
ERRORS = {-1: "input inconsistent", -2: "not enough memory", -3: "reordering problem",
          -4: "zero pivot, numerical factorization or iterative refinement problem",
          -5: "unclassified internal error", -7: "diagonal matrix is singular", -8: "32-bit integer overflow"}
"""PARDISO's error codes (its manual's words)."""


class PardisoError(RuntimeError):
    """A PARDISO phase failed."""


@functools.cache
def _entry():
    """``PARDISO_64`` of the extension, or None where it does not export it."""
    import pymklpardiso._mkl_pardiso as ext

    try:
        f = ctypes.CDLL(ext.__file__).PARDISO_64
    except (OSError, AttributeError):
        log.info("py-mkl-pardiso exports no PARDISO_64: a PARDISO handle per matrix")
        return None
    i64 = ctypes.POINTER(ctypes.c_int64)
    f.argtypes = [ctypes.c_void_p, i64, i64, i64, i64, i64, ctypes.c_void_p, ctypes.c_void_p, ctypes.c_void_p,
                  ctypes.c_void_p, i64, ctypes.c_void_p, i64, ctypes.c_void_p, ctypes.c_void_p, i64]
    f.restype = None
    return f


def _call(handle: dict, phase: int, mnum: int, a: np.ndarray, b: np.ndarray | None = None,
          x: np.ndarray | None = None) -> None:
    """One PARDISO phase on ``handle`` (its ``pt``, ``iparm``, ``ia``, ``ja``, ``perm``, ``n``)."""
    n = ctypes.c_int64
    nrhs = 1 if b is None or b.ndim == 1 else b.shape[1]
    err, none = n(0), handle["none"]
    _entry()(handle["pt"].ctypes.data, n(MAXFCT), n(mnum), n(SPD), n(phase), n(handle["n"]), a.ctypes.data,
             handle["ia"].ctypes.data, handle["ja"].ctypes.data, handle["perm"].ctypes.data, n(nrhs),
             handle["iparm"].ctypes.data, n(0), (none if b is None else b).ctypes.data,
             (none if x is None else x).ctypes.data, err)
    if err.value:
        raise PardisoError(f"PARDISO phase {phase} failed: {ERRORS.get(err.value, 'error')} ({err.value})")


def _release(handle: dict, free: list[int], mnum: int | None) -> None:
    """Free the factor ``mnum`` (its slot back to ``free``), or with None everything."""
    try:
        _call(handle, 0 if mnum else -1, mnum or 1, handle["none"])
    except PardisoError as err:  # at exit, nothing to tell
        log.debug("%s", err)
    if mnum:
        free.append(mnum)


class Analysis:
    """PARDISO's analysis of the pattern of ``U`` (the upper triangle of an SPD matrix, CSR,
    sorted) in ``order`` (a fill-reducing order, or None: PARDISO's METIS); :meth:`factor`
    factors a matrix of that pattern by its values, beside the others it holds."""

    def __init__(self, U: sp.csr_matrix, order: np.ndarray | None):
        n = U.shape[0]
        iparm = np.zeros(64, dtype=np.int64)
        iparm[[0, 2, 34]] = 1  # these values, not defaults; zero-based indices
        iparm[1], iparm[4] = 2, 0 if order is None else 1  # PARDISO's METIS, or the order given
        self._handle = {"pt": np.zeros(64, dtype=np.int64), "iparm": iparm, "n": n, "none": np.zeros(1),
                        "ia": U.indptr.astype(np.int64), "ja": U.indices.astype(np.int64),
                        "perm": np.zeros(n, np.int64) if order is None else np.asarray(order, dtype=np.int64)}
        self._free = list(range(MAXFCT, 0, -1))
        _call(self._handle, 11, 1, np.ascontiguousarray(U.data, dtype=float))
        weakref.finalize(self, _release, self._handle, self._free, None)

    def __getstate__(self):
        raise TypeError("a PARDISO analysis lives in the process that made it")

    def fits(self, U: sp.csr_matrix) -> bool:
        """Whether ``U`` has this pattern and a factor slot is free."""
        h = self._handle
        return bool(self._free) and U.shape[0] == h["n"] and U.nnz == len(h["ja"]) and \
            np.array_equal(U.indptr, h["ia"]) and np.array_equal(U.indices, h["ja"])

    def factor(self, values: np.ndarray) -> "Factor":
        """The factor of the matrix of this pattern with ``values`` (``U.data``)."""
        return Factor(self, np.ascontiguousarray(values, dtype=float), self._free.pop())


class Factor:
    """``x = factor(b)``, ``b`` (n,) or (n, k): solves with one factor of an :class:`Analysis`."""

    def __init__(self, analysis: Analysis, values: np.ndarray, mnum: int):
        self.analysis, self.values, self.mnum = analysis, values, mnum
        try:
            _call(analysis._handle, 22, mnum, values)
        except PardisoError:
            _release(analysis._handle, analysis._free, mnum)
            raise
        weakref.finalize(self, _release, analysis._handle, analysis._free, mnum)

    def __call__(self, b: np.ndarray) -> np.ndarray:
        b = np.asfortranarray(b, dtype=float)
        x = np.empty_like(b, order="F")
        _call(self.analysis._handle, 33, self.mnum, self.values, b, x)
        return x


class Analyses:
    """The analyses made for a family of matrices (the steps of a heat march): a matrix whose
    pattern one of them has is factored there, in its order."""

    def __init__(self):
        self._made: list[Analysis] = []

    def factor(self, U: sp.csr_matrix, order: np.ndarray | None):
        """A solve with the SPD matrix whose upper triangle is ``U`` (CSR, sorted)."""
        if _entry() is None:
            return _alone(U, order)
        analysis = next((a for a in self._made if a.fits(U)), None)
        if analysis is None:
            analysis = Analysis(U, order)
            self._made.append(analysis)
        return analysis.factor(U.data)


def _alone(U: sp.csr_matrix, order: np.ndarray | None):
    """The extension class's solve: a handle of its own (its wrapper checks the upper triangle
    row by row in Python, 1.4 s on the 3-D elastic matrix: the class itself is called)."""
    from pymklpardiso._mkl_pardiso import MTYPE_REAL_SYM_POSDEF, PardisoSolver

    solver = PardisoSolver(MTYPE_REAL_SYM_POSDEF, 0)
    solver.set_pattern(ia=U.indptr.astype(np.int64), ja=U.indices.astype(np.int64), n=U.shape[0])
    if order is None:
        solver.set_iparm(1, 2)
    else:
        solver.set_iparm(4, 1)
        solver.set_perm(np.asarray(order, dtype=np.int64))
    try:
        solver.factor(U.data.astype(float))
    except RuntimeError as err:
        raise PardisoError(str(err)) from None
    return solver.solve
