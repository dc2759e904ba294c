"""Case files: a user's frame described in the names of its mesh's physical groups.

A TOML case names a mesh (``.msh`` of any gmsh version, or a ``.geo``/CAD file meshed
through gmsh) and gives materials per region, thermal conditions per boundary (film to
an ambient, fixed temperature, heat flux; adiabatic where nothing is said), sources,
lumped fluid volumes, supports, probes, relative displacements and the time settings.
Every key is checked where it is read: an unknown key, a name that is not a group of
the mesh, a region without a material or a boundary with two conditions is one
:class:`~gatetherm.InputError` line naming the file and the key and listing what is
valid. README "Case files" is the reference of every key.
"""
from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from gatetherm import InputError
from gatetherm.checks import CELSIUS, Range, ranges
from gatetherm.files import read_text
from gatetherm.geometry.gmshfile import CAD, SCRIPT, BoxGroup, MeshSpec, Refinement, mesh_geometry
from gatetherm.geometry.mesh import FrameMesh, load_mesh
from gatetherm.solvers.expr import Value
from gatetherm.solvers.frame import enclosed_volume, region_volume
from gatetherm.solvers.heat import TimeScheme
from gatetherm.solvers.material import Material
from gatetherm.studies.run.tables import Table
from gatetherm.solvers.problem import (AXES, FaceFilm, Film, FixedTemperature, Fluid, Flux, Probe, Problem,
                                       Relative, Signals, Source, Support, values)

SECTIONS = ("case", "mesh", "materials", "initial", "temperature", "thermal", "faces", "sources", "fluids",
            "supports", "probes", "relative", "means", "signals", "time")
MATERIAL_KEYS = {"k": "W/(m K)", "rho": "kg/m³", "c": "J/(kg K)", "E": "Pa", "nu": "1", "alpha": "1/K",
                 "thickness": "m"}
MATERIAL = ranges(Material)
"""Admissible values of the material keys (those of the model file's [material])."""
SCHEME = ranges(TimeScheme)
METRES, SECONDS = Range(0.0, lo_open=True, unit="m"), Range(0.0, lo_open=True, unit="s")
THICKNESS = Range(1e-6, 1e3, unit="m")
"""Thickness of a 2-D section, from a micrometre to a kilometre: far beyond, the solid's
matrices lose every digit against the rest (PARDISO fails at 1e30 and 1e-30 m in the
C-frame example, whose other regions are 0.25–0.6 m thick)."""
FILM = Range(0.0, unit="W/(m² K)")


@dataclass(frozen=True)
class TimeSettings:
    """A transient run."""

    end: float
    """Length of the run, s."""
    step: float
    """Time step, s (the scheme refines the intervals after pump switches)."""
    output: float
    """Interval of the time series, s (a whole multiple of ``step``)."""
    fields: float
    """Interval of the field output, s."""
    schedule: Path | None = None
    """A time-series file (the data format) whose columns the expressions read."""


@dataclass(frozen=True)
class Case:
    """A case file, read and checked against its mesh."""

    path: Path
    name: str
    problem: Problem
    mesh: FrameMesh
    time: TimeSettings | None = None
    """None: steady state (or a prescribed temperature)."""
    effects: dict = field(default_factory=dict)
    """Catalogue effects switched on (the scenario path's interface; none from the file)."""
    sensors: dict = field(default_factory=dict)
    """Sensor faults, {channel: {fault: value}} (the scenario path's interface; none from the file)."""
    inputs: tuple[Path, ...] = ()
    """The files the case reads (itself, its mesh or geometry, its schedule): a run keeps them."""

    @property
    def source(self) -> str:
        return str(self.path)


