"""The neutral mesh handed from gmsh to the solvers, and its meshio round trip."""
from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from gatetherm import InputError
from gatetherm import atomic_path

_CELL = {2: "triangle", 3: "tetra"}
_FACET = {2: "line", 3: "triangle"}
_MASK = "group:"


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
    by :func:`gatetherm.geometry.build.build_mesh` (not kept in files)."""

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


def to_meshio(m: FrameMesh, point_data: dict | None = None):
    """Convert to ``meshio.Mesh``: gmsh physical tags and names plus one
    ``group:<name>`` 0/1 cell array per group (VTU keeps no field data)."""
    import meshio

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
    return meshio.Mesh(pts, cells, point_data=point_data or {},
                       cell_data={"gmsh:physical": phys, "gmsh:geometrical": phys, **masks},
                       field_data=field_data)


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


def _named_blocks(mm):
    """Yield (name, cell type, connectivity) per group, from group masks (VTU)
    or gmsh tags and names (MSH); readers may merge blocks of one cell type."""
    masks = [k for k in mm.cell_data if k.startswith(_MASK)]
    if masks:
        sel = {k[len(_MASK):]: mm.cell_data[k] for k in masks}
    else:
        names = {int(v[0]): k for k, v in mm.field_data.items()}
        phys = mm.cell_data["gmsh:physical"]
        sel = {n: [arr == t for arr in phys] for t, n in names.items()}
    for name, per_block in sel.items():
        for block, on in zip(mm.cells, per_block):
            on = np.asarray(on, dtype=bool)
            if on.any():
                yield name, block.type, block.data[on]


def load_mesh(path: str | os.PathLike) -> FrameMesh:
    """Read a mesh written by :func:`save_mesh` (``.msh`` or ``.vtu``)."""
    import meshio

    path = Path(path)
    mm = meshio.read(path, file_format="gmsh" if path.suffix == ".msh" else None)
    dim = 3 if any(c.type == "tetra" for c in mm.cells) else 2
    regions, boundaries, sensors, chunks = {}, {}, {}, []
    offset = 0
    for name, ctype, conn in _named_blocks(mm):
        if ctype == _CELL[dim]:
            chunks.append(conn)
            regions[name] = np.arange(offset, offset + len(conn))
            offset += len(conn)
        elif ctype == _FACET[dim]:
            boundaries[name] = conn
        elif ctype == "vertex":
            sensors[name] = int(conn[0, 0])
    if not chunks:
        raise InputError(str(path), "holds no named volume groups", "write it with 'gatetherm mesh'")
    return FrameMesh(dim, mm.points[:, :dim].copy(), np.vstack(chunks), regions, boundaries, sensors)
