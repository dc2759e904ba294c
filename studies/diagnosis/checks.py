"""Model-form checks: is an explanation a cause, or only what makes the model fit?

A set of pieces fitted to a run *explains* it only if it passes all of these:

* **Holds on data it was not fitted to, in every input phase.** Leave one phase of the run
  out, refit the pieces on the others, predict the phase left out: no channel may keep a
  significant residual there (:func:`folds`). The refit is one Gauss–Newton step from the
  values fitted on the whole run, on the Jacobian of every channel and sample (one model run
  per piece for the whole check), bounded to the plausible ranges and lightly damped, so a
  piece that the other phases do not determine keeps its value.
* **The same values in every phase.** A piece whose value fitted without one phase moves by
  more than :data:`Z_CONSISTENT` of its statistical spread *and* by more than
  :data:`REL_CONSISTENT` of its change from the model's value stands in for something that
  differs from phase to phase: it is not a cause.
* **Physically plausible values:** none at an end of its stated range (``--list-effects``).
* **No more pieces than the evidence supports:** every piece lowers the held-out score by the
  margin with the penalty k·ln N (the Bayesian information criterion of the held-out
  log-likelihood; :mod:`calibrate`, :mod:`select`'s removal check).
* **A sensor fault needs evidence of a sensor** (:func:`sensor_evidence`): with it, its own
  channel keeps no significant residual. And where a physical piece (an effect, a parameter, a
  dimension) put in its place explains all channels together as well (an equivalent,
  :mod:`identify`), the physical piece is named and the fault listed as its equivalent.

A piece that fails is a *stand-in*: it is reported as what makes the model fit, not named as
a cause.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import lsq_linear

from gatetherm.studies.diagnosis.calibrate import Objective, coordinate, refit
from gatetherm.studies.diagnosis.hypotheses import Piece
from gatetherm.studies.diagnosis.locate import Phase, significant
from gatetherm.studies.diagnosis.replay import resolution

Z_CONSISTENT = 4.0
"""Statistical spreads by which a piece's value fitted without one phase may differ from the whole run's."""
REL_CONSISTENT = 0.2
"""… and the fraction of its change from the model's value (from zero for an effect) by which it may differ."""
AT_BOUND = 1e-3
"""A value this close to an end of its range (in [0, 1] range coordinates) is at the end."""
STEP = 0.01
"""Finite-difference step of the Jacobian, in range coordinates."""
DAMPING = 1e-6
"""Tikhonov damping of the phase refits, relative to the largest diagonal entry of JᵀWJ."""


@dataclass(frozen=True)
class Fold:
    """One phase left out: the pieces refitted on the others, and the prediction of the phase."""

    phase: Phase
    values: dict
    """{piece: value fitted without the phase}."""
    unexplained: tuple[str, ...]
    """Channels with a significant predicted residual in the phase."""

    @property
    def holds(self) -> bool:
        return not self.unexplained


@dataclass(frozen=True)
class Checks:
    """The model-form checks of a set of pieces."""

    folds: tuple[Fold, ...]
    implausible: tuple[Piece, ...]
    """At an end of the plausible range."""
    inconsistent: tuple[Piece, ...]
    """Values that differ from phase to phase."""
    unevidenced: tuple[Piece, ...] = ()
    """Sensor faults without evidence of a sensor."""

    @property
    def holds(self) -> bool:
        return all(f.holds for f in self.folds)

    @property
    def stand_ins(self) -> tuple[Piece, ...]:
        return tuple(dict.fromkeys(self.implausible + self.inconsistent + self.unevidenced))

    def why(self, p: Piece) -> str:
        """Why ``p`` is a stand-in ('' if it is not)."""
        out = (["its value is at an end of its plausible range"] * (p in self.implausible)
               + ["its value differs between the phases of the run"] * (p in self.inconsistent)
               + ["no evidence of a sensor fault"] * (p in self.unevidenced))
        return "; ".join(out)

    def summary(self) -> dict:
        return {"phases_held_out": [{"phase": f"{f.phase.label} {f.phase.span()}", "holds": f.holds,
                                     "unexplained": list(f.unexplained),
                                     "values": {p.label: float(v) for p, v in f.values.items()}} for f in self.folds],
                "implausible": [p.label for p in self.implausible],
                "inconsistent": [p.label for p in self.inconsistent],
                "unevidenced": [p.label for p in self.unevidenced]}


def jacobian(obj: Objective, values: dict) -> tuple[dict, dict]:
    """({channel: residual}, {channel: d residual / d coordinate, samples × pieces}) at ``values``,
    every sample, by forward differences of :data:`STEP` (one model run per piece that needs one)."""
    pieces = list(values)
    r0 = obj.residuals(values, solve=False)[0]
    J = {c: np.empty((len(obj.t), len(pieces))) for c in obj.channels}
    for j, p in enumerate(pieces):
        to, back = coordinate(p)
        x = float(to(values[p]))
        h = STEP if x + STEP <= 1.0 else -STEP
        rj = obj.residuals({**values, p: back(x + h)}, solve=False)[0]
        for c in obj.channels:
            J[c][:, j] = (rj[c] - r0[c]) / h
    return r0, J


