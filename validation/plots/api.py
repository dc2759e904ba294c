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

from gatetherm import InputError
from gatetherm.checks import argument
from gatetherm.validation.plots import save
from gatetherm.validation.plots.api_studies import (  # noqa: F401 (gt.plot's)
    compensation, prediction, residuals, sensor_curve, sensors, sweep)
from gatetherm.validation.plots.axes import LABELS, _axes, _panels, _run, _title  # noqa: F401 (re-exported)
from gatetherm.validation.plots.painter import Painter

__all__ = ["Painter", "channels", "compensation", "deformed", "field", "fluids", "prediction", "residuals", "response",
           "save", "sensor_curve", "sensors", "series", "sweep"]


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
    if ax is not None and not hasattr(ax, "plot"):
        _axes(ax)  # TypeError naming ax, before the columns
    if not columns:
        raise InputError("columns", "none given: nothing to draw", f"name columns, e.g. gt.plot.series(run, "
                         f"{next((repr(c) for c in cols.keys() if c != 'time_s'), repr('delta_um'))})")
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

    _need(run, ("theta_A_degC", "theta_B_degC", "theta_C_degC", "delta_um"), "the four signals of [signals]")
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

    if not run.scenario.model.problem.fluids:
        raise InputError("run", "its case has no [fluids]: no fluid temperature to draw",
                         "draw a run of a case with [fluids.NAME], or its columns with gt.plot.series")
    return plot_fluids(run.columns, run.scenario.model.problem, _title(run), _axes(ax))


def _need(run, columns, what: str) -> None:
    """InputError naming the columns a plot needs that ``run`` lacks."""
    cols = run.columns if hasattr(run, "columns") else run
    missing = [c for c in columns if c not in cols.keys()]
    if missing:
        raise InputError("run", f"has no {', '.join(missing)} ({what})",
                         "draw a run of a case that has them, or its columns with gt.plot.series")


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
