"""``gatetherm report``: every validation result on one page, or the thermal drift report of
one time series (``--data``)."""
from __future__ import annotations

import os
from pathlib import Path

from gatetherm.api import InputError
from gatetherm.api.reports import DRIFT, PAGE, SECTION_KEYS, drift_report, report
from gatetherm.cli.options import WORKERS, Progress, number

ORDER = 130  # its place in `gatetherm --help` (gatetherm.cli finds the command here)

__all__ = ["DRIFT", "PAGE", "register", "run"]


def register(sub) -> None:
    p = sub.add_parser("report", help="every validation result on one page (DIR/index.html, DIR/validation.md); --data: a drift report",
                       description="Compute (or reuse from DIR) every section of the validation report and write "
                       "DIR/index.html with its figures beside it, and the same results as Markdown, DIR/validation.md "
                       "(--docs: also into a repository's docs folder). The long studies run a stated subset unless "
                       "--full. With --data FILE.csv: the thermal drift report of one time series instead.")
    p.add_argument("--out", required=True, metavar="DIR", help="output directory (also the cache of the results)")
    p.add_argument("--full", action="store_true", help="run every study in full (default: the stated subsets)")
    p.add_argument("--section", nargs="+", choices=SECTION_KEYS, metavar="KEY",
                   help="compute only these sections (others are shown if cached): " + ", ".join(SECTION_KEYS))
    p.add_argument("--workers", type=number(WORKERS), default=os.cpu_count() or 1, metavar="N",
                   help="worker processes for the sweeps (default: the CPU count)")
    p.add_argument("--docs", metavar="DIR", help="also write the results page DIR/validation.md (docs/ of a "
                   "checkout); a section this run does not compute keeps its text from the page there")
    p.add_argument("--data", metavar="FILE.csv", help="thermal drift report of this time series (data format)")
    p.set_defaults(func=run)


def run(args) -> int:
    if args.data:
        given = [o for o, v in (("--full", args.full), ("--section", args.section), ("--docs", args.docs)) if v]
        if given:
            raise InputError(f"--data/{given[0]}", "applies to the validation report, not to a drift report",
                             f"drop {given[0]}, or --data")
        print(drift_report(args.data, args.out).summary())
        return 0
    if args.docs is not None and not Path(args.docs).is_dir():
        raise InputError("--docs", f"'{args.docs}' is not a folder", "give the docs folder of a checkout (docs)")
    bar = Progress("report")

    def tell(key, status, seconds):
        if bar.on:  # the section's line over the bar, which the next section draws again
            bar.stream.write("\r" + " " * 60 + "\r")
        print(f"{key:<16} {status}" + (f" ({seconds:.0f} s)" if status in ("computed", "cached") else ""), flush=True)

    done = report(args.out, full=args.full, sections=args.section, workers=args.workers, docs=args.docs,
                  on_section=tell, on_progress=bar)
    print(done.summary())
    return 0
