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
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from gatetherm import InputError
from gatetherm.geometry.build import _extract
from gatetherm.geometry.geoscan import scan
from gatetherm.geometry.isolate import run_isolated
from gatetherm.geometry.mesh import FrameMesh, check_mesh, from_arrays, group_name, to_arrays
from gatetherm.geometry.sizing import check_estimate

log = logging.getLogger(__name__)

CAD = (".step", ".stp", ".brep", ".iges", ".igs")
SCRIPT = ".geo"
NORMAL_TOLERANCE = 1e-3
"""Default largest angle between a face's (curve's) outward normal and a group's ``normal``, rad."""
_CELL = {2: math.sqrt(3) / 4, 3: 1 / (6 * math.sqrt(2))}
"""Area (volume) of an equilateral triangle (regular tetrahedron) of unit edge."""


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
class GroupRule:
    """A physical group of the entities of one dimension that a rule selects: inside any of
    ``boxes``, with outward normal ``normal``, both, or the ``rest``."""

    name: str
    dim: int
    boxes: tuple[tuple[float, ...], ...] = ()
    """Boxes xmin, ymin, zmin, xmax, ymax, zmax, m: the entities inside any of them."""
    rest: bool = False
    """Every boundary entity (of the body's dimension: every solid) no other group holds."""
    normal: tuple[float, ...] | None = None
    """Plane faces (3-D) or straight curves (2-D) of the boundary whose outward normal is this direction."""
    tolerance: float = NORMAL_TOLERANCE
    """Largest angle to ``normal``, rad."""


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


def _physical(gmsh) -> dict[tuple[int, int], str]:
    """Name of every physical group by (dimension, tag)."""
    return {(d, t): gmsh.model.getPhysicalName(d, t) or group_name(d, t, {}) for d, t in gmsh.model.getPhysicalGroups()}


def _add_group(gmsh, dim: int, ents, name: str) -> None:
    gmsh.model.setPhysicalName(dim, gmsh.model.addPhysicalGroup(dim, sorted(int(e) for e in ents)), name)


def _fragment(gmsh, dim: int) -> None:
    """Make several OpenCASCADE solids (surfaces) conformal, keeping the physical groups."""
    occ = gmsh.model.occ
    if len(occ.getEntities(dim)) < 2:
        return
    phys = [(d, t, gmsh.model.getPhysicalName(d, t), list(gmsh.model.getEntitiesForPhysicalGroup(d, t)))
            for d, t in gmsh.model.getPhysicalGroups()]
    lower = sorted({(d, int(e)) for d, _, _, ents in phys if d < dim for e in ents})
    objects = occ.getEntities(dim) + [e for e in lower if e in set(occ.getEntities(e[0]))]
    _, images = occ.fragment(objects, [])
    occ.synchronize()
    image = {obj: [t for d, t in img if d == obj[0]] for obj, img in zip(objects, images)}
    gmsh.model.removePhysicalGroups()
    for d, t, name, ents in phys:
        new = sorted({x for e in ents for x in image.get((d, int(e)), [int(e)])})
        gmsh.model.addPhysicalGroup(d, new, t)
        if name:
            gmsh.model.setPhysicalName(d, t, name)


def _label(gmsh, dim: int, tag: int) -> str:
    """The CAD label of an entity (the last part of gmsh's name), '' if none or the translator's."""
    name = gmsh.model.getEntityName(dim, tag).rsplit("/", 1)[-1].strip()
    return "" if name.startswith("Open CASCADE STEP translator") else name


