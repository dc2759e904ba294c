"""``gatetherm export FORMAT``: a thermoelastic state as a deck for another code (``ccx``: a CalculiX input
deck), to check gatetherm against an independent FE code; the formats: :mod:`gatetherm.studies.run.formats`."""
from __future__ import annotations

from gatetherm.cli.options import Progress, add_model_options, refuse_model_options

ORDER = 120  # its place in `gatetherm --help` (gatetherm.cli finds the command here)


def register(sub) -> None:
    from gatetherm.api import FORMATS  # the output formats (gatetherm.studies.run.formats), each in one place

    formats = FORMATS.values()
    p = sub.add_parser("export", help=f"export a state for another code "
                       f"({', '.join(f'{f.name}: {f.title}' for f in formats)})",
                       description=" ".join(f.about for f in formats))
    p.add_argument("format", choices=tuple(FORMATS), help="; ".join(f"{f.name}: {f.code}" for f in formats))
    p.add_argument("case", nargs="?", metavar="CASE.toml", help="a case file, 2-D or 3-D (else the paper's frame, "
                   "--condition)")
    p.add_argument("--condition", type=int, metavar="N", help="the paper's condition N (with --time)")
    p.add_argument("--time", type=float, metavar="MIN", help="time of the state, minutes (default: the run's end)")
    add_model_options(p)
    runs = [f for f in formats if f.runner]
    p.add_argument("--run", action="store_true", help=f"also run {' or '.join(repr(f.command) for f in runs)} in DIR "
                   f"({', '.join(f.code for f in runs)} installed) and print {', '.join(f.code for f in runs)}'s "
                   "relative displacements beside gatetherm's and the largest probe difference")
    p.add_argument("--out", required=True, metavar="DIR", help="output directory")
    p.set_defaults(func=run)


def run(args) -> int:
    import gatetherm.api as gt

    if (args.case is None) == (args.condition is None):
        raise gt.InputError("CASE.toml/--condition", "give one of the two", "e.g. --condition 1 --time 15")
    if args.case:
        refuse_model_options(args, "CASE.toml")
    res = gt.export_case(args.case, condition=args.condition, time=None if args.time is None else args.time * 60.0,
                         dim=args.dim, config=args.config, run=args.run, out=args.out, format=args.format,
                         on_progress=Progress(f"export {args.case or f'condition {args.condition}'}"))
    print(res.summary())
    return 0
