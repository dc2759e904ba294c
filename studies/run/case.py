"""Case files: a user's frame described in the names of its mesh's physical groups.

A TOML case names a mesh (``.msh`` of any gmsh version, or a ``.geo``/CAD file meshed through gmsh) and gives
materials per region, thermal conditions per boundary (film to an ambient, fixed temperature, heat flux; adiabatic
where nothing is said), sources, lumped fluid volumes, supports, probes, relative displacements and the time
settings. Every key is checked where it is read: an unknown key, a name that is not a group of the mesh, a region
without a material or a boundary with two conditions is one :class:`~gatetherm.InputError` line naming the file
and the key and listing what is valid. ``docs/case-file.md`` is the reference of every key. The tables are read by
:mod:`~gatetherm.studies.run.case_mesh` (``[mesh]``), :mod:`~gatetherm.studies.run.case_tables` (materials,
thermal conditions, fluids, supports, probes, signals, actuator) and :mod:`~gatetherm.studies.run.case_mech`
(loads, contacts); this module reads the rest and puts the case together.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from gatetherm import InputError
from gatetherm.checks import CELSIUS, Range, argument, ranges
from gatetherm.files import parse_toml, read_text
from gatetherm.geometry.measure import region_volume
from gatetherm.geometry.mesh import FrameMesh, facet_keys
from gatetherm.solvers.effects import Targets
from gatetherm.solvers.heat import TimeScheme
from gatetherm.solvers.problem import FaceFilm, Problem, inputs, values
from gatetherm.studies.control.actuator import ActuatorParams
from gatetherm.studies.run import case_mech, case_mesh, case_sources, case_tables
from gatetherm.studies.run.origin import ModelParameters, Origin
from gatetherm.studies.run.parameters import UNCERTAIN_FIX, mesh_parameter
from gatetherm.studies.run.schedules import STEADY, Schedule, series_drive, timed_schedule
from gatetherm.studies.run.tables import Inputs, Said, Table
from gatetherm.studies.run.timeseries import read_timeseries

SECTIONS = ("case", "mesh", "materials", "initial", "temperature", "thermal", "faces", "sources", "fluids",
            "supports", "probes", "relative", "means", "signals", "time", "actuator", "sensors") + case_mech.SECTIONS
SCHEME = ranges(TimeScheme)
SECONDS = Range(0.0, lo_open=True, unit="s")
KEYS = {
    "case": ("name", "order", "plane", "uncertain"),
    "initial": ("temperature", "reference"),
    "temperature": ("field", "regions"),
    "faces": ("film", "ambient"),
    "time": ("end", "step", "output", "schedule", "fields", "scheme"),
    "time.scheme": ("theta", "restart", "restart_intervals"),
    "sensors": ("exclude",),
    **case_mesh.KEYS,
    **case_tables.KEYS,
    **case_sources.KEYS,
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

    A case file is read into one (:func:`load_case`); so is the paper's frame (:func:`gatetherm.frame.case.gate_frame`).
    Every command, study and API function runs a Case; nothing downstream asks which of the two it came from."""

    name: str
    problem: Problem
    mesh: FrameMesh
    time: TimeSettings | None = None
    """None: steady state (or a prescribed temperature)."""
    schedule: Schedule = STEADY
    """What drives a run by default (a case file's ``[time]`` and schedule file; a paper condition)."""
    origin: Origin | None = None
    """How the case was made (:class:`CaseFile` or the frame generator's origin): ``remake`` with some of its
    keys changed (:meth:`with_overrides`), and its ``parameters`` (the hypotheses a diagnosis may move)."""
    targets: Targets = Targets()
    """The names the effects act on (joints, supports, regions; declared effects)."""
    defaults: dict = field(default_factory=dict)
    """Inputs that a recorded series may leave out, with the value they then keep."""
    actuator: ActuatorParams | None = None
    """The compensation actuator (``[actuator]``), None: ideal (a correction sent to the control as an offset)."""
    parameters: ModelParameters | None = None
    """What a generator made the case from (the frame's ModelConfig) for what only it has (beam theory); None: a file"""
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
    unmountable: tuple[str, ...] = ()
    """Regions and boundaries no thermocouple can be mounted on (``[sensors] exclude``: they rotate
    or move): sensor placement and the diagnosis' sensor hypotheses leave them out."""

    @property
    def dim(self) -> int:
        return self.mesh.dim

    def with_overrides(self, overrides: dict) -> "Case":
        """The case made again with ``overrides`` ({dotted key: value} of its file: ``materials.column.k``,
        ``thermal.free.film``, ``mesh.parameters.h``, ``geometry.l4`` …); effects and sensor faults kept.
        The mesh is reused when nothing it depends on changed."""
        argument("overrides", overrides, (dict, type(None)), "a dict {dotted key: value}", 'e.g. {"thermal.free.film": 8.0}')
        if not overrides:
            return self
        made = self.origin.remake(overrides, self)
        return dataclasses.replace(made, effects={**made.effects, **self.effects},
                                   sensors={**made.sensors, **self.sensors})

    def with_order(self, order: int) -> "Case":
        """The case with elements of ``order`` (1 linear, 2 quadratic), kept by later overrides."""
        if self.origin is None:
            return dataclasses.replace(self, problem=dataclasses.replace(self.problem, order=order))
        return self.with_overrides({self.origin.ORDER: order})

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
    said: Said = field(default_factory=Said, repr=False, compare=False)  # its reading's warnings: a remake's are not
    ORDER = "case.order"
    """The key of the element order."""

    def remake(self, overrides: dict, previous: Case | None = None) -> Case:
        doc = overlay(self.document, nested(overrides))
        same_mesh = previous is not None and doc.get("mesh") == self.document.get("mesh")
        return case_from_document(doc, self.path, self.mesh_factor, previous.mesh if same_mesh else None, self.said)

    def parameters(self, case: Case) -> tuple:
        from gatetherm.studies.run.parameters import case_parameters

        return case_parameters(case)

    def uncertain(self, case: Case, keys) -> tuple:
        """Further geometry parameters (``--uncertain mesh.parameters.NAME``)."""
        from gatetherm.studies.run.parameters import marked

        return marked(case, keys)

    def model_file(self, case: Case, header: str = "") -> None:
        """None: a case file is not rewritten (its layout is the user's); the diagnosis report lists the values."""
        return None


