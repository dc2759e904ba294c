"""Diagnosis section: runs with a hidden catalogue effect, noise only, effects outside the
catalogue and wrong parameters, diagnosed blind (``gatetherm validate hidden-effects``)."""
from __future__ import annotations

from gatetherm.validation.report.result import Figure, Result, from_dicts, table


def compute(ctx) -> Result:
    from gatetherm.validation.hidden_effects import ALL_CASES, COLUMNS, write_hidden_effects
    from gatetherm.validation.plots import save
    from gatetherm.validation.plots.discrepancy import plot_hidden_study

    s = ctx.scope
    wanted = ALL_CASES if s["effects"] == "all" else tuple(s["effects"])
    acc, rows = write_hidden_effects(ctx.work, max(ctx.workers, 1), s["seed"], tuple(s["conditions"]), wanted,
                               per_kind=s.get("per_kind"))
    save(plot_hidden_study(rows), ctx.work / "hidden_effects.png")
    cases = from_dicts("Every case: true effect, verdict, named effect and the held-out RMS", rows,
                       [c for c in COLUMNS if c != "reason"],
                       note="Held-out window: the last 40 % of each 5-h run; weighted RMS: all channels in units of "
                            "their resolution (0.1 µm, 0.05 K).")
    summary = table("Acceptance figures", ("figure", "value"), [(k, str(v)) for k, v in acc.items()])
    return Result(tables=(summary, cases), figures=(
        Figure("hidden_effects.png", "Held-out RMS of δ before and after the diagnosis, per case (true effect → "
                                     "named effect or verdict)"),),
        files=(("hidden_effects.md", "the study's table and acceptance"),
               ("hidden_effects.csv", "every case with its fitted parameters")))
