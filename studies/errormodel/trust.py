"""How far a thermal-error model's prediction can be trusted: its 90 % interval, calibrated on
held-out data, and a drift detector.

* :func:`calibrate_forward` (one or two runs): the half-width grows with the horizon h since the
  fit, ``w (1 + h / L)``; the forward-chaining residuals inside the fitting span are scaled the same
  way by their own horizons, and w is a conformal quantile over the held-out *blocks* (the unit a
  later stretch of hours is exchangeable with; the samples inside a block are not independent):
  each block's 90 % quantile of its scores, and w the ``ceil(0.9 (B + 1))``-th smallest of the B
  blocks' (:func:`block_quantile`; the largest for 9 … 18 blocks). :func:`calibrate` (leave one run
  out): the 90 % quantile of the held-out absolute residuals. Coverage is checked out of sample:
  each held-out block's residuals against the width of the blocks that end before it starts
  (forward) or do not overlap it, the fraction inside over all checked samples.
* :func:`trust` widens the interval where the model extrapolates: by the part of the prediction
  that rests on terms beyond their fitted ranges (:func:`beyond`), which the held-out calibration
  cannot vouch for.
* :func:`term_ranges` / :func:`drift_warning`: each term's range on the fitting rows; a sample is *outside*
  where a term (not the drift term, which always grows) leaves its range by more than
  :data:`MARGIN` of the range's width. A file whose share of outside samples exceeds
  :data:`MAX_OUTSIDE`, or whose measured target leaves the 90 % interval on more than
  :data:`MAX_MISSED` of its samples, is unlike the fitting data (another duty cycle or room, or a
  changed machine).
"""
from __future__ import annotations

import numpy as np

from gatetherm.studies.errormodel.model import ErrorModel, _term_values, predict

LEVEL = 0.9
"""Nominal coverage of the interval."""
MARGIN = 0.25
"""A term further than this fraction of its fitted range beyond the range is outside it."""
MAX_OUTSIDE = 0.10
"""Largest share of samples outside the fitted ranges before the drift warning."""
MAX_MISSED = 0.25
"""Largest share of measured samples outside the 90 % interval before the drift warning."""


def calibrate(residuals: list[np.ndarray], blocks: list[tuple[int, int]], chain: bool) -> dict:
    """``half_width_um`` of the 90 % interval, ``coverage`` (out-of-sample check, module docstring;
    None if no block could be checked) and ``samples`` checked, from the held-out ``residuals`` per
    block (um) of ``blocks`` (row ranges). Used for leave one run out; a single run's interval is
    :func:`calibrate_forward`."""
    if not residuals:
        return {}
    a = [np.abs(r) for r in residuals]
    q = [float(np.quantile(x, LEVEL)) for x in a]
    half = block_quantile(q)
    inside, n = 0, 0
    for i, (lo, hi) in enumerate(blocks):
        others = [q[j] for j, (l2, h2) in enumerate(blocks)
                  if j != i and (h2 <= lo if chain else (h2 <= lo or l2 >= hi))]
        if not others:
            continue
        inside += int((a[i] <= block_quantile(others)).sum())
        n += a[i].size
    return {"half_width_um": half, "coverage": inside / n if n else None, "samples": n, "level": LEVEL}


def block_quantile(quantiles) -> float:
    """The conformal quantile over blocks: the ``ceil(LEVEL (B + 1))``-th smallest of the B blocks'
    90 % quantiles (the largest where that exceeds B): a later block exchangeable with these has its
    own 90 % quantile below it with probability at least :data:`LEVEL`."""
    q = np.sort(np.asarray(quantiles, float))
    return float(q[min(q.size, int(np.ceil(LEVEL * (q.size + 1)))) - 1])


def calibrate_forward(residuals: list[np.ndarray], blocks: list[tuple[int, int]], t_s: np.ndarray) -> dict:
    """The 90 % interval of a model fitted on one run, growing with the horizon since the fit:
    ``half(h) = half_width_um * (1 + h / fit_length_s)``, h the time since the fitting span's end, s.

    ``residuals`` are the forward-chaining held-out residuals (um) of ``blocks`` (row ranges, each
    predicted by the fit on the rows before it; ``t_s`` the rows' times, s): each sample's score is
    ``|r| / (1 + h / L)``, h its time since the end of its fold's fitting rows and L their length;
    ``half_width_um`` is :func:`block_quantile` of the blocks' 90 % quantiles of their scores.
    ``coverage`` checks it out of sample: each block against :func:`block_quantile` of the blocks
    that end before it starts."""
    if not residuals:
        return {}
    scores, q = [], []
    for r, (lo, hi) in zip(residuals, blocks):
        length = max(float(t_s[lo - 1] - t_s[0]), 1e-9)
        h = t_s[lo:hi] - t_s[lo - 1]
        scores.append(np.abs(r) / (1.0 + h / length))
        q.append(float(np.quantile(scores[-1], LEVEL)))
    inside, n = 0, 0
    for i, (lo, _) in enumerate(blocks):
        earlier = [q[j] for j, (_, h2) in enumerate(blocks) if h2 <= lo]
        if earlier:
            inside += int((scores[i] <= block_quantile(earlier)).sum())
            n += scores[i].size
    return {"half_width_um": block_quantile(q), "coverage": inside / n if n else None, "samples": n, "level": LEVEL,
            "blocks": len(blocks), "growth": "horizon", "fit_end_s": float(t_s[-1]),
            "fit_length_s": float(t_s[-1] - t_s[0])}


