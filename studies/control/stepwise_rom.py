"""The rom method step by step: the Kalman filter of :mod:`.observer` and the predictive control of
:mod:`.predictive`, one sample at a time (see :mod:`.stepwise`).

The controller knows the inputs in advance (the schedule: when the spindle runs, the oil set
point): the stepper is built on the schedule's inputs on the controller grid, as the batch form
:func:`~.predictive.rom_prediction` takes a series' input columns. The event threshold is planned
from the nominal forecast of that schedule before the first sample, as in the batch form. The
state (filter mean and covariance, δ correction and its covariance, held command, updates) is
saved as JSON; the setup is rebuilt from the same reduced model and schedule.
"""
from __future__ import annotations

import logging
import math

import numpy as np

from gatetherm import InputError
from gatetherm.solvers.expr import Value
from gatetherm.solvers.rom import ReducedModel
from gatetherm.solvers.rom_time import discretise, march_rom
from gatetherm.studies.control.compensator import CompensatorParams, controller_grid
from gatetherm.studies.control.observer import CORRECTION, ObserverParams, _update, room_column, uniform_state
from gatetherm.studies.control.predictive import THERMOCOUPLES, PredictiveParams, minimax, plan_threshold
from gatetherm.studies.control.stepwise import Correction, Stepper
from gatetherm.studies.run.reduce import series_inputs
from gatetherm.studies.run.timeseries import TimeSeries

log = logging.getLogger(__name__)


def schedule_grid(ts: TimeSeries, rom: ReducedModel, params: CompensatorParams) -> TimeSeries:
    """The input columns ``rom`` reads of a series or schedule (``time_s`` and the inputs), on the
    controller grid from its first sample (pump states held from the sample before)."""
    pumps = set().union(*(Value.of(p).names() for p in rom.pumps)) - {"t"}
    read = set().union(*(Value.of(u.text).names() for u in rom.inputs)) | pumps
    extra = tuple(sorted(k for k in read - {"t"} if k in ts))
    return controller_grid(ts, params, extra, held=tuple(pumps), needed=("time_s",))[0]


