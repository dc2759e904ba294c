"""The readable ``report.md`` of a diagnosis (text only; the plots are made by
``validation/discrepancy_plots.py`` and referred to by file name)."""
from __future__ import annotations

import math

from gatetherm.solvers.effects import CATALOGUE
from gatetherm.studies.diagnosis.calibrate import RECAL
from gatetherm.studies.diagnosis.discrepancy import Diagnosis
from gatetherm.studies.diagnosis.locate import clock
from gatetherm.studies.diagnosis.replay import DELTA, label, resolution, unit

VERDICT_TEXT = {
    "no-discrepancy": "The model agrees with the measurement within the sensor resolution; nothing to add.",
    "parameter-mismatch": "Recalibrating the model's existing parameters closes the gap; no new effect is needed.",
    "missing-effect": "The model misses a physical effect; the catalogue names it and adding it closes the gap.",
    "unexplained": "The model and the measurement disagree, and nothing in the catalogue explains it.",
}


def _num(v, digits: int = 4) -> str:
    if v is None or (isinstance(v, float) and not math.isfinite(v)):
        return "—"
    return f"{v:.{digits}g}"


def _param_unit(key: str) -> str:
    name = key.split(".")[0]
    if name in CATALOGUE:
        return CATALOGUE[name].unit
    return next((p.unit for p in RECAL if p.name == key), "")


def _fitted(values: dict, sigma: dict) -> str:
    return ", ".join(f"{k} = {_num(v)}" + (f" ± {_num(sigma[k], 2)}" if k in sigma else "") + f" {_param_unit(k)}"
                     for k, v in values.items())


def report_markdown(d: Diagnosis, data: str, model: str, files: dict[str, str]) -> str:
    """``files``: {"residuals", "scores", "before_after", "model"} → file names written (if any)."""
    t = d.time_s
    L = [f"# Discrepancy diagnosis: {data}", "",
         f"Model: `{model}`, 2-D FE, {d.runs} model runs, {d.seconds:.0f} s. "
         f"Channels compared: {', '.join(label(c) for c in d.channels)} ({len(t)} samples, "
         f"{clock(t[0])}–{clock(t[-1])}). Training window {clock(t[0])}–{clock(d.train_end_s)}, "
         f"held out {clock(d.train_end_s)}–{clock(t[-1])}.", "",
         f"## Verdict: **{d.verdict}**" + (f" — **{d.named_effect}**" if d.named_effect else ""), "",
         VERDICT_TEXT[d.verdict], "", f"Reason: {d.reason}."]
    if d.runner_up:
        L += ["", f"Runner-up: {d.runner_up}, margin {_num(d.margin)} (score units: χ² + k ln n)."]
    L += ["", "## 1. Replay", "",
          "The model was driven by the file's oil temperature and pump state"
          + (" and room temperature" if d.has_ambient else " (room at the model's constant T_room)")
          + ". Noise scale per channel "
          "(the residual weight; at least the resolution 0.1 µm / 0.05 K): "
          + ", ".join(f"{label(c)} {_num(s, 2)} {unit(c)}" for c, s in d.scale.items()) + ".", "",
          "## 2. Locate", "",
          "A residual is significant where its 15-min moving average exceeds the sensor resolution by more "
          "than three standard errors of that average (noise estimated from the residual itself).", ""]
    sig = [f for f in d.findings if f.significant]
    L += [f"- {f.sentence()}" for f in sig] or ["- Nowhere: the baseline residual stays within the resolution."]
    L += ["", "| channel | " + " | ".join(f"{p.label} {p.span()}" for p in d.phases) + " |",
          "|---|" + "---|" * len(d.phases)]
    for c in d.channels:
        cells = []
        for p in d.phases:
            f = next((f for f in d.findings if f.channel == c and f.phase == p), None)
            bold = "**" if f is not None and f.significant else ""
            cells.append("—" if f is None else f"{bold}{f.peak / resolution(c):+.1f}×{bold}")
        L.append(f"| {label(c)} | " + " | ".join(cells) + " |")
    L += ["", "Cells: largest systematic residual (measured − model) in units of the resolution; bold = significant."]
    if "residuals" in files:
        L += ["", f"![baseline residual]({files['residuals']})"]
    if d.verdict == "no-discrepancy":
        return "\n".join(L) + "\n"
    recal = next((c for c in d.candidates if c.name == "recalibration"), None)
    L += ["", "## 3. Recalibration of existing parameters", ""]
    if recal:
        L += [f"Fitted on the training window: {_fitted(recal.fit.values, recal.fit.sigma)}.",
              f"Held-out δ RMS {_num(recal.rms.get(DELTA))} µm; "
              + ("explains the held-out data." if recal.explains else "a significant held-out residual remains.")]
    else:
        L += ["Not run."]
    L += ["", "## 4. Candidate effects", "",
          "Each fitted alone on the training window (one parameter within its plausible range), "
          "scored on the held-out window.", "",
          "| hypothesis | k | fitted | held-out score | − best | δ RMS held-out (µm) | explains |",
          "|---|---|---|---|---|---|---|"]
    best = min(c.score for c in d.candidates + (d.baseline,))
    for c in sorted(d.candidates + (d.baseline,), key=lambda c: c.score):
        L.append(f"| {c.name} | {c.fit.k} | {_fitted(c.fit.values, c.fit.sigma) or '—'} | {_num(c.score, 6)} | "
                 f"{_num(c.score - best, 4)} | {_num(c.rms.get(DELTA))} | {'yes' if c.explains else 'no'} |")
    if "scores" in files:
        L += ["", f"![candidate scores]({files['scores']})"]
    L += ["", "## 5. Name", "", f"Verdict **{d.verdict}**: {d.reason}."]
    if d.adopted is not None:
        a = d.adopted
        L += ["", "## 6. Add and show", "",
              f"Adopted: **{a.name}** ({_fitted(a.fit.values, a.fit.sigma)})."]
        if "model" in files:
            L += [f"Model file: `{files['model']}` — run it with "
                  f"`gatetherm simulate --config {files['model']} --schedule {data}`."]
        L += ["", "| channel | held-out RMS before | after | change |", "|---|---|---|---|"]
        for c in d.channels:
            b, af = d.baseline.rms[c], a.rms[c]
            L.append(f"| {label(c)} ({unit(c)}) | {_num(b, 3)} | {_num(af, 3)} | {100 * (af - b) / b:+.0f} % |")
        if "before_after" in files:
            L += ["", f"![held-out residual before and after]({files['before_after']})"]
    return "\n".join(L) + "\n"
