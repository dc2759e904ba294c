"""Step-wise compensators: every method's state and a ``step(t, sample) -> Correction`` form.

The batch functions (:func:`~.compensator.predict`, :func:`~.regression.regression_forecast` with
:func:`~.compensator.external_prediction`, :func:`~gatetherm.studies.errormodel.replay.replay`,
:func:`~.predictive.rom_prediction`) run over a whole recorded series; a compensator beside a
machine sees one sample at a time. A stepper here is fed the samples of the controller grid in
order (``sample_interval_s`` apart, the first at index 0) and after sample ``c`` returns the
command the batch form holds from sample ``c + 1`` on (one sample of latency, as in the paper). Fed
the samples of a series on the grid it gives the batch form's ``Prediction.u_um[1:]`` and
``delta_pred_um[1:]`` to round-off (``tests/test_stepwise.py``: 1e-9 µm on the C-frame and the
paper frame).

Each stepper's state is plain numbers: :meth:`Stepper.state` returns a JSON-ready dict and
:meth:`Stepper.restore` sets it back, so a service killed between two samples resumes where it was
(the caller rebuilds the setup, K_i, K_C or the reduced model, from the same inputs).

A missing reading (NaN): the causal batch forms' treatment, else a NaN prediction (live guards it).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from gatetherm import InputError
from gatetherm.studies.control.compensator import NEEDED, CompensatorParams, held_ratio
from gatetherm.studies.control.regression import LinearModel

STATE_FORMAT = "gatetherm-stepper/1"


@dataclass(frozen=True)
class Correction:
    """What a stepper decided after one sample."""

    t_s: float
    """Time of the sample it was decided on (the machine's clock), s."""
    offset_um: float
    """Command held from the next sample on (−predicted δ at the update instants), µm."""
    predicted_um: float
    """δ forecast for the next sample, µm (NaN where the method has none yet)."""
    updated: bool
    """True when the command changes (an update) at the next sample."""


def _num(x) -> float | None:
    """JSON-ready float (None for NaN)."""
    return None if x is None or not math.isfinite(x) else float(x)


def _val(x) -> float:
    return math.nan if x is None else float(x)


class Stepper:
    """Base of the step-wise compensators: the sample count, the held command and the update rule
    of :func:`~.compensator.held_commands` (every ``update_interval_s`` from the first sample)."""

    method = "base"
    columns: tuple[str, ...] = ()
    """Columns of a sample that the stepper reads."""

    def __init__(self, params: CompensatorParams):
        self.params = params
        self.every = round(params.update_interval_s / params.sample_interval_s)
        self.count = 0
        """Samples stepped."""
        self.t_last: float | None = None
        self.held = 0.0

    def step(self, t: float, sample) -> Correction:
        """Take sample ``c`` = :attr:`count` (a mapping of column -> value) at time ``t`` (s)."""
        if self.t_last is not None and not t > self.t_last:
            raise InputError(f"sample at t = {t:g} s", f"not after the last one ({self.t_last:g} s)",
                             "feed samples in increasing time")
        pred = self._predict(float(t), sample)
        c = self.count
        updated = (c + 1) % self.every == 0
        if updated and not math.isnan(pred):  # no forecast yet: the command stays (0 at the start, as batch)
            self.held = -pred
        self.count, self.t_last = c + 1, float(t)
        return Correction(float(t), self.held, pred, updated)

    def skip(self, t: float) -> Correction:
        """No usable sample at ``t`` (missing, stale, a jump, or a period the service was down): the
        command holds, the sample count advances; forecasts restart from the next samples."""
        self._skip()
        self.count, self.t_last = self.count + 1, float(t)
        return Correction(float(t), self.held, math.nan, False)

    def _skip(self) -> None:
        pass

    def _predict(self, t: float, sample) -> float:
        raise NotImplementedError

    def _own(self) -> dict:
        return {}

    def _load(self, state: dict) -> None:
        pass

    def state(self) -> dict:
        """The JSON-ready state (floats; NaN as None)."""
        return {"format": STATE_FORMAT, "method": self.method, "count": self.count, "t_last": _num(self.t_last),
                "held": self.held, **self._own()}

    def restore(self, state: dict) -> None:
        """Set the state saved by :meth:`state` of a stepper of the same setup."""
        if state.get("format") != STATE_FORMAT or state.get("method") != self.method:
            raise InputError("compensator state", f"not a {self.method} state ({state.get('method')!r})",
                             "resume with the same method, or start in a new output directory")
        self.count, self.t_last, self.held = int(state["count"]), state["t_last"], float(state["held"])
        self._load(state)


class AheadStepper(Stepper):
    """A predictor of δ now, forecast one sample ahead by the extrapolation (33) (NaN for the first two)."""

    def __init__(self, params):
        super().__init__(params)
        self.now: list[float] = []
        """The last two values of the predictor."""

    def _predict(self, t, sample) -> float:
        self.now = (self.now + [self._value(t, sample)])[-2:]
        return 2 * self.now[1] - self.now[0] if len(self.now) == 2 else math.nan

    def _skip(self):
        self.now = []

    def _value(self, t, sample) -> float:
        raise NotImplementedError

    def _own(self):
        return {"now": [_num(v) for v in self.now]}

    def _load(self, state):
        self.now = [_val(v) for v in state["now"]]


class PaperStepper(Stepper):
    """The paper's adaptive predictor (eqs 30–38, :func:`~.compensator.predict`); K in µm/K."""

    method = "paper"
    columns = NEEDED[1:]

    def __init__(self, Ki: float, Kc: float, params: CompensatorParams, columns=NEEDED[1:4]):
        super().__init__(params)
        self.Ki, self.Kc = float(Ki), float(Kc)
        self.columns = (*columns, "delta_um")
        self.first: list[float] | None = None
        self.prev: tuple[float, float] | None = None
        self.R_i = self.R_C = 1.0
        self.best = -math.inf
        self.best_count, self.peak, self.R_peak = 0, None, 1.0

    def _predict(self, t, sample) -> float:
        a, b, cc, delta = (float(sample[n]) for n in self.columns)
        if self.first is None:
            self.first = [a, b, cc]
        d_ab = (a - self.first[0]) - (b - self.first[1])
        th_c = cc - self.first[2]
        p, c = self.params, self.count
        if self.peak is None:
            if c == 0 or delta > self.best:
                self.best, self.best_count = delta, c
            if self.best > 0 and self.best - delta > p.peak_drop_um:
                self.peak = self.best_count
        if self.peak is None:  # phase 1, eq (34)
            theory = self.Ki * d_ab - self.Kc * th_c
            self.R_i = held_ratio(delta, theory, self.R_i, p.min_theory_um, p.r_limits)[0]
            if self.best_count == c:
                self.R_peak = self.R_i  # R_i(j + 1) should j be the peak
        else:  # phase 2, eq (37)
            self.R_i = self.R_peak
            self.R_C = held_ratio(self.R_peak * self.Ki * d_ab - delta, self.Kc * th_c, self.R_C,
                                  p.min_tie_bar_um, p.r_limits)[0]
        pred = math.nan
        if self.prev is not None:  # eqs (33)/(36) and (35)/(38)
            pred = self.R_i * self.Ki * (2 * d_ab - self.prev[0]) - self.R_C * self.Kc * (2 * th_c - self.prev[1])
        self.prev = (d_ab, th_c)
        return pred

    def _skip(self):
        self.prev = None

    def _own(self):
        return {"first": self.first, "prev": None if self.prev is None else list(self.prev), "R_i": self.R_i,
                "R_C": self.R_C, "best": _num(self.best), "best_count": self.best_count, "peak": self.peak,
                "R_peak": self.R_peak}

    def _load(self, s):
        self.first, self.prev = s["first"], None if s["prev"] is None else tuple(s["prev"])
        self.R_i, self.R_C, self.best = float(s["R_i"]), float(s["R_C"]), _val(s["best"])
        self.best_count, self.peak, self.R_peak = int(s["best_count"]), s["peak"], float(s["R_peak"])


class RegressionStepper(AheadStepper):
    """The mlr baseline: a static regression of δ on temperature rises from the first sample,
    forecast one sample ahead (:func:`~.regression.regression_forecast`)."""

    method = "mlr"

    def __init__(self, model: LinearModel, params: CompensatorParams):
        super().__init__(params)
        self.model = model
        self.columns = tuple(model.features)
        self.beta = np.r_[model.intercept_um, model.coefficients]
        self.first: list[float] | None = None

    def _value(self, t, sample):
        x = [float(sample[f]) for f in self.columns]
        if self.first is None:
            self.first = x
        return float(np.r_[1.0, np.subtract(x, self.first)] @ self.beta)

    def _own(self):
        return {**super()._own(), "first": self.first}

    def _load(self, s):
        super()._load(s)
        self.first = s["first"]


def _lag(x: float, s0: float, s: float, h: float, tau: float) -> float:
    """One step h of the lag τ x' = s − x, exact for s linear from s0 to s."""
    a = math.exp(-h / tau)
    return a * x + (1.0 - a) * s0 + (s - s0) * (1.0 - tau * (1.0 - a) / h)


class ErrorModelStepper(AheadStepper):
    """A fitted thermal-error model (:mod:`gatetherm.studies.errormodel`) of one target, its lags
    stepped exactly for signals linear between samples, forecast one sample ahead
    (:func:`~gatetherm.studies.errormodel.replay.replay` without ``correction``)."""

    method = "errormodel"

    def __init__(self, model, target: str, params: CompensatorParams):
        super().__init__(params)
        self.model, self.target = model, model.target(target)
        self.columns = self.target.columns
        self.lags: list[float | None] = [None] * len(self.target.terms)
        self.signal: list[float | None] = [None] * len(self.target.terms)
        self.h = params.sample_interval_s
        self.smooth_s = float(model.settings.get("smooth_s", 0.0))  # the fit's smoothing of the readings
        self.read: dict[str, tuple[float, float]] = {}  # per temperature column: (smoothed, last reading)

    def _reading(self, name: str, sample) -> float:
        r = float(sample[name])
        if self.smooth_s <= 0:
            return r
        if name in self.now:  # a column read by two terms is stepped once per sample
            return self.now[name]
        x, r0 = self.read.get(name, (r, r))  # steady state at the first sample
        if name in self.read:
            x = _lag(x, r0, r, self.h, self.smooth_s)
        self.read[name], self.now[name] = (x, r), x
        return x

    def _term(self, term, sample) -> float:
        ref = self.model.reference_degC
        if term.kind == "input":
            return (abs(float(sample[term.column])) / term.scale) ** term.exponent
        s = self._reading(term.column, sample) - ref[term.column]
        return s - (self._reading(term.other, sample) - ref[term.other]) if term.other is not None else s

    def _value(self, t, sample):
        m, y, self.now = self.target, self.target.intercept_um, {}
        for j, (term, b) in enumerate(zip(m.terms, m.coefficients)):
            s = self._term(term, sample)
            if term.tau_s is not None:  # steady state at the first sample
                x = s if self.lags[j] is None else _lag(self.lags[j], self.signal[j], s, self.h, term.tau_s)
                self.lags[j], self.signal[j], s = x, s, x
            y += b * s
        return y

    def _own(self):
        return {**super()._own(), "lags": self.lags, "signal": self.signal, "read": self.read}

    def _load(self, s):
        super()._load(s)
        self.lags, self.signal = list(s["lags"]), list(s["signal"])
        self.read = {k: tuple(v) for k, v in s.get("read", {}).items()}


def error_model_stepper(model, target: str, params: CompensatorParams, correction: bool = False) -> Stepper:
    """The stepper of :func:`~gatetherm.studies.errormodel.replay.replay`: the model's forecast, or
    with ``correction`` (paper form) the paper's procedure on the model's sensors and coefficients."""
    m = model.target(target)
    if not correction:
        return ErrorModelStepper(model, target, params)
    if m.form != "paper":
        raise InputError(f"target {target}", f"the on-line correction R needs the paper's form, not {m.form}",
                         "fit with --form paper, or compensate without the correction")
    diff, third = m.terms
    stepper = PaperStepper(m.coefficients[0], -m.coefficients[1], params, (diff.column, diff.other, third.column))
    stepper.columns = (diff.column, diff.other, third.column, target)
    return stepper
