"""Plots of a diagnosis (:class:`studies.discrepancy.Diagnosis`): where the residual
is significant, how the candidates scored, and the held-out residual before and
after the adopted hypothesis."""
from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from gatetherm.studies.diagnosis.locate import significant, smooth, threshold  # noqa: E402
from gatetherm.studies.diagnosis.replay import label, resolution, unit  # noqa: E402
from gatetherm.validation.plots import save  # noqa: E402

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


def plot_residuals(diag, path: Path) -> None:
    """Baseline residual per channel over the whole run: samples, systematic part,
    ±resolution band, significant stretches in red, phases shaded, training/held-out split dashed."""
    t = diag.time_s
    n = len(diag.channels)
    fig, axes = plt.subplots(n, 1, figsize=(9, 1.9 * n + 0.8), sharex=True, squeeze=False)
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
    fig.suptitle("Residual of the baseline model", y=0.995)
    fig.tight_layout()
    save(fig, path, dpi=110, tight=False)


def plot_before_after(diag, path: Path) -> None:
    """Held-out residual per channel with the baseline and with the adopted hypothesis."""
    t = diag.time_s
    held = t > diag.train_end_s
    n = len(diag.channels)
    fig, axes = plt.subplots(n, 1, figsize=(8, 1.9 * n + 0.8), sharex=True, squeeze=False)
    name = diag.adopted.name if diag.adopted else "—"
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
    fig.suptitle(f"Held-out residual before and after: {name}", y=0.995)
    fig.tight_layout()
    save(fig, path, dpi=110, tight=False)


def plot_scores(diag, path: Path) -> None:
    """Held-out score of every hypothesis relative to the best (log scale)."""
    cands = list(diag.candidates) + [diag.baseline]
    best = min(c.score for c in cands)
    cands.sort(key=lambda c: c.score)
    fig, ax = plt.subplots(figsize=(7, 0.32 * len(cands) + 1.2))
    y = np.arange(len(cands))[::-1]
    gaps = [max(c.score - best, 0.0) + 1.0 for c in cands]
    ax.barh(y, gaps, color=["C2" if c.explains else "C7" for c in cands])
    ax.set_yticks(y, [f"{c.name} (k={c.fit.k})" for c in cands], fontsize=8)
    ax.set_xscale("log")
    ax.axvline(1.0 + diag.margin_min, color="k", ls=":", lw=1)
    ax.set_xlabel(f"1 + score − best score  (χ² + k ln n, held-out window; dotted: margin {diag.margin_min:g})")
    ax.set_title("Candidates (green: explains the held-out data)", fontsize=10)
    fig.tight_layout()
    save(fig, path, dpi=110, tight=False)


def plot_hidden_study(rows: list[dict], path) -> None:
    """Held-out RMS of δ before (the baseline model) and after the diagnosis, one pair of bars
    per case of the hidden-effect study, labelled with the true effect and the verdict."""
    labels = [f"{r['effect']} (c{r['condition']}) → {r['named'] or r['verdict']}" for r in rows]
    y = np.arange(len(rows))
    fig, ax = plt.subplots(figsize=(7.5, 1.2 + 0.32 * len(rows)))
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
    save(fig, path)
