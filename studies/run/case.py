"""Case files: a user's frame described in the names of its mesh's physical groups.

A TOML case names a mesh (``.msh`` of any gmsh version, or a ``.geo``/CAD file meshed
through gmsh) and gives materials per region, thermal conditions per boundary (film to
an ambient, fixed temperature, heat flux; adiabatic where nothing is said), sources,
lumped fluid volumes, supports, probes, relative displacements and the time settings.
Every key is checked where it is read: an unknown key, a name that is not a group of
the mesh, a region without a material or a boundary with two conditions is one
:class:`~gatetherm.InputError` line naming the file and the key and listing what is
valid. ``docs/case-file.md`` is the reference of every key.
"""
from __future__ import annotations

import dataclasses
import math
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from gatetherm import InputError
from gatetherm.checks import CELSIUS, Range, ranges
from gatetherm.files import read_text
from gatetherm.geometry.gmshfile import CAD, SCRIPT, MeshSpec, Refinement, mesh_geometry
from gatetherm.geometry.groups import NORMAL_TOLERANCE, GroupRule
from gatetherm.geometry.mesh import FrameMesh, load_mesh
from gatetherm.solvers.effects import Targets
from gatetherm.solvers.frame import enclosed_volume, region_volume
from gatetherm.solvers.heat import TimeScheme
from gatetherm.solvers.material import Material
from gatetherm.studies.run import case_mech
from gatetherm.studies.run.tables import Table
from gatetherm.solvers.problem import (AXES, FaceFilm, Film, FixedTemperature, Fluid, Flux, Probe, Problem,
                                       Relative, Signals, Source, Support, inputs, values)
from gatetherm.studies.run.parameters import UNCERTAIN_FIX, mesh_parameter
from gatetherm.studies.run.schedules import STEADY, Schedule, series_drive, timed_schedule
from gatetherm.studies.run.timeseries import read_timeseries

