"""Pictures of one run against time: its channels and the paper's Figs. 10–13 analogues (fluid
temperatures; θ rises and δ). :mod:`.pictures` writes them into a run directory."""
from __future__ import annotations

import numpy as np

from gatetherm.validation.plots import figure

THETAS = (("theta_A_degC", "θ_A"), ("theta_B_degC", "θ_B"), ("theta_C_degC", "θ_C"))
"""The response's temperature signals and their labels."""


def pump_phases(t, on) -> list[tuple[float, float]]:
    """(start, end) of the runs of ``on`` (booleans at the times ``t``): the last sample of a
    phase ends it at the next sample."""
    on = np.asarray(on, bool)
    edges = np.flatnonzero(np.diff(np.r_[0, on.astype(int), 0]))
    return [(t[a], t[min(b, len(t) - 1)]) for a, b in zip(edges[::2], edges[1::2])]


def shade(ax, t, on, label: str = "pump on") -> None:
    """Grey bands where ``on``; the first band carries ``label`` for the legend."""
    for k, (a, b) in enumerate(pump_phases(t, on)):
        ax.axvspan(a, b, color="0.9", lw=0, label=label if k == 0 else None, zorder=0)


def plot_fluids(cols: dict, problem, title: str = "", ax=None):
    """Fig. 10 analogue: the temperature of each fluid volume of ``problem`` (a
    :class:`~gatetherm.solvers.problem.Problem`; ``T_<name>_degC``), its supply where that is a
    column, and the mean of its wetted wall where the problem reports it, the phases its pump
    runs shaded. Returns the Axes."""
    ax = figure((7, 4)) if ax is None else ax
    t, fluids = cols["time_s"] / 60.0, problem.fluids
    for k, f in enumerate(fluids):
        tag = f" of {f.name}" if len(fluids) > 1 else ""
        if f.pump.text in cols and k == 0:
            shade(ax, t, cols[f.pump.text] > 0.5)
        if f.supply.text in cols:
            ax.plot(t, cols[f.supply.text], label="supply" + tag)
        ax.plot(t, cols[f"T_{f.name}_degC"], label=f.name.replace("_", " "))
        for name, boundary in problem.means:
            if boundary == f.boundary:
                ax.plot(t, cols[f"T_{name}_degC"], label=f"{name.replace('_', ' ')} (mean)")
    ax.set(xlabel="time [min]", ylabel="temperature [°C]", title=title)
    ax.legend()
    ax.grid(alpha=0.3)
    return ax


def plot_response(cols: dict, title: str = "", axes=None, fig=None, labels=None):
    """Figs. 11–13 analogue: θ_A, θ_B, θ_C rises (top) and δ (bottom) against time, pump
    phases shaded; ``labels``: the signals' legend entries (:func:`~gatetherm.validation.plots.labels.signal_labels`
    of the case). Returns the two Axes."""
    return plot_responses({"": cols}, title, axes, fig, labels)


def plot_responses(runs: dict, title: str = "", axes=None, fig=None, labels=None):
    """Figs. 11–13 analogue for one or more runs of the same schedule ({label: columns}: solid
    lines for the first, dashed for the second, …): θ_A, θ_B, θ_C rises and δ against time,
    pump phases shaded; on ``axes`` (two), or two panels of ``fig`` or of a new figure.
    ``labels``: legend entries by column (default: θ_A, θ_B, θ_C, δ). Returns the two Axes."""
    labels = labels or {}
    axes = figure((7.5, 6.5), 2, 1, fig, sharex=True) if axes is None else axes
    a1, a2 = axes
    first = next(iter(runs.values()))
    t0 = first["time_s"] / 60.0
    for ax in (a1, a2):
        if "pump" in first:
            shade(ax, t0, first["pump"] > 0.5)
    for k, (name, cols) in enumerate(runs.items()):
        t, ls, tag = cols["time_s"] / 60.0, ("-", "--", ":")[k % 3], f" {name}" if name else ""
        for i, (key, lab) in enumerate(THETAS):
            a1.plot(t, cols[key] - cols[key][0], ls=ls, color=f"C{i}", label=labels.get(key, lab) + tag)
        a2.plot(t, cols["delta_um"], ls=ls, color="k", label=labels.get("delta_um", "δ") + tag)
        if "delta_E_um" in cols and k == 0:
            a2.plot(t, cols["delta_E_um"], ls=":", color="0.4", lw=0.9, label="δ at E (beam theory point)" + tag)
    a1.set(ylabel="temperature rise [K]", title=title)
    a2.axhline(0, color="0.5", lw=0.5)
    a2.set(xlabel="time [min]", ylabel="δ [µm] (+ = approach)")
    for ax in (a1, a2):
        ax.legend(fontsize="small", ncol=2 if len(runs) > 1 else 1)
        ax.grid(alpha=0.3)
    return axes


def plot_channels(cols: dict, title: str = "", axes=None, fig=None):
    """Every temperature (°C, top) and displacement (µm, bottom) column of a run against time.
    Returns the two Axes."""
    axes = figure((7, 6), 2, 1, fig, sharex=True) if axes is None else axes
    t = cols["time_s"] / 3600.0
    temps = [k for k in cols if k.endswith("_degC")]
    disp = [k for k in cols if k.endswith("_um")]
    for ax, keys, label in ((axes[0], temps, "temperature [°C]"), (axes[1], disp, "displacement [µm]")):
        for k in keys:
            ax.plot(t, cols[k], label=k)
        ax.set(ylabel=label)
        ax.grid(alpha=0.3)
        if keys:
            ax.legend(fontsize="small", ncol=2)
    axes[0].set_title(title)
    axes[1].set(xlabel="time [h]")
    return axes


def state_title(title: str, t: float | None) -> str:
    """The title of a picture of one state: ``title, t = … min``, or ``title, steady state`` for
    a steady run (``t`` None)."""
    when = "steady state" if t is None else f"t = {t / 60:.0f} min"
    return f"{title}, {when}" if title else when


def has_response(cols: dict) -> bool:
    """Whether ``cols`` hold the signals of :func:`plot_response` over time."""
    return len(cols["time_s"]) > 1 and all(k in cols for k in (*dict(THETAS), "delta_um"))
