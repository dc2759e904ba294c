"""The hypotheses a diagnosis tries, of three kinds, each with one parameter.

* ``effect``: a catalogue effect the model leaves out (:data:`solvers.effects.CATALOGUE`);
* ``parameter``: an existing model parameter off its value (film coefficients, tank-wall
  films, initial temperature, the material's k, α, ρc), within a plausible factor (or
  shift) of the model file's value; on a case file's frame, the case's own film
  coefficients (per boundary), fluid films, sources (per region), initial temperature and
  one factor on every region's k, α or c (:func:`case_parameter_pieces`);
* ``sensor``: a fault of one recorded channel (:mod:`solvers.sensors`): thermocouple
  offset, gain, lag; displacement-sensor offset, gain, drift.

A set of hypotheses with values (an *assignment*) turns into a model file or a case
(:func:`configure`): parameters change the configuration, effects switch on, sensor
faults go to ``sensors``; every run goes through the scenario path.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass

from gatetherm.solvers.effects import CATALOGUE
from gatetherm.solvers.expr import Value
from gatetherm.solvers.sensors import compose, faults_of
from gatetherm.studies.run.case import Case
from gatetherm.studies.run.config import Config


@dataclass(frozen=True)
class Piece:
    """One hypothesis and its parameter's plausible range (in the parameter's unit)."""

    kind: str
    name: str
    param: str
    unit: str
    lo: float
    hi: float
    log_scale: bool
    neutral: float | None
    """The value that changes nothing (a parameter's model value, a fault's identity);
    None for an effect (off is a limit, not a value)."""
    doc: str
    channel: str | None = None
    """The channel of a sensor piece."""
    rerun: bool = True
    """A new value needs a new model run (model- or drive-side); else it acts on a kept run."""
    linear: bool = False
    """The reported signal is linear in the value (sensor offset, gain, drift: fitted in closed form)."""
    target: str | None = None
    """The boundary, fluid or region a case parameter acts on."""

    @property
    def key(self) -> str:
        return f"{self.kind}:{self.name}" + (f"@{self.channel}" if self.channel else "")

    @property
    def label(self) -> str:
        return f"{self.name}({self.channel})" if self.channel else self.name

    def describe(self) -> dict:
        """The ``--list-effects --json`` entry."""
        d = {"kind": self.kind, "name": self.name,
             "params": {self.param: {"unit": self.unit, "range": [self.lo, self.hi]}}, "doc": self.doc}
        if self.channel:
            d["channel"] = self.channel
        if self.kind == "effect":
            d["acts_on"] = CATALOGUE[self.name].acts_on
        return d


@dataclass(frozen=True)
class ParamDef:
    """An existing model parameter a diagnosis may move."""

    name: str
    field: str
    """``ThermalParams`` field, or ``Material`` field (``rho_c``: ρ·c, set through c)."""
    unit: str
    lo: float
    hi: float
    """Plausible range: factors of the model's value, or (``shift``) offsets from it."""
    shift: bool
    doc: str

    @property
    def material(self) -> bool:
        return self.field in ("k", "alpha", "rho_c")


PARAMETERS = (
    ParamDef("air_film", "h_air", "W/(m2 K)", 0.4, 2.5, False, "film coefficient of the free surfaces to room air"),
    ParamDef("oil_film_on", "h_oil_on", "W/(m2 K)", 0.2, 5.0, False, "tank-wall film coefficient, pump on"),
    ParamDef("oil_film_off", "h_oil_off", "W/(m2 K)", 0.2, 5.0, False, "tank-wall film coefficient, pump off"),
    ParamDef("initial_offset", "T0", "degC", -3.0, 3.0, True,
             "initial temperature of frame and oil (room unchanged): the frame was not in equilibrium at the start"),
    ParamDef("conductivity", "k", "W/(m K)", 0.6, 1.6, False, "thermal conductivity of the frame material"),
    ParamDef("expansion", "alpha", "1/K", 0.8, 1.25, False,
             "thermal expansion coefficient of the frame material (with one material, δ is proportional to it: "
             "the data cannot tell it from a gain of the δ sensor)"),
    ParamDef("heat_capacity", "rho_c", "J/(m3 K)", 0.8, 1.25, False,
             "volumetric heat capacity ρc of the frame material"),
)
PARAMETER_DEFS = {p.name: p for p in PARAMETERS}


