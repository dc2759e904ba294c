"""``gatetherm simulate``: run a paper condition or a schedule file through the FE model."""
from __future__ import annotations

import time
from pathlib import Path

from gatetherm.checks import POSITIVE
from gatetherm.studies.cli.options import FIELD_FILES, Progress, add_model_options, number

#: What a run writes into --out; a rerun replaces all of it.
OUTPUTS = ("timeseries.csv", "summary.json", *FIELD_FILES, "oil_temperatures.png", "response.png", "deformed.png")


def register(sub) -> None:
    p = sub.add_parser("simulate", help="simulate a heating condition; write time series, fields, plots")
    src = p.add_mutually_exclusive_group(required=True)
    src.add_argument("--condition", type=int, metavar="N", help="the paper's condition 1, 2 or 3")
    src.add_argument("--schedule", metavar="FILE.csv",
                     help="inputs (time_s, oil_degC, pump[, ambient_degC]) in the gatetherm time-series format")
    add_model_options(p)
    p.add_argument("--out", required=True, metavar="DIR", help="output directory")
    p.add_argument("--fields-every", type=number(POSITIVE), default=60.0, metavar="MIN",
                   help="write temperature/displacement fields every MIN minutes (default 60)")
    p.add_argument("--effect", action="append", default=[], metavar="NAME:PARAM=VALUE",
                   help="switch on a catalogue effect (see 'gatetherm diagnose --list-effects')")
    p.add_argument("--no-pictures", action="store_true", help="skip the PNG plots and the 3-D picture")
    p.set_defaults(func=run)


def run(args) -> int:
    from gatetherm.outdir import output_dir
    from gatetherm.solvers.effects import parse_effect_options
    from gatetherm.studies.run.config import load_config
    from gatetherm.studies.run.scenario import condition_schedule, file_schedule

    cfg = load_config(args.config)
    effects = parse_effect_options(args.effect).values  # on top of the model file's
    schedule = file_schedule(args.schedule, cfg) if args.schedule else condition_schedule(args.condition, cfg)
    with output_dir(args.out, OUTPUTS, keep=(args.config, args.schedule)) as out:
        return _simulate(args, cfg, effects, schedule, out)


def _simulate(args, cfg, effects, schedule, out: Path) -> int:
    from gatetherm.studies.run.output import write_json, write_run
    from gatetherm.studies.run.scenario import run_scenario
    from gatetherm.studies.run.simulate import delta_figures

    t_start = time.perf_counter()
    every = max(args.fields_every, 1.0) * 60.0
    field_times = {float(t) for t in schedule.times if t % every < 1e-6}
    keep = sorted(field_times | {float(t) for t in schedule.times if t % 300.0 < 1e-6})  # + picture candidates
    res = run_scenario(cfg, args.dim, schedule, effects, keep_times=keep,
                       on_step=Progress(f"condition {args.condition or 'file'}"))
    cols = res.columns
    figs = delta_figures(cols["time_s"], cols["delta_um"])
    meta = {"source": "gatetherm simulate", "schedule": schedule.label, "dim": str(args.dim), "config": cfg.source}
    if args.condition:
        meta["condition"] = str(args.condition)
    pictures = not args.no_pictures
    if pictures:
        from gatetherm.validation.plots.run import picture_time, plot_run
    solved = write_run(out, res, meta, field_times, (picture_time(figs),) if pictures else ())
    if pictures:
        title = f"gatetherm {args.dim}-D, " + (f"condition {args.condition}" if args.condition
                                               else Path(args.schedule).name)
        plot_run(res, figs, out, title, solved)
    model = res.model
    summary = {**figs, "wall_time_s": round(time.perf_counter() - t_start, 2),
               "build_s": round(res.seconds - res.result.seconds, 2), "march_s": round(res.result.seconds, 2),
               "dim": args.dim, "nodes": len(model.fmesh.points), "elements": len(model.fmesh.cells),
               "schedule": schedule.label, "config": cfg.source, "effects": res.effects.describe()}
    write_json(out / "summary.json", summary)
    print(f"wrote {out}/timeseries.csv, summary.json, fields/ and plots")
    print("first peak {first_peak_um} µm at {first_peak_min} min, swing {swing_um} µm, wall time {w} s"
          .format(**{k: (round(v, 2) if isinstance(v, float) else v) for k, v in figs.items()},
                  w=summary["wall_time_s"]))
    return 0
