"""Least-squares models of delta on temperature rises.

* :func:`fit_coefficients`: K_i, K_C of ``delta = K_i (theta_A - theta_B) - K_C theta_C``
  (eq 21, no intercept), the "fit" source of the compensator's coefficients.
* :func:`fit_regression` / :func:`apply_regression`: the industry baseline, a static
  multiple linear regression of delta on temperature rises with intercept, fitted on one
  run and applied to another. By default the regressors are theta_A, theta_B, theta_C and
  every ``T_<name>_degC`` column, less any that is an exact linear combination of those
  before it (e.g. the last tie-bar point, theta_C being the mean of C1..C10); a caller may
  name them instead (e.g. :data:`THETAS`, the paper's three sensors).

Rows with a missing value in any used column are left out of a fit (and logged).
"""
from __future__ import annotations

import logging
import re
from dataclasses import dataclass

import numpy as np

from gatetherm import InputError
from gatetherm.studies.control.compensator import extrapolate
from gatetherm.studies.run.timeseries import TimeSeries, rises

log = logging.getLogger(__name__)

THETAS = ("theta_A_degC", "theta_B_degC", "theta_C_degC")
_SENSOR = re.compile(r"^T_\w+_degC$")


@dataclass(frozen=True)
class LinearModel:
    """``delta = intercept + sum_i coefficients[i] * rise(features[i])``."""

    features: tuple[str, ...]
    """Temperature columns whose rises are the regressors."""
    coefficients: tuple[float, ...]
    """One per feature, um/K."""
    intercept_um: float
    """Constant term, um."""


def _least_squares(x: np.ndarray, y: np.ndarray, what: str) -> np.ndarray:
    ok = np.isfinite(x).all(axis=1) & np.isfinite(y)
    if (~ok).any():
        log.info("%s: %d of %d rows with missing values left out", what, int((~ok).sum()), len(y))
    if ok.sum() < x.shape[1] or np.linalg.matrix_rank(x[ok]) < x.shape[1]:
        raise InputError(what, "the temperatures do not vary independently enough to fit",
                         "use a longer run, or give the coefficients explicitly")
    return np.linalg.lstsq(x[ok], y[ok], rcond=None)[0]


def fit_coefficients(ts: TimeSeries) -> tuple[float, float]:
    """(K_i, K_C) in um/K: least squares of delta on theta_A - theta_B and -theta_C rises."""
    x = np.column_stack([rises(ts, "theta_A_degC") - rises(ts, "theta_B_degC"),
                         -rises(ts, "theta_C_degC")])
    ki, kc = _least_squares(x, ts["delta_um"], "K_i, K_C fit")
    log.info("fitted K_i = %.6g um/K, K_C = %.6g um/K", ki, kc)
    return float(ki), float(kc)


def regression_features(ts: TimeSeries) -> tuple[str, ...]:
    """The baseline's regressors present in ``ts``: the thetas and any T_<name>_degC."""
    return THETAS + tuple(n for n in ts.names if _SENSOR.match(n))


def _design(ts: TimeSeries, features) -> np.ndarray:
    missing = [f for f in features if f not in ts]
    if missing:
        raise InputError(f"{getattr(ts, 'source', '') or 'data'}: column {missing[0]}",
                         "used by the regression model but absent",
                         "apply the model to a run with the same sensors")
    return np.column_stack([np.ones(len(ts))] + [rises(ts, f) for f in features])


def independent_features(ts: TimeSeries, features) -> tuple[str, ...]:
    """``features`` in order, less those whose rise is (to round-off) a linear combination of
    the intercept and the features kept before it; the dropped ones are logged."""
    keep: list[str] = []
    for name in features:
        x = _design(ts, keep + [name])
        x = x[np.isfinite(x).all(axis=1)]
        if np.linalg.matrix_rank(x) == x.shape[1]:
            keep.append(name)
    if len(keep) < len(features):
        log.info("regression: left out linearly dependent %s", ", ".join(f for f in features if f not in keep))
    return tuple(keep)


def fit_regression(ts: TimeSeries, features=None) -> LinearModel:
    """Fit the static multiple linear regression baseline on one run; ``features`` are
    temperature columns (default: :func:`regression_features`, dependent ones left out)."""
    features = independent_features(ts, regression_features(ts)) if features is None else tuple(features)
    beta = _least_squares(_design(ts, features), ts["delta_um"], "regression baseline")
    log.info("regression baseline on %d sensors: intercept %.4g um, coefficients %s um/K", len(features),
             beta[0], ", ".join(f"{f} {b:.4g}" for f, b in zip(features, beta[1:])))
    return LinearModel(features, tuple(float(b) for b in beta[1:]), float(beta[0]))


def apply_regression(model: LinearModel, ts: TimeSeries) -> np.ndarray:
    """Predicted delta (um) for another run (rises from its own first sample)."""
    return _design(ts, model.features) @ np.r_[model.intercept_um, model.coefficients]


def regression_forecast(model: LinearModel, ts: TimeSeries) -> np.ndarray:
    """One-sample-ahead forecast of delta (um) from temperatures extrapolated one step (eq 33):
    the model is linear, so extrapolating its inputs extrapolates its output (NaN for the first two)."""
    now = apply_regression(model, ts)
    return np.r_[np.nan, np.nan, extrapolate(now[:-2], now[1:-1])]