def model_value(config: Config, p: ParamDef) -> float:
    """The model file's value of a parameter."""
    if p.field == "rho_c":
        return config.model.material.rho * config.model.material.c
    return getattr(config.model.material if p.material else config.model.thermal, p.field)


def effect_pieces(names=tuple(CATALOGUE), has_ambient: bool = False, case: Case | None = None) -> list[Piece]:
    """Catalogue effects as hypotheses; ``ambient_drift`` only when the room is not recorded.
    On a ``case``, only the observation-side ones (the others act on the paper frame), and
    ``stand_drift`` only with a boundary mean named ``base`` (the temperature it reads)."""
    out = []
    for n in names:
        e = CATALOGUE[n]
        if e.acts_on == "drive" and has_ambient:
            continue  # the file drives the model with the recorded room: a drift cannot act
        if case is not None and (e.acts_on != "observation" or (
                n == "stand_drift" and "base" not in dict(case.problem.means))):
            continue
        out.append(Piece("effect", n, e.param, e.unit, e.lo, e.hi, e.log_scale, None, e.doc,
                         rerun=e.acts_on != "observation"))
    return out


def parameter_pieces(config: Config | Case, names=None) -> list[Piece]:
    """The existing parameters ``names`` (default: all) of a model file or a case as hypotheses."""
    if isinstance(config, Case):
        return [p for p in case_parameter_pieces(config) if names is None or p.name in names]
    out = []
    for n in PARAMETER_DEFS if names is None else names:
        p = PARAMETER_DEFS[n]
        v = model_value(config, p)
        lo, hi = (v + p.lo, v + p.hi) if p.shift else (v * p.lo, v * p.hi)
        out.append(Piece("parameter", n, p.field, p.unit, lo, hi, not p.shift, v, p.doc))
    return out


def sensor_pieces(channels, config: Config | None = None) -> list[Piece]:
    """Faults of every channel (a lag only where the model file sets none: two lags do not compose)."""
    out = []
    for c in channels:
        for f in faults_of(c).values():
            if f.name == "lag" and config is not None and "lag" in config.sensors.get(c, {}):
                continue
            out.append(Piece("sensor", f"sensor_{f.name}", f.name, f.unit, f.lo, f.hi, f.log_scale, f.identity,
                             f.doc, channel=c, rerun=False, linear=f.linear))
    return out


def catalogue(config: Config | Case, channels) -> list[Piece]:
    """Every hypothesis, as ``--list-effects`` shows them."""
    case = config if isinstance(config, Case) else None
    return effect_pieces(case=case) + parameter_pieces(config) + sensor_pieces(channels)


#: One factor on every region's material property: piece name -> (Material field, range, doc).
CASE_MATERIAL = {
    "conductivity": ("k", 0.6, 1.6, "thermal conductivity k of every region (one factor)"),
    "expansion": ("alpha", 0.8, 1.25, "thermal expansion coefficient α of every region (one factor; δ is "
                  "proportional to it where all regions share it: the data cannot tell it from a gain of the "
                  "δ sensor)"),
    "heat_capacity": ("c", 0.8, 1.25, "specific heat c, so ρc, of every region (one factor)"),
}
CASE_FILM, CASE_FLUID_FILM, CASE_SOURCE, CASE_SHIFT = (0.4, 2.5), (0.2, 5.0), (0.5, 2.0), 3.0
"""Plausible ranges of a case's films, fluid films and sources (factors) and initial temperature (shift, K)."""


def case_parameter_pieces(case: Case) -> list[Piece]:
    """A case's own parameters as hypotheses: every film coefficient (per boundary, and the
    2-D faces'), every fluid's films, every source (a factor), the initial temperature of
    a transient case, and one factor on every region's k, α, c."""
    pr, out = case.problem, []

    def absolute(name, param, v, rng, doc, target=None):
        if v > 0:
            out.append(Piece("parameter", name, param, "W/(m2 K)", v * rng[0], v * rng[1], True, v, doc, target=target))

    for f in pr.films:
        absolute(f"film_{f.boundary}", "h", f.h, CASE_FILM, f"film coefficient of boundary '{f.boundary}'", f.boundary)
    if pr.faces is not None:
        absolute("faces_film", "h", pr.faces.h, CASE_FILM, "film coefficient of the section's front and back faces")
    for fl in pr.fluids:
        for param in ("film_on", "film_off"):
            absolute(f"{fl.name}_{param}", param, getattr(fl, param), CASE_FLUID_FILM,
                     f"wall film coefficient of fluid '{fl.name}', pump {param[5:]}", fl.name)
    for src in pr.sources:
        out.append(Piece("parameter", f"source_{src.region}", "factor", "1", *CASE_SOURCE, True, 1.0,
                         f"factor on the heat source of region '{src.region}'", target=src.region))
    if case.time is not None:
        out.append(Piece("parameter", "initial_offset", "T0", "degC", pr.T0 - CASE_SHIFT, pr.T0 + CASE_SHIFT, False,
                         pr.T0, "initial temperature of solid and fluids (stress-free temperature unchanged)"))
    out += [Piece("parameter", n, "factor", "1", lo, hi, True, 1.0, doc)
            for n, (_, lo, hi, doc) in CASE_MATERIAL.items()]
    return out