def _normal(gmsh, d: int, tag: int, dim: int) -> np.ndarray | None:
    """The outward unit normal of a plane boundary face (3-D) or straight boundary curve
    (2-D), None if it is curved or not on the boundary."""
    up, _ = gmsh.model.getAdjacencies(d, tag)
    if len(up) != 1:
        return None
    lo, hi = gmsh.model.getParametrizationBounds(d, tag)
    frac = np.array([0.2, 0.5, 0.8])
    if d == 2:
        uv = np.array([[lo[0] + a * (hi[0] - lo[0]), lo[1] + b * (hi[1] - lo[1])] for a in frac for b in frac])
        n = np.reshape(gmsh.model.getNormal(tag, uv.ravel()), (-1, 3))
        mid = uv[4]
    else:
        u = lo[0] + frac * (hi[0] - lo[0])
        t = np.reshape(gmsh.model.getDerivative(1, tag, u), (-1, 3))
        n = np.column_stack([t[:, 1], -t[:, 0], np.zeros(len(t))])
        mid = u[1:2]
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    if np.abs(n - n[1 if d == 1 else 4]).max() > 1e-9:
        return None
    p = np.array(gmsh.model.getValue(d, tag, mid))
    box = np.reshape(gmsh.model.getBoundingBox(-1, -1), (2, 3))
    eps = 1e-4 * float(np.linalg.norm(box[1] - box[0]))
    inside = gmsh.model.isInside(dim, int(up[0]), list(p + eps * n[0]))
    return -n[0] if inside > 0 else n[0]


def _select(gmsh, rule: GroupRule, dim: int, taken: set[int]) -> list[int]:
    """The entity tags ``rule`` selects."""
    where = f"mesh.groups.{rule.name}"
    if rule.dim > dim:
        raise InputError(where, f"dim = {rule.dim} but the geometry is {dim}-D", f"give dim = 0 … {dim}")
    if rule.rest and rule.dim < dim - 1:
        raise InputError(where, f"rest = true selects boundary entities (dim = {dim - 1}) or solids (dim = {dim})",
                         "give boxes for points and edges")
    if rule.normal is not None and rule.dim != dim - 1:
        raise InputError(where, f"normal selects faces of the boundary (dim = {dim - 1})", f"give dim = {dim - 1}")
    if rule.rest and rule.dim == dim - 1:
        bnd = gmsh.model.getBoundary(gmsh.model.getEntities(dim), combined=True, oriented=False)
        cand = sorted({abs(t) for _, t in bnd} - taken)
    else:
        cand = [t for _, t in gmsh.model.getEntities(rule.dim) if not rule.rest or t not in taken]
    if rule.boxes:
        inside = {t for b in rule.boxes for _, t in gmsh.model.getEntitiesInBoundingBox(*b, dim=rule.dim)}
        cand = [t for t in cand if t in inside]
    if rule.normal is not None:
        want = np.asarray(rule.normal, dtype=float) / np.linalg.norm(rule.normal)
        want = np.r_[want, np.zeros(3 - len(want))]
        cand = [t for t in cand if (n := _normal(gmsh, rule.dim, t, dim)) is not None
                and math.acos(min(1.0, float(n @ want))) <= rule.tolerance]
    if not cand:
        how = " and ".join(x for x in (f"inside the boxes {[list(b) for b in rule.boxes]}" if rule.boxes else "",
                                       f"with outward normal {list(rule.normal)}" if rule.normal else "",
                                       "left by the other groups" if rule.rest else "") if x)
        raise InputError(where, f"no {rule.dim}-D entity {how}", "check the rule's coordinates (m) or direction")
    return cand


def _regions(gmsh, spec: MeshSpec, dim: int) -> None:
    """The physical groups of the rules and, for a file without solids' groups, one region per solid."""
    own = bool(gmsh.model.getPhysicalGroups(dim))
    taken = {d: {int(e) for dd, t in gmsh.model.getPhysicalGroups(d)
                 for e in gmsh.model.getEntitiesForPhysicalGroup(dd, t)} for d in range(dim + 1)}
    for rule in sorted(spec.groups, key=lambda r: r.rest):
        ents = _select(gmsh, rule, dim, taken[rule.dim])
        _add_group(gmsh, rule.dim, ents, rule.name)
        taken[rule.dim] |= set(ents)
    if own:
        return
    free = [t for _, t in gmsh.model.getEntities(dim) if t not in taken[dim]]
    labels = [_label(gmsh, dim, t) for t in free]
    for i, (t, label) in enumerate(zip(free, labels), start=1):
        _add_group(gmsh, dim, [t], label if label and labels.count(label) == 1 else
                   "solid" if len(free) == 1 else f"solid{i}")