def _time(top: Table, base: Path):
    """The time settings, the scheme and the schedule file's series (None: no schedule)."""
    if "time" not in top.data:
        return None, TimeScheme(), None
    from gatetherm.studies.run.timeseries import check_steps

    t = top.sub("time", KEYS["time"])
    end = t.number("end", SECONDS)
    within = Range(0.0, end, lo_open=True, unit="s")  # an interval longer than the run is refused
    try:
        output = t.number("output", within, min(60.0, end))
        step = t.number("step", within, output)
    except InputError as err:  # or the run's end in hours
        raise InputError(err.field, err.problem, f"{err.fix}; or end in s: {end:g} h is end = {end * 3600:g}".lstrip("; "))
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


def _check_schedule(top: Table, fm: FrameMesh, problem: Problem, ts, time: TimeSettings | None) -> None:
    """A band off its region warned of; each value that reads the schedule in its key's range at the run's samples."""
    case_sources.warn_bands(top, fm, problem, ts, time)
    if ts is None:
        return
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
    data = parse_toml(text, str(path), "fix the case file's syntax")
    return case_from_document(overlay(data, nested(overrides or {})), path, mesh_factor)


def case_from_document(data: dict, path: Path, mesh_factor: float = 1.0, mesh: FrameMesh | None = None,
                       said: Said | None = None) -> Case:
    """The case of a parsed case file ``data`` read from ``path`` (``mesh``: already made; ``said``: warnings given)."""
    top = Table(path, "", data, SECTIONS, said=Said(said or ()))
    head = top.sub("case", KEYS["case"])
    uncertain = head.data.get("uncertain", [])
    bad = [k for k in uncertain if mesh_parameter(data, k) is None] if isinstance(uncertain, list) else [uncertain]
    if bad:
        head.fail("uncertain", f"{bad[0]!r} is not a non-zero number of [mesh.parameters]", UNCERTAIN_FIX)
    order = head.data.get("order", 1)
    if isinstance(order, bool) or order not in (1, 2):
        head.fail("order", f"{order!r} is not admissible", "give 1 (linear) or 2 (quadratic elements)")
    fm = case_mesh.read_mesh(top, path.parent, mesh_factor) if mesh is None else mesh
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
    materials, thickness = case_tables.materials(top, fm, need)
    names = Inputs(("t", *columns), f"the schedule {time.schedule}" if time and time.schedule else "")
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
        kw.update(case_tables.boundary_conditions(top, fm, names))
        src = top.sub("sources", case_sources.where(fm))
        sources = []
        for r in src.data:
            sources.append(case_sources.read_source(
                src.sub(r, case_sources.KEYS["sources.REGION"]), r, names,
                lambda r=r: case_mech.revolved_volume(fm, r) if plane == "axisymmetric" else
                region_volume(fm, r, thickness.get(r, 1.0)), fm.dim, r not in fm.regions))
        kw["sources"] = tuple(sources)
        case_sources.warn_sizes(src, float(np.ptp(fm.points, axis=0).max()))
        if "faces" in data:
            if fm.dim != 2:
                top.fail("faces", "applies to 2-D sections only", "remove it")
            f = top.sub("faces", KEYS["faces"])
            kw["faces"] = FaceFilm(f.number("film", case_tables.FILM), f.value("ambient", names, unit="°C"))
        kw["fluids"] = case_tables.fluids(top, fm, names, thickness)
    twice = _twice(kw)
    if twice:
        top.fail("thermal", f"boundary '{twice}' is given two conditions", "give each boundary one condition")
    both = _overlapping(fm, [c.boundary for c in (*kw.get("films", ()), *kw.get("fixed", ()), *kw.get("fluxes", ()),
                                                  *kw.get("fluids", ()))])
    if both:
        top.fail(f"thermal.{both[1]}", f"shares facets with thermal.{both[0]}: two conditions on those facets",
                 "give every part of the boundary one condition (split the groups, or use rest = true)")
    supports = case_tables.supports(top, fm, names) if elastic else ()
    if elastic:
        kw.update(case_mech.read_loads(top, fm, names))
        both = _overlapping(fm, [ld.boundary for ld in kw.get("loads", ())])
        if both:
            top.fail(f"loads.{both[1]}", f"shares facets with loads.{both[0]}: the loads would add up unseen",
                     "give every part of the boundary one load table")
    elif key := next((k for k in ("gravity", "loads", "relative") if k in data), None):  # needs a held body
        top.fail(key, f"a {'relative displacement' if key == 'relative' else 'mechanical load'} needs [supports] (without "
                 "them the body is not solved for displacements)", "hold the body with [supports.BOUNDARY] tables")
    kw["contacts"] = case_mech.read_contacts(top, fm, not (prescribed or mechanical), elastic)
    quantities = ("T",) * (not mechanical) + (("u", "sigma") if elastic else ())
    probes = case_tables.probes(top, fm, quantities)
    relative = case_tables.relative(top, probes, fm.dim) if elastic or "relative" in data else ()
    means = top.sub("means", None)
    mean_pairs = tuple((k, means.name(k, fm.boundaries, "boundary")) for k in means.data)
    problem = Problem(fm.dim, materials, int(order), thickness, plane,
                      T0, init.number("reference", CELSIUS, T0),
                      supports=supports, probes=probes, relative=relative, means=mean_pairs,
                      signals=case_tables.signals(top, probes, relative), elastic=elastic, scheme=scheme,
                      thermal=not mechanical, **kw)
    case_mech.check_assembly(top, fm, problem, time is None)
    _check_schedule(top, fm, problem, schedule_ts, time)
    if time is None:
        schedule = STEADY
    else:
        drive = (series_drive(schedule_ts, columns, {n for f in problem.fluids for n in f.pump.names()},
                              label=str(time.schedule)) if schedule_ts is not None else (lambda _: {}))
        schedule = timed_schedule(time.end, time.step, time.output, drive,
                                  f"schedule {time.schedule}" if time.schedule else "no schedule")
    return Case(head.string("name", path.stem), problem, fm, time, schedule,
                CaseFile(path, data, mesh_factor, top.said), case_targets(problem, fm),
                actuator=case_tables.actuator(top), path=path, source=str(path), unmountable=_unmountable(top, fm),
                files=(path, path.parent / data["mesh"]["file"], *([time.schedule] if time and time.schedule else [])))


