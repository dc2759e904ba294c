"""Where and when a model and a measurement disagree.

A run is split into phases from its inputs (pump off, heating, oil steady,
forced cooling; on a case file's frame, where an input steps). A residual is
*significant* where its systematic part (a centred moving average over
``SMOOTH_S``) exceeds the sensor resolution with
confidence: by more than ``Z`` standard errors of that average, the
sample-to-sample noise being estimated from first differences (at least the
rounding noise of the resolution, res/√12). A model error below the
resolution, such as the FE discretisation error, is therefore not reported.
All functions are pure and work on arrays in the channels' units.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from gatetherm.studies.diagnosis.replay import label, resolution, unit

SMOOTH_S = 900.0
"""Length of the moving average that separates the systematic residual from noise, s."""
OIL_RATE_K_PER_H = 2.0
"""Supply-oil rate that counts as heating or cooling rather than steady, K/h."""
STEP_FRACTION = 0.1
"""A change of an input between two samples by more than this fraction of its range is a step."""
MIN_PHASE_S = 600.0
"""Shorter phases are merged into the one before, s."""
Z = 3.0
"""Standard errors of the moving average by which it must exceed the resolution."""


@dataclass(frozen=True)
class Phase:
    """A stretch of the run with one kind of input."""

    label: str
    start_s: float
    """Start, s from the first sample."""
    end_s: float
    """End, s; exclusive unless ``closed``."""
    closed: bool = False
    """The last phase includes its end sample."""

    def mask(self, t: np.ndarray) -> np.ndarray:
        return (t >= self.start_s) & ((t <= self.end_s) if self.closed else (t < self.end_s))

    def span(self) -> str:
        return f"{clock(self.start_s)}–{clock(self.end_s)}"


def clock(seconds: float) -> str:
    """h:mm of a time in s."""
    m = int(round(seconds / 60.0))
    return f"{m // 60}:{m % 60:02d}"


def phases(t: np.ndarray, oil: np.ndarray, pump: np.ndarray, others: dict | None = None) -> list[Phase]:
    """Phases of a run from its (gap-free) inputs: "pump off", "heating",
    "forced cooling", "pump on, oil steady (N °C oil)"; each cut again where one of ``others``
    (the other inputs) steps, named by their values as :func:`input_phases` names them."""
    n = len(t)
    rate = np.append(np.diff(oil) / np.diff(t), 0.0) * 3600.0 if n > 1 else np.zeros(n)
    if n > 1:  # the trend over the interval after each sample, like the pump state
        rate[-1] = rate[-2]
    kinds = np.where(pump < 0.5, "pump off", np.where(rate > OIL_RATE_K_PER_H, "heating",
                     np.where(rate < -OIL_RATE_K_PER_H, "forced cooling", "pump on, oil steady")))
    stepping, ids = _steps(others or {})
    out = []
    for kind, a, b in _merged(t, [f"{k}|{i}" for k, i in zip(kinds, ids)] if stepping else kinds):
        kind = kind.split("|")[0]
        if kind == "pump on, oil steady":
            kind = f"pump on, oil steady ({np.mean(oil[a:b]):.0f} °C)"
        kind = ", ".join([kind, *(f"{k} {np.median(others[k][a:b]):.3g}" for k in stepping)])
        out.append(Phase(str(kind), float(t[a]), float(t[b] if b < n else t[-1]), closed=b >= n))
    return out


def _steps(columns: dict) -> tuple[list[str], np.ndarray]:
    """The inputs of ``columns`` that step (change between two samples by more than
    :data:`STEP_FRACTION` of their range) and per sample the count of steps before it."""
    jumps = {k: np.abs(np.diff(v)) > STEP_FRACTION * np.ptp(v) for k, v in columns.items() if np.ptp(v) > 0}
    stepping = [k for k, j in jumps.items() if j.any()]
    n = len(next(iter(columns.values()))) if columns else 0
    ids = np.concatenate([[0], np.cumsum(np.any([jumps[k] for k in stepping], axis=0))]) if stepping else np.zeros(n)
    return stepping, ids


def input_phases(t: np.ndarray, columns: dict[str, np.ndarray]) -> list[Phase]:
    """Phases of a case's run from the inputs that drive it: cut where an input steps (changes
    between two samples by more than :data:`STEP_FRACTION` of its range), each named by the median
    values of the stepping inputs ("spindle_W 120"); one phase, "whole run", if none steps."""
    n = len(t)
    stepping, ids = _steps(columns)
    if not stepping or n < 2:
        return [Phase("whole run", float(t[0]), float(t[-1]), closed=True)]
    out = []
    for _, a, b in _merged(t, ids):
        name = ", ".join(f"{k} {np.median(columns[k][a:b]):.3g}" for k in stepping)
        out.append(Phase(name, float(t[a]), float(t[b] if b < n else t[-1]), closed=b >= n))
    return out


def _merged(t: np.ndarray, kinds) -> list[list]:
    """Runs of equal ``kinds`` as [kind, first, end] sample ranges, those shorter than
    :data:`MIN_PHASE_S` merged into the one before (a short first one into the next)."""
    n = len(t)
    cuts = [0] + [i for i in range(1, n) if kinds[i] != kinds[i - 1]] + [n]
    segs = [[kinds[a], a, b] for a, b in zip(cuts[:-1], cuts[1:])]

    def short(seg) -> bool:
        return t[min(seg[2], n - 1)] - t[seg[1]] < MIN_PHASE_S

    merged: list[list] = []
    for seg in segs:
        if merged and (short(seg) or merged[-1][0] == seg[0]):
            merged[-1][2] = seg[2]
        else:
            merged.append(seg)
    if len(merged) > 1 and short(merged[0]):
        merged[1][1] = 0
        merged.pop(0)
    return merged


def _window(t: np.ndarray, window_s: float) -> int:
    """Half-width in samples of a moving average over about ``window_s``."""
    dt = float(np.median(np.diff(t))) if len(t) > 1 else 1.0
    return max(int(round(0.5 * window_s / dt)), 0)


def smooth(t: np.ndarray, r: np.ndarray, window_s: float = SMOOTH_S) -> np.ndarray:
    """Centred moving average of ``r`` over about ``window_s`` (missing samples skipped)."""
    half = _window(t, window_s)
    ok = np.isfinite(r)
    s = np.concatenate([[0.0], np.cumsum(np.where(ok, r, 0.0))])
    n = np.concatenate([[0], np.cumsum(ok)])
    i = np.arange(len(r))
    lo, hi = np.maximum(i - half, 0), np.minimum(i + half + 1, len(r))
    cnt = n[hi] - n[lo]
    return np.where(cnt > 0, (s[hi] - s[lo]) / np.maximum(cnt, 1), np.nan)


def noise_sd(r: np.ndarray) -> float:
    """Sample-to-sample noise of a residual, robust to its slow systematic part."""
    d = np.diff(r[np.isfinite(r)])
    return float(1.4826 * np.median(np.abs(d - np.median(d))) / np.sqrt(2.0)) if len(d) > 2 else 0.0


def threshold(t: np.ndarray, r: np.ndarray, res: float) -> float:
    """Level above which the moving average of ``r`` is significant: the resolution
    plus ``Z`` standard errors of the average."""
    noise = max(noise_sd(r), res / np.sqrt(12.0))
    return res + Z * noise / np.sqrt(2 * _window(t, SMOOTH_S) + 1)


def significant(t: np.ndarray, r: np.ndarray, res: float) -> np.ndarray:
    """Samples where the systematic residual exceeds the resolution with confidence."""
    s = smooth(t, r)
    return np.isfinite(s) & (np.abs(s) > threshold(t, r, res))


@dataclass(frozen=True)
class Finding:
    """The residual of one channel in one phase."""

    channel: str
    phase: Phase
    rms: float
    """RMS residual (channel unit)."""
    peak: float
    """Systematic residual of largest magnitude, signed (measured − model)."""
    peak_s: float
    """Time of ``peak``, s."""
    significant_fraction: float
    """Fraction of the phase's samples where the residual is significant."""

    @property
    def significant(self) -> bool:
        return self.significant_fraction > 0.0

    def sentence(self) -> str:
        res = resolution(self.channel)
        what = "above" if self.peak > 0 else "below"
        if not self.significant:
            return (f"{label(self.channel)}, {self.phase.label} {self.phase.span()}: within resolution "
                    f"(systematic part ≤ {abs(self.peak):.2g} {unit(self.channel)})")
        return (f"{label(self.channel)}, {self.phase.label} {self.phase.span()}: measured {what} the model "
                f"by up to {abs(self.peak):.2g} {unit(self.channel)} ({abs(self.peak) / res:.0f}× resolution) "
                f"at {clock(self.peak_s)}, significant {100 * self.significant_fraction:.0f} % of the phase")


