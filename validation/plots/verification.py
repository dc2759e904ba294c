"""Observed convergence: errors against mesh size and time step, log-log, with fitted orders."""
from __future__ import annotations

from gatetherm.validation.plots import figure


def plot_orders(spatial: dict, temporal: dict, axes=None):
    """Two panels: ``spatial`` {label: (h, L2 error, order)} and ``temporal`` {label: (dt, error, order)};
    each study's errors with markers, its observed order in the legend; on ``axes`` (two) or a
    new figure's. Returns the Axes."""
    axes = figure((10.0, 4.4), 1, 2) if axes is None else axes
    for ax, studies, xlabel, ylabel in ((axes[0], spatial, "element size h", "L2 error [K or m]"),
                                         (axes[1], temporal, "time step dt", "max nodal error [K]")):
        for i, (label, (x, err, p)) in enumerate(studies.items()):
            ax.loglog(x, err, "o-" if "heat" in label or ax is axes[1] else "s--", color=f"C{i % 10}", ms=4,
                      lw=1, label=f"{label}: {p:.2f}")
        ax.set(xlabel=xlabel, ylabel=ylabel)
        ax.grid(True, which="both", lw=0.3)
        ax.legend(fontsize="x-small", title="observed order", title_fontsize="x-small")
    axes[0].set_title("manufactured solutions (space)", fontsize="medium")
    axes[1].set_title("exact modal solution (time)", fontsize="medium")
    return axes