SECTIONS = ("case", "mesh", "materials", "initial", "temperature", "thermal", "faces", "sources", "fluids",
            "supports", "probes", "relative", "means", "signals", "time", "actuator") + case_mech.SECTIONS
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
KEYS = {
    "case": ("name", "order", "plane", "uncertain"),
    "mesh": ("file", "size", "parameters", "refine", "groups", "include"),
    "mesh.refine": ("near", "size", "distance"),
    "mesh.groups.NAME": ("dim", "box", "rest", "normal", "tolerance"),
    "materials.REGION": tuple(MATERIAL_KEYS),
    "initial": ("temperature", "reference"),
    "temperature": ("field", "regions"),
    "thermal.BOUNDARY": ("film", "ambient", "temperature", "flux"),
    "faces": ("film", "ambient"),
    "sources.REGION": ("density", "power"),
    "fluids.NAME": ("boundary", "volume", "rho_c", "flow_rate", "capacity", "conductance", "film_on", "film_off",
                    "supply", "pump", "hose_capacity", "hose_loss", "hose_name", "ambient"),
    "supports.BOUNDARY": ("type", "components", "stiffness", "value"),
    "probes.NAME": ("point", "quantities", "region"),
    "relative.NAME": ("a", "b", "axis"),
    "signals": ("theta_A", "theta_B", "theta_C", "delta"),
    "time": ("end", "step", "output", "schedule", "fields", "scheme"),
    "time.scheme": ("theta", "restart", "restart_intervals"),
    "actuator": ("type", "stroke", "stack_stiffness", "spring_stiffness", "preload", "dead_band", "hysteresis",
                 "reset"),
    **case_mech.KEYS,
}
"""The keys of every table of a case file (NAME, REGION, BOUNDARY, POINT: a name of the case or a
group of its mesh); ``docs/case-file.md`` documents each one (``tests/test_docs.py``).
Tables of names the user chooses: :data:`FREE`."""
FREE = {"mesh.parameters": "NAME", "temperature.regions": "REGION", "means": "NAME"}
"""Tables whose keys are names: a .geo parameter, a region, a mean's name."""


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
    """A model ready to run: a problem on its named mesh, what drives it, and how it was made.

    A case file is read into one (:func:`load_case`); so is the paper's frame
    (:func:`gatetherm.studies.run.frame_case.gate_frame`). Every command, study and API
    function runs a Case; nothing downstream asks which of the two it came from."""

    name: str
    problem: Problem
    mesh: FrameMesh
    time: TimeSettings | None = None
    """None: steady state (or a prescribed temperature)."""
    schedule: Schedule = STEADY
    """What drives a run by default (a case file's ``[time]`` and schedule file; a paper condition)."""
    origin: object = None
    """How the case was made (:class:`CaseFile` or the frame generator's origin): ``remake``
    with some of its keys changed (:meth:`with_overrides`), and its ``parameters`` (the
    hypotheses a diagnosis may move)."""
    targets: Targets = Targets()
    """The names the effects act on (joints, supports, regions; declared effects)."""
    defaults: dict = field(default_factory=dict)
    """Inputs that a recorded series may leave out, with the value they then keep."""
    actuator: object = None
    """The compensation actuator (``[actuator]``: an ActuatorParams), None: ideal (a correction sent
    to the control as an offset)."""
    parameters: object = None
    """What a generator made the case from (the frame's ModelConfig), for analyses that only such a
    model has (beam theory); None for a case file."""
    effects: dict = field(default_factory=dict)
    """Effects switched on, {key: value} (:mod:`gatetherm.solvers.effects`)."""
    sensors: dict = field(default_factory=dict)
    """Sensor faults, {channel: {fault: value}}."""
    path: Path | None = None
    """The case (or model) file, if any."""
    files: tuple[Path, ...] = ()
    """The files the case reads (itself, its mesh or geometry, its schedule): a run never overwrites them."""
    source: str = ""
    """Where the case came from, for metadata (a file path, or the generator and its model file)."""

    @property
    def dim(self) -> int:
        return self.mesh.dim

    def with_overrides(self, overrides: dict) -> "Case":
        """The case made again with ``overrides`` ({dotted key: value} of its file: ``materials.column.k``,
        ``thermal.free.film``, ``mesh.parameters.h``, ``geometry.l4`` …); effects and sensor faults kept.
        The mesh is reused when nothing it depends on changed."""
        if not overrides:
            return self
        made = self.origin.remake(overrides, self)
        return dataclasses.replace(made, effects={**made.effects, **self.effects},
                                   sensors={**made.sensors, **self.sensors})

    def with_schedule(self, schedule: Schedule) -> "Case":
        return dataclasses.replace(self, schedule=schedule)

    def inputs(self) -> set[str]:
        """The schedule columns its values read."""
        return inputs(self.problem)

    def held(self) -> set[str]:
        """Inputs that are pump states (they keep their last sample)."""
        return {n for f in self.problem.fluids for n in f.pump.names()}


def nested(overrides: dict) -> dict:
    """``{"a.b": 1}`` as ``{"a": {"b": 1}}`` (a TOML document to overlay)."""
    out: dict = {}
    for key, value in overrides.items():
        node, parts = out, key.split(".")
        for part in parts[:-1]:
            node = node.setdefault(part, {})
            if not isinstance(node, dict):
                raise InputError(key, "overrides a value with a table", "check the key")
        node[parts[-1]] = value
    return out


def overlay(document: dict, changes: dict) -> dict:
    """``document`` with the tables of ``changes`` merged in (values replaced), as a new dict."""
    out = dict(document)
    for k, v in changes.items():
        out[k] = overlay(out[k], v) if isinstance(v, dict) and isinstance(out.get(k), dict) else v
    return out


