"""Fit hypotheses to a measured run on a training window; score them on the held-out rest.

Residuals (measured − model) are weighted per channel by 1/noise scale (at least the
sensor resolution) and by a channel-group weight (:func:`group_weights`): the
displacement channels together weigh as much as the thermocouples together.

*Score* of a set of hypotheses with k parameters, on the held-out window:
``Σ_c w_c n_c ln max(χ̄²_c, 1) + k ln N``, with χ̄²_c the mean squared weighted residual of
channel c over its n_c held-out samples, w_c the group weight and N = Σ w_c n_c: the
Gaussian log-likelihood of each channel with its own unknown noise level, floored at
the sensor noise. A channel's residual counts by the *factor* a hypothesis takes off
it, not by its size in kelvin or micrometres, so a large temperature residual cannot
hide the hypothesis that explains δ.

*Fits*, on the training window, by weighted least squares: sensor offsets, gains and
drifts in closed form for every value of the other parameters (variable projection);
one new hypothesis by a scan of its plausible range (effects) and Gauss–Newton steps on
secant slopes (one model run each) from the best point or the model's value; all
chosen hypotheses jointly by bounded least squares from their current values; 1-σ
uncertainties from the Jacobian.
"""
from __future__ import annotations

import logging
from dataclasses import dataclass

import numpy as np
from scipy.optimize import least_squares, minimize_scalar

from gatetherm import InputError
from gatetherm.solvers.sensors import ORDER, apply_fault, linear_basis
from gatetherm.studies.diagnosis.hypotheses import Piece, configure, model_side
from gatetherm.studies.diagnosis.locate import significant
from gatetherm.studies.diagnosis.replay import Replayer, resolution
from gatetherm.studies.run.timeseries import TimeSeries

log = logging.getLogger(__name__)

SCAN = 5
"""Points of the coarse scan of an effect's range (model runs)."""
CHEAP_SCAN = 9
"""Points of the scan of a hypothesis that needs no model run."""
SECANT_STEP = 0.02
"""First step of a local search, as a fraction of the plausible range."""


def group_weights(channels) -> dict[str, float]:
    """Channel weights: every group (``_degC`` thermocouples, ``_um`` displacements) weighs
    the same in total, and the weights sum to the number of channels."""
    group = {c: c.rsplit("_", 1)[-1] for c in channels}
    n_groups = len(set(group.values()))
    return {c: len(channels) / (n_groups * sum(g == group[c] for g in group.values())) for c in channels}


def coordinate(p: Piece):
    """(to, back): value ↔ position in [0, 1] across the plausible range (log for positive ranges)."""
    if p.log_scale:
        a, b = np.log(p.lo), np.log(p.hi)
        return (lambda v: (np.log(v) - a) / (b - a)), (lambda x: float(np.exp(a + x * (b - a))))
    return (lambda v: (v - p.lo) / (p.hi - p.lo)), (lambda x: float(p.lo + x * (p.hi - p.lo)))


class Refused(InputError):
    """A model run that the model refuses for the hypotheses in it (an
    :class:`~gatetherm.InputError` of the model: a part left free to move, a singular system):
    the search drops them (:mod:`select`) and goes on, never the whole diagnosis. Where no step
    of the search expects it, it is still the model's one-line error."""

    def __init__(self, pieces, error: InputError):
        super().__init__(error.field, error.problem, error.fix)
        self.pieces, self.error = tuple(pieces), error

    def __reduce__(self):  # across processes: the model's error itself
        return InputError, (self.field, self.problem, self.fix)


@dataclass(frozen=True)
class Scored:
    """A set of hypotheses with values, scored on the held-out window."""

    values: dict
    """{Piece: value}."""
    fit: float
    """Held-out score without the penalty."""
    score: float
    """``fit + k ln N``."""
    rms: dict
    """Held-out RMS residual per channel (channel unit)."""
    explains: bool
    """No channel keeps a significant residual anywhere in the run (training window included:
    a set that only fits the held-out part does not explain the run)."""
    approx: bool = False
    """Scored from superposed earlier runs (screening), not from a run of the set itself."""


