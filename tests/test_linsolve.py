"""The elastic solvers: AMG-CG agrees with the direct solve, and raises when it cannot converge."""
from __future__ import annotations

import numpy as np
import pytest

from skfem import Basis, ElementTetP1, ElementVector, MeshTet, asm

from gatetherm.solvers import linsolve
from gatetherm.solvers.elasticity import stiffness
from gatetherm.solvers.material import lame


@pytest.fixture(scope="module")
def elastic_3d():
    """A 1 x 0.2 x 0.2 m steel bar clamped at x = 0, P1 (5k DOFs)."""
    mesh = MeshTet.init_tensor(np.linspace(0, 1, 41), np.linspace(0, 0.2, 9), np.linspace(0, 0.2, 9))
    vb = Basis(mesh, ElementVector(ElementTetP1()))
    lam, mu = lame(2.1e11, 0.3)
    K = asm(stiffness, vb, lam=lam, mu=mu, t=1.0)
    free = np.setdiff1d(np.arange(vb.N), vb.get_dofs(lambda x: x[0] < 1e-9).all())
    rbm = linsolve.rigid_body_modes(vb.doflocs, vb.split_indices())[free]
    return K[free][:, free].tocsr(), rbm


def test_amg_cg_matches_the_direct_solve(elastic_3d, monkeypatch):
    Kff, rbm = elastic_3d
    b = np.random.default_rng(0).normal(size=Kff.shape[0])
    direct = linsolve.spd_solver(Kff, 2)(b)  # 2: always the sparse LU
    monkeypatch.setattr(linsolve, "DIRECT_LIMIT_3D", 0)
    amg = linsolve.spd_solver(Kff, 3, rbm)(b)
    assert np.linalg.norm(amg - direct) <= 1e-7 * np.linalg.norm(direct)


def test_amg_cg_that_does_not_converge_raises(elastic_3d, monkeypatch):
    Kff, rbm = elastic_3d
    monkeypatch.setattr(linsolve, "DIRECT_LIMIT_3D", 0)
    monkeypatch.setattr(linsolve, "MAXITER", 2)
    solve = linsolve.spd_solver(Kff, 3, rbm)
    with pytest.raises(linsolve.SolverError, match="did not converge: relative residual"):
        solve(np.ones(Kff.shape[0]))
