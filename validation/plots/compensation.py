"""Compensation-run plots (paper Figs. 10-12 style), the Figs. 14-16 analogues of the
compensation study and the Fig. 5 analogue (piezo loops)."""
from __future__ import annotations

import os
from dataclasses import replace

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from gatetherm.studies.control import actuator as piezo
from gatetherm.studies.control.compensator import ClosedLoop
from gatetherm.validation.plots import save


def plot_compensation(loop: ClosedLoop, path: str | os.PathLike) -> None:
    """Four panels against time: delta and prediction, prediction error, compensated delta, R."""
    fig = Figure(figsize=(7.5, 9.0))
    FigureCanvasAgg(fig)
    axes = fig.subplots(4, 1, sharex=True)
    t_h = loop.t_s / 3600.0
    pr = loop.prediction
    axes[0].plot(t_h, loop.delta_um, label=r"measured $\delta$ (uncompensated)")
    axes[0].plot(t_h, loop.delta_pred_um, "--", label=r"predicted $\delta_{et}$")
    axes[0].set_ylabel(r"$\delta$ / µm")
    axes[1].plot(t_h, loop.delta_um - loop.delta_pred_um, color="C3")
    axes[1].set_ylabel(r"$\delta - \delta_{et}$ / µm")
    axes[2].plot(t_h, loop.delta_comp_um, color="C2", label=r"compensated $\delta$")
    axes[2].step(t_h, loop.stroke_um, where="post", color="0.5", lw=0.8, label="piezo at cutting area")
    axes[2].set_ylabel("µm")
    axes[3].plot(pr.t_s / 3600.0, pr.R_i, label=r"$R_i$")
    axes[3].plot(pr.t_s / 3600.0, pr.R_C, label=r"$R_C$")
    axes[3].set_ylabel("correction factor")
    axes[3].set_xlabel("time / h")
    if pr.peak_index is not None:
        for ax in axes:
            ax.axvline(pr.t_s[pr.peak_index] / 3600.0, color="0.6", lw=0.7, ls=":")
    for ax in axes:
        ax.grid(True, lw=0.3)
        if ax.get_legend_handles_labels()[0]:
            ax.legend(fontsize="small")
    save(fig, path)


def plot_piezo_loops(params: piezo.ActuatorParams, path: str | os.PathLike, steps: int = 30) -> dict:
    """Fig. 5 analogue: 0 -> max -> 0 V loops unloaded / preloaded, direct / reset drive.

    Returns {panel label: open-loop width in um} for the four cases drawn.
    """
    fig = Figure(figsize=(9.0, 4.2))
    FigureCanvasAgg(fig)
    axes = fig.subplots(1, 2, sharey=True)
    widths = {}
    for ax, preload in zip(axes, (0.0, params.preload_N)):
        for strategy, style in (("direct", "-o"), ("reset", "--s")):
            p = replace(params, preload_N=preload, strategy=strategy)
            volts, stroke = piezo.hysteresis_loop(p, steps)
            width = piezo.loop_width_um(p, steps)
            label = f"preload {preload:g} N, {strategy}"
            widths[label] = width
            ax.plot(volts, stroke, style, ms=3, mfc="none",
                    label=f"{strategy}: open loop {width:.2f} µm\n"
                    f"({p.transmission * width:.2f} µm at the cutting area)")
        ax.set_title(f"preload {preload:g} N, dead band {piezo.dead_band_um(p):.3g} µm", fontsize="medium")
        ax.axvline(params.bias_voltage_V, color="0.6", lw=0.7, ls=":")
        ax.set_xlabel(f"voltage / V (bias {params.bias_voltage_V:g} V dotted)")
        ax.grid(True, lw=0.3)
        ax.legend(fontsize="small", loc="lower right")
    axes[0].set_ylabel("stroke / µm")
    axes[0].set_xlim(0, params.max_voltage_V * 1.02)
    axes[0].set_ylim(bottom=min(0.0, float(np.min(stroke))) - 0.5)
    save(fig, path)
    return widths


def plot_condition_study(title: str, loops: dict[str, ClosedLoop], path: str | os.PathLike,
                         band_um: float = 7.0, settle_s: float = 600.0) -> None:
    """Figs. 14-16 analogue: uncompensated delta, prediction error delta - delta_et, and the
    compensated delta with the actuator in the loop, one line per predictor in ``loops``."""
    fig = Figure(figsize=(7.5, 8.0))
    FigureCanvasAgg(fig)
    axes = fig.subplots(3, 1, sharex=True)
    first = next(iter(loops.values()))
    axes[0].plot(first.t_s / 3600.0, first.delta_um, color="k")
    axes[0].set_ylabel(r"uncompensated $\delta$ / µm")
    axes[0].set_title(title, fontsize="medium")
    for k, (label, loop) in enumerate(loops.items()):
        t_h = loop.t_s / 3600.0
        style = dict(color=f"C{k}", lw=0.9, ls=("-", "--", ":", "-.")[k % 4], label=label)
        axes[1].plot(t_h, loop.delta_um - loop.delta_pred_um, **style)
        axes[2].plot(t_h, loop.delta_comp_um, **style)
    axes[1].set_ylabel(r"$\delta - \delta_{et}$ / µm")
    axes[2].set_ylabel(r"compensated $\delta$ / µm")
    axes[2].set_xlabel("time / h")
    for ax in axes[1:]:
        ax.axhspan(-band_um, band_um, color="0.85", zorder=0, label=f"paper: ±{band_um:g} µm")
        ax.axvline((first.t_s[0] + settle_s) / 3600.0, color="0.6", lw=0.7, ls=":")
        ax.legend(fontsize="x-small", ncol=2)
    for ax in axes:
        ax.grid(True, lw=0.3)
    save(fig, path)
