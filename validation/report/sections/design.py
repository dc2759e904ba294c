"""Design section: the tie-bar height that minimises the worst 5-h swing of δ over conditions
1-3, and a second tie bar above the cutting area (``gatetherm validate design``)."""
from __future__ import annotations

import csv

from gatetherm.validation.report.result import Figure, Result, table
from gatetherm.validation import paper_model


def compute(ctx) -> Result:
    from gatetherm.validation.design_study import write_design_study

    s = ctx.scope
    cfg = paper_model(size=s["size"])
    lines = write_design_study(ctx.work, cfg, s["dim"], ctx.workers, positions=s["positions"], refine=s["refine"],
                               second_above=s["second_above"])
    with open(ctx.work / "second_tie_bar.csv", newline="", encoding="utf-8") as f:
        second = list(csv.DictReader(f))
    rows = [(f"{float(r['l4']):.4g}", f"{float(r['l4_2']):.4g}" if float(r["l4_2"]) else "none",
             *(f"{float(r[f'swing_cond{c}_um']):.1f}" for c in (1, 2, 3)), f"{float(r['worst_swing_um']):.1f}",
             f"{-float(r['reduction_vs_one_bar']):+.0%}" if float(r["l4_2"]) else "reference") for r in second]
    t = table("A second tie bar above the cutting area: 5-h swing of δ per condition (µm)",
              ("l4 (m)", "l4_2 (m)", "cond. 1", "cond. 2", "cond. 3", "worst", "vs one bar"), rows,
              note="The column is raised to hold the highest second bar, for the references without it too; the "
                   "first bar at the model's height and at the optimum.")
    return Result(tables=(t,), notes=tuple(lines[1:]), figures=(
        Figure("design_position.png", "5-h swing of δ against the height l4 of one tie bar, conditions 1-3"),
        Figure("design_second.png", "Worst swing against the height of a second tie bar above the cutting area"),
        Figure("design_histories.png", "δ against time for the model as built, the optimal l4 and the best "
                                       "two-bar design")),
        files=(("report.md", "the design report"), ("positions.csv", "every tie-bar height and condition")))
