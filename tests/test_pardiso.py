"""PARDISO factors sharing one analysis: each solves to round-off and gives what a handle of
its own gives, a freed factor's slot is used again, and a matrix that is not positive definite
is refused."""
from __future__ import annotations

import gc

import numpy as np
import pytest
import scipy.sparse as sp

from gatetherm.solvers import linsolve, pardiso

pytest.importorskip("pymklpardiso")


def _steps(n=30):
    """Heat-step-like matrices of one pattern (a 3-D grid Laplacian plus mass / dt), two step
    lengths by two films on one face: the upper triangles, CSR, sorted."""
    L1 = sp.diags([-1.0, 2.0, -1.0], [-1, 0, 1], shape=(n, n))
    I1 = sp.identity(n)
    K = (sp.kron(sp.kron(L1, I1), I1) + sp.kron(sp.kron(I1, L1), I1) + sp.kron(sp.kron(I1, I1), L1)).tocsr()
    face = np.zeros(n ** 3)
    face[:n * n] = 1.0
    mats = []
    for dt in (0.5, 2.0):
        for film in (0.0, 3.0):
            U = sp.triu(K + sp.diags(1.0 / dt + film * face), format="csr")
            U.sort_indices()
            mats.append(U)
    order = linsolve.nd_order(K)
    return mats, order


def _full(U):
    return (U + sp.triu(U, 1).T).tocsr()


def test_factors_of_one_pattern_share_one_analysis_and_solve_as_alone():
    if pardiso._entry() is None:
        pytest.skip("this py-mkl-pardiso exports no PARDISO_64")
    mats, order = _steps()
    shared = pardiso.Analyses()
    solves = [shared.factor(U, order) for U in mats]
    assert len(shared._made) == 1 and sorted(f.mnum for f in solves) == [1, 2, 3, 4]
    B = np.random.default_rng(0).normal(size=(mats[0].shape[0], 2))
    for U, solve in zip(mats, solves):
        X = solve(B)
        A = _full(U)
        assert X.shape == B.shape and np.linalg.norm(A @ X - B) < 1e-12 * np.linalg.norm(B)  # 1.7e-15 seen
        alone = pardiso._alone(U, order)(B[:, 0])  # the extension class's handle of its own
        assert np.array_equal(solve(B[:, 0]), alone)


def test_a_freed_factor_gives_its_slot_to_the_next_and_a_full_analysis_makes_another():
    if pardiso._entry() is None:
        pytest.skip("this py-mkl-pardiso exports no PARDISO_64")
    mats, order = _steps(12)
    shared = pardiso.Analyses()
    kept = [shared.factor(mats[k % 4], order) for k in range(pardiso.MAXFCT)]
    gone = kept.pop(2).mnum
    gc.collect()
    again = shared.factor(mats[1], order)
    assert again.mnum == gone and len(shared._made) == 1
    more = shared.factor(mats[3], order)  # every slot taken: a second analysis
    assert len(shared._made) == 2 and more.analysis is shared._made[1]
    b = np.ones(mats[0].shape[0])
    assert np.linalg.norm(_full(mats[1]) @ again(b) - b) < 1e-12 * np.linalg.norm(b)
    assert np.linalg.norm(_full(mats[3]) @ more(b) - b) < 1e-12 * np.linalg.norm(b)


def test_without_the_entry_point_each_matrix_has_a_handle_of_its_own(monkeypatch):
    mats, order = _steps(12)
    monkeypatch.setattr(pardiso, "_entry", lambda: None)
    shared = pardiso.Analyses()
    solve = shared.factor(mats[0], order)
    b = np.ones(mats[0].shape[0])
    assert not shared._made and np.linalg.norm(_full(mats[0]) @ solve(b) - b) < 1e-12 * np.linalg.norm(b)


def test_a_matrix_not_positive_definite_is_refused():
    mats, order = _steps(8)
    U = mats[0].copy()
    U.data[U.indices == np.repeat(np.arange(U.shape[0]), np.diff(U.indptr))] *= -1.0  # negative diagonal
    with pytest.raises(linsolve.SolverError, match="cannot be factorised .*PARDISO"):
        linsolve.spd_factor(_full(U), order, ("pardiso",))