def _mesh(top: Table, base: Path, factor: float = 1.0) -> FrameMesh:
    m = top.sub("mesh", ("file", "size", "parameters", "refine", "groups"))
    path = base / m.string("file")
    if not path.is_file():
        m.fail("file", f"no such file '{path}'", "give a .msh, .geo or CAD file beside the case")
    suffix = path.suffix.lower()
    if suffix in (".msh", ".vtu"):
        for k in ("size", "parameters", "refine", "groups"):
            if k in m.data:
                m.fail(k, f"applies only to a geometry that gatetherm meshes ({SCRIPT}, {', '.join(CAD)})",
                       "mesh the file again in gmsh, or give the .geo")
        if factor != 1.0:
            m.fail("file", "a mesh file cannot be refined", "give the .geo or CAD file to mesh it finer")
        return load_mesh(path)
    if suffix not in (SCRIPT, *CAD):
        m.fail("file", f"unknown mesh or geometry format '{suffix}'", f"use .msh, {SCRIPT} or {', '.join(CAD)}")
    params = m.sub("parameters")
    refine = []
    for i, r in enumerate(m.data.get("refine", [])):
        rt = Table(top.file, f"mesh.refine[{i + 1}]", r, ("near", "size", "distance"))
        refine.append(Refinement(rt.string("near"), factor * rt.number("size", METRES),
                                 rt.number("distance", METRES)))
    groups = []
    for name in m.data.get("groups", {}):
        g = m.sub("groups").sub(name, ("dim", "box"))
        box = g.data.get("box")
        if not (isinstance(box, list) and len(box) == 6 and all(isinstance(b, (int, float)) for b in box)):
            g.fail("box", f"expected [xmin, ymin, zmin, xmax, ymax, zmax], got {box!r}", "give six numbers in m")
        groups.append(BoxGroup(name, int(g.number("dim", Range(0, 3, whole=True))), tuple(float(b) for b in box)))
    size = factor * m.number("size", METRES, 0.0) or None
    return mesh_geometry(MeshSpec(path, size, {k: params.number(k) for k in params.data}, tuple(refine),
                                  tuple(groups)))


def _materials(top: Table, fm: FrameMesh, need: set[str]) -> tuple[dict, dict]:
    mats = top.sub("materials", tuple(fm.regions))
    missing = [r for r in fm.regions if r not in mats.data]
    if missing:
        mats.fail(missing[0], "region without a material", f"add [materials.{missing[0]}] (regions: "
                  f"{', '.join(fm.regions)})")
    materials, thickness = {}, {}
    for region in fm.regions:
        t = mats.sub(region, tuple(MATERIAL_KEYS))
        for k in need - set(t.data):
            t.fail(k, "missing", f"give {k} in {MATERIAL_KEYS[k]} (needed for "
                   f"{'elasticity' if k in ('E', 'nu', 'alpha') else 'the heat solve'})")
        given = {k: t.number(k, MATERIAL[k], math.nan if k not in need else None) for k in MATERIAL}
        materials[region] = Material(**given)
        if "thickness" in t.data:
            if fm.dim == 3:
                t.fail("thickness", "applies to 2-D sections only", "remove it")
            thickness[region] = t.number("thickness", THICKNESS)
    return materials, thickness


def _boundary_conditions(top: Table, fm: FrameMesh, names) -> dict:
    th = top.sub("thermal", tuple(fm.boundaries))
    out = {"films": [], "fixed": [], "fluxes": []}
    for b in th.data:
        t = th.sub(b, ("film", "ambient", "temperature", "flux"))
        kinds = [k for k in ("film", "temperature", "flux") if k in t.data]
        if len(kinds) != 1:
            t.fail("/".join(kinds) or "film", "give exactly one condition: film (with ambient), temperature or flux",
                   "a boundary without a condition is adiabatic; leave it out")
        if kinds == ["film"]:
            out["films"].append(Film(b, t.number("film", FILM), t.value("ambient", names, unit="°C")))
        elif "ambient" in t.data:
            t.fail("ambient", "goes with a film only", "remove it or give film")
        elif kinds == ["temperature"]:
            out["fixed"].append(FixedTemperature(b, t.value("temperature", names, unit="°C")))
        else:
            out["fluxes"].append(Flux(b, t.value("flux", names, unit="W/m²")))
    return out


def _fluids(top: Table, fm: FrameMesh, names, thickness: dict) -> tuple:
    out = []
    fl = top.sub("fluids")
    for name in fl.data:
        t = fl.sub(name, ("boundary", "volume", "rho_c", "flow_rate", "capacity", "conductance", "film_on", "film_off",
                          "supply", "pump", "hose_capacity", "hose_loss", "hose_name", "ambient"))
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


def _supports(top: Table, fm: FrameMesh) -> tuple:
    sup = top.sub("supports", tuple(fm.boundaries))
    out = []
    for b in sup.data:
        t = sup.sub(b, ("type", "components", "stiffness"))
        kind = t.string("type", choices=("clamped", "normal", "fixed", "foundation"))
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


