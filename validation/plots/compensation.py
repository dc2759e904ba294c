"""Compensation-run plots (paper Figs. 10-12 style), the Figs. 14-16 analogues of the
compensation study and the Fig. 5 analogue (piezo loops)."""
from __future__ import annotations

from dataclasses import replace

import numpy as np

from gatetherm.studies.control import actuator as piezo
from gatetherm.studies.control.compensator import ClosedLoop
from gatetherm.validation.plots import figure


def plot_compensation(loop: ClosedLoop, axes=None, fig=None, title: str = "", delta: str = "δ"):
    """Panels against time: δ and its prediction, the prediction error, the compensated δ (with
    the actuator's stroke where the loop drove one: a piezo model), and the correction factors
    R_i, R_C where the method has them (the paper's; none for the others: three panels). On
    ``axes`` (four, or three; a fourth left over is removed), or panels of ``fig`` or of a new
    figure; ``delta``: what δ is on this machine (a :func:`~gatetherm.validation.plots.labels.signal_labels`
    entry). Returns the Axes drawn on."""
    pr = loop.prediction
    has_R = bool(np.isfinite(np.asarray(pr.R_i, float)).any())
    n = 4 if has_R else 3
    if axes is None:
        axes = figure((7.5, 9.0 if has_R else 7.0), n, 1, fig, sharex=True)
    else:
        for extra in list(axes)[n:]:
            extra.remove()
        axes = axes[:n]
    t_h = loop.t_s / 3600.0
    axes[0].plot(t_h, loop.delta_um, label=f"{delta} (uncompensated)")
    axes[0].plot(t_h, loop.delta_pred_um, "--", label="predicted δ_et")
    axes[0].set_ylabel("δ [µm]")
    axes[1].plot(t_h, loop.delta_um - loop.delta_pred_um, color="C3")
    axes[1].set_ylabel("δ − δ_et [µm]")
    axes[2].plot(t_h, loop.delta_comp_um, color="C2", label="compensated δ")
    if np.isfinite(np.asarray(loop.voltage_V, float)).any():  # an actuator model drove it
        axes[2].step(t_h, loop.stroke_um, where="post", color="0.5", lw=0.8, label="actuator stroke (piezo model)")
    axes[2].set_ylabel("compensated δ [µm]")
    if has_R:
        axes[3].plot(pr.t_s / 3600.0, pr.R_i, label="R_i")
        axes[3].plot(pr.t_s / 3600.0, pr.R_C, label="R_C")
        axes[3].set_ylabel("correction factor [1]")
    axes[-1].set_xlabel("time [h]")
    axes[0].set_title(title, fontsize="medium")
    if pr.peak_index is not None:
        for ax in axes:
            ax.axvline(pr.t_s[pr.peak_index] / 3600.0, color="0.6", lw=0.7, ls=":")
    for ax in axes:
        ax.grid(True, lw=0.3)
        if ax.get_legend_handles_labels()[0]:
            ax.legend(fontsize="small")
    return axes


def piezo_drives(params: piezo.ActuatorParams) -> list[list[piezo.ActuatorParams]]:
    """The drives of the Fig. 5 analogue: [direct, reset] unloaded, then preloaded."""
    return [[replace(params, preload_N=preload, strategy=s) for s in ("direct", "reset")]
            for preload in (0.0, params.preload_N)]


def loop_widths(params: piezo.ActuatorParams, steps: int = 30) -> dict:
    """{"preload P N, STRATEGY": open-loop width in um} of the loops :func:`plot_piezo_loops` draws."""
    return {f"preload {p.preload_N:g} N, {p.strategy}": piezo.loop_width_um(p, steps)
            for pair in piezo_drives(params) for p in pair}


def plot_piezo_loops(params: piezo.ActuatorParams, axes=None, steps: int = 30):
    """Fig. 5 analogue: 0 -> max -> 0 V loops unloaded (left) / preloaded (right), direct /
    reset drive, on ``axes`` (two) or a new figure's. Returns the Axes."""
    axes = figure((9.0, 4.2), 1, 2, sharey=True) if axes is None else axes
    for ax, pair in zip(axes, piezo_drives(params)):
        for p, style in zip(pair, ("-o", "--s")):
            strategy, preload = p.strategy, p.preload_N
            volts, stroke = piezo.hysteresis_loop(p, steps)
            width = piezo.loop_width_um(p, steps)
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
    return axes


def plot_condition_study(title: str, loops: dict[str, ClosedLoop], band_um: float = 7.0,
                         settle_s: float = 600.0, axes=None):
    """Figs. 14-16 analogue: uncompensated delta, prediction error delta - delta_et, and the
    compensated delta with the actuator in the loop, one line per predictor in ``loops``, on
    ``axes`` (three) or a new figure's. Returns the Axes."""
    axes = figure((7.5, 8.0), 3, 1, sharex=True) if axes is None else axes
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
    return axes
