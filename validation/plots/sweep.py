"""Plots of sweep tables: y against x, one line per value of a hue column."""
from __future__ import annotations

import numpy as np
from matplotlib.ticker import NullFormatter, ScalarFormatter

from gatetherm.validation.plots import figure
from gatetherm.validation.plots.labels import axis_label, unit

SIZE = (6.0, 4.2)
"""Size of a one-panel sweep plot, inches."""


def _num(v) -> float:
    try:
        return float(v)
    except (TypeError, ValueError):
        return np.nan


def _value(key: str, value) -> str:
    """A legend entry ``key = value unit``."""
    u = unit(key)
    return f"{key} = {value}" + (f" {u}" if u and u != "1" else "")


def plot_xy(rows: list[dict], x: str, y: str, hue: str | None = None, title: str = "", logx: bool = False,
            hline: float | None = None, lines_by=(), ax=None):
    """Lines with markers of ``y`` over ``x`` (rows without a number left out): one colour per
    ``hue`` value, one line per combination of the ``lines_by`` columns (other swept
    parameters; line styles tell them apart, the legend names them); each axis labelled with its
    column's unit (:func:`~gatetherm.validation.plots.labels.unit`). Returns the Axes."""
    ax = figure(SIZE) if ax is None else ax
    hues = list(dict.fromkeys(r.get(hue) for r in rows)) if hue else [None]
    others = list(dict.fromkeys(tuple(r.get(k) for k in lines_by) for r in rows))
    styles = ["-", "--", ":", "-."]
    for i, h in enumerate(hues):
        for j, o in enumerate(others):
            grp = [r for r in rows if (not hue or r.get(hue) == h) and tuple(r.get(k) for k in lines_by) == o]
            pts = [p for p in sorted((_num(r.get(x)), _num(r.get(y))) for r in grp) if np.isfinite(p).all()]
            if not pts:
                continue
            label = ", ".join(([_value(hue, h)] if hue else []) + [_value(k, v) for k, v in zip(lines_by, o)])
            ax.plot(*zip(*pts), "o", ls=styles[j % len(styles)], ms=3.5, color=f"C{i % 10}", label=label or None)
    if hline is not None:
        ax.axhline(hline, color="0.4", lw=0.8, ls="--")
    if logx:  # ticks at the data, in plain numbers
        ax.set_xscale("log")
        ax.set_xticks(sorted({p for r in rows if np.isfinite(p := _num(r.get(x)))}))
        ax.xaxis.set_major_formatter(ScalarFormatter())
        ax.xaxis.set_minor_formatter(NullFormatter())
    ax.set_xlabel(axis_label(x))
    ax.set_ylabel(axis_label(y))
    ax.set_title(title, fontsize="medium")
    ax.grid(True, lw=0.3)
    if hue or lines_by:
        ax.legend(fontsize="x-small", ncol=2 if len(hues) * len(others) > 6 else 1)
    return ax


# --- the design study (studies/design.py) ---------------------------------------------------

def plot_positions(rows: list[dict], marks: dict[str, float], title: str = "", axes=None):
    """Swing of delta per condition (and the worst) over the tie-bar height, with the FE
    K_i, K_C at the tips below; vertical lines at ``marks`` (label -> l4). On ``axes`` (two)
    or a new figure's; returns the Axes."""
    axes = figure((6.4, 6.4), 2, 1, sharex=True) if axes is None else axes
    ax, bx = axes
    ok = [r for r in rows if r.get("status") == "ok"]
    conds = sorted({r["condition"] for r in ok})
    worst: dict = {}
    for i, c in enumerate(conds):
        pts = sorted((r["geometry.l4"], r["swing_um"]) for r in ok if r["condition"] == c)
        ax.plot(*zip(*pts), "o-", ms=3, color=f"C{i}", label=f"condition {c}")
        for l4, s in pts:
            worst[l4] = max(worst.get(l4, -np.inf), s)
    ax.plot(*zip(*sorted(worst.items())), "k--", lw=1, label="worst of 1-3")
    coef = sorted({(r["geometry.l4"], r["Ki_F_fe"], r["Kc_F_fe"]) for r in ok})
    bx.plot([c[0] for c in coef], [c[1] for c in coef], "o-", ms=3, color="C3", label="$K_i$ (FE, tips)")
    bx.plot([c[0] for c in coef], [c[2] for c in coef], "s-", ms=3, color="C4", label="$K_C$ (FE, tips)")
    for j, (label, x) in enumerate(marks.items()):
        for a in (ax, bx):
            a.axvline(x, color="0.3", lw=0.8, ls=(0, (4, 2 + 2 * j)))
        ax.annotate(label, (x, ax.get_ylim()[1]), fontsize="small", rotation=90, va="top", ha="right")
    ax.set_ylabel(r"5-h swing of $\delta$ (µm)")
    bx.set_ylabel("µm/K")
    bx.set_xlabel(r"tie-bar height $l_4$ (m)")
    for a in (ax, bx):
        a.grid(True, lw=0.3)
        a.legend(fontsize="small")
    ax.set_title(title, fontsize="medium")
    return axes


def plot_second(summary: list[dict], title: str = "", ax=None):
    """Worst swing over conditions 1-3 against the second tie bar's height, one line per
    first-bar height; the level without a second bar dashed. Returns the Axes."""
    ax = figure(SIZE) if ax is None else ax
    for i, l4 in enumerate(sorted({r["l4"] for r in summary})):
        rs = [r for r in summary if r["l4"] == l4]
        ref = [r["worst_swing_um"] for r in rs if r["l4_2"] == 0.0]
        pts = sorted((r["l4_2"], r["worst_swing_um"]) for r in rs if r["l4_2"] > 0)
        ax.plot(*zip(*pts), "o-", color=f"C{i}", label=f"$l_4$ = {l4:.3g} m, second bar at $l_{{4,2}}$")
        if ref:
            ax.axhline(ref[0], color=f"C{i}", ls="--", lw=1, label=f"$l_4$ = {l4:.3g} m, one bar")
    ax.set_xlabel(r"second tie-bar height $l_{4,2}$ (m)")
    ax.set_ylabel(r"worst 5-h swing of $\delta$, conditions 1-3 (µm)")
    ax.set_ylim(bottom=0)
    ax.grid(True, lw=0.3)
    ax.legend(fontsize="small")
    ax.set_title(title, fontsize="medium")
    return ax


def plot_histories(histories: dict[str, dict[int, tuple]], axes=None):
    """delta(t) per condition (one panel each), one line per design (label -> condition -> (t_s, delta_um)),
    on ``axes`` (one per condition) or a new figure's. Returns the Axes."""
    conds = sorted(next(iter(histories.values())))
    axes = np.atleast_1d(figure((6.4, 2.3 * len(conds)), len(conds), 1, sharex=True) if axes is None else axes)
    for ax, c in zip(axes, conds):
        for i, (label, runs) in enumerate(histories.items()):
            t, d = runs[c]
            ax.plot(np.asarray(t) / 3600.0, d, color=f"C{i}", label=label)
        ax.axhline(0.0, color="0.5", lw=0.6)
        ax.set_ylabel(rf"$\delta$ (µm), cond. {c}")
        ax.grid(True, lw=0.3)
    axes[0].legend(fontsize="x-small")
    axes[-1].set_xlabel("time (h)")
    return axes
