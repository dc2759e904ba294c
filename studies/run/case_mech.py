"""The mechanical tables of a case file and the checks of an assembly: ``[gravity]``,
``[loads.NAME]``, ``[contacts.NAME]``, supports of ``type = "displacement"``, the
axisymmetric section, parts connected to nothing. Each refusal is one
:class:`~gatetherm.InputError` line naming the file and the key (``docs/case-file.md``).
"""
from __future__ import annotations

import math

import numpy as np

from gatetherm.checks import ACCELERATION, Range
from gatetherm.geometry.interface import interface_name, parts
from gatetherm.geometry.mesh import FrameMesh
from gatetherm.solvers.expr import Value
from gatetherm.solvers.problem import BoundaryLoad, Contact, PointLoad, Support
from gatetherm.studies.run.tables import Table

KEYS = {"gravity": ("acceleration",), "loads.BOUNDARY": ("pressure", "traction", "force"), "loads.POINT": ("force",),
        "contacts.NAME": ("between", "conductance", "stiffness")}
"""The keys of each mechanical table (as :data:`gatetherm.studies.run.case.KEYS`)."""
SECTIONS = ("gravity", "loads", "contacts")
THERMAL = ("thermal", "sources", "faces", "fluids", "temperature")
"""Tables that make a case thermal (without any, a case with loads is purely mechanical)."""
FREE = "free"
"""A displacement component left free in ``value = [...]``."""
STIFFNESS = Range(0.0, lo_open=True, unit="N/m³")


def mechanical_only(data: dict) -> bool:
    """A case with supports and mechanical loads but no thermal table: no temperature at all."""
    sup = data.get("supports", {})
    moved = isinstance(sup, dict) and any(isinstance(t, dict) and t.get("type") == "displacement" for t in sup.values())
    return "supports" in data and not any(s in data for s in THERMAL) and \
        ("gravity" in data or "loads" in data or moved)


def vector(t: Table, k: str, names, dim: int, free: bool = False, unit: str = "") -> list[Value | None]:
    """The list at ``k`` of ``dim`` values (None for ``"free"`` where ``free``)."""
    raw = t.data.get(k)
    if not (isinstance(raw, list) and len(raw) == dim):
        example = ", ".join(["0"] * (dim - 1) + ["-9.81" if k == "acceleration" else "1e3"])
        t.fail(k, f"expected a list of {dim} values, got {raw!r}",
               f"e.g. {k} = [{example}]" + (f' (a component "{FREE}": not held)' if free else ""))
    out = []
    for i, x in enumerate(raw):
        if free and x == FREE:
            out.append(None)
            continue
        key = f"{k}[{i + 1}]"
        out.append(Table(t.file, t.where, {key: x}, said=t.said).value(key, names, unit=unit))
    return out


def read_loads(top: Table, fm: FrameMesh, names) -> dict:
    """``gravity``, ``loads`` and ``point_loads`` of the Problem."""
    out: dict = {}
    if "gravity" in top.data:
        g = top.sub("gravity", KEYS["gravity"])
        out["gravity"] = tuple(Value.of(v.text or v.constant, v.key, ACCELERATION)
                               for v in vector(g, "acceleration", names, fm.dim, unit="m/s²"))
    lt = top.sub("loads", tuple(fm.boundaries) + tuple(fm.sensors))
    loads, points = [], []
    for name in lt.data:
        if name not in fm.boundaries:
            t = lt.sub(name, KEYS["loads.POINT"])
            points.append(PointLoad(name, tuple(vector(t, "force", names, fm.dim, unit="N"))))
            continue
        t = lt.sub(name, KEYS["loads.BOUNDARY"])
        kinds = [k for k in KEYS["loads.BOUNDARY"] if k in t.data]
        if len(kinds) != 1:
            t.fail("/".join(kinds) or "pressure", "give exactly one load: pressure, traction or force",
                   "pressure in Pa (positive into the body), traction [tx, ty(, tz)] in Pa or force [Fx, Fy(, Fz)] "
                   "in N (the total)")
        kind = kinds[0]
        values = (t.value("pressure", names, unit="Pa"),) if kind == "pressure" else \
            tuple(vector(t, kind, names, fm.dim, unit="Pa" if kind == "traction" else "N"))
        loads.append(BoundaryLoad(name, kind, values))
    return {**out, "loads": tuple(loads), "point_loads": tuple(points)}


def displacement_support(t: Table, fm: FrameMesh, boundary: str, names) -> Support:
    """A support of ``type = "displacement"``: ``value = [ux, uy(, uz)]``, m, ``"free"`` for
    a component not held."""
    for k in t.data:
        if k not in ("type", "value"):
            t.fail(k, 'does not go with type = "displacement"', "give value = [ux, uy(, uz)] only")
    values = vector(t, "value", names, fm.dim, free=True, unit="m")
    held = tuple(c for c, v in enumerate(values) if v is not None)
    if not held:
        t.fail("value", f'every component is "{FREE}"', "give a displacement (m) for at least one component")
    return Support(boundary, held, None, tuple(values[c] for c in held))


