"""Build and mesh the frame with gmsh (OpenCASCADE kernel), 2-D or 3-D.

gmsh is process-global state; :func:`gmsh_session` confines it to a ``with``
block and always finalises. The result is a :class:`FrameMesh` whose regions,
boundaries and sensors are referred to by name only.
"""
from __future__ import annotations

import contextlib
import logging
import signal
import threading

import numpy as np

from gatetherm.geometry.frame import (FrameParams, MeshParams, part_boxes, sensor_points,
                            tank_box, validate, validate_mesh)
from gatetherm.geometry.mesh import FrameMesh
from gatetherm.geometry.sizing import check_mesh_size

log = logging.getLogger(__name__)
_TOL = 1e-7


@contextlib.contextmanager
def gmsh_session(name: str = "frame", verbosity: int = 0):
    """Initialise gmsh for the duration of the block, quietly, and finalise it."""
    import gmsh

    if gmsh.isInitialized():
        gmsh.finalize()
    gmsh.initialize(interruptible=False)
    if threading.current_thread() is threading.main_thread():  # gmsh resets SIGTERM: Python's handler back
        for sig in (signal.SIGINT, signal.SIGTERM):
            if signal.getsignal(sig) is not None:
                signal.signal(sig, signal.getsignal(sig))
    try:
        gmsh.option.setNumber("General.Terminal", int(verbosity > 0))
        gmsh.option.setNumber("General.Verbosity", verbosity)
        gmsh.model.add(name)
        yield gmsh
    finally:
        gmsh.finalize()


def _inside(c, box, dim) -> bool:
    return all(box[2 * i] - _TOL <= c[i] <= box[2 * i + 1] + _TOL for i in range(dim))


def _on_box_surface(c, box, dim) -> bool:
    return _inside(c, box, dim) and any(
        abs(c[i] - box[2 * i + s]) < _TOL for i in range(dim) for s in (0, 1))


def _add_box(occ, b, dim):
    if dim == 2:
        return occ.addRectangle(b[0], b[2], 0.0, b[1] - b[0], b[3] - b[2])
    return occ.addBox(b[0], b[2], b[4], b[1] - b[0], b[3] - b[2], b[5] - b[4])


def _size_field(gmsh, size: float, mp: MeshParams, refine_curves):
    """Finer elements near the tank wall and the member joints."""
    f = gmsh.model.mesh.field
    dist = f.add("Distance")
    key = "CurvesList" if refine_curves[0][0] == 1 else "SurfacesList"
    f.setNumbers(dist, key, [t for _, t in refine_curves])
    f.setNumber(dist, "Sampling", 40)
    thr = f.add("Threshold")
    f.setNumber(thr, "InField", dist)
    f.setNumber(thr, "SizeMin", size * mp.refine)
    f.setNumber(thr, "SizeMax", size)
    f.setNumber(thr, "DistMin", 0.5 * size)
    f.setNumber(thr, "DistMax", 3.0 * size)
    f.setAsBackgroundMesh(thr)
    gmsh.option.setNumber("Mesh.MeshSizeExtendFromBoundary", 0)
    gmsh.option.setNumber("Mesh.MeshSizeFromPoints", 0)
    gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", 0)


def build_mesh(p: FrameParams, dim: int = 2, mesh: MeshParams = MeshParams()) -> FrameMesh:
    """Mesh the frame in ``dim`` = 2 (plane section) or 3 (solid) dimensions."""
    validate(p, dim)
    validate_mesh(mesh)
    check_mesh_size(p, mesh, dim)  # before gmsh runs
    boxes = part_boxes(p, dim)
    tank = tank_box(p, dim)
    sensors = sensor_points(p, dim)
    with gmsh_session() as gmsh:
        occ = gmsh.model.occ
        tags = {name: _add_box(occ, b, dim) for name, b in boxes.items()}
        hole = _add_box(occ, tank, dim)
        occ.cut([(dim, tags["column_L"])], [(dim, hole)])
        pts = [(0, occ.addPoint(*xyz)) for xyz in sensors.values()]
        occ.fragment(occ.getEntities(dim), pts)
        occ.synchronize()

        region_ents: dict[str, list[int]] = {n: [] for n in boxes}
        for d, t in gmsh.model.getEntities(dim):
            c = occ.getCenterOfMass(d, t)
            name = next(n for n, b in boxes.items() if _inside(c, b, dim))
            region_ents[name].append(t)
        bnd = gmsh.model.getBoundary(gmsh.model.getEntities(dim), combined=True, oriented=False)
        facet_ents: dict[str, list[int]] = {"mounting_face": [], "tank_wall": [], "free_surface": []}
        refine = []
        for d, t in bnd:
            c = occ.getCenterOfMass(d, abs(t))
            if abs(c[1]) < _TOL:
                facet_ents["mounting_face"].append(abs(t))
            elif _on_box_surface(c, tank, dim):
                facet_ents["tank_wall"].append(abs(t))
                refine.append((d, abs(t)))
            else:
                facet_ents["free_surface"].append(abs(t))
        # joints: internal facets shared by a column and an arm or tie bar
        for d, t in gmsh.model.getEntities(dim - 1):
            up, _ = gmsh.model.getAdjacencies(d, t)
            if len(up) == 2:
                refine.append((d, t))
        for name, ents in region_ents.items():
            gmsh.model.setPhysicalName(dim, gmsh.model.addPhysicalGroup(dim, ents), name)
        for name, ents in facet_ents.items():
            gmsh.model.setPhysicalName(dim - 1, gmsh.model.addPhysicalGroup(dim - 1, ents), name)
        point_of = {}
        for name, xyz in sensors.items():
            found = gmsh.model.getEntitiesInBoundingBox(
                *(v - _TOL for v in xyz), *(v + _TOL for v in xyz), dim=0)
            point_of[name] = found[0][1]
        _size_field(gmsh, mesh.size if dim == 2 else mesh.size_3d, mesh, refine)
        gmsh.option.setNumber("Mesh.Algorithm3D", 10)  # HXT: fast Delaunay
        gmsh.option.setNumber("General.NumThreads", 1)  # threads make meshes differ run to run
        gmsh.model.mesh.generate(dim)
        return _extract(gmsh, dim, region_ents, facet_ents, point_of, p)


def _extract(gmsh, dim, region_ents, facet_ents, point_of, p, line_ents=None) -> FrameMesh:
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
    used = np.unique(cells)
    if len(used) != len(points):  # drop nodes of geometry not in any element
        remap = -np.ones(len(points), dtype=np.int64)
        remap[used] = np.arange(len(used))
        points, cells = points[used], remap[cells]
        boundaries = {k: remap[v] for k, v in boundaries.items()}
        sensors = {k: int(remap[v]) for k, v in sensors.items()}
        lines = {k: remap[v] for k, v in lines.items()}
    log.info("meshed %d-D frame: %d nodes, %d elements", dim, len(points), len(cells))
    return FrameMesh(dim, points, cells, regions, boundaries, sensors, {"frame": p} if p is not None else {}, lines)
