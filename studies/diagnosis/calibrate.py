"""Fit a model to a measured run on a training window.

Two kinds of fit, both on residuals weighted by the channels' noise scale
(at least the sensor resolution):

* recalibration of the model's existing uncertain parameters, jointly by
  bounded least squares (film coefficient to air, tank-wall film with the pump
  on and off, initial frame temperature), with 1-σ uncertainties from the
  Jacobian;
* one catalogue effect at a time: a coarse scan of its plausible range and a
  bounded 1-D search (log scale for positive parameters) around the best point.
"""
from __future__ import annotations

import dataclasses
import logging
from dataclasses import dataclass

import numpy as np
from scipy.optimize import least_squares, minimize_scalar

from gatetherm.solvers.effects import CATALOGUE
from gatetherm.studies.diagnosis.replay import Hypothesis, Replayer, residuals
from gatetherm.studies.run.timeseries import TimeSeries

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class RecalParam:
    """An existing model parameter (a ``ThermalParams`` field) and how far it may move."""

    name: str
    unit: str
    kind: str
    """"log": searched as log(value / nominal) within ±log(bound); "shift": nominal ± bound."""
    bound: float
    doc: str


RECAL = (
    RecalParam("h_air", "W/(m2 K)", "log", 4.0, "film coefficient of the free surfaces to room air"),
    RecalParam("h_oil_on", "W/(m2 K)", "log", 5.0, "tank-wall film coefficient, pump on"),
    RecalParam("h_oil_off", "W/(m2 K)", "log", 5.0, "tank-wall film coefficient, pump off"),
    RecalParam("T0", "degC", "shift", 3.0, "initial temperature of frame and oil (room unchanged)"),
)


@dataclass
class Objective:
    """Weighted residuals of hypotheses on a window of a measured run (memoised)."""

    replayer: Replayer
    measured: TimeSeries
    channels: tuple[str, ...]
    scale: dict[str, float]
    """Noise scale per channel (channel unit), the residual weight is 1/scale."""
    mask: np.ndarray
    """Samples of the fitting window."""
    _memo: dict = dataclasses.field(default_factory=dict, repr=False)

    def columns(self, hyp: Hypothesis) -> dict[str, np.ndarray]:
        if hyp not in self._memo:
            self._memo[hyp] = self.replayer.run(hyp)
        return self._memo[hyp]

    def vector(self, hyp: Hypothesis, mask: np.ndarray | None = None) -> np.ndarray:
        """Weighted residuals (measured − model)/scale of the finite samples in ``mask``."""
        m = self.mask if mask is None else mask
        res = residuals(self.measured, self.columns(hyp), self.channels)
        parts = [(res[c] / self.scale[c])[m] for c in self.channels]
        v = np.concatenate(parts)
        return v[np.isfinite(v)]

    def chi2(self, hyp: Hypothesis, mask: np.ndarray | None = None) -> float:
        v = self.vector(hyp, mask)
        return float(v @ v)


@dataclass(frozen=True)
class Fit:
    """A fitted hypothesis."""

    name: str
    """"baseline", "recalibration" or a catalogue effect name."""
    hypothesis: Hypothesis
    k: int
    """Number of fitted parameters."""
    values: dict[str, float]
    """Fitted values ({"effect.param" or thermal field: value}) in their units."""
    sigma: dict[str, float]
    """1-σ uncertainties of ``values`` (empty when not estimated)."""
    chi2_train: float


def baseline(obj: Objective) -> Fit:
    return Fit("baseline", Hypothesis(), 0, {}, {}, obj.chi2(Hypothesis()))


def _thermal(params, nominal, z) -> dict[str, float]:
    return {p.name: (getattr(nominal, p.name) * float(np.exp(x)) if p.kind == "log"
                     else getattr(nominal, p.name) + float(x)) for p, x in zip(params, z)}


