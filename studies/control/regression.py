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

What the thermocouples' noise allows (the error model's rule, docs/errormodel.md "Sensor noise";
``resolution_K`` their resolution, default 0.05 K, taken as the noise's standard deviation): a
regressor spanning fewer than :data:`~gatetherm.studies.errormodel.fit.SPAN_RESOLUTIONS` (10)
resolutions gets no weight (coefficient 0), and every fit minimises ``|y - X c|^2 + n sum_k
sigma_k^2 c_k^2`` (sigma_k the noise of regressor k, sqrt(2) resolutions for a difference), so that
no coefficient is larger than the noise makes identifiable: two nearly collinear signals (a
symmetric ram's theta_A ~ theta_B) share a bounded weight instead of +-1e5 um/K. Where least
squares' coefficients add at most :data:`INFLATION` (2) times the noise the bounded ones add to a
prediction (or within delta's 0.1 um resolution of it), the fit is identified and plain least
squares is kept, unchanged; else the bounded fit is used, and the coefficients it moved by more
than delta's resolution on one noisy reading are named. Exactly dependent
regressors are refused. What was dropped or bounded is said in one line
(:attr:`LinearModel.warning`, :func:`fit_coefficients_noted`).
"""
from __future__ import annotations

import logging
import re
from dataclasses import dataclass

import numpy as np

from gatetherm import InputError
from gatetherm.studies.control.compensator import extrapolate
from gatetherm.studies.errormodel.fit import SPAN_RESOLUTIONS, FitParams
from gatetherm.studies.errormodel.select import informative, noisy_least_squares
from gatetherm.studies.errormodel.terms import Term, noise_sd
from gatetherm.studies.run.timeseries import TimeSeries, rises

log = logging.getLogger(__name__)

THETAS = ("theta_A_degC", "theta_B_degC", "theta_C_degC")
_SENSOR = re.compile(r"^T_\w+_degC$")
RESOLUTION_K = FitParams.resolution_K
"""Default thermocouple resolution, K (the error model's, 0.05 K)."""
DELTA_RESOLUTION_UM = 0.1
"""Resolution of delta, um: a coefficient moved by the noise bound by more than this on one
noisy reading (|change| x sigma) is reported as bounded."""
INFLATION = 2.0
"""Least squares stands where the noise its coefficients add to a prediction, sqrt(sum sigma_k^2 c_k^2),
is at most this many times that of the bounded fit (or within delta's resolution of it): the fit is
identified and the bound would only shrink it."""


@dataclass(frozen=True)
class LinearModel:
    """``delta = intercept + sum_i coefficients[i] * rise(features[i])``."""

    features: tuple[str, ...]
    """Temperature columns whose rises are the regressors."""
    coefficients: tuple[float, ...]
    """One per feature, um/K."""
    intercept_um: float
    """Constant term, um."""
    warning: str = ""
    """What the fit dropped or bounded for the sensors' noise (one line; empty: nothing)."""


def _noisy_fit(x: np.ndarray, y: np.ndarray, sd, labels, what: str, resolution_K: float,
               intercept: bool = False) -> tuple[np.ndarray, str]:
    """Coefficients of ``y ~ x`` bounded by the regressors' noise ``sd`` (K, one per column; column 0
    the intercept where ``intercept``), those spanning under SPAN_RESOLUTIONS resolutions set to 0,
    and a one-line warning of what was dropped or bounded ('' if nothing)."""
    ok = np.isfinite(x).all(axis=1) & np.isfinite(y)
    if (~ok).any():
        log.info("%s: %d of %d rows with missing values left out", what, int((~ok).sum()), len(y))
    x, y, sd = x[ok], y[ok], np.asarray(sd, float)
    if len(y) < x.shape[1]:
        raise InputError(what, f"only {len(y)} complete rows for {x.shape[1]} coefficients",
                         "use a longer run, or give the coefficients explicitly")
    min_span = SPAN_RESOLUTIONS * resolution_K
    first = 1 if intercept else 0
    keep = list(range(first)) + [j for j in range(first, x.shape[1]) if informative(x[:, j], min_span)]
    dropped = [f"{labels[j]} (spans {np.ptp(x[:, j]):.3g} K)" for j in range(first, x.shape[1]) if j not in keep]
    if len(keep) == first:
        raise InputError(what, f"no temperature regressor spans {SPAN_RESOLUTIONS} sensor resolutions "
                         f"({min_span:g} K): the temperatures carry no information on delta",
                         "use a run whose temperatures change, or give the coefficients explicitly")
    if np.linalg.matrix_rank(x[:, keep]) < len(keep):
        raise InputError(what, "the temperatures do not vary independently enough to fit",
                         "use a longer run, or give the coefficients explicitly")
    c, plain = np.zeros(x.shape[1]), np.zeros(x.shape[1])
    c[keep] = noisy_least_squares(x[:, keep], y, sd[keep] ** 2)
    plain[keep] = np.linalg.lstsq(x[:, keep], y, rcond=None)[0]
    noise_plain, noise_bound = (float(np.linalg.norm(sd * v)) for v in (plain, c))
    bounded = [f"{labels[j]} {c[j]:.4g} um/K (least squares alone: {plain[j]:.4g})" for j in keep[first:]
               if abs(plain[j] - c[j]) * sd[j] > DELTA_RESOLUTION_UM]
    if noise_plain <= INFLATION * noise_bound or noise_plain - noise_bound <= DELTA_RESOLUTION_UM:
        c, bounded = plain, []  # identified: least squares, unchanged
    else:
        log.info("%s: the sensors' noise would add %.3g um to least squares' prediction, %.3g um bounded", what,
                 noise_plain, noise_bound)
    parts = []
    if dropped:
        parts.append(f"no weight for {', '.join(dropped)}: under {SPAN_RESOLUTIONS} sensor resolutions "
                     f"({min_span:g} K)")
    if bounded:
        parts.append(f"bounded by the sensor noise ({resolution_K:g} K) (least squares would fit the noise): "
                     + ", ".join(bounded))
    warning = f"{what}: {'; '.join(parts)}" if parts else ""
    if warning:
        log.info("%s", warning)
    return c, warning


def fit_coefficients_noted(ts: TimeSeries, resolution_K: float = RESOLUTION_K) -> tuple[float, float, str]:
    """(K_i, K_C) in um/K and a warning: least squares of delta on theta_A - theta_B and -theta_C
    rises, bounded by the sensors' noise (module docstring); a regressor spanning under 10
    resolutions gets K = 0, and what was dropped or bounded is the warning ('' if nothing)."""
    x = np.column_stack([rises(ts, "theta_A_degC") - rises(ts, "theta_B_degC"),
                         -rises(ts, "theta_C_degC")])
    sd = [noise_sd(Term("difference", "theta_A_degC", other="theta_B_degC"), resolution_K, 0.0),
          noise_sd(Term("sensor", "theta_C_degC"), resolution_K, 0.0)]
    (ki, kc), warning = _noisy_fit(x, ts["delta_um"], sd, ("theta_A - theta_B", "theta_C"), "K_i, K_C fit",
                                   resolution_K)
    log.info("fitted K_i = %.6g um/K, K_C = %.6g um/K", ki, kc)
    return float(ki), float(kc), warning


def fit_coefficients(ts: TimeSeries) -> tuple[float, float]:
    """(K_i, K_C) in um/K: :func:`fit_coefficients_noted` without its warning (logged)."""
    ki, kc, warning = fit_coefficients_noted(ts)
    if warning:
        log.warning("%s", warning)
    return ki, kc


def prediction_noise_um(coefficients, resolution_K: float = RESOLUTION_K, difference_first: bool = False) -> float:
    """What white noise of ``resolution_K`` (K) on each thermocouple adds to a prediction with these
    coefficients (um/K), one standard deviation, um: ``sqrt(sum sigma_k^2 c_k^2)``, sigma_k sqrt(2)
    resolutions for a difference (the first coefficient where ``difference_first``: K_i)."""
    c = np.asarray(coefficients, float)
    sd = np.full(c.size, float(resolution_K))
    if difference_first and c.size:
        sd[0] = noise_sd(Term("difference", "theta_A_degC", other="theta_B_degC"), resolution_K, 0.0)
    return float(np.sqrt(np.sum((sd * c) ** 2)))


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


def fit_regression(ts: TimeSeries, features=None, resolution_K: float = RESOLUTION_K) -> LinearModel:
    """Fit the static multiple linear regression baseline on one run; ``features`` are
    temperature columns (default: :func:`regression_features`, dependent ones left out); the
    coefficients are bounded by the sensors' noise of ``resolution_K`` (K; module docstring)."""
    features = independent_features(ts, regression_features(ts)) if features is None else tuple(features)
    sd = [0.0] + [noise_sd(Term("sensor", f), resolution_K, 0.0) for f in features]
    beta, warning = _noisy_fit(_design(ts, features), ts["delta_um"], sd, ("intercept",) + features,
                               "regression baseline", resolution_K, intercept=True)
    log.info("regression baseline on %d sensors: intercept %.4g um, coefficients %s um/K", len(features),
             beta[0], ", ".join(f"{f} {b:.4g}" for f, b in zip(features, beta[1:])))
    return LinearModel(features, tuple(float(b) for b in beta[1:]), float(beta[0]), warning)


def apply_regression(model: LinearModel, ts: TimeSeries) -> np.ndarray:
    """Predicted delta (um) for another run (rises from its own first sample)."""
    return _design(ts, model.features) @ np.r_[model.intercept_um, model.coefficients]


def regression_forecast(model: LinearModel, ts: TimeSeries) -> np.ndarray:
    """One-sample-ahead forecast of delta (um) from temperatures extrapolated one step (eq 33):
    the model is linear, so extrapolating its inputs extrapolates its output (NaN for the first two)."""
    now = apply_regression(model, ts)
    return np.r_[np.nan, np.nan, extrapolate(now[:-2], now[1:-1])]
