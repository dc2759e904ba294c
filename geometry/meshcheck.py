"""The checks every mesh read from a user's file passes: point groups snapped to the elements' nodes
(:func:`snap_points`), no degenerate elements nor stray boundary facets (:func:`check_mesh`), and the
mesh's connected parts (:func:`components`); the facet keys they use (:func:`facet_keys`,
:func:`find_facets`). The mesh itself is :class:`gatetherm.geometry.mesh.FrameMesh`.
"""
from __future__ import annotations

import numpy as np

from gatetherm import InputError

SNAP_TOLERANCE = 0.01
"""A point group off the mesh's nodes is moved to the nearest node if that is within this
fraction of the body's size (its bounding-box diagonal) or within the longest edge of the
elements at that node; refused beyond."""
DEGENERATE = 1e-10
"""An element whose area (volume) is below this fraction of its longest edge squared (cubed)
is degenerate."""


def snap_points(points: np.ndarray, cells: np.ndarray, sensors: dict[str, int]) -> tuple[dict[str, int], list[str]]:
    """Point groups at nodes of the elements: one at a node in no element moves to the
    nearest node of an element (:data:`SNAP_TOLERANCE`), with a note giving the distance;
    beyond the tolerance an InputError. Returns the nodes and the notes."""
    used = np.zeros(len(points), dtype=bool)
    used[cells.ravel()] = True
    out, notes = dict(sensors), []
    idx = np.flatnonzero(used)
    for name, node in sensors.items():
        if used[node]:
            continue
        dist = np.linalg.norm(points[idx] - points[node], axis=1)
        near = int(idx[np.argmin(dist)])
        at = cells[(cells == near).any(axis=1)]
        edge = max(np.linalg.norm(points[at[:, i]] - points[at[:, j]], axis=1).max()
                   for i in range(cells.shape[1]) for j in range(i))
        tol = max(SNAP_TOLERANCE * float(np.linalg.norm(np.ptp(points[idx], axis=0))), edge)
        where = ", ".join(f"{v:.6g}" for v in points[node])
        if dist.min() > tol:
            raise InputError(f"mesh point {name}", f"at ({where}) is {dist.min():.3g} m from the nearest node of the "
                             f"mesh's elements, more than the tolerance {tol:.3g} m",
                             "put the point on the meshed body (embed it in gmsh)")
        out[name] = near
        notes.append(f"mesh point {name} at ({where}) is not a node of the mesh's elements: read at the nearest "
                     f"node, {dist.min():.3g} m away (embed the point in gmsh to read it exactly)" if in_simplices(
                         points, cells, points[node]) else f"mesh point {name} at ({where}) lies outside the meshed "
                     f"body: read at its nearest node, {dist.min():.3g} m away; move the point onto the body")
    return out, notes


def in_simplices(points: np.ndarray, simplices: np.ndarray, x, tol: float = 1e-9) -> bool:
    """Whether the point ``x`` lies in one of ``simplices`` (node lists: elements, or facets of a lower
    dimension), their faces included, to ``tol`` of the mesh's size."""
    x = np.asarray(x, float)
    eps = tol * (float(np.ptp(points, axis=0).max()) or 1.0)
    v = points[np.asarray(simplices)]  # (S, k+1, dim)
    v = v[((v.min(axis=1) <= x + eps) & (v.max(axis=1) >= x - eps)).all(axis=1)]  # those whose box holds it
    if not len(v):
        return False
    E = np.swapaxes(v[:, 1:] - v[:, :1], 1, 2)  # (S, dim, k): the edges from the first vertex
    lam = np.einsum("skd,sd->sk", np.linalg.pinv(E), x - v[:, 0])
    gap = np.linalg.norm(np.einsum("sdk,sk->sd", E, lam) - (x - v[:, 0]), axis=1)  # off a facet's plane
    return bool(((lam >= -tol).all(axis=1) & (lam.sum(axis=1) <= 1 + tol) & (gap <= eps)).any())


CHUNK = 1 << 15
"""Elements checked at a time: the arrays of a chunk stay in the cache and are made again without
page faults (with the facets of the elements touching the boundaries only, the 3-D frame's check
0.092 s against 0.251 s: ``benchmarks/assembly_parts.py``)."""


