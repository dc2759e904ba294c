"""Case-diagnosis section: runs of the C-frame case with hidden pieces of the case, diagnosed
blind through ``gatetherm diagnose --case`` (``gatetherm validate case-diagnosis``)."""
from __future__ import annotations

from gatetherm.validation.report.result import Result, from_dicts


def compute(ctx) -> Result:
    import gatetherm.validation
    from pathlib import Path

    from gatetherm.validation.case_diagnosis import COLUMNS, MESH_FACTOR, SCENARIOS, cell, write_case_diagnosis

    case = Path(gatetherm.validation.__path__[0]) / ctx.scope["case"]
    line, rows = write_case_diagnosis(ctx.work, case, ctx.scope["seed"], ctx.scope.get("scenarios") or tuple(SCENARIOS))
    shown = [{**r, "fitted": cell(r["fitted"])} for r in rows]
    return Result(tables=(from_dicts("Every scenario: hidden pieces, verdict, pieces named", shown, COLUMNS,
                                     note=f"{line}. Truth: P2 elements on the case's geometry with its element sizes "
                                          f"times {MESH_FACTOR:g}; diagnosis: the case's P1 elements with its "
                                          "element sizes times mesh_factor, replayed with P2 (order 2) where its "
                                          "discretisation check exceeds the resolution. "
                                          "p2_minus_p1_delta: the diagnosis' discretisation check on δ, in units "
                                          "of the 0.1-µm resolution. Noise at the resolution (0.1 µm, 0.05 K); "
                                          "held-out window: the last 40 % of the 6-h run."),),
                  files=(("case_diagnosis.md", "the study's table"), ("case_diagnosis.json", "every row in full"),
                         ("measured_film+offset.csv", "the measured run of one scenario, for gatetherm "
                                                      "diagnose --case CASE.toml --data FILE --mesh-factor 0.5")),
                  notes=(line,))
