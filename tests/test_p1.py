"""The vectorised P1 matrices equal scikit-fem's forms to round-off, in 2-D and 3-D,
with element-wise coefficients (the frame's regions) and thickness."""
from __future__ import annotations

import numpy as np
import pytest
from scipy.sparse import coo_matrix
from skfem import CellBasis, ElementVector, asm

from gatetherm.solvers import p1
from gatetherm.solvers.elasticity import moduli, stiffness, thermal_load
from gatetherm.solvers.fem import Field, dof_basis, element, to_skfem
from gatetherm.solvers.heat import capacity, conduction


def _close(A, B) -> float:
    return abs(A - B).max() / abs(B).max()


@pytest.mark.parametrize("dim", [2, 3])
def test_p1_matrices_equal_the_forms(dim, frame_2d, frame_3d):
    fm = frame_2d if dim == 2 else frame_3d
    mesh = to_skfem(fm)
    rng = np.random.default_rng(dim)
    c, k, E = (Field(rng.uniform(1.0, 2.0, mesh.nelements) * s) for s in (3e6, 48.0, 1.2e11))
    nu, t = Field(rng.uniform(0.2, 0.3, mesh.nelements)), Field(rng.uniform(0.05, 0.2, mesh.nelements))
    sb = CellBasis(mesh, element(dim, 1), intorder=2)
    vb = CellBasis(mesh, ElementVector(element(dim, 1)), intorder=1)
    tb = CellBasis(mesh, element(dim, 1), intorder=1)
    lam, mu, b = moduli(E.values, nu.values, np.full(mesh.nelements, 1e-5), dim)
    G, vol = p1.gradients(mesh.p.T, mesh.t.T)
    pattern = p1.Pattern(mesh.t.T, mesh.nvertices)
    th = t.values
    pairs = [
        (pattern.scalar(p1.mass, G, vol, c.values * th), asm(capacity, sb, rc=c.at(sb), t=t.at(sb))),
        (pattern.scalar(p1.conduction, G, vol, k.values * th), asm(conduction, sb, k=k.at(sb), t=t.at(sb))),
        (p1.stiffness(pattern, G, vol, lam * th, mu * th),
         asm(stiffness, vb, lam=Field(lam).at(vb), mu=Field(mu).at(vb), t=t.at(vb))),
        (p1.thermal_load(pattern, G, vol, b * th), asm(thermal_load, tb, vb, b=Field(b).at(vb), t=t.at(vb))),
    ]
    for fast, reference in pairs:
        assert fast.shape == reference.shape
        assert _close(fast, reference) < 1e-13


@pytest.mark.parametrize("dim, plane", [(2, "stress"), (2, "strain"), (3, "stress")])
def test_p1_stress_projection_equals_the_forms(dim, plane, frame_2d, frame_3d):
    from gatetherm.solvers.stress import COMPONENTS, _INDEX, recovery, stress_of_T, stress_of_u
    from skfem.helpers import div  # noqa: F401  (the forms' helpers)
    from skfem.assembly import BilinearForm  # noqa: F401
    from gatetherm.solvers.stress import mass

    fm = frame_2d if dim == 2 else frame_3d
    mesh = to_skfem(fm)
    rng = np.random.default_rng(1)
    f = {"E": Field(rng.uniform(1e11, 2e11, mesh.nelements)), "nu": Field(rng.uniform(0.2, 0.3, mesh.nelements)),
         "alpha": Field(rng.uniform(1e-5, 2e-5, mesh.nelements))}
    region = mesh.subdomains["column_L"]
    for elements in (None, region):
        rec = recovery(mesh, 1, f, dim, plane, element(dim, 1), elements)
        kw = {"intorder": 2} if elements is None else {"intorder": 2, "elements": elements}
        sb, ub = CellBasis(mesh, element(dim, 1), **kw), CellBasis(mesh, ElementVector(element(dim, 1)), **kw)
        lam, mu, b = (Field(v).at(sb) for v in moduli(f["E"].values, f["nu"].values, f["alpha"].values, dim, plane))
        assert _close(rec.Q[COMPONENTS[(dim, plane)][0]], asm(stress_of_T, sb, sb, b=b)) < 1e-13
        u, z = rng.normal(size=ub.N), rng.normal(size=sb.N)
        rhs, grad = rec.S(u), rec.S.transposed(z)
        for c in COMPONENTS[(dim, plane)]:
            ref = asm(stress_of_u, ub, sb, lam=lam, mu=mu, i=_INDEX[c][0], j=_INDEX[c][1], dim=dim)
            assert _close(rhs[c], ref @ u) < 1e-13, c
            assert _close(grad[c], ref.T @ z) < 1e-13, c
        M = asm(mass, sb)
        a = np.unique(sb.element_dofs)
        x = rng.normal(size=len(a))
        np.testing.assert_allclose(rec.lu.solve(M[a][:, a] @ x), x, rtol=1e-9)