def _degenerate(points: np.ndarray, cells: np.ndarray) -> np.ndarray:
    """The rows of ``cells`` whose area or volume is below :data:`DEGENERATE` times their longest
    edge to the power of the dimension."""
    dim = cells.shape[1] - 1
    E = points[cells[:, 1:]] - points[cells[:, :1]]  # the edges from the first node
    size = np.abs(E[:, 0, 0] * E[:, 1, 1] - E[:, 0, 1] * E[:, 1, 0] if dim == 2 else
                  np.einsum("ij,ij->i", E[:, 0], np.cross(E[:, 1], E[:, 2])))
    i, j = np.triu_indices(dim, 1)
    edges = np.concatenate([E, E[:, i] - E[:, j]], axis=1)  # and the others
    return np.flatnonzero(size <= DEGENERATE * np.einsum("ijk,ijk->ij", edges, edges).max(axis=1) ** (dim / 2))


def check_mesh(fm, where: str) -> None:
    """Refuse a mesh (a :class:`~gatetherm.geometry.mesh.FrameMesh`) that cannot be solved on:
    coordinates that are not finite, degenerate (zero-area or zero-volume) elements, boundary
    facets that are not facets of the elements."""
    if not np.isfinite(fm.points).all():
        raise InputError(where, "has node coordinates that are not finite numbers", "check the file")
    bad = np.concatenate([start + _degenerate(fm.points, fm.cells[start:start + CHUNK])
                          for start in range(0, len(fm.cells), CHUNK)] or [np.zeros(0, dtype=np.int64)])
    if len(bad):
        at = ", ".join(f"{v:.4g}" for v in fm.points[fm.cells[bad[0]]].mean(axis=0))
        raise InputError(where, f"has {len(bad)} element(s) of zero {'area' if fm.dim == 2 else 'volume'} "
                         f"(the first at ({at}))", "check the geometry for coincident points or collapsed entities")
    listed = {name: np.asarray(fac) for name, fac in fm.boundaries.items() if np.size(fac)}
    on = np.zeros(len(fm.points) + 1, dtype=bool)  # the nodes of the boundaries' facets (-1: the last)
    for fac in listed.values():
        on[fac.ravel()] = True
    near = fm.cells[np.count_nonzero(on[fm.cells], axis=1) >= fm.dim]  # the elements that may own one
    rows = np.vstack([np.delete(near, i, axis=1) for i in range(fm.dim + 1)])
    facets = np.sort(facet_keys(rows, len(fm.points)))  # not np.unique: numpy 2.4 hashes (benchmarks/assembly_parts.py)
    for name, fac in listed.items():
        if (fac < 0).any() or find_facets(facets, fac, len(fm.points)) is None:
            raise InputError(f"{where}: boundary {name}", "has facets that are not facets of the mesh's elements "
                             "(a surface or curve that is not part of the meshed body?)",
                             "remove it from the group or make it part of the body (fragment it in gmsh)")


def facet_keys(facets: np.ndarray, n: int) -> np.ndarray:
    """One key per facet (rows of ``n`` node numbers, any order within a row), ordered as the
    sorted rows are lexicographically: an integer while n**(nodes per facet) fits in int64 (a
    3-D mesh of up to 2 million nodes), else a record of the sorted row."""
    rows = np.sort(facets, axis=1).astype(np.int64)
    if float(n) ** rows.shape[1] >= 2.0 ** 63:
        return np.ascontiguousarray(rows).view([(f"n{i}", np.int64) for i in range(rows.shape[1])]).ravel()
    key = np.zeros(len(rows), dtype=np.int64)
    for column in rows.T:
        key = key * n + column
    return key


def find_facets(keys: np.ndarray, facets: np.ndarray, n: int) -> np.ndarray | None:
    """Positions in ``keys`` (the sorted :func:`facet_keys` of a mesh's facets) of the rows
    ``facets``; None if one of them is not there."""
    want = facet_keys(np.asarray(facets), n)
    at = np.minimum(np.searchsorted(keys, want), len(keys) - 1)
    return at if np.array_equal(keys[at], want) else None


def components(fm) -> list[set[str]]:
    """The regions of each connected part of the mesh ``fm`` (elements connected through shared
    nodes), largest part first; a region split into several parts is in each of them."""
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components

    n_cells, k = fm.cells.shape
    cell_ids = np.repeat(np.arange(n_cells), k)
    incidence = coo_matrix((np.ones(n_cells * k), (cell_ids, fm.cells.ravel())),
                           shape=(n_cells, len(fm.points))).tocsr()
    _, label = connected_components(incidence @ incidence.T, directed=False)
    parts = sorted(np.unique(label), key=lambda c: -np.count_nonzero(label == c))
    return [{r for r, idx in fm.regions.items() if np.any(label[np.asarray(idx, dtype=np.int64)] == c)}
            for c in parts]
