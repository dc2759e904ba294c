"""Mesh a user's geometry with gmsh: a ``.geo`` script or a CAD file (``.step``, ``.stp``,
``.brep``, ``.iges``), with a target element size, finer elements near named groups, the
``.geo`` script's own parameters, and groups selected by bounding box (a CAD file has
no names). The mesh comes back with every physical group under its name."""
from __future__ import annotations

import logging
from dataclasses import dataclass, field
from pathlib import Path

from gatetherm import InputError
from gatetherm.geometry.build import _extract, gmsh_session
from gatetherm.geometry.mesh import FrameMesh, group_name

log = logging.getLogger(__name__)

CAD = (".step", ".stp", ".brep", ".iges", ".igs")
SCRIPT = ".geo"


@dataclass(frozen=True)
class Refinement:
    """Finer elements near a named group."""

    near: str
    """The group (any dimension)."""
    size: float
    """Element size at the group, m."""
    distance: float
    """Distance over which the size grows back to the global size, m."""


@dataclass(frozen=True)
class BoxGroup:
    """A physical group made of the entities of one dimension inside a box."""

    name: str
    dim: int
    box: tuple[float, ...]
    """xmin, ymin, zmin, xmax, ymax, zmax, m."""


@dataclass(frozen=True)
class MeshSpec:
    """How to mesh a geometry file."""

    path: Path
    size: float | None = None
    """Largest element size, m (None: the file's own sizes)."""
    parameters: dict[str, float] = field(default_factory=dict)
    """``.geo`` numbers set before the script runs (``If (!Exists(h)) h = ...; EndIf``)."""
    refine: tuple[Refinement, ...] = ()
    groups: tuple[BoxGroup, ...] = ()


def _physical(gmsh) -> dict[tuple[int, int], str]:
    """Name of every physical group by (dimension, tag)."""
    return {(d, t): gmsh.model.getPhysicalName(d, t) or group_name(d, t, {}) for d, t in gmsh.model.getPhysicalGroups()}


def _refine(gmsh, spec: MeshSpec, names: dict, dim: int) -> None:
    f = gmsh.model.mesh.field
    big = spec.size or 1e22
    fields = []
    for r in spec.refine:
        groups = [k for k, n in names.items() if n == r.near]
        if not groups:
            raise InputError(f"mesh.refine {r.near}", "no group of that name", f"groups: {', '.join(names.values())}")
        d, tag = groups[0]
        ents = gmsh.model.getEntitiesForPhysicalGroup(d, tag)
        dist = f.add("Distance")
        f.setNumbers(dist, {0: "PointsList", 1: "CurvesList", 2: "SurfacesList"}.get(d, "SurfacesList"),
                     [int(e) for e in ents])
        thr = f.add("Threshold")
        f.setNumber(thr, "InField", dist)
        f.setNumber(thr, "SizeMin", r.size)
        f.setNumber(thr, "SizeMax", big)
        f.setNumber(thr, "DistMin", 0.0)
        f.setNumber(thr, "DistMax", r.distance)
        fields.append(thr)
    if fields:
        low = f.add("Min")
        f.setNumbers(low, "FieldsList", fields)
        f.setAsBackgroundMesh(low)
        gmsh.option.setNumber("Mesh.MeshSizeExtendFromBoundary", 0)


def mesh_geometry(spec: MeshSpec) -> FrameMesh:
    """Mesh ``spec.path`` and return the named mesh (2-D if the geometry is planar)."""
    suffix = spec.path.suffix.lower()
    with gmsh_session("case") as gmsh:
        for k, v in spec.parameters.items():
            gmsh.parser.setNumber(k, [float(v)])
        try:
            if suffix == SCRIPT:
                gmsh.merge(str(spec.path))  # (gmsh.open would forget the parameters)
            else:
                gmsh.model.occ.importShapes(str(spec.path))
                gmsh.model.occ.synchronize()
        except Exception as err:  # gmsh reports a bad file as a plain Exception
            raise InputError(str(spec.path), f"gmsh cannot read it ({err})", "check the file in gmsh") from None
        dim = max((d for d, _ in gmsh.model.getEntities()), default=0)
        if dim < 2:
            raise InputError(str(spec.path), "has no surfaces or volumes", "give a 2-D or 3-D geometry")
        for g in spec.groups:
            ents = gmsh.model.getEntitiesInBoundingBox(*g.box, dim=g.dim)
            if not ents:
                raise InputError(f"mesh.groups.{g.name}", f"no {g.dim}-D entity inside the box {list(g.box)}",
                                 "enlarge the box or check its coordinates (m)")
            gmsh.model.setPhysicalName(g.dim, gmsh.model.addPhysicalGroup(g.dim, [t for _, t in ents]), g.name)
        if not gmsh.model.getPhysicalGroups(dim):  # a CAD file without groups: one region
            tag = gmsh.model.addPhysicalGroup(dim, [t for _, t in gmsh.model.getEntities(dim)])
            gmsh.model.setPhysicalName(dim, tag, "solid")
        if spec.size:
            gmsh.option.setNumber("Mesh.MeshSizeMax", spec.size)
        names = _physical(gmsh)
        _refine(gmsh, spec, names, dim)
        gmsh.option.setNumber("General.NumThreads", 1)  # threads make meshes differ run to run
        gmsh.model.mesh.generate(dim)
        groups = {d: {names[(d, t)]: [int(e) for e in gmsh.model.getEntitiesForPhysicalGroup(d, t)]
                      for dd, t in names if dd == d} for d in range(dim + 1)}
        owner: dict[int, str] = {}
        for name, ents in groups[dim].items():
            for e in ents:
                if e in owner:
                    raise InputError(f"mesh region {name}", f"shares entities with region {owner[e]}",
                                     "give every part of the body to one region only")
                owner[e] = name
        points = {name: ents[0] for name, ents in groups[0].items()}
        if dim == 2:
            _, xyz, _ = gmsh.model.mesh.getNodes()
            if abs(xyz[2::3]).max(initial=0.0) > 1e-12:
                raise InputError(str(spec.path), "a 2-D geometry must lie in the x-y plane", "draw it in z = 0")
        fm = _extract(gmsh, dim, groups[dim], groups[dim - 1], points, None, groups[1] if dim == 3 else None)
        log.info("meshed %s: %d nodes, %d elements, regions %s", spec.path.name, len(fm.points), len(fm.cells),
                 ", ".join(fm.regions))
        return fm