@dataclass(frozen=True)
class CaseFile:
    """A case file as read: its parsed document, to be read again with keys changed."""

    path: Path
    document: dict = field(repr=False, compare=False)
    mesh_factor: float = 1.0

    def remake(self, overrides: dict, previous: Case | None = None) -> Case:
        doc = overlay(self.document, nested(overrides))
        same_mesh = previous is not None and doc.get("mesh") == self.document.get("mesh")
        return case_from_document(doc, self.path, self.mesh_factor, previous.mesh if same_mesh else None)

    def parameters(self, case: Case) -> tuple:
        from gatetherm.studies.run.parameters import case_parameters

        return case_parameters(case)

    def uncertain(self, case: Case, keys) -> tuple:
        """Further geometry parameters (``--uncertain mesh.parameters.NAME``)."""
        from gatetherm.studies.run.parameters import marked

        return marked(case, keys)

    def model_file(self, case: Case, header: str = "") -> None:
        """None: a case file is not rewritten (its comments and layout are the user's); the
        diagnosis report lists the values to put into it."""
        return None


def _mesh(top: Table, base: Path, factor: float = 1.0) -> FrameMesh:
    m = top.sub("mesh", KEYS["mesh"])
    path = base / m.string("file")
    if not path.is_file():
        m.fail("file", f"no such file '{path}'", "give a .msh, .geo or CAD file beside the case")
    suffix = path.suffix.lower()
    if suffix in (".msh", ".vtu"):
        for k in ("size", "parameters", "refine", "groups", "include"):
            if k in m.data:
                m.fail(k, f"applies only to a geometry that gatetherm meshes ({SCRIPT}, {', '.join(CAD)})",
                       "mesh the file again in gmsh, or give the .geo")
        if factor != 1.0:
            m.fail("file", "a mesh file cannot be refined", "give the .geo or CAD file to mesh it finer")
        return _in_case(top, load_mesh, path)
    if suffix not in (SCRIPT, *CAD):
        m.fail("file", f"unknown mesh or geometry format '{suffix}'", f"use .msh, {SCRIPT} or {', '.join(CAD)}")
    params = m.sub("parameters")
    refine = []
    for i, r in enumerate(m.data.get("refine", [])):
        rt = Table(top.file, f"mesh.refine[{i + 1}]", r, KEYS["mesh.refine"])
        refine.append(Refinement(rt.string("near"), factor * rt.number("size", METRES),
                                 rt.number("distance", METRES)))
    include = m.data.get("include", [])
    if not (isinstance(include, list) and all(isinstance(f, str) for f in include)):
        m.fail("include", f"expected a list of file names, got {include!r}", 'e.g. include = ["../common.geo"]')
    for f in include:
        if not (base / f).is_file():
            m.fail("include", f"no such file '{base / f}'",
                   "name files the geometry script reads, relative to the case")
    groups = tuple(_group(m.sub("groups").sub(name, KEYS["mesh.groups.NAME"]), name)
                   for name in m.data.get("groups", {}))
    size = factor * m.number("size", METRES, 0.0) or None
    return _in_case(top, mesh_geometry, MeshSpec(path, size, {k: params.number(k) for k in params.data},
                                                 tuple(refine), groups, tuple(base / f for f in include), base, factor))


def _in_case(top: Table, read, arg) -> FrameMesh:
    """``read(arg)``, its errors about case keys (``mesh.…``, ``--mesh-factor``) naming the case file."""
    try:
        return read(arg)
    except InputError as err:
        raise err.at(str(top.file)) if err.field.startswith(("mesh", "--")) else err from None


