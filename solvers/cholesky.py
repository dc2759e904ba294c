"""Sparse Cholesky factors of SPD matrices (:func:`spd_factor`) in a nested-dissection order
(:func:`nd_order`: METIS through pymetis). The backend is the first of :data:`BACKENDS` that is
installed and works:

* ``pardiso``: Intel MKL PARDISO through py-mkl-pardiso (wheels for Linux x86_64 and
  Windows), with METIS ordering; the factors of a family of matrices of one pattern (a heat
  march's steps) share one analysis (:mod:`.pardiso`);
* ``cholmod``: CHOLMOD through cvxopt (GPL-3, not a dependency; used if installed), in the
  pymetis order;
* ``superlu``: scipy's SuperLU on the METIS-permuted matrix (symmetric mode, no column
  reordering), or its minimum degree without pymetis. Always there.

Which backend runs, and why a better one was skipped, is logged once (with the pip command); the
solver option ``backend`` (``GATETHERM_SPD_BACKEND``) forces one. When to factor at all, and the
solvers built on the factors, are :mod:`gatetherm.solvers.linsolve`."""
from __future__ import annotations

import contextlib
import logging
import os
import signal
import threading
from typing import Callable

import numpy as np
import scipy.sparse as sp
from scipy.sparse.linalg import splu

from gatetherm import options
from gatetherm.solvers.iterative import SolverError

log = logging.getLogger(__name__)

Solve = Callable[[np.ndarray], np.ndarray]
"""``x = solve(b)`` for ``b`` of shape (n,) or (n, k): k right-hand sides at once."""
HINTS = {"pardiso": "pip install py-mkl-pardiso (Linux x86_64, Windows)", "cholmod": "pip install cvxopt (GPL-3)",
         "metis": "pip install pymetis"}


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
    # one refinement pass per level, not METIS's ten: on the 3-D frame's nodes 0.35 s against 0.48 s
    # (benchmarks/assembly_parts.py); the heat steps factored in it as fast (benchmarks/peer.py's parts)
    with _signals_deferred():
        perm, _ = pymetis.nested_dissection(pymetis.CSRAdjacency(G.indptr.astype(np.int32),
                                                                 G.indices.astype(np.int32)),
                                            options=pymetis.Options(niter=1))
    return expand_order(np.asarray(perm, dtype=np.int64), block)


@contextlib.contextmanager
def _signals_deferred():
    """SIGINT and SIGTERM held back while METIS orders: its GKlib traps SIGTERM and SIGABRT with a
    longjmp, which, landing in the middle of a malloc, left the process waiting on the allocator's
    lock for ever (a SIGTERM'd run that never ended). Blocked in the only thread of the process, a
    signal waits and reaches Python's handler when METIS returns. Only where every other native
    thread blocks them too (the command line starts the libraries' threads so): else the kernel
    would hand the signal to one of those, into GKlib's handler on the wrong stack."""
    held = {signal.SIGINT, signal.SIGTERM}
    alone = threading.current_thread() is threading.main_thread() and _others_block(held)
    old = signal.pthread_sigmask(signal.SIG_BLOCK, held) if alone else None
    try:
        yield
    finally:
        if old is not None:
            signal.pthread_sigmask(signal.SIG_SETMASK, old)


def _others_block(held) -> bool:
    """Whether every other thread of this process, those of C libraries included, blocks the
    signals ``held`` (Linux: /proc; False where it cannot be told)."""
    bits, me = sum(1 << (int(s) - 1) for s in held), threading.get_native_id()
    try:
        for task in os.listdir("/proc/self/task"):
            if int(task) != me:
                with open(f"/proc/self/task/{task}/status") as f:
                    blocked = next(int(line.split()[1], 16) for line in f if line.startswith("SigBlk:"))
                if blocked & bits != bits:
                    return False
    except (OSError, StopIteration, ValueError):
        return False
    return True


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


def _pardiso(A: sp.spmatrix, order, shared=None) -> Solve:
    # our order skips PARDISO's own reordering (its analysis 2.2 s → 1.0 s on the 3-D elastic
    # matrix); ``shared``: the analyses of matrices of the same pattern (:mod:`.pardiso`)
    from gatetherm.solvers.pardiso import Analyses, PardisoError

    U = sp.triu(A, format="csr")
    U.sort_indices()
    try:
        return (Analyses() if shared is None else shared).factor(U, order)
    except PardisoError as err:
        raise SolverError(f"the matrix cannot be factorised ({err}): material constants or thicknesses many "
                          "orders of magnitude apart?") from None


def _cholmod(A: sp.spmatrix, order, shared=None) -> Solve:
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


def _superlu(A: sp.spmatrix, order, shared=None) -> Solve:
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
"""Cholesky backends in order of preference: ``factor(A, order, shared)`` (``shared``: a
:class:`~gatetherm.solvers.pardiso.Analyses` for matrices of one pattern, used by pardiso)."""


def spd_factor(A: sp.spmatrix, order: np.ndarray | None = None, allow=tuple(BACKENDS),
               shared=None) -> tuple[Solve, str]:
    """Factor the SPD matrix ``A`` (in ``order``, from :func:`nd_order`, where the backend
    takes one) with the first backend of ``allow`` that works (only the one forced by
    the solver option ``backend``, if that names one); ``(solve, backend name)``. ``shared``: a
    :class:`~gatetherm.solvers.pardiso.Analyses` whose analysis a matrix of the same pattern
    shares (PARDISO)."""
    forced = options.current().backend
    names = [forced] if forced in allow else [] if forced in BACKENDS else list(allow)
    for name in names:
        try:
            solve = BACKENDS[name](A, order, shared)
        except ImportError as err:
            _say_once(f"missing {name}", logging.INFO, "solver backend %s not installed (%s): %s", name, err,
                      HINTS.get(name, ""))
            continue
        _say_once(f"use {name}", logging.INFO, "sparse Cholesky backend: %s", name)
        return solve, name
    raise NoBackend(f"no sparse Cholesky backend of {', '.join(names)} is installed")