def _case_with(case: Case, params: dict) -> Case:
    """``case`` with its parameter pieces ``params`` ({Piece: value}) set."""
    pr = case.problem
    films, fluids, materials, sources = list(pr.films), list(pr.fluids), dict(pr.materials), list(pr.sources)
    faces, T0 = pr.faces, pr.T0
    for p, v in params.items():
        if p.name in CASE_MATERIAL:
            field = CASE_MATERIAL[p.name][0]
            materials = {r: dataclasses.replace(m, **{field: getattr(m, field) * v}) for r, m in materials.items()}
        elif p.param == "factor":
            sources = [dataclasses.replace(s, density=_scaled(s.density, v)) if s.region == p.target else s
                       for s in sources]
        elif p.param == "h" and p.target is None:
            faces = dataclasses.replace(faces, h=v)
        elif p.param == "h":
            films = [dataclasses.replace(f, h=v) if f.boundary == p.target else f for f in films]
        elif p.param == "T0":
            T0 = v
        else:
            fluids = [dataclasses.replace(f, **{p.param: v}) if f.name == p.target else f for f in fluids]
    return dataclasses.replace(case, problem=dataclasses.replace(
        pr, films=tuple(films), fluids=tuple(fluids), materials=materials, sources=tuple(sources), faces=faces, T0=T0))


def _scaled(v: Value, factor: float) -> Value:
    return Value(v.constant * factor) if v.is_constant else Value.of(f"{factor!r} * ({v.text})", v.key, v.range)


PROPORTIONAL = (frozenset({"parameter:expansion", "sensor:sensor_gain@delta_um"}),)
"""Pairs of hypotheses (keys) whose signals are proportional by construction: α of every
material scales δ and nothing else, and so does a gain of the δ sensor; only their product
shows in the data (where no other displacement channel is recorded)."""

Assignment = tuple  # ((Piece, value), ...) sorted by key: hashable


def assignment(values: dict) -> Assignment:
    return tuple(sorted(values.items(), key=lambda kv: kv[0].key))


def model_side(values: dict) -> Assignment:
    """The part of an assignment a model run depends on (effects and parameters)."""
    return assignment({p: v for p, v in values.items() if p.kind != "sensor"})


def configure(config: Config | Case, values: dict) -> Config | Case:
    """``config`` (a model file or a case) with the hypotheses ``values`` ({Piece: value}) in it."""
    effects, faults, params = dict(config.effects), {}, {}
    for p, v in values.items():
        if p.kind == "effect":
            effects[p.name] = float(v)
        elif p.kind == "sensor":
            faults.setdefault(p.channel, {})[p.param] = float(v)
        else:
            params[p] = float(v)
    if isinstance(config, Case):
        return dataclasses.replace(_case_with(config, params), effects=effects, sensors=compose(config.sensors, faults))
    model = config.model
    thermal, material, tie = {}, {}, {}
    for p, v in params.items():
        d = PARAMETER_DEFS[p.name]
        if not d.material:
            thermal[d.field] = v
            continue
        field, value = (("c", v / model.material.rho) if d.field == "rho_c" else (d.field, v))
        material[field] = value
        if model.tie_material is not None:  # the tie bar's own material moves by the same factor
            tie[field] = getattr(model.tie_material, field) * value / getattr(model.material, field)
    model = dataclasses.replace(
        model, thermal=dataclasses.replace(model.thermal, **thermal),
        material=dataclasses.replace(model.material, **material),
        tie_material=dataclasses.replace(model.tie_material, **tie) if tie else model.tie_material)
    return dataclasses.replace(config, model=model, effects=effects, sensors=compose(config.sensors, faults))