class Objective:
    """Residuals of hypotheses on the training and held-out windows of a measured run.
    Model runs are memoised by their model-side hypotheses; sensor faults act on them."""

    def __init__(self, replayer: Replayer, measured: TimeSeries, channels, scale: dict, train: np.ndarray):
        self.replayer, self.channels, self.scale = replayer, tuple(channels), scale
        self.train, self.held = train, ~train
        self.t = replayer.times
        self.y = {c: np.asarray(measured[c], dtype=float) for c in self.channels}
        self.weight = group_weights(self.channels)
        self.n_held = sum(self.weight[c] * np.isfinite(self.y[c][self.held]).sum() for c in self.channels)
        self._memo: dict = {}

    def model_columns(self, values: dict) -> dict[str, np.ndarray]:
        """Run columns with the effects and parameters of ``values`` (scenario path, memoised)."""
        key = model_side({p: v for p, v in values.items()  # a neutral value changes nothing
                          if p.neutral is None or abs(v - p.neutral) > 1e-9 * abs(p.neutral)})
        if key not in self._memo:
            try:
                self._memo[key] = self.replayer.run(configure(self.replayer.config, dict(key)))
            except InputError as err:
                if not key:  # the case itself: its own bad input, not a hypothesis's
                    raise
                log.info("model run refused with %s: %s", " + ".join(p.label for p, _ in key), err)
                self._memo[key] = err
        found = self._memo[key]
        if isinstance(found, InputError):
            raise Refused([p for p, _ in key], found)
        return found

    def solo_runs(self, piece: Piece) -> list[tuple[float, dict]]:
        """Runs made so far with ``piece`` alone, as (value, columns)."""
        return [(k[0][1], cols) for k, cols in self._memo.items()
                if len(k) == 1 and k[0][0] == piece and not isinstance(cols, InputError)]

    def residuals(self, values: dict, cols: dict | None = None, solve: bool = True) -> tuple[dict, dict]:
        """(measured − model per channel, values) with the sensor faults of ``values`` applied to
        the model columns (``cols``, default: a run of ``values``); with ``solve`` the offsets,
        gains and drifts are first fitted in closed form on the training window."""
        cols = self.model_columns(values) if cols is None else cols
        values = dict(values)
        faults: dict[str, list[Piece]] = {}
        for p in values:
            if p.kind == "sensor":
                faults.setdefault(p.channel, []).append(p)
        res = {}
        for c in self.channels:
            x, y = cols[c], self.y[c]
            mine = {p.param: p for p in faults.get(c, ())}
            if "lag" in mine:
                x = apply_fault(self.t, x, "lag", values[mine["lag"]])
            linear = [p for p in mine.values() if p.linear]
            if solve and linear:
                m = self.train & np.isfinite(y)
                A = np.column_stack([linear_basis(self.t, x, p.param) for p in linear])
                coef = np.linalg.lstsq(A[m], (y - x)[m], rcond=None)[0]
                for p, a in zip(linear, coef):
                    values[p] = float(np.clip(p.neutral + a, p.lo, p.hi))
            for name in ORDER[1:]:
                if name in mine:
                    x = apply_fault(self.t, x, name, values[mine[name]])
            res[c] = y - x
        return res, values

    def vector(self, res: dict, mask: np.ndarray) -> np.ndarray:
        """Weighted residuals of the finite samples in ``mask``."""
        v = np.concatenate([(np.sqrt(self.weight[c]) * res[c] / self.scale[c])[mask] for c in self.channels])
        return v[np.isfinite(v)]

    def chi2(self, res: dict, mask: np.ndarray | None = None) -> float:
        v = self.vector(res, self.train if mask is None else mask)
        return float(v @ v)

    def held_fit(self, res: dict) -> float:
        """The held-out score without penalty (see the module docstring)."""
        total = 0.0
        for c in self.channels:
            r = (res[c] / self.scale[c])[self.held]
            r = r[np.isfinite(r)]
            if len(r):
                total += self.weight[c] * len(r) * np.log(max(float(np.mean(r * r)), 1.0))
        return total

    def penalty(self, k: int) -> float:
        return k * float(np.log(max(self.n_held, 2.0)))

    def scored(self, values: dict, cols: dict | None = None, approx: bool = False) -> Scored:
        """Score ``values`` (complete: nothing is refitted)."""
        res, _ = self.residuals(values, cols, solve=False)
        fit = self.held_fit(res)
        rms = {c: float(np.sqrt(np.nanmean(res[c][self.held] ** 2))) for c in self.channels}
        sig = any(np.any(significant(self.t, res[c], resolution(c))) for c in self.channels)
        return Scored(dict(values), fit, fit + self.penalty(len(values)), rms, not sig, approx)


def refit(obj: Objective, values: dict, free=None, max_nfev: int = 8) -> dict:
    """``values`` with the ``free`` pieces (default: all) refitted jointly on the training
    window by bounded least squares from their current values; sensor offsets, gains and
    drifts are solved in closed form inside."""
    return bounded_fit(obj, values, list(values if free is None else free), obj.residuals, diff_step=0.01,
                       x_scale=1.0, max_nfev=max_nfev, ftol=1e-4, xtol=1e-3, method="trf")


def bounded_fit(obj: Objective, values: dict, free, residuals, **options) -> dict:
    """``values`` with the non-linear ``free`` pieces fitted jointly on the training window by
    bounded least squares (``scipy.optimize.least_squares`` with ``options``) in their [0, 1]
    coordinates, from their current values; ``residuals(values)`` gives (residuals, values
    with the linear sensor faults solved), from model runs or a surrogate."""
    nl = [p for p in free if not p.linear]
    if not nl:
        return residuals(values)[1]
    coords = [coordinate(p) for p in nl]
    x0 = np.clip([to(values[p]) for p, (to, _) in zip(nl, coords)], 1e-6, 1 - 1e-6)

    def at(x) -> dict:
        return {**values, **{p: back(float(xi)) for p, (_, back), xi in zip(nl, coords, x)}}

    sol = least_squares(lambda x: obj.vector(residuals(at(x))[0], obj.train), x0, bounds=(0.0, 1.0), **options)
    return residuals(at(sol.x))[1]


