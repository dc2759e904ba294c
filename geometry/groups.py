"""Physical groups of a gmsh model (in gmsh's process): several OpenCASCADE solids made
conformal keeping the file's groups, one region per solid named by its CAD label or
``solid1`` …, groups selected by rules (boxes, outward normal, the rest of the boundary) and
the interfaces ``A/B`` between regions."""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from gatetherm import InputError
from gatetherm.geometry.mesh import group_name

NORMAL_TOLERANCE = 1e-3
"""Default largest angle between a face's (curve's) outward normal and a group's ``normal``, rad."""


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


def physical(gmsh) -> dict[tuple[int, int], str]:
    """Name of every physical group by (dimension, tag)."""
    return {(d, t): gmsh.model.getPhysicalName(d, t) or group_name(d, t, {}) for d, t in gmsh.model.getPhysicalGroups()}


def add_group(gmsh, dim: int, ents, name: str) -> None:
    gmsh.model.setPhysicalName(dim, gmsh.model.addPhysicalGroup(dim, sorted(int(e) for e in ents)), name)


def fragment(gmsh, dim: int) -> None:
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


def select(gmsh, rule: GroupRule, dim: int, taken: set[int]) -> list[int]:
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


def regions(gmsh, rules, dim: int) -> None:
    """The physical groups of the rules and, for a file without solids' groups, one region per solid."""
    own = bool(gmsh.model.getPhysicalGroups(dim))
    taken = {d: {int(e) for dd, t in gmsh.model.getPhysicalGroups(d)
                 for e in gmsh.model.getEntitiesForPhysicalGroup(dd, t)} for d in range(dim + 1)}
    for rule in sorted(rules, key=lambda r: r.rest):
        ents = select(gmsh, rule, dim, taken[rule.dim])
        add_group(gmsh, rule.dim, ents, rule.name)
        taken[rule.dim] |= set(ents)
    if own:
        return
    free = [t for _, t in gmsh.model.getEntities(dim) if t not in taken[dim]]
    labels = [_label(gmsh, dim, t) for t in free]
    for i, (t, label) in enumerate(zip(free, labels), start=1):
        add_group(gmsh, dim, [t], label if label and labels.count(label) == 1 else
                   "solid" if len(free) == 1 else f"solid{i}")


def interfaces(gmsh, dim: int) -> None:
    """A boundary ``A/B`` (names sorted) for the facets between the regions A and B."""
    owner = {}
    for (d, t), name in physical(gmsh).items():
        if d == dim:
            owner |= {int(e): name for e in gmsh.model.getEntitiesForPhysicalGroup(d, t)}
    pairs: dict[str, list[int]] = {}
    for _, t in gmsh.model.getEntities(dim - 1):
        up, _ = gmsh.model.getAdjacencies(dim - 1, t)
        names = sorted({owner[int(u)] for u in up if int(u) in owner})
        if len(names) == 2 and len(up) == 2:
            pairs.setdefault("/".join(names), []).append(t)
    taken = set(physical(gmsh).values())
    for name, ents in pairs.items():
        if name not in taken:
            add_group(gmsh, dim - 1, ents, name)
