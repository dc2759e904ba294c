"""Where a thermocouple may go: mesh nodes of the outer surface or of named boundaries, thinned
to a spacing, minus boxes that are not allowed and the parts that cannot carry one (a case's
``[sensors] exclude``: regions and boundaries that rotate or move).

The outer surface is every facet that belongs to one cell only (in a 2-D section: its outline;
interfaces between regions are inside), but for the facets on the axis r = 0 of an axisymmetric
section, which lie inside the solid of revolution (a node of the axis on an end face stays). Each
candidate carries the name of the boundary it lies on: the first named boundary of the mesh whose facets are all outer that holds the node; else, for
a node of the outer surface, ``surface`` (an unnamed part of the outline, where an interface may
end); else the first named boundary that holds it.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from itertools import combinations

import numpy as np
from scipy.spatial import cKDTree

from gatetherm import InputError
from gatetherm.geometry.meshcheck import in_simplices

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
    excluded: dict[str, int] = field(default_factory=dict)
    """Per part that cannot carry a sensor (``[sensors] exclude``, a face a support holds): the candidate
    nodes it took away."""

    def __len__(self) -> int:
        return len(self.nodes)

    def subset(self, keep: np.ndarray) -> Candidates:
        """The candidates at the mask or indices ``keep``."""
        idx = np.flatnonzero(keep) if np.asarray(keep).dtype == bool else np.asarray(keep, int)
        return Candidates(self.nodes[idx], self.xyz[idx], tuple(self.boundary[i] for i in idx), self.excluded)

    def without(self, parts: dict[str, np.ndarray]) -> tuple[np.ndarray, Candidates]:
        """The mask of the candidates on none of ``parts`` ({name: its nodes}), and those candidates,
        the count each part took in :attr:`excluded` (a part that takes none is not listed)."""
        keep, excluded = np.ones(len(self.nodes), bool), dict(self.excluded)
        for name, nodes in parts.items():
            on = np.isin(self.nodes, nodes) & keep
            excluded.update({name: int(on.sum())} if on.any() else {})
            keep &= ~on
        return keep, dataclasses.replace(self.subset(keep), excluded=excluded)


def outer_facets(cells: np.ndarray) -> np.ndarray:
    """Facets (F x dim node lists, sorted) that belong to exactly one cell of ``cells`` (E x dim+1)."""
    d = cells.shape[1] - 1
    faces = np.sort(np.vstack([cells[:, list(c)] for c in combinations(range(d + 1), d)]), axis=1)
    uniq, count = np.unique(faces, axis=0, return_counts=True)
    return uniq[count == 1]


def surface_facets(mesh, axisymmetric: bool = False) -> np.ndarray:
    """:func:`outer_facets` of the mesh, less those on the axis x = 0 of an ``axisymmetric`` section."""
    facets = outer_facets(mesh.cells)
    if not axisymmetric:
        return facets
    tol = 1e-9 * (float(np.ptp(mesh.points, axis=0).max()) or 1.0)
    return facets[~np.all(np.abs(mesh.points[facets, 0]) <= tol, axis=1)]


def boundary_names(mesh, nodes: np.ndarray, skip=()) -> tuple[str, ...]:
    """The boundary each of ``nodes`` lies on (module docstring); one of ``skip`` only where it lies on no other."""
    facets = outer_facets(mesh.cells)
    outer = {tuple(f) for f in facets}
    is_outer = {b: b not in skip and all(tuple(sorted(f)) in outer for f in mesh.boundaries[b])
                for b in mesh.boundaries}
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


def unmountable_nodes(mesh, names) -> dict[str, np.ndarray]:
    """The nodes of each of ``names`` (a region's: every node of its elements, its interfaces
    included; a boundary's: every node of its facets), where no thermocouple can go."""
    out = {}
    for n in names:
        if n in mesh.regions:
            out[n] = np.unique(mesh.cells[np.asarray(mesh.regions[n], int)])
        elif n in mesh.boundaries:
            out[n] = np.unique(np.ravel(mesh.boundaries[n]))
        else:
            raise InputError(f"[sensors] exclude {n}", "is not a region or boundary of the mesh",
                             f"names: {', '.join((*mesh.regions, *mesh.boundaries))}")
    return out

def part_at(mesh, names, xyz, tol: float = 1e-9) -> str | None:
    """The first of ``names`` (regions, boundaries) that the point ``xyz`` (m) lies in or on (a
    region: inside one of its elements, faces included; a boundary: on one of its facets), else None."""
    return next((n for n in names if in_simplices(mesh.points, mesh.cells[np.asarray(mesh.regions[n], int)]
                                                  if n in mesh.regions else mesh.boundaries[n], xyz, tol)), None)


def seated_nodes(mesh, names) -> dict[str, np.ndarray]:
    """The nodes of each boundary of ``names`` (faces a support holds) on no free outer facet: between the
    face and what holds it. Its edges' nodes, on a free face too, stay (the side of a foot, at its seat)."""
    held = {tuple(f) for n in names for f in np.sort(np.asarray(mesh.boundaries[n]), axis=1)}
    free = np.unique([f for f in outer_facets(mesh.cells) if tuple(f) not in held])
    return {n: np.setdiff1d(np.unique(np.ravel(mesh.boundaries[n])), free) for n in names}


def candidates(mesh, boundaries=(), spacing_m: float = 0.0, exclude=(), where: str = "--candidates",
               unmountable=(), axisymmetric: bool = False) -> Candidates:
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
    unmountable : sequence of str
        Regions and boundaries whose nodes are not candidates (:func:`unmountable_nodes`; a case's
        ``[sensors] exclude``).
    axisymmetric : bool
        An axisymmetric section: the axis is no surface (:func:`surface_facets`).

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
        nodes = np.unique(surface_facets(mesh, axisymmetric))
    for box in exclude:
        if len(box.lo) != mesh.dim or len(box.hi) != mesh.dim:
            raise InputError("--exclude", f"a box of {len(box.lo)}-D corners on a {mesh.dim}-D mesh",
                             f"give {2 * mesh.dim} numbers: the low corner, then the high one")
        nodes = nodes[~box.contains(mesh.points[nodes])]
    excluded = {}
    for name, held in unmountable_nodes(mesh, unmountable).items():
        out = np.isin(nodes, held)
        excluded[name] = int(out.sum())
        nodes = nodes[~out]
    nodes = nodes[thin(mesh.points[nodes], spacing_m)]
    if not len(nodes):
        raise InputError(where, "no candidate location is left", "name other boundaries, or fewer --exclude boxes"
                         + (" or [sensors] exclude names" if unmountable else ""))
    return Candidates(nodes, mesh.points[nodes].copy(), boundary_names(mesh, nodes), excluded)


ROTATING = ("rotating_cylinder", "rotating_disc")
"""The film correlations of a part that rotates."""


def on_rotating(case, sensors) -> list[str]:
    """One line per sensor of ``sensors`` (``.name``, ``.node``) on a region that a film of
    :data:`ROTATING` bounds and the case's ``[sensors] exclude`` does not name: a part that likely
    rotates, where no thermocouple can go."""
    mesh, out = case.mesh, []
    for film in case.problem.films:
        if getattr(film.law, "correlation", "") not in ROTATING or film.boundary not in mesh.boundaries:
            continue
        facets = {tuple(f) for f in np.sort(np.asarray(mesh.boundaries[film.boundary]), axis=1)}
        for region, cells in mesh.regions.items():
            if region in case.unmountable:
                continue
            nodes = set(np.unique(mesh.cells[np.asarray(cells, int)]).tolist())
            if not any(set(f) <= nodes for f in facets):
                continue
            out += [f"{x.name} lies on region '{region}', which the {film.law.correlation} film of '{film.boundary}' "
                    "bounds: if it rotates, no thermocouple can go there; name it in [sensors] exclude"
                    for x in sensors if x.node in nodes]
    return out
