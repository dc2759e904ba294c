"""``[sources.REGION]`` of a case file (REGION a region, or a boundary for a surface source): a heat
source given as a density, a power, or the loss of a machine element (``kind``: a bearing, a ball
screw's nut or bearing, a linear guide's carriage, a motor) driven by the schedule's columns
(:mod:`gatetherm.solvers.elements`); a source may move (``position``: :mod:`gatetherm.solvers.moving`).

An element's loss becomes an ordinary power in W (an expression of the run's inputs), spread
evenly over the region, and is reported over time as the output column ``P_REGION_W``.
"""
from __future__ import annotations

import logging
import math
from typing import Callable

from gatetherm.checks import Range
from gatetherm.solvers import elements
from gatetherm.solvers.expr import Value
from gatetherm.solvers.problem import Source
from gatetherm.studies.run.tables import Table

log = logging.getLogger(__name__)

ELEMENT_KEYS = {
    "bearing": ("type", "speed", "dm", "f0", "f1", "viscosity", "load"),
    "ball_screw_bearing": ("type", "speed", "dm", "f0", "f1", "viscosity", "load"),
    "ball_screw_nut": ("speed", "lead", "diameter", "preload", "load", "efficiency"),
    "guide": ("speed", "load", "friction", "seal"),
    "motor": ("speed", "torque", "efficiency", "idle"),
}
"""The keys of each element ``kind``."""
MOVING = ("position", "direction", "length")
"""The keys of a source that moves (with power or kind)."""
KEYS = {"sources.REGION": ("density", "power", "kind", "factor",
                           *dict.fromkeys(k for keys in ELEMENT_KEYS.values() for k in keys), *MOVING)}
"""The keys of ``[sources.REGION]`` (as :data:`gatetherm.studies.run.case.KEYS`)."""
POSITIVE_M = Range(0.0, lo_open=True, unit="m")
FACTOR = Range(0.0, unit="1")
VISCOSITY = Range(0.0, lo_open=True, unit="mm²/s")
"""A lubricant's kinematic viscosity (Palmgren's law reads only |ν n|: a negative one would pass unseen)."""
FRICTION = Range(0.0, 1.0, unit="1")
"""A guide's rolling friction coefficient (typically 0.002 to 0.005; above 1 is no rolling guide)."""
LOSS = Range(0.0, unit="W")
"""An element's loss: never negative (an efficiency above 1 is refused where it is evaluated)."""


def _text(t: Table, k: str, names, default=None, unit: str = "", rng: Range | None = None) -> str:
    v = t.value(k, names, default, unit, rng)
    if k in ("speed", "load") and v.is_constant and float(v.constant) < 0:  # a signed column is read as |x|
        log.warning("%s = %g %s: its sign is ignored (a loss depends on the magnitude); give %g", t.key(k),
                    float(v.constant), unit, -float(v.constant))
    return v.text or repr(v.constant)


def _bearing(t: Table, names) -> str:
    f0, f1 = elements.BEARING_TYPES[t.string("type", "angular_contact_oil", tuple(elements.BEARING_TYPES))]
    return elements.bearing_text(_text(t, "speed", names, unit="1/min"), _text(t, "viscosity", names, unit="mm²/s", rng=VISCOSITY),
                                 t.number("dm", POSITIVE_M), t.number("f0", FACTOR, f0), t.number("f1", FACTOR, f1),
                                 _text(t, "load", names, 0.0, "N"))


def _nut(t: Table, names) -> str:
    return elements.ball_screw_nut_text(
        _text(t, "speed", names, unit="1/min"), t.number("lead", POSITIVE_M), t.number("diameter", POSITIVE_M),
        t.number("preload", Range(0.0, unit="N"), 0.0), _text(t, "load", names, 0.0, "N"),
        t.number("efficiency", Range(0.0, 1.0, lo_open=True, unit="1"), 0.9))


def _guide(t: Table, names) -> str:
    return elements.guide_text(_text(t, "speed", names, unit="m/s"), _text(t, "load", names, 0.0, "N"),
                               t.number("friction", FRICTION, 0.003), t.number("seal", Range(0.0, unit="N"), 0.0))


def _motor(t: Table, names) -> str:
    return elements.motor_text(_text(t, "speed", names, unit="1/min"), _text(t, "torque", names, unit="N m"),
                               _text(t, "efficiency", names, unit="1"), t.number("idle", Range(0.0, unit="W"), 0.0))


READERS = {"bearing": _bearing, "ball_screw_bearing": _bearing, "ball_screw_nut": _nut, "guide": _guide,
           "motor": _motor}


