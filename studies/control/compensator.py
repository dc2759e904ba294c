"""Thermal-displacement prediction and piezo compensation (paper section 3.2, eqs 30-38).

Notation (counts n are samples, count 1 = t = 0; arrays here are 0-based, index k = n - 1):
``theta`` are temperature rises, ``dtheta = theta_A - theta_B``,
``delta_th = K_i dtheta - K_C theta_C`` (21) and ``delta_ex`` the measured delta.

At every sample ``c`` (data known up to ``c``) the controller predicts sample ``c + 1``:

* temperatures are extrapolated one step (33, 36): ``theta_et(c+1) = 2 theta(c) - theta(c-1)``;
* before the first positive peak ``j`` of delta is recognised (phase 1),
  ``R_i(c+1) = delta_ex(c) / delta_th(c)`` (34), ``R_C = 1`` and
  ``delta_et(c+1) = R_i(c+1) K_i dtheta_et(c+1) - K_C theta_Cet(c+1)`` (35);
* afterwards (phase 2) ``R_i`` stays at ``R_i(j+1)`` and
  ``R_C(c+1) = [R_i(j+1) K_i dtheta(c) - delta_ex(c)] / (K_C theta_C(c))`` (37),
  ``delta_et(c+1) = R_i(j+1) K_i dtheta_et(c+1) - R_C(c+1) K_C theta_Cet(c+1)`` (38).

As written in the paper, (34) divides by the whole ``delta_th`` while (35) applies ``R_i``
to the ``K_i`` term only; the two agree while ``theta_C`` is still small (before the peak).

The peak ``j`` is the running maximum of delta (> 0) once delta has dropped below it by
more than ``peak_drop_um``; with the paper's rule (0) that happens at ``j + 1`` at the
earliest, so phase 2 starts exactly at count ``j + 1`` as in the paper. The controller is
causal: nothing is recomputed after the fact.

Hold rule: where the denominator of (34) or (37) is at or below its threshold in um
(``|delta_th| <= min_theory_um``, ``|K_C theta_C| <= min_tie_bar_um``; e.g. at t = 0 where
both are 0, or while the tie bar has not warmed) the factor keeps its previous value (1 at
the start) and the hold is logged. No prediction exists for the first two samples.

The piezo command ``u = -delta_et`` is refreshed every ``update_interval_s`` from the
first sample and held in between (0 before the first prediction).

Coefficient sources (um/K): ``gatetherm.frame.beam.theory_coefficients`` (beam theory of a
model's frame), ``gatetherm.frame.loadcases.tip_coefficients_um`` (FE load cases at the tips F), and
``studies.regression.fit_coefficients`` (least squares on a run). Any other predictor
(e.g. the static regression baseline) can drive the same loop via :func:`external_prediction`.
"""
from __future__ import annotations

import logging
from dataclasses import dataclass

import numpy as np

from gatetherm import InputError
from gatetherm.studies.control import actuator as piezo
from gatetherm.studies.run.timeseries import TimeSeries, check_steps, rises, validate_complete

log = logging.getLogger(__name__)

NEEDED = ("time_s", "theta_A_degC", "theta_B_degC", "theta_C_degC", "delta_um")


@dataclass(frozen=True)
class CompensatorParams:
    """Settings of the prediction and compensation procedure."""

    sample_interval_s: float = 60.0
    """Controller sampling period, s (paper: 1 min); other data are resampled linearly."""
    update_interval_s: float = 300.0
    """Piezo command refresh period, s, a whole multiple of sample_interval_s (paper: 5 min)."""
    min_theory_um: float = 1.0
    """Hold R_i when |delta_th| is at or below this, um (10 x the 0.1 um sensor resolution)."""
    min_tie_bar_um: float = 1.0
    """Hold R_C when |K_C theta_C| is at or below this, um."""
    peak_drop_um: float = 0.0
    """Drop below the running maximum of delta that confirms the first peak, um (paper: 0)."""
    r_limits: tuple[float, float] | None = None
    """Clip range of R_i and R_C, dimensionless; None = no clipping (paper)."""
    settle_s: float = 600.0
    """Summary bands ignore the first settle_s of the run, s (10 min)."""

    def __post_init__(self):
        ratio = self.update_interval_s / self.sample_interval_s if self.sample_interval_s > 0 else 0
        if ratio < 1 or abs(ratio - round(ratio)) > 1e-9:
            raise InputError("update interval", f"{self.update_interval_s:g} s is not a whole multiple "
                             f"of the {self.sample_interval_s:g} s sampling", "use e.g. 5 min")
        if min(self.min_theory_um, self.min_tie_bar_um, self.peak_drop_um, self.settle_s) < 0:
            raise InputError("compensator thresholds", "negative", "use values >= 0")