def horizon_factor(interval: dict, t_s: np.ndarray) -> np.ndarray:
    """Per sample the factor ``1 + h / fit_length_s`` of a horizon-growing interval
    (:func:`calibrate_forward`); 1 for a constant one. h is the time since the fitting span's end on
    the file's clock where the file's first sample lies within the fitting span (the fitting run
    continued), else the time since the file's first sample (a later file, taken as starting right
    after the fit)."""
    t_s = np.asarray(t_s, float)
    if interval.get("growth") != "horizon" or not t_s.size:
        return np.ones(t_s.size)
    end, length = interval["fit_end_s"], max(interval["fit_length_s"], 1e-9)
    h = t_s - end if end - length <= t_s[0] < end else t_s - t_s[0]
    return 1.0 + np.maximum(h, 0.0) / length


def term_ranges(X: np.ndarray) -> tuple[tuple[float, float], ...]:
    """Smallest and largest value of each column of ``X`` (the terms on the fitting rows)."""
    return tuple((float(c.min()), float(c.max())) for c in X.T)


def outside(values: list[np.ndarray], ranges, kinds) -> np.ndarray:
    """Per sample: True where a term's ``values`` (one array per term) leave its range by more than
    :data:`MARGIN` of its width (drift terms not checked)."""
    out = np.zeros(values[0].size if values else 0, bool)
    for v, (lo, hi), kind in zip(values, ranges, kinds):
        if kind == "drift":
            continue
        pad = MARGIN * max(hi - lo, 1e-12)
        out |= (v < lo - pad) | (v > hi + pad)
    return out


def beyond(values: list[np.ndarray], ranges, coefficients) -> np.ndarray:
    """Per sample, the part of the prediction (um) that rests on terms beyond their fitted ranges:
    ``sum_k |c_k| * (distance of term k's value outside [lo_k, hi_k])``; 0 inside the ranges."""
    out = np.zeros(values[0].size if values else 0)
    for v, (lo, hi), c in zip(values, ranges, coefficients):
        out += abs(c) * np.maximum(0.0, np.maximum(v - hi, lo - v))
    return out


def drift_warning(target: str, share_outside: float, share_missed: float | None) -> str | None:
    """One line if the data are unlike the fitting data (module docstring), else None."""
    why = []
    if share_outside > MAX_OUTSIDE:
        why.append(f"{share_outside:.0%} of the samples outside the fitting data's range")
    if share_missed is not None and share_missed > MAX_MISSED:
        why.append(f"{share_missed:.0%} of the measured samples outside the 90 % interval")
    if not why:
        return None
    return (f"{target}: the record is unlike the fitting data ({'; '.join(why)}): a duty cycle, room or range the fit "
            "did not see, or a changed machine; refit on data that hold it")


def trust(model: ErrorModel, columns, predicted: dict[str, np.ndarray] | None = None) -> dict[str, dict]:
    """The 90 % interval and the drift check of every target on ``columns``.

    Parameters
    ----------
    model : ErrorModel
        The fitted model (:mod:`gatetherm.studies.errormodel.model`).
    columns : mapping or TimeSeries
        As for :func:`predict`; where it holds a target, the measured samples are checked against
        the interval too.
    predicted : dict, optional
        :func:`predict`'s result on ``columns`` (computed if None).

    Returns
    -------
    dict
        Per target: ``lower``, ``upper`` (um per sample, the 90 % interval widened by :func:`beyond`
        where the model extrapolates; NaN without a calibrated interval),
        ``outside`` (per sample: a term beyond its fitted range), ``share_outside``,
        ``share_missed`` (measured samples outside the interval; None if not measured) and
        ``warning`` (one line, or None; :func:`~gatetherm.studies.errormodel.trust.drift_warning`).
    """
    predicted = predict(model, columns) if predicted is None else predicted
    values, _, _ = _term_values(model, columns)
    out = {}
    for m in model.targets:
        p = predicted[m.target]
        half = m.interval.get("half_width_um", np.nan) * horizon_factor(m.interval, columns["time_s"]) \
            + beyond(values[m.target], m.ranges, m.coefficients)
        off = outside(values[m.target], m.ranges, [t.kind for t in m.terms]) if m.ranges \
            else np.zeros(p.size, bool)
        missed = None
        if m.target in columns and np.all(np.isfinite(half)):
            y = np.asarray(columns[m.target], float)
            if model.run_reference:
                valid = np.flatnonzero(np.isfinite(y))
                y = y - (y[valid[0]] if valid.size else np.nan)
            ok = np.isfinite(y) & np.isfinite(p)
            missed = float(np.mean(np.abs(y[ok] - p[ok]) > half[ok])) if ok.any() else None
        share = float(off.mean()) if off.size else 0.0
        out[m.target] = {"lower": p - half, "upper": p + half, "outside": off, "share_outside": share,
                         "share_missed": missed, "warning": drift_warning(m.target, share, missed)}
    return out
