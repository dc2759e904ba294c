"""Plots of a diagnosis (:class:`studies.diagnosis.discrepancy.Diagnosis`): where the
residual is significant, how the additions scored round by round, and the held-out
residual before and after the chosen pieces."""
from __future__ import annotations

import numpy as np

from gatetherm.studies.diagnosis.locate import significant, smooth, threshold
from gatetherm.studies.diagnosis.replay import label, resolution, unit
from gatetherm.validation.plots import figure

DPI = 110
"""Resolution of the diagnosis' pictures, dots per inch (``gatetherm diagnose`` writes them at it)."""

PHASE_COLOURS = {"pump off": "#dddddd", "heating": "#f6d5c8", "forced cooling": "#cfe0f3"}


def _phases(ax, diag, names: bool) -> None:
    h = diag.time_s / 3600.0
    for ph in diag.phases:
        colour = next((c for k, c in PHASE_COLOURS.items() if ph.label.startswith(k)), "#ffffff")
        ax.axvspan(ph.start_s / 3600.0, ph.end_s / 3600.0, color=colour, alpha=0.6, lw=0)
        if names:
            ax.text(0.5 * (ph.start_s + ph.end_s) / 3600.0, 1.02, ph.label.split(" (")[0], fontsize=7,
                    ha="center", va="bottom", transform=ax.get_xaxis_transform())
    ax.axvline(diag.train_end_s / 3600.0, color="k", ls="--", lw=1)
    ax.set_xlim(h[0], h[-1])


def plot_residuals(diag, axes=None, fig=None):
    """Baseline residual per channel over the whole run: samples, systematic part,
    ±resolution band, significant stretches in red, phases shaded, training/held-out split dashed;
    on ``axes`` (one per channel), or panels of ``fig`` or of a new figure. Returns the Axes."""
    t = diag.time_s
    n = len(diag.channels)
    axes = (figure((9, 1.9 * n + 0.8), n, 1, fig, sharex=True, squeeze=False) if axes is None
            else np.reshape(axes, (n, 1)))
    for k, (ax, c) in enumerate(zip(axes[:, 0], diag.channels)):
        r, res = diag.residual_before[c], resolution(c)
        s = smooth(t, r)
        sig = significant(t, r, res)
        _phases(ax, diag, names=k == 0)
        ax.plot(t / 3600, r, ".", ms=2, color="0.55", label="measured − model")
        ax.plot(t / 3600, s, color="C0", lw=1.5, label="systematic part")
        ax.plot(t / 3600, np.where(sig, s, np.nan), color="C3", lw=3, label="significant")
        ax.axhspan(-res, res, color="C2", alpha=0.25, lw=0, label="± resolution")
        lim = threshold(t, r, res)
        for y in (-lim, lim):
            ax.axhline(y, color="C2", ls=":", lw=1, label="significance level" if y > 0 else None)
        ax.set_ylabel(f"{label(c)} ({unit(c)})")
    axes[0, 0].legend(fontsize=7, loc="lower left", ncol=5)
    axes[-1, 0].set_xlabel("time (h)   — dashed: end of the training window")
    axes[0, 0].figure.suptitle("Residual of the baseline model", y=0.995)
    return axes


def plot_before_after(diag, axes=None):
    """Held-out residual per channel with the baseline and with the chosen pieces, on ``axes``
    (one per channel) or a new figure's. Returns the Axes."""
    t = diag.time_s
    held = t > diag.train_end_s
    n = len(diag.channels)
    axes = figure((8, 1.9 * n + 0.8), n, 1, sharex=True, squeeze=False) if axes is None else np.reshape(axes, (n, 1))
    name = " + ".join(r.piece.label for r in diag.pieces) or "—"
    for ax, c in zip(axes[:, 0], diag.channels):
        res = resolution(c)
        ax.axhspan(-res, res, color="C2", alpha=0.25, lw=0)
        for r, colour, what in ((diag.residual_before[c], "C3", "baseline"),
                                (diag.residual_after[c], "C0", f"with {name}")):
            rms = float(np.sqrt(np.nanmean(r[held] ** 2)))
            ax.plot(t[held] / 3600, r[held], ".", ms=2, color=colour, alpha=0.4)
            ax.plot(t[held] / 3600, smooth(t, r)[held], color=colour, lw=1.5,
                    label=f"{what}: RMS {rms:.3g} {unit(c)}")
        ax.set_ylabel(f"{label(c)} ({unit(c)})")
        ax.legend(fontsize=7, loc="best")
    axes[-1, 0].set_xlabel("time (h), held-out window")
    axes[0, 0].figure.suptitle(f"Held-out residual before and after: {name}", y=0.995)
    return axes


def plot_scores(diag, shown: int = 12, axes=None):
    """Score gain of the best additions tried in each selection round (log scale), on ``axes``
    (one per round) or a new figure's. Returns the Axes."""
    n = len(diag.rounds)
    axes = (figure((4.2 * n + 1.5, 0.3 * shown + 1.4), 1, n, squeeze=False) if axes is None
            else np.reshape(axes, (1, n)))
    for ax, k, rnd in zip(axes[0], range(1, n + 1), diag.rounds):
        trials = rnd.trials[:shown]
        y = np.arange(len(trials))[::-1]
        gains = [rnd.before - s.score for _, s in trials]
        ax.barh(y, np.maximum(gains, 0.0) + 1.0,
                color=["C2" if s.explains else ("C1" if s.approx else "C7") for _, s in trials])
        ax.set_yticks(y, [f"{p.label}" for p, _ in trials], fontsize=7)
        ax.set_xscale("log")
        ax.axvline(1.0 + diag.margin_min, color="k", ls=":", lw=1)
        added = f"+ {' + '.join(p.label for p in rnd.added)}" if rnd.added else "nothing added"
        ax.set_title(f"round {k}: {added}", fontsize=9)
        ax.set_xlabel("1 + score gain", fontsize=8)
    axes[0, 0].figure.suptitle(f"Additions by round (green: explains the held-out data, orange: screened only; "
                               f"dotted: margin {diag.margin_min:g})", fontsize=9)
    return axes


def plot_hidden_study(rows: list[dict], ax=None):
    """Held-out RMS of δ before (the baseline model) and after the diagnosis, one pair of bars
    per case of the hidden-effect study, labelled with the true effect and the verdict. Returns the Axes."""
    labels = [f"{r['effect']} (c{r['condition']}) → {r['named'] or r['verdict']}" for r in rows]
    y = np.arange(len(rows))
    ax = figure((7.5, 1.2 + 0.32 * len(rows))) if ax is None else ax
    before = [r["rms_before_um"] for r in rows]
    after = [r["rms_after_um"] if r["rms_after_um"] is not None else np.nan for r in rows]
    ax.barh(y - 0.2, before, 0.4, color="0.7", label="baseline model")
    ax.barh(y + 0.2, after, 0.4, color="C0", label="after the diagnosis")
    ax.axvline(0.1, color="C3", lw=0.8, ls="--", label="δ sensor resolution 0.1 µm")
    ax.set_yticks(y, labels, fontsize="small")
    ax.invert_yaxis()
    ax.set_xscale("log")
    ax.set_xlabel("held-out RMS of δ [µm]")
    ax.legend(fontsize="small", loc="lower right")
    ax.grid(axis="x", which="both", lw=0.3)
    return ax
