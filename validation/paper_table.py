"""The paper-vs-gatetherm table (docs/paper.md) (``gatetherm validate paper --out runs``).

Runs every condition in every dimension through the scenario path that ``gatetherm
simulate`` takes, writes ``runs/cN_dD/summary.json`` and ``response.png`` (``reuse``
keeps a run whose ``summary.json`` exists) and ``runs/paper_table.md``: the markdown
table of each figure against the paper and whether it meets the acceptance band
(±25 % in 2-D, ±35 % in 3-D; peak time ±8 min).
"""
from __future__ import annotations

import json
from pathlib import Path

from gatetherm import write_text_atomic
from gatetherm.frame.config import Config

#: (condition, summary key, paper value, label); cond. 3's peak is its second positive one.
PAPER = [(1, "first_peak_um", 44.0, "first peak [µm]"), (1, "first_peak_min", 15.0, "time of peak [min]"),
         (1, "swing_um", 52.0, "swing [µm]"),
         (2, "first_peak_um", 42.0, "first peak [µm]"), (2, "first_peak_min", 30.0, "time of peak [min]"),
         (2, "swing_um", 49.0, "swing [µm]"),
         (3, "second_peak_um", 37.0, "second peak [µm] (cond. 2 − 5)"), (3, "swing_um", 60.0, "swing [µm]")]
BAND = {2: 0.25, 3: 0.35}


def within(key: str, got: float | None, want: float, dim: int) -> bool:
    if got is None:
        return False
    if key.endswith("_min"):
        return abs(got - want) <= 8.0
    return abs(got - want) <= BAND[dim] * want


def run_condition(cfg: Config, dim: int, c: int, cache=None, keep_times=()):
    """(the run, its summary: the figures of :data:`PAPER`, wall time, nodes) of condition ``c``."""
    from gatetherm.frame.case import condition_runs
    from gatetherm.studies.run.simulate import delta_figures

    run = condition_runs(cfg, dim, (c,), cache, keep_times=keep_times)[c]
    cols = run.columns
    return run, {**delta_figures(cols["time_s"], cols["delta_um"]), "wall_time_s": round(run.seconds, 2),
                 "dim": dim, "nodes": len(run.model.fmesh.points), "config": cfg.source, "condition": c}


def run_all(out: Path, cfg: Config, dims, reuse: bool) -> dict:
    from gatetherm.validation.plots import save
    from gatetherm.validation.plots.run import plot_response

    res = {}
    for dim in dims:
        for c in (1, 2, 3):
            d = out / f"c{c}_d{dim}"
            if not (reuse and (d / "summary.json").exists()):
                run, summary = run_condition(cfg, dim, c)
                write_text_atomic(d / "summary.json", json.dumps(summary, indent=2, sort_keys=True) + "\n")
                save(plot_response(run.columns, f"gatetherm {dim}-D, condition {c}"), d / "response.png")
            res[(c, dim)] = json.loads((d / "summary.json").read_text())
    return res


def table_rows(res: dict, dims, load: float | None = None) -> tuple[list[str], list[list[str]]]:
    """(columns, rows) of the table of ``res`` {(condition, dim): summary}: every figure against
    the paper with ✓/✗ for its band, the mesh nodes and the wall time of condition 1 (``load``:
    the machine's load average when it was timed)."""
    rows = []
    for c, key, want, label in PAPER:
        cells = []
        for d in dims:
            got = res[(c, d)].get(key)
            cells.append("—" if got is None else f"{got:.1f} {'✓' if within(key, got, want, d) else '✗'}")
        rows.append([str(c), label, f"{want:g}", *cells])
    rows.append(["—", "mesh nodes", "—", *(str(res[(1, d)]["nodes"]) for d in dims)])
    busy = f"; load {load:.1f}" if load is not None else ""
    rows.append(["1", f"wall time of the run (build and march{busy})", "—",
                 *(f"{res[(1, d)]['wall_time_s']:.1f} s" for d in dims)])
    return ["cond.", "figure", "paper", *(f"{d}-D" for d in dims)], rows


def table(res: dict, dims) -> str:
    """:func:`table_rows` as markdown."""
    columns, rows = table_rows(res, dims)
    return "\n".join("| " + " | ".join(r) + " |" for r in [columns, ["---"] * len(columns), *rows])


def write_paper_table(out: Path, cfg: Config, dims=(2, 3), reuse: bool = False) -> str:
    """Run (or reuse) the conditions, write ``out/paper_table.md`` and return its text."""
    text = table(run_all(Path(out), cfg, dims, reuse), dims) + "\n"
    write_text_atomic(Path(out) / "paper_table.md", text)
    return text
