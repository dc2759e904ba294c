"""The catalogue of effects (:data:`KINDS`), the targets a case names for them (:class:`Targets`),
and their keys and values: a key resolved to its kind and target (:func:`resolve`), a value checked
against the kind (:func:`checked`), the ``--effect`` option (:func:`parse_effect`) and a file's
``[effects]`` table (:func:`effects_from_table`). What the effects do to a problem or a run is
:mod:`gatetherm.solvers.effects` (whose docstring tells how a key is written).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Mapping

import numpy as np

from gatetherm import InputError
from gatetherm.solvers.material import Material


@dataclass(frozen=True)
class Effect:
    """A kind of effect: one parameter, its unit and plausible range, and what it acts on.

    The ranges are chosen so that, on the paper's conditions 1–3 with the default model,
    the effect changes δ by more than 0.4 µm RMS over the last two hours of a run or a
    thermocouple by more than 0.3 K at its peak, at both ends of the range (for
    ``ambient_drift``, whose range spans zero, for |rate| ≥ 0.2 K/h);
    ``tests/test_effects.py`` checks this.
    """

    name: str
    param: str
    unit: str
    lo: float
    hi: float
    acts_on: str
    """"model" (a new run) or "observation" (on a run's columns)."""
    target: str
    """What it names: "joint", "support", "boundary", "region", "room", "sensors" or "stand"."""
    doc: str
    linear: bool = False
    """The run is linear in the value (a source's power): it is searched on a linear scale, where a
    secant step is exact."""

    @property
    def log_scale(self) -> bool:
        """Strictly positive parameters are searched and drawn on a log scale, unless linear."""
        return self.lo > 0 and not self.linear


KINDS: dict[str, Effect] = {e.name: e for e in (
    Effect("ambient_drift", "rate", "K/h", -1.0, 1.0, "model", "room",
           "the room temperature drifts linearly from its initial value (heating, sun, "
           "neighbouring machines): every film's ambient; where the file records the room, added to it (the room "
           "the machine sees drifts away from the thermometer's)"),
    Effect("joint_resistance", "conductance", "W/(m2 K)", 150.0, 2000.0, "model", "joint",
           "thermal contact conductance of a joint (bolted, painted or lightly loaded faces) in series "
           "with its layers"),
    Effect("joint_compliance", "stiffness", "N/m3", 1e10, 3e12, "model", "joint",
           "normal contact stiffness per unit area of a joint (bolted interface compliance) in series "
           "with its layers, so the joint restrains less"),
    Effect("compliant_base", "stiffness", "N/m3", 1e9, 1e12, "model", "support",
           "a support sits on an elastic foundation (levelling blocks, bolted bed) instead of a rigid "
           "clamp, so the feet can expand and tilt"),
    Effect("base_conduction", "h", "W/(m2 K)", 50.0, 1000.0, "model", "boundary",
           "heat flows from a boundary into a foundation held at room temperature"),
    Effect("heat_source", "power", "W", 0.5, 200.0, "model", "region",
           "heat released uniformly in a region the model does not heat, constant from the start of the run",
           linear=True),
    Effect("thermocouple_lag", "tau", "s", 15.0, 180.0, "observation", "sensors",
           "thermocouples read a first-order lagged surface temperature (bonding, cement, contact pad)"),
    Effect("stand_drift", "coefficient", "um/K", 0.2, 3.0, "observation", "stand",
           "the displacement-sensor stand on the base expands with the base's mean temperature rise "
           "and adds to the measured delta"),
)}


@dataclass(frozen=True)
class JointLayer:
    """A thin region through which a joint carries heat and load."""

    region: str
    thickness: float
    """Thickness of the layer normal to the joint, m."""
    bulk: Material
    """The layer's material without the joint (a joint's resistance and compliance act in series with it)."""


@dataclass(frozen=True)
class Named:
    """A named effect a case declares: a kind on a target, with its own range and doc."""

    kind: str
    target: str | None
    doc: str
    lo: float | None = None
    """Plausible range of its parameter (None: the kind's)."""
    hi: float | None = None
    log_scale: bool | None = None
    """Search it on a log scale (None: as the kind)."""


@dataclass(frozen=True)
class Targets:
    """The names a case's effects act on."""

    joints: Mapping[str, tuple[JointLayer, ...]] = field(default_factory=dict)
    """Joints by name: the layer regions whose material a joint effect changes."""
    interfaces: tuple[str, ...] = ()
    """Boundaries ``A/B`` between two regions: a joint effect there is a contact of the problem
    (its own ``[contacts]`` entry changed, or a new one on a bonded interface)."""
    defaults: Mapping[str, str] = field(default_factory=dict)
    """Kind → the target meant when a key names the kind alone."""
    named: Mapping[str, Named] = field(default_factory=dict)
    """Effects the case declares under a name of their own."""
    candidates: tuple[str, ...] | None = None
    """The effect keys a diagnosis tries (None: every kind on every target that applies)."""
    base_mean: str = "base"
    """The boundary mean whose rise a stand drift follows."""


@dataclass(frozen=True)
class Resolved:
    """An effect key resolved against a case: its kind, target and range."""

    key: str
    effect: Effect
    target: str | None
    lo: float
    hi: float
    doc: str
    log_scale: bool

    @property
    def unit(self) -> str:
        return self.effect.unit


def resolve(key: str, targets: Targets = Targets(), where: str = "--effect") -> Resolved:
    """The kind and target of an effect key (``KIND@TARGET``, ``KIND`` or a declared name)."""
    if key in targets.named:
        n = targets.named[key]
        e = KINDS[n.kind]
        lo, hi = e.lo if n.lo is None else n.lo, e.hi if n.hi is None else n.hi
        return Resolved(key, e, n.target, lo, hi, n.doc, (lo > 0 and not e.linear) if n.log_scale is None
                        else n.log_scale)
    kind, _, target = key.partition("@")
    if kind not in KINDS:
        known = [*KINDS, *targets.named]
        raise InputError(where, f"unknown effect '{kind}'", f"choose one of {', '.join(known)}")
    e = KINDS[kind]
    if not target:
        target = targets.defaults.get(kind)
        if target is None and e.target in ("joint", "support", "boundary", "region"):
            raise InputError(where, f"effect '{kind}' acts on a {e.target}: name it",
                             f"write {kind}@NAME (the {e.target} of the case)")
    return Resolved(key, e, target or None, e.lo, e.hi, e.doc, e.log_scale)


def catalogue_json(targets: Targets = Targets(), keys=None) -> list[dict]:
    """Effects as ``gatetherm diagnose --list-effects --json`` prints them."""
    keys = list(targets.named) if keys is None else keys
    out = []
    for k in keys:
        r = resolve(k, targets)
        out.append({"name": k, "params": {r.effect.param: {"unit": r.unit, "range": [r.lo, r.hi]}},
                    "acts_on": r.effect.acts_on, "target": r.target, "doc": r.doc})
    return out

BEYOND = 1e3
"""A value more than this many times the largest end of its plausible range is refused: no
effect's physics reaches it (a factor of 1e300 overflowed the temperatures it then named)."""


def checked(r: Resolved, value, where: str) -> float:
    """``value`` if it is a finite number the effect's physics accepts (positive for positive
    ranges, within :data:`BEYOND` times the plausible range), else InputError."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise InputError(where, f"expected a number in {r.unit}, got {value!r}")
    positive = r.lo > 0
    if not np.isfinite(value) or (positive and value <= 0) or abs(value) > BEYOND * max(abs(r.lo), abs(r.hi)):
        raise InputError(where, f"{r.key}.{r.effect.param} = {value:g} is not physical",
                         f"give a {'positive' if positive else 'finite'} value in {r.unit}, at most "
                         f"{BEYOND:g} × the plausible {r.lo:g} … {r.hi:g} in size")
    return float(value)


def parse_effect(text: str, targets: Targets = Targets()) -> tuple[str, float]:
    """``KEY:PARAM=VALUE`` (or ``KEY=VALUE``) → (key, value), checked against the kinds."""
    head, _, value = text.partition("=")
    key, _, param = head.partition(":")
    r = resolve(key, targets)
    if param and param != r.effect.param:
        raise InputError("--effect", f"effect '{key}' has no parameter '{param}'", f"use {key}:{r.effect.param}=VALUE")
    try:
        number = float(value)
    except ValueError:
        raise InputError("--effect", f"'{text}' has no numeric value",
                         f"write {key}:{r.effect.param}=VALUE in {r.unit}") from None
    return key, checked(r, number, "--effect")


def effects_from_table(table: dict, targets: Targets = Targets(), section: str = "effects") -> dict[str, float]:
    """An ``[effects]`` table, ``KEY = {PARAM = VALUE}``, as {key: value}."""
    out = {}
    for key, params in table.items():
        where = f"{section}.{key}"
        r = resolve(key, targets, where)
        if not isinstance(params, dict) or set(params) != {r.effect.param}:
            raise InputError(where, f"expected one parameter '{r.effect.param}'",
                             f"write {key} = {{ {r.effect.param} = VALUE }}")
        out[key] = checked(r, params[r.effect.param], f"{where}.{r.effect.param}")
    return out


def effects_table(values: dict[str, float], targets: Targets = Targets()) -> dict[str, dict[str, float]]:
    """{key: value} as the ``[effects]`` table of a model file."""
    return {k: {resolve(k, targets).effect.param: float(v)} for k, v in values.items()}
