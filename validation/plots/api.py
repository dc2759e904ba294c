"""Plots of the public API (``gt.plot``): each takes ``ax=`` (a matplotlib Axes; a new figure's
when None), draws on it and returns it; none chooses a backend or writes a file."""
from __future__ import annotations

LABELS = {"_um": "displacement [µm]", "_degC": "temperature [°C]", "_MPa": "stress [MPa]"}


def _axes(ax):
    if ax is None:
        import matplotlib.pyplot as plt

        _, ax = plt.subplots()
    return ax


def series(run, *columns: str, ax=None, hours: bool = True):
    """The ``columns`` of a run (a :class:`gatetherm.api.Run`, or a mapping of columns with ``time_s``)
    against time; returns the Axes."""
    ax = _axes(ax)
    cols = run.columns if hasattr(run, "columns") else run
    t = cols["time_s"] / (3600.0 if hours else 60.0)
    for c in columns:
        ax.plot(t, cols[c], label=c)
    unit = next((v for k, v in LABELS.items() if columns and columns[0].endswith(k)), "")
    ax.set(xlabel=f"time [{'h' if hours else 'min'}]", ylabel=unit)
    if len(columns) > 1:
        ax.legend(fontsize="small")
    ax.grid(alpha=0.3)
    return ax
