"""The neutral mesh handed from gmsh to the solvers and its meshio and array round trips; the
checks every mesh read from a user's file passes are :mod:`gatetherm.geometry.meshcheck` (their names
importable from here too)."""
from __future__ import annotations

import logging
import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from gatetherm import InputError
from gatetherm import atomic_path
from gatetherm.geometry import msh22
from gatetherm.geometry.meshcheck import (  # noqa: F401 (re-exported)
    CHUNK, DEGENERATE, SNAP_TOLERANCE, check_mesh, components, facet_keys, find_facets, snap_points)

_CELL = {2: "triangle", 3: "tetra"}
_FACET = {2: "line", 3: "triangle"}
_MASK = "group:"
log = logging.getLogger(__name__)


@dataclass(frozen=True)
class FrameMesh:
    """A simplex mesh with named regions, boundaries and sensor nodes.

    ``points`` is (N, dim) in metres; ``cells`` (E, dim+1) node indices;
    ``regions`` maps a name to element indices; ``boundaries`` maps a name to
    (F, dim) facet node lists; ``sensors`` maps a name to a node index.
    """

    dim: int
    points: np.ndarray
    cells: np.ndarray
    regions: dict[str, np.ndarray]
    boundaries: dict[str, np.ndarray]
    sensors: dict[str, int]
    meta: dict = field(default_factory=dict, compare=False)
    """What the mesh was made from, when known: ``{"frame": FrameParams}`` for a mesh built
    by :func:`gatetherm.frame.build.build_mesh` (not kept in files)."""
    lines: dict[str, np.ndarray] = field(default_factory=dict)
    """3-D: named curves as (L, 2) node pairs (a support on a line)."""

    def sensor_xyz(self, name: str) -> np.ndarray:
        return self.points[self.sensors[name]]

    def counts(self) -> dict[str, int]:
        return {"nodes": len(self.points), "elements": len(self.cells),
                "regions": len(self.regions), "boundaries": len(self.boundaries),
                "sensors": len(self.sensors)}


def _groups(m: FrameMesh):
    """(name, dim, cell type, connectivity) for every named group, in file order."""
    d = m.dim
    for name, idx in m.regions.items():
        yield name, d, _CELL[d], m.cells[idx]
    for name, fac in m.boundaries.items():
        yield name, d - 1, _FACET[d], fac
    for name, node in m.sensors.items():
        yield name, 0, "vertex", np.array([[node]])
    for name, pairs in m.lines.items():
        yield name, 1, "line", pairs


def mesh_arrays(m: FrameMesh) -> tuple[np.ndarray, list, dict, dict]:
    """What a VTU or ``.msh`` file holds of ``m``: points (N, 3), cell blocks ``[(type, (C, k)
    nodes)]`` (the regions, boundaries, sensors and lines in turn), cell arrays by name, one
    per block (gmsh physical tags, one ``group:<name>`` 0/1 array per group) and the groups'
    ``[tag, dim]`` by name."""
    groups = list(_groups(m))
    pts = np.zeros((len(m.points), 3))
    pts[:, : m.dim] = m.points
    cells, phys, masks = [], [], {f"{_MASK}{g[0]}": [] for g in groups}
    for tag, (name, _, ctype, conn) in enumerate(groups, start=1):
        cells.append((ctype, np.asarray(conn, dtype=np.int64)))
        phys.append(np.full(len(conn), tag, dtype=np.int32))
        for other in masks:
            masks[other].append(np.full(len(conn), int(other == f"{_MASK}{name}"), dtype=np.int8))
    field_data = {g[0]: np.array([t, g[1]]) for t, g in enumerate(groups, start=1)}
    return pts, cells, {"gmsh:physical": phys, "gmsh:geometrical": phys, **masks}, field_data


def to_meshio(m: FrameMesh, point_data: dict | None = None):
    """Convert to ``meshio.Mesh`` (:func:`mesh_arrays`; VTU keeps no field data)."""
    import meshio

    pts, cells, cell_data, field_data = mesh_arrays(m)
    return meshio.Mesh(pts, cells, point_data=point_data or {}, cell_data=cell_data, field_data=field_data)


