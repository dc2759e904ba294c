"""Mesh a user's geometry with gmsh: a ``.geo`` script or a CAD file (``.step``, ``.stp``,
``.brep``, ``.iges``), with a target element size, finer elements near named groups, the
``.geo`` script's own parameters, and groups selected by boxes, outward normal or as the
rest of the boundary. Several solids (surfaces in 2-D) are made conformal (OpenCASCADE
fragments) and each is a region; the interface of two regions is the boundary ``A/B``.
gmsh runs sandboxed in a child process (:mod:`gatetherm.geometry.isolate`); the element
count is estimated and checked against the machine's memory before it meshes."""
from __future__ import annotations

import functools
import logging
import signal
from dataclasses import dataclass, field
from itertools import pairwise
from pathlib import Path

import numpy as np

from gatetherm import InputError
from gatetherm.geometry.extract import extract_mesh
from gatetherm.geometry.geoscan import scan, tokens
from gatetherm.geometry.groups import GroupRule, fragment, interfaces, physical, regions
from gatetherm.geometry.isolate import READ_LIMIT_S, quiet, run_isolated
from gatetherm.geometry.mesh import FrameMesh, check_mesh, from_arrays, to_arrays
from gatetherm.geometry.sizing import check_count, check_estimate, model_estimate

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
class MeshSpec:
    """How to mesh a geometry file."""

    path: Path
    size: float | None = None
    """Largest element size, m (None: the file's own sizes)."""
    parameters: dict[str, float] = field(default_factory=dict)
    """``.geo`` numbers set before the script runs (``If (!Exists(h)) h = ...; EndIf``)."""
    refine: tuple[Refinement, ...] = ()
    groups: tuple[GroupRule, ...] = ()
    include: tuple[Path, ...] = ()
    """Files outside the case's folder that the script may read."""
    root: Path | None = None
    """The case's folder (default: the file's)."""
    factor: float = 1.0
    """The factor ``size`` and the refinements' sizes were multiplied by; it scales the file's own sizes too."""


def _own_background(gmsh) -> list[int]:
    """The file's own size fields that may be its ``Background Field``: those no other field
    reads (a Distance gives lengths, not sizes)."""
    f = gmsh.model.mesh.field
    read = set()
    for tag in f.list():
        for key, many in (("InField", False), ("IField", False), ("FieldsList", True)):
            try:
                read |= {int(t) for t in f.getNumbers(tag, key)} if many else {int(f.getNumber(tag, key))}
            except Exception:  # noqa: BLE001 - gmsh: the field has no such option
                pass
    return [t for t in f.list() if t not in read and f.getType(t) not in ("Distance", "Attractor")]


def _refine(gmsh, spec: MeshSpec, names: dict, own_background: bool = False) -> dict[int, int]:
    """Size fields of the refinements; their field tags and numbers (from 1). A script's own
    background field stays in force (the smallest size wins)."""
    f = gmsh.model.mesh.field
    big = spec.size or 1e22
    own = _own_background(gmsh) if own_background and spec.refine else []
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
        f.setNumbers(low, "FieldsList", fields + own)
        f.setAsBackgroundMesh(low)
        gmsh.option.setNumber("Mesh.MeshSizeExtendFromBoundary", 0)
    return {tag: i for i, tag in enumerate(fields, start=1)}


def _scale_own(gmsh, factor: float, sized: bool) -> None:
    """Multiply the file's own element sizes by ``factor``: the points' sizes, the size
    fields' and, unless the case gives ``size``, ``Mesh.MeshSizeMax`` (the case's sizes
    come scaled)."""
    for p in gmsh.model.getEntities(0):
        (s,) = gmsh.model.mesh.getSizes([p])
        if s > 0:
            gmsh.model.mesh.setSize([p], s * factor)
    f = gmsh.model.mesh.field
    for tag in f.list():
        for key in {"Threshold": ("SizeMin", "SizeMax"), "Box": ("VIn", "VOut"), "Ball": ("VIn", "VOut"),
                    "Cylinder": ("VIn", "VOut")}.get(f.getType(tag), ()):
            f.setNumber(tag, key, f.getNumber(tag, key) * factor)
    if not sized and gmsh.option.getNumber("Mesh.MeshSizeMax") < 1e22:
        gmsh.option.setNumber("Mesh.MeshSizeMax", gmsh.option.getNumber("Mesh.MeshSizeMax") * factor)


def _size_key(spec: MeshSpec, tag: int | None, size: float, mine: dict[int, int]) -> tuple[str, float]:
    """The key (and its value) that sets the largest part of the element estimate."""
    if spec.factor != 1.0:
        return "--mesh-factor", spec.factor
    if tag is None:
        if spec.size:
            return "mesh.size", spec.size
        given = [k for k, v in spec.parameters.items() if abs(float(v) - size) <= 1e-9 * size]  # the script's size
        return (f"mesh.parameters.{given[0]}", size) if given else (f"{spec.path.name}: element size", size)
    return (f"mesh.refine[{mine[tag]}].size" if tag in mine else f"{spec.path.name}: Field[{tag}].SizeMin"), size


