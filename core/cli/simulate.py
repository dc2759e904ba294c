"""``gatetherm simulate``: run the paper's frame through a condition or a schedule file."""
from __future__ import annotations

from gatetherm.cli.options import Progress, add_model_options, number

ORDER = 30  # its place in `gatetherm --help` (gatetherm.cli finds the command here)


def register(sub) -> None:
    p = sub.add_parser("simulate", help="simulate the paper's frame under a condition; write time series, fields, "
                       "plots")
    src = p.add_mutually_exclusive_group(required=True)
    src.add_argument("--condition", type=int, metavar="N", help="the paper's condition 1, 2 or 3")
    src.add_argument("--schedule", metavar="FILE.csv",
                     help="inputs (time_s, oil_degC, pump[, ambient_degC]) in the gatetherm time-series format")
    add_model_options(p)
    p.add_argument("--out", required=True, metavar="DIR", help="output directory")
    p.add_argument("--fields-every", type=number("POSITIVE"), default=60.0, metavar="MIN",
                   help="write temperature/displacement fields every MIN minutes (default 60)")
    p.add_argument("--effect", action="append", default=[], metavar="NAME:PARAM=VALUE",
                   help="switch on an effect (see 'gatetherm diagnose --list-effects')")
    p.add_argument("--no-pictures", action="store_true", help="skip the PNG plots and the 3-D picture")
    p.set_defaults(func=run)


def run(args) -> int:
    import gatetherm.api as gt

    label = f"condition {args.condition}" if args.condition is not None else f"schedule {args.schedule}"
    res = gt.simulate(args.condition, args.schedule, dim=args.dim, config=args.config, effects=args.effect,
                      fields_every=args.fields_every * 60.0, out=args.out, pictures=not args.no_pictures,
                      on_progress=Progress(label))
    print(res.summary())
    return 0