def save_mesh(m: FrameMesh, path: str | os.PathLike) -> None:
    """Write ``.msh`` (gmsh 2.2 with physical names) or ``.vtu``, atomically."""
    import meshio

    path = Path(path)
    fmt = {".msh": "gmsh22", ".vtu": "vtu"}.get(path.suffix)
    if fmt is None:
        raise InputError("out", f"unknown mesh format '{path.suffix}'", "use .msh or .vtu")
    mm = to_meshio(m)
    if fmt == "gmsh22":  # the gmsh writer takes only its own tag arrays
        mm.cell_data = {k: v for k, v in mm.cell_data.items() if k.startswith("gmsh:")}
    with atomic_path(path) as tmp:
        meshio.write(tmp, mm, file_format=fmt)


_CORNERS = {"line": 2, "line3": 2, "triangle": 3, "triangle6": 3, "tetra": 4, "tetra10": 4, "vertex": 1}
"""Corner nodes of the cell types read (higher-order cells keep their corners)."""
_KIND = {0: "point", 1: "curve", 2: "surface", 3: "volume"}


def group_name(dim: int, tag: int, names: dict) -> str:
    """The name of the physical group (``dim``, ``tag``), or ``<kind><tag>`` (e.g.
    ``surface3``) for a group without one."""
    return names.get((dim, tag), f"{_KIND[dim]}{tag}")


def _named_blocks(mm):
    """Yield (name, dimension, corner connectivity) per group, from group masks (VTU) or
    gmsh physical tags matched by (dimension, number) with their names (MSH 2.2 and 4.1);
    readers may merge blocks of one cell type."""
    blocks = [(b, _CORNERS[b.type]) for b in mm.cells if b.type in _CORNERS]
    masks = [k for k in mm.cell_data if k.startswith(_MASK)]
    if masks:
        for k in masks:
            for block, on in zip(mm.cells, mm.cell_data[k]):
                on = np.asarray(on, dtype=bool)
                if block.type in _CORNERS and on.any():
                    yield k[len(_MASK):], block.dim, block.data[on][:, :_CORNERS[block.type]]
        return
    if "gmsh:physical" not in mm.cell_data:
        raise InputError("mesh", "has no physical groups", "name the regions, boundaries and points in gmsh")
    names = {(int(v[1]), int(v[0])): k for k, v in mm.field_data.items()}
    phys = dict(zip([id(b) for b in mm.cells], mm.cell_data["gmsh:physical"]))
    for block, n in blocks:
        tags = np.asarray(phys[id(block)])
        for tag in np.unique(tags):
            yield group_name(block.dim, int(tag), names), block.dim, block.data[tags == tag][:, :n]


def from_groups(dim: int, points: np.ndarray, groups) -> FrameMesh:
    """A :class:`FrameMesh` from (name, dimension, connectivity) groups; nodes in no
    element are dropped."""
    regions, boundaries, sensors, lines, chunks, offset = {}, {}, {}, {}, [], 0
    for name, d, conn in groups:
        if d == dim:
            chunks.append(conn)
            regions[name] = np.arange(offset, offset + len(conn)) if name not in regions else \
                np.r_[regions[name], np.arange(offset, offset + len(conn))]
            offset += len(conn)
        elif d == dim - 1:
            boundaries[name] = np.vstack([boundaries[name], conn]) if name in boundaries else conn
        elif d == 0:
            sensors[name] = int(conn[0, 0])
        elif d == 1:
            lines[name] = np.vstack([lines[name], conn]) if name in lines else conn
    if not chunks:
        raise InputError("mesh", f"holds no named {_KIND[dim]} groups", f"add a Physical {_KIND[dim].title()}")
    cells = np.vstack(chunks)
    used = np.zeros(len(points), dtype=bool)  # np.unique(cells) by a mask: 1 ms against 38 ms (3-D frame)
    used[cells.ravel()] = True
    used = np.flatnonzero(used)
    remap = -np.ones(len(points), dtype=np.int64)
    remap[used] = np.arange(len(used))
    sensors, notes = snap_points(points[:, :dim], cells, sensors)
    for note in notes:
        log.warning(note)
    return FrameMesh(dim, points[used][:, :dim].copy(), remap[cells], regions,
                     {k: remap[v] for k, v in boundaries.items()}, {k: int(remap[v]) for k, v in sensors.items()},
                     lines={k: remap[v] for k, v in lines.items()})


