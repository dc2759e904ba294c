"""``[sources.REGION]`` of a case file (REGION a region, or a boundary for a surface source): a heat
source given as a density, a power, or the loss of a machine element (``kind``: a bearing, a ball
screw's nut or bearing, a linear guide's carriage, a motor) driven by the schedule's columns; the
kinds, their keys and readers are :data:`gatetherm.solvers.elements.KINDS` (one module each, read
here); a source may move (``position``: :mod:`gatetherm.solvers.moving`).

An element's loss becomes an ordinary power in W (an expression of the run's inputs), spread
evenly over the region, and is reported over time as the output column ``P_REGION_W``.
"""
from __future__ import annotations

import logging
import math
from typing import Callable

import numpy as np

from gatetherm.checks import Range
from gatetherm.solvers import elements
from gatetherm.solvers.expr import Value
from gatetherm.solvers.problem import Source
from gatetherm.studies.run.tables import MeshNames, Table

log = logging.getLogger(__name__)

def __getattr__(name: str):
    """``ELEMENT_KEYS`` (the keys of each element ``kind``), ``KEYS`` (of ``[sources.REGION]``, as
    :data:`gatetherm.studies.run.case.KEYS`) and ``SIZES``, from the kinds registered when asked."""
    kinds = elements.KINDS.values()
    if name == "ELEMENT_KEYS":
        return {k.name: k.keys for k in kinds}
    if name == "KEYS":
        return {"sources.REGION": ("density", "power", "kind", "factor",
                                   *dict.fromkeys(key for k in kinds for key in k.keys), *MOVING)}
    if name == "SIZES":  # lengths of an element (m) that cannot exceed the body they sit in: larger is mm
        return (*dict.fromkeys(key for k in kinds for key in k.lengths), "length")
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


MOVING = ("position", "direction", "length")
"""The keys of a source that moves (with power or kind)."""
POSITIVE_M = elements.POSITIVE_M
FACTOR = elements.FACTOR
LOSS = Range(0.0, unit="W")
"""An element's loss: never negative (an efficiency above 1 is refused where it is evaluated)."""


def _text(t: Table, k: str, names, default=None, unit: str = "", rng: Range | None = None) -> str:
    v = t.value(k, names, default, unit, rng)
    if k in ("speed", "load") and v.is_constant and float(v.constant) < 0:  # a signed column is read as |x|
        t.said.warn(log, "%s = %g %s: its sign is ignored (a loss depends on the magnitude); give %g", t.key(k),
                    float(v.constant), unit, -float(v.constant))
    return v.text or repr(v.constant)


def element_loss(t: Table, names) -> Value:
    """The loss of the element of ``[sources.REGION]`` table ``t`` (with ``kind``), W."""
    kinds = elements.KINDS
    kind = t.string("kind", choices=tuple(kinds))
    for k in ("density", "power"):
        if k in t.data:
            t.fail(k, f"goes without kind (the {kind}'s loss is the power)", "remove it or kind")
    keys = kinds[kind].keys
    other = next((k for k in t.data if k not in ("kind", "factor") and k not in keys + MOVING), None)
    if other:
        t.fail(other, f"is not a key of kind = \"{kind}\"", f"its keys: {', '.join(keys)}")

    def text(key: str, unit: str = "", default=None, rng: Range | None = None) -> str:
        return _text(t, key, names, default, unit, rng)

    text, factor = kinds[kind].read(t, text), t.number("factor", FACTOR, 1.0)
    return Value.of(text if factor == 1.0 else f"{factor!r}*({text})", t.key("kind"), LOSS)


def where(fm) -> MeshNames:
    """What ``[sources.NAME]`` may name: a region, or a boundary (a surface source)."""
    return MeshNames((*fm.regions, *(b for b in fm.boundaries if b not in fm.regions)), "region or boundary",
                     "regions and boundaries")


def warn_sizes(src: Table, extent: float) -> None:
    """Warn of an element length of ``[sources]`` larger than the body's largest extent (m): the
    value was most likely meant in mm."""
    sizes = __getattr__("SIZES")
    for r, data in src.data.items():
        for k in sizes:
            v = data.get(k) if isinstance(data, dict) else None
            if isinstance(v, (int, float)) and not isinstance(v, bool) and v > extent > 0:
                src.said.warn(log, "%s: %g m is larger than the whole body (%.3g m); lengths are in m (%g mm = %g m)",
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
        kind = elements.KINDS.get(t.data["kind"]) if isinstance(t.data["kind"], str) else None
        parts = tuple(t.value(k, names, unit=unit, rng=rng) for k, unit, rng in (kind.parts if kind else ())
                      if isinstance(t.data.get(k), str))
        return Source(region, element_loss(t, names), 1.0 if on_boundary else 1.0 / volume(), loss=f"P_{region}_W",
                      parts=parts, **band)
    extra = next((k for k in t.data if k not in ("density", "power", *MOVING)), None)
    if extra:
        t.fail(extra, "goes with kind only", f"give kind ({', '.join(elements.KINDS)}) or remove it")
    if ("density" in t.data) == ("power" in t.data):
        t.fail("density", "give either density (W/m³), power (W) or kind (a machine element)")
    if "density" in t.data:
        return Source(region, t.value("density", names, unit="W/m³"))
    return Source(region, t.value("power", names, unit="W"), 1.0 if on_boundary else 1.0 / volume(), **band)


def warn_bands(top: Table, fm, problem, ts, time) -> None:
    """Warn of a source that moves whose band's centre leaves its region along its direction at a sample
    of the case's own run (``ts``: its schedule, or None; ``time``: its [time]): more than half the band
    is off, and its power is spread over the part inside, denser than the band says. A band wholly off
    is refused when the run reaches it (:class:`gatetherm.solvers.moving.MovingLoad`)."""
    if time is None:
        return
    if ts is None:
        t, env = np.arange(0.0, time.end + time.step, time.step), {}
    else:
        t, env = np.asarray(ts.time_s - ts.time_s[0], float), {k: ts[k] for k in ts.names if k != "time_s"}
    env["t"] = t
    for s in (s for s in problem.sources if s.position is not None):
        on = np.asarray(fm.boundaries[s.region]) if s.on_boundary else fm.cells[np.asarray(fm.regions[s.region], int)]
        along = fm.points[np.unique(on)] @ np.asarray(s.direction, float)
        lo, hi = float(along.min()), float(along.max())
        names = s.position.names() | {"t"}
        rows = (t <= time.end) & np.logical_and.reduce([np.isfinite(env[n]) for n in names])
        p = np.broadcast_to(np.asarray(s.position({n: env[n][rows] for n in names}), float), (int(rows.sum()),))
        off = (p < lo) | (p > hi)
        if off.any():
            k = int(np.argmax(off))
            top.said.warn(log, "%s: the band's centre leaves its region (%g to %g m along its direction) from "
                          "t = %g s (position %g m): more than half its %g m is off, its power spread over the part "
                          "inside; keep the position within %g to %g m", s.position.key, lo, hi, t[rows][k], p[k],
                          s.length, lo, hi)
