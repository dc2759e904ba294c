"""Where a thermocouple may go: mesh nodes of the outer surface or of named boundaries, thinned
to a spacing, minus boxes that are not allowed.

The outer surface is every facet that belongs to one cell only (in a 2-D section: its outline;
interfaces between regions are inside). Each candidate carries the name of the boundary it lies
on: the first named boundary of the mesh whose facets are all outer that holds the node; else, for
a node of the outer surface, ``surface`` (an unnamed part of the outline, where an interface may
end); else the first named boundary that holds it.
"""
from __future__ import annotations

from dataclasses import dataclass
from itertools import combinations

import numpy as np
from scipy.spatial import cKDTree

from gatetherm import InputError

UNNAMED = "surface"
"""The boundary name of an outer node that no named boundary holds."""


@dataclass(frozen=True)
class Box:
    """An axis-aligned box of points that are not allowed, m."""

    lo: tuple[float, ...]
    hi: tuple[float, ...]

    def contains(self, xyz: np.ndarray) -> np.ndarray:
        """Mask of the rows of ``xyz`` (m) inside the box, faces included."""
        return np.all((xyz >= np.asarray(self.lo) - 1e-12) & (xyz <= np.asarray(self.hi) + 1e-12), axis=1)


@dataclass(frozen=True)
class Candidates:
    """Candidate sensor locations: mesh nodes."""

    nodes: np.ndarray
    """Mesh node indices."""
    xyz: np.ndarray
    """Their coordinates (candidates x dim), m."""
    boundary: tuple[str, ...]
    """The boundary each lies on."""

    def __len__(self) -> int:
        return len(self.nodes)

    def subset(self, keep: np.ndarray) -> Candidates:
        """The candidates at the mask or indices ``keep``."""
        idx = np.flatnonzero(keep) if np.asarray(keep).dtype == bool else np.asarray(keep, int)
        return Candidates(self.nodes[idx], self.xyz[idx], tuple(self.boundary[i] for i in idx))


def outer_facets(cells: np.ndarray) -> np.ndarray:
    """Facets (F x dim node lists, sorted) that belong to exactly one cell of ``cells`` (E x dim+1)."""
    d = cells.shape[1] - 1
    faces = np.sort(np.vstack([cells[:, list(c)] for c in combinations(range(d + 1), d)]), axis=1)
    uniq, count = np.unique(faces, axis=0, return_counts=True)
    return uniq[count == 1]


def boundary_names(mesh, nodes: np.ndarray) -> tuple[str, ...]:
    """The boundary each of ``nodes`` lies on (module docstring)."""
    facets = outer_facets(mesh.cells)
    outer = {tuple(f) for f in facets}
    is_outer = {b: all(tuple(sorted(f)) in outer for f in mesh.boundaries[b]) for b in mesh.boundaries}
    label = dict.fromkeys(np.unique(facets).tolist(), UNNAMED)
    for b in reversed([b for b in mesh.boundaries if is_outer[b]]):  # the first in mesh order wins
        label.update(dict.fromkeys(np.unique(mesh.boundaries[b]).tolist(), b))
    for b in (b for b in mesh.boundaries if not is_outer[b]):
        for n in np.unique(mesh.boundaries[b]).tolist():
            label.setdefault(n, b)
    return tuple(label.get(int(n), UNNAMED) for n in nodes)


def thin(xyz: np.ndarray, spacing_m: float) -> np.ndarray:
    """Indices of the points kept when each point, in order, removes those within ``spacing_m``
    (m) of it: no two kept points are closer than the spacing; deterministic."""
    if spacing_m <= 0:
        return np.arange(len(xyz))
    tree = cKDTree(xyz)
    gone = np.zeros(len(xyz), bool)
    keep = []
    for i in range(len(xyz)):
        if not gone[i]:
            keep.append(i)
            gone[tree.query_ball_point(xyz[i], spacing_m * (1 - 1e-9))] = True
    return np.array(keep, int)


def candidates(mesh, boundaries=(), spacing_m: float = 0.0, exclude=(), where: str = "--candidates") -> Candidates:
    """The candidate nodes of ``mesh``.

    Parameters
    ----------
    mesh : FrameMesh
        The case's mesh.
    boundaries : sequence of str
        Named boundaries whose nodes are candidates; empty: the outer surface.
    spacing_m : float
        Thin to this spacing, m (0: every node).
    exclude : sequence of Box
        Points inside any of these are not candidates.

    Returns
    -------
    Candidates
    """
    if boundaries:
        bad = [b for b in boundaries if b not in mesh.boundaries]
        if bad:
            raise InputError(f"{where} {bad[0]}", "is not a boundary of the mesh",
                             f"boundaries: {', '.join(mesh.boundaries)}")
        nodes = np.unique(np.concatenate([np.ravel(mesh.boundaries[b]) for b in boundaries]))
    else:
        nodes = np.unique(outer_facets(mesh.cells))
    for box in exclude:
        if len(box.lo) != mesh.dim or len(box.hi) != mesh.dim:
            raise InputError("--exclude", f"a box of {len(box.lo)}-D corners on a {mesh.dim}-D mesh",
                             f"give {2 * mesh.dim} numbers: the low corner, then the high one")
        nodes = nodes[~box.contains(mesh.points[nodes])]
    nodes = nodes[thin(mesh.points[nodes], spacing_m)]
    if not len(nodes):
        raise InputError(where, "no candidate location is left", "name other boundaries, or fewer --exclude boxes")
    return Candidates(nodes, mesh.points[nodes].copy(), boundary_names(mesh, nodes))