def _group(g: Table, name: str) -> GroupRule:
    """A [mesh.groups.NAME] rule: box (one or a list), rest, normal (with tolerance)."""
    box = g.data.get("box", [])
    boxes = [box] if box and all(isinstance(b, (int, float)) for b in box) else box
    if not (isinstance(boxes, list) and all(_numbers(b, (6,)) for b in boxes)):
        g.fail("box", f"expected [xmin, ymin, zmin, xmax, ymax, zmax] or a list of them, got {box!r}",
               "give six numbers in m per box")
    rest = g.data.get("rest", False)
    if not isinstance(rest, bool):
        g.fail("rest", f"expected true or false, got {rest!r}")
    normal = g.data.get("normal")
    if normal is not None and not (_numbers(normal, (2, 3)) and any(normal)):
        g.fail("normal", f"expected a direction [nx, ny(, nz)], got {normal!r}", "e.g. normal = [0, 0, 1]")
    if not (boxes or rest or normal):
        g.fail("box", "the group selects nothing", "give box, normal or rest = true")
    if "tolerance" in g.data and normal is None:
        g.fail("tolerance", "goes with normal only", "remove it or give normal")
    return GroupRule(name, int(g.number("dim", Range(0, 3, whole=True))), tuple(tuple(map(float, b)) for b in boxes),
                     rest, tuple(map(float, normal)) if normal else None,
                     g.number("tolerance", Range(0.0, math.pi, lo_open=True, unit="rad"), NORMAL_TOLERANCE))


def _numbers(v, lengths) -> bool:
    """Whether ``v`` is a list of finite numbers of one of ``lengths``."""
    return isinstance(v, list) and len(v) in lengths and all(
        isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x) for x in v)


def _materials(top: Table, fm: FrameMesh, need: set[str]) -> tuple[dict, dict]:
    mats = top.sub("materials", tuple(fm.regions))
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
        if "thickness" in t.data:
            if fm.dim == 3:
                t.fail("thickness", "applies to 2-D sections only", "remove it")
            thickness[region] = t.number("thickness", THICKNESS)
    return materials, thickness


def _boundary_conditions(top: Table, fm: FrameMesh, names) -> dict:
    th = top.sub("thermal", tuple(fm.boundaries))
    out = {"films": [], "fixed": [], "fluxes": []}
    for b in th.data:
        t = th.sub(b, KEYS["thermal.BOUNDARY"])
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


def _supports(top: Table, fm: FrameMesh, names) -> tuple:
    sup = top.sub("supports", case_mech.support_names(fm))
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


def _probes(top: Table, fm: FrameMesh, quantities: tuple[str, ...]) -> tuple:
    pr = top.sub("probes")
    out = []
    finder = None
    for name in pr.data:
        t = pr.sub(name, KEYS["probes.NAME"])
        point = t.data.get("point")
        if isinstance(point, str):
            if point not in fm.sensors:
                t.fail("point", f"'{point}' is not a point group of the mesh", f"points: {', '.join(fm.sensors) or 'none'}"
                       "; or give coordinates [x, y(, z)] in m")
            xyz = tuple(float(v) for v in fm.points[fm.sensors[point]])
        elif _numbers(point, (fm.dim,)):
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
        t = rel.sub(name, KEYS["relative.NAME"])
        out.append(Relative(name, t.name("a", names, "probe"), t.name("b", names, "probe"),
                            AXES.index(t.string("axis", choices=tuple(AXES[:dim])))))
    return tuple(out)


def _signals(top: Table, probes, relative) -> Signals:
    s = top.sub("signals", KEYS["signals"])
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
    from gatetherm.studies.run.timeseries import check_steps

    t = top.sub("time", KEYS["time"])
    end = t.number("end", SECONDS)
    within = Range(0.0, end, lo_open=True, unit="s")  # an interval longer than the run is refused
    output = t.number("output", within, min(60.0, end))
    step = t.number("step", within, output)
    check_steps(end, step, t.key("step"))
    if abs(output / step - round(output / step)) > 1e-9:
        t.fail("output", f"{output:g} s is not a whole multiple of the step {step:g} s", "change output or step")
    sch = t.sub("scheme", KEYS["time.scheme"])
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


