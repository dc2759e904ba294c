"""Joints of an assembly: zero-thickness layers on the interface of two regions, on a mesh
cut open there (:func:`gatetherm.geometry.interface.split_interface`).

Region ``a`` (the first of the sorted pair) keeps the boundary ``"A/B"``; every DOF on it
has a twin at the same place on ``b``'s side. With the jump ``[v] = v_a − v_b`` the layers are

    thermal contact:  ∫ t h [T] [v] ds
    elastic joint:    ∫ t (k_n ([u]·n)([v]·n) + k_t [u]_t·[v]_t) ds

(``t``: the 2-D thickness, 2π r for an axisymmetric section, 1 in 3-D), assembled as
``Jᵀ M J`` with ``M`` the layer's matrix on ``a``'s DOFs and ``J`` the jump. A contact
without a stiffness bonds the two sides mechanically through a joint :data:`BOND` times
stiffer than the adjacent elements (``E/h``): its jump is below 10⁻⁶ of the elements' strain
times their size.
"""
from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from skfem import BilinearForm, FacetBasis, asm
from skfem.helpers import dot

from gatetherm.geometry.mesh import FrameMesh

BOND = 1e6
"""Stiffness of a bonding joint in units of E/h of the adjacent elements."""


@BilinearForm
def layer(u, v, w):
    """A conductance ``w.h`` per unit area (trial and test on side a)."""
    return w.t * w.h * u * v


@BilinearForm
def joint(u, v, w):
    """Normal stiffness ``w.kn`` and tangential ``w.kt`` per unit area (trial and test on side a)."""
    return w.t * (w.kt * dot(u, v) + (w.kn - w.kt) * dot(u, w.n) * dot(v, w.n))


def split_contacts(fm: FrameMesh, contacts) -> FrameMesh:
    """``fm`` cut open along the interface of every contact."""
    from gatetherm.geometry.interface import split_interface

    for c in contacts:
        fm = split_interface(fm, *sorted(c.between))[0]
    return fm


def jump(basis, mesh, boundary: str, b_region: str) -> tuple[sp.csr_matrix, np.ndarray]:
    """``(J, a)``: the DOFs ``a`` on side a of the interface ``boundary`` and the jump
    ``J`` (rows: ``a``; ``(J v)_i = v[a_i] − v[twin_i]``), the twins found by place among
    the DOFs of ``b_region`` (component by component for a vector basis)."""
    from scipy.spatial import cKDTree  # here: a run without contacts does not import it

    a = basis.get_dofs(mesh.boundaries[boundary]).all()
    b = np.unique(basis.element_dofs[:, mesh.subdomains[b_region]])
    groups = basis.split_indices() if hasattr(basis.elem, "elem") else [np.arange(basis.N)]
    X = basis.doflocs
    scale = max(float(np.ptp(mesh.p, axis=1).max()), 1.0)
    twin = np.empty(len(a), dtype=np.int64)
    for g in groups:
        ia, gb = np.flatnonzero(np.isin(a, g)), b[np.isin(b, g)]
        dist, k = cKDTree(X[:, gb].T).query(X[:, a[ia]].T)
        if len(ia) and dist.max() > 1e-9 * scale:
            raise ValueError(f"interface {boundary}: no twin DOF on the side of {b_region}")
        twin[ia] = gb[k]
    n = len(a)
    J = sp.csr_matrix((np.r_[np.ones(n), -np.ones(n)], (np.r_[np.arange(n), np.arange(n)], np.r_[a, twin])),
                      shape=(n, basis.N))
    return J, a


def layer_matrix(basis, mesh, boundary: str, b_region: str, form, thickness, **coefficients) -> sp.csr_matrix:
    """The layer ``form`` (:func:`layer` or :func:`joint`) on the interface ``boundary``
    between its side a and ``b_region``, on all DOFs of ``basis``."""
    fb = FacetBasis(mesh, basis.elem, facets=mesh.boundaries[boundary], intorder=2 * basis.elem.maxdeg)
    M = asm(form, fb, t=thickness.at(fb), **coefficients).tocsr()
    J, a = jump(basis, mesh, boundary, b_region)
    return (J.T @ M[a][:, a] @ J).tocsr()


def bond_stiffness(mesh, boundary: str, E_max: float) -> float:
    """Stiffness per unit area (N/m³) of a joint that bonds: :data:`BOND` E/h, h the
    smallest facet of the interface."""
    f = mesh.facets[:, mesh.boundaries[boundary]]
    X = mesh.p[:, f]
    size = np.linalg.norm(X[:, 1] - X[:, 0], axis=0) if mesh.dim() == 2 else \
        np.sqrt(np.linalg.norm(np.cross(X[:, 1] - X[:, 0], X[:, 2] - X[:, 0], axis=0), axis=0))
    return BOND * E_max / float(size.min())


def joints(basis, mesh, contacts, thickness, E_max: float) -> list[sp.csr_matrix]:
    """The elastic layer of every contact: its joint, or a bond without a stiffness."""
    out = []
    for c in contacts:
        kn, kt = c.stiffness or (bond_stiffness(mesh, c.boundary, E_max),) * 2
        out.append(layer_matrix(basis, mesh, c.boundary, sorted(c.between)[1], joint, thickness, kn=kn, kt=kt))
    return out


def conductances(basis, mesh, contacts, thickness) -> sp.csr_matrix | None:
    """The thermal contact layers of the contacts with a conductance (None if none)."""
    out = [layer_matrix(basis, mesh, c.boundary, sorted(c.between)[1], layer, thickness, h=c.conductance)
           for c in contacts if c.conductance is not None]
    return sum(out[1:], out[0]) if out else None
