"""The mesh of a CalculiX deck: element types, node numbering, connectivity in CalculiX's
orientation and node order, element faces of a boundary, the twin nodes of a split interface,
and the interpolation of a probe that is not a node.

Nodes are the DOFs of the scalar basis (vertices first, then mid-sides at P2), numbered from 1
in that order; element ``e`` of the mesh is CalculiX element ``e + 1``.
"""
from __future__ import annotations

import re

import numpy as np

from gatetherm import InputError

PREFIX = {"stress": "CPE", "strain": "CPE", "axisymmetric": "CAX"}
"""2-D CalculiX elements by the problem's plane: plane stress and plane strain (plane stress with
the equivalent material, :func:`gatetherm.studies.run.ccx.plane_strain_equivalent`), axisymmetric."""

_PAIRS = {3: ((0, 1), (1, 2), (0, 2), (0, 3), (1, 3), (2, 3)), 2: ((0, 1), (1, 2), (2, 0))}
"""Corner pairs of CalculiX's mid-side nodes: C3D10 nodes 5-10, CPS6/CPE6/CAX6 nodes 4-6."""

CHUNK = 20_000
"""Elements matched at a time (memory: 60 distances of 3 coordinates each per element)."""

_FACE = {3: {3: 1, 2: 2, 0: 3, 1: 4}, 2: {2: 1, 0: 2, 1: 3}}
"""CalculiX face number by the corner a face leaves out (C3D4: 1-2-3, 1-4-2, 2-4-3, 3-4-1;
triangles: 1-2, 2-3, 3-1)."""


def set_name(name: str) -> str:
    """A CalculiX set name (letters, digits, underscores, at most 80 characters)."""
    return re.sub(r"\W", "_", name).upper()[:80]


def element_type(dim: int, plane: str, order: int) -> str:
    """C3D4/C3D10 in 3-D; CPE3/CPE6 (plane strain, and plane stress with the equivalent material),
    CAX3/CAX6 (axisymmetric)."""
    if dim == 3:
        return "C3D10" if order == 2 else "C3D4"
    return PREFIX[plane] + ("6" if order == 2 else "3")


def connectivity(basis) -> np.ndarray:
    """Nodes (0-based) of every element in CalculiX's order: corners with a positive volume
    (area in 2-D), then the mid-side nodes of :data:`_PAIRS` (found by place among the
    element's own DOFs, so twin nodes of a split interface stay apart)."""
    mesh = basis.mesh
    dim = mesh.dim()
    t = mesh.t.T.copy()
    X = mesh.p.T
    if dim == 3:
        a, b, c = (X[t[:, k]] - X[t[:, 0]] for k in (1, 2, 3))
        neg = np.einsum("ij,ij->i", np.cross(a, b), c) < 0
        t[neg] = t[neg][:, [1, 0, 2, 3]]
    else:
        a, b = X[t[:, 1]] - X[t[:, 0]], X[t[:, 2]] - X[t[:, 0]]
        neg = a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0] < 0
        t[neg] = t[neg][:, [0, 2, 1]]
    if basis.elem.maxdeg == 1:
        return t
    ed, out = basis.element_dofs.T, []
    for s in range(0, len(t), CHUNK):  # (elements, mid-sides, local DOFs) distances, a chunk at a time
        tc, ec = t[s:s + CHUNK], ed[s:s + CHUNK]
        mids = np.stack([(X[tc[:, a]] + X[tc[:, b]]) / 2 for a, b in _PAIRS[dim]], axis=1)
        d = np.linalg.norm(basis.doflocs.T[ec][:, None, :, :] - mids[:, :, None, :], axis=-1)
        out.append(np.hstack([tc, np.take_along_axis(ec, d.argmin(axis=2), axis=1)]))
    return np.vstack(out)


def faces(mesh, cells: np.ndarray, boundary: str, where: str) -> list[tuple[int, int]]:
    """(element, CalculiX face number) of every facet of an outer ``boundary``."""
    f = mesh.boundaries[boundary]
    if np.any(mesh.f2t[1, f] >= 0):
        raise InputError(where, f"boundary {boundary} lies inside the body: a pressure on it has no side",
                         "put the pressure on an outer boundary")
    e = mesh.f2t[0, f]
    corners = cells[e, :mesh.dim() + 1]
    on = (corners[:, :, None] == mesh.facets[:, f].T[:, None, :]).any(axis=2)
    left_out = np.argmin(on, axis=1)
    return [(int(el), _FACE[mesh.dim()][int(k)]) for el, k in zip(e, left_out)]


def twin_groups(basis, contacts) -> list[np.ndarray]:
    """Nodes at one place on the two (or more) sides of split interfaces, as groups (0-based)."""
    from gatetherm.solvers.contact import jump

    if not contacts:
        return []
    parent = np.arange(basis.N)

    def root(i):
        while parent[i] != i:
            parent[i] = parent[parent[i]]
            i = parent[i]
        return i

    for c in contacts:
        J, a = jump(basis, basis.mesh, c.boundary, sorted(c.between)[1])
        J = J.tocoo()
        twin = np.empty(J.shape[0], dtype=np.int64)
        twin[J.row[J.data < 0]] = J.col[J.data < 0]
        for i, j in zip(a, twin):
            ri, rj = root(int(i)), root(int(j))
            if ri != rj:
                parent[max(ri, rj)] = min(ri, rj)
    roots = np.array([root(i) for i in range(basis.N)])
    groups: dict[int, list[int]] = {}
    for i in np.flatnonzero(roots != np.arange(basis.N)):
        groups.setdefault(int(roots[i]), [int(roots[i])]).append(int(i))
    return [np.array(sorted(g)) for g in groups.values()]


def interpolation(basis, points) -> list[tuple[np.ndarray, np.ndarray]]:
    """For each point (m), the nodes (0-based) and weights whose sum is the field there: the
    element's shape functions (one node, weight 1, where the point is a node)."""
    if not len(points):
        return []
    W = basis.probes(np.asarray(points, float).T).tocsr()
    out = []
    for i in range(W.shape[0]):
        row = W[i]
        keep = np.abs(row.data) > 1e-12
        out.append((row.indices[keep].astype(int), row.data[keep]))
    return out
