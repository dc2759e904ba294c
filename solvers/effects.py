"""Physical effects a model leaves out, as switchable edits of a problem through its names.

Each kind of effect (:data:`KINDS`) has one parameter with its unit and plausible range and
acts on a *target* of the problem, named as the mesh and the case name it: a joint (its
layer regions, or the interface of two regions), a support boundary, a boundary, a region,
the room (every film's ambient) or the sensors. Model-side effects edit the
:class:`~gatetherm.solvers.problem.Problem` (:func:`apply_effects`); observation-side ones
act on the run's columns (:meth:`ActiveEffects.observe`).

An effect is switched on by a key and a value: ``KIND@TARGET`` (``heat_source@arm_R``),
``KIND`` alone where the case names a default target (or the kind needs none), or a name the
case declares (:class:`Targets`: the paper frame's ``piezo_heat`` is ``heat_source@arm_R``).
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from typing import Mapping

import numpy as np

from gatetherm import InputError
from gatetherm.solvers.expr import Value
from gatetherm.solvers.material import Material
from gatetherm.solvers.problem import Contact, Film, Problem, Source


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
           "neighbouring machines): every film's ambient; no effect when the file records the room temperature"),
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


@dataclass(frozen=True)
class ActiveEffects:
    """Effects switched on: ``{key: value}`` (values in the kinds' units)."""

    values: dict[str, float] = field(default_factory=dict)
    targets: Targets = field(default=Targets(), compare=False)

    def describe(self) -> dict[str, float]:
        return dict(self.values)

    def resolved(self, acts_on: str | None = None) -> list[tuple[Resolved, float]]:
        out = [(resolve(k, self.targets), v) for k, v in self.values.items()]
        return [(r, v) for r, v in out if acts_on is None or r.effect.acts_on == acts_on]

    def observe(self, cols: dict[str, np.ndarray], problem: Problem | None = None) -> dict[str, np.ndarray]:
        """Apply the observation-side effects to run columns; returns new columns."""
        out = dict(cols)
        t = cols["time_s"]
        for r, v in self.resolved("observation"):
            if r.effect.name == "thermocouple_lag":
                for k in thermocouples(cols, problem):
                    out[k] = first_order_lag(t, cols[k], v)
            elif r.effect.name == "stand_drift":
                base = cols.get(f"T_{r.target or self.targets.base_mean}_degC")
                if base is not None and "delta_um" in cols:
                    out["delta_um"] = cols["delta_um"] + v * (base - base[0])
        return out


def thermocouples(cols, problem: Problem | None) -> list[str]:
    """The temperature channels a thermocouple reads: the signals θ, probes, boundary means and
    supply hoses; not a fluid volume itself nor the mean of a wall a fluid wets."""
    wet = set()
    if problem is not None:
        walls = {f.boundary for f in problem.fluids}
        wet = {f"T_{f.name}_degC" for f in problem.fluids} | {f"T_{n}_degC" for n, b in problem.means if b in walls}
    return [k for k in cols if k.endswith("_degC") and k.startswith(("theta_", "T_")) and k not in wet]


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


def checked(r: Resolved, value, where: str) -> float:
    """``value`` if it is a finite number the effect's physics accepts (positive for positive
    ranges), else InputError."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise InputError(where, f"expected a number in {r.unit}, got {value!r}")
    positive = r.lo > 0
    if not np.isfinite(value) or (positive and value <= 0):
        raise InputError(where, f"{r.key}.{r.effect.param} = {value:g} is not physical",
                         f"give a {'positive' if positive else 'finite'} value in {r.unit} "
                         f"(plausible: {r.lo:g} … {r.hi:g})")
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


def _layers(r: Resolved, targets: Targets) -> tuple[JointLayer, ...]:
    if r.target not in targets.joints:
        raise InputError(f"effect {r.key}", f"no joint '{r.target}'",
                         f"joints of this case: {', '.join(targets.joints) or 'none'}")
    return targets.joints[r.target]


def _series(L: float, bulk: float, joint: float) -> float:
    """The modulus of a layer of thickness ``L`` in series with a joint of ``joint`` per unit area."""
    return L / (L / bulk + 1.0 / joint)


def apply_effects(problem: Problem, eff: ActiveEffects, volume) -> Problem:
    """``problem`` with the model-side effects of ``eff`` in it; ``volume(region)`` gives a
    region's volume (m³; 2-D: area times its thickness) for a source's power."""
    p = problem
    for r, v in eff.resolved("model"):
        kind, target = r.effect.name, r.target
        if kind == "ambient_drift":
            p = _drifting(p, v)
        elif kind in ("joint_resistance", "joint_compliance") and target not in eff.targets.joints:
            p = _contact(p, r, eff.targets, kind, v)
        elif kind in ("joint_resistance", "joint_compliance"):
            mats = dict(p.materials)
            for layer in _layers(r, eff.targets):
                mats[layer.region] = _with_joint(mats[layer.region], layer, kind, v)
            p = dataclasses.replace(p, materials=mats)
        elif kind == "compliant_base":
            _named(r, [s.boundary for s in p.supports], "support")
            p = dataclasses.replace(p, supports=tuple(dataclasses.replace(s, stiffness=v) if s.boundary == target
                                                      else s for s in p.supports))
        elif kind == "base_conduction":
            films = [f for f in p.films if f.boundary != target]
            p = dataclasses.replace(p, films=(*films, Film(target, v, room(p))))
        elif kind == "heat_source":
            _named(r, p.materials, "region")
            p = dataclasses.replace(p, sources=(*p.sources, Source(target, Value(v / volume(target)))))
    return p


PERFECT_CONTACT = 1e9
"""Conductance of a bonded interface, W/(m² K), where a compliance effect makes it a contact."""


def _contact(p: Problem, r: Resolved, targets: Targets, kind: str, v: float) -> Problem:
    """A joint effect on a contact (by its name or its interface ``A/B``): its conductance or its
    normal stiffness set; a bonded interface becomes a contact."""
    old = next((c for c in p.contacts if r.target in (c.name, c.boundary)), None)
    if old is None:
        if r.target not in targets.interfaces:
            names = [*targets.joints, *(c.name for c in p.contacts), *targets.interfaces]
            raise InputError(f"effect {r.key}", f"no joint, contact or interface '{r.target}'",
                             f"joints of this case: {', '.join(names) or 'none'}")
        old = Contact(r.target, tuple(r.target.split("/")), PERFECT_CONTACT if p.heat else None, None)
    if kind == "joint_resistance":
        new = dataclasses.replace(old, conductance=v)
    else:
        new = dataclasses.replace(old, stiffness=(v, old.stiffness[1] if old.stiffness else v))
    return dataclasses.replace(p, contacts=(*(c for c in p.contacts if c is not old and c.boundary != new.boundary),
                                            new))


def _named(r: Resolved, names, what: str) -> None:
    if r.target not in names:
        raise InputError(f"effect {r.key}", f"no {what} '{r.target}'", f"{what}s: {', '.join(names) or 'none'}")


def _with_joint(m: Material, layer: JointLayer, kind: str, v: float) -> Material:
    if kind == "joint_resistance":
        return dataclasses.replace(m, k=_series(layer.thickness, layer.bulk.k, v))
    return dataclasses.replace(m, E=_series(layer.thickness, layer.bulk.E, v))


def room(problem: Problem) -> Value:
    """The room temperature of a problem: the ambient its films share (else its initial temperature)."""
    ambients = {f.ambient for f in problem.films} | ({problem.faces.ambient} if problem.faces else set())
    return ambients.pop() if len(ambients) == 1 else Value(problem.T0)


def _drifting(p: Problem, rate_k_per_h: float) -> Problem:
    """Every film's, the faces' and the hoses' ambient drifting by ``rate`` from its value."""
    def drift(v: Value) -> Value:
        return Value.of(f"({v.text or repr(v.constant)}) + {rate_k_per_h / 3600.0!r} * t", v.key, v.range)

    return dataclasses.replace(
        p, films=tuple(dataclasses.replace(f, ambient=drift(f.ambient)) for f in p.films),
        faces=dataclasses.replace(p.faces, ambient=drift(p.faces.ambient)) if p.faces else None,
        fluids=tuple(dataclasses.replace(f, ambient=drift(f.ambient)) for f in p.fluids))