def _probes(top: Table, fm: FrameMesh, quantities: tuple[str, ...]) -> tuple:
    pr = top.sub("probes")
    out = []
    finder = None
    for name in pr.data:
        t = pr.sub(name, ("point", "quantities", "region"))
        point = t.data.get("point")
        if isinstance(point, str):
            if point not in fm.sensors:
                t.fail("point", f"'{point}' is not a point group of the mesh", f"points: {', '.join(fm.sensors) or 'none'}"
                       "; or give coordinates [x, y(, z)] in m")
            xyz = tuple(float(v) for v in fm.points[fm.sensors[point]])
        elif isinstance(point, list) and len(point) == fm.dim and all(
                isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) for v in point):
            xyz = tuple(float(v) for v in point)
            if finder is None:
                from gatetherm.solvers.fem import to_skfem

                finder = to_skfem(fm).element_finder()
            try:
                finder(*np.array(xyz)[:, None])
            except ValueError:
                t.fail("point", f"{list(xyz)} lies outside the mesh", "give a point inside the body")
        else:
            t.fail("point", f"expected a point group name or {fm.dim} coordinates, got {point!r}",
                   'e.g. point = "A" or point = [0.1, 0.2]')
        q = t.data.get("quantities", list(quantities))
        if not (isinstance(q, list) and all(x in quantities for x in q)):
            t.fail("quantities", f"{q!r} is not admissible", f"choose from {', '.join(quantities)}")
        region = t.name("region", fm.regions, "region", default="") or None
        out.append(Probe(name, xyz, tuple(q), region))
    return tuple(out)


def _relative(top: Table, probes, dim: int) -> tuple:
    rel = top.sub("relative")
    names = [p.name for p in probes if "u" in p.quantities] + [p.name for p in probes if "u" not in p.quantities]
    out = []
    for name in rel.data:
        t = rel.sub(name, ("a", "b", "axis"))
        out.append(Relative(name, t.name("a", names, "probe"), t.name("b", names, "probe"),
                            AXES.index(t.string("axis", choices=tuple(AXES[:dim])))))
    return tuple(out)


def _signals(top: Table, probes, relative) -> Signals:
    s = top.sub("signals", ("theta_A", "theta_B", "theta_C", "delta"))
    temps = [p.name for p in probes if "T" in p.quantities]
    c = s.data.get("theta_C", [])
    c = [c] if isinstance(c, str) else c
    if not (isinstance(c, list) and all(x in temps for x in c)):
        s.fail("theta_C", f"{c!r} is not a list of probes with T", f"probes: {', '.join(temps)}")
    return Signals(s.name("theta_A", temps, "probe", "") or None, s.name("theta_B", temps, "probe", "") or None,
                   tuple(c), s.name("delta", [r.name for r in relative], "relative displacement", "") or None)


def _time(top: Table, base: Path):
    """The time settings, the scheme and the schedule file's series (None: no schedule)."""
    if "time" not in top.data:
        return None, TimeScheme(), None
    from gatetherm.studies.run.timeseries import check_steps, read_timeseries

    t = top.sub("time", ("end", "step", "output", "schedule", "fields", "scheme"))
    end = t.number("end", SECONDS)
    within = Range(0.0, end, lo_open=True, unit="s")  # an interval longer than the run is refused
    output = t.number("output", within, min(60.0, end))
    step = t.number("step", within, output)
    check_steps(end, step, t.key("step"))
    if abs(output / step - round(output / step)) > 1e-9:
        t.fail("output", f"{output:g} s is not a whole multiple of the step {step:g} s", "change output or step")
    sch = t.sub("scheme", ("theta", "restart", "restart_intervals"))
    scheme = TimeScheme(sch.number("theta", SCHEME["theta"], 0.5), int(sch.number("restart", SCHEME["restart"], 4)),
                        int(sch.number("restart_intervals", SCHEME["restart_intervals"], 3)))
    schedule, ts = None, None
    if "schedule" in t.data:
        schedule = base / t.string("schedule")
        if not schedule.is_file():
            t.fail("schedule", f"no such file '{schedule}'", "give a time-series file (docs/data-format.md)")
        ts = read_timeseries(schedule, required=("time_s",))
        span = float(ts.time_s[-1] - ts.time_s[0])
        if span < end * (1 - 1e-9):
            t.fail("schedule", f"'{schedule}' spans {span:g} s, less than the run (end = {end:g} s)",
                   "extend the schedule (its times are seconds) or shorten end")
    return TimeSettings(end, step, output, t.number("fields", within, end), schedule), scheme, ts


def _check_schedule(problem: Problem, ts, time: TimeSettings) -> None:
    """Every value that reads the schedule, at the schedule's samples within the run
    (where its columns are recorded): in the range of its key; every column it reads recorded."""
    t = np.asarray(ts.time_s - ts.time_s[0], float)
    env = {"t": t, **{k: ts[k] for k in ts.names if k != "time_s"}}
    for v in values(problem):
        names = v.names() | {"t"}
        empty = next((n for n in sorted(names) if not np.isfinite(env[n]).any()), None)
        if empty:
            raise InputError(f"{time.schedule}, column {empty}", "has no values", f"fill it ({v.key} reads it)")
        rows = (t <= time.end) & np.logical_and.reduce([np.isfinite(env[n]) for n in names])
        if not v.is_constant and rows.any():
            v({n: env[n][rows] for n in names})


