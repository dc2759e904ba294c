"""An offset and a gradient along an axis, from a model's δ at two or more probe positions.

Controls take a thermal correction as Δs = offset + gradient·(s − s0) (SINUMERIK's temperature
compensation: value, slope and reference position; TwinCAT: offset(T) + coefficient(T)·(s − s0)).
Where a model gives δ at probes along an axis (a fitted error model with one target per probe,
:class:`Axis` naming each target's position), :class:`AxisStepper` steps one compensator per
probe and fits a straight line to their commands over the positions (least squares; exact for
two probes): its value at the reference position ``s0`` is the offset (µm), its slope the gradient
(µm per m of travel). Where no model gives δ at more than one position, nothing here runs and
``live`` writes the offset only.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from gatetherm import InputError
from gatetherm.studies.control.stepwise import Correction


@dataclass(frozen=True)
class Axis:
    """Where along the axis each probe's δ is."""

    positions_m: dict[str, float]
    """Target channel (e.g. ``delta_x0_um``) -> its position along the axis, m."""
    reference_m: float | None = None
    """Reference position s0 of the offset, m (None: the smallest probe position)."""

    def __post_init__(self):
        pos = self.positions_m
        if len(pos) < 2:
            raise InputError("--axis", f"{len(pos)} probe position(s) given", "give two or more, e.g. "
                             "--axis delta_x0_um=0 --axis delta_x1_um=0.8")
        if not all(isinstance(v, (int, float)) and math.isfinite(v) for v in pos.values()):
            raise InputError("--axis", "a position is not a finite number of m", "e.g. --axis delta_x0_um=0.25")
        if len(set(pos.values())) < 2:
            raise InputError("--axis", "the probes are all at one position", "give probes at two positions or more")
        if self.reference_m is not None and not math.isfinite(self.reference_m):
            raise InputError("--reference", "must be a finite position in m", "e.g. --reference 0")

    @property
    def s0(self) -> float:
        """The reference position, m."""
        return float(min(self.positions_m.values()) if self.reference_m is None else self.reference_m)


def line(positions_m, values_um, s0: float) -> tuple[float, float]:
    """Least-squares line through (position, value): its value at ``s0`` (µm) and slope (µm/m);
    NaN for both where a value is NaN."""
    v = np.asarray(values_um, float)
    if not np.isfinite(v).all():
        return math.nan, math.nan
    a = np.c_[np.ones(len(v)), np.asarray(positions_m, float) - s0]
    (offset, gradient), *_ = np.linalg.lstsq(a, v, rcond=None)
    return float(offset), float(gradient)


@dataclass(frozen=True)
class AxisCorrection(Correction):
    """A :class:`~gatetherm.studies.control.stepwise.Correction` at the reference position, with its gradient."""

    gradient_um_per_m: float = math.nan
    """Slope of the command along the axis, µm per m."""
    reference_m: float = math.nan
    """Reference position s0 of ``offset_um``, m."""


class AxisStepper:
    """One stepper per probe (target -> stepper), combined into an offset at s0 and a gradient."""

    method = "axis"

    def __init__(self, steppers: dict, axis: Axis):
        missing = [k for k in steppers if k not in axis.positions_m]
        if missing:
            raise InputError("--axis", f"no position for {', '.join(missing)}", "give --axis TARGET=S for each")
        self.steppers, self.axis = dict(steppers), axis
        self.positions = [axis.positions_m[k] for k in self.steppers]
        self.columns = tuple(dict.fromkeys(c for s in self.steppers.values() for c in s.columns))

    def _combine(self, corrs) -> AxisCorrection:
        s0 = self.axis.s0
        offset, gradient = line(self.positions, [c.offset_um for c in corrs], s0)
        predicted, _ = line(self.positions, [c.predicted_um for c in corrs], s0)
        return AxisCorrection(corrs[0].t_s, offset, predicted, any(c.updated for c in corrs), gradient, s0)

    def step(self, t: float, sample) -> AxisCorrection:
        """Step every probe's compensator on ``sample``."""
        return self._combine([s.step(t, sample) for s in self.steppers.values()])

    def skip(self, t: float) -> AxisCorrection:
        """No usable sample: every command holds."""
        return self._combine([s.skip(t) for s in self.steppers.values()])

    def state(self) -> dict:
        return {"method": self.method, "probes": {k: s.state() for k, s in self.steppers.items()}}

    def restore(self, state: dict) -> None:
        probes = state.get("probes", {})
        if state.get("method") != self.method or set(probes) != set(self.steppers):
            raise InputError("compensator state", "not the state of this axis' probes",
                             "resume with the same model and --axis, or start in a new output directory")
        for k, s in self.steppers.items():
            s.restore(probes[k])