@dataclass(frozen=True)
class Prediction:
    """The procedure on the controller's sampling grid."""

    t_s: np.ndarray
    """Sample times, s."""
    delta_um: np.ndarray
    """Measured (uncompensated) delta_ex, um."""
    delta_th_um: np.ndarray
    """Beam-theory delta_th (21), um."""
    delta_pred_um: np.ndarray
    """Predicted delta_et for each sample, made one sample earlier, um (NaN for the first two)."""
    R_i: np.ndarray
    """Correction factor used for each sample's prediction, dimensionless."""
    R_C: np.ndarray
    """Tie-bar correction factor used for each sample's prediction, dimensionless."""
    u_um: np.ndarray
    """Piezo command held between updates, -delta_et at the update instants, um."""
    peak_index: int | None
    """Grid index j of the first positive peak of delta, None if not recognised."""
    resampled: bool
    """True if the input was linearly resampled onto the grid."""
    updates: np.ndarray | None = None
    """Grid indices of the piezo updates; None: every ``update_interval_s`` from the first sample."""


@dataclass(frozen=True)
class ClosedLoop:
    """Compensation evaluated at the input's own sample times."""

    prediction: Prediction
    """The procedure on the controller grid."""
    t_s: np.ndarray
    """Input sample times, s."""
    delta_um: np.ndarray
    """Uncompensated delta, um."""
    delta_pred_um: np.ndarray
    """Prediction, linearly interpolated from the grid where resampled, um."""
    u_um: np.ndarray
    """Held command, um."""
    voltage_V: np.ndarray
    """Held piezo voltage, V (NaN for the ideal actuator)."""
    stroke_um: np.ndarray
    """Held displacement achieved at the cutting area, um."""
    delta_comp_um: np.ndarray
    """Compensated delta = delta + stroke, um."""
    update_t_s: np.ndarray
    """Times of the piezo updates, s: each sets the command to -delta_et of that instant."""
    saturated_updates: int = 0
    """Piezo updates whose command was outside the actuator's reach (clipped); 0 if ideal."""


def extrapolate(previous, last):
    """One-step linear extrapolation (33): theta(n+1) + [theta(n+1) - theta(n)]."""
    return 2 * np.asarray(last) - np.asarray(previous)


def theory_um(Ki: float, Kc: float, dtheta_ab, theta_c):
    """Beam-theory displacement (21), um, for K in um/K and rises in K."""
    return Ki * np.asarray(dtheta_ab) - Kc * np.asarray(theta_c)


def held_ratio(numerator: float, denominator: float, previous: float, threshold_um: float,
               limits: tuple[float, float] | None = None) -> tuple[float, bool]:
    """``numerator / denominator``, or ``previous`` (held=True) if ``|denominator| <= threshold``."""
    if not abs(denominator) > threshold_um:
        return previous, True
    ratio = numerator / denominator
    return (float(np.clip(ratio, *limits)) if limits else ratio), False


def controller_grid(ts: TimeSeries, params: CompensatorParams, extra=(), held=("pump",),
                    needed=NEEDED) -> tuple[TimeSeries, bool]:
    """The ``needed`` columns and ``extra`` ones on the sampling grid from the first sample; linear
    resampling if off it (the ``held`` ones, pump states, from the sample before)."""
    validate_complete(ts, needed)
    t, dt = ts.time_s, params.sample_interval_s
    back = np.flatnonzero(np.diff(t) <= 0)
    if back.size:
        raise InputError(f"data row {back[0] + 2}, column time_s", "time does not increase",
                         "sort the rows or remove the duplicate")
    check_steps(t[-1] - t[0], dt, "time_s")
    grid = t[0] + dt * np.arange(int(np.floor((t[-1] - t[0]) / dt + 1e-9)) + 1)
    if len(grid) < 3:
        raise InputError("time_s", f"the run covers fewer than 3 samples of {dt:g} s",
                         "the one-step extrapolation needs at least 3")
    names = tuple(needed) + tuple(n for n in extra if n not in needed)
    if len(grid) == len(t) and np.allclose(t, grid, rtol=0, atol=1e-6 * dt):
        return TimeSeries({n: ts[n] for n in names}), False
    log.info("data not on a %g s grid (%d samples, spacing %.4g..%.4g s): resampled linearly to %d",
             dt, len(t), np.diff(t).min(), np.diff(t).max(), len(grid))
    before = np.clip(np.searchsorted(t, grid + 1e-9 * dt, side="right") - 1, 0, len(t) - 1)
    return TimeSeries({"time_s": grid, **{n: ts[n][before] if n in held else np.interp(grid, t, ts[n])
                                          for n in names[1:]}}), True


