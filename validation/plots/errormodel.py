"""Thermal-error model plots: measured and predicted displacement and the residual per channel,
and the held-out error against the number of sensors."""
from __future__ import annotations

import numpy as np

from gatetherm.validation.plots import figure


def plot_prediction(t_s, predicted, measured=None, ax=None, residual_ax=None, name: str = "delta", span=None):
    """Predicted (and measured) displacement of one channel against time on ``ax``; the residual
    (measured - predicted) on ``residual_ax`` if given. ``span`` (s, s) shades the fitting span.
    Displacements in um, times in s (drawn in h). Returns ``ax``."""
    ax = figure((7.0, 3.0)) if ax is None else ax
    t_h = np.asarray(t_s) / 3600.0
    if measured is not None:
        ax.plot(t_h, measured, color="k", lw=0.9, label=f"{name} measured")
    ax.plot(t_h, predicted, color="C1", lw=0.9, label=f"{name} predicted")
    ax.set_ylabel("µm")
    for a in (ax, residual_ax):
        if a is None:
            continue
        if span is not None:
            a.axvspan(span[0] / 3600.0, span[1] / 3600.0, color="0.92", zorder=0)
        a.grid(True, lw=0.3)
    if residual_ax is not None and measured is not None:
        r = np.asarray(measured) - np.asarray(predicted)
        residual_ax.plot(t_h, r, color="C3", lw=0.8, label=f"residual, MAE {np.nanmean(np.abs(r)):.2f} µm")
        residual_ax.set_ylabel("µm")
        residual_ax.legend(fontsize="small", loc="upper left")
    ax.legend(fontsize="small", loc="upper left")
    return ax


def plot_predictions(t_s, predicted: dict, measured: dict, span=None, axes=None, fig=None):
    """One row per target: displacement (left) and residual (right), time in h; on ``axes``
    (targets × 2), or panels of ``fig`` or of a new figure. Returns the Axes."""
    n = len(predicted)
    axes = np.reshape(figure((10.0, 2.2 * n + 0.6), n, 2, fig, sharex=True) if axes is None else axes, (n, 2))
    for row, (name, pred) in zip(axes, predicted.items()):
        plot_prediction(t_s, pred, measured.get(name), row[0], row[1] if name in measured else None, name, span)
    for a in axes[-1]:
        a.set_xlabel("time / h")
    return axes


def plot_model_prediction(model, columns, axes=None, fig=None):
    """What the error model ``model`` predicts for the run ``columns`` (a mapping or
    :class:`~gatetherm.studies.run.timeseries.TimeSeries` of the columns it reads), against the
    measured targets the run has, its fitting span shaded: :func:`plot_predictions`."""
    from gatetherm.studies.errormodel.model import predict

    pred, span = predict(model, columns), (model.fit_span.get("start_s"), model.fit_span.get("end_s"))
    return plot_predictions(columns["time_s"], pred, {n: columns[n] for n in pred if n in columns},
                            None if None in span else span, axes, fig)


def plot_selection(selection, ax=None, name: str = ""):
    """Held-out MAE (um) against the number of terms along each form's forward-selection path, the
    count of sensors written at each point (``selection``: a target's :attr:`TargetModel.selection`).
    Returns ``ax``."""
    ax = figure((7.0, 3.0)) if ax is None else ax
    for form in dict.fromkeys(s["form"] for s in selection):
        steps = [s for s in selection if s["form"] == form]
        ax.plot(range(len(steps)), [s["cv_mae_um"] for s in steps], "o-", label=f"{name} {form}".strip())
        for k, s in enumerate(steps):
            ax.annotate(str(s["sensors"]), (k, s["cv_mae_um"]), fontsize="x-small", xytext=(2, 3),
                        textcoords="offset points")
    ax.set_xlabel("terms (numbers: sensors)")
    ax.set_ylabel("held-out MAE / µm")
    ax.grid(True, lw=0.3)
    ax.legend(fontsize="small")
    return ax
