"""The paper's design conclusion tested by FE: where to put the tie bar, and what a
second tie bar above the cutting area does (paper section 3.1 and conclusion 3).

Both parts are sweep studies (studies/sweeps/sweep.py) on a model (the paper model by
default) that run the 5-h conditions 1-3 and read the swing of delta (tips F):

1. *Position*: one tie bar at ``l4`` from just above the mounting face to just below
   the arms (in 2-D a tie bar cannot cross them; in 3-D it can pass behind them, up to
   ``l``); a grid, then a finer grid around its best point. The objective is the worst
   swing over conditions 1-3; each condition's own optimum is reported too.
2. *Second tie bar*: ``l4_2`` above the arms, with the first tie bar at the model's
   ``l4`` and at the optimum. The column is raised to hold the highest second tie bar;
   the reference without a second bar has the same raised column, so the comparison
   isolates the bar.

Numbers only; ``gatetherm validate design`` writes the tables, plots and report.
"""
from __future__ import annotations

import dataclasses

import numpy as np

from gatetherm.frame.config import Config
from gatetherm.frame.sweeppoint import FRAME
from gatetherm.studies.sweeps.sweep import Study

CONDITIONS = (1, 2, 3)
N_POSITIONS = 14
"""Points of the first l4 grid."""
N_REFINE = 6
"""Extra points of the finer grid, spread between the neighbours of the best first-grid point."""
MARGIN = 0.01
"""Clearance of a tie bar from the mounting face and the arms, m."""
SECOND_ABOVE = (0.0, 0.1, 0.2, 0.35)
"""Heights of the second tie bar above the lowest position clear of the arms, as a fraction of l."""


def position_range(cfg: Config, dim: int) -> tuple[float, float]:
    """Lowest and highest buildable height (m) of a single tie bar below or at the cutting area."""
    p = cfg.model.frame
    hi = p.l if dim == 3 else p.l - 0.5 * (p.t_C + p.arm_thickness) - MARGIN
    return 0.5 * p.t_C + MARGIN, hi


def _study(name: str, cfg: Config, dim: int, fixed: dict, grid: dict) -> Study:
    return Study(name, dim, cfg, tuple(fixed.items()),
                 tuple((k, tuple(v)) for k, v in grid.items()) + (("condition", CONDITIONS),),
                 ("run", "coefficients"), frame=FRAME)


def position_study(cfg: Config, dim: int, l4_values) -> Study:
    """One tie bar at each of ``l4_values`` (m), conditions 1-3."""
    return _study("tie-bar position", cfg, dim, {}, {"geometry.l4": [round(float(v), 6) for v in l4_values]})


def first_grid(cfg: Config, dim: int, n: int = N_POSITIONS) -> np.ndarray:
    lo, hi = position_range(cfg, dim)
    return np.linspace(lo, hi, n)


def refined_grid(grid, best: float, n: int = N_REFINE) -> np.ndarray:
    """``n`` points strictly between the grid neighbours of ``best``."""
    grid = np.sort(np.asarray(grid, float))
    i = int(np.argmin(np.abs(grid - best)))
    lo, hi = grid[max(i - 1, 0)], grid[min(i + 1, len(grid) - 1)]
    return np.linspace(lo, hi, n + 2)[1:-1]


def swings(rows) -> dict[float, dict[int, float]]:
    """l4 -> condition -> 5-h swing of delta (um), from the rows of a position study."""
    out: dict[float, dict[int, float]] = {}
    for r in rows:
        if r.get("status") == "ok":
            out.setdefault(r["geometry.l4"], {})[r["condition"]] = r["swing_um"]
    return {l4: s for l4, s in sorted(out.items()) if len(s) == len(CONDITIONS)}


def optimum(rows) -> dict:
    """The l4 with the smallest worst-case swing, and each condition's own best l4."""
    s = swings(rows)
    worst = {l4: max(v.values()) for l4, v in s.items()}
    best = min(worst, key=worst.get)
    return {"l4": best, "worst_swing_um": worst[best], "swing_um": s[best],
            "per_condition": {c: min(s, key=lambda l4: s[l4][c]) for c in CONDITIONS}}


def second_heights(cfg: Config, above=SECOND_ABOVE) -> tuple[float, ...]:
    """Heights (m) of the second tie bar: from just clear of the arms upwards (``above``: as a
    fraction of l)."""
    p = cfg.model.frame
    low = p.l + 0.5 * (p.t_C + p.arm_thickness) + MARGIN
    return tuple(round(low + f * p.l, 6) for f in above)


def second_study(cfg: Config, dim: int, first: tuple[float, ...], above=SECOND_ABOVE) -> Study:
    """First tie bar at each of ``first`` (m), with no second bar (``l4_2 = 0``) or one at
    each of :func:`second_heights`; the column raised to hold the highest."""
    p = cfg.model.frame
    heights = second_heights(cfg, above)
    top = max(p.column_height, max(heights) + 0.5 * p.t_C)
    return _study("second tie bar", cfg, dim, {"geometry.column_height": round(top, 6)},
                  {"geometry.l4": [round(float(v), 6) for v in first], "geometry.l4_2": (0.0,) + heights})