def locate(t: np.ndarray, res: dict[str, np.ndarray], run_phases: list[Phase]) -> list[Finding]:
    """One :class:`Finding` per channel and phase."""
    out = []
    for c, r in res.items():
        s = smooth(t, r)
        sig = significant(t, r, resolution(c))
        for ph in run_phases:
            m = ph.mask(t) & np.isfinite(r)
            if not m.any():
                continue
            i = np.flatnonzero(m)[np.nanargmax(np.abs(np.where(np.isfinite(s[m]), s[m], 0.0)))]
            out.append(Finding(c, ph, float(np.sqrt(np.mean(r[m] ** 2))), float(s[i]), float(t[i]),
                               float(np.mean(sig[m]))))
    return out


def case_phases(case, t: np.ndarray, columns: dict) -> list[Phase]:
    """Phases of a run: a pumped fluid's (pump off, heating, forced cooling, supply steady) where
    the case has one whose supply and pump are columns, cut again where another input steps; else
    where an input steps."""
    fluid = next((f for f in case.problem.fluids if len(f.supply.names()) == 1 and len(f.pump.names()) == 1
                  and f.supply.text in columns and f.pump.text in columns), None)
    if fluid is None:
        return input_phases(t, columns)
    others = {k: v for k, v in columns.items() if k not in (fluid.supply.text, fluid.pump.text)}
    return phases(t, columns[fluid.supply.text], columns[fluid.pump.text], others)

