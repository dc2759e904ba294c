"""``gatetherm sweep``: run a parametric study file; one tidy table and the plots it asks for.

Files: ``DIR/points/<key>.json`` (one per finished point), ``DIR/table.csv`` (re-assembled
from the point files after every run), ``DIR/study.json`` and the PNGs of the study's
``[[plot]]`` tables.
"""
from __future__ import annotations

import json
from pathlib import Path

from gatetherm import InputError, write_text_atomic
from gatetherm.cli.options import Progress, add_parallel_options

#: What a run writes into --out besides the point files (kept: a rerun resumes from them);
#: a rerun replaces all of it.
OUTPUTS = ("table.csv", "study.json", "*_vs_*.png")


def register(sub) -> None:
    p = sub.add_parser("sweep", help="run a parametric study (grid of parameters); table and plots",
                       description="Evaluate every point of the grid in STUDY.toml (its tables and keys: docs/sweep.md; "
                       "a case file's keys with [study] case = \"case.toml\", the paper frame's: "
                       "studies/data/example_sweep.toml); resumes where a stopped run left off.")
    p.add_argument("study", metavar="STUDY.toml", help="study file")
    p.add_argument("--out", required=True, metavar="DIR", help="output directory")
    add_parallel_options(p)
    p.add_argument("--no-plots", action="store_true", help="write the table only")
    p.set_defaults(func=run)


def run(args) -> int:
    from gatetherm.outdir import output_dir
    from gatetherm.studies.sweeps.runner import PointsFailed
    from gatetherm.studies.sweeps.studyfile import load_study
    from gatetherm.studies.sweeps.sweep import plan

    study = load_study(args.study)
    try:
        tasks = plan(study)
    except InputError as err:
        raise err.at(args.study) from None
    with output_dir(args.out, OUTPUTS, keep=(args.study,)) as out:
        failed = _sweep(args, study, tasks, out)
    if failed:
        raise PointsFailed(failed, len(tasks))
    return 0


def _sweep(args, study, tasks, out) -> list:
    from gatetherm.studies.sweeps.runner import PointStore, run_studies, write_table
    from gatetherm.studies.sweeps.sweep import table

    (records,), failed = run_studies([(tasks, PointStore(Path(args.out)))], args.workers, args.scheduler,
                                     Progress(f"sweep {study.name}"))
    columns, rows = table(tasks, records, study.columns)
    write_table(out / "table.csv", columns, rows)
    write_text_atomic(out / "study.json", json.dumps(
        {"name": study.name, "dim": study.dim, "config": study.case or study.base.source, "compute": list(study.compute),
         "set": dict(study.fixed), "grid": {k: list(v) for k, v in study.grid}}, indent=2) + "\n")
    n_skip = sum(r["status"] == "skipped" for r in rows)
    print(f"wrote {Path(args.out) / 'table.csv'}: {len(rows)} points, {len(rows) - n_skip - len(failed)} done, "
          f"{n_skip} skipped (frame cannot be built), {len(failed)} failed")
    if not args.no_plots and study.plots:
        from gatetherm.validation.plots import save
        from gatetherm.validation.plots.sweep import plot_xy

        for spec in study.plots:
            path = out / f"{spec.y}_vs_{spec.x}{'_by_' + spec.hue if spec.hue else ''}.png".replace("/", "_")
            others = [k for k, _ in study.grid if k not in (spec.x, spec.hue)]
            save(plot_xy(rows, spec.x, spec.y, spec.hue, study.name, lines_by=others), path)
            print(f"wrote {Path(args.out) / path.name}")  # the final file, not the stage's
    return failed