MAX_PARTS = 200
"""Budget of solids (surfaces in 2-D) of a geometry: more are refused before they are made
conformal (an assembly of 1 000 touching cubes gave no output in 300 s)."""


def _read(gmsh, spec: MeshSpec) -> int:
    for k, v in spec.parameters.items():
        gmsh.parser.setNumber(k, [float(v)])
    try:
        if spec.path.suffix.lower() == SCRIPT:
            signal.signal(signal.SIGALRM, signal.SIG_DFL)  # not a handler the caller set (inherited by the
            signal.alarm(READ_LIMIT_S)  # fork: gmsh holds the GIL, it would never run); an endless loop: the child
            # ends on SIGALRM (isolate._result)
            verbosity = gmsh.option.getNumber("General.Verbosity")
            gmsh.option.setNumber("General.Verbosity", min(verbosity, 1))  # the script's Printf: not shown
            gmsh.merge(str(spec.path))  # (gmsh.open would forget the parameters)
            gmsh.option.setNumber("General.Verbosity", verbosity)
        else:
            signal.signal(signal.SIGALRM, signal.SIG_DFL)  # a CAD file too large to read: ended as a script is
            signal.alarm(READ_LIMIT_S)
            gmsh.model.occ.importShapes(str(spec.path))
            gmsh.model.occ.synchronize()
    except Exception as err:  # gmsh reports a bad file as a plain Exception
        raise InputError(str(spec.path), f"gmsh cannot read it ({quiet(str(err))})", "check the file in gmsh") from None
    finally:
        signal.alarm(0)
    dim = max((d for d, _ in gmsh.model.getEntities()), default=0)
    if dim < 2:
        raise InputError(str(spec.path), "has no surfaces or volumes", "give a 2-D or 3-D geometry")
    return dim


def _mean_edge(gmsh, d: int, entities) -> float | None:
    """Mean length of the first edge of the mesh's elements on ``entities`` of dimension ``d``."""
    lengths = []
    for e in entities:
        tags, xyz, _ = gmsh.model.mesh.getNodes(d, int(e), includeBoundary=True)
        at = dict(zip(tags.tolist(), xyz.reshape(-1, 3)))
        for kind, _, nodes in zip(*gmsh.model.mesh.getElements(d, int(e))):
            n = gmsh.model.mesh.getElementProperties(kind)[3]
            lengths += [float(np.linalg.norm(at[a] - at[b])) for a, b in nodes.reshape(-1, n)[:, :2].tolist()]
    return sum(lengths) / len(lengths) if lengths else None


def _coarser(gmsh, spec: MeshSpec, names: dict) -> list[str]:
    """Notes for refinements coarser than the mesh the file's own sizes made at their group
    (they change nothing there)."""
    notes = []
    for i, r in enumerate(spec.refine, start=1):
        d, tag = next(k for k, n in names.items() if n == r.near)
        h = _mean_edge(gmsh, d, gmsh.model.getEntitiesForPhysicalGroup(d, tag)) if d else None
        if h is not None and h < 0.5 * r.size:
            notes.append(f"mesh.refine[{i}] (near {r.near}): size = {r.size:g} m, but the file's own sizes give "
                         f"{h:.3g} m there already, so it changes nothing; give a smaller size, or remove it")
    return notes


STEP_SOLIDS = (b"MANIFOLD_SOLID_BREP(", b"BREP_WITH_VOIDS(")
"""The entities of a STEP file that are one solid each (counted before gmsh reads it)."""


def check_step_parts(path: Path) -> None:
    """InputError if the STEP file ``path`` holds more than :data:`MAX_PARTS` solids: counted in
    its text before gmsh reads it (reading 2 000 cubes alone took minutes)."""
    if path.suffix.lower() not in (".step", ".stp"):
        return
    count, tail = 0, b""
    with open(path, "rb") as f:
        while chunk := f.read(1 << 22):
            block = tail + chunk
            count += sum(block.count(k) for k in STEP_SOLIDS)
            tail = block[-32:]
            count -= sum(tail.count(k) for k in STEP_SOLIDS)  # counted again with the next block
        count += sum(tail.count(k) for k in STEP_SOLIDS)
    if count > MAX_PARTS:
        raise InputError(str(path), f"has {count} solids, more than the budget of {MAX_PARTS} parts (making them "
                         "conformal takes hours)", "merge parts in the CAD model, or mesh a sub-assembly")


