"""Plots of sweep tables: y against x, one line per value of a hue column."""
from __future__ import annotations

import os

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.ticker import NullFormatter, ScalarFormatter

from geometry.files import atomic_path


def new_axes(figsize=(6.0, 4.2)):
    fig = Figure(figsize=figsize)
    FigureCanvasAgg(fig)
    return fig, fig.add_subplot()


def save(fig, path: str | os.PathLike) -> None:
    """Tight layout and an atomic PNG."""
    fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format="png", dpi=120)


def _num(v) -> float:
    try:
        return float(v)
    except (TypeError, ValueError):
        return np.nan


def plot_xy(rows: list[dict], x: str, y: str, hue: str | None, path: str | os.PathLike,
            title: str = "", logx: bool = False, logy: bool = False, hline: float | None = None) -> None:
    """Lines with markers of ``y`` over ``x`` (rows without a number are left out), one per
    distinct ``hue`` value in order of appearance."""
    fig, ax = new_axes()
    groups: dict = {}
    for r in rows:
        groups.setdefault(r.get(hue) if hue else None, []).append(r)
    for i, (h, grp) in enumerate(groups.items()):
        pts = sorted((_num(r.get(x)), _num(r.get(y))) for r in grp)
        pts = [p for p in pts if np.isfinite(p).all()]
        if not pts:
            continue
        xs, ys = zip(*pts)
        ax.plot(xs, ys, "o-", ms=3.5, color=f"C{i % 10}", label=f"{hue} = {h}" if hue else None)
    if hline is not None:
        ax.axhline(hline, color="0.4", lw=0.8, ls="--")
    if logx:  # ticks at the data, in plain numbers
        ax.set_xscale("log")
        ax.set_xticks(sorted({p for r in rows if np.isfinite(p := _num(r.get(x)))}))
        ax.xaxis.set_major_formatter(ScalarFormatter())
        ax.xaxis.set_minor_formatter(NullFormatter())
    ax.set_yscale("log" if logy else "linear")
    ax.set_xlabel(x)
    ax.set_ylabel(y)
    ax.set_title(title, fontsize="medium")
    ax.grid(True, lw=0.3)
    if hue:
        ax.legend(fontsize="small")
    save(fig, path)
