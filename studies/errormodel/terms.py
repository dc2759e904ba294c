"""The regressors of a thermal-error model: temperature rises, their differences and lags, and
operating inputs through first-order lags.

A :class:`Term` is evaluated on a series' own sample times:

* ``sensor``: the rise ``theta_k = T_k - T_ref,k`` of a temperature column, K;
* ``difference``: ``theta_k - theta_m`` of two temperature columns, K;
* ``input``: ``(|u| / scale) ** exponent`` of an operating input such as ``spindle_rpm``
  (dimensionless; spindle losses grow with the speed roughly as rpm^1..2);
* ``drift``: the time since the reference instant (``reference["time_s"]``, default the first
  sample), h: a slow drift, offered only where it earns its place (column ``time_s``).

Any of them may pass through a first-order lag ``tau dx/dt = s - x`` (``tau_s``), integrated
exactly on the sample times for a signal varying linearly between samples (first-order hold):
with ``h`` the step and ``a = exp(-h / tau)``,
``x[k+1] = a x[k] + (1 - a) s[k] + (s[k+1] - s[k]) (1 - tau (1 - a) / h)``,
starting in steady state, ``x[0] = s[0]`` (a machine at rest at the first sample).
"""
from __future__ import annotations

import logging
from dataclasses import dataclass

import numpy as np

from gatetherm import InputError

log = logging.getLogger(__name__)

KINDS = ("sensor", "difference", "input", "drift")


@dataclass(frozen=True)
class Term:
    """One regressor of a model; its coefficient is in um/K (sensor, difference), um (input) or
    um/h (drift)."""

    kind: str
    """``sensor``, ``difference``, ``input`` or ``drift`` (see the module docstring)."""
    column: str
    """The column it reads (the first of a difference)."""
    other: str | None = None
    """The subtracted column of a difference; None otherwise."""
    tau_s: float | None = None
    """Time constant of the first-order lag, s; None = no lag."""
    exponent: float = 1.0
    """Exponent of an input term, dimensionless (1 for the others)."""
    scale: float = 1.0
    """Scale of an input term in the input's unit (e.g. the largest speed, 1/min)."""

    def __post_init__(self):
        if self.kind not in KINDS:
            raise InputError("term kind", f"{self.kind!r} is not one of {', '.join(KINDS)}", "use one of those")
        if (self.kind == "difference") != (self.other is not None):
            raise InputError(f"term {self.column}", "a difference, and only a difference, names another column",
                             "give 'other' for kind 'difference' only")
        if self.tau_s is not None and not (np.isfinite(self.tau_s) and self.tau_s > 0):
            raise InputError(f"term {self.column}", f"time constant {self.tau_s} s is not > 0", "give tau_s > 0")
        if not (np.isfinite(self.scale) and self.scale > 0 and np.isfinite(self.exponent) and self.exponent > 0):
            raise InputError(f"term {self.column}", "scale and exponent must be > 0", "e.g. scale 5000, exponent 2")

    @property
    def columns(self) -> tuple[str, ...]:
        """The columns this term reads."""
        return (self.column,) if self.other is None else (self.column, self.other)

    @property
    def unit(self) -> str:
        """Unit of this term's coefficient."""
        return {"input": "um", "drift": "um/h"}.get(self.kind, "um/K")

    @property
    def label(self) -> str:
        """Short readable name, e.g. ``t4_degC``, ``A-B``, ``lag(spindle_rpm^2, 600 s)``."""
        base = {"sensor": self.column, "difference": f"{self.column}-{self.other}",
                "input": f"{self.column}^{self.exponent:g}", "drift": "drift (h)"}[self.kind]
        return base if self.tau_s is None else f"lag({base}, {self.tau_s:.4g} s)"


def lag(t_s: np.ndarray, signal: np.ndarray, tau_s: float) -> np.ndarray:
    """First-order lag of ``signal`` (linear between the samples ``t_s``, s), exact; see the module
    docstring. Starts in steady state. Same unit as ``signal``."""
    s = np.asarray(signal, float)
    h = np.diff(np.asarray(t_s, float))
    if s.size < 2:
        return s.copy()
    if np.ptp(h) <= 1e-9 * h[0]:  # uniform sampling: one C-level recursion
        from scipy.signal import lfilter, lfilter_zi  # here: a service stepping a model imports no scipy.signal

        a = np.exp(-h[0] / tau_s)
        c1 = 1.0 - tau_s * (1.0 - a) / h[0]
        b, den = [c1, 1.0 - a - c1], [1.0, -a]
        return lfilter(b, den, s, zi=lfilter_zi(b, den) * s[0])[0]
    a = np.exp(-h / tau_s)
    c1 = 1.0 - tau_s * (1.0 - a) / h
    x = np.empty_like(s)
    x[0] = s[0]
    for k in range(len(h)):
        x[k + 1] = a[k] * x[k] + (1.0 - a[k]) * s[k] + (s[k + 1] - s[k]) * c1[k]
    return x


