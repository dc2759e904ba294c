"""Evaluating a fitted thermal-error model on a series: :func:`predict`, :func:`score`, the
columns it needs (:func:`check_columns`) and the gaps it fills (:func:`input_gaps`)."""
from __future__ import annotations

import numpy as np

from gatetherm import InputError
from gatetherm.studies.errormodel.fitted import ErrorModel, residual_stats
from gatetherm.studies.errormodel.terms import GapReport, evaluate, fill_gaps, readings


def check_columns(model: ErrorModel, columns, where: str = "data") -> None:
    """Raise InputError if ``columns`` (a mapping or TimeSeries) lacks ``time_s`` or a column the model reads."""
    for name in ("time_s", *model.columns):
        if name not in columns:
            raise InputError(f"{getattr(columns, 'source', '') or where}: column {name}", "missing; the model reads it",
                             f"give a file with the columns {', '.join(('time_s',) + model.columns)}")


def _filled(model: ErrorModel, columns) -> tuple[dict, np.ndarray, dict[str, GapReport]]:
    check_columns(model, columns)
    t = np.asarray(columns["time_s"], float)
    cols, bad, reports = {}, np.zeros(t.size, bool), {}
    for name in model.columns:
        try:
            cols[name], long, reports[name] = fill_gaps(t, columns[name], model.max_gap_s)
        except ValueError:
            raise InputError(f"column {name}", "has no valid sample", "give measured values") from None
        smooth, anchor = (float(model.settings.get(k, 0.0)) for k in ("smooth_s", "anchor_s"))
        if name not in model.settings.get("inputs", ()) and (smooth > 0 or anchor > 0):
            cols[name] = readings(t, cols[name], smooth, anchor)  # as the fit read them
        bad |= long
    return cols, bad, reports


def input_gaps(model: ErrorModel, columns) -> dict[str, GapReport]:
    """Per column the model reads, what :func:`predict` fills (only columns with gaps)."""
    return {k: r for k, r in _filled(model, columns)[2].items() if r.filled}


def _references(model: ErrorModel, cols, t: np.ndarray) -> dict:
    if not model.run_reference:
        return {**model.reference_degC, "time_s": float(model.fit_span.get("start_s", t[0]))}
    return {**{c: float(v[0]) for c, v in cols.items()}, "time_s": float(t[0])}


def _term_values(model: ErrorModel, columns):
    cols, bad, _ = _filled(model, columns)
    t = np.asarray(columns["time_s"], float)
    ref = _references(model, cols, t)
    values = {}
    for m in model.targets:
        vs = [evaluate(term, t, cols, ref) for term in m.terms]
        values[m.target] = [v - v[0] for v in vs] if model.run_reference else vs
    return values, bad, t


def predict(model: ErrorModel, columns) -> dict[str, np.ndarray]:
    """Evaluate the model at the samples of ``columns``.

    Parameters
    ----------
    model : ErrorModel
        From :func:`~gatetherm.studies.errormodel.fit.fit_error_model` or :func:`load_model`.
    columns : mapping or TimeSeries
        ``time_s`` (s, increasing) and every column the model reads (degC, the inputs' units).
        Missing samples (NaN) are filled linearly (held at the ends); in gaps longer than
        ``model.max_gap_s`` the prediction is NaN. Lags start in steady state at the first sample.
        A model fitted on several runs takes the file as a run of its own: rises from its first
        sample, the prediction 0 there.

    Returns
    -------
    dict
        Target name -> predicted displacement at each sample, um.
    """
    values, bad, t = _term_values(model, columns)
    out = {}
    for m in model.targets:
        y = np.full(t.size, 0.0 if model.run_reference else m.intercept_um)
        for v, b in zip(values[m.target], m.coefficients):
            y += b * v
        y[bad] = np.nan
        out[m.target] = y
    return out


def score(predicted: dict[str, np.ndarray], columns) -> dict[str, dict]:
    """Per predicted target: ``predicted_samples``, and where ``columns`` has the target measured,
    :func:`residual_stats` of measured - predicted over the samples where both exist (um)."""
    out = {}
    for name, p in predicted.items():
        entry = {"predicted_samples": int(np.isfinite(p).sum())}
        if name in columns:
            r = np.asarray(columns[name], float) - p
            r = r[np.isfinite(r)]
            entry.update(residual_stats(r) if r.size else {"samples": 0})
        out[name] = entry
    return out
