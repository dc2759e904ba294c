"""The readable ``report.md`` of a diagnosis (text only; the plots are made by
``validation/plots/discrepancy.py`` and referred to by file name)."""
from __future__ import annotations

import math

from gatetherm.studies.diagnosis.discrepancy import Diagnosis
from gatetherm.studies.diagnosis.locate import clock
from gatetherm.studies.diagnosis.replay import DELTA, label, resolution, unit

VERDICT_TEXT = {
    "no-discrepancy": "The model agrees with the measurement within the sensor resolution; nothing to add.",
    "explained": "The pieces below, together, leave no significant residual anywhere in the run, and hold on "
                 "every input phase when fitted on the others, with the same, plausible values.",
    "partly-explained": "The pieces below lower the held-out residual, but a significant part remains or they do "
                        "not hold on every phase (sections 5 and 6 say where and when, and what kind of cause "
                        "would fit): something outside the hypotheses is missing too.",
    "unexplained": "The model and the measurement disagree, and no hypothesis lowers the held-out residual as a "
                   "cause would (section 6 says where and when, and what kind of cause would fit).",
}
SHOWN, SHOWN_PAIRS = 8, 3
"""Single and two-piece additions shown per selection round."""


def _num(v, digits: int = 4) -> str:
    if v is None or (isinstance(v, float) and not math.isfinite(v)):
        return "—"
    return f"{v:.{digits}g}"


def _table(d: Diagnosis, cells: dict) -> list[str]:
    """Channel × phase table of ``cells`` ({(channel, phase): text})."""
    out = ["| channel | " + " | ".join(f"{p.label} {p.span()}" for p in d.phases) + " |",
           "|---|" + "---|" * len(d.phases)]
    for c in d.channels:
        out.append(f"| {label(c)} | " + " | ".join(cells.get((c, p), "—") for p in d.phases) + " |")
    return out


def _cells(findings) -> dict:
    out = {}
    for f in findings:
        bold = "**" if f.significant else ""
        out[(f.channel, f.phase)] = f"{bold}{f.peak / resolution(f.channel):+.1f}×{bold}"
    return out


