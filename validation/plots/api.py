"""Plots of the public API (``gt.plot``), for notebooks and scripts::

    run = gt.run(gt.load_case("validation/examples/c_frame/case.toml"))
    ax = gt.plot.series(run, "delta_um")          # a new figure's Axes
    gt.plot.field(run, "T", t=run.time[-1], ax=ax2)  # or the Axes you give
    gt.plot.save(ax, "delta.png")

Each takes what the API gives (a :class:`~gatetherm.api.Run`, a compensation, a diagnosis …) and
``ax=`` (``axes=`` for a figure of several panels), draws on it and returns it. None chooses a
backend or writes a file (:func:`save` writes a PNG; a :class:`Painter` writes them in processes of
its own, beside the work: ``run.write(out, painter=painter)``). Given no Axes, a plot draws on a new
*pyplot* figure, so that it shows in a notebook or with ``plt.show()`` as your own figures do:
pyplot uses the backend matplotlib would anyway (``MPLBACKEND``, ``matplotlibrc``, the
notebook's) and leaves it so. The pictures the command line and the report write come from the
same functions on bare figures (:mod:`gatetherm.validation.plots`).
"""
from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from gatetherm import InputError
from gatetherm.checks import argument
from gatetherm.validation.plots import save
from gatetherm.validation.plots.painter import Painter

__all__ = ["Painter", "channels", "compensation", "deformed", "field", "fluids", "prediction", "residuals", "response",
           "save", "sensor_curve", "sensors", "series", "sweep"]

LABELS = {"_um": "displacement [µm]", "_degC": "temperature [°C]", "_MPa": "stress [MPa]"}


def _figure():
    import matplotlib.pyplot as plt

    return plt.figure()


def _axes(ax):
    if ax is not None and not hasattr(ax, "plot"):
        argument("ax", ax, (), "a matplotlib Axes or None", "None draws on a new figure")
    return _figure().subplots() if ax is None else ax


def _panels(axes):
    """The ``fig`` for a plot of several panels: a new pyplot figure unless ``axes`` are given."""
    if axes is not None and not all(hasattr(a, "plot") for a in np.asarray(axes, dtype=object).flat):
        argument("axes", axes, (), "matplotlib Axes (as many as the plot's panels) or None",
                 "None draws on a new figure")
    return _figure() if axes is None else None


def _run(run, what: str = "a Run") -> None:
    """TypeError unless ``run`` is a run of the API (:func:`gatetherm.run`)."""
    if not hasattr(run, "scenario"):
        argument("run", run, (), what, "make one with gt.run(case)")


def _title(run, t: float | None = None) -> str:
    name = getattr(getattr(run, "case", None), "name", "")
    if t is None:
        return name
    when = "steady state" if len(getattr(run, "time", ())) <= 1 else f"t = {t / 3600:.3g} h"
    return f"{name}, {when}" if name else when


def series(run, *columns: str, ax=None, hours: bool = True):
    """Columns of a run against time.

    Parameters
    ----------
    run : Run or mapping
        A :class:`gatetherm.api.Run`, a time series, or a mapping of columns with ``time_s``.
    *columns : str
        The columns drawn (``"delta_um"``, ``"theta_A_degC"`` …).
    ax : matplotlib.axes.Axes, optional
        Where to draw (default: a new figure).
    hours : bool
        Time in h (else min).

    Returns
    -------
    matplotlib.axes.Axes
        One line per column, labelled with its name.
    """
    cols = run.columns if hasattr(run, "columns") else run
    if not hasattr(cols, "keys"):
        argument("run", run, (), "a Run, a time series or a mapping of columns", "make one with gt.run(case)")
    missing = [c for c in ("time_s", *columns) if c not in cols.keys()]
    if missing:
        raise InputError("columns", f"{', '.join(map(repr, missing))} not among the run's columns",
                         f"choose from {', '.join(list(cols.keys())[:12])}")
    ax = _axes(ax)
    t = cols["time_s"] / (3600.0 if hours else 60.0)
    for c in columns:
        ax.plot(t, cols[c], label=c)
    unit = next((v for k, v in LABELS.items() if columns and columns[0].endswith(k)), "")
    ax.set(xlabel=f"time [{'h' if hours else 'min'}]", ylabel=unit)
    if len(columns) > 1:
        ax.legend(fontsize="small")
    ax.grid(alpha=0.3)
    return ax