def read_contacts(top: Table, fm: FrameMesh, heat: bool, elastic: bool) -> tuple[Contact, ...]:
    ct = top.sub("contacts")
    out, seen = [], {}
    for name in ct.data:
        t = ct.sub(name, KEYS["contacts.NAME"])
        pair = t.data.get("between")
        if not (isinstance(pair, list) and len(pair) == 2 and all(p in fm.regions for p in pair)
                and pair[0] != pair[1]):
            t.fail("between", f"expected two regions of the mesh, got {pair!r}", f"regions: {', '.join(fm.regions)}")
        boundary = interface_name(*pair)
        if boundary not in fm.boundaries:
            t.fail("between", f"the mesh has no interface '{boundary}' (the regions do not touch, or the mesh names "
                   "it otherwise)", f"make the solids conformal (BooleanFragments) and name their common boundary "
                   f"\"{boundary}\"")
        if boundary in seen:
            t.fail("between", f"interface '{boundary}' is given by [contacts.{seen[boundary]}] already",
                   "give each interface one contact")
        seen[boundary] = name
        h = t.number("conductance", Range(0.0, lo_open=True, unit="W/(m² K)"), 0.0) or None
        if heat and h is None:
            t.fail("conductance", "missing: the case solves for the temperature", "give it in W/(m² K)")
        if not heat and h is not None:
            t.fail("conductance", "applies to a heat solve only", "remove it")
        stiff = None
        if "stiffness" in t.data:
            raw = t.data["stiffness"]
            if not elastic:
                t.fail("stiffness", "applies to a case with [supports] only", "remove it")
            if not (isinstance(raw, list) and len(raw) == 2):
                t.fail("stiffness", f"expected [normal, tangential], got {raw!r}", "e.g. stiffness = [1e12, 1e11]")
            stiff = tuple(float(rng.check(t.key(f"stiffness[{i + 1}]"), v))  # tangential 0: a slide
                          for i, (rng, v) in enumerate(zip((STIFFNESS, Range(0.0, unit="N/m³")), raw)))
        if h is None and stiff is None:
            t.fail("stiffness", "the contact has neither a conductance nor a stiffness",
                   "give one of them or remove it")
        out.append(Contact(name, tuple(pair), h, stiff))
    return tuple(out)


def check_axisymmetric(top: Table, fm: FrameMesh, data: dict) -> None:
    """An axisymmetric section: 2-D, in x ≥ 0, no out-of-plane thickness or faces, fluids
    with their own volume."""
    head = top.sub("case")
    if fm.dim != 2:
        head.fail("plane", '"axisymmetric" applies to a 2-D section', "remove it (a 3-D mesh is the solid itself)")
    size = max(float(np.ptp(fm.points, axis=0).max()), 1e-300)
    if fm.points[:, 0].min() < -1e-9 * size:
        head.fail("plane", f"the section reaches x = {fm.points[:, 0].min():.4g} m < 0 (x is the radius)",
                  "draw the section in x >= 0 with the axis at x = 0")
    if "faces" in data:
        top.fail("faces", "does not apply to an axisymmetric section", "remove it")
    for region, m in data.get("materials", {}).items():
        if isinstance(m, dict) and "thickness" in m:
            top.sub("materials").sub(region).fail("thickness", "does not apply to an axisymmetric section",
                                                   "remove it (every integral is over the full revolution)")
    for name, f in data.get("fluids", {}).items():
        if isinstance(f, dict) and not ({"volume", "capacity"} & set(f)):
            top.sub("fluids").sub(name).fail("volume", "missing: an axisymmetric fluid needs its volume",
                                             "give volume (m³, the whole ring) or capacity")


def revolved_volume(fm: FrameMesh, region: str) -> float:
    """Volume (m³) of a region of an axisymmetric section revolved about the y axis (Pappus)."""
    X = fm.points[fm.cells[fm.regions[region]]]
    E = X[:, 1:] - X[:, :1]
    return float((2.0 * math.pi * X[:, :, 0].mean(axis=1) * np.abs(np.linalg.det(E)) / 2.0).sum())


def check_assembly(top: Table, fm: FrameMesh, problem, steady: bool) -> None:
    """Refuse a mesh in pieces (a region connected to nothing) and a steady heat solve that
    nothing ties to a temperature, before any solve."""
    pieces = parts(fm)
    if len(pieces) > 1:
        alone = set(pieces[1].tolist())
        regions = [r for r, els in fm.regions.items() if fm.cells[els[0], 0] in alone]
        top.sub("mesh").fail("file", f"region{'s' * (len(regions) > 1)} {', '.join(regions)} touch{'es' * (len(regions) == 1)} "
                 f"no other region (the mesh falls into {len(pieces)} pieces)",
                 "make the solids touch in one conformal mesh (BooleanFragments in gmsh), and join them by a "
                 "[contacts] table where they should not be bonded")
    p = problem
    if steady and p.heat and not (p.films or p.fixed or p.fluids or p.faces):
        top.fail("thermal", "the steady temperature is undetermined: no film, fixed temperature, fluid or faces",
                 "give a boundary a film (with ambient) or a temperature, or add a [time] table")


def support_names(fm: FrameMesh) -> tuple[str, ...]:
    """What a support may hold: a boundary, or in 3-D a line."""
    return tuple(fm.boundaries) + tuple(fm.lines)


def check_support(t: Table, fm: FrameMesh, name: str, kind: str) -> None:
    """A line holds components only (no foundation, no normal)."""
    if name in fm.lines and kind in ("foundation", "normal"):
        t.fail("type", f"'{name}' is a line: it takes clamped, fixed or displacement", "hold components of it")

