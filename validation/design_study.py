"""``gatetherm validate design``: the tie-bar position that minimises the 5-h swing of
delta over conditions 1-3, and a second tie bar above the cutting area (the numbers are
core/frame/design.py; this writes the tables, figures and report)."""
from __future__ import annotations

import time
from pathlib import Path

from gatetherm import write_text_atomic
from gatetherm.frame.config import Config
from gatetherm.studies.sweeps.runner import run_points, write_table
from gatetherm.validation.beam_study import columns_of, cpu_seconds


def write_design_study(out: Path, base: Config, dim: int, workers: int = 1, scheduler: str | None = None,
                       progress=None, positions: int | None = None, refine: int | None = None,
                       second_above=None) -> list[str]:
    """Run the design studies (resumable), write the tables, figures and ``report.md``;
    returns the key figures as sentences. ``positions``, ``refine``, ``second_above``: a
    coarser grid than core/frame/design.py's (first grid, refined points, second-bar
    heights as fractions of l)."""
    from gatetherm.frame import design as ds
    from gatetherm.studies.sweeps.sweep import table
    from gatetherm.validation.plots import save
    from gatetherm.validation.plots.sweep import plot_histories, plot_positions, plot_second

    t0, c0 = time.perf_counter(), cpu_seconds()
    out = Path(out)
    positions, refine = positions or ds.N_POSITIONS, refine or ds.N_REFINE
    second_above = tuple(second_above or ds.SECOND_ABOVE)
    grid = ds.first_grid(base, dim, positions)

    def run_positions(values):
        plans, records = run_points({"p": [ds.position_study(base, dim, values)]}, out, workers, scheduler, progress)
        return table(plans["p"][0], records)[1]

    rows = run_positions(grid)
    rows += run_positions(ds.refined_grid(grid, ds.optimum(rows)["l4"], refine))
    best = ds.optimum(rows)
    paper_rows = run_positions([base.model.frame.l4])
    first = (base.model.frame.l4, best["l4"])
    plans, records = run_points({"s": [ds.second_study(base, dim, first, second_above)]}, out, workers, scheduler,
                                progress)
    second = ds.second_summary(table(plans["s"][0], records)[1])
    columns = list(dict.fromkeys(k for r in rows for k in r))
    write_table(out / "positions.csv", columns, sorted(rows, key=lambda r: (r["geometry.l4"], r["condition"])))
    write_table(out / "second_tie_bar.csv", *columns_of(second))
    save(plot_positions(rows, {f"model l4 = {first[0]:.3g}": first[0], f"optimum {best['l4']:.3g}": best["l4"]},
                        f"one tie bar, {dim}-D"), out / "design_position.png")
    save(plot_second(second, f"second tie bar above the cutting area, {dim}-D"), out / "design_second.png")
    top = min(second, key=lambda r: r["worst_swing_um"])
    column = plans["s"][0][0].config.model.frame.column_height
    designs = {f"model, l4 = {first[0]:.3g} m": base,
               f"optimal l4 = {best['l4']:.3g} m": ds.with_frame(base, l4=best["l4"]),
               f"l4 = {top['l4']:.3g} m + second bar at {top['l4_2']:.3g} m":
                   ds.with_frame(base, l4=top["l4"], l4_2=top["l4_2"], column_height=column)}
    save(plot_histories(ds.histories(designs, dim)), out / "design_histories.png")
    paper_swing = ds.swings(paper_rows)[round(first[0], 6)]
    timing = {"wall s": round(time.perf_counter() - t0, 1), "CPU s": round(cpu_seconds() - c0, 1),
              "workers": scheduler or workers}
    write_text_atomic(out / "report.md", ds.report(dim, base, best, paper_swing, second, timing, (positions, refine)))
    return [f"wrote {out}/report.md, positions.csv, second_tie_bar.csv and design_*.png",
            f"optimal l4 = {best['l4']:.4g} m: worst swing {best['worst_swing_um']:.1f} um "
          f"(model's l4 = {first[0]:.4g} m: {max(paper_swing.values()):.1f} um)",
            f"second tie bar at {top['l4_2']:.4g} m with l4 = {top['l4']:.4g} m: worst swing "
          f"{top['worst_swing_um']:.1f} um ({top['reduction_vs_one_bar']:.0%} below one bar)"]