def _peak_confirmed(delta: np.ndarray, c: int, best: int, drop_um: float) -> bool:
    return delta[best] > 0 and delta[best] - delta[c] > drop_um


def predict(ts: TimeSeries, Ki: float, Kc: float, params: CompensatorParams) -> Prediction:
    """Run the procedure (eqs 30-38) over a series; K in um/K. See the module docstring."""
    grid, resampled = controller_grid(ts, params)
    d_ab = rises(grid, "theta_A_degC") - rises(grid, "theta_B_degC")
    th_c = rises(grid, "theta_C_degC")
    delta = grid["delta_um"]
    delta_th = theory_um(Ki, Kc, d_ab, th_c)
    n = len(delta)
    R_i, R_C, pred = np.ones(n), np.ones(n), np.full(n, np.nan)
    peak, best, holds = None, 0, [0, 0]
    for c in range(n - 1):
        if peak is None:
            best = c if delta[c] > delta[best] else best
            if _peak_confirmed(delta, c, best, params.peak_drop_um):
                peak = best
                log.info("first positive peak of delta: %.4g um at t = %.6g s (recognised at %.6g s); "
                         "R_i frozen at %.4g", delta[peak], grid.time_s[peak], grid.time_s[c], R_i[peak + 1])
        if peak is None:  # phase 1, eq (34)
            R_i[c + 1], held = held_ratio(delta[c], delta_th[c], R_i[c], params.min_theory_um,
                                          params.r_limits)
            which, denom = 0, delta_th[c]
        else:  # phase 2, eq (37)
            R_i[c + 1] = R_i[peak + 1]
            R_C[c + 1], held = held_ratio(R_i[peak + 1] * Ki * d_ab[c] - delta[c], Kc * th_c[c],
                                          R_C[c], params.min_tie_bar_um, params.r_limits)
            which, denom = 1, Kc * th_c[c]
        if held:
            holds[which] += 1
            log.debug("t = %.6g s: |%s| = %.3g um at or below threshold, %s held", grid.time_s[c],
                      ("delta_th", "K_C theta_C")[which], abs(denom), ("R_i", "R_C")[which])
        if c >= 1:  # eqs (33)/(36) and (35)/(38)
            pred[c + 1] = theory_um(R_i[c + 1] * Ki, R_C[c + 1] * Kc,
                                    extrapolate(d_ab[c - 1], d_ab[c]), extrapolate(th_c[c - 1], th_c[c]))
    if peak is None:
        log.info("no first positive peak of delta recognised: R_i adapted over the whole run")
    if any(holds):
        log.info("near-zero denominators: R_i held at %d samples, R_C at %d", *holds)
    return Prediction(grid.time_s, delta, delta_th, pred, R_i, R_C, held_commands(pred, params), peak,
                      resampled)