def _interfaces(gmsh, dim: int) -> None:
    """A boundary ``A/B`` (names sorted) for the facets between the regions A and B."""
    owner = {}
    for (d, t), name in _physical(gmsh).items():
        if d == dim:
            owner |= {int(e): name for e in gmsh.model.getEntitiesForPhysicalGroup(d, t)}
    pairs: dict[str, list[int]] = {}
    for _, t in gmsh.model.getEntities(dim - 1):
        up, _ = gmsh.model.getAdjacencies(dim - 1, t)
        names = sorted({owner[int(u)] for u in up if int(u) in owner})
        if len(names) == 2 and len(up) == 2:
            pairs.setdefault("/".join(names), []).append(t)
    taken = set(_physical(gmsh).values())
    for name, ents in pairs.items():
        if name not in taken:
            _add_group(gmsh, dim - 1, ents, name)


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


def _measure(gmsh, d: int, t: int) -> float:
    """Length, area or volume of an entity (its bounding box's for the built-in kernel); 1 for a point."""
    if d == 0:
        return 1.0
    try:
        return float(gmsh.model.occ.getMass(d, t))
    except Exception:  # noqa: BLE001 - not an OpenCASCADE entity
        box = np.reshape(gmsh.model.getBoundingBox(d, t), (2, 3))
        ext = np.sort(box[1] - box[0])[::-1]
        return float(np.prod(ext[:d])) if d else 1.0


def estimate(gmsh, spec: MeshSpec, dim: int) -> list[tuple[float, str, float]]:
    """Elements the current model will have, by contribution, as (elements, key, size):
    the solids at their element size (``Mesh.MeshSizeMax``, the points' sizes, the size
    factor) and every Threshold field (a refinement: the elements within its distance,
    the size growing linearly from SizeMin to SizeMax). The same area (volume) per
    element as the frame's :func:`~gatetherm.geometry.sizing.element_estimate`."""
    opt = gmsh.option.getNumber
    box = np.reshape(gmsh.model.getBoundingBox(-1, -1), (2, 3))
    lo, hi, factor = opt("Mesh.MeshSizeMin"), opt("Mesh.MeshSizeMax"), opt("Mesh.MeshSizeFactor")
    clip = lambda h: min(max(h * factor, lo), hi)  # noqa: E731
    f = gmsh.model.mesh.field
    thresholds = [t for t in f.list() if f.getType(t) == "Threshold"]
    far = min((clip(f.getNumber(t, "SizeMax")) for t in thresholds), default=hi)
    base, h_base = 0.0, math.inf
    for _, t in gmsh.model.getEntities(dim):
        pts = [p for p in gmsh.model.getBoundary([(dim, t)], recursive=True) if p[0] == 0]
        lc = [s for s in gmsh.model.mesh.getSizes(pts) if s > 0] if pts and opt("Mesh.MeshSizeFromPoints") else []
        h = min(clip(math.exp(np.mean(np.log(lc))) if lc else float(np.linalg.norm(box[1] - box[0]))), far)
        base += _measure(gmsh, dim, t) / (_CELL[dim] * h ** dim)
        h_base = min(h_base, h)
    total = sum(_measure(gmsh, dim, t) for _, t in gmsh.model.getEntities(dim))
    key = "--mesh-factor" if spec.factor != 1.0 else "mesh.size" if spec.size else f"{spec.path.name}: element size"
    out = [(base, key, spec.factor if spec.factor != 1.0 else h_base)]
    for tag in thresholds:
        src = int(f.getNumber(tag, "InField"))
        smin, smax = clip(f.getNumber(tag, "SizeMin")), clip(f.getNumber(tag, "SizeMax"))
        d0, d1 = f.getNumber(tag, "DistMin"), max(f.getNumber(tag, "DistMax"), f.getNumber(tag, "DistMin"))
        near = []
        if src in f.list() and f.getType(src) == "Distance":
            near = [(d, int(e)) for d, key_ in enumerate(("PointsList", "CurvesList", "SurfacesList"))
                    for e in f.getNumbers(src, key_)]
        r = np.linspace(0.0, d1, 201)[1:]
        h = np.where(r <= d0, smin, smin + (smax - smin) * (r - d0) / max(d1 - d0, 1e-300))
        n = 0.0
        for d, e in near:
            if d == dim:  # inside a solid: all at SizeMin, then the ramp outside its boundary
                n += _measure(gmsh, d, e) / (_CELL[dim] * smin ** dim)
                near += [(b, abs(t)) for b, t in gmsh.model.getBoundary([(d, e)], oriented=False)]
                continue
            shell = {1: 2.0 * np.ones_like(r), 2: 2 * np.pi * r, 3: 4 * np.pi * r ** 2}[dim - d]
            n += float(np.sum(_measure(gmsh, d, e) * shell / (_CELL[dim] * h ** dim)) * (r[1] - r[0]))
        n = min(n, total / (_CELL[dim] * smin ** dim))
        user = next((i for i, rr in enumerate(spec.refine, 1) if math.isclose(rr.size, f.getNumber(tag, "SizeMin"))),
                    None)
        out.append((n, "--mesh-factor" if spec.factor != 1.0 else f"mesh.refine[{user}].size" if user else
                    f"{spec.path.name}: Field[{tag}].SizeMin", spec.factor if spec.factor != 1.0 else smin))
    return out


