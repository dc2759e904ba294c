"""``gatetherm run CASE.toml --out DIR``: any machine described by a case file."""
from __future__ import annotations

from gatetherm.cli.options import FIELD_FILES, Progress, picture_keep

#: What a run writes into --out; a rerun replaces all of it.
OUTPUTS = ("timeseries.csv", "summary.json", *FIELD_FILES, "channels.png", "oil_temperatures.png", "response.png",
           "deformed.png")


def register(sub) -> None:
    p = sub.add_parser("run", help="run a case file (any machine): time series, summary, fields",
                       description="Solve the case (steady, or transient over its [time] settings) and write "
                       "DIR/timeseries.csv, DIR/summary.json (probes at the final time) and the fields for ParaView "
                       "(DIR/fields/*.vtu, fields.pvd). docs/case-file.md lists every key.")
    p.add_argument("case", metavar="CASE.toml", help="case file")
    p.add_argument("--out", required=True, metavar="DIR", help="output directory")
    p.add_argument("--no-pictures", action="store_true", help="skip the pictures")
    p.set_defaults(func=run)


def run(args) -> int:
    import gatetherm as gt
    from gatetherm.outdir import output_dir

    with gt.plot.Painter(0 if args.no_pictures else 2) as painter:  # before the work it overlaps
        case = gt.load_case(args.case)
        every = case.time.fields if case.time else 1.0
        with output_dir(args.out, OUTPUTS, keep=case.files) as out:
            res = gt.run(case, keep=picture_keep(case.schedule, every), on_step=Progress(case.name),
                         check_order=True)
            summary = res.write(out, pictures=not args.no_pictures, painter=painter, release=True)
    print(f"wrote {args.out}/timeseries.csv, summary.json and fields/")
    for name, q in summary["probes"].items():
        print(f"{name}: " + ", ".join(f"{k} {v:.6g}" for k, v in q.items() if v is not None))
    for name, v in summary["relative"].items():
        print(f"{name}: {v:.6g} um")
    for name, q in summary.get("losses", {}).items():
        print(f"{name}: mean {q['mean_W']:.6g} W, max {q['max_W']:.6g} W, energy {q['energy_J']:.6g} J")
    return 0
