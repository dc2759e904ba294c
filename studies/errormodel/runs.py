"""The fitting data of a thermal-error model: one run or several, each with its own reference.

A single run is referenced as before: temperature rises from the first valid sample of the fitting
span, a drift's hours from the span's start. Several runs (:attr:`Runs.anchored`) are each a
machine homed anew, cold or warm: every run's rises are taken from its own first sample, and the
model's value at a run's start is its zero, so every regressor and the target enter as their
change since the run's first sample (lags start in steady state there). :mod:`.model` predicts
such a model the same way: from the predicted file's own first sample.
"""
from __future__ import annotations

import logging

import numpy as np

from gatetherm import InputError
from gatetherm.studies.errormodel.terms import Term, evaluate, fill_gaps, readings

log = logging.getLogger(__name__)


class Runs:
    """The runs' gap-filled columns, their references and the rows a fit may use, concatenated."""

    def __init__(self, series, candidates, inputs, spans, max_gap_s: float, sources=(), smooth_s: float = 0.0,
                 anchor_s: float = 0.0):
        """``series``: the runs (mappings or TimeSeries with ``time_s``); ``spans``: per run the
        fitting span ``(start_s, end_s)``; ``sources``: per run its file (for messages);
        ``smooth_s``, ``anchor_s``: how the temperature columns are read
        (:func:`~gatetherm.studies.errormodel.terms.readings`, s)."""
        self.anchored = len(series) > 1
        self.t, self.cols, self.refs, self.rows, self.series = [], [], [], [], list(series)
        for k, (ts, (lo, hi)) in enumerate(zip(series, spans)):
            where = sources[k] if k < len(sources) and sources[k] else f"run {k + 1}"
            t = np.asarray(ts["time_s"], float)
            in_span = (t >= lo) & (t <= hi)
            cols, long = {}, np.zeros(t.size, bool)
            for name in (*candidates, *inputs):
                v = np.asarray(ts[name], float)
                if not np.isfinite(v[in_span]).any():
                    raise InputError(f"{where}: column {name}", "no valid sample in the fitting span",
                                     "give measured values")
                cols[name], gap, report = fill_gaps(t, v, max_gap_s)
                if name in candidates and (smooth_s > 0 or anchor_s > 0):
                    cols[name] = readings(t, cols[name], smooth_s, anchor_s, int(np.argmax(in_span)))
                long |= gap
                if report.filled:
                    log.info("%s: %s: %d missing samples filled (longest gap %.0f s)", where, name, report.filled,
                             report.longest_s)
            ref = {c: float(cols[c][np.flatnonzero(in_span & np.isfinite(np.asarray(ts[c], float)))[0]])
                   for c in candidates}
            ref["time_s"] = float(lo)
            self.t.append(t)
            self.cols.append(cols)
            self.refs.append(ref)
            self.rows.append(in_span & ~long)
        self.first = [int(np.flatnonzero(r)[0]) if r.any() else 0 for r in self.rows]

    @property
    def time(self) -> np.ndarray:
        """All runs' sample times, concatenated, s."""
        return np.concatenate(self.t)

    @property
    def clock(self) -> np.ndarray:
        """All runs' sample times on one clock, s: each run after the one before it, its first sample
        one :attr:`step_s` after that run's last (a forward chaining's horizons across runs)."""
        out, end = [], None
        for t in self.t:
            out.append(t if end is None else t - t[0] + end + self.step_s)
            end = out[-1][-1] if t.size else end
        return np.concatenate(out)

    @property
    def ok(self) -> np.ndarray:
        """Rows inside the fitting spans and outside long gaps, concatenated."""
        return np.concatenate(self.rows)

    @property
    def step_s(self) -> float:
        """Median sample step, s."""
        return float(np.median(np.concatenate([np.diff(t) for t in self.t if t.size > 1]) if any(
            t.size > 1 for t in self.t) else [1.0]))

    def column(self, term: Term) -> np.ndarray:
        """The term's values on every run, concatenated (anchored: minus its value at the run's first row)."""
        out = []
        for t, cols, ref, i in zip(self.t, self.cols, self.refs, self.first):
            v = evaluate(term, t, cols, ref)
            out.append(v - v[i] if self.anchored else v)
        return np.concatenate(out)

    def target(self, name: str) -> np.ndarray:
        """The target column on every run, concatenated, um (anchored: minus the run's first valid value)."""
        out = []
        for ts, rows in zip(self.series, self.rows):
            y = np.asarray(ts[name], float)
            if self.anchored:
                valid = np.flatnonzero(rows & np.isfinite(y))
                y = y - (y[valid[0]] if valid.size else np.nan)
            out.append(y)
        return np.concatenate(out)

    def blocks(self, rows: np.ndarray) -> list[tuple[int, int]] | None:
        """Leave-one-run-out blocks of the selected ``rows`` (indices into the selected rows) with three
        or more runs that each keep a row; None otherwise (blocked folds within the rows)."""
        sizes, start = [], 0
        for t in self.t:
            sizes.append(int(rows[start:start + t.size].sum()))
            start += t.size
        if sum(s > 0 for s in sizes) < 3:
            return None
        edges = np.cumsum([0] + [s for s in sizes if s > 0])
        return [(int(a), int(b)) for a, b in zip(edges[:-1], edges[1:])]

    def reference(self) -> dict[str, float]:
        """The single run's reference temperatures (degC); for anchored runs each run's own (empty)."""
        return {} if self.anchored else {k: v for k, v in self.refs[0].items() if k != "time_s"}
