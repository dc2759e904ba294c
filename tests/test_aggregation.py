"""The level-by-level smoothed-aggregation hierarchy is pyamg's with its energy minimisation:
the same levels and prolongator patterns, values to round-off, the same iterations, for
elasticity (rigid-body modes, node blocks) and heat (constants, relaxed)."""
from __future__ import annotations

import numpy as np
import pytest
import scipy.sparse as sp
from skfem import Basis, ElementTetP1, ElementVector, MeshTet, asm
from skfem.models.poisson import laplace, mass

from gatetherm.solvers import linsolve
from gatetherm.solvers.elasticity import stiffness
from gatetherm.solvers.iterative import AMG, PCG
from gatetherm.solvers.material import lame

MESH = MeshTet.init_tensor(np.linspace(0, 1, 31), np.linspace(0, 0.2, 9), np.linspace(0, 0.3, 11))


def _elastic():
    vb = Basis(MESH, ElementVector(ElementTetP1()))
    lam, mu = lame(2.1e11, 0.3)
    K = asm(stiffness, vb, lam=lam, mu=mu, t=1.0)
    free = np.setdiff1d(np.arange(vb.N), vb.get_dofs(lambda x: x[0] < 1e-9).all())
    return K[free][:, free].tocsr(), linsolve.rigid_body_modes(vb.doflocs, vb.split_indices())[free], 3


def _heat():
    b = Basis(MESH, ElementTetP1())
    return (asm(mass, b) * 7850 * 460 / 30.0 + asm(laplace, b) * 50.0).tocsr(), None, 1


@pytest.mark.parametrize("system", [_elastic, _heat], ids=["elastic", "heat"])
def test_the_hierarchy_is_pyamgs_energy_minimisation(system):
    A, modes, block = system()
    smooth = "energy" if modes is not None else ("energy", {"maxiter": 2})
    ours, theirs = AMG(A, modes, block, coarsest=40), AMG(A, modes, block, smooth=smooth, coarsest=40)
    assert len(ours.ml.levels) == len(theirs.ml.levels) >= 3
    for a, b in zip(ours.ml.levels[:-1], theirs.ml.levels[:-1]):
        Pa, Pb = a.P.astype(float).tocsr(), b.P.astype(float).tocsr()
        assert Pa.shape == Pb.shape and np.array_equal(Pa.indptr, Pb.indptr) and np.array_equal(Pa.indices, Pb.indices)
        assert abs(Pa - Pb).max() <= 1e-6 * abs(Pb).max()  # float32 levels: apart by float32 round-off at most
    rhs = np.random.default_rng(0).normal(size=(A.shape[0], 2))
    x = [PCG(A, modes, block, amg=amg, rtol=1e-10, split=False) for amg in (ours, theirs)]
    X = [p(rhs) for p in x]
    assert x[0].iterations == x[1].iterations
    assert np.abs(X[0] - X[1]).max() <= 1e-9 * np.abs(X[1]).max()
    assert np.linalg.norm(A @ X[0] - rhs) <= 1e-10 * np.linalg.norm(rhs) * 1.01


def test_an_energy_minimisation_with_nothing_to_improve_keeps_the_tentative_prolongator():
    """Where ``A T`` is already zero within the pattern (a matrix with no couplings), the
    tentative prolongator comes back unchanged, as pyamg's does."""
    from pyamg.aggregation.aggregate import standard_aggregation
    from pyamg.aggregation.tentative import fit_candidates
    from pyamg.strength import symmetric_strength_of_connection

    from gatetherm.solvers.aggregation import energy_smoothed

    A = sp.csr_array(sp.kron(sp.identity(20), sp.csr_matrix(np.array([[2.0, -1.0], [-1.0, 2.0]]))))
    C = symmetric_strength_of_connection(A, theta=0.0)
    T, Bc = fit_candidates(standard_aggregation(C)[0], np.array([[1.0, 1.0] * 20]).T)
    P = energy_smoothed(A, T, C, Bc, 4)
    assert P is T
