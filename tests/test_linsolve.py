"""The sparse solvers: every Cholesky backend, with and without the METIS order, solves to
round-off; the bordered (lumped-fluid) solve equals a sparse LU of the whole nonsymmetric
matrix; AMG-CG agrees with the direct solve and raises when it cannot converge."""
from __future__ import annotations

import importlib.util

import numpy as np
import pytest
import scipy.sparse as sp
from scipy.sparse.linalg import spsolve
from skfem import Basis, ElementTetP1, ElementVector, MeshTet, asm

from gatetherm.solvers import iterative, linsolve
from gatetherm.solvers.elasticity import stiffness
from gatetherm.solvers.material import lame

INSTALLED = {"pardiso": "pymklpardiso", "cholmod": "cvxopt", "superlu": "scipy"}


@pytest.fixture(scope="module")
def elastic_3d():
    """A 1 x 0.2 x 0.2 m steel bar clamped at x = 0, P1 (5k DOFs)."""
    mesh = MeshTet.init_tensor(np.linspace(0, 1, 41), np.linspace(0, 0.2, 9), np.linspace(0, 0.2, 9))
    vb = Basis(mesh, ElementVector(ElementTetP1()))
    lam, mu = lame(2.1e11, 0.3)
    K = asm(stiffness, vb, lam=lam, mu=mu, t=1.0)
    free = np.setdiff1d(np.arange(vb.N), vb.get_dofs(lambda x: x[0] < 1e-9).all())
    rbm = linsolve.rigid_body_modes(vb.doflocs, vb.split_indices())[free]
    return K[free][:, free].tocsr(), rbm, K.tocsr(), free


def _residual(A, x, b) -> float:
    return np.linalg.norm(A @ x - b) / np.linalg.norm(b)


@pytest.mark.parametrize("ordered", [False, True])
@pytest.mark.parametrize("backend", list(linsolve.BACKENDS))
def test_every_backend_solves_to_round_off(backend, ordered, elastic_3d):
    if importlib.util.find_spec(INSTALLED[backend]) is None:
        pytest.skip(f"{backend} not installed")
    Kff, _, K, free = elastic_3d
    order = linsolve.restrict_order(linsolve.nd_order(K, 3), free, K.shape[0]) if ordered else None
    if ordered and order is None:
        pytest.skip("pymetis not installed")
    if ordered:  # a permutation of the free DOFs
        assert np.array_equal(np.sort(order), np.arange(Kff.shape[0]))
    B = np.random.default_rng(1).normal(size=(Kff.shape[0], 3))
    solve, name = linsolve.spd_factor(Kff, order, (backend,))
    assert name == backend
    X = solve(B)  # three right-hand sides at once, and one
    assert X.shape == B.shape and _residual(Kff, X, B) < 1e-9
    assert np.allclose(solve(B[:, 1]), X[:, 1], rtol=0, atol=1e-12 * np.abs(X).max())


def test_bordered_solve_equals_lu_of_the_whole_matrix():
    """An SPD block with two lumped unknowns coupled one way (as the pump couples oil to hose)."""
    rng = np.random.default_rng(2)
    n = 400
    S = sp.diags([-1.0, 2.2, -1.0], [-1, 0, 1], shape=(n, n)).tocsr()
    U = sp.random(n, 2, density=0.05, random_state=3)
    V = sp.random(2, n, density=0.05, random_state=4)
    D = np.array([[3.0, 0.0], [-1.0, 2.5]])
    A = sp.bmat([[S, U], [V, D]]).tocsr()
    b = rng.normal(size=n + 2)
    bordered = linsolve.Bordered(A, n, linsolve.spd_factor(S, linsolve.nd_order(S))[0])
    reference = spsolve(A.tocsc(), b)
    assert np.abs(bordered(b) - reference).max() < 1e-12 * np.abs(reference).max()


def test_amg_cg_matches_the_direct_solve(elastic_3d, monkeypatch):
    Kff, rbm, *_ = elastic_3d
    b = np.random.default_rng(0).normal(size=(Kff.shape[0], 2))
    direct = linsolve.SPDSolver(Kff, 3, rbm)(b)
    monkeypatch.setenv(linsolve.BACKEND_ENV, "amg")
    amg = linsolve.SPDSolver(Kff, 3, rbm, nodal=True)(b)
    assert np.linalg.norm(amg - direct) <= 1e-7 * np.linalg.norm(direct)


def test_amg_cg_that_does_not_converge_raises(elastic_3d, monkeypatch):
    Kff, rbm, *_ = elastic_3d
    monkeypatch.setenv(linsolve.BACKEND_ENV, "amg")
    monkeypatch.setattr(iterative, "MAXITER", 2)
    solve = linsolve.SPDSolver(Kff, 3, rbm)
    with pytest.raises(linsolve.SolverError, match="did not converge: relative residual"):
        solve(np.ones(Kff.shape[0]))


def test_without_a_cholesky_backend_large_3d_elasticity_uses_amg(elastic_3d, monkeypatch, caplog):
    """Where neither PARDISO nor CHOLMOD installs, the 3-D elastic solve falls back to
    AMG-CG (logged), not to SuperLU's fill."""
    Kff, rbm, *_ = elastic_3d
    for name in ("pardiso", "cholmod"):
        monkeypatch.setitem(linsolve.BACKENDS, name, lambda A, order, shared: (_ for _ in ()).throw(ImportError("absent")))
    monkeypatch.setattr(linsolve, "DIRECT_LIMIT_3D", 0)
    monkeypatch.setattr(linsolve, "_say_once", lambda key, level, msg, *a: linsolve.log.log(level, msg, *a))
    b = np.ones(Kff.shape[0])
    with caplog.at_level("INFO", logger="gatetherm.solvers.linsolve"):
        solve = linsolve.SPDSolver(Kff, 3, rbm)
        x = solve(b)
    assert "no Cholesky backend for the elastic system: AMG-CG" in caplog.text and _residual(Kff, x, b) < 1e-8
    assert solve.path == "iterative"
