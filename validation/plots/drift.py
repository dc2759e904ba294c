"""The thermal drift chart of a time series: displacement drifts, temperature drifts and the
inputs against time, the input phases shaded."""
from __future__ import annotations

from gatetherm.validation.plots import figure
from gatetherm.validation.plots.labels import unit
from gatetherm.validation.plots.run import shade as shade_phases


def _input_label(name: str) -> str:
    """An input's axis label with its unit: a pump is on at 1, off at 0."""
    if name == "pump" or name.endswith("_pump"):
        return f"{name} [1 = on, 0 = off]"
    u = unit(name)
    return f"{name} [{u}]" if u else f"{name} [as in the file]"


def plot_drift(t_s, displacement: dict, temperature: dict, inputs: dict, shade, title: str = "", axes=None):
    """Three panels against time ``t_s`` (s from the start): the drift of each displacement
    (µm; ``delta_um`` bold), of each temperature (K), and the inputs (temperatures on the left
    axis, others on the right); each dict maps a column name to its values. ``shade``:
    (label, on per sample) or None. On ``axes`` (three) or a new figure's; returns the Axes."""
    hours = t_s[-1] > 3 * 3600.0
    t = t_s / (3600.0 if hours else 60.0)
    axes = figure((8.0, 9.0), 3, 1, sharex=True) if axes is None else axes
    for ax in axes:
        if shade:
            shade_phases(ax, t, shade[1], shade[0])
        ax.grid(alpha=0.3)
    for n, d in displacement.items():
        axes[0].plot(t, d, lw=1.8 if n == "delta_um" else 1.0, color="k" if n == "delta_um" else None, label=n)
    axes[0].set_ylabel("displacement drift [µm]")
    for n, d in temperature.items():
        axes[1].plot(t, d, lw=1.0, label=n)
    axes[1].set_ylabel("temperature drift [K]")
    temps = [n for n in inputs if n.endswith("_degC")]
    for n in temps:
        axes[2].plot(t, inputs[n], label=n)
    others = [n for n in inputs if n not in temps]
    if temps:
        axes[2].set_ylabel("input temperature [°C]")
    if others:  # beside the temperatures on a right axis, else on the panel's own
        right = axes[2].twinx() if temps else axes[2]
        for i, n in enumerate(others):
            right.step(t, inputs[n], where="post", color=f"C{len(temps) + i}", ls="--", label=n)
        right.set_ylabel(", ".join(_input_label(n) for n in others))
        if temps:
            right.legend(fontsize="x-small", loc="upper right")
    if not inputs:  # no empty 0-1 panel: the time axis on the temperatures'
        axes[2].set_visible(False)
        axes[1].tick_params(labelbottom=True)
    axes[2 if inputs else 1].set_xlabel(f"time [{'h' if hours else 'min'}]")
    for ax in axes:
        handles = ax.get_legend_handles_labels()[0]
        if handles:
            ax.legend(fontsize="x-small", ncol=3 if len(handles) > 6 else 1, loc="upper left")
    axes[0].set_title(title)
    return axes
