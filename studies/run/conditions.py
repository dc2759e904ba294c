"""An oil supply unit's schedules, and schedules from files.

A condition is data: the supply unit's initial oil temperature and a list of
segments, each with a start time, the pump state and the controller set point.
The supply oil approaches the set point with a first-order lag (its heater or
forced cooling), which is what makes the paper's condition 2 start from 20 °C oil.
The tank itself (oil mass, wall film) is part of the FE model. The paper's
experiments are conditions of this kind: :mod:`gatetherm.frame.conditions`.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from gatetherm import InputError
from gatetherm.checks import CELSIUS, POSITIVE, admissible
from gatetherm.solvers.heat import Drive
from gatetherm.studies.run.timeseries import AMBIENT, PUMP, SUPPLY

HOUR = 3600.0


@admissible(T_room=CELSIUS, tau_heat=POSITIVE, tau_cool=POSITIVE)
@dataclass(frozen=True)
class SupplyParams:
    """The oil temperature controller feeding the tank."""

    T_room: float = 20.0
    """Room temperature, also the oil temperature before heating, °C."""
    tau_heat: float = 650.0
    """Time constant of the supply oil approaching a higher set point (heater), s."""
    tau_cool: float = 600.0
    """Time constant of the supply oil approaching a lower set point (forced cooling), s."""


@dataclass(frozen=True)
class Segment:
    """From ``start`` on: pump state and set point."""

    start: float
    """Start time, s."""
    pump: bool
    """Oil circulation through the tank on."""
    set_point: float
    """Controller set point, °C."""


@dataclass(frozen=True)
class Condition:
    """An experiment schedule."""

    name: str
    segments: tuple[Segment, ...]
    T_supply0: float | None
    """Supply oil temperature at t = 0, °C (None: the room temperature)."""
    duration: float = 5 * HOUR
    """Length of the run, s."""


def supply_temperature(cond: Condition, sp: SupplyParams, t: np.ndarray) -> np.ndarray:
    """Supply oil temperature (°C) at times ``t`` (s): exact first-order response
    to the piecewise-constant set point."""
    t = np.atleast_1d(np.asarray(t, dtype=float))
    out = np.empty_like(t)
    for start, end, set_point, T, tau in _responses(cond, sp):
        on = (t >= start) & (t < end)
        out[on] = _approach(set_point, T, t[on] - start, tau, np.exp)
    return out


def _approach(set_point: float, T: float, elapsed, tau: float, exp=math.exp):
    """The first-order response: ``T`` (°C) approaching ``set_point`` after ``elapsed`` s with
    time constant ``tau`` s (``exp``: ``np.exp`` for arrays)."""
    return set_point + (T - set_point) * exp(-elapsed / tau)


def _responses(cond: Condition, sp: SupplyParams) -> list[tuple[float, float, float, float, float]]:
    """(start, end, set point, temperature at the start, time constant) of each segment."""
    out, T = [], sp.T_room if cond.T_supply0 is None else cond.T_supply0
    ends = [s.start for s in cond.segments[1:]] + [math.inf]
    for seg, end in zip(cond.segments, ends):
        tau = sp.tau_heat if seg.set_point >= T else sp.tau_cool
        out.append((seg.start, end, seg.set_point, T, tau))
        if math.isfinite(end):
            T = _approach(seg.set_point, T, end - seg.start, tau)
    return out


def pump_state(cond: Condition, t: float) -> bool:
    return next(s.pump for s in reversed(cond.segments) if t >= s.start)


def condition_drive(cond: Condition, sp: SupplyParams) -> Drive:
    """The model input for a paper condition."""

    responses = _responses(cond, sp)

    def drive(t: float) -> dict[str, float]:  # a scalar: each step asks for one time
        supply = next((_approach(set_point, T, t - start, tau) for start, end, set_point, T, tau in responses
                       if start <= t < end), math.nan)
        return {SUPPLY: supply, PUMP: float(pump_state(cond, t)), AMBIENT: sp.T_room}

    return drive


@dataclass(frozen=True)
class TableDrive:
    """Inputs from a recorded schedule: every column interpolated linearly, except the
    ``held`` ones (pump states), which keep their last sample."""

    time: np.ndarray
    columns: dict[str, np.ndarray]
    """Gap-free values by input name."""
    held: frozenset[str] = frozenset({PUMP})

    def __call__(self, t: float) -> dict[str, float]:
        i = max(int(np.searchsorted(self.time, t, side="right")) - 1, 0)
        return {k: float(v[i] > 0.5) if k in self.held else float(np.interp(t, self.time, v))
                for k, v in self.columns.items()}


def filled(name: str, time: np.ndarray, v, hold: bool = False) -> np.ndarray:
    """``v`` with its missing samples filled: linearly, or with the last known value (the
    first known one before it) for a ``hold`` column."""
    v = np.asarray(v, dtype=float)
    ok = np.isfinite(v)
    if not ok.any():
        raise InputError(name, "has no values", "fill the column or leave it out")
    if hold:
        idx = np.maximum.accumulate(np.where(ok, np.arange(len(v)), 0))
        return np.where(ok[idx], v[idx], v[ok][0])
    return np.interp(time, time[ok], v[ok])


def table_drive(time, oil, pump, ambient=None, T_room: float = 20.0) -> TableDrive:
    """The frame's :class:`TableDrive` from a schedule's columns, missing samples filled
    channel by channel; without an ambient column the room stays at ``T_room`` (°C)."""
    time = np.asarray(time, dtype=float)
    amb = np.full_like(time, T_room) if ambient is None else filled(AMBIENT, time, ambient)
    return TableDrive(time, {SUPPLY: filled(SUPPLY, time, oil), PUMP: filled(PUMP, time, pump, hold=True),
                             AMBIENT: amb})