@pytest.mark.parametrize("dim", [2, 3])
def test_p1_fixed_dofs_equal_scikit_fem_facet_dofs(dim, frame_2d, frame_3d):
    """The nodal shortcut of ``fixed_dofs`` gives scikit-fem's facet DOFs, for every component
    set of a support (a sliding support holds one component)."""
    from gatetherm.solvers.elasticity import fixed_dofs
    from gatetherm.solvers.problem import Support

    mesh = to_skfem(frame_2d if dim == 2 else frame_3d)
    vb = CellBasis(mesh, ElementVector(element(dim, 1)), intorder=1)
    names = [f"u^{c + 1}" for c in range(dim)]
    for comps in [(1,), tuple(range(dim))]:
        want = np.unique(vb.get_dofs(mesh.boundaries["mounting_face"]).all([names[c] for c in comps]))
        got = fixed_dofs(vb, mesh, [Support("mounting_face", comps)])
        assert len(want) > 0 and np.array_equal(got, want)


@pytest.mark.parametrize("dim", [2, 3])
def test_facets_by_integer_keys_equal_scikit_fem_entities(dim, frame_2d, frame_3d):
    """``to_skfem`` finds the facets and the element-to-facet map by integer keys: exactly
    scikit-fem's ``build_entities`` (same facets, same order, same map)."""
    from skfem import MeshTet, MeshTri

    fm = frame_2d if dim == 2 else frame_3d
    mesh = to_skfem(fm)
    ref = (MeshTri if dim == 2 else MeshTet)(np.ascontiguousarray(fm.points.T), np.ascontiguousarray(fm.cells.T))
    facets, t2f = ref.build_entities(ref.t, ref.elem.refdom.facets)
    assert np.array_equal(mesh.facets, facets) and np.array_equal(mesh.t2f, t2f)


@pytest.mark.parametrize("order", [1, 2])
@pytest.mark.parametrize("dim", [2, 3])
def test_dof_basis_numbers_locates_and_probes_as_a_full_basis(dim, order, frame_2d, frame_3d):
    """``dof_basis`` is made on one element and widened: its DOFs, element DOFs, DOF locations
    and probes equal those of scikit-fem's basis on every element."""
    fm = frame_2d if dim == 2 else frame_3d
    mesh = to_skfem(fm)
    x = fm.points[fm.cells[::997]].mean(axis=1).T  # element centroids
    for elem in (element(dim, order), ElementVector(element(dim, order))):
        got = dof_basis(mesh, elem)
        want = CellBasis(mesh, elem, quadrature=(np.zeros((dim, 0)), np.zeros(0)))
        assert got.N == want.N and got.nelems == want.nelems == mesh.nelements
        assert np.array_equal(got.element_dofs, want.element_dofs)
        assert np.abs(got.doflocs - want.doflocs).max() < 1e-15
        assert abs(got.probes(x) - want.probes(x)).max() < 1e-12


def test_complement_equals_setdiff():
    """``complement`` gives what ``np.setdiff1d(np.arange(n), taken)`` gives: repeated, unsorted
    or no indices taken, and all of them."""
    from gatetherm.solvers.fem import complement

    rng = np.random.default_rng(5)
    for n, taken in ((10, [7, 2, 2, 9]), (10, []), (4, [3, 0, 1, 2]), (1000, rng.integers(0, 1000, 300))):
        got = complement(n, np.array(taken, dtype=int))
        assert got.dtype.kind == "i" and np.array_equal(got, np.setdiff1d(np.arange(n), taken))