class RomStepper(Stepper):
    """Kalman filter on the reduced model and predictive control (:func:`~.predictive.rom_prediction`)."""

    method = "rom"

    def __init__(self, rom: ReducedModel, schedule: TimeSeries, params: CompensatorParams,
                 control: PredictiveParams, observer: ObserverParams = ObserverParams(), sensors=THERMOCOUPLES):
        super().__init__(params)
        self.rom, self.control, self.sensors = rom, control, tuple(sensors)
        self.columns = (*self.sensors, "delta_um")
        grid = schedule_grid(schedule, rom, params)
        self.t0, self.n = float(grid.time_s[0]), len(grid.time_s)
        self.u, self.modes = series_inputs(rom, grid.columns)
        self.disc = disc = discretise(rom, params.sample_interval_s)
        self.channels = [rom.output(s) for s in self.sensors]
        self.y0 = np.array([rom.y0[c] for c in self.channels])
        r, n = rom.states, rom.states + 1
        x1 = uniform_state(rom, disc)
        iso = (observer.state_K * np.linalg.norm(x1)) ** 2 / r
        self.F, self.Q = {}, {}
        for p in disc.Phi:
            g = disc.G0[p] + disc.G1[p]
            self.F[p] = np.eye(n)
            self.F[p][:r, :r], self.F[p][:r, r] = disc.Phi[p], room_column(rom, g)
            self.Q[p] = np.zeros((n, n))
            self.Q[p][:r, :r] = observer.input_K ** 2 * g @ g.T + iso * np.eye(r)
            self.Q[p][r, r] = observer.room_K ** 2
        self.H = np.zeros((len(self.channels), n))
        self.H[:, :r] = rom.C[self.channels]
        self.obs = observer
        self.z = np.r_[(self.u[0, rom.room] if rom.room is not None else 0.0) * x1, 0.0]
        self.P = np.zeros((n, n))
        self.P[:r, :r] = observer.initial_K ** 2 * np.outer(x1, x1) + iso * np.eye(r)
        self.P[r, r] = observer.initial_K ** 2
        self.correction = np.array([rom.C[rom.output(o)] for o in CORRECTION if o in rom.outputs])
        m = len(self.correction) + 1
        self.b, self.Pb = np.zeros(m), np.diag(np.r_[np.full(m - 1, observer.prior_um_per_K ** 2),
                                                     observer.delta_um ** 2])
        self.Qb = np.diag(np.r_[np.full(m - 1, observer.coefficient_um_per_K ** 2), observer.bias_um ** 2])
        self.C_delta = rom.C[rom.output("delta_um")]
        self.steps = max(int(round(control.horizon_s / disc.dt)), 1)
        self.interval = max(int(round(control.interval_s / disc.dt)), 1)
        self.threshold = None
        if control.mode == "event":
            nominal = march_rom(disc, self.u, self.modes) @ self.C_delta
            self.threshold = plan_threshold(nominal, control, self.steps)
        self.updates, self.started = 0, False

    def _filter(self, sample) -> None:
        """The filters' predict (from the previous sample) and update (this sample's readings)."""
        r, k = self.rom.states, self.count
        if k:
            p = int(self.modes[k - 1])
            self.z = self.F[p] @ self.z
            self.z[:r] += self.disc.G0[p] @ self.u[k - 1] + self.disc.G1[p] @ self.u[k]
            self.P = self.F[p] @ self.P @ self.F[p].T + self.Q[p]
        y = np.array([float(sample[s]) for s in self.sensors]) - self.y0
        ok = np.isfinite(y)
        if ok.any():
            self.z, self.P = _update(self.z, self.P, self.H[ok], y[ok], np.full(ok.sum(), self.obs.sensor_K ** 2))
        x, delta = self.z[:r], float(sample["delta_um"])
        model = x @ self.C_delta
        if k and self.started:
            self.Pb = self.Pb + self.Qb
        if not self.started and math.isfinite(delta):  # β_0 from the first δ read (batch: sample 0)
            self.b[-1], self.started = delta - model, True
        if math.isfinite(delta):
            phi = np.r_[x @ self.correction.T, 1.0][None, :]
            self.b, self.Pb = _update(self.b, self.Pb, phi, np.array([delta - model]),
                                      np.array([self.obs.delta_um ** 2]))

    def forecast(self) -> np.ndarray:
        """δ̂ at the coming samples (up to the horizon, fewer at the schedule's end), µm."""
        c, r = self.count, self.rom.states
        end = min(c + self.steps, self.n - 1)
        if end <= c:
            return np.zeros(0)
        ud = self.u[c:end + 1].copy()
        if self.rom.room is not None:
            ud[:, self.rom.room] += self.z[r]
        X = march_rom(self.disc, ud, self.modes[c:end], self.z[:r])[1:]
        return X @ (self.C_delta + self.b[:-1] @ self.correction) + self.b[-1]

    def step(self, t: float, sample) -> Correction:
        if self.count >= self.n:
            raise InputError(f"sample at t = {t:g} s", f"beyond the schedule's {self.n} samples",
                             "give a schedule that covers the run")
        if self.t_last is not None and not t > self.t_last:
            raise InputError(f"sample at t = {t:g} s", f"not after the last one ({self.t_last:g} s)",
                             "feed samples in increasing time")
        self._filter(sample)
        c, f = self.count, self.forecast()
        updated, pred = False, math.nan
        if f.size:
            pred = float(f[0])
            if self.control.mode == "fixed":
                due, window, half = c % self.interval == 0, f[:self.interval], np.inf
            else:
                due = (not self.updates or abs(f[0] + self.held) > self.threshold) \
                    and self.updates < self.control.max_updates
                window, half = f, self.threshold
            if due:
                self.held, updated = float(minimax(window, half)[0]), True
                self.updates += 1
                if self.control.mode == "event" and self.updates == self.control.max_updates and c + 1 < self.n - 1:
                    log.warning("update budget of %d used up at t = %g s (acting from the next sample), before the "
                                "schedule's end: the command is held from then on", self.updates, t)
        self.count, self.t_last = c + 1, float(t)
        return Correction(float(t), self.held, pred, updated)

    def skip(self, t: float) -> Correction:
        """No usable sample at ``t``: the filters predict across it, the command holds."""
        self._filter({k: math.nan for k in self.columns})
        self.count, self.t_last = self.count + 1, float(t)
        return Correction(float(t), self.held, math.nan, False)

    def _own(self):
        return {"started": self.started, "z": self.z.tolist(), "P": self.P.tolist(), "b": self.b.tolist(),
                "Pb": self.Pb.tolist(), "updates": self.updates, "threshold_um": self.threshold}

    def _load(self, s):
        self.z, self.P, self.b, self.Pb = (np.array(s[k], float) for k in ("z", "P", "b", "Pb"))
        self.updates, self.started = int(s["updates"]), bool(s["started"])
        if self.threshold is not None and s["threshold_um"] != self.threshold:
            raise InputError("compensator state", f"planned for a threshold of {s['threshold_um']} um, "
                             f"this setup plans {self.threshold} um", "resume with the same schedule and model")
