"""Compound-diagnosis section: random pairs of hidden pieces (effects, parameters off, sensor
faults) diagnosed blind (``gatetherm validate compound``)."""
from __future__ import annotations

from gatetherm.validation.report.result import Result, from_dicts, table


def compute(ctx) -> Result:
    from gatetherm.validation.compound_study import COLUMNS, write_compound

    s = ctx.scope
    figures, rows = write_compound(ctx.work, max(ctx.workers, 1), s["seed"], s["pairs"], s["single"], s["mesh_size"])
    pairs = from_dicts("Every pair: hidden pieces, verdict, pieces named and the held-out RMS of δ", rows, COLUMNS,
                       note="Held-out window: the last 40 % of each 5-h, 1-min run; noise at the sensors' resolution "
                            "(0.1 µm, 0.05 K); strengths in each hypothesis' unit.")
    summary = table("Acceptance figures", ("figure", "value"), [(k, str(v)) for k, v in figures.items()])
    return Result(tables=(summary, pairs), files=(("compound.md", "the study's tables and figures"),
                                                  ("compound.csv", "every pair with its fitted parameters")))