def load_case(path, mesh_factor: float = 1.0, overrides: dict | None = None) -> Case:
    """Read and check a case file (``docs/case-file.md``); paths inside it are relative to its folder.

    Parameters
    ----------
    path : str or path
        The ``.toml`` case file.
    mesh_factor : float
        A geometry (``.geo``, CAD) is meshed with its element sizes times this factor (a ``.msh``
        is read as it is).
    overrides : dict, optional
        ``{dotted key: value}`` changing keys of the file as it is read, e.g.
        ``{"thermal.free.film": 8.0}``.

    Returns
    -------
    Case
        Bad input raises :class:`gatetherm.InputError` naming the file, the key and the fix.
    """
    path = Path(path)
    text = read_text(path, "CASE.toml", "give the path of a .toml case file")
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as err:
        raise InputError(str(path), f"not valid TOML ({err})") from None
    return case_from_document(overlay(data, nested(overrides or {})), path, mesh_factor)


def case_from_document(data: dict, path: Path, mesh_factor: float = 1.0, mesh: FrameMesh | None = None) -> Case:
    """The case of a parsed case file ``data`` read from ``path`` (``mesh``: its mesh, already made)."""
    top = Table(path, "", data, SECTIONS)
    head = top.sub("case", KEYS["case"])
    uncertain = head.data.get("uncertain", [])
    bad = [k for k in uncertain if mesh_parameter(data, k) is None] if isinstance(uncertain, list) else [uncertain]
    if bad:
        head.fail("uncertain", f"{bad[0]!r} is not a non-zero number of [mesh.parameters]", UNCERTAIN_FIX)
    order = head.data.get("order", 1)
    if isinstance(order, bool) or order not in (1, 2):
        head.fail("order", f"{order!r} is not admissible", "give 1 (linear) or 2 (quadratic elements)")
    fm = _mesh(top, path.parent, mesh_factor) if mesh is None else mesh
    plane = head.string("plane", "stress", ("stress", "strain", "axisymmetric"))
    if plane == "axisymmetric":
        case_mech.check_axisymmetric(top, fm, data)
    time, scheme, schedule_ts = _time(top, path.parent)
    columns = tuple(n for n in schedule_ts.names if n != "time_s") if schedule_ts is not None else ()
    prescribed = "temperature" in data
    elastic = "supports" in data
    mechanical = case_mech.mechanical_only(data)  # no temperature at all
    need = ({"E", "nu", "alpha"} if elastic else set()) | (set() if prescribed else {"k"}) | \
        ({"rho", "c"} if time else set())
    need = ({"E", "nu"} if mechanical else need) | ({"rho"} if "gravity" in data else set())
    materials, thickness = _materials(top, fm, need)
    names = ("t", *columns)
    init = top.sub("initial", KEYS["initial"])
    T0 = init.number("temperature", CELSIUS, 20.0)
    kw: dict = {}
    if prescribed:
        for s in ("thermal", "faces", "sources", "fluids", "time"):
            if s in data:
                top.fail(s, "cannot go with a prescribed [temperature]", "remove one of the two")
        tt = top.sub("temperature", KEYS["temperature"])
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
            s = src.sub(r, KEYS["sources.REGION"])
            if ("density" in s.data) == ("power" in s.data):
                s.fail("density", "give either density (W/m³) or power (W)")
            if "density" in s.data:
                sources.append(Source(r, s.value("density", names, unit="W/m³")))
            else:
                vol = case_mech.revolved_volume(fm, r) if plane == "axisymmetric" else \
                    region_volume(fm, r, thickness.get(r, 1.0))
                sources.append(Source(r, s.value("power", names, unit="W"), 1.0 / vol))
        kw["sources"] = tuple(sources)
        if "faces" in data:
            if fm.dim != 2:
                top.fail("faces", "applies to 2-D sections only", "remove it")
            f = top.sub("faces", KEYS["faces"])
            kw["faces"] = FaceFilm(f.number("film", FILM), f.value("ambient", names, unit="°C"))
        kw["fluids"] = _fluids(top, fm, names, thickness)
    twice = _twice(kw)
    if twice:
        top.fail("thermal", f"boundary '{twice}' is given two conditions", "give each boundary one condition")
    both = _overlapping(fm, [c.boundary for c in (*kw.get("films", ()), *kw.get("fixed", ()), *kw.get("fluxes", ()),
                                                  *kw.get("fluids", ()))])
    if both:
        top.fail(f"thermal.{both[1]}", f"shares facets with thermal.{both[0]}: two conditions on those facets",
                 "give every part of the boundary one condition (split the groups, or use rest = true)")
    supports = _supports(top, fm, names) if elastic else ()
    if elastic:
        kw.update(case_mech.read_loads(top, fm, names))
        both = _overlapping(fm, [ld.boundary for ld in kw.get("loads", ())])
        if both:
            top.fail(f"loads.{both[1]}", f"shares facets with loads.{both[0]}: the loads would add up unseen",
                     "give every part of the boundary one load table")
    elif "gravity" in data or "loads" in data:
        top.fail("gravity" if "gravity" in data else "loads", "a mechanical load needs [supports]",
                 "hold the body with [supports.BOUNDARY] tables")
    kw["contacts"] = case_mech.read_contacts(top, fm, not (prescribed or mechanical), elastic)
    quantities = ("T",) * (not mechanical) + (("u", "sigma") if elastic else ())
    probes = _probes(top, fm, quantities)
    relative = _relative(top, probes, fm.dim) if elastic or "relative" in data else ()
    means = top.sub("means", None)
    mean_pairs = tuple((k, means.name(k, fm.boundaries, "boundary")) for k in means.data)
    problem = Problem(fm.dim, materials, int(order), thickness, plane,
                      T0, init.number("reference", CELSIUS, T0),
                      supports=supports, probes=probes, relative=relative, means=mean_pairs,
                      signals=_signals(top, probes, relative), elastic=elastic, scheme=scheme,
                      thermal=not mechanical, **kw)
    case_mech.check_assembly(top, fm, problem, time is None)
    if schedule_ts is not None:
        _check_schedule(problem, schedule_ts, time)
    if time is None:
        schedule = STEADY
    else:
        drive = (series_drive(schedule_ts, columns, {n for f in problem.fluids for n in f.pump.names()},
                              label=str(time.schedule)) if schedule_ts is not None else (lambda _: {}))
        schedule = timed_schedule(time.end, time.step, time.output, drive,
                                  f"schedule {time.schedule}" if time.schedule else "no schedule")
    return Case(head.string("name", path.stem), problem, fm, time, schedule, CaseFile(path, data, mesh_factor),
                case_targets(problem, fm), actuator=_actuator(top), path=path, source=str(path),
                files=(path, path.parent / data["mesh"]["file"], *([time.schedule] if time and time.schedule else [])))


