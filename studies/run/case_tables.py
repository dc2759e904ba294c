"""The physics tables of a case file: materials, thermal conditions, fluids, supports, probes,
relative displacements, the compensation signals and the actuator. Each reader checks its
table's keys and values and refuses with one :class:`~gatetherm.InputError` line naming the
file and the key (``docs/case-file.md``)."""
from __future__ import annotations

import dataclasses
import logging
import math

import numpy as np

from gatetherm import InputError
from gatetherm.checks import Range, ranges
from gatetherm.geometry.measure import enclosed_volume
from gatetherm.geometry.mesh import FrameMesh
from gatetherm.geometry.nearest import nearest_on_body
from gatetherm.solvers.material import Material
from gatetherm.solvers.problem import AXES, FixedTemperature, Fluid, Flux, Probe, Relative, Signals, Support
from gatetherm.studies.run import case_films, case_mech
from gatetherm.studies.run.case_mesh import numbers
from gatetherm.studies.run.tables import MeshNames, Table

KEYS = {
    "materials.REGION": ("k", "rho", "c", "E", "nu", "alpha", "thickness"),
    "thermal.BOUNDARY": ("film", "ambient", "temperature", "flux", "emissivity"),
    "fluids.NAME": ("boundary", "volume", "rho_c", "flow_rate", "capacity", "conductance", "film_on", "film_off",
                    "supply", "pump", "hose_capacity", "hose_loss", "hose_name", "ambient"),
    "supports.BOUNDARY": ("type", "components", "stiffness", "value"),
    "probes.NAME": ("point", "quantities", "region"),
    "relative.NAME": ("a", "b", "axis"),
    "signals": ("theta_A", "theta_B", "theta_C", "delta"),
    **case_films.KEYS,
    "actuator": ("type", "stroke", "stack_stiffness", "spring_stiffness", "preload", "dead_band", "hysteresis",
                 "reset"),
}
"""The keys of these tables (as :data:`gatetherm.studies.run.case.KEYS`)."""
MATERIAL_KEYS = {"k": "W/(m K)", "rho": "kg/m³", "c": "J/(kg K)", "E": "Pa", "nu": "1", "alpha": "1/K",
                 "thickness": "m"}
MATERIAL = ranges(Material)
"""Admissible values of the material keys (those of the model file's [material])."""
PLAUSIBLE = {"k": (0.01, 2500.0), "rho": (10.0, 25000.0), "c": (50.0, 5000.0), "E": (1e5, 1.3e12)}
"""What the solids of machines span (insulating foams to diamond's conduction, foams to tungsten's
density, …, rubber to diamond's stiffness): a value outside is read with a warning (a unit slip:
c = 0.46 meant kJ/(kg K))."""
THICKNESS = Range(1e-6, 1e3, unit="m")
"""Thickness of a 2-D section, from a micrometre to a kilometre: far beyond, the solid's
matrices lose every digit against the rest (PARDISO fails at 1e30 and 1e-30 m in the
C-frame example, whose other regions are 0.25–0.6 m thick)."""
THICK = 10.0
"""A 2-D section deeper than this many times the body's largest in-plane extent is read with a
warning (a thickness in mm, say: 350 for 0.35 m)."""
FILM = Range(0.0, unit="W/(m² K)")
log = logging.getLogger(__name__)


def materials(top: Table, fm: FrameMesh, need: set[str]) -> tuple[dict, dict]:
    mats = top.sub("materials", MeshNames(fm.regions, "region", "regions"))
    missing = [r for r in fm.regions if r not in mats.data]
    if missing:
        mats.fail(missing[0], "region without a material", f"add [materials.{missing[0]}] (regions: "
                  f"{', '.join(fm.regions)})")
    materials, thickness = {}, {}
    for region in fm.regions:
        t = mats.sub(region, KEYS["materials.REGION"])
        for k in need - set(t.data):
            t.fail(k, "missing", f"give {k} in {MATERIAL_KEYS[k]} (needed for "
                   f"{'elasticity' if k in ('E', 'nu', 'alpha') else 'the heat solve'})")
        given = {k: t.number(k, MATERIAL[k], math.nan if k not in need else None) for k in MATERIAL}
        materials[region] = Material(**given)
        for k, (lo, hi) in PLAUSIBLE.items():
            if k in t.data and not lo <= given[k] <= hi:
                t.said.warn(log, "%s = %g %s is outside what the solids of machines have (%g to %g): check its unit "
                            "(SI: %s)", t.key(k), given[k], MATERIAL_KEYS[k], lo, hi, MATERIAL_KEYS[k])
        if "thickness" in t.data:
            if fm.dim == 3:
                t.fail("thickness", "applies to 2-D sections only", "remove it")
            thickness[region] = t.number("thickness", THICKNESS)
            _plausible_thickness(t, fm, thickness[region])
    return materials, thickness