def load_case(path, mesh_factor: float = 1.0) -> Case:
    """Read and check a case file (paths inside it are relative to its folder); with
    ``mesh_factor``, a geometry is meshed with its element sizes times that factor."""
    path = Path(path)
    text = read_text(path, "CASE.toml", "give the path of a .toml case file")
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as err:
        raise InputError(str(path), f"not valid TOML ({err})") from None
    top = Table(path, "", data, SECTIONS)
    head = top.sub("case", ("name", "order", "plane"))
    order = head.data.get("order", 1)
    if isinstance(order, bool) or order not in (1, 2):
        head.fail("order", f"{order!r} is not admissible", "give 1 (linear) or 2 (quadratic elements)")
    fm = _mesh(top, path.parent, mesh_factor)
    time, scheme, schedule = _time(top, path.parent)
    columns = tuple(n for n in schedule.names if n != "time_s") if schedule is not None else ()
    prescribed = "temperature" in data
    elastic = "supports" in data
    need = ({"E", "nu", "alpha"} if elastic else set()) | (set() if prescribed else {"k"}) | \
        ({"rho", "c"} if time else set())
    materials, thickness = _materials(top, fm, need)
    names = ("t", *columns)
    init = top.sub("initial", ("temperature", "reference"))
    T0 = init.number("temperature", CELSIUS, 20.0)
    kw: dict = {}
    if prescribed:
        for s in ("thermal", "faces", "sources", "fluids", "time"):
            if s in data:
                top.fail(s, "cannot go with a prescribed [temperature]", "remove one of the two")
        tt = top.sub("temperature", ("field", "regions"))
        if ("field" in tt.data) == ("regions" in tt.data):
            tt.fail("field", "give either field (an expression of x, y, z) or a [temperature.regions] table")
        if "field" in tt.data:
            kw["prescribed"] = tt.value("field", ("x", "y", "z")[:fm.dim], unit="°C")
        else:
            reg = tt.sub("regions", tuple(fm.regions))
            kw["prescribed_regions"] = {r: reg.number(r, CELSIUS) for r in reg.data}
    else:
        kw.update(_boundary_conditions(top, fm, names))
        src = top.sub("sources", tuple(fm.regions))
        sources = []
        for r in src.data:
            s = src.sub(r, ("density", "power"))
            if ("density" in s.data) == ("power" in s.data):
                s.fail("density", "give either density (W/m³) or power (W)")
            if "density" in s.data:
                sources.append(Source(r, s.value("density", names, unit="W/m³")))
            else:
                vol = region_volume(fm, r, thickness.get(r, 1.0))
                sources.append(Source(r, Value.of(f"({s.value('power', names, unit='W')}) / {vol!r}", s.key("power"))))
        kw["sources"] = tuple(sources)
        if "faces" in data:
            if fm.dim != 2:
                top.fail("faces", "applies to 2-D sections only", "remove it")
            f = top.sub("faces", ("film", "ambient"))
            kw["faces"] = FaceFilm(f.number("film", FILM), f.value("ambient", names, unit="°C"))
        kw["fluids"] = _fluids(top, fm, names, thickness)
    twice = _twice(kw)
    if twice:
        top.fail("thermal", f"boundary '{twice}' is given two conditions", "give each boundary one condition")
    supports = _supports(top, fm) if elastic else ()
    quantities = ("T",) + (("u", "sigma") if elastic else ())
    probes = _probes(top, fm, quantities)
    relative = _relative(top, probes, fm.dim) if elastic or "relative" in data else ()
    means = top.sub("means", None)
    mean_pairs = tuple((k, means.name(k, fm.boundaries, "boundary")) for k in means.data)
    problem = Problem(fm.dim, materials, int(order), thickness,
                      head.string("plane", "stress", ("stress", "strain")),
                      T0, init.number("reference", CELSIUS, T0),
                      supports=supports, probes=probes, relative=relative, means=mean_pairs,
                      signals=_signals(top, probes, relative), elastic=elastic, scheme=scheme, **kw)
    if schedule is not None:
        _check_schedule(problem, schedule, time)
    inputs = (path, path.parent / data["mesh"]["file"], *([time.schedule] if time and time.schedule else []))
    return Case(path, head.string("name", path.stem), problem, fm, time, inputs=inputs)


def _twice(kw: dict) -> str | None:
    """A boundary that carries two thermal conditions (films, fixed, fluxes, fluids), if any."""
    seen = set()
    for c in (*kw.get("films", ()), *kw.get("fixed", ()), *kw.get("fluxes", ()), *kw.get("fluids", ())):
        if c.boundary in seen:
            return c.boundary
        seen.add(c.boundary)
    return None
