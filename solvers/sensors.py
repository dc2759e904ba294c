"""Sensor faults: what a miscalibrated or slow sensor does to the signal it reports.

A fault belongs to one recorded channel (``theta_B_degC``, ``delta_um`` …) and acts
on that column only, after the model run and after the catalogue's observation-side
effects: a first-order lag, then a gain on the change from the first sample, then an
offset, then (displacement only) a linear drift. Thermocouple channels (``*_degC``)
have ``offset``, ``gain``, ``lag``; displacement channels (``*_um``) ``offset``,
``gain``, ``drift``. A model file sets them in ``[sensors]`` as
``CHANNEL = {FAULT = VALUE, ...}``.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from gatetherm import InputError
from gatetherm.solvers.effects import first_order_lag


@dataclass(frozen=True)
class Fault:
    """One kind of sensor fault, its identity value and plausible range."""

    name: str
    unit: str
    lo: float
    hi: float
    identity: float
    """The value at which the fault does nothing."""
    linear: bool
    """The reported signal is linear in the value (fitted in closed form)."""
    doc: str

    @property
    def log_scale(self) -> bool:
        return self.lo > 0 and not self.linear


THERMOCOUPLE = {f.name: f for f in (
    Fault("offset", "K", -1.5, 1.5, 0.0, True, "constant error (cold-junction or calibration offset)"),
    Fault("gain", "1", 0.9, 1.1, 1.0, True, "wrong sensitivity: reports gain × the rise from the first sample"),
    Fault("lag", "s", 15.0, 300.0, 0.0, False, "first-order lag of this thermocouple (loose bonding, thick cement)"),
)}
DISPLACEMENT = {f.name: f for f in (
    Fault("offset", "um", -2.0, 2.0, 0.0, True, "constant error (zero not set at the start)"),
    Fault("gain", "1", 0.9, 1.1, 1.0, True, "wrong sensitivity of the differential transformer"),
    Fault("drift", "um/h", -1.0, 1.0, 0.0, True, "linear drift of the sensor electronics over the run"),
)}
ORDER = ("lag", "gain", "offset", "drift")
"""The order in which a channel's faults act."""


def faults_of(channel: str) -> dict[str, Fault]:
    """The faults a channel can have, by its unit suffix (empty for an unknown unit)."""
    if channel.endswith("_degC"):
        return THERMOCOUPLE
    if channel.endswith("_um"):
        return DISPLACEMENT
    return {}


LINEAR_IDENTITY = {"gain": 1.0, "offset": 0.0, "drift": 0.0}
"""The linear faults and the values at which they do nothing."""


def linear_basis(t: np.ndarray, x: np.ndarray, fault: str) -> np.ndarray:
    """The direction of a linear fault: it reports ``x + (value − identity) · basis``."""
    if fault == "gain":
        return x - x[0]
    if fault == "offset":
        return np.ones_like(x, dtype=float)
    if fault == "drift":
        return (t - t[0]) / 3600.0
    raise ValueError(f"unknown linear sensor fault {fault!r}")


def apply_fault(t: np.ndarray, x: np.ndarray, fault: str, value: float) -> np.ndarray:
    """``x`` (a channel sampled at ``t``, s) as a sensor with one fault reports it."""
    if fault == "lag":
        return first_order_lag(t, x, value) if value > 0 else x
    basis = linear_basis(t, x, fault)
    return x + (value - LINEAR_IDENTITY[fault]) * basis


def apply_faults(cols: dict[str, np.ndarray], faults: dict[str, dict[str, float]]) -> dict[str, np.ndarray]:
    """Columns as faulty sensors report them ({channel: {fault: value}}); channels the run
    does not have are left out."""
    if not faults:
        return cols
    out = dict(cols)
    t = cols["time_s"]
    for channel, fs in faults.items():
        if channel in out:
            for name in ORDER:
                if name in fs:
                    out[channel] = apply_fault(t, out[channel], name, fs[name])
    return out


def compose(first: dict, then: dict) -> dict:
    """Faults equal to ``first`` followed by ``then``: offsets and drifts add, gains
    multiply (a gain acts on the change from the first sample, so it commutes with an
    offset); two lags on one channel do not compose and are refused."""
    out = {ch: dict(fs) for ch, fs in first.items()}
    for ch, fs in then.items():
        mine = out.setdefault(ch, {})
        for name, v in fs.items():
            if name not in mine:
                mine[name] = v
            elif name == "gain":
                mine[name] *= v
            elif name in ("offset", "drift"):
                mine[name] += v
            else:
                raise ValueError(f"{ch}: two {name}s do not compose")
    return out


def faults_from_table(table: dict, section: str = "sensors") -> dict[str, dict[str, float]]:
    """A model file's ``[sensors]`` table, checked."""
    out = {}
    for channel, params in table.items():
        where = f"{section}.{channel}"
        known = faults_of(channel)
        if not known:
            raise InputError(where, "not a sensor channel", "name a column ending in _degC or _um, e.g. theta_B_degC")
        if not isinstance(params, dict) or not params:
            raise InputError(where, "expected a table of faults", f"write {channel} = {{ offset = VALUE }}")
        out[channel] = {}
        for name, value in params.items():
            if name not in known:
                raise InputError(f"{where}.{name}", "unknown fault", f"known: {', '.join(known)}")
            f = known[name]
            ok = isinstance(value, (int, float)) and not isinstance(value, bool) and np.isfinite(value)
            if not ok or (name in ("lag", "gain") and value <= 0):
                raise InputError(f"{where}.{name}", f"expected a {'positive ' if name in ('lag', 'gain') else ''}"
                                 f"number in {f.unit}, got {value!r}", f"plausible: {f.lo:g} … {f.hi:g}")
            out[channel][name] = float(value)
    return out


def faults_table_lines(faults: dict[str, dict[str, float]]) -> list[str]:
    """The ``[sensors]`` lines of a model file."""
    if not faults:
        return []
    return ["[sensors]"] + [f"{ch} = {{ " + ", ".join(f"{k} = {float(v)!r}" for k, v in fs.items()) + " }"
                            for ch, fs in faults.items() if fs]
