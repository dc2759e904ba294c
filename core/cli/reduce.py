"""``gatetherm reduce``: a reduced-order heat model of any case (or the paper's frame), checked against FE.

Writes ``DIR/rom.npz`` (the continuous-time matrices per pump mode, the inputs with their offsets,
the outputs: everything to integrate it without gatetherm, see
:mod:`gatetherm.studies.run.reduce`), ``DIR/rom.key`` (by which ``gatetherm compensate --method rom
--out DIR`` recognises it as the model it would build) and, last, ``DIR/summary.json`` (states,
the error estimates, timings and, per checked schedule, the largest error of every output against
the full FE run).
"""
from __future__ import annotations

import time

from gatetherm import InputError
from gatetherm.cli.options import add_model_options, refuse_model_options

MAX_STATES = 200
#: What a run writes into --out; a rerun replaces all of it.
OUTPUTS = ("rom.npz", "rom.key", "summary.json")


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
    import gatetherm as gt
    from gatetherm.outdir import output_dir

    if not 2 <= args.states <= MAX_STATES:
        raise InputError("--states", f"{args.states} is outside 2..{MAX_STATES}", "e.g. --states 30")
    if args.case is not None:
        refuse_model_options(args)
    case = gt.load_case(args.case) if args.case else gt.gate_frame(args.dim, args.config)
    step = case.time.step if case.time else 60.0  # a --check file at the case's own step
    schedules = [] if args.no_check else [*gt.check_schedules(case), *(gt.schedule_file(f, case, step)
                                                                       for f in args.check)]
    with output_dir(args.out, OUTPUTS, keep=(args.config, *case.files, *args.check)) as out:
        t0 = time.perf_counter()
        red = gt.reduce(case, args.states)
        seconds = time.perf_counter() - t0
        checks = gt.check_rom(case, red.rom, schedules)
        gt.write_reduction(out, red, checks, case, args.states, seconds)
    b = red.error_bound
    print(f"wrote {args.out}/rom.npz, summary.json: {red.rom.states} states from {red.basis.shape[0]} unknowns "
          f"in {seconds:.1f} s; BT bound " + ", ".join(f"{m} {v:.3g}".strip() for m, v in b.items()))
    for c in checks:
        print(f"{c.schedule.split(':')[0]}: max |δ_rom − δ_FE| = {c.max_delta_error_um:.3f} µm, "
              f"θ {c.max_theta_error_K:.3f} K; reduced run {c.rom_ms:.2f} ms (FE {c.fe_seconds:.1f} s)")
        print("  largest error per output: " + ", ".join(f"{k} {v:.3g}" for k, v in c.errors.items()))
    return 0
