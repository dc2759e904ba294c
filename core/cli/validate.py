"""``gatetherm validate TARGET``: regenerate a validation study in one command.

Each target is an entry of :data:`TARGETS` (help, add_arguments, run); adding a target is
adding an entry. The studies themselves live in ``gatetherm.validation``; this only parses
arguments and prints what they return.
"""
from __future__ import annotations

import argparse

from gatetherm.api import POSITIVE, InputError, Range
from gatetherm.api.validate_study import TARGETS as STUDIES, validate
from gatetherm.cli.options import SEED, WORKERS, Progress, add_model_options, add_parallel_options, number

ORDER = 80  # its place in `gatetherm --help` (gatetherm.cli finds the command here)


def register(sub) -> None:
    p = sub.add_parser("validate", help="regenerate a validation study (" + ", ".join(TARGETS) + ")",
                       description="Regenerate a validation study: tables, figures and reports.")
    targets = p.add_subparsers(dest="target", metavar="TARGET", required=True)
    for name, (text, add_arguments, run) in TARGETS.items():
        t = targets.add_parser(name, help=text, description=text)
        add_arguments(t)
        t.add_argument("--out", required=True, metavar="DIR", help="output directory")
        t.set_defaults(func=run_target)


def run_target(args):
    """``gt.validate(args.target, args.out, **options)`` with the target's options from the command
    line (in its output directory, locked, stale temporaries removed), its lines printed as they
    come, then its summary; an option the study refuses is named as the command line's."""
    options, progress = TARGETS[args.target][2](args)
    try:
        result = validate(args.target, args.out, on_line=lambda text: print(text, flush=True),
                          on_progress=progress, **options)
    except InputError as err:
        if err.field not in options:
            raise
        raise InputError(f"--{err.field.replace('_', '-')}", err.problem, err.fix) from None
    print(result.summary(), end="")
    return 0


def _options(progress=None, **options):
    return options, progress


def _swept(p) -> None:
    add_model_options(p)
    add_parallel_options(p)


def run_beam(args):
    return _options(Progress(f"validate beam {args.dim}-D"), config=args.config, dim=args.dim,
                 workers=args.workers, scheduler=args.scheduler)


def run_design(args):
    return _options(Progress("validate design"), config=args.config, dim=args.dim, workers=args.workers,
                 scheduler=args.scheduler)


def _paper_arguments(p) -> None:
    p.add_argument("--config", metavar="FILE.toml", help="model file (default: the shipped paper model)")
    p.add_argument("--dims", type=int, nargs="+", choices=(2, 3), default=[2, 3], help="dimensions (default 2 3)")
    p.add_argument("--reuse", action="store_true", help="keep a run whose summary.json exists")


def run_paper(args):
    return _options(config=args.config, dims=args.dims, reuse=args.reuse)


def run_compensation(args):
    return _options(config=args.config, dim=args.dim)


def _conditions(text: str) -> tuple[int, ...]:
    """An argparse ``type``: the paper's condition numbers, comma separated."""
    items = tuple(x.strip() for x in text.split(","))
    if not all(x in ("1", "2", "3") for x in items):
        raise argparse.ArgumentTypeError(f"got {text!r}, must be numbers of 1, 2, 3 separated by commas")
    return tuple(map(int, items))


def _rom_arguments(p) -> None:
    p.add_argument("--config", metavar="FILE.toml", help="model file (default: the shipped paper model)")
    p.add_argument("--dims", type=int, nargs="+", choices=(2, 3), default=[2, 3], help="dimensions (default 2 3)")


def run_rom(args):
    return _options(config=args.config, dims=args.dims)


def _hidden_arguments(p) -> None:
    p.add_argument("--workers", type=number(WORKERS), default=2, metavar="N", help="worker processes (default 2)")
    p.add_argument("--seed", type=number(SEED), default=6, metavar="N", help="seed of the strengths and the noise (default 6)")
    p.add_argument("--conditions", type=_conditions, default=(1, 2, 3),
                   help="conditions, comma separated (default 1,2,3)")
    p.add_argument("--effects", metavar="NAME,...",
                   help="catalogue effects, outside-catalogue cases, mismatches and 'none' (default: all)")
    p.add_argument("--mesh-size", type=number(POSITIVE), metavar="M",
                   help="diagnosis element size, m (default: the model's)")


def run_hidden(args):
    return _options(workers=args.workers, seed=args.seed, conditions=args.conditions,
                    effects=args.effects.split(",") if args.effects else None, mesh_size=args.mesh_size)


def _compound_arguments(p) -> None:
    p.add_argument("--workers", type=number(WORKERS), default=2, metavar="N", help="worker processes (default 2)")
    p.add_argument("--seed", type=number(SEED), default=14, metavar="N", help="seed of the pairs, strengths and noise (default 14)")
    p.add_argument("--pairs", type=number(Range(1, whole=True)), default=48, metavar="N", help="two-piece cases (default 48)")
    p.add_argument("--no-single", action="store_true", help="skip the single-piece cases of the hidden-effect study")
    p.add_argument("--mesh-size", type=number(POSITIVE), metavar="M", help="diagnosis element size, m (default: the model's)")


def run_compound(args):
    return _options(workers=args.workers, seed=args.seed, pairs=args.pairs, single=not args.no_single,
                 mesh_size=args.mesh_size)


def _case_diagnosis_arguments(p) -> None:
    p.add_argument("--case", metavar="CASE.toml", help="case file (default: the C-frame example)")
    p.add_argument("--seed", type=number(SEED), default=10, metavar="N", help="seed of the noise (default 10)")


def run_case_diagnosis(args):
    return _options(case=args.case, seed=args.seed)


def _calibrate_arguments(p) -> None:
    p.add_argument("--evals", type=number(Range(1, whole=True)), default=150,
                   help="objective evaluations (default 150)")
    p.add_argument("--mesh-size", type=number(POSITIVE), default=0.012, metavar="M",
                   help="element size, m (default 0.012)")


def run_calibrate(args):
    return _options(evals=args.evals, mesh_size=args.mesh_size)


def _zoo_arguments(p) -> None:
    p.add_argument("--machines", metavar="NAME,...", help="machines of the zoo, comma separated (default: all)")
    p.add_argument("--timeout", type=number(POSITIVE), default=300.0, metavar="S",
                   help="time limit of one cell, s (default 300)")


def run_zoo(args):
    machines = [m.strip() for m in args.machines.split(",") if m.strip()] if args.machines else None
    return _options(machines=machines, timeout=args.timeout)


_ARGUMENTS = {
    "beam": (_swept, run_beam), "design": (_swept, run_design), "paper": (_paper_arguments, run_paper),
    "compensation": (add_model_options, run_compensation), "rom": (_rom_arguments, run_rom),
    "hidden-effects": (_hidden_arguments, run_hidden), "compound": (_compound_arguments, run_compound),
    "case-diagnosis": (_case_diagnosis_arguments, run_case_diagnosis), "zoo": (_zoo_arguments, run_zoo),
    "calibrate": (_calibrate_arguments, run_calibrate),
}
TARGETS = {name: (STUDIES[name][0], *_ARGUMENTS[name]) for name in STUDIES}
"""Target -> (help, add_arguments, options from the parsed arguments): the studies of :data:`gatetherm.api.validate_study.TARGETS`."""