def _plausible_thickness(t: Table, fm: FrameMesh, value: float) -> None:
    """Warn of a section deeper than :data:`THICK` times the body's largest in-plane extent (mm meant)."""
    extent = float(np.ptp(fm.points, axis=0).max())
    if value > THICK * extent:
        t.said.warn(log, "%s: %g m is more than %g times the body's largest in-plane extent (%.3g m); the thickness "
                    "is in m (%g mm = %g m)", t.key("thickness"), value, THICK, extent, value, value / 1000)


def boundary_conditions(top: Table, fm: FrameMesh, names) -> dict:
    th = top.sub("thermal", MeshNames(fm.boundaries, "boundary", "boundaries"))
    out = {"films": [], "fixed": [], "fluxes": []}
    for b in th.data:
        t = th.sub(b, KEYS["thermal.BOUNDARY"])
        kinds = [k for k in ("film", "temperature", "flux") if k in t.data]
        if len(kinds) != 1:
            t.fail("/".join(kinds) or "film", "give exactly one condition: film (with ambient), temperature or flux",
                   "a boundary without a condition is adiabatic; leave it out")
        if kinds == ["film"]:
            out["films"].append(case_films.film(t, b, names))
        elif "ambient" in t.data or "emissivity" in t.data:
            t.fail("ambient" if "ambient" in t.data else "emissivity", "goes with a film only",
                   "remove it or give film")
        elif kinds == ["temperature"]:
            out["fixed"].append(FixedTemperature(b, t.value("temperature", names, unit="°C")))
        else:
            out["fluxes"].append(Flux(b, t.value("flux", names, unit="W/m²")))
    return out


def fluids(top: Table, fm: FrameMesh, names, thickness: dict) -> tuple:
    out = []
    fl = top.sub("fluids")
    for name in fl.data:
        t = fl.sub(name, KEYS["fluids.NAME"])
        wall = t.name("boundary", fm.boundaries, "boundary")
        hose = t.number("hose_capacity", Range(0.0, unit="J/K"), 0.0)
        if "capacity" in t.data:  # the lump's own figures
            capacity = t.number("capacity", Range(0.0, lo_open=True, unit="J/K"))
            conductance = t.number("conductance", Range(0.0, unit="W/K"))
        else:  # the fluid's: volume (default: enclosed by the boundary), rho_c and flow
            depths = set(thickness.values()) | ({1.0} if len(thickness) < len(fm.regions) else set())
            if fm.dim == 2 and len(depths) > 1 and "volume" not in t.data:
                t.fail("volume", "missing: the regions of this 2-D section differ in thickness",
                       "give the volume in m³")
            volume = t.number("volume", Range(0.0, unit="m³"), 0.0) or enclosed_volume(fm, wall, min(depths))
            rho_c = t.number("rho_c", Range(0.0, lo_open=True, unit="J/(m³ K)"))
            capacity, conductance = rho_c * volume, rho_c * t.number("flow_rate", Range(0.0, unit="m³/s"))
        out.append(Fluid(name, wall, capacity, t.number("film_on", FILM),
                         t.number("film_off", FILM), conductance, t.value("supply", names, unit="°C"),
                         t.value("pump", names, default=1.0), hose, t.number("hose_loss", Range(0.0, unit="W/K"), 0.0),
                         t.value("ambient", names, default=20.0 if not hose else None, unit="°C"),
                         t.string("hose_name", default="")))
    return tuple(out)