def _actuator(top: Table):
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


def case_targets(problem: Problem, fm: FrameMesh) -> Targets:
    """What a case file's effects act on: its one support by default, if it has only one; its
    contacts and the interfaces ``A/B`` of its regions as joints."""
    rigid = [s.boundary for s in problem.supports if s.stiffness is None]
    interfaces = tuple(b for b in fm.boundaries if b.count("/") == 1 and all(r in fm.regions for r in b.split("/")))
    return Targets(defaults={"compliant_base": rigid[0], "base_conduction": rigid[0]} if len(rigid) == 1 else {},
                   interfaces=interfaces)


def _overlapping(fm: FrameMesh, boundaries: list[str]) -> tuple[str, str] | None:
    """Two different ``boundaries`` of the mesh that share a facet (the first such pair), if any."""
    owner: dict = {}
    for b in dict.fromkeys(boundaries):
        for f in map(tuple, np.sort(fm.boundaries[b], axis=1)):
            if owner.setdefault(f, b) != b:
                return owner[f], b
    return None


def _twice(kw: dict) -> str | None:
    """A boundary that carries two thermal conditions (films, fixed, fluxes, fluids), if any."""
    seen = set()
    for c in (*kw.get("films", ()), *kw.get("fixed", ()), *kw.get("fluxes", ()), *kw.get("fluids", ())):
        if c.boundary in seen:
            return c.boundary
        seen.add(c.boundary)
    return None