def _mesh_in_gmsh(spec: MeshSpec, gmsh, own_background: bool = False) -> tuple[dict, dict]:
    """Read, name, check the size of and mesh the geometry (in the sandboxed child)."""
    dim = _read(gmsh, spec)
    parts = len(gmsh.model.getEntities(dim))
    if parts > MAX_PARTS:
        raise InputError(str(spec.path), f"has {parts} {'surfaces' if dim == 2 else 'volumes'}, more than the budget of "
                         f"{MAX_PARTS} parts (making them conformal takes hours)",
                         "merge parts in the CAD model, or mesh a sub-assembly")
    try:
        fragment(gmsh, dim)
    except Exception as err:  # noqa: BLE001 - OpenCASCADE's own failure
        raise InputError(str(spec.path), f"its solids cannot be made conformal ({quiet(str(err), script=False)})",
                         "check the CAD model") from None
    regions(gmsh, spec.groups, dim)
    interfaces(gmsh, dim)
    if spec.factor != 1.0:
        _scale_own(gmsh, spec.factor, bool(spec.size))
    if spec.size:
        gmsh.option.setNumber("Mesh.MeshSizeMax", spec.size)
    names = physical(gmsh)
    mine = _refine(gmsh, spec, names, own_background)
    parts = model_estimate(gmsh, dim)
    _, tag, size = max(parts, key=lambda p: p[0])
    check_estimate(sum(p[0] for p in parts), dim, *_size_key(spec, tag, size, mine))
    gmsh.option.setNumber("General.NumThreads", 1)  # threads make meshes differ run to run
    try:
        gmsh.model.mesh.generate(dim)
    except Exception as err:  # noqa: BLE001
        raise InputError(str(spec.path), f"gmsh cannot mesh it ({quiet(str(err), script=False)})", "check the geometry in gmsh") from None
    elements = sum(len(t) for e in gmsh.model.getEntities(dim) for t in gmsh.model.mesh.getElements(*e)[1])
    key, value = _size_key(spec, tag, size, mine)
    check_count(elements, dim, key, value, "" if "factor" in key else " m", counted=True)
    groups = {d: {names[(d, t)]: [int(e) for e in gmsh.model.getEntitiesForPhysicalGroup(d, t)]
                  for dd, t in names if dd == d} for d in range(dim + 1)}
    owner: dict[int, str] = {}
    for name, ents in groups[dim].items():
        for e in ents:
            if e in owner:
                raise InputError(f"mesh region {name}", f"shares entities with region {owner[e]}",
                                 "give every part of the body to one region only")
            owner[e] = name
    if not any(len(gmsh.model.mesh.getElements(dim, e)[0]) for e in owner):
        raise InputError(str(spec.path), "gmsh made no elements", "check the geometry and the element size")
    points = {name: ents[0] for name, ents in groups[0].items()}
    if dim == 2:
        _, xyz, _ = gmsh.model.mesh.getNodes()
        if abs(xyz[2::3]).max(initial=0.0) > 1e-12:
            raise InputError(str(spec.path), "a 2-D geometry must lie in the x-y plane", "draw it in z = 0")
    fm, notes = extract_mesh(gmsh, dim, groups[dim], groups[dim - 1], points, groups[1] if dim == 3 else None)
    return to_arrays(fm, [*_coarser(gmsh, spec, names), *notes])


def mesh_geometry(spec: MeshSpec) -> FrameMesh:
    """Mesh ``spec.path`` and return the named mesh (2-D if the geometry is planar)."""
    root = spec.root or spec.path.parent
    script = spec.path if spec.path.suffix.lower() == SCRIPT else None
    check_step_parts(spec.path)
    background = False
    if script is not None:
        read = scan(script, root, spec.include)  # every file it reads inside the case's folder or named
        background = any(a == "Background" and b == "Field" for f in read if f.suffix.lower() == SCRIPT
                         for (a, _), (b, _) in pairwise(tokens(f.read_text(encoding="utf-8", errors="replace"))))
    meta, arrays = run_isolated(functools.partial(_mesh_in_gmsh, spec, own_background=background), str(spec.path),
                                script,
                                functools.partial(scan, root=root, allowed=spec.include, commands=True))
    for note in meta.pop("notes", []):
        log.warning(note)
    fm = from_arrays(meta, arrays)
    check_mesh(fm, str(spec.path))
    extent = float(np.ptp(fm.points, axis=0).max())
    if spec.size and spec.size > 2 * extent:
        log.warning("mesh.size = %g m is larger than the body (%.3g m across): the elements are as coarse as its "
                    "geometry allows (%d of them); give a size of a fraction of the body", spec.size, extent,
                    len(fm.cells))
    log.info("meshed %s: %d nodes, %d elements, regions %s", spec.path.name, len(fm.points), len(fm.cells),
             ", ".join(fm.regions))
    return fm
