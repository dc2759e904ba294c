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

from geometry.errors import InputError
from geometry.frame import part_boxes
from solvers.heat import Drive, Inputs
from solvers.model import ModelConfig


@dataclass(frozen=True)
class Effect:
    """A catalogue entry: one parameter, its unit and plausible range."""

    name: str
    param: str
    unit: str
    lo: float
    hi: float
    acts_on: str
    """"model", "drive" or "observation"."""
    doc: str


CATALOGUE: dict[str, Effect] = {e.name: e for e in (
    Effect("ambient_drift", "rate", "K/h", -1.0, 1.0, "drive",
           "the room temperature drifts linearly from its initial value"),
    Effect("joint_resistance", "conductance", "W/(m2 K)", 200.0, 5000.0, "model",
           "thermal contact conductance at both tie-bar/column joints"),
    Effect("compliant_base", "stiffness", "N/m3", 2e9, 5e10, "model",
           "the mounting face sits on an elastic foundation instead of a rigid clamp"),
    Effect("base_conduction", "h", "W/(m2 K)", 50.0, 1000.0, "model",
           "heat flows from the mounting face into a foundation at room temperature"),
    Effect("expansion_slope", "slope", "1/K", 5e-3, 3e-2, "model",
           "the expansion coefficient grows with temperature, alpha(T) = alpha (1 + s (T - T0))"),
    Effect("piezo_heat", "power", "W", 0.5, 5.0, "model",
           "the piezo stack and its spring member heat the workpiece-side arm"),
    Effect("thermocouple_lag", "tau", "s", 30.0, 300.0, "observation",
           "thermocouples read a first-order lagged surface temperature"),
    Effect("stand_drift", "coefficient", "um/K", 0.5, 5.0, "observation",
           "the displacement-sensor stand on the base expands with the mounting-face temperature"),
)}


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
        return name, float(value)
    except ValueError:
        raise InputError("--effect", f"'{text}' has no numeric value",
                         f"write {name}:{e.param}=VALUE in {e.unit}") from None


def parse_effect_options(items) -> ActiveEffects:
    return ActiveEffects(dict(parse_effect(s) for s in items))


def _piezo_source(cfg: ModelConfig, power: float, dim: int) -> dict[str, float]:
    """W/m³ in the workpiece-side arm for a total power (W)."""
    x0, x1, y0, y1, z0, z1 = part_boxes(cfg.frame, dim)["arm_R"]
    vol = (x1 - x0) * (y1 - y0) * (z1 - z0)
    return {"arm_R": power / vol}


def apply_effects(cfg: ModelConfig, drive: Drive, eff: ActiveEffects,
                  dim: int) -> tuple[ModelConfig, Drive]:
    """The model configuration and drive with the model- and drive-side effects on."""
    v = eff.values
    changes: dict = {}
    if "joint_resistance" in v:
        changes["joint_conductance"] = v["joint_resistance"]
    if "compliant_base" in v:
        changes["k_base"] = v["compliant_base"]
    if "base_conduction" in v:
        changes["thermal"] = dataclasses.replace(cfg.thermal, h_base=v["base_conduction"])
    if "expansion_slope" in v:
        changes["alpha_slope"] = v["expansion_slope"]
    if "piezo_heat" in v:
        changes["source"] = {**cfg.source, **_piezo_source(cfg, v["piezo_heat"], dim)}
    if "ambient_drift" in v:
        rate = v["ambient_drift"] / 3600.0
        base = drive

        def drive(t: float) -> Inputs:
            u = base(t)
            return u._replace(T_amb=u.T_amb + rate * t)

    return (dataclasses.replace(cfg, **changes) if changes else cfg), drive
