"""``gatetherm sweep``: run a parametric study file; one tidy table and the plots it asks for.

Files: ``DIR/points/<key>.json`` (one per finished point), ``DIR/table.csv`` (re-assembled
from the point files after every run), ``DIR/study.json`` and the PNGs of the study's
``[[plot]]`` tables.
"""
from __future__ import annotations

from pathlib import Path

from gatetherm.api.study import OUTPUTS, sweep
from gatetherm.cli.options import Progress, add_parallel_options

ORDER = 70  # its place in `gatetherm --help` (gatetherm.cli finds the command here)

__all__ = ["OUTPUTS", "register", "run"]


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
    result = sweep(args.study, args.out, workers=args.workers, scheduler=args.scheduler, plots=not args.no_plots,
                   on_progress=Progress(f"sweep {Path(args.study).stem}"))
    print(result.summary(args.out))
    result.raise_failed()
    return 0
