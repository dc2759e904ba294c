"""The hypotheses a diagnosis tries, of three kinds, each with one parameter.

* ``effect``: a catalogue effect the model leaves out (:data:`solvers.effects.CATALOGUE`);
* ``parameter``: an existing model parameter off its value (film coefficients, tank-wall
  films, initial temperature, the material's k, α, ρc), within a plausible factor (or
  shift) of the model file's value;
* ``sensor``: a fault of one recorded channel (:mod:`solvers.sensors`): thermocouple
  offset, gain, lag; displacement-sensor offset, gain, drift.

A set of hypotheses with values (an *assignment*) turns into a model file
(:func:`configure`): parameters change the configuration, effects switch on, sensor
faults go to ``Config.sensors``; every run goes through the scenario path.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass

from gatetherm.solvers.effects import CATALOGUE
from gatetherm.solvers.sensors import compose, faults_of
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


def effect_pieces(names=tuple(CATALOGUE), has_ambient: bool = False) -> list[Piece]:
    """Catalogue effects as hypotheses; ``ambient_drift`` only when the room is not recorded."""
    out = []
    for n in names:
        e = CATALOGUE[n]
        if e.acts_on == "drive" and has_ambient:
            continue  # the file drives the model with the recorded room: a drift cannot act
        out.append(Piece("effect", n, e.param, e.unit, e.lo, e.hi, e.log_scale, None, e.doc,
                         rerun=e.acts_on != "observation"))
    return out


def parameter_pieces(config: Config, names=tuple(PARAMETER_DEFS)) -> list[Piece]:
    out = []
    for n in names:
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


def catalogue(config: Config, channels) -> list[Piece]:
    """Every hypothesis, as ``--list-effects`` shows them."""
    return effect_pieces() + parameter_pieces(config) + sensor_pieces(channels)


Assignment = tuple  # ((Piece, value), ...) sorted by key: hashable


def assignment(values: dict) -> Assignment:
    return tuple(sorted(values.items(), key=lambda kv: kv[0].key))


def model_side(values: dict) -> Assignment:
    """The part of an assignment a model run depends on (effects and parameters)."""
    return assignment({p: v for p, v in values.items() if p.kind != "sensor"})


def configure(config: Config, values: dict) -> Config:
    """``config`` with the hypotheses ``values`` ({Piece: value}) in it."""
    model, effects, faults = config.model, dict(config.effects), {}
    thermal, material, tie = {}, {}, {}
    for p, v in values.items():
        if p.kind == "effect":
            effects[p.name] = float(v)
        elif p.kind == "sensor":
            faults.setdefault(p.channel, {})[p.param] = float(v)
        else:
            d = PARAMETER_DEFS[p.name]
            if not d.material:
                thermal[d.field] = float(v)
                continue
            field, value = (("c", v / model.material.rho) if d.field == "rho_c" else (d.field, v))
            material[field] = float(value)
            if model.tie_material is not None:  # the tie bar's own material moves by the same factor
                tie[field] = getattr(model.tie_material, field) * float(value) / getattr(model.material, field)
    model = dataclasses.replace(
        model, thermal=dataclasses.replace(model.thermal, **thermal),
        material=dataclasses.replace(model.material, **material),
        tie_material=dataclasses.replace(model.tie_material, **tie) if tie else model.tie_material)
    return dataclasses.replace(config, model=model, effects=effects, sensors=compose(config.sensors, faults))
