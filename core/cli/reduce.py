"""``gatetherm reduce``: a reduced-order heat model of any case (or the paper's frame), checked against FE.

Writes ``DIR/rom.npz`` (the continuous-time matrices per pump mode, the inputs with their offsets,
the outputs: everything to integrate it without gatetherm, see
:mod:`gatetherm.studies.run.reduce`), ``DIR/rom.key`` (by which ``gatetherm compensate --method rom
--out DIR`` recognises it as the model it would build) and, last, ``DIR/summary.json`` (states,
the error estimates, timings and, per checked schedule, the largest error of every output against
the full FE run).
"""
from __future__ import annotations

from gatetherm.cli.options import Progress, add_model_options, refuse_model_options

ORDER = 50  # its place in `gatetherm --help` (gatetherm.cli finds the command here)

MAX_STATES = 200


def register(sub) -> None:
    p = sub.add_parser("reduce", help="reduced-order heat model (balanced truncation), checked against FE",
                       description=__doc__.splitlines()[0])
    p.add_argument("--case", metavar="CASE.toml", help="a case file (default: the paper's frame, --dim/--config)")
    add_model_options(p)
    p.add_argument("--states", type=int, default=30, metavar="N", help="states of the reduced model (default 30)")
    p.add_argument("--check", action="append", default=[], metavar="FILE.csv",
                   help="also check it on this schedule file (repeatable), sampled at the case's [time] step (else "
                   "60 s); always on the model's own schedule and, where the model reads their inputs, the paper's "
                   "conditions 1-3")
    p.add_argument("--no-check", action="store_true", help="skip the full FE runs")
    p.add_argument("--out", required=True, metavar="DIR", help="output directory")
    p.set_defaults(func=run)


def run(args) -> int:
    import gatetherm.api as gt

    if not 2 <= args.states <= MAX_STATES:
        raise gt.InputError("--states", f"{args.states} is outside 2..{MAX_STATES}", "e.g. --states 30")
    if args.case is not None:
        refuse_model_options(args)
    res = gt.reduce_case(args.case, dim=args.dim, config=args.config, states=args.states,
                         check=args.check, check_fe=not args.no_check, out=args.out,
                         on_progress=Progress(f"reduce {args.case or 'frame'}"))
    print(res.summary())
    return 0
