"""Plots of the public API (``gt.plot``) of what the studies give: a compensation, an error model's
prediction, a diagnosis' residuals, a sweep's table, a sensor placement; those of a run, and the
conventions they share, are :mod:`gatetherm.validation.plots.api`."""
from __future__ import annotations

import os
from pathlib import Path

from gatetherm import InputError
from gatetherm.validation.plots.axes import _axes, _panels


def compensation(result, axes=None):
    """A compensation (:func:`gatetherm.compensate`): δ and its prediction, the prediction error,
    the compensated δ (with the actuator's stroke where it drove one), and the correction factors
    R_i, R_C where the method has them (the paper's), against time.

    Parameters
    ----------
    result : Compensation
        What :func:`gatetherm.compensate` returns.
    axes : four (or three) matplotlib.axes.Axes, optional
        Where to draw (default: a new figure of four panels, three without R_i, R_C; a panel left
        over is removed).

    Returns
    -------
    numpy.ndarray of matplotlib.axes.Axes
        The panels drawn on, titled with what was done (``result.label``).
    """
    from gatetherm.validation.plots.compensation import plot_compensation

    return plot_compensation(result.loop, axes, _panels(axes), title=result.label)


def prediction(model, data, axes=None):
    """What a thermal-error model predicts for a run, against the measured targets the run has,
    and the residual, one row per target; the model's fitting span shaded.

    Parameters
    ----------
    model : ErrorModel
        From ``gatetherm.studies.errormodel`` (``fit_error_model``, ``load_model``).
    data : Run, TimeSeries or mapping
        The run: the columns the model reads (and the targets, to compare).
    axes : array of matplotlib.axes.Axes, optional
        Targets × 2 (default: a new figure).

    Returns
    -------
    numpy.ndarray of matplotlib.axes.Axes
        Targets × 2: displacement, residual.
    """
    from gatetherm.validation.plots.errormodel import plot_model_prediction

    return plot_model_prediction(model, getattr(data, "columns", data), axes, _panels(axes))


def residuals(diagnosis, axes=None):
    """A diagnosis' residuals (:func:`gatetherm.diagnose`): measured minus the baseline model per
    channel, its systematic part, the resolution band and the significant stretches, the phases
    shaded and the end of the training window dashed.

    Parameters
    ----------
    diagnosis : Diagnosis
        What :func:`gatetherm.diagnose` returns.
    axes : array of matplotlib.axes.Axes, optional
        One per channel (default: a new figure).

    Returns
    -------
    numpy.ndarray of matplotlib.axes.Axes
        Channels × 1.
    """
    from gatetherm.validation.plots.discrepancy import plot_residuals

    return plot_residuals(diagnosis, axes, _panels(axes))


def sweep(rows, x: str, y: str, hue: str | None = None, ax=None, **options):
    """A sweep's ``y`` against ``x``: lines with markers, one colour per value of ``hue``.

    Parameters
    ----------
    rows : sequence of mappings, or path
        The sweep's table: its rows, or its ``table.csv`` (``gatetherm sweep``).
    x, y, hue : str
        Columns of the table (``hue``: one line per value).
    ax : matplotlib.axes.Axes, optional
    **options
        ``title``, ``logx``, ``hline``, ``lines_by`` of
        :func:`gatetherm.validation.plots.sweep.plot_xy`.

    Returns
    -------
    matplotlib.axes.Axes
        Rows without a number in ``x`` or ``y`` are left out.
    """
    from gatetherm.validation.plots.sweep import plot_xy

    if isinstance(rows, (str, os.PathLike)):
        import csv

        if not Path(rows).is_file():
            raise InputError("rows", f"no such file {str(rows)!r}", "give a sweep's table.csv or its rows")
        with open(rows, newline="", encoding="utf-8") as f:
            rows = list(csv.DictReader(f))
    return plot_xy(rows, x, y, hue, ax=_axes(ax), **options)


def sensors(placement, case, ax=None, probes=None):
    """A sensor placement (:func:`gatetherm.place_sensors`) on the machine: the outline (3-D: the
    surface nodes, seen along the axis of least extent), the candidates (grey), the screened ones
    (open circles), the chosen points (red stars, named) and the case's own thermocouples (blue).

    Parameters
    ----------
    placement : Placement
        What :func:`gatetherm.place_sensors` returns.
    case : Case
        The case it was made for (its mesh is drawn).
    ax : matplotlib.axes.Axes, optional
    probes : mapping of str to coordinates, optional
        Points to mark, m (default: the case's temperature probes).

    Returns
    -------
    matplotlib.axes.Axes
        Coordinates in m.
    """
    from gatetherm.validation.plots.sensors import plot_machine

    if probes is None:
        probes = {p.name: p.xyz for p in case.problem.probes if "T" in p.quantities}
    return plot_machine(case.mesh, placement, _axes(ax), probes)


def sensor_curve(placement, ax=None):
    """A sensor placement's held-out error against the number of sensors: per target the MAE on
    the held-out loads (solid) and leave one training load out (dashed), and the same model family
    given the case's θ_A, θ_B, θ_C (stars at 3), where it has them.

    Parameters
    ----------
    placement : Placement
        What :func:`gatetherm.place_sensors` returns.
    ax : matplotlib.axes.Axes, optional

    Returns
    -------
    matplotlib.axes.Axes
        MAE in µm against the sensor count.
    """
    from gatetherm.validation.plots.sensors import plot_curve

    return plot_curve(placement, _axes(ax))
