"""Predictive compensation on a reduced model: forecast δ over the hold, command its minimax.

At every sample c (data known up to c) the Kalman filter (:mod:`.observer`) has estimated the
state; the controller forecasts δ over the coming samples from that state and the known
inputs (it knows when it will switch the pump and the oil set point, or the spindle; for a
measured file, the file's own future input columns stand for that knowledge), holding the room
offset and the δ correction the filters estimated. A command decided at c acts from c + 1 on, one
sample of latency as in the paper's procedure.

* ``event`` (default): the piezo is updated at c + 1 when the forecast residual there,
  |δ̂(c+1) + u_held|, would exceed the threshold ``h``; the new command is −(max + min)/2 of the
  forecast over the longest coming window whose half-range stays within h, which minimises the
  worst forecast residual over that hold. ``h`` is chosen before the run as the smallest
  value (on a ``threshold_step_um`` grid) for which the same rule, run on the reduced model's
  open-loop forecast of the whole schedule, needs at most ``plan_fraction`` of the update budget;
  the budget ``max_updates`` (per run, not per hour) is never exceeded; where it runs out before
  the record ends, the command is held from then on and :attr:`Commands.exhausted_at` says when.
* ``fixed``: updates every ``interval_s`` from c + 1 = 1; each command is the minimax of the
  forecast over its own hold.
"""
from __future__ import annotations

import logging
from dataclasses import dataclass

import numpy as np

from gatetherm import InputError
from gatetherm.solvers.rom import ReducedModel
from gatetherm.solvers.rom_time import Discrete, discretise, march_rom
from gatetherm.studies.control.compensator import CompensatorParams, Prediction, controller_grid
from gatetherm.studies.control.observer import Estimate, ObserverParams, kalman
from gatetherm.solvers.expr import Value
from gatetherm.studies.run.reduce import series_inputs
from gatetherm.studies.run.timeseries import TimeSeries

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class PredictiveParams:
    """Settings of the predictive compensation."""

    mode: str = "event"
    """"event": updates when the forecast residual would exceed the threshold; "fixed": every interval_s."""
    max_updates: int = 60
    """Update budget over the whole run (event mode): the paper's count, 60 in its 5-h runs; a longer
    record needs a larger budget in proportion (a budget used up before the end is warned of)."""
    interval_s: float = 300.0
    """Update period of the fixed mode, s."""
    horizon_s: float = 3600.0
    """Longest forecast (and hold), s."""
    plan_fraction: float = 0.75
    """Share of the budget the threshold is planned to use on the nominal forecast; the rest
    absorbs the re-triggers that forecast errors cause."""
    threshold_step_um: float = 0.1
    """Resolution of the planned threshold, µm."""

    def __post_init__(self):
        if self.mode not in ("event", "fixed"):
            raise InputError("--updates", f"unknown mode {self.mode!r}", "use event or fixed")
        if self.max_updates < 1 or self.interval_s <= 0 or not 0 < self.plan_fraction <= 1:
            raise InputError("--max-updates", "must be >= 1 (and the interval > 0)", "e.g. --max-updates 60")


def forecast(disc: Discrete, rom: ReducedModel, est: Estimate, c: int, u: np.ndarray, modes: np.ndarray,
             steps: int) -> np.ndarray:
    """δ̂ at samples c+1 .. c+steps (fewer at the end of the run) from the estimate at c, µm."""
    r = rom.states
    end = min(c + steps, len(u) - 1)
    if end <= c:
        return np.zeros(0)
    z = est.z[c]
    ud = u[c:end + 1].copy()
    if rom.room is not None:
        ud[:, rom.room] += z[r]  # the estimated room offset, held
    return est.delta_of(rom, c, march_rom(disc, ud, modes[c:end], z[:r])[1:])


def minimax(window: np.ndarray, half_band: float) -> tuple[float, int]:
    """(command, hold length): −midrange over the longest prefix of ``window`` whose half-range
    is at most ``half_band`` (at least one sample)."""
    hi, lo = np.maximum.accumulate(window), np.minimum.accumulate(window)
    over = hi - lo > 2 * half_band + 1e-12
    L = max(int(np.argmax(over)) if over.any() else len(window), 1)
    return -0.5 * (hi[L - 1] + lo[L - 1]), L


def event_updates(path: np.ndarray, h: float, steps: int) -> int:
    """Updates the event rule needs on a known δ path (a perfect forecast of ``steps`` samples)."""
    c, count = 0, 0
    while c < len(path):
        count += 1
        c += minimax(path[c:c + steps], h)[1]
    return count


def plan_threshold(nominal_delta: np.ndarray, params: PredictiveParams, steps: int) -> float:
    """The smallest threshold (µm, a multiple of ``threshold_step_um``) for which the event rule
    needs at most ``plan_fraction × max_updates`` updates on the nominal δ path from sample 1 on."""
    budget = params.plan_fraction * params.max_updates
    path, step = nominal_delta[1:], params.threshold_step_um
    lo, hi = 0, max(int(np.ceil(np.ptp(path) / 2 / step)), 1)  # in steps; the count falls as h grows
    while hi - lo > 1:
        mid = (lo + hi) // 2
        lo, hi = (lo, mid) if event_updates(path, mid * step, steps) <= budget else (mid, hi)
    return hi * step