def fit_one(obj: Objective, context: dict, piece: Piece, start: float | None = None) -> dict:
    """``context`` (kept, except that sensor offsets, gains and drifts are re-solved) plus
    ``piece`` fitted: in closed form, by a fine scan and Brent's method (no model run
    needed), or by Gauss–Newton steps on secant slopes from ``start`` (default: from the best
    two points of a coarse scan of the range)."""
    if piece.linear:
        return obj.residuals({**context, piece: piece.neutral})[1]
    to, back = coordinate(piece)

    def f(x: float) -> float:
        return obj.chi2(obj.residuals({**context, piece: back(x)})[0])

    if not piece.rerun:
        grid = np.linspace(0.0, 1.0, CHEAP_SCAN)
        vals = [f(x) for x in grid]
        i = int(np.argmin(vals))
        sol = minimize_scalar(f, bounds=(grid[max(i - 1, 0)], grid[min(i + 1, CHEAP_SCAN - 1)]), method="bounded",
                              options={"xatol": 1e-3, "maxiter": 25})
        x = float(sol.x) if sol.fun < vals[i] else float(grid[i])
        return obj.residuals({**context, piece: back(x)})[1]
    def r(x: float) -> np.ndarray:
        return obj.vector(obj.residuals({**context, piece: back(x)})[0], obj.train)

    if start is None:
        grid = scan_grid(piece, SCAN)
        scan = [r(x) for x in grid]
        i = int(np.argmin([v @ v for v in scan]))
        j = i + 1 if i == 0 or (i < SCAN - 1 and scan[i + 1] @ scan[i + 1] < scan[i - 1] @ scan[i - 1]) else i - 1
        x = secant(r, (grid[j], scan[j]), (grid[i], scan[i]))
    else:
        x0 = float(np.clip(to(start), 0.0, 1.0))
        x = secant(r, (x0, r(x0)), (x0 + SECANT_STEP if x0 + SECANT_STEP <= 1 else x0 - SECANT_STEP,))
    return obj.residuals({**context, piece: back(x)})[1]


def scan_grid(piece: Piece, n: int) -> np.ndarray:
    """``n`` evenly spaced positions across the range; the middle one moved to the neutral
    value (which needs no run) when that lies inside."""
    grid = np.linspace(0.0, 1.0, n)
    if piece.neutral is not None and piece.lo <= piece.neutral <= piece.hi:
        grid[n // 2] = coordinate(piece)[0](piece.neutral)
    return grid


def secant(r, a: tuple, b: tuple, iters: int = 4, tol: float = 2e-3) -> float:
    """Minimise |r(x)|² over x in [0, 1] by Gauss–Newton steps on secant slopes (one
    evaluation per step) from the points ``a`` = (x, r(x)) and ``b`` = (x,) or (x, r(x)).
    Returns the best point evaluated."""
    if len(b) == 1:
        b = (b[0], r(b[0]))
    best = min((a, b), key=lambda p: p[1] @ p[1])
    for _ in range(iters):
        J = (b[1] - a[1]) / (b[0] - a[0])
        if not J @ J > 0:
            break
        x = float(np.clip(b[0] - (J @ b[1]) / (J @ J), 0.0, 1.0))
        if abs(x - b[0]) < tol or abs(x - a[0]) < tol:
            break
        a, b = b, (x, r(x))
        best = min((best, b), key=lambda p: p[1] @ p[1])
    return float(best[0])


def uncertainty(obj: Objective, values: dict, step: float = 0.01) -> dict:
    """1-σ uncertainty of every value, from the Jacobian of the training residuals (forward
    differences across 1 % of each plausible range), scaled by the reduced χ² when above 1."""
    pieces = list(values)
    if not pieces:
        return {}
    coords = [coordinate(p) for p in pieces]
    x0 = np.array([to(values[p]) for p, (to, _) in zip(pieces, coords)])
    r0 = obj.vector(obj.residuals(values, solve=False)[0], obj.train)
    J = np.empty((len(r0), len(pieces)))
    for j, (p, (_, back)) in enumerate(zip(pieces, coords)):
        h = step if x0[j] + step <= 1.0 else -step
        rj = obj.vector(obj.residuals({**values, p: back(x0[j] + h)}, solve=False)[0], obj.train)
        J[:, j] = (rj - r0) / h
    s2 = max(float(r0 @ r0) / max(len(r0) - len(pieces), 1), 1.0)
    try:
        sd_x = np.sqrt(np.clip(np.diag(np.linalg.inv(J.T @ J)) * s2, 0.0, None))
    except np.linalg.LinAlgError:
        sd_x = np.full(len(pieces), np.nan)
    out = {}
    for p, (to, back), x, s in zip(pieces, coords, x0, sd_x):
        slope = (back(min(x + 1e-4, 1.0)) - back(max(x - 1e-4, 0.0))) / (min(x + 1e-4, 1.0) - max(x - 1e-4, 0.0))
        out[p] = float(abs(slope) * s)
    return out