def report_markdown(d: Diagnosis, data: str, model: str, files: dict[str, str]) -> str:
    """``files``: {"residuals", "scores", "before_after", "model"} → file names written (if any)."""
    t = d.time_s
    L = [f"# Discrepancy diagnosis: {data}", "",
         f"Model: `{model}`, {d.dim}-D FE, {d.runs} model runs, {d.seconds:.0f} s. "
         f"Channels compared: {', '.join(label(c) for c in d.channels)} ({len(t)} samples, "
         f"{clock(t[0])}–{clock(t[-1])}). Training window {clock(t[0])}–{clock(d.train_end_s)}, "
         f"held out {clock(d.train_end_s)}–{clock(t[-1])}.", "",
         f"## Verdict: **{d.verdict}**" + (f" — {', '.join(r.piece.label for r in d.pieces)}" if d.pieces else ""),
         "", VERDICT_TEXT[d.verdict], "", f"Reason: {d.reason}."]
    if d.pieces:
        L += ["", "| # | kind | piece | fitted (± 1σ) | share of the held-out residual | or equally |", "|---|---|---|---|---|---|"]
        for i, r in enumerate(d.pieces, 1):
            p = r.piece
            L.append(f"| {i} | {p.kind} | {p.label} | {p.param} = {_num(r.value)} ± {_num(r.sigma, 2)} {p.unit} | "
                     f"{100 * r.share:.0f} % | {', '.join(q.label for q in r.alternatives) or '—'} |")
    for g in d.groups:
        L += ["", f"**Cannot be told apart:** {g.sentence()}."]
    if d.stand_ins:
        L += ["", "**Stand-ins, not causes** (they make the model fit, but fail a model-form check; section 6): "
              + "; ".join(f"{p.label} {p.param} = {_num(v)} {p.unit} ({why})" for p, v, why in d.stand_ins) + "."]
    if d.dropped:
        L += ["", "**Dropped: the model refuses them** (their runs fail, the diagnosis went on without them): "
              + "; ".join(f"{p.label} ({why})" for p, why in d.dropped) + "."]
    if d.best_rejected:
        L += ["", f"Best rejected: {d.best_rejected[0].label} (score gain {_num(d.margin)} < margin {d.margin_min:g})."]
    if d.removed:
        L += ["", f"Chosen, then dropped (removal check or swap): {', '.join(p.label for p in d.removed)}."]
    drive = (f"the file's columns {', '.join(d.inputs)} (the inputs the case reads)" if d.inputs is not None else
             "the file's oil temperature and pump state"
             + (" and room temperature" if d.has_ambient else " (room at the model's constant T_room)"))
    L += ["", "## 1. Replay", "",
          f"The model was driven by {drive}. Noise scale per channel (the residual weight; at least the "
          "resolution 0.1 µm / 0.05 K): " + ", ".join(f"{label(c)} {_num(s, 2)} {unit(c)}" for c, s in d.scale.items()) + "."]
    if d.discretisation is not None:
        L += ["", "Discretisation check (the baseline run again with P2 elements; largest |P2 − P1| in units of the "
              "resolution): " + ", ".join(f"{label(c)} {v:.2f}×" for c, v in d.discretisation.items()) + ". "
              + (f"**Above the resolution on {', '.join(label(c) for c in d.too_coarse)}**: " + (
                  "the model's own discretisation error shows in the data, so the diagnosis replayed the model "
                  "with P2 elements (about four times the cost of a run in 2-D); to diagnose with P1, refine the mesh "
                  "(`--mesh-factor`, or `size` in the case); for a run gatetherm simulated on this mesh with P1 (the "
                  "same error in the data), `--keep-order` replays with P1." if d.order == 2 else
                  "the model's own discretisation error shows in the data and the pieces below may partly stand in "
                  "for it; refine the mesh (`--mesh-factor`, or `size` in the case) or set `order = 2`.")
                 if d.too_coarse else "Below the resolution: the mesh is fine enough for these sensors.")]
    L += ["",
          "## 2. Locate", "",
          "A residual is significant where its 15-min moving average exceeds the sensor resolution by more "
          "than three standard errors of that average (noise estimated from the residual itself).", ""]
    L += [f"- {f.sentence()}" for f in d.findings if f.significant] \
        or ["- Nowhere: the baseline residual stays within the resolution."]
    L += [""] + _table(d, _cells(d.findings))
    L += ["", "Cells: largest systematic residual (measured − model) in units of the resolution; bold = significant."]
    if "residuals" in files:
        L += ["", f"![baseline residual]({files['residuals']})"]
    if d.verdict == "no-discrepancy":
        return "\n".join(L) + "\n"
    L += ["", "## 3. Forward selection", "",
          "Each round fits every hypothesis added to the pieces already chosen (training window) and scores the "
          "set on the held-out window: Σ over channels of w·n·ln max(mean squared residual / noise², 1) "
          "+ (number of parameters)·ln N, the displacement and the temperature channels weighing the same. "
          f"An addition is kept when it lowers the score by at least {d.margin_min:g} (a pair: when it also "
          "beats the best single addition by that); 'screened' = scored from superposed runs only."]
    for i, rnd in enumerate(d.rounds, 1):
        L += ["", f"Round {i} (score before {_num(rnd.before, 6)}): "
              + (f"**{' + '.join(p.label for p in rnd.added)}** added." if rnd.added else "nothing added."), "",
              "| hypothesis | kind | fitted | score − before | δ RMS held-out (µm) | explains |", "|---|---|---|---|---|---|"]
        for p, s in rnd.trials[:SHOWN]:
            L.append(f"| {p.label} | {p.kind} | {p.param} = {_num(s.values[p])} {p.unit} | "
                     f"{_num(s.score - rnd.before, 4)}{' (screened)' if s.approx else ''} | "
                     f"{_num(s.rms.get(DELTA))} | {'yes' if s.explains else 'no'} |")
        for pq, s in rnd.pairs[:SHOWN_PAIRS]:
            L.append(f"| {' + '.join(p.label for p in pq)} | pair | "
                     + ", ".join(f"{p.param} = {_num(s.values[p])} {p.unit}" for p in pq) + " | "
                     f"{_num(s.score - rnd.before, 4)}{' (screened)' if s.approx else ''} | "
                     f"{_num(s.rms.get(DELTA))} | {'yes' if s.explains else 'no'} |")
    if "scores" in files:
        L += ["", f"![selection rounds]({files['scores']})"]
    if not d.pieces:
        return "\n".join(L + _checks(d)) + "\n"
    L += ["", "## 4. Add and show", ""]
    if "model" in files:
        L += [f"Model file with every piece: `{files['model']}` — run it with "
              f"`gatetherm simulate --config {files['model']} --schedule {data}`.", ""]
    elif d.inputs is not None:
        L += ["To adopt the parameters, put the fitted values into the case file (a `factor` multiplies the "
              "case's value: a source's power, every region's k, α or c) and run it again with `gatetherm run`.", ""]
    L += ["| channel | held-out RMS before | after | change |", "|---|---|---|---|"]
    for c in d.channels:
        b, af = d.baseline.rms[c], d.final.rms[c]
        change = f"{100 * (af - b) / b:+.0f} %" if b > 0 else "—"
        L.append(f"| {label(c)} ({unit(c)}) | {_num(b, 3)} | {_num(af, 3)} | {change} |")
    if "before_after" in files:
        L += ["", f"![held-out residual before and after]({files['before_after']})"]
    L += ["", "## 5. What remains", ""]
    L += [f"- {f.sentence()}" for f in d.remaining if f.significant] \
        or ["- Nothing significant: the residual with the pieces stays within the resolution."]
    L += [""] + _table(d, _cells(d.remaining))
    L += _checks(d)
    return "\n".join(L) + "\n"


def _checks(d: Diagnosis) -> list[str]:
    """Section 6: the model-form checks, what stays unexplained and what kind of cause would fit."""
    L = ["", "## 6. Model-form checks", "",
         "An explanation is only `explained` when it holds on every input phase fitted on the others (one phase "
         "left out at a time, the pieces refitted by a Gauss–Newton step on the whole run's Jacobian), with the "
         "same values in every phase, none at an end of its plausible range, each piece needed (held-out score "
         "with the penalty k·ln N, a Bayesian information criterion), and a sensor fault only where its own "
         "channel is then explained."]
    if d.checks and d.checks.folds:
        L += ["", "| phase left out | holds | channels unexplained | " + " | ".join(p.label for p in d.checks.folds[0].values)
              + " |", "|---|---|---|" + "---|" * len(d.checks.folds[0].values)]
        for f in d.checks.folds:
            L.append(f"| {f.phase.label} {f.phase.span()} | {'yes' if f.holds else '**no**'} | "
                     f"{', '.join(label(c) for c in f.unexplained) or '—'} | "
                     + " | ".join(_num(v) for v in f.values.values()) + " |")
    left = d.summary()["unexplained"]
    if left and d.verdict != "explained":
        L += ["", "Unexplained: " + "; ".join(f"{label(c)} in {', '.join(ph)}" for c, ph in left.items()) + "."]
    if d.cause:
        L += ["", f"What kind of cause would fit: {d.cause}"]
    return L