def to_arrays(fm: FrameMesh, notes=()) -> tuple[dict, dict[str, np.ndarray]]:
    """The mesh as a JSON-able header and numeric arrays (for a pipe), with ``notes``."""
    meta = {"dim": fm.dim, "regions": list(fm.regions), "boundaries": list(fm.boundaries), "lines": list(fm.lines),
            "sensors": {k: int(v) for k, v in fm.sensors.items()}, "notes": list(notes)}
    arrays = {"points": np.asarray(fm.points, dtype=np.float64), "cells": np.asarray(fm.cells, dtype=np.int64)}
    arrays |= {f"region{i}": np.asarray(v, dtype=np.int64) for i, v in enumerate(fm.regions.values())}
    arrays |= {f"boundary{i}": np.asarray(v, dtype=np.int64).reshape(-1, fm.dim)
               for i, v in enumerate(fm.boundaries.values())}
    arrays |= {f"line{i}": np.asarray(v, dtype=np.int64).reshape(-1, 2) for i, v in enumerate(fm.lines.values())}
    return meta, arrays


def from_arrays(meta: dict, arrays: dict[str, np.ndarray]) -> FrameMesh:
    """The mesh of :func:`to_arrays`, its indices checked (the arrays may come from a
    sandboxed process)."""
    dim = int(meta["dim"])
    points, cells = arrays["points"], arrays["cells"]
    regions = {name: arrays[f"region{i}"] for i, name in enumerate(meta["regions"])}
    boundaries = {name: arrays[f"boundary{i}"] for i, name in enumerate(meta["boundaries"])}
    sensors = {str(k): int(v) for k, v in meta["sensors"].items()}
    lines = {name: arrays[f"line{i}"] for i, name in enumerate(meta.get("lines", []))}
    ok = dim in (2, 3) and points.ndim == 2 and points.shape[1] == dim and cells.ndim == 2 and \
        cells.shape[1] == dim + 1 and cells.dtype.kind == "i" and points.dtype.kind == "f"
    n, e = len(points), len(cells)
    ok = ok and (cells.size == 0 or 0 <= cells.min() and cells.max() < n) and all(
        v.ndim == 1 and (v.size == 0 or 0 <= v.min() and v.max() < e) for v in regions.values()) and all(
        v.ndim == 2 and v.shape[1] == dim and (v.size == 0 or v.min() >= -1 and v.max() < n)
        for v in boundaries.values()) and all(0 <= v < n for v in sensors.values()) and all(
        v.ndim == 2 and v.shape[1] == 2 and (v.size == 0 or 0 <= v.min() and v.max() < n) for v in lines.values())
    if not ok:
        raise ValueError("inconsistent mesh arrays")
    return FrameMesh(dim, points, cells, regions, boundaries, sensors, lines=lines)


def load_mesh(path: str | os.PathLike) -> FrameMesh:
    """Read a mesh with named groups: ``.msh`` (gmsh 2.2 or 4.1, physical groups matched
    by dimension and number) or a ``.vtu`` written by :func:`save_mesh`."""
    import meshio

    path = Path(path)
    if path.suffix not in (".msh", ".vtu"):
        raise InputError(str(path), f"unknown mesh format '{path.suffix}'", "give a .msh or .vtu file")
    try:
        # the format's reader itself: meshio.read prints an unreadable file's error and exits
        mm = msh22.read_binary(path.read_bytes()) if path.suffix == ".msh" else None
        if mm is None:
            import contextlib
            import io

            said = io.StringIO()  # meshio prints its warnings (a section not closed …) to stderr: logged, naming the file
            with contextlib.redirect_stderr(said):
                mm = (meshio.gmsh if path.suffix == ".msh" else meshio.vtu).read(str(path))
            for line in filter(None, (x.strip() for x in said.getvalue().splitlines())):
                log.warning("%s: meshio: %s", path.name, line.removeprefix("Warning: ")[:200])
        dim = max((b.dim for b in mm.cells if b.type in _CORNERS), default=0)
        if dim < 2:
            raise InputError(str(path), "holds no triangles or tetrahedra", "mesh a surface (2-D) or a volume (3-D)")
        if dim == 2 and np.ptp(mm.points[:, 2]) > 1e-12 * max(np.ptp(mm.points[:, :2]), 1.0):
            raise InputError(str(path), "a 2-D mesh must lie in the x-y plane", "mesh the section in z = 0")
        fm = from_groups(dim, np.asarray(mm.points, dtype=np.float64), _named_blocks(mm))
    except (InputError, OSError):
        raise
    except Exception as err:  # noqa: BLE001 - a broken file: meshio's errors are of any type
        raise InputError(str(path), f"is not a readable {path.suffix or 'mesh'} file ({type(err).__name__}: "
                         f"{str(err)[:200]})", "write it again with gmsh (.msh 2.2 or 4.1) or gatetherm mesh (.vtu)") \
            from None
    check_mesh(fm, str(path))
    return fm