def fit_recalibration(obj: Objective, params=RECAL, max_nfev: int = 15) -> Fit:
    """Joint bounded least-squares fit of ``params`` on the objective's window."""
    nominal = obj.replayer.config.model.thermal
    bounds = np.array([np.log(p.bound) if p.kind == "log" else p.bound for p in params])

    def fun(z):
        return obj.vector(Hypothesis.of(thermal=_thermal(params, nominal, z)))

    sol = least_squares(fun, np.zeros(len(params)), bounds=(-bounds, bounds), diff_step=0.01,
                        x_scale=np.ones(len(params)), max_nfev=max_nfev, ftol=1e-4, method="trf")
    values = _thermal(params, nominal, sol.x)
    n = len(sol.fun)
    s2 = max(float(sol.fun @ sol.fun) / max(n - len(params), 1), 1.0)
    try:
        cov = np.linalg.inv(sol.jac.T @ sol.jac) * s2
        sd = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    except np.linalg.LinAlgError:
        sd = np.full(len(params), np.nan)
    sigma = {p.name: float(values[p.name] * s if p.kind == "log" else s) for p, s in zip(params, sd)}
    hyp = Hypothesis.of(thermal=values)
    log.info("recalibration: %s (χ² %.4g → %.4g)", {k: round(v, 4) for k, v in values.items()},
             obj.chi2(Hypothesis()), obj.chi2(hyp))
    return Fit("recalibration", hyp, len(params), values, sigma, obj.chi2(hyp))


def _coordinate(name: str):
    """(to search coordinate, from search coordinate, lower, upper) of an effect's parameter."""
    e = CATALOGUE[name]
    if e.log_scale:
        return np.log10, lambda u: float(10.0 ** u), np.log10(e.lo), np.log10(e.hi)
    return float, float, e.lo, e.hi


def fit_effect(obj: Objective, name: str, scan: int = 5, rel_tol: float = 0.004) -> Fit:
    """Fit one catalogue effect's parameter within its plausible range: ``scan``
    evenly spaced points, then a bounded Brent search between the best one's neighbours."""
    _, back, lo, hi = _coordinate(name)

    def f(u: float) -> float:
        return obj.chi2(Hypothesis.of(effects={name: back(u)}))

    grid = np.linspace(lo, hi, scan)
    vals = [f(u) for u in grid]
    i = int(np.argmin(vals))
    a, b = grid[max(i - 1, 0)], grid[min(i + 1, scan - 1)]
    sol = minimize_scalar(f, bounds=(a, b), method="bounded",
                          options={"xatol": rel_tol * (hi - lo), "maxiter": 20})
    u = float(sol.x) if sol.fun < vals[i] else float(grid[i])
    key = f"{name}.{CATALOGUE[name].param}"
    log.info("effect %s: %s = %.4g (χ² %.4g)", name, key, back(u), min(sol.fun, vals[i]))
    return Fit(name, Hypothesis.of(effects={name: back(u)}), 1, {key: back(u)}, {}, min(float(sol.fun), vals[i]))


def effect_uncertainty(obj: Objective, fit: Fit, step: float = 0.01) -> Fit:
    """``fit`` with a 1-σ uncertainty from the curvature of χ² at the optimum
    (scaled by the reduced χ² when that exceeds 1)."""
    name = fit.name
    to, back, lo, hi = _coordinate(name)
    (key, value), = fit.values.items()
    u, h = to(value), step * (hi - lo)

    def f(x):
        return obj.chi2(Hypothesis.of(effects={name: back(x)}))

    f0, fm, fp = fit.chi2_train, f(u - h), f(u + h)
    curv = (fp - 2 * f0 + fm) / h ** 2
    n = len(obj.vector(fit.hypothesis))
    s2 = max(f0 / max(n - 1, 1), 1.0)
    su = float(np.sqrt(2.0 * s2 / curv)) if curv > 0 else float("nan")
    sd = value * np.log(10.0) * su if CATALOGUE[name].log_scale else su
    return dataclasses.replace(fit, sigma={key: float(sd)})
