"""Fig. 7 / Fig. 8 analogues: normalised K_i and K_C against l/l4, theory curves and FE markers."""
from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from gatetherm.validation.plots import figure

KI_LABEL = r"$K_i\,/\,(3\alpha l^2/8h)$  ($l_1 = l/2$)"
KC_LABEL = r"$K_C\,/\,(\alpha l_C)$  ($l_1 = l/2$)"
A_LABEL = r"$l/l_4$"
A_RANGE = (0.5, 5.0)


def _plot_one(theory_a, curves: Mapping, fe_points: Mapping | None, ylabel: str, zero_line: bool, ax=None):
    """A theory line per beta and FE markers of the same colour; returns the Axes."""
    ax = figure((6.0, 4.2)) if ax is None else ax
    a = np.asarray(theory_a, dtype=float)
    for i, (b, y) in enumerate(sorted(curves.items())):
        colour = f"C{i}"
        ax.plot(a, np.asarray(y, dtype=float), color=colour, label=rf"$\beta$ = {b:g}")
        if fe_points and b in fe_points:
            fa, fy = fe_points[b]
            ax.plot(fa, fy, "o", color=colour, mfc="none")
    if zero_line:
        ax.axhline(0.0, color="0.4", lw=0.8, ls="--")
    ax.set_xlim(*A_RANGE)
    ax.set_xlabel(A_LABEL)
    ax.set_ylabel(ylabel)
    ax.grid(True, lw=0.3)
    ax.plot([], [], color="0.3", label="beam theory")
    if fe_points:
        ax.plot([], [], "o", color="0.3", mfc="none", label="FE")
    ax.legend(fontsize="small", ncol=2)
    return ax


def plot_ki_kc(theory_a, theory: Mapping, fe: Mapping | None, axes=(None, None)):
    """The Fig. 7 (``K_i``) and Fig. 8 (``K_C``) analogues on the two Axes ``axes`` (each None:
    a figure of its own); returns them.

    ``theory_a``: the l/l4 values of the theory curves; ``theory``: beta -> (Ki_norm, Kc_norm)
    arrays over ``theory_a``; ``fe``: beta -> (a, Ki_norm, Kc_norm) FE results or None.
    """
    fe = fe or {}
    return (_plot_one(theory_a, {b: v[0] for b, v in theory.items()},
                      {b: (v[0], v[1]) for b, v in fe.items()}, KI_LABEL, True, axes[0]),
            _plot_one(theory_a, {b: v[1] for b, v in theory.items()},
                      {b: (v[0], v[2]) for b, v in fe.items()}, KC_LABEL, False, axes[1]))