def supports(top: Table, fm: FrameMesh, names) -> tuple:
    sup = top.sub("supports", MeshNames(case_mech.support_names(fm), "boundary or line", "boundaries and lines"))
    out = []
    for b in sup.data:
        t = sup.sub(b, KEYS["supports.BOUNDARY"])
        kind = t.string("type", choices=("clamped", "normal", "fixed", "foundation", "displacement"))
        case_mech.check_support(t, fm, b, kind)
        if kind == "displacement":
            out.append(case_mech.displacement_support(t, fm, b, names))
            continue
        comps = tuple(range(fm.dim))
        if kind in ("fixed", "foundation") and ("components" in t.data or kind == "fixed"):
            raw = t.data.get("components")
            axes = AXES[:fm.dim]
            if not (isinstance(raw, list) and raw and all(isinstance(c, str) and c in axes for c in raw)):
                t.fail("components", f"expected a list of {', '.join(axes)}, got {raw!r}", 'e.g. components = ["x"]')
            comps = tuple(sorted({axes.index(c) for c in raw}))
        if kind == "normal":
            comps = (_normal_axis(t, fm, b),)
        stiff = t.number("stiffness", Range(0.0, lo_open=True, unit="N/m³")) if kind == "foundation" else None
        if kind != "foundation" and "stiffness" in t.data:
            t.fail("stiffness", "goes with type = \"foundation\" only", "remove it")
        out.append(Support(b, comps, stiff))
    return tuple(out)


def _normal_axis(t: Table, fm: FrameMesh, boundary: str) -> int:
    """The axis normal to a plane boundary parallel to a coordinate plane."""
    X = fm.points[np.unique(fm.boundaries[boundary])]
    spread = np.ptp(X, axis=0)
    flat = np.flatnonzero(spread <= 1e-9 * max(np.ptp(fm.points, axis=0).max(), 1.0))
    if len(flat) != 1:
        t.fail("type", f"boundary '{boundary}' is not a plane normal to x, y{' or z' if fm.dim == 3 else ''}",
               'use type = "fixed" with components')
    return int(flat[0])


def probes(top: Table, fm: FrameMesh, quantities: tuple[str, ...]) -> tuple:
    """The probes; coordinates off the elements by round-off are read on the body with a warning."""
    pr = top.sub("probes")
    out = []
    finder = None
    for name in pr.data:
        t = pr.sub(pr.column_name(name, "probe"), KEYS["probes.NAME"])
        point = t.data.get("point")
        if isinstance(point, str):
            if point not in fm.sensors:
                t.fail("point", f"'{point}' is not a point group of the mesh", f"points: {', '.join(fm.sensors) or 'none'}"
                       "; or give coordinates [x, y(, z)] in m")
            xyz = tuple(float(v) for v in fm.points[fm.sensors[point]])
        elif numbers(point, (fm.dim,)):
            xyz = tuple(float(v) for v in point)
            if finder is None:
                from gatetherm.solvers.fem import to_skfem

                finder = to_skfem(fm).element_finder()
            try:
                finder(*np.array(xyz)[:, None])
            except (ValueError, IndexError):  # outside (IndexError: far outside, in skfem's search)
                xyz = _onto_body(t, fm, xyz, finder)
        else:
            t.fail("point", f"expected a point group name or {fm.dim} coordinates, got {point!r}",
                   'e.g. point = "A" or point = [0.1, 0.2]')
        q = t.data.get("quantities", list(quantities))
        if not (isinstance(q, list) and q and all(x in quantities for x in q) and len(set(q)) == len(q)):
            t.fail("quantities", f"{q!r} is not admissible", f"choose each once from {', '.join(quantities)}")
        region = t.name("region", fm.regions, "region", default="") or None
        out.append(Probe(name, xyz, tuple(q), region))
    return tuple(out)


def _onto_body(t: Table, fm: FrameMesh, xyz: tuple, finder) -> tuple:
    """Coordinates outside the elements: read at the nearest point of the body if within the
    tolerance of a point group (a warning gives the distance and the region read), else refused
    with the distance and the nearest point."""
    with np.errstate(over="ignore"):  # a point 1e300 away: an infinite distance, refused below
        near = nearest_on_body(fm.points, fm.cells, xyz)
    at = ", ".join(f"{v:.6g}" for v in near.point)
    if near.distance > near.tolerance:
        t.fail("point", f"{list(xyz)} lies outside the mesh, {near.distance:.3g} m from the body (more than the "
               f"tolerance {near.tolerance:.3g} m); the nearest point on it is [{at}]",
               "give a point inside the body")
    inside = tuple(float(v) for v in near.inside)
    cell = int(np.ravel(finder(*np.array(inside)[:, None]))[0])  # in its element now (a ValueError: a defect)
    region = next((r for r, cells in fm.regions.items() if cell in np.asarray(cells)), "?")
    t.said.warn(log, "%s: %s lies %.3g m outside the mesh (within the tolerance %.3g m): read at the nearest point on "
                "the body, [%s], in region %r", t.key("point"), list(xyz), near.distance, near.tolerance, at, region)
    return inside


