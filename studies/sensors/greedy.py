"""Choosing K sensors from the shortlist with the error-model family, by held-out loads.

The base columns on the training rows are a column of ones, the shortlisted candidates'
temperature rises (with the sensor noise) and the operating inputs through first-order lags
(the terms of :mod:`gatetherm.studies.errormodel.terms` on the grid of its ``FitParams``); each
target (a relative displacement) has a :class:`~gatetherm.studies.errormodel.select.CrossValidation`
over them whose blocks are the training loads: leave one load out.

A sensor set's error is the mean over the targets of their held-out MAE. Per form:

* ``static``: ``delta = c0 + sum_k K_k theta_k`` over the set;
* ``dynamic``: the same plus, per target, at most ``max_inputs`` input lags chosen by the
  errormodel's forward selection (``select.forward`` and ``select.choose``) given the set.

:func:`path` grows the set one sensor at a time (the one that lowers the error most, at least
``min_distance`` from the others; the lags of the previous set held), then exchanges each member
for any other shortlisted candidate while that lowers the error, then re-chooses the lags. The
form of each size is the errormodel's rule: dynamic only if its error is lower by ``min_gain``.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from gatetherm.studies.errormodel import select
from gatetherm.studies.errormodel.fit import FitParams


class Design:
    """The training rows: ``theta`` (rows x shortlist, K), ``lags`` (rows x lag terms), targets ``Y``
    (rows x targets, um), ``blocks`` the row range of each training load."""

    def __init__(self, theta: np.ndarray, lags: np.ndarray, Y: np.ndarray, blocks):
        self.s, self.q = theta.shape[1], lags.shape[1]
        self.Z = np.column_stack([np.ones(len(Y)), theta, lags])
        self.Y = Y
        self.cvs = [select.CrossValidation(self.Z, Y[:, j], blocks=blocks) for j in range(Y.shape[1])]

    def columns(self, sensors, lags=()) -> list[int]:
        """Base columns of the intercept, the sensors (shortlist indices) and lags (lag indices)."""
        return [0, *(1 + i for i in sensors), *(1 + self.s + k for k in lags)]

    def errors(self, sensors, lags) -> np.ndarray:
        """Held-out MAE of every target (um); ``lags`` holds one tuple per target."""
        return np.array([cv.error_of(self.columns(sensors, lg)) for cv, lg in zip(self.cvs, lags)])

    def choose_lags(self, sensors, params: FitParams) -> tuple[tuple[int, ...], ...]:
        """Per target, the input lags the errormodel's forward selection adds to ``sensors``."""
        if not self.q or params.max_inputs == 0:
            return ((),) * len(self.cvs)
        p = self.Z.shape[1]
        fixed = np.eye(p)[:, self.columns(sensors)]
        cands = [select.Candidate(k, np.eye(p)[:, 1 + self.s + k], frozenset(), True) for k in range(self.q)]
        out = []
        for cv in self.cvs:
            path = select.forward(cv, cands, fixed, 0, params.max_inputs)
            out.append(select.choose(path, params.min_gain).chosen)
        return tuple(out)

    def coefficients(self, sensors, lags) -> list[np.ndarray]:
        """Per target, least squares on every training row: [c0, sensors..., lags...]."""
        return [np.linalg.lstsq(self.Z[:, self.columns(sensors, lg)], self.Y[:, j], rcond=None)[0]
                for j, lg in enumerate(lags)]


@dataclass(frozen=True)
class Step:
    """A sensor set of the path and its model."""

    sensors: tuple[int, ...]
    """Shortlist indices, in the order of the sensor names."""
    form: str
    lags: tuple[tuple[int, ...], ...]
    """Per target, lag indices (empty for static)."""
    cv_mae_um: tuple[float, ...]
    """Per target, leave-one-load-out MAE, um."""

    @property
    def error(self) -> float:
        return float(np.mean(self.cv_mae_um))


