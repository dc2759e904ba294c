"""``gatetherm run CASE.toml --out DIR``: any frame described by a case file."""
from __future__ import annotations

import time
from pathlib import Path

from gatetherm.studies.cli.options import FIELD_FILES, Progress

#: What a run writes into --out; a rerun replaces all of it.
OUTPUTS = ("timeseries.csv", "summary.json", *FIELD_FILES, "channels.png", "deformed.png")


def register(sub) -> None:
    p = sub.add_parser("run", help="run a case file (any frame): time series, summary, fields",
                       description="Solve the case (steady, or transient over its [time] settings) and write "
                       "DIR/timeseries.csv, DIR/summary.json (probes at the final time) and the fields for ParaView "
                       "(DIR/fields/*.vtu, fields.pvd). README 'Case files' lists every key.")
    p.add_argument("case", metavar="CASE.toml", help="case file")
    p.add_argument("--out", required=True, metavar="DIR", help="output directory")
    p.add_argument("--no-pictures", action="store_true", help="skip channels.png and deformed.png")
    p.set_defaults(func=run)


def run(args) -> int:
    from gatetherm.outdir import output_dir
    from gatetherm.studies.run.case import load_case

    t0 = time.perf_counter()
    case = load_case(args.case)
    with output_dir(args.out, OUTPUTS, keep=case.inputs) as out:
        return _run(args, case, out, t0)


def _run(args, case, out: Path, t0: float) -> int:
    from gatetherm.studies.run.output import probe_summary, write_json, write_run
    from gatetherm.studies.run.scenario import case_schedule, run_scenario

    schedule = case_schedule(case)
    every = case.time.fields if case.time else 1.0
    fields = {float(t) for t in schedule.times if abs(t / every - round(t / every)) < 1e-9} | {float(schedule.times[-1])}
    res = run_scenario(case, case.mesh.dim, schedule, keep_times=sorted(fields), on_step=Progress(case.name))
    solved = write_run(out, res, {"source": "gatetherm run", "case": str(args.case), "name": case.name}, fields)
    if not args.no_pictures:
        from gatetherm.validation.plots.run import plot_case

        plot_case(res, out, case.name, solved)
    p = case.problem
    summary = {"case": case.name, "file": str(args.case), "dim": p.dim, "order": p.order,
               "analysis": "prescribed temperature" if not p.heat else ("transient" if case.time else "steady"),
               "nodes": len(case.mesh.points), "elements": len(case.mesh.cells),
               "wall_time_s": round(time.perf_counter() - t0, 2), **probe_summary(p, res.columns)}
    write_json(out / "summary.json", summary)
    print(f"wrote {out}/timeseries.csv, summary.json and fields/")
    for name, q in summary["probes"].items():
        print(f"{name}: " + ", ".join(f"{k} {v:.6g}" for k, v in q.items() if v is not None))
    for name, v in summary["relative"].items():
        print(f"{name}: {v:.6g} um")
    return 0