def relative(top: Table, probes, dim: int) -> tuple:
    rel = top.sub("relative")
    names = [p.name for p in probes if "u" in p.quantities] + [p.name for p in probes if "u" not in p.quantities]
    out = []
    for name in rel.data:
        t = rel.sub(rel.column_name(name, "relative displacement"), KEYS["relative.NAME"])
        a, b = t.name("a", names, "probe"), t.name("b", names, "probe")
        if a == b:  # its displacement is zero at every time: a δ that can never say anything
            t.fail("b", f"is {b!r}, the same probe as a: the relative displacement would be 0 at all times",
                   "give two different probes")
        at = {p.name: p.xyz for p in probes}
        if np.allclose(at[a], at[b], rtol=0.0, atol=1e-9):  # a probe read on the body at the other's point
            where = ", ".join(f"{v:.6g}" for v in at[a])
            t.fail("b", f"probe {b!r} reads the same point as {a!r}, [{where}]: the relative displacement would be 0 "
                   "at all times", "move one of them (one outside the mesh is read at the nearest point on the body)")
        out.append(Relative(name, a, b, AXES.index(t.string("axis", choices=tuple(AXES[:dim])))))
    return tuple(out)


def signals(top: Table, probes, relative) -> Signals:
    s = top.sub("signals", KEYS["signals"])
    temps = [p.name for p in probes if "T" in p.quantities]
    c = s.data.get("theta_C", [])
    c = [c] if isinstance(c, str) else c
    if not (isinstance(c, list) and all(x in temps for x in c)) or ("theta_C" in s.data and not c):
        s.fail("theta_C", f"{c!r} is not a list of probes with T", f"probes: {', '.join(temps)}")
    return Signals(s.name("theta_A", temps, "probe", "") or None, s.name("theta_B", temps, "probe", "") or None,
                   tuple(c), s.name("delta", [r.name for r in relative], "relative displacement", "") or None)


def actuator(top: Table):
    """``[actuator]``: the paper's piezo model with its reach, stiffnesses, preload, dead band,
    hysteresis and drive set, or ``type = "none"`` (ideal: an offset to the control); None without it."""
    from gatetherm.studies.control.actuator import ActuatorParams, with_stroke

    if "actuator" not in top.data:
        return None
    a = top.sub("actuator", KEYS["actuator"])
    if a.string("type", "piezo", ("piezo", "none")) == "none":
        if len(a.data) > 1:
            a.fail(next(k for k in a.data if k != "type"), "goes with type = \"piezo\" only", "remove it")
        return None
    base, stiff = ActuatorParams(), Range(0.0, lo_open=True, unit="N/m")
    reset = a.data.get("reset", True)
    if not isinstance(reset, bool):
        a.fail("reset", f"expected true/false, got {reset!r}", "true: back to 0 V before each new voltage")
    h = a.number("hysteresis", Range(0.0, 4.0, unit="× the default"), 1.0)
    p = dataclasses.replace(
        base, stack_stiffness_N_per_m=a.number("stack_stiffness", stiff, base.stack_stiffness_N_per_m),
        spring_stiffness_N_per_m=a.number("spring_stiffness", stiff, base.spring_stiffness_N_per_m),
        preload_N=a.number("preload", Range(0.0, unit="N"), base.preload_N),
        dead_band_unloaded_um=a.number("dead_band", Range(0.0, 100.0, unit="um"), base.dead_band_unloaded_um),
        play_weights=(base.play_weights[0], *(w * h for w in base.play_weights[1:])),
        strategy="reset" if reset else "direct")
    if "stroke" not in a.data:
        return p
    st = a.data["stroke"]
    if not (isinstance(st, list) and len(st) == 2 and all(isinstance(v, (int, float)) and not isinstance(v, bool)
                                                         for v in st)):
        a.fail("stroke", f"expected [away, towards] in um, got {st!r}", "e.g. stroke = [-70.0, 10.0]")
    try:
        return with_stroke(p, float(st[0]), float(st[1]))
    except InputError as err:
        a.fail("stroke", err.problem, err.fix)