def fixed_set(design: Design, sensors, form: str, params: FitParams) -> Step:
    """The ``form`` model (``static``/``dynamic``) of a given sensor set."""
    lags = design.choose_lags(sensors, params) if form == "dynamic" else ((),) * len(design.cvs)
    return Step(tuple(sensors), form, lags, tuple(map(float, design.errors(sensors, lags))))


def best_form(steps: list[Step], params: FitParams) -> Step:
    """The errormodel's rule: the dynamic step only if its error is lower by ``min_gain``."""
    by = {s.form: s for s in steps}
    if "dynamic" in by and ("static" not in by or by["dynamic"].error < by["static"].error * (1 - params.min_gain)):
        return by["dynamic"]
    return by["static"]


def path(design: Design, count: int, form: str, params: FitParams, xyz: np.ndarray,
         min_distance_m: float = 0.0, passes: int = 3) -> list[Step]:
    """Sets of 1 ... ``count`` sensors (module docstring); shorter if no candidate is left at
    ``min_distance_m`` (m) from the chosen ones."""
    def allowed(chosen):
        if not chosen or min_distance_m <= 0:
            return [i for i in range(design.s) if i not in chosen]
        d = np.linalg.norm(xyz[:, None, :] - xyz[list(chosen)][None], axis=2).min(axis=1)
        return [i for i in np.flatnonzero(d >= min_distance_m) if i not in chosen]

    def cost(chosen, lags):
        return float(np.mean(design.errors(chosen, lags)))

    dynamic = form == "dynamic"
    chosen: list[int] = []
    lags = design.choose_lags(chosen, params) if dynamic else ((),) * len(design.cvs)
    out = []
    for _ in range(count):
        pool = allowed(chosen)
        if not pool:
            break
        chosen.append(min(pool, key=lambda i: cost(chosen + [i], lags)))
        best = cost(chosen, lags)
        for _ in range(passes):
            changed = False
            for pos in range(len(chosen)):
                others = chosen[:pos] + chosen[pos + 1:]
                for i in allowed(others):
                    trial = others[:pos] + [i] + others[pos:]
                    e = cost(trial, lags)
                    if e < best * (1 - 1e-9):
                        chosen, best, changed = trial, e, True
            if not changed:
                break
        if dynamic:
            lags = design.choose_lags(chosen, params)
        out.append(Step(tuple(chosen), form, lags, tuple(map(float, design.errors(chosen, lags)))))
    return out


def curve(paths, forms, count: int, min_distance_m: float, fit: FitParams, point) -> tuple[list, list, str]:
    """The error curve along the greedy paths: one more sensor while it lowers the
    leave-one-load-out error by ``fit.min_gain`` and a candidate is left ``min_distance_m`` from
    the chosen; why it stopped. ``point(k, step)`` scores the ``k + 1``-th (a curve point)."""
    points, chosen = [], []
    for k in range(count):
        if any(len(paths[f]) <= k for f in forms):
            return points, chosen, (f"no candidate is left {min_distance_m:g} m or more from the {k} chosen: "
                                   f"the curve stops at {k}")
        step = best_form([paths[f][k] for f in forms], fit)
        if chosen and step.error > chosen[-1].error * (1 - fit.min_gain):
            return points, chosen, (f"a sensor {k + 1} lowers the leave-one-load-out error by less than "
                                   f"{fit.min_gain:.0%} ({chosen[-1].error:.3g} -> {step.error:.3g} um): "
                                   f"the curve stops at {k}")
        chosen.append(step)
        points.append(point(k, step))
    return points, chosen, ""


def rising(curve) -> list[str]:
    """Notes where the held-out error rises along the curve."""
    return [f"the held-out error rises from {a.count} to {b.count} sensors "
            f"({a.held_out_mean_um:.3g} -> {b.held_out_mean_um:.3g} um) although the leave-one-load-out "
            "error falls: within the scatter of the estimate, or the held-out loads differ from the training loads"
            for a, b in zip(curve, curve[1:]) if b.held_out_mean_um > a.held_out_mean_um]
