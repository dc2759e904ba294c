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

The catalogue, the targets and the keys are :mod:`gatetherm.solvers.effect_kinds` (their names are
importable from here too).
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

import numpy as np

from gatetherm import InputError
from gatetherm.solvers.effect_kinds import (  # noqa: F401 (re-exported)
    KINDS, Effect, JointLayer, Named, Resolved, Targets, catalogue_json, checked, effects_from_table, effects_table,
    parse_effect, resolve)
from gatetherm.solvers.expr import Value
from gatetherm.solvers.material import Material
from gatetherm.solvers.problem import Contact, Film, Problem, Source


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