def _read(gmsh, spec: MeshSpec) -> int:
    for k, v in spec.parameters.items():
        gmsh.parser.setNumber(k, [float(v)])
    try:
        if spec.path.suffix.lower() == SCRIPT:
            gmsh.merge(str(spec.path))  # (gmsh.open would forget the parameters)
        else:
            gmsh.model.occ.importShapes(str(spec.path))
            gmsh.model.occ.synchronize()
    except Exception as err:  # gmsh reports a bad file as a plain Exception
        raise InputError(str(spec.path), f"gmsh cannot read it ({err})", "check the file in gmsh") from None
    dim = max((d for d, _ in gmsh.model.getEntities()), default=0)
    if dim < 2:
        raise InputError(str(spec.path), "has no surfaces or volumes", "give a 2-D or 3-D geometry")
    return dim


def _mesh_in_gmsh(spec: MeshSpec, gmsh) -> tuple[dict, dict]:
    """Read, name, check the size of and mesh the geometry (in the sandboxed child)."""
    dim = _read(gmsh, spec)
    try:
        _fragment(gmsh, dim)
    except Exception as err:  # noqa: BLE001 - OpenCASCADE's own failure
        raise InputError(str(spec.path), f"its solids cannot be made conformal ({err})", "check the CAD model") from None
    _regions(gmsh, spec, dim)
    _interfaces(gmsh, dim)
    if spec.factor != 1.0:
        _scale_own(gmsh, spec.factor, bool(spec.size))
    if spec.size:
        gmsh.option.setNumber("Mesh.MeshSizeMax", spec.size)
    names = _physical(gmsh)
    _refine(gmsh, spec, names, dim)
    parts = estimate(gmsh, spec, dim)
    elements, key, size = max(parts)
    check_estimate(sum(p[0] for p in parts), dim, key, size)
    gmsh.option.setNumber("General.NumThreads", 1)  # threads make meshes differ run to run
    try:
        gmsh.model.mesh.generate(dim)
    except Exception as err:  # noqa: BLE001
        raise InputError(str(spec.path), f"gmsh cannot mesh it ({err})", "check the geometry in gmsh") from None
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
    fm, notes = _extract(gmsh, dim, groups[dim], groups[dim - 1], points)
    return to_arrays(fm, notes)


def mesh_geometry(spec: MeshSpec) -> FrameMesh:
    """Mesh ``spec.path`` and return the named mesh (2-D if the geometry is planar)."""
    root = spec.root or spec.path.parent
    script = spec.path if spec.path.suffix.lower() == SCRIPT else None
    if script is not None:
        scan(script, root, spec.include)  # every file it reads inside the case's folder or named
    meta, arrays = run_isolated(functools.partial(_mesh_in_gmsh, spec), str(spec.path), script,
                                functools.partial(scan, root=root, allowed=spec.include, commands=True))
    for note in meta.pop("notes", []):
        log.warning(note)
    fm = from_arrays(meta, arrays)
    check_mesh(fm, str(spec.path))
    log.info("meshed %s: %d nodes, %d elements, regions %s", spec.path.name, len(fm.points), len(fm.cells),
             ", ".join(fm.regions))
    return fm