def held_commands(pred_um: np.ndarray, params: CompensatorParams) -> np.ndarray:
    """Piezo commands on the grid: ``-pred`` at each update, held in between (0 before any)."""
    every = round(params.update_interval_s / params.sample_interval_s)
    return -np.nan_to_num(pred_um[(np.arange(len(pred_um)) // every) * every], nan=0.0)


def external_prediction(ts: TimeSeries, pred_um, params: CompensatorParams, ahead: bool = False,
                        needed=NEEDED) -> Prediction:
    """Wrap another predictor's delta (um, at ``ts``'s samples) for :func:`close_loop`;
    it has no correction factors (R_i = R_C = NaN) and no theory term. With ``ahead`` each grid
    sample's value is forecast one sample earlier by the extrapolation (33) of the predictor's
    values, the paper's latency (NaN for the first two). ``ts`` needs the ``needed`` columns."""
    grid, resampled = controller_grid(ts, params, needed=needed)
    pred = np.asarray(pred_um, float)
    pred = np.interp(grid.time_s, ts.time_s, pred) if resampled else pred
    if ahead:
        pred = np.concatenate([[np.nan, np.nan], extrapolate(pred[:-2], pred[1:-1])])
    nan = np.full(len(pred), np.nan)
    return Prediction(grid.time_s, grid["delta_um"], nan, pred, nan, nan, held_commands(pred, params),
                      None, resampled)


def close_loop(ts: TimeSeries, pr: Prediction, params: CompensatorParams,
               actuator: piezo.ActuatorParams | None = None) -> ClosedLoop:
    """Drive the piezo (ideal if ``actuator`` is None) with a prediction's held commands."""
    every = round(params.update_interval_s / params.sample_interval_s)
    updates = np.arange(0, len(pr.t_s), every) if pr.updates is None else pr.updates
    if actuator is None:
        volts, stroke, saturated = np.full(updates.size, np.nan), pr.u_um[updates], 0
    else:
        volts, stroke = piezo.apply_commands(actuator, pr.u_um[updates])
        saturated = int(np.sum(piezo.saturated_commands(actuator, pr.u_um[updates])))
    t = ts.time_s
    # entry 0: the actuator at rest (0 V, no stroke) before the first update
    held = np.searchsorted(pr.t_s[updates], t + 1e-9 * params.sample_interval_s, side="right")
    command, stroke = np.r_[0.0, pr.u_um[updates]][held], np.r_[0.0, stroke][held]
    volts = np.r_[np.nan if actuator is None else 0.0, volts][held]
    pred = np.interp(t, pr.t_s, pr.delta_pred_um) if pr.resampled else pr.delta_pred_um
    delta = ts["delta_um"]
    return ClosedLoop(pr, t, delta, pred, command, volts, stroke, delta + stroke, pr.t_s[updates], saturated)


def compensate(ts: TimeSeries, Ki: float, Kc: float, params: CompensatorParams,
               actuator: piezo.ActuatorParams | None = None) -> ClosedLoop:
    """Closed loop: prediction, piezo drive (ideal if ``actuator`` is None), compensated delta."""
    return close_loop(ts, predict(ts, Ki, Kc, params), params, actuator)


def summarize(loop: ClosedLoop, settle_s: float = 600.0) -> dict[str, float | None]:
    """Summary figures (um; R dimensionless, None without factors); bands skip the first
    ``settle_s`` seconds. ``residual_at_updates_um`` is the compensated delta only at the
    update instants, for which each command was predicted: the paper's reading (its
    compensation result minus its prediction error is "the mechanism's error"), while
    ``residual_band_um`` also counts the drift while a command is held."""
    late = loop.t_s >= loop.t_s[0] + settle_s
    pr = loop.prediction
    at = loop.update_t_s[loop.update_t_s >= loop.t_s[0] + settle_s]

    def band(x):
        x = np.abs(x[late])
        return float(np.nanmax(x)) if np.isfinite(x).any() else None

    return {
        "swing_um": float(np.nanmax(loop.delta_um) - np.nanmin(loop.delta_um)),
        "prediction_error_band_um": band(loop.delta_um - loop.delta_pred_um),
        "residual_band_um": band(loop.delta_comp_um),
        "residual_at_updates_um": float(np.max(np.abs(np.interp(at, loop.t_s, loop.delta_comp_um))))
        if at.size else None,
        "R_i_final": float(pr.R_i[-1]) if np.isfinite(pr.R_i[-1]) else None,
        "R_C_final": float(pr.R_C[-1]) if np.isfinite(pr.R_C[-1]) else None,
        "peak_time_s": None if pr.peak_index is None else float(pr.t_s[pr.peak_index]),
        "peak_delta_um": None if pr.peak_index is None else float(pr.delta_um[pr.peak_index]),
        "piezo_saturated_updates": loop.saturated_updates,
        "updates": int(loop.update_t_s.size),
    }
