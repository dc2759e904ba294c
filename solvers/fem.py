"""Bridge from the neutral :class:`FrameMesh` to scikit-fem meshes and bases."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import skfem

from gatetherm.geometry.mesh import FrameMesh

_MESH = {2: skfem.MeshTri, 3: skfem.MeshTet}
_ELEM = {(2, 1): skfem.ElementTriP1, (2, 2): skfem.ElementTriP2,
         (3, 1): skfem.ElementTetP1, (3, 2): skfem.ElementTetP2}
_P0 = {2: skfem.ElementTriP0, 3: skfem.ElementTetP0}


def to_skfem(fm: FrameMesh) -> skfem.Mesh:
    """A scikit-fem mesh with the named regions as subdomains and the named
    boundaries as facet sets."""
    mesh = _MESH[fm.dim](np.ascontiguousarray(fm.points.T), np.ascontiguousarray(fm.cells.T))
    facet_id = {tuple(f): i for i, f in enumerate(np.sort(mesh.facets.T, axis=1))}
    boundaries = {name: np.array([facet_id[tuple(f)] for f in np.sort(fac, axis=1)], dtype=np.int64)
                  for name, fac in fm.boundaries.items()}
    return mesh.with_boundaries(boundaries).with_subdomains(
        {k: np.asarray(v) for k, v in fm.regions.items()})


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