def element_loss(t: Table, names) -> Value:
    """The loss of the element of ``[sources.REGION]`` table ``t`` (with ``kind``), W."""
    kind = t.string("kind", choices=tuple(ELEMENT_KEYS))
    for k in ("density", "power"):
        if k in t.data:
            t.fail(k, f"goes without kind (the {kind}'s loss is the power)", "remove it or kind")
    other = next((k for k in t.data if k not in ("kind", "factor") and k not in ELEMENT_KEYS[kind] + MOVING), None)
    if other:
        t.fail(other, f"is not a key of kind = \"{kind}\"", f"its keys: {', '.join(ELEMENT_KEYS[kind])}")
    if kind == "motor" and t.data.get("efficiency") is not None and not isinstance(t.data["efficiency"], str):
        Range(0.0, 1.0, lo_open=True, unit="1").check(t.key("efficiency"), t.data["efficiency"])
    text, factor = READERS[kind](t, names), t.number("factor", FACTOR, 1.0)
    return Value.of(text if factor == 1.0 else f"{factor!r}*({text})", t.key("kind"), LOSS)


SIZES = ("dm", "diameter", "lead", "length")
"""Lengths of an element (m) that cannot exceed the body they sit in: a larger one is a unit slip (mm)."""


def warn_sizes(src: Table, extent: float) -> None:
    """Warn of an element length of ``[sources]`` larger than the body's largest extent (m): the
    value was most likely meant in mm."""
    for r, data in src.data.items():
        for k in SIZES:
            v = data.get(k) if isinstance(data, dict) else None
            if isinstance(v, (int, float)) and not isinstance(v, bool) and v > extent > 0:
                log.warning("%s: %g m is larger than the whole body (%.3g m); lengths are in m (%g mm = %g m)",
                            src.sub(r).key(k), v, extent, v, v / 1000.0)


def moving(t: Table, names, dim: int) -> dict:
    """``position``, ``direction`` and ``length`` of a source that moves, as Source's fields ({}: none)."""
    given = [k for k in MOVING if k in t.data]
    if not given:
        return {}
    missing = next((k for k in MOVING if k not in t.data), None)
    if missing:
        t.fail(missing, f"missing: a source that moves needs {', '.join(MOVING)}",
               'e.g. position = "x_axis", direction = [1, 0], length = 0.05')
    if "density" in t.data:
        t.fail("density", "cannot move (a band takes a power)", "give power (W) or kind")
    d = t.data["direction"]
    if not (isinstance(d, list) and len(d) == dim and all(isinstance(x, (int, float)) and not isinstance(x, bool)
                                                          and math.isfinite(x) for x in d) and any(d)):
        t.fail("direction", f"expected {dim} numbers, not all zero, got {d!r}",
               f"e.g. direction = {[1] + [0] * (dim - 1)}")
    d = [float(x) for x in d]
    norm = sum(x * x for x in d) ** 0.5
    return {"position": t.value("position", names, unit="m"), "direction": tuple(x / norm for x in d),
            "length": t.number("length", POSITIVE_M)}


def read_source(t: Table, region: str, names, volume: Callable[[], float], dim: int = 3,
                on_boundary: bool = False) -> Source:
    """The source of the ``[sources.REGION]`` table ``t``; ``volume()`` the region's volume, m³;
    ``on_boundary``: REGION names a boundary (a surface source: power or kind only)."""
    band = moving(t, names, dim)
    if on_boundary and "density" in t.data:
        t.fail("density", "is a volume density: a boundary takes power (W) or kind",
               "give power, or a heat flux in [thermal.BOUNDARY] flux")
    if on_boundary:
        band["on_boundary"] = True
    if "kind" in t.data:
        parts = tuple(t.value(k, names, unit="mm²/s", rng=VISCOSITY) for k in ("viscosity",)
                      if isinstance(t.data.get(k), str))
        return Source(region, element_loss(t, names), 1.0 if on_boundary else 1.0 / volume(), loss=f"P_{region}_W",
                      parts=parts, **band)
    extra = next((k for k in t.data if k not in ("density", "power", *MOVING)), None)
    if extra:
        t.fail(extra, "goes with kind only", f"give kind ({', '.join(ELEMENT_KEYS)}) or remove it")
    if ("density" in t.data) == ("power" in t.data):
        t.fail("density", "give either density (W/m³), power (W) or kind (a machine element)")
    if "density" in t.data:
        return Source(region, t.value("density", names, unit="W/m³"))
    return Source(region, t.value("power", names, unit="W"), 1.0 if on_boundary else 1.0 / volume(), **band)
