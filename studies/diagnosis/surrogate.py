"""Screening without model runs: a superposition surrogate of a set of hypotheses.

The columns of a set are approximated by the run of the hypotheses already chosen that
need runs (the *anchor*) plus, for each hypothesis that needs runs, the change its
first-round runs alone showed against the baseline run, interpolated (linearly
extrapolated beyond them) at the new value minus that change at the anchor's value.
Observation-side effects and sensor faults then act exactly. The heat equation is linear
in the temperatures but not in the parameters, so the surrogate is only good enough to
rank additions and to start their real joint fit; it lets every chosen parameter move
when a candidate is tried, so that a piece chosen first at a compensating value does not
hide the candidate that explains the rest.
"""
from __future__ import annotations

import numpy as np

from gatetherm.solvers.effects import ActiveEffects
from gatetherm.studies.diagnosis.calibrate import CHEAP_SCAN, Objective, Scored, bounded_fit, coordinate
from gatetherm.studies.diagnosis.hypotheses import Piece


class Surrogate:
    """Approximate columns of sets that extend ``current`` (:mod:`surrogate`)."""

    def __init__(self, obj: Objective, current: dict):
        self.obj = obj
        self.anchor_values = {p: v for p, v in current.items() if p.rerun}
        self.anchor = obj.model_columns(self.anchor_values)
        self.base = obj.model_columns({})
        self._tables: dict[Piece, tuple[np.ndarray, dict]] = {}

    def _table(self, p: Piece):
        if p not in self._tables:
            to, _ = coordinate(p)
            runs = self.obj.solo_runs(p) + ([(p.neutral, self.base)] if p.neutral is not None else [])
            xs, keep = np.unique([to(v) for v, _ in runs], return_index=True)
            runs = [runs[i] for i in keep]
            self._tables[p] = (xs, {k: np.array([cols[k] - self.base[k] for _, cols in runs]) for k in self.base})
        return self._tables[p]

    def _delta(self, p: Piece, x: float) -> dict:
        xs, d = self._table(p)
        if len(xs) == 1:
            return {k: v[0] for k, v in d.items()}
        i = int(np.clip(np.searchsorted(xs, x) - 1, 0, len(xs) - 2))
        w = (x - xs[i]) / (xs[i + 1] - xs[i])
        return {k: (1 - w) * v[i] + w * v[i + 1] for k, v in d.items()}

    def usable(self, p: Piece) -> bool:
        """Has ``p`` runs to superpose (or needs none)?"""
        return not p.rerun or len(self._table(p)[0]) > 0

    def columns(self, values: dict) -> dict:
        """Approximate columns of ``values`` (anchor pieces missing from it are taken out)."""
        cols = dict(self.anchor)
        for p in {q for q in values if q.rerun} | set(self.anchor_values):
            to, _ = coordinate(p)
            new = self._delta(p, to(values[p])) if p in values else None
            old = self._delta(p, to(self.anchor_values[p])) if p in self.anchor_values else None
            cols = {k: c + (new[k] if new else 0.0) - (old[k] if old else 0.0) for k, c in cols.items()}
        obs = {p.name: v for p, v in values.items() if p.kind == "effect" and not p.rerun}
        return ActiveEffects(obs).observe(cols) if obs else cols


def screen(sur: Surrogate, current: dict, adds: dict) -> Scored:
    """``current`` plus the pieces ``adds`` ({piece: start value, or None: the best of a scan
    of its range with the others kept}), every non-linear value refitted on the surrogate by
    bounded least squares; scored on the held-out window (approximate)."""
    obj = sur.obj

    def residuals(values):
        return obj.residuals(values, sur.columns(values))

    values = dict(current)
    for piece, start in adds.items():
        if piece.linear:
            values[piece] = piece.neutral
        elif start is not None:
            values[piece] = start
        else:
            back = coordinate(piece)[1]
            tried = [{**values, piece: back(x)} for x in np.linspace(0.0, 1.0, CHEAP_SCAN)]
            values = min(tried, key=lambda v: obj.chi2(residuals(v)[0]))
    values = bounded_fit(obj, values, list(values), residuals, diff_step=1e-3, max_nfev=30, ftol=1e-5, xtol=1e-5)
    return obj.scored(values, sur.columns(values), approx=True)