def _rows(obj: Objective, r0: dict, J: dict, mask: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Weighted (residual, Jacobian) rows of the finite samples in ``mask``."""
    rs, Js = [], []
    for c in obj.channels:
        w = np.sqrt(obj.weight[c]) / obj.scale[c]
        m = mask & np.isfinite(r0[c])
        rs.append(w * r0[c][m])
        Js.append(w * J[c][m])
    return np.concatenate(rs), np.vstack(Js)


def _covariance(A: np.ndarray, r: np.ndarray) -> np.ndarray:
    s2 = max(float(r @ r) / max(len(r) - A.shape[1], 1), 1.0)
    return np.linalg.pinv(A.T @ A) * s2


def folds(obj: Objective, values: dict, run_phases) -> tuple[list[Fold], list[Piece]]:
    """Leave every phase out in turn (:mod:`checks`); returns the folds and the pieces whose values
    differ between them."""
    pieces = list(values)
    if not pieces:
        return [], []
    r0, J = jacobian(obj, values)
    coords = [coordinate(p) for p in pieces]
    x0 = np.array([to(values[p]) for p, (to, _) in zip(pieces, coords)])
    everything = np.ones_like(obj.t, dtype=bool)
    b_all, A_all = _rows(obj, r0, J, everything)
    var_all = np.diag(_covariance(A_all, b_all))
    out, inconsistent = [], set()
    for ph in run_phases:
        left = ph.mask(obj.t)
        if left.sum() < 5 or (~left).sum() < 5:
            continue
        b, A = _rows(obj, r0, J, ~left)
        lam = DAMPING * max(float(np.max(np.diag(A.T @ A))), 1e-30)
        k = len(pieces)
        sol = lsq_linear(np.vstack([A, np.sqrt(lam) * np.eye(k)]), np.concatenate([-b, np.zeros(k)]),
                         bounds=(-x0, 1.0 - x0))
        dx = sol.x
        var = np.diag(_covariance(A, b + A @ dx))
        fold_values = {p: back(float(x)) for p, (_, back), x in zip(pieces, coords, x0 + dx)}
        for j, p in enumerate(pieces):
            ref = p.neutral if p.neutral is not None else 0.0
            spread = np.sqrt(max(var[j] - var_all[j], 1e-12 * max(var[j], 1e-30)))
            if abs(dx[j]) > Z_CONSISTENT * spread and \
                    abs(fold_values[p] - values[p]) > REL_CONSISTENT * abs(values[p] - ref):
                inconsistent.add(p)
        bad = []
        for c in obj.channels:
            pred = r0[c] + J[c] @ dx
            if np.any(significant(obj.t, pred, resolution(c))[left]):
                bad.append(c)
        out.append(Fold(ph, fold_values, tuple(bad)))
    return out, [p for p in pieces if p in inconsistent]


def implausible(values: dict) -> list[Piece]:
    """The pieces at an end of their plausible range."""
    out = []
    for p, v in values.items():
        x = float(coordinate(p)[0](v))
        if x <= AT_BOUND or x >= 1.0 - AT_BOUND:
            out.append(p)
    return out


def sensor_evidence(values: dict, explains_channel) -> list[Piece]:
    """The sensor faults of ``values`` without evidence of a sensor: with them, their own channel
    keeps a significant residual (``explains_channel(channel)`` false)."""
    return [p for p in values if p.kind == "sensor" and not explains_channel(p.channel)]


def explained_channels(obj: Objective, values: dict) -> set[str]:
    """The channels with no significant residual anywhere in the run, with ``values``."""
    res = obj.residuals(values, solve=False)[0]
    return {c for c in obj.channels if not np.any(significant(obj.t, res[c], resolution(c)))}


def model_form(obj: Objective, values: dict, run_phases) -> Checks:
    """Every check of :mod:`checks` on the set ``values``."""
    fl, inconsistent = folds(obj, values, run_phases)
    ok = explained_channels(obj, values)
    return Checks(tuple(fl), tuple(implausible(values)), tuple(inconsistent),
                  tuple(sensor_evidence(values, lambda c: c in ok)))


def confirm(obj: Objective, values: dict, run_phases, margin: float, base_score: float) -> tuple[dict, dict, Checks]:
    """The pieces of ``values`` that are causes: the stand-ins (:class:`Checks`) dropped and the rest
    refitted, until none is left; a rest that no longer lowers the held-out score ``base_score`` by
    ``margin`` goes too. Returns (values named, {stand-in: (value, why)}, checks of the named set)."""
    stand: dict = {}
    while True:
        chk = model_form(obj, values, run_phases)
        if not chk.stand_ins:
            return values, stand, chk
        stand.update({p: (values[p], chk.why(p)) for p in chk.stand_ins})
        keep = {p: v for p, v in values.items() if p not in chk.stand_ins}
        values = refit(obj, keep, max_nfev=5) if keep else {}
        if values and base_score - obj.scored(values).score < margin:
            stand.update({p: (v, "without the stand-ins it does not lower the held-out score by the margin")
                          for p, v in values.items()})
            values = {}
