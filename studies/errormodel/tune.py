"""Refining one target's selected terms (:func:`refine`): the lags' time constants refined
continuously, then every term dropped that does not earn ``min_gain``; and the two pieces the fit
shares with it, the terms' noise variances (:func:`variances`) and the held-out error of a design
(:func:`held_out`). :mod:`gatetherm.studies.errormodel.fit`'s docstring gives the method."""
from __future__ import annotations

import dataclasses
import logging

import numpy as np

from gatetherm.studies.errormodel import select
from gatetherm.studies.errormodel.fitparams import FitParams
from gatetherm.studies.errormodel.runs import Runs
from gatetherm.studies.errormodel.terms import noise_sd

log = logging.getLogger(__name__)

SQRT2 = float(np.sqrt(2.0))


def variances(terms, data: Runs, params: FitParams) -> np.ndarray:
    """Noise variance of the intercept (0) and of each term's values (K^2; 0 for inputs); with
    ``anchor_s`` and several runs also the noise of each run's reference (``2 (2m - 1) / (m (m + 1))``
    of a reading's, m the samples of the first ``anchor_s``)."""
    step = data.step_s
    var = [noise_sd(term, params.resolution_K, step, params.smooth_s) ** 2 for term in terms]
    if params.anchor_s > 0 and data.anchored:
        m = int(params.anchor_s // step) + 1
        share = 2 * (2 * m - 1) / (m * (m + 1))  # 1 for m = 1, 2
        var = [v + share * noise_sd(dataclasses.replace(term, tau_s=None), params.resolution_K, step) ** 2
               for v, term in zip(var, terms)]
    return np.array([0.0] + var)


def held_out(X, y, data: Runs, rows, params: FitParams, penalty) -> select.CrossValidation:
    """Leave one run out with three or more runs, else ``params.cv`` within the rows."""
    blocks = data.blocks(rows)
    return select.CrossValidation(X, y, params.folds, blocks=blocks, penalty=penalty,
                                  chain=blocks is None and params.cv == "chain", noisy=params.noisy_cv)


def tune_lags(terms, data: Runs, y_all, rows, params: FitParams):
    """The terms with their lag time constants refined by least squares on the span (each within the
    grid's range widened by sqrt(2)) and their held-out error; inf if two lags of one signal end up
    within a factor sqrt(2) of each other (one of them is redundant)."""
    lagged = [j for j, term in enumerate(terms) if term.tau_s is not None]
    fixed = [data.column(term)[rows] for term in terms]
    y = y_all[rows]

    def design(log_tau):
        cs = list(fixed)
        for j, lt in zip(lagged, log_tau):
            cs[j] = data.column(dataclasses.replace(terms[j], tau_s=float(np.exp(lt))))[rows]
        return np.column_stack([np.ones(y.size)] + cs)

    def sse(log_tau):
        X = design(log_tau)
        now = list(terms)
        for j, lt in zip(lagged, log_tau):
            now[j] = dataclasses.replace(terms[j], tau_s=float(np.exp(lt)))
        v = variances(now, data, params)
        c = select.noisy_least_squares(X, y, v)
        r = X @ c - y
        return float(r @ r + y.size * (v @ c**2))

    out = list(terms)
    if lagged:
        from scipy.optimize import minimize  # here: a service stepping a model imports no scipy.optimize

        grid = {j: params.input_taus_s if terms[j].kind == "input" else params.sensor_taus_s for j in lagged}
        bounds = [(np.log(min(grid[j]) / SQRT2), np.log(max(grid[j]) * SQRT2)) for j in lagged]
        res = minimize(sse, np.log([terms[j].tau_s for j in lagged]), method="L-BFGS-B", bounds=bounds)
        for j, lt in zip(lagged, res.x):
            out[j] = dataclasses.replace(terms[j], tau_s=float(np.exp(lt)))
        if any(a.columns == b.columns and a.kind == b.kind and a.exponent == b.exponent
               and max(a.tau_s, b.tau_s) < SQRT2 * min(a.tau_s, b.tau_s)
               for i, a in enumerate(out) for b in out[i + 1:] if a.tau_s and b.tau_s):
            return out, np.inf
    X = np.column_stack([np.ones(y.size)] + [data.column(term)[rows] for term in out])
    cv = held_out(X, y, data, rows, params, variances(out, data, params))
    return out, cv.error(np.eye(X.shape[1]))


def refine(terms, cv_mae, data: Runs, y_all, rows, params: FitParams):
    """Refine the selected terms' time constants (:func:`tune_lags`), then drop, one at a time, any
    term whose removal (time constants refined again) raises the held-out error by less than
    ``min_gain``: two grid lags that bracket one true time constant become one. Returns the terms
    and their held-out error; the grid's (``terms``, ``cv_mae``) if refining does not lower it."""
    best, best_cv = terms, cv_mae
    tuned, tuned_cv = tune_lags(terms, data, y_all, rows, params)
    if tuned_cv <= best_cv:
        best, best_cv = tuned, tuned_cv
    dropped = True
    while dropped and len(best) > 1:
        dropped = False
        for j in reversed(range(len(best))):
            fewer, fewer_cv = tune_lags(best[:j] + best[j + 1:], data, y_all, rows, params)
            if fewer_cv < best_cv * (1 + params.min_gain):
                log.info("%s dropped: held-out error %.4g without it, %.4g with", best[j].label, fewer_cv, best_cv)
                best, best_cv, dropped = fewer, min(fewer_cv, best_cv), True
                break
    return best, best_cv