@dataclass(frozen=True)
class Commands:
    """The controller's decisions on the sampling grid."""

    u_um: np.ndarray
    """Command held at each sample (0 before the first), µm."""
    updates: np.ndarray
    """Grid indices at which a new command takes effect."""
    predicted_um: np.ndarray
    """One-step forecast δ̂(c | c−1) for each sample, µm (NaN at the first)."""
    threshold_um: float | None
    """Event threshold h (None in the fixed mode)."""
    exhausted_at: int | None = None
    """Grid index of the last update where the budget ran out before the last sample (the command is
    held from there to the end); None otherwise."""


def commands(rom: ReducedModel, disc: Discrete, est: Estimate, u: np.ndarray, modes: np.ndarray,
             params: PredictiveParams, nominal_delta: np.ndarray | None = None) -> Commands:
    """Run the controller over a filtered series (see the module docstring)."""
    N = len(u)
    steps = max(int(round(params.horizon_s / disc.dt)), 1)
    every = max(int(round(params.interval_s / disc.dt)), 1)
    h = plan_threshold(nominal_delta, params, steps) if params.mode == "event" else None
    held, cmd, updates = 0.0, np.zeros(N), []
    pred = np.full(N, np.nan)
    for c in range(N - 1):
        f = forecast(disc, rom, est, c, u, modes, steps)
        pred[c + 1] = f[0]
        if params.mode == "fixed":
            due = c % every == 0
            window = f[:every]
            half = np.inf
        else:
            due = (not updates or abs(f[0] + held) > h) and len(updates) < params.max_updates
            window, half = f, h
        if due:
            held, _ = minimax(window, half)
            updates.append(c + 1)
        cmd[c + 1] = held
    out = None
    if params.mode == "event" and len(updates) >= params.max_updates and updates[-1] < N - 1:
        out = updates[-1]
        log.warning("update budget of %d used up at sample %d of %d: the command is held from then on",
                    params.max_updates, out, N - 1)
    return Commands(cmd, np.array(updates, int), pred, h, out)


def budget_warning(t_s: np.ndarray, delta_comp_um: np.ndarray, out_s: float, max_updates: int) -> str:
    """One line: the budget of ``max_updates`` used up at ``out_s`` (s) of the record ``t_s`` (s), the
    largest compensated |δ| (um) after it and the budget a record this long needs at the same pace."""
    span_h, out_h = (t_s[-1] - t_s[0]) / 3600, (out_s - t_s[0]) / 3600
    need = int(np.ceil(max_updates * span_h / max(out_h, 1e-9)))
    return (f"rom: the update budget of {max_updates} was used up at {out_h:.2f} h of the record's {span_h:.2f} h; "
            f"the command was held from then on (|δ| compensated up to "
            f"{np.nanmax(np.abs(delta_comp_um[t_s >= out_s])):.1f} um after it): give --max-updates {need} or more "
            f"for a record this long, or --updates fixed")


THERMOCOUPLES = ("theta_A_degC", "theta_B_degC", "theta_C_degC")
"""The observer's default channels: the paper's three thermocouples."""


def rom_prediction(ts: TimeSeries, rom: ReducedModel, params: CompensatorParams, control: PredictiveParams,
                   observer: ObserverParams = ObserverParams(), sensors=THERMOCOUPLES) -> tuple[Prediction, Commands]:
    """Filter a series (the reduced model's inputs, ``sensors`` columns, δ) and run the controller
    on the compensator's sampling grid; the result drives :func:`~.compensator.close_loop`."""
    sensors = tuple(sensors)
    missing = [s for s in sensors if s not in ts]
    if missing:
        raise InputError(f"{getattr(ts, 'source', '') or 'data'}: column {missing[0]}",
                         "named as an observer sensor but absent", "name columns of the file")
    channels = [rom.output(s) for s in sensors]
    pumps = set().union(*(Value.of(p).names() for p in rom.pumps)) - {"t"}
    read = set().union(*(Value.of(u.text).names() for u in rom.inputs)) | pumps
    extra = tuple(sorted(k for k in read - {"t"} if k in ts)) + sensors
    grid, resampled = controller_grid(ts, params, extra, held=tuple(pumps))
    u, modes = series_inputs(rom, grid.columns)
    disc = discretise(rom, params.sample_interval_s)
    readings = np.column_stack([grid[s] - rom.y0[c] for s, c in zip(sensors, channels)])
    est = kalman(rom, disc, u, modes, readings, channels, grid["delta_um"], observer)
    nominal = march_rom(disc, u, modes) @ rom.C[rom.output("delta_um")]
    cmds = commands(rom, disc, est, u, modes, control, nominal)
    nan = np.full(len(u), np.nan)
    log.info("rom compensation: %d updates%s", cmds.updates.size,
             "" if cmds.threshold_um is None else f", threshold {cmds.threshold_um:.2f} µm")
    return Prediction(grid.time_s, grid["delta_um"], nan, cmds.predicted_um, nan, nan, cmds.u_um, None, resampled,
                      cmds.updates), cmds
