"""``gatetherm simulate``: run the paper's frame through a condition or a schedule file."""
from __future__ import annotations

from gatetherm.checks import POSITIVE
from gatetherm.cli.options import FIELD_FILES, Progress, add_model_options, number, picture_keep

#: What a run writes into --out; a rerun replaces all of it.
OUTPUTS = ("timeseries.csv", "summary.json", *FIELD_FILES, "channels.png", "oil_temperatures.png", "response.png",
           "deformed.png")


def register(sub) -> None:
    p = sub.add_parser("simulate", help="simulate the paper's frame under a condition; write time series, fields, "
                       "plots")
    src = p.add_mutually_exclusive_group(required=True)
    src.add_argument("--condition", type=int, metavar="N", help="the paper's condition 1, 2 or 3")
    src.add_argument("--schedule", metavar="FILE.csv",
                     help="inputs (time_s, oil_degC, pump[, ambient_degC]) in the gatetherm time-series format")
    add_model_options(p)
    p.add_argument("--out", required=True, metavar="DIR", help="output directory")
    p.add_argument("--fields-every", type=number(POSITIVE), default=60.0, metavar="MIN",
                   help="write temperature/displacement fields every MIN minutes (default 60)")
    p.add_argument("--effect", action="append", default=[], metavar="NAME:PARAM=VALUE",
                   help="switch on an effect (see 'gatetherm diagnose --list-effects')")
    p.add_argument("--no-pictures", action="store_true", help="skip the PNG plots and the 3-D picture")
    p.set_defaults(func=run)


def run(args) -> int:
    import gatetherm as gt
    from gatetherm.outdir import output_dir
    from gatetherm.solvers.effects import parse_effect
    from gatetherm.studies.run.conditions import condition as check_condition

    with gt.plot.Painter(0 if args.no_pictures else 2) as painter:  # before the work it overlaps
        if args.condition is not None:
            check_condition(args.condition)  # 0 is no condition (it ran condition 1)
        case = gt.gate_frame(args.dim, args.config, 1 if args.condition is None else args.condition)
        effects = dict(parse_effect(s, case.targets) for s in args.effect)  # on top of the model file's
        schedule = gt.schedule_file(args.schedule, case) if args.schedule else case.schedule
        every = max(args.fields_every, 1.0) * 60.0
        with output_dir(args.out, OUTPUTS, keep=(args.config, args.schedule)) as out:
            res = gt.run(case, schedule, effects, keep=picture_keep(schedule, every),
                         on_step=Progress(f"condition {args.condition}" if args.condition is not None else
                                                   f"schedule {args.schedule}"), fields_every=every)
            s = res.write(out, pictures=not args.no_pictures, fields_every=every, painter=painter, release=True)
    print(f"wrote {args.out}/timeseries.csv, summary.json, fields/ and plots")
    print("first peak {first_peak_um} µm at {first_peak_min} min, swing {swing_um} µm, wall time {w} s"
          .format(**{k: (round(v, 2) if isinstance(v, float) else v) for k, v in s.items()}, w=s["wall_time_s"]))
    return 0
