"""Bridge from the neutral :class:`FrameMesh` to scikit-fem meshes and bases."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import skfem

from gatetherm.geometry.mesh import FrameMesh, facet_keys, find_facets

_MESH = {2: skfem.MeshTri, 3: skfem.MeshTet}
_ELEM = {(2, 1): skfem.ElementTriP1, (2, 2): skfem.ElementTriP2,
         (3, 1): skfem.ElementTetP1, (3, 2): skfem.ElementTetP2}
_P0 = {2: skfem.ElementTriP0, 3: skfem.ElementTetP0}


def _entities(t: np.ndarray, local, n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """scikit-fem's ``build_entities``: the facets as sorted node rows in lexicographic order
    and the element-to-facet map, by integer keys instead of ``np.unique(axis=1)`` on the
    rows (1.2 s against 0.25 s on the 3-D frame); also the facets' sorted keys."""
    rows = np.hstack([t[ix] for ix in local])
    keys, first, inverse = np.unique(facet_keys(rows.T, n), return_index=True, return_inverse=True)
    return np.ascontiguousarray(np.sort(rows[:, first], axis=0)), inverse.reshape(len(local), t.shape[1]), keys


def to_skfem(fm: FrameMesh) -> skfem.Mesh:
    """A scikit-fem mesh with the named regions as subdomains and the named
    boundaries as facet sets."""
    mesh = _MESH[fm.dim](np.ascontiguousarray(fm.points.T), np.ascontiguousarray(fm.cells.T))
    n = len(fm.points)
    mesh._facets, mesh._t2f, keys = _entities(mesh.t, mesh.elem.refdom.facets, n)
    boundaries = {}
    for name, fac in fm.boundaries.items():
        ids = find_facets(keys, fac, n)
        if ids is None:
            raise ValueError(f"boundary {name!r} has facets that are not facets of the mesh")
        boundaries[name] = ids
    out = mesh.with_boundaries(boundaries).with_subdomains({k: np.asarray(v) for k, v in fm.regions.items()})
    out._facets, out._t2f = mesh._facets, mesh._t2f  # the copies would find them again
    return out


def dof_basis(mesh: skfem.Mesh, elem: skfem.Element) -> skfem.CellBasis:
    """A basis for DOF numbers, DOF locations and point probes only: no quadrature points,
    so none of the per-element arrays of a full basis (0.3 GB for the vector P1 basis of
    the 3-D frame), for matrices assembled by :mod:`gatetherm.solvers.p1`."""
    d = mesh.dim()
    linear = elem.maxdeg == 1 and elem.interior_dofs == 0 and elem.edge_dofs == 0 and elem.facet_dofs == 0
    # made on one element, then widened to all: the basis functions at no points still cost an
    # einsum over every element (the 3-D frame's vector P1 basis 0.056 s against 0.167 s, benchmarks/assembly_parts.py)
    basis = skfem.CellBasis(mesh, elem, quadrature=(np.zeros((d, 0)), np.zeros(0)), elements=np.array([0]),
                            disable_doflocs=linear)
    basis.tind, basis.nelems, basis.dx = None, mesh.nelements, np.zeros((mesh.nelements, 0))
    if linear:  # the nodes, each repeated for its interleaved components (mapping every element: 1 s in 3-D)
        basis.doflocs = np.repeat(mesh.p, elem.nodal_dofs, axis=1)
    return basis


def complement(n: int, taken: np.ndarray) -> np.ndarray:
    """The indices ``0 … n−1`` not in ``taken``, ascending: by a mask, not ``np.setdiff1d``'s sort
    (under 1 ms against 29 ms for the free displacement DOFs of the 3-D frame,
    ``benchmarks/assembly_parts.py``)."""
    keep = np.ones(n, dtype=bool)
    keep[np.asarray(taken, dtype=np.int64)] = False
    return np.flatnonzero(keep)


def element(dim: int, order: int) -> skfem.Element:
    """Lagrange element of ``order`` (1 or 2) on simplices."""
    return _ELEM[(dim, order)]()


@dataclass(frozen=True)
class Field:
    """A piecewise-constant coefficient: one value per element of the mesh."""

    values: np.ndarray

    @classmethod
    def by_region(cls, mesh: skfem.Mesh, values: dict[str, float], default: float) -> "Field":
        v = np.full(mesh.nelements, float(default))
        for name, val in values.items():
            v[mesh.subdomains[name]] = val
        return cls(v)

    def at(self, basis) -> np.ndarray:
        """Values at the quadrature points of ``basis`` (cell or facet basis)."""
        v = self.values if basis.tind is None else self.values[basis.tind]
        return v[:, None] * np.ones(basis.X.shape[-1])
