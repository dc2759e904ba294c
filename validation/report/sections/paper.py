"""Paper section: conditions 1-3 in 2-D and 3-D against the paper's figures (the table of
``gatetherm validate paper``), the Fig. 10 analogue (oil and tank temperatures), the
Figs. 11-13 analogues (θ rises and δ, 2-D and 3-D together) and the deformed frame at the
first peak of δ."""
from __future__ import annotations

import os

from gatetherm.validation.report.result import Figure, Result, table
from gatetherm.validation import paper_model

CONDITIONS = (1, 2, 3)


def compute(ctx) -> Result:
    from gatetherm.studies.run.scenario import ScenarioCache
    from gatetherm.validation.paper_table import run_condition, table_rows
    from gatetherm.validation.plots import save
    from gatetherm.validation.plots.field import draw_deformed
    from gatetherm.validation.plots.labels import signal_labels
    from gatetherm.validation.plots.run import plot_fluids, plot_responses

    dims, load = ctx.scope["dims"], os.getloadavg()[0]
    keep = [60.0 * k for k in range(61)]  # every minute of the first hour: the first peak of δ is in it
    runs, res = {}, {}
    for dim in dims:
        cfg, cache = paper_model(size_3d=ctx.scope.get("size_3d")), ScenarioCache()
        for c in CONDITIONS:
            runs[(c, dim)], res[(c, dim)] = run_condition(cfg, dim, c, cache, keep_times=keep if c == 1 else ())
    figures = []
    for c in CONDITIONS:
        run = runs[(c, 2)]
        save(plot_fluids(run.columns, run.model.problem, f"condition {c}: oil and tank (2-D)"),
             ctx.work / f"fig10_oil_c{c}.png")
        figures.append(Figure(f"fig10_oil_c{c}.png", f"Fig. 10 analogue, condition {c}: supply oil, oil in the "
                              "tank and tank wall; grey: pump on"))
        save(plot_responses({f"{d}-D": runs[(c, d)].columns for d in dims},
                            f"condition {c}: θ rises and δ" + (" (solid 2-D, dashed 3-D)" if len(dims) > 1 else ""),
                            labels=signal_labels(run.model.problem)),
             ctx.work / f"response_c{c}.png")
        figures.append(Figure(f"response_c{c}.png", f"Figs. 11–13 analogue, condition {c}: θ_A, θ_B, θ_C rises "
                              "and δ against time, pump phases shaded"))
    for dim in dims:
        peak = res[(1, dim)]["first_peak_min"] or 60.0
        save(draw_deformed(runs[(1, dim)], peak * 60.0,
                           lambda t: f"condition 1, {dim}-D, t = {t / 60:.0f} min (first peak of δ)"),
             ctx.work / f"deformed_c1_d{dim}.png")
        figures.append(Figure(f"deformed_c1_d{dim}.png", f"Temperature on the deformed {dim}-D frame at the first "
                              "peak of δ, condition 1"))
    columns, rows = table_rows(res, dims, load)
    size = ctx.scope.get("size_3d")
    t = table("The paper's figures against gatetherm's", columns, rows,
              note="✓: within the acceptance band (±25 % in 2-D, ±35 % in 3-D, peak time ±8 min). "
                   + (f"3-D on {size * 1e3:g}-mm elements (the model's are "
                      f"{paper_model().model.mesh.size_3d * 1e3:g} mm). " if size else "")
                   + "Wall time: condition 1, model build and march, at the load average stated on this machine.")
    return Result(tables=(t,), figures=tuple(figures))