def second_summary(rows) -> list[dict]:
    """Per first-bar height and second-bar height: swings per condition, worst swing and its
    reduction against no second bar (same column)."""
    table: dict[tuple[float, float], dict[int, float]] = {}
    for r in rows:
        if r.get("status") == "ok":
            table.setdefault((r["geometry.l4"], r["geometry.l4_2"]), {})[r["condition"]] = r["swing_um"]
    out = []
    for (l4, l42), s in sorted(table.items()):
        ref = max(table[(l4, 0.0)].values()) if (l4, 0.0) in table else np.nan
        worst = max(s.values())
        out.append({"l4": l4, "l4_2": l42, **{f"swing_cond{c}_um": s.get(c) for c in CONDITIONS},
                    "worst_swing_um": worst, "reduction_vs_one_bar": 1.0 - worst / ref})
    return out


def with_frame(cfg: Config, **changes) -> Config:
    """``cfg`` with frame fields changed (for the delta histories of chosen designs)."""
    return dataclasses.replace(cfg, model=dataclasses.replace(
        cfg.model, frame=dataclasses.replace(cfg.model.frame, **changes)))


def histories(designs: dict[str, Config], dim: int) -> dict[str, dict[int, tuple]]:
    """delta(t) (s, um) of each design (label -> model) for conditions 1-3."""
    from gatetherm.frame.case import condition_runs
    from gatetherm.studies.run.scenario import ScenarioCache

    out = {}
    for label, cfg in designs.items():
        runs = condition_runs(cfg, dim, CONDITIONS, ScenarioCache())
        out[label] = {c: (r.columns["time_s"], r.columns["delta_um"]) for c, r in runs.items()}
    return out


def _versus(r: dict) -> str:
    return f"{-r['reduction_vs_one_bar']:+.0%}" if r["l4_2"] else "reference"


def report(dim: int, cfg: Config, best: dict, paper_swing: dict, second: list[dict], timing: dict,
           points: tuple[int, int] = (N_POSITIONS, N_REFINE)) -> str:
    """report.md of ``gatetherm validate design``."""
    p = cfg.model.frame
    lo, hi = position_range(cfg, dim)
    pw = max(paper_swing.values())
    top = min(second, key=lambda r: r["worst_swing_um"])
    at_model = ", ".join(f"{paper_swing[c]:.1f}" for c in CONDITIONS)
    at_best = ", ".join(f"{best['swing_um'][c]:.1f}" for c in CONDITIONS)
    where = ("below the arms: a 2-D tie bar cannot cross them" if dim == 2
             else "up to the cutting area, behind the arms")
    lines = [f"# Tie-bar position and a second tie bar ({dim}-D, {cfg.source})", "",
             f"Frame: l = {p.l:g} m, h = {p.h:g} m, l_C = {p.l_C:g} m, A_C = {p.A_C:g} m², t_C = {p.t_C:g} m, "
             f"the model's tie bar at l4 = {p.l4:g} m. Each point runs conditions 1-3 for 5 h; the swing is "
             "max(delta) - min(delta) at the tips F.", "",
             "## One tie bar", "",
             f"l4 scanned from {lo:.3g} to {hi:.3g} m ({where}), "
             f"{points[0]} points and {points[1]} more around the best (`positions.csv`, `design_position.png`).", "",
             f"- model's l4 = {p.l4:g} m: swing {at_model} um "
             f"(conditions 1-3), worst {pw:.1f} um.",
             f"- optimum (smallest worst swing): l4 = {best['l4']:.4g} m (l/l4 = {p.l / best['l4']:.3g}): swing "
             f"{at_best} um, worst {best['worst_swing_um']:.1f} um "
             f"({1 - best['worst_swing_um'] / pw:.0%} less than at the model's l4).",
             "- each condition's own optimum: " + ", ".join(f"condition {c}: l4 = {v:.4g} m"
                                                            for c, v in best["per_condition"].items()), ""]
    if best["l4"] >= hi - 1e-6:
        lines += ["The optimum is the top of the scan: the swing still falls towards the cutting area, as the "
                  "beam theory's K_i does towards l/l4 = 1 (Fig. 7)"
                  + (", and a 2-D tie bar cannot cross the arms (`--dim 3` lets it pass behind them)." if dim == 2
                     else "."), ""]
    lines += ["## A second tie bar above the cutting area", "",
              "Column raised to hold the highest second bar, for the references without it too "
              "(`second_tie_bar.csv`, `design_second.png`). Worst swing over conditions 1-3:", "",
              "| l4 (m) | l4_2 (m) | cond. 1 (um) | cond. 2 (um) | cond. 3 (um) | worst (um) | vs one bar |",
              "|---|---|---|---|---|---|---|"]
    lines += [f"| {r['l4']:.4g} | {r['l4_2'] or 'none'} | {r['swing_cond1_um']:.1f} | {r['swing_cond2_um']:.1f} | "
              f"{r['swing_cond3_um']:.1f} | {r['worst_swing_um']:.1f} | {_versus(r)} |"
              for r in second]
    lines += ["", f"Best: l4 = {top['l4']:.4g} m with l4_2 = {top['l4_2']:.4g} m, worst swing "
              f"{top['worst_swing_um']:.1f} um, {top['reduction_vs_one_bar']:.0%} below one bar at the same l4 "
              f"and {1 - top['worst_swing_um'] / pw:.0%} below the model as built. delta(t) of the designs: "
              "`design_histories.png`.", "", "## Run", "",
              " | ".join(f"{k}: {v}" for k, v in timing.items()), ""]
    return "\n".join(lines)