def channels(run, axes=None):
    """Every channel of a run against time: temperatures (°C) above, displacements (µm) below.

    Parameters
    ----------
    run : Run
    axes : pair of matplotlib.axes.Axes, optional
        Where to draw (default: a new figure of two panels).

    Returns
    -------
    numpy.ndarray of matplotlib.axes.Axes
        The two panels, one line per ``*_degC`` and per ``*_um`` column.
    """
    from gatetherm.validation.plots.run import plot_channels

    return plot_channels(run.columns, _title(run), axes, _panels(axes))


def response(run, axes=None):
    """The response of the paper's Figs. 11–13: the rises of θ_A, θ_B, θ_C (top) and δ (bottom)
    against time, the pump phases shaded where the run has a ``pump`` column.

    Parameters
    ----------
    run : Run
        A run with the signals ``theta_A_degC``, ``theta_B_degC``, ``theta_C_degC`` and ``delta_um``.
    axes : pair of matplotlib.axes.Axes, optional
        Where to draw (default: a new figure of two panels).

    Returns
    -------
    numpy.ndarray of matplotlib.axes.Axes
        The two panels.
    """
    from gatetherm.validation.plots.labels import signal_labels
    from gatetherm.validation.plots.run import plot_response

    return plot_response(run.columns, _title(run), axes, _panels(axes), signal_labels(run.case.problem))


def fluids(run, ax=None):
    """The fluid temperatures of the paper's Fig. 10: each fluid volume of the case
    (``T_<name>_degC``), its supply where a column gives it and the mean of its wetted wall where
    the case reports one, the phases its pump runs shaded.

    Parameters
    ----------
    run : Run
        A run of a case with ``[fluids]`` (the paper's frame: its oil tank).
    ax : matplotlib.axes.Axes, optional

    Returns
    -------
    matplotlib.axes.Axes
    """
    from gatetherm.validation.plots.run import plot_fluids

    return plot_fluids(run.columns, run.scenario.model.problem, _title(run), _axes(ax))


def field(run, name: str = "T", t: float | None = None, ax=None):
    """A nodal field on the mesh at a kept time: a tripcolor in 2-D, a picture of the body's
    surface (pyvista, off screen) in 3-D, with a colour bar.

    Parameters
    ----------
    run : Run
    name : str
        ``"T"`` (drawn in °C), ``"u"`` (its magnitude, µm), ``"sigma_xx"`` … or ``"von_mises"`` (MPa).
    t : float, optional
        Time, s (default: the last sample); a state must be kept there (``gt.run(..., keep=...)``).
    ax : matplotlib.axes.Axes, optional

    Returns
    -------
    matplotlib.axes.Axes
        2-D: the tripcolor's values are the field's at the mesh nodes.
    """
    from gatetherm.validation.plots.field import plot_field

    _run(run)
    kept, _ = run.state(float(run.time[-1]) if t is None else t)
    return plot_field(run.scenario.model.fmesh, name, run.field(name, kept), _title(run, kept), _axes(ax))


def deformed(run, t: float | None = None, ax=None):
    """Temperature on the deformed body (pyvista, off screen; the displacement magnified by a
    power of ten so that it shows), the undeformed edges in grey, with a colour bar.

    Parameters
    ----------
    run : Run
        A run of a case with elasticity.
    t : float, optional
        Time, s (default: the last sample); a state must be kept there.
    ax : matplotlib.axes.Axes, optional

    Returns
    -------
    matplotlib.axes.Axes
    """
    from gatetherm.validation.plots.field import draw_deformed

    _run(run)
    if run.scenario.model.elastic is None:
        raise InputError("run", f"{run.case.name} has no displacements (a heat-only case): nothing to deform",
                         "plot its temperature: gt.plot.field(run, 'T')")
    kept, _ = run.state(float(run.time[-1]) if t is None else float(t))
    return draw_deformed(run.scenario, kept, lambda s: _title(run, s), ax=_axes(ax))


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
