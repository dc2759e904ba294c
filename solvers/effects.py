"""Physical effects the baseline paper model leaves out, as switchable components.

Each effect has named parameters with units and a plausible range, and acts
on the model in one of three places: the model configuration (material,
boundary and joint physics), the drive (what the room does), or the
observation (what the sensors do to the true signal). With no effect switched
on, a model is the paper's baseline.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from gatetherm import InputError
from gatetherm.solvers.frame import AMBIENT, ModelConfig
from gatetherm.solvers.heat import Drive


@dataclass(frozen=True)
class Effect:
    """A catalogue entry: one parameter, its unit and plausible range.

    The ranges are chosen so that, on the paper's conditions 1–3 with the
    default model, the effect changes δ by more than 0.4 µm RMS over the last
    two hours of a run or a thermocouple by more than 0.3 K at its peak, at
    both ends of the range (for ``ambient_drift``, whose range spans zero, for
    |rate| ≥ 0.2 K/h); ``tests/test_effects.py`` checks this.
    """

    name: str
    param: str
    unit: str
    lo: float
    hi: float
    acts_on: str
    """"model", "drive" or "observation"."""
    doc: str

    @property
    def log_scale(self) -> bool:
        """Strictly positive parameters are searched and drawn on a log scale."""
        return self.lo > 0

    def describe(self) -> dict:
        """The ``--list-effects --json`` entry."""
        return {"name": self.name, "params": {self.param: {"unit": self.unit, "range": [self.lo, self.hi]}},
                "acts_on": self.acts_on, "doc": self.doc}


CATALOGUE: dict[str, Effect] = {e.name: e for e in (
    Effect("ambient_drift", "rate", "K/h", -1.0, 1.0, "drive",
           "the room temperature drifts linearly from its initial value (heating, sun, "
           "neighbouring machines); no effect when the file records the room temperature"),
    Effect("joint_resistance", "conductance", "W/(m2 K)", 150.0, 2000.0, "model",
           "thermal contact conductance of both tie-bar/column joints (bolted, painted or "
           "lightly loaded faces) in series with the 5 mm end layers"),
    Effect("joint_compliance", "stiffness", "N/m3", 1e10, 3e12, "model",
           "normal contact stiffness per unit area of both tie-bar/column joints (bolted "
           "interface compliance) in series with the end layers, so the tie bar restrains less"),
    Effect("compliant_base", "stiffness", "N/m3", 1e9, 1e12, "model",
           "the mounting face sits on an elastic foundation (levelling blocks, bolted bed) "
           "instead of a rigid clamp, so the column feet can expand and tilt"),
    Effect("base_conduction", "h", "W/(m2 K)", 50.0, 1000.0, "model",
           "heat flows from the mounting face into a foundation held at room temperature"),
    Effect("piezo_heat", "power", "W", 0.5, 5.0, "model",
           "heat released in the workpiece-side arm by the piezo stack, its spring member and "
           "drive, constant from the start of the run"),
    Effect("thermocouple_lag", "tau", "s", 15.0, 180.0, "observation",
           "thermocouples read a first-order lagged surface temperature (bonding, cement, "
           "contact pad)"),
    Effect("stand_drift", "coefficient", "um/K", 0.2, 3.0, "observation",
           "the displacement-sensor stand on the base expands with the mounting-face "
           "temperature rise and adds to the measured delta"),
)}


def catalogue_json() -> list[dict]:
    """The catalogue as ``gatetherm diagnose --list-effects --json`` prints it."""
    return [e.describe() for e in CATALOGUE.values()]


@dataclass(frozen=True)
class ActiveEffects:
    """Effects switched on, with parameter values (in the catalogue's units)."""

    values: dict[str, float] = dataclasses.field(default_factory=dict)

    def describe(self) -> dict[str, float]:
        return dict(self.values)

    def observe(self, cols: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
        """Apply the sensor-side effects to run columns; returns new columns."""
        out = dict(cols)
        t = cols["time_s"]
        if "thermocouple_lag" in self.values:
            tau = self.values["thermocouple_lag"]
            for k in out:
                if k.endswith("_degC") and (k.startswith("theta_") or k.startswith("T_")) \
                        and not k.startswith("T_tank"):
                    out[k] = first_order_lag(t, cols[k], tau)
        if "stand_drift" in self.values and "T_base_degC" in cols:
            base = cols["T_base_degC"]
            out["delta_um"] = cols["delta_um"] + self.values["stand_drift"] * (base - base[0])
        return out


def first_order_lag(t: np.ndarray, x: np.ndarray, tau: float) -> np.ndarray:
    """Exact response of τ y' + y = x for ``x`` linear between samples, y(0) = x(0)."""
    y = np.empty_like(x, dtype=float)
    y[0] = x[0]
    for i in range(1, len(t)):
        dt = t[i] - t[i - 1]
        a = np.exp(-dt / tau)
        slope = (x[i] - x[i - 1]) / dt
        y[i] = x[i] - slope * tau + a * (y[i - 1] - x[i - 1] + slope * tau)
    return y


def parse_effect(text: str) -> tuple[str, float]:
    """``NAME:PARAM=VALUE`` (or ``NAME=VALUE``) → (name, value), checked against the catalogue."""
    head, _, value = text.partition("=")
    name, _, param = head.partition(":")
    if name not in CATALOGUE:
        raise InputError("--effect", f"unknown effect '{name}'",
                         f"choose one of {', '.join(CATALOGUE)}")
    e = CATALOGUE[name]
    if param and param != e.param:
        raise InputError("--effect", f"effect '{name}' has no parameter '{param}'", f"use {name}:{e.param}=VALUE")
    try:
        number = float(value)
    except ValueError:
        raise InputError("--effect", f"'{text}' has no numeric value",
                         f"write {name}:{e.param}=VALUE in {e.unit}") from None
    return name, _checked(e, number, "--effect")


def _checked(e: Effect, value: float, where: str) -> float:
    """``value`` if it is a finite number the effect's physics accepts (positive for
    positive ranges), else InputError."""
    if not np.isfinite(value) or (e.log_scale and value <= 0):
        raise InputError(where, f"{e.name}.{e.param} = {value:g} is not physical",
                         f"give a {'positive' if e.log_scale else 'finite'} value in {e.unit} "
                         f"(plausible: {e.lo:g} … {e.hi:g})")
    return value


def parse_effect_options(items) -> ActiveEffects:
    return ActiveEffects(dict(parse_effect(s) for s in items))


def effects_from_table(table: dict, section: str = "effects") -> dict[str, float]:
    """A model file's ``[effects]`` table, ``NAME = {PARAM = VALUE}``, as {name: value}."""
    out = {}
    for name, params in table.items():
        where = f"{section}.{name}"
        if name not in CATALOGUE:
            raise InputError(where, "unknown effect", f"choose one of {', '.join(CATALOGUE)}")
        e = CATALOGUE[name]
        if not isinstance(params, dict) or set(params) != {e.param}:
            raise InputError(where, f"expected one parameter '{e.param}'", f"write {name} = {{ {e.param} = VALUE }}")
        value = params[e.param]
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise InputError(f"{where}.{e.param}", f"expected a number in {e.unit}, got {value!r}")
        out[name] = _checked(e, float(value), f"{where}.{e.param}")
    return out


def effects_table(values: dict[str, float]) -> dict[str, dict[str, float]]:
    """{name: value} as the ``[effects]`` table of a model file."""
    return {name: {CATALOGUE[name].param: float(v)} for name, v in values.items()}


def apply_effects(cfg: ModelConfig, drive: Drive, eff: ActiveEffects) -> tuple[ModelConfig, Drive]:
    """The model configuration and drive with the model- and drive-side effects on."""
    v = eff.values
    changes: dict = {}
    if "joint_resistance" in v:
        changes["joint_conductance"] = v["joint_resistance"]
    if "joint_compliance" in v:
        changes["joint_stiffness"] = v["joint_compliance"]
    if "compliant_base" in v:
        changes["k_base"] = v["compliant_base"]
    if "base_conduction" in v:
        changes["thermal"] = dataclasses.replace(cfg.thermal, h_base=v["base_conduction"])
    if "piezo_heat" in v:
        changes["power"] = {**cfg.power, "arm_R": v["piezo_heat"]}
    return (dataclasses.replace(cfg, **changes) if changes else cfg), drive_effects(drive, eff)


def drive_effects(drive: Drive, eff: ActiveEffects) -> Drive:
    """The drive with the drive-side effects on (the room drifting from its initial value)."""
    if "ambient_drift" not in eff.values:
        return drive
    rate, base = eff.values["ambient_drift"] / 3600.0, drive

    def drifting(t: float) -> dict[str, float]:
        u = base(t)
        return {**u, AMBIENT: u[AMBIENT] + rate * t}

    return drifting