def test_bordered_equals_block_diag():
    """``heat.bordered`` gives ``sp.block_diag([A, diag(d)])`` exactly: no border, a border of
    zeros (no entries), and one with zeros and values."""
    import scipy.sparse as sp

    from gatetherm.solvers.heat import bordered

    A = sp.random(30, 30, density=0.2, random_state=1, format="csr")
    for d in ([], [0.0, 0.0], [2.0, 0.0, 3.0]):
        got, want = bordered(A, d), sp.block_diag([A, sp.diags(d)]).tocsr() if d else A
        want.eliminate_zeros()
        assert got.shape == want.shape and got.nnz == want.nnz and abs(got - want).max() == 0.0


@pytest.mark.parametrize("dim", [2, 3])
def test_boundary_films_in_numpy_equal_the_facet_forms(dim, frame_2d, frame_3d):
    """The P1 facet mass and load of :func:`~gatetherm.solvers.heat.boundary_terms` equal
    scikit-fem's ``film`` and ``film_load`` over a facet basis, with an element-wise thickness."""
    from skfem import FacetBasis

    from gatetherm.solvers.heat import boundary_terms, film, film_load

    mesh = to_skfem(frame_2d if dim == 2 else frame_3d)
    t = Field(np.random.default_rng(3).uniform(0.05, 0.2, mesh.nelements) if dim == 2 else np.ones(mesh.nelements))
    for name in ("tank_wall", "free_surface"):
        A, a = boundary_terms(mesh, name, element(dim, 1), 2, t)
        fb = FacetBasis(mesh, element(dim, 1), facets=mesh.boundaries[name], intorder=2)
        assert _close(A, asm(film, fb, h=1.0, t=t.at(fb))) < 1e-13
        assert np.abs(a - asm(film_load, fb, h=1.0, t=t.at(fb))).max() < 1e-13 * np.abs(a).max()


@pytest.mark.parametrize("dim", [2, 3])
def test_probes_by_barycentric_coordinates_equal_scikit_fems(dim, frame_2d, frame_3d, monkeypatch):
    """At the frame's sensor nodes and inside elements, scalar and vector P1 bases: the
    matrix of scikit-fem's element finder to round-off; for P2, and for a point outside the
    body, scikit-fem's own (it raises there)."""
    fm = frame_2d if dim == 2 else frame_3d
    mesh = to_skfem(fm)
    rng = np.random.default_rng(dim)
    inside = fm.points[fm.cells[rng.choice(len(fm.cells), 12, replace=False)]]
    weights = rng.dirichlet(np.ones(dim + 1), 12)
    X = np.vstack([fm.points[list(fm.sensors.values())], np.einsum("ek,ekd->ed", weights, inside)]).T
    for elem in (element(dim, 1), ElementVector(element(dim, 1))):
        basis = CellBasis(mesh, elem, intorder=1)
        ours, theirs = p1.probes(basis, X), basis.probes(X).tocsr()
        assert ours.shape == theirs.shape and _close(ours.toarray(), theirs.toarray()) < 1e-13
        assert ours.nnz == (dim + 1) * X.shape[1] * (dim if isinstance(elem, ElementVector) else 1)
    asked = []
    P2 = CellBasis(mesh, element(dim, 2), intorder=2)
    marker = coo_matrix(np.full((1, 1), 7.0))  # what scikit-fem's probes give, as CSR
    monkeypatch.setattr(type(P2), "probes", lambda self, x: asked.append(x.shape) or marker)
    assert p1.probes(P2, X).format == "csr" and p1.probes(P2, X).toarray().tolist() == [[7.0]]
    outside = np.full((dim, 1), 10.0)  # 10 m away: in no element around the nearest node
    assert p1.probes(CellBasis(mesh, element(dim, 1), intorder=1), outside).toarray().tolist() == [[7.0]]
    assert asked == [X.shape, X.shape, (dim, 1)]
