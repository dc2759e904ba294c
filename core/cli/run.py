"""``gatetherm run CASE.toml --out DIR``: any machine described by a case file."""
from __future__ import annotations

from pathlib import Path

from gatetherm.cli.options import Progress

ORDER = 10  # its place in `gatetherm --help` (gatetherm.cli finds the command here)


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
    import gatetherm.api as gt

    res = gt.run_case(args.case, args.out, pictures=not args.no_pictures, on_progress=Progress(Path(args.case).stem))
    print(res.summary())
    return 0
