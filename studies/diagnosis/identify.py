"""Which hypotheses the data cannot tell apart, and which measurement would.

Two hypotheses are *equivalent* on a run when their effects on the compared channels are
(nearly) the same over it: the angle between their sensitivity vectors (the change each
makes to the weighted residual of every compared channel and sample) is below
:data:`ANGLE_DEG`, or one put in the other's place and refitted scores within the margin
(:func:`~gatetherm.studies.diagnosis.select.select` lists those as alternatives). A chosen
piece and its equivalents are one :class:`Group`: the diagnosis reports the group, and a
study counts a group that holds the hidden piece as right, never as a wrong piece.

What would separate two members (:func:`separating`): measuring the dimension on the
machine (a geometry piece), checking the sensor against a reference (a sensor piece), and
the output of the model that is not compared (another probe, another displacement) where
the two explanations differ most, in units of its resolution.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from gatetherm.studies.diagnosis.calibrate import Objective, Refused, refit
from gatetherm.studies.diagnosis.hypotheses import Piece
from gatetherm.studies.diagnosis.replay import NOT_COMPARED, RESOLUTION, label, resolution, unit
from gatetherm.studies.diagnosis.surrogate import Surrogate

ANGLE_DEG = 5.0
"""Sensitivity vectors closer than this angle, degrees: the data cannot separate the two."""


@dataclass(frozen=True)
class Group:
    """A chosen piece and the hypotheses the data cannot tell from it."""

    piece: Piece
    members: tuple[Piece, ...]
    """The equivalents (the chosen piece not included)."""
    values: dict
    """{member: value that stands in for the chosen piece}."""
    angles: dict
    """{member: angle between its sensitivity vector and the chosen piece's, degrees}."""
    separate_by: str
    """What measurement would tell them apart."""

    def sentence(self) -> str:
        alts = " or ".join(f"{q.label} {q.param} = {self.values[q]:.4g}" for q in self.members)
        return f"{self.piece.label} or {alts}: the data cannot separate them; {self.separate_by}"

    def entry(self) -> dict:
        return {"piece": self.piece.label, "members": [q.label for q in self.members],
                "keys": [self.piece.key] + [q.key for q in self.members],
                "values": {q.label: float(self.values[q]) for q in self.members},
                "angle_deg": {q.label: float(self.angles[q]) for q in self.members}, "separate_by": self.separate_by}


def _angle(a: np.ndarray, b: np.ndarray) -> float:
    na, nb = float(np.linalg.norm(a)), float(np.linalg.norm(b))
    if na == 0 or nb == 0:
        return 90.0
    return float(np.degrees(np.arccos(min(abs(float(a @ b)) / (na * nb), 1.0))))


def _all(obj: Objective) -> np.ndarray:
    return np.ones_like(obj.t, dtype=bool)


def contribution(obj: Objective, values: dict, p: Piece, columns=None) -> np.ndarray:
    """Weighted change of the residual (all samples) that ``p`` at its value in ``values`` makes
    (``columns(values)``: the model columns of a set, default from model runs)."""
    rest = {q: v for q, v in values.items() if q != p}

    def vec(v):
        return obj.vector(obj.residuals(v, None if columns is None else columns(v), solve=False)[0], _all(obj))
    return vec(rest) - vec(values)


def groups(obj: Objective, values: dict, pool, alternatives: dict, solo: dict, margin: float) -> list[Group]:
    """One group per chosen piece with equivalents: the ``alternatives`` ({piece: [pieces]}, refitted
    for real) and the hypotheses of ``pool`` whose sensitivity vector (from its value in ``solo``, on
    the superposition surrogate) lies within :data:`ANGLE_DEG` of the chosen piece's and that, put in
    its place and refitted, score within ``margin``."""
    if not values:
        return []
    sur = Surrogate(obj, values)
    chosen = {p: contribution(obj, values, p) for p in values}
    out = []
    for p, vp in chosen.items():
        rest = {q: v for q, v in values.items() if q != p}
        members, vals, angles = [], {}, {}
        for q in pool:
            if q in values or q not in solo or not sur.usable(q):
                continue
            vq = contribution(obj, {**rest, q: solo[q]}, q, sur.columns)
            ang = _angle(vp, vq)
            if q in alternatives.get(p, ()) or ang < ANGLE_DEG:
                try:
                    swapped = refit(obj, {**rest, q: solo[q]}, free=[q], max_nfev=6)
                    worse = obj.scored(swapped).score - obj.scored(values).score
                except Refused:  # the model refuses q with the rest: no equivalent
                    continue
                if worse < margin:
                    members.append(q)
                    vals[q], angles[q] = swapped[q], ang
        if members:
            text = "; ".join(dict.fromkeys(separating(obj, values, p, q, {**rest, q: vals[q]}) for q in members))
            out.append(Group(p, tuple(members), vals, angles, text))
    return out


def separating(obj: Objective, values: dict, p: Piece, q: Piece, other: dict) -> str:
    """What tells ``p`` (in ``values``) from ``q`` (in ``other``): the dimension measured, the sensor
    checked, or the model output not compared where the two explanations differ most."""
    out = [f"measure {r.name.rsplit('.', 1)[-1]} on the machine (the model has {r.neutral:.4g} {r.unit})".rstrip()
           for r in (p, q) if r.kind == "geometry"]
    out += [f"check the {label(r.channel)} sensor against a reference" for r in (p, q) if r.kind == "sensor"]
    a, b = obj.model_columns(values), obj.model_columns(other)
    best, name = 0.0, None
    for c in a:
        if c in obj.channels or c in NOT_COMPARED or not c.endswith(tuple(RESOLUTION)) or c not in b:
            continue
        d = float(np.nanmax(np.abs(a[c] - b[c]))) / resolution(c)
        if d > best:
            best, name = d, c
    if name is not None and best >= 1.0:
        out.append(f"record {label(name)} (the two differ there by up to {best * resolution(name):.2g} "
                   f"{unit(name)}, {best:.0f}× its resolution)")
    elif not out:
        out.append("no output of the model tells them apart on this run: a run with other inputs may")
    return " or ".join(out)


def physical_first(values: dict, found: list[Group]) -> tuple[dict, list[Group]]:
    """Where a named sensor fault has a physical equivalent (an effect, a parameter, a dimension),
    name the physical piece (the first) and list the fault in its group: a sensor is only chosen
    when it explains its channel better than any physical piece explains all channels together."""
    values, out = dict(values), []
    for g in found:
        physical = [q for q in g.members if q.kind != "sensor"]
        if g.piece.kind != "sensor" or not physical:
            out.append(g)
            continue
        q, s = physical[0], g.piece
        others = tuple(m for m in g.members if m != q)
        out.append(Group(q, (s, *others), {s: values[s], **{m: g.values[m] for m in others}},
                         {s: g.angles[q], **{m: g.angles[m] for m in others}}, g.separate_by))
        values = {(q if p == s else p): (g.values[q] if p == s else v) for p, v in values.items()}
    return values, out
