"""Volumes of a mesh's parts: a region's (:func:`region_volume`) and a cavity's that a closed
boundary encloses (:func:`enclosed_volume`, e.g. an oil tank's)."""
from __future__ import annotations

import numpy as np

from gatetherm.geometry.mesh import FrameMesh


def enclosed_volume(fm: FrameMesh, boundary: str, thickness: float = 1.0) -> float:
    """Volume (m³) of the cavity a closed boundary of the mesh encloses, by the divergence
    theorem over its facets (2-D: area times ``thickness``)."""
    fac = np.sort(fm.boundaries[boundary], axis=1)
    near = np.flatnonzero(np.isin(fm.cells, fac).sum(axis=1) >= fm.dim)  # cells with a whole facet there
    cells = fm.cells[near]  # each facet of each, and the node opposite it
    faces = np.sort(np.stack([np.delete(cells, k, axis=1) for k in range(fm.dim + 1)], axis=1), axis=2)
    opposite = dict(zip(map(tuple, faces.reshape(-1, fm.dim).tolist()), cells.ravel().tolist()))
    X, Y = fm.points[fac], fm.points[[opposite[f] for f in map(tuple, fac.tolist())]]
    E = X[:, 1:] - X[:, :1]
    n = np.stack([-E[:, 0, 1], E[:, 0, 0]], axis=1) if fm.dim == 2 else np.cross(E[:, 0], E[:, 1])
    n *= -np.sign(np.einsum("ij,ij->i", n, Y - X[:, 0]))[:, None]  # away from the solid: into the cavity
    measure = np.linalg.norm(n, axis=1) / (1.0 if fm.dim == 2 else 2.0)
    n /= np.linalg.norm(n, axis=1)[:, None]
    # the cavity's own outward normal is -n
    return float(-np.sum(np.einsum("ij,ij->i", X.mean(axis=1), n) * measure) / fm.dim) * thickness


def region_volume(fm: FrameMesh, region: str, thickness: float = 1.0) -> float:
    """Volume (m³) of a region of the mesh (2-D: area times ``thickness``)."""
    X = fm.points[fm.cells[fm.regions[region]]]
    E = X[:, 1:] - X[:, :1]
    return float(np.abs(np.linalg.det(E)).sum()) / (2.0 if fm.dim == 2 else 6.0) * thickness
