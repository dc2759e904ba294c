"""Figures of the reduced-model study (``gatetherm validate rom``): the reduced model's δ error
against the FE runs, and the residual band of each compensator per case."""
from __future__ import annotations

import numpy as np
from matplotlib.ticker import ScalarFormatter

from gatetherm.validation.plots import figure

COMPENSATORS = (("paper_um", "paper (K theory, 5 min)"), ("mlr_um", "MLR (5 min)"),
                ("rom_5min_um", "rom, 5 min"), ("rom_event_um", "rom, event-triggered"))
"""Columns of the study's rows drawn as bars, with their legend."""


def plot_rom_error(errors: dict, ax=None):
    """δ_rom − δ_FE (µm) against time, one curve per (dimension, condition). Returns the Axes."""
    ax = figure((7, 3.6)) if ax is None else ax
    for (dim, n), (t, err) in sorted(errors.items()):
        ax.plot(np.asarray(t) / 3600.0, err, ls="-" if dim == 2 else "--", color=f"C{n - 1}",
                label=f"{dim}-D, condition {n}")
    ax.axhline(0.0, color="0.5", lw=0.6)
    ax.set(xlabel="time [h]", ylabel="δ_rom − δ_FE [µm]", title="Reduced model (30 states) against the FE runs")
    ax.grid(alpha=0.3)
    ax.legend(fontsize="small", ncol=2)
    return ax


def plot_rom_bands(rows, ax=None):
    """Residual band (µm, log scale) of each compensator per case of the study. Returns the Axes."""
    ax = figure((max(7.0, 0.45 * len(rows) + 2.0), 4.2)) if ax is None else ax
    x, w = np.arange(len(rows)), 0.8 / len(COMPENSATORS)
    for k, (field, label) in enumerate(COMPENSATORS):
        ax.bar(x + (k - 1.5) * w, [getattr(r, field) for r in rows], w, label=label, color=f"C{k}")
    ax.set_yscale("log")
    ax.yaxis.set_major_formatter(ScalarFormatter())
    ax.set_xticks(x, [f"{r.case if r.case != 'measured' else r.data.split()[0]}, c{r.condition}"
                      + (f" ({r.data.split()[0]})" if r.case == "model" else "") for r in rows],
                  rotation=60, ha="right", fontsize="small")
    ax.set(ylabel="residual band [µm]", title="Compensated δ: residual band after the first 10 min")
    ax.grid(axis="y", alpha=0.3, which="both")
    ax.legend(fontsize="small", ncol=2)
    return ax
