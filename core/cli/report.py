"""``gatetherm report``: every validation result on one page, or the thermal drift report of
one time series (``--data``)."""
from __future__ import annotations

import os
import time
from pathlib import Path

from gatetherm import InputError, write_text_atomic
from gatetherm.cli.options import WORKERS, number

PAGE = ("index.html", "validation.md")
"""What a report run replaces in --out; the sections' folders (the cache) are kept."""
DRIFT = ("index.html", "drift.png")
"""What a drift report writes into --out."""


def register(sub) -> None:
    from gatetherm.validation.report.registry import SECTIONS

    p = sub.add_parser("report", help="every validation result on one page (DIR/index.html, DIR/validation.md); --data: a drift report",
                       description="Compute (or reuse from DIR) every section of the validation report and write "
                       "DIR/index.html with its figures beside it, and the same results as Markdown, DIR/validation.md "
                       "(--docs: also into a repository's docs folder). The long studies run a stated subset unless "
                       "--full. With --data FILE.csv: the thermal drift report of one time series instead.")
    p.add_argument("--out", required=True, metavar="DIR", help="output directory (also the cache of the results)")
    p.add_argument("--full", action="store_true", help="run every study in full (default: the stated subsets)")
    p.add_argument("--section", nargs="+", choices=[s.key for s in SECTIONS], metavar="KEY",
                   help="compute only these sections (others are shown if cached): " + ", ".join(s.key for s in SECTIONS))
    p.add_argument("--workers", type=number(WORKERS), default=os.cpu_count() or 1, metavar="N",
                   help="worker processes for the sweeps (default: the CPU count)")
    p.add_argument("--docs", metavar="DIR", help="also write the results page DIR/validation.md (docs/ of a "
                   "checkout); a section this run does not compute keeps its text from the page there")
    p.add_argument("--data", metavar="FILE.csv", help="thermal drift report of this time series (data format)")
    p.set_defaults(func=run)


def run(args) -> int:
    t0 = time.perf_counter()
    if args.data:
        given = [o for o, v in (("--full", args.full), ("--section", args.section), ("--docs", args.docs)) if v]
        if given:
            raise InputError(f"--data/{given[0]}", "applies to the validation report, not to a drift report",
                             f"drop {given[0]}, or --data")
        return _drift(args)
    from gatetherm.files import read_text
    from gatetherm.outdir import output_dir
    from gatetherm.validation.report.build import build, code_digest
    from gatetherm.validation.report.markdown import results_markdown
    from gatetherm.validation.report.page import report_html
    from gatetherm.validation.report.registry import SECTIONS

    docs = Path(args.docs) if args.docs else None
    if docs is not None and not docs.is_dir():
        raise InputError("--docs", f"'{docs}' is not a folder", "give the docs folder of a checkout (docs)")
    page = docs / "validation.md" if docs is not None else None
    before = read_text(page, fix="delete it, or restore it from the checkout") if page and page.exists() else None

    def tell(key, status, seconds):
        print(f"{key:<16} {status}" + (f" ({seconds:.0f} s)" if status in ("computed", "cached") else ""), flush=True)

    with output_dir(args.out, PAGE) as out:  # the sections' folders are the cache: kept
        results = build(Path(args.out), SECTIONS, args.full, args.workers,  # the cache: beside the page
                        set(args.section) if args.section else None, tell)
        code = code_digest()
        write_text_atomic(out / "index.html", report_html(SECTIONS, results, args.out, args.full, code))
        write_text_atomic(out / "validation.md", results_markdown(SECTIONS, results, args.out, args.full, code))
    if docs is not None:
        write_text_atomic(page, results_markdown(SECTIONS, results, "R", args.full, code, figures=False,
                                                 previous=before))
    print(f"wrote {args.out}/index.html and validation.md" + (f" and {page}" if page else "")
          + f" in {time.perf_counter() - t0:.0f} s")
    return 0


def _drift(args) -> int:
    from gatetherm.outdir import output_dir
    from gatetherm.studies.run.timeseries import read_timeseries
    from gatetherm.validation.report.drift import check_record, compute
    from gatetherm.validation.report.page import drift_html

    ts = read_timeseries(args.data, required=("time_s",))
    check_record(ts, args.data)
    with output_dir(args.out, DRIFT, keep=(args.data,)) as out:
        result = compute(ts, out, Path(args.data).name)
        write_text_atomic(out / "index.html", drift_html(result, args.data, f"gatetherm report --data {args.data} "
                                                                            f"--out {args.out}"))
    print(f"wrote {args.out}/index.html and drift.png")
    for line in result.notes[:-1]:
        print(line)
    return 0
