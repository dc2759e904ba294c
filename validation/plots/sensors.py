"""Sensor placement plots: the held-out error against the number of sensors, and the machine
with its candidates and the chosen points (:mod:`gatetherm.studies.sensors`)."""
from __future__ import annotations

import numpy as np
from matplotlib.collections import LineCollection

from gatetherm.studies.sensors.candidates import outer_facets
from gatetherm.validation.plots import figure


def _axes(ax, size):
    return figure(size) if ax is None else ax


def plot_curve(placement, ax=None):
    """Held-out MAE (solid) and leave-one-load-out MAE (dashed) of every target against the number
    of sensors, um; the same family given the case's own thermocouples (θ_A, θ_B, θ_C) dotted at
    its sensor count (3). Returns ``ax``."""
    ax = _axes(ax, (6.0, 3.6))
    k = [c.count for c in placement.curve]
    for i, target in enumerate(placement.curve[0].held_out_mae_um):
        colour = f"C{i}"
        ax.plot(k, [c.held_out_mae_um[target] for c in placement.curve], "o-", color=colour,
                label=f"{target}, held-out loads")
        ax.plot(k, [c.cv_mae_um[target] for c in placement.curve], "s--", color=colour, ms=4, lw=0.8,
                label=f"{target}, leave one training load out")
        if placement.signals:
            ax.plot([3], [placement.signals["held_out_mae_um"][target]], "*", color=colour, ms=11,
                    label=f"{target}, the case's θ_A, θ_B, θ_C (held-out)")
    ax.set_xlabel("sensors")
    ax.set_ylabel("MAE [µm]")
    ax.set_xticks(range(1, max(k + [3 if placement.signals else 1]) + 1))
    ax.set_ylim(bottom=0)
    ax.grid(True, lw=0.3)
    ax.legend(fontsize="x-small")
    return ax


def plot_machine(mesh, placement, ax=None, probes=None):
    """The mesh's outer surface (3-D: its nodes, seen along the axis of least extent), the
    candidates (grey), the shortlist (open circles), the chosen sensors (red, named) and
    ``probes`` ({name: xyz}, m: e.g. the case's own thermocouples, blue). Returns ``ax``."""
    ax = _axes(ax, (6.0, 5.0))
    pts = mesh.points
    axes = [0, 1] if mesh.dim == 2 else sorted(np.argsort(np.ptp(pts, axis=0))[1:])
    facets = outer_facets(mesh.cells)
    if mesh.dim == 2:
        ax.add_collection(LineCollection(pts[facets][:, :, axes], colors="0.3", linewidths=0.6))
    else:
        surface = np.unique(facets)
        ax.plot(pts[surface, axes[0]], pts[surface, axes[1]], ",", color="0.75")
    xy = placement.candidates.xyz[:, axes]
    ax.plot(xy[:, 0], xy[:, 1], ".", color="0.6", ms=2, label=f"{len(xy)} candidates")
    sl = xy[placement.shortlist]
    ax.plot(sl[:, 0], sl[:, 1], "o", mfc="none", color="C0", ms=4, lw=0.5, label=f"{len(sl)} screened")
    for name, xyz in (probes or {}).items():
        ax.plot(xyz[axes[0]], xyz[axes[1]], "D", color="C9", ms=5)
        ax.annotate(name, (xyz[axes[0]], xyz[axes[1]]), xytext=(3, -9), textcoords="offset points",
                    fontsize="x-small", color="C9")
    for s in placement.sensors:
        ax.plot(s.xyz[axes[0]], s.xyz[axes[1]], "*", color="C3", ms=12)
        ax.annotate(s.name, (s.xyz[axes[0]], s.xyz[axes[1]]), xytext=(5, 4), textcoords="offset points",
                    fontsize="small", color="C3", weight="bold")
    ax.set_aspect("equal")
    ax.autoscale_view()
    labels = "xyz"
    ax.set_xlabel(f"{labels[axes[0]]} [m]")
    ax.set_ylabel(f"{labels[axes[1]]} [m]")
    ax.legend(fontsize="x-small", loc="best")
    return ax