def _unmountable(top: Table, fm: FrameMesh) -> tuple[str, ...]:
    """``[sensors] exclude``: regions or boundaries of the mesh no thermocouple can go on."""
    t = top.sub("sensors", KEYS["sensors"])
    names = t.data.get("exclude", [])
    names = [names] if isinstance(names, str) else names
    valid = (*fm.regions, *fm.boundaries)
    if not isinstance(names, list) or not all(isinstance(n, str) for n in names):
        t.fail("exclude", f"{names!r} is not a list of names", 'e.g. exclude = ["spindle"]')
    bad = [n for n in names if n not in valid]
    if bad:
        t.fail("exclude", f"'{bad[0]}' is not a region or boundary of the mesh", f"names: {', '.join(valid)}")
    return tuple(dict.fromkeys(names))


def case_targets(problem: Problem, fm: FrameMesh) -> Targets:
    """What a case file's effects act on: its one support by default, if it has only one; its
    contacts and the interfaces ``A/B`` of its regions as joints."""
    rigid = [s.boundary for s in problem.supports if s.stiffness is None]
    interfaces = tuple(b for b in fm.boundaries if b.count("/") == 1 and all(r in fm.regions for r in b.split("/")))
    return Targets(defaults={"compliant_base": rigid[0], "base_conduction": rigid[0]} if len(rigid) == 1 else {},
                   interfaces=interfaces)


def _overlapping(fm: FrameMesh, boundaries: list[str]) -> tuple[str, str] | None:
    """Two different ``boundaries`` of the mesh that share a facet (the first such pair), if any."""
    names = list(dict.fromkeys(boundaries))
    if not names:
        return None
    facets = [np.asarray(fm.boundaries[b]) for b in names]
    label = np.repeat(np.arange(len(names)), [len(f) for f in facets])
    _, first, inverse = np.unique(facet_keys(np.concatenate(facets), len(fm.points)), return_index=True,
                                  return_inverse=True)
    owner = label[first][inverse]  # the boundary that lists each facet first
    clash = np.flatnonzero(owner != label)
    return (names[owner[clash[0]]], names[label[clash[0]]]) if len(clash) else None


def _twice(kw: dict) -> str | None:
    """A boundary that carries two thermal conditions (films, fixed, fluxes, fluids), if any."""
    seen = set()
    for c in (*kw.get("films", ()), *kw.get("fixed", ()), *kw.get("fluxes", ()), *kw.get("fluids", ())):
        if c.boundary in seen:
            return c.boundary
        seen.add(c.boundary)
    return None
