"""Interfaces of an assembly: where two regions touch, and cutting the mesh open there.

A conformal mesh of several regions shares the nodes of every interface. A joint (a
contact conductance, an elastic layer) needs the two sides to move and warm apart:
:func:`split_interface` gives the second region copies of the interface's nodes.
"""
from __future__ import annotations

import dataclasses

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

from gatetherm.geometry.mesh import FrameMesh


def interface_name(a: str, b: str) -> str:
    """The boundary name of the interface of regions ``a`` and ``b``: the names sorted, ``"A/B"``."""
    return "/".join(sorted((a, b)))


def parts(fm: FrameMesh) -> list[np.ndarray]:
    """The mesh's connected pieces (cells that share a node), as node indices, largest first."""
    n, e = len(fm.points), len(fm.cells)
    rows = np.repeat(np.arange(e), fm.cells.shape[1])
    graph = coo_matrix((np.ones(rows.size), (rows, e + fm.cells.ravel())), shape=(n + e, n + e))
    count, label = connected_components(graph, directed=False)
    nodes = [np.flatnonzero(label[e:] == k) for k in range(count)]
    return sorted((p for p in nodes if p.size), key=len, reverse=True)


def _facets(cells: np.ndarray) -> np.ndarray:
    """The facets of each cell, (cells, dim + 1, dim) node lists (facet k omits node k)."""
    k = cells.shape[1]
    return np.stack([np.delete(cells, i, axis=1) for i in range(k)], axis=1)


def split_interface(fm: FrameMesh, a: str, b: str) -> tuple[FrameMesh, np.ndarray]:
    """Cut ``fm`` open along the interface of regions ``a`` and ``b`` (the boundary
    :func:`interface_name`): the cells on ``b``'s side get copies of its nodes (appended to
    the points), the boundary itself stays on ``a``'s side, every other boundary follows its
    own cells, point groups stay on ``a``'s side. Around a node where a third region joins
    both sides, the node stays shared. Returns the mesh and the (original, copy) node pairs."""
    name = interface_name(a, b)
    cut_facets = np.sort(fm.boundaries[name], axis=1)
    cut = {tuple(f) for f in cut_facets.tolist()}
    cells = fm.cells
    region = np.full(len(cells), -1)
    for i, idx in enumerate(fm.regions.values()):
        region[idx] = i
    ia, ib = list(fm.regions).index(a), list(fm.regions).index(b)
    nodes = set(np.unique(cut_facets).tolist())
    star_of: dict[int, list[int]] = {n: [] for n in nodes}
    for c in np.flatnonzero(np.isin(cells, list(nodes)).any(axis=1)).tolist():
        for n in cells[c].tolist():
            if n in star_of:
                star_of[n].append(c)
    new_cells, pairs = cells.copy(), []
    for n in sorted(nodes):
        star = np.array(star_of[n])
        side = _a_side(cells[star], n, region[star] == ia, region[star] == ib, cut)
        if side is None:  # a third region joins a's and b's cells around n: no cut here
            continue
        copy = len(fm.points) + len(pairs)
        pairs.append((n, copy))
        moved = star[~side]
        new_cells[moved] = np.where(cells[moved] == n, copy, new_cells[moved])
    pairs = np.array(pairs, dtype=np.int64).reshape(-1, 2)
    points = np.vstack([fm.points, fm.points[pairs[:, 0]]])
    split = set(pairs[:, 0].tolist())
    boundaries = {k: (f if k == name else _follow(f, cells, new_cells, star_of, split))
                  for k, f in fm.boundaries.items()}
    return dataclasses.replace(fm, points=points, cells=new_cells, boundaries=boundaries), pairs


def _a_side(star: np.ndarray, n: int, in_a: np.ndarray, in_b: np.ndarray, cut: set) -> np.ndarray | None:
    """Which of the cells ``star`` around node ``n`` lie on ``a``'s side: those reached from
    ``a``'s cells through facets at ``n`` off the interface (None if that reaches ``b``'s)."""
    owner: dict[tuple, int] = {}
    rows, cols = [], []
    for i, f in enumerate(_facets(star).tolist()):
        for facet in f:
            if n not in facet:
                continue
            key = tuple(sorted(facet))
            if key in cut:
                continue
            if key in owner:
                rows.append(owner[key])
                cols.append(i)
            else:
                owner[key] = i
    m = len(star)
    _, label = connected_components(coo_matrix((np.ones(len(rows)), (rows, cols)), shape=(m, m)), directed=False)
    side = np.isin(label, label[in_a])
    return None if (side & in_b).any() else side


def _follow(facets: np.ndarray, old: np.ndarray, new: np.ndarray, star_of: dict, split: set) -> np.ndarray:
    """Boundary facets renumbered as the cell they belong to numbers its nodes now (a facet of
    a cell that kept those nodes keeps them)."""
    out = facets.copy()
    for r in np.flatnonzero(np.isin(facets, list(split)).any(axis=1)).tolist():
        f = facets[r]
        n = next(x for x in f.tolist() if x in split)
        adjacent = [c for c in star_of[n] if np.isin(f, old[c]).all()]
        renamed = [new[c][np.argmax(old[c][None, :] == f[:, None], axis=1)] for c in adjacent]
        if renamed and not any(np.array_equal(x, f) for x in renamed):
            out[r] = renamed[0]
    return out