def anchor_value(t_s: np.ndarray, values: np.ndarray, window_s: float) -> float:
    """The value at the first sample of the straight line fitted by least squares through the
    samples of the first ``window_s`` seconds (fewer than three: the first sample): a reference
    that one noisy reading does not set alone. Its variance is ``2 (2m - 1) / (m (m + 1))`` times
    a reading's for ``m`` equally spaced samples (0.35 for m = 10). Unit of ``values``."""
    t = np.asarray(t_s, float)
    v = np.asarray(values, float)
    near = (t - t[0] <= window_s) & np.isfinite(v)
    if window_s <= 0 or near.sum() < 3:
        return float(v[0])
    slope, intercept = np.polyfit(t[near] - t[0], v[near], 1)
    return float(intercept)


def readings(t_s: np.ndarray, values: np.ndarray, smooth_s: float = 0.0, anchor_s: float = 0.0,
             start: int = 0) -> np.ndarray:
    """A temperature column as the model reads it (gap-free ``values``, degC, at ``t_s``, s): its
    reading at ``start`` replaced by :func:`anchor_value` over the ``anchor_s`` seconds from there
    (the run's reference, 0 = the reading itself), then, with ``smooth_s`` > 0, passed through a
    first-order lag of that time constant, s, in steady state at its first sample: white noise of
    the readings reduced to ``sqrt((1 - a) / (1 + a))`` of it (``a = exp(-h / smooth_s)``)."""
    v = np.array(values, float)
    if anchor_s > 0 and start < v.size:
        v[start] = anchor_value(t_s[start:], v[start:], anchor_s)
    return lag(t_s, v, smooth_s) if smooth_s > 0 else v


def evaluate(term: Term, t_s: np.ndarray, columns, reference_degC: dict[str, float]) -> np.ndarray:
    """The term's values at the samples ``t_s`` (s) from gap-free ``columns`` (name -> array) and the
    reference temperatures (degC) of the sensors; K for sensors and differences, 1 for inputs, h for
    a drift (from ``reference["time_s"]``, s, default the first sample)."""
    if term.kind == "drift":
        s = (np.asarray(t_s, float) - reference_degC.get("time_s", t_s[0])) / 3600.0
    elif term.kind == "input":
        s = (np.abs(columns[term.column]) / term.scale) ** term.exponent
    else:
        s = columns[term.column] - reference_degC[term.column]
        if term.other is not None:
            s = s - (columns[term.other] - reference_degC[term.other])
    return s if term.tau_s is None else lag(t_s, s, term.tau_s)


def noise_sd(term: Term, sensor_K: float, step_s: float, smooth_s: float = 0.0) -> float:
    """Standard deviation of the term's values when each temperature reading carries independent
    white noise of ``sensor_K`` (K): ``sensor_K`` for a rise, sqrt(2) times that for a difference,
    reduced by a lag of step ``step_s`` (s) to ``sqrt((1 - a) / (1 + a))`` of it, ``a = exp(-h / tau)``
    (the stationary variance of a first-order lag of white noise; of the term's lag or the readings'
    smoothing ``smooth_s``, whichever reduces more: an upper bound for the two in series); 0 for an
    input (a commanded value) and a drift."""
    if term.kind in ("input", "drift"):
        return 0.0
    sd = sensor_K * (np.sqrt(2.0) if term.kind == "difference" else 1.0)
    tau = max(term.tau_s or 0.0, smooth_s)
    if tau > 0:
        a = np.exp(-step_s / tau)
        sd *= np.sqrt((1.0 - a) / (1.0 + a))
    return float(sd)


@dataclass(frozen=True)
class GapReport:
    """What :func:`fill_gaps` did to one column."""

    filled: int
    """Samples that were missing (empty or non-finite) and were filled."""
    longest_s: float
    """Longest run of missing samples, s (from the last good sample to the next)."""
    unpredicted: int
    """Filled samples in runs longer than the allowed gap: their predictions are not kept."""


def fill_gaps(t_s: np.ndarray, values: np.ndarray, max_gap_s: float) -> tuple[np.ndarray, np.ndarray, GapReport]:
    """Fill missing (non-finite) samples: linearly between good samples, the first good value
    before it, the last good value after it (held). Returns the filled values, a mask of the
    samples in gaps longer than ``max_gap_s`` (s), and a :class:`GapReport`."""
    v = np.asarray(values, float)
    good = np.isfinite(v)
    if good.all():
        return v, np.zeros(v.size, bool), GapReport(0, 0.0, 0)
    if not good.any():
        raise ValueError("no valid sample")
    idx = np.flatnonzero(good)
    filled = np.interp(t_s, t_s[idx], v[idx])
    # each missing sample's gap: from the good sample before it (or the start) to the one after (or the end)
    pos = np.searchsorted(idx, np.arange(v.size))
    t_before = np.where(pos > 0, t_s[idx[np.maximum(pos - 1, 0)]], t_s[0])
    t_after = np.where(pos < idx.size, t_s[idx[np.minimum(pos, idx.size - 1)]], t_s[-1])
    span = np.where(good, 0.0, t_after - t_before)
    long = ~good & (span > max_gap_s)
    return filled, long, GapReport(int((~good).sum()), float(span.max()), int(long.sum()))
