"""Refitting a thermal-error model as data arrive: periodic refit on a window (:func:`refit`).

The terms (sensors, time constants) stay; the coefficients are fitted again, with the fit's noise
rule (:func:`~gatetherm.studies.errormodel.select.noisy_least_squares` at the model's
``resolution_K``), on the last ``window_s`` of the data.

Guarded against fitting its own corrections: on a compensated machine the measured displacement
is what the correction left, ``measured = raw - applied``; fitting it would teach the model its
own residual (a model that corrects well would learn to correct nothing). The refit therefore
fits ``measured + applied``, the raw thermal error, with ``applied`` the offset the control wrote
(a column per target); data without such a column are taken as uncompensated. And never silently
worse: the new coefficients, fitted on the window's first three quarters, must predict its last
quarter better than the current ones, else the current model is kept and the reason returned.
"""
from __future__ import annotations

import dataclasses
import logging

import numpy as np

from gatetherm import InputError
from gatetherm.studies.errormodel import select
from gatetherm.studies.errormodel.model import ErrorModel, _term_values, residual_stats
from gatetherm.studies.errormodel.terms import noise_sd

log = logging.getLogger(__name__)

CHECK_SHARE = 0.25
"""The share of the window, at its end, that the refit must predict better than the current model."""


def _solve(X, y, var, intercept: bool):
    A = np.column_stack([np.ones(len(y)), X]) if intercept else X
    v = np.r_[0.0, var] if intercept else var
    c = select.noisy_least_squares(A, y, v)
    return (c[0], c[1:]) if intercept else (0.0, c)


def refit(model: ErrorModel, columns, window_s: float, applied: dict[str, str] | None = None):
    """Refit every target's coefficients on the last ``window_s`` of ``columns`` (module docstring).

    Returns ``(model, report)``: the refitted model (or the current one where the refit does not
    predict the window's last quarter better) and per target ``kept`` (True: current coefficients
    kept), ``current_mae_um`` and ``refit_mae_um`` on that quarter, ``samples``."""
    if not (np.isfinite(window_s) and window_s > 0):
        raise InputError("window_s", f"{window_s} is not > 0", "e.g. 86400 (one day)")
    applied = dict(applied or {})
    for target, col in applied.items():
        if target not in model.names:
            raise InputError(f"applied correction of {target}", "is not a target of the model",
                             f"name targets of the model: {', '.join(model.names)}")
        read = {c for m in model.targets for c in m.columns} | set(model.names)
        if col in read:  # measured + measured, or a sensor as a correction: the refit would fit nonsense
            raise InputError(f"applied correction of {target}", f"column {col} is a target or a column the model "
                             "reads, not the correction the control applied", "name the correction's own column, um")
        if col not in columns:
            raise InputError(f"applied correction of {target}", f"column {col} missing", "name a column of the file")
    values, bad, t = _term_values(model, columns)
    if t.size and window_s > t[-1] - t[0]:
        log.warning("window_s: %g s is longer than the data (%g s): the refit window is all of it", window_s,
                    t[-1] - t[0])
    window = (t >= t[-1] - window_s) & ~bad
    resolution = float(model.settings.get("resolution_K", 0.0))
    step = float(np.median(np.diff(t))) if t.size > 1 else 1.0
    targets, report = [], {}
    for m in model.targets:
        if m.target not in columns:
            raise InputError(f"data: column {m.target}", "missing; the refit needs the measured target",
                             "give a file with the measured displacement")
        y = np.asarray(columns[m.target], float)
        if m.target in applied:
            y = y + np.asarray(columns[applied[m.target]], float)  # the raw error, not what the correction left
        if model.run_reference:
            valid = np.flatnonzero(np.isfinite(y))
            y = y - y[valid[0]]
        X = np.column_stack(values[m.target])
        rows = np.flatnonzero(window & np.isfinite(y))
        if rows.size < 4 * (X.shape[1] + 1):
            raise InputError(f"refit of {m.target}", f"only {rows.size} valid samples in the window",
                             "give a longer window or more data")
        var = np.array([noise_sd(term, resolution, step, float(model.settings.get("smooth_s", 0.0))) ** 2
                        for term in m.terms])
        cut = rows[: int(rows.size * (1 - CHECK_SHARE))]
        check = rows[cut.size:]
        c0, c = _solve(X[cut], y[cut], var, not model.run_reference)
        current = np.asarray(m.coefficients)
        now_mae = float(np.mean(np.abs((0.0 if model.run_reference else m.intercept_um) + X[check] @ current
                                       - y[check])))
        new_mae = float(np.mean(np.abs(c0 + X[check] @ c - y[check])))
        kept = not new_mae < now_mae
        report[m.target] = {"kept": kept, "current_mae_um": now_mae, "refit_mae_um": new_mae,
                            "samples": int(rows.size)}
        if kept:
            log.info("%s: refit kept the current coefficients (%.3g um against %.3g um on the window's end)",
                     m.target, now_mae, new_mae)
            targets.append(m)
            continue
        c0, c = _solve(X[rows], y[rows], var, not model.run_reference)
        targets.append(dataclasses.replace(m, coefficients=tuple(float(v) for v in c), intercept_um=float(c0),
                                           residual=residual_stats(c0 + X[rows] @ c - y[rows]),
                                           noise_um=float(np.sqrt(var @ c**2))))
    span = {**model.fit_span, "refit_window_s": float(window_s), "refit_end_s": float(t[-1])}
    return dataclasses.replace(model, targets=tuple(targets), fit_span=span), report
