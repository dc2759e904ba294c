"""The mesh gmsh holds, as a :class:`~gatetherm.geometry.mesh.FrameMesh` with its named groups:
:func:`extract_mesh` (the frame's builder and a user's gmsh file both read their meshes through it)."""
from __future__ import annotations

import numpy as np

from gatetherm.geometry.mesh import FrameMesh, snap_points


def extract_mesh(gmsh, dim, region_ents, facet_ents, point_of, line_ents=None) -> tuple[FrameMesh, list[str]]:
    """The mesh of the current model with the named groups (entity tags; ``line_ents``: curves of a
    3-D model), and the notes of point groups snapped to nodes
    (:func:`~gatetherm.geometry.mesh.snap_points`)."""
    tags, xyz, _ = gmsh.model.mesh.getNodes()
    index = np.zeros(int(tags.max()) + 1, dtype=np.int64)
    index[tags.astype(np.int64)] = np.arange(len(tags))
    points = xyz.reshape(-1, 3)[:, :dim]

    def elements(d, ents):
        out = []
        for e in ents:
            types, _, nodes = gmsh.model.mesh.getElements(d, e)
            for ty, nd in zip(types, nodes):
                n = gmsh.model.mesh.getElementProperties(ty)[3]
                out.append(index[nd.astype(np.int64)].reshape(-1, n))
        return np.vstack(out) if out else np.zeros((0, d + 1), dtype=np.int64)

    chunks, regions, offset = [], {}, 0
    for name, ents in region_ents.items():
        cells = elements(dim, ents)
        chunks.append(cells)
        regions[name] = np.arange(offset, offset + len(cells))
        offset += len(cells)
    boundaries = {name: elements(dim - 1, ents) for name, ents in facet_ents.items()}
    lines = {name: elements(1, ents) for name, ents in (line_ents or {}).items()}
    sensors = {}
    for name, t in point_of.items():
        ntags, _, _ = gmsh.model.mesh.getNodes(0, t)
        sensors[name] = int(index[int(ntags[0])])
    cells = np.vstack(chunks)
    sensors, notes = snap_points(points, cells, sensors)
    used = np.unique(cells)
    if len(used) != len(points):  # drop nodes of geometry not in any element
        remap = -np.ones(len(points), dtype=np.int64)
        remap[used] = np.arange(len(used))
        points, cells = points[used], remap[cells]
        boundaries = {k: remap[v] for k, v in boundaries.items()}
        sensors = {k: int(remap[v]) for k, v in sensors.items()}
        lines = {k: remap[v] for k, v in lines.items()}
    return FrameMesh(dim, points, cells, regions, boundaries, sensors, lines=lines), notes
