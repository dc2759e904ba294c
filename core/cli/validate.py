"""``gatetherm validate TARGET``: regenerate a validation study in one command.

Each target is an entry of :data:`TARGETS` (help, add_arguments, run); adding a target is
adding an entry. The studies themselves live in ``gatetherm.validation``; this only parses
arguments and prints what they return.
"""
from __future__ import annotations

import argparse
from pathlib import Path

from gatetherm import InputError
from gatetherm.checks import POSITIVE, Range
from gatetherm.cli.options import WORKERS, Progress, add_model_options, add_parallel_options, number


def register(sub) -> None:
    p = sub.add_parser("validate", help="regenerate a validation study (" + ", ".join(TARGETS) + ")",
                       description="Regenerate a validation study: tables, figures and reports.")
    targets = p.add_subparsers(dest="target", metavar="TARGET", required=True)
    for name, (text, add_arguments, run) in TARGETS.items():
        t = targets.add_parser(name, help=text, description=text)
        add_arguments(t)
        t.add_argument("--out", required=True, metavar="DIR", help="output directory")
        t.set_defaults(func=_in_output_dir(run))


def _in_output_dir(run):
    """A target's run(args) inside its output directory (checked, locked, stale temporaries
    removed; a study's own files are rewritten or resumed by the study)."""
    def wrapped(args) -> int:
        from gatetherm.outdir import output_dir

        with output_dir(args.out):
            return run(args)
    return wrapped


def _swept(p) -> None:
    add_model_options(p)
    add_parallel_options(p)


def run_beam(args) -> int:
    from gatetherm.studies.run.config import load_config
    from gatetherm.validation.beam_study import write_beam_study

    s = write_beam_study(Path(args.out), load_config(args.config), args.dim, args.workers, args.scheduler,
                         Progress(f"validate beam {args.dim}-D"))
    print("\n".join(s["lines"]))
    return 0


def run_design(args) -> int:
    from gatetherm.studies.run.config import load_config
    from gatetherm.validation.design_study import write_design_study

    print("\n".join(write_design_study(Path(args.out), load_config(args.config), args.dim, args.workers,
                                       args.scheduler, Progress("validate design"))))
    return 0


def _paper_arguments(p) -> None:
    p.add_argument("--config", metavar="FILE.toml", help="model file (default: the shipped paper model)")
    p.add_argument("--dims", type=int, nargs="+", choices=(2, 3), default=[2, 3], help="dimensions (default 2 3)")
    p.add_argument("--reuse", action="store_true", help="keep a run whose summary.json exists")


def run_paper(args) -> int:
    from gatetherm.studies.run.config import load_config
    from gatetherm.validation.paper_table import write_paper_table

    print(write_paper_table(Path(args.out), load_config(args.config), args.dims, args.reuse), end="")
    return 0


def run_compensation(args) -> int:
    from gatetherm.studies.run.config import load_config
    from gatetherm.validation.compensation_study import markdown, write_compensation_study

    print(markdown(write_compensation_study(Path(args.out), load_config(args.config), args.dim)), end="")
    return 0


def _conditions(text: str) -> tuple[int, ...]:
    """An argparse ``type``: the paper's condition numbers, comma separated."""
    items = tuple(x.strip() for x in text.split(","))
    if not all(x in ("1", "2", "3") for x in items):
        raise argparse.ArgumentTypeError(f"got {text!r}, must be numbers of 1, 2, 3 separated by commas")
    return tuple(map(int, items))


def _rom_arguments(p) -> None:
    p.add_argument("--config", metavar="FILE.toml", help="model file (default: the shipped paper model)")
    p.add_argument("--dims", type=int, nargs="+", choices=(2, 3), default=[2, 3], help="dimensions (default 2 3)")


def run_rom(args) -> int:
    from gatetherm.studies.run.config import load_config
    from gatetherm.validation.rom_study import write_rom_study

    print(write_rom_study(Path(args.out), load_config(args.config), args.dims,
                          on_row=lambda r: print(f"{r.case}, condition {r.condition}, {r.data}: paper {r.paper_um:.2f}, "
                                                 f"MLR {r.mlr_um:.2f}, rom {r.rom_5min_um:.2f} / {r.rom_event_um:.2f} "
                                                 f"µm ({r.rom_updates} updates)", flush=True)).markdown, end="")
    return 0


def _hidden_arguments(p) -> None:
    p.add_argument("--workers", type=number(WORKERS), default=2, metavar="N", help="worker processes (default 2)")
    p.add_argument("--seed", type=int, default=6, help="seed of the strengths and the noise (default 6)")
    p.add_argument("--conditions", type=_conditions, default=(1, 2, 3),
                   help="conditions, comma separated (default 1,2,3)")
    p.add_argument("--effects", metavar="NAME,...",
                   help="catalogue effects, outside-catalogue cases, mismatches and 'none' (default: all)")
    p.add_argument("--mesh-size", type=number(POSITIVE), metavar="M",
                   help="diagnosis element size, m (default: the model's)")


def run_hidden(args) -> int:
    from gatetherm.validation.hidden_effects import ALL_CASES, row_line, write_hidden_effects

    effects = set(args.effects.split(",")) if args.effects else set(ALL_CASES)
    if effects - set(ALL_CASES):
        raise InputError("--effects", f"unknown {', '.join(sorted(effects - set(ALL_CASES)))}",
                         f"choose from {', '.join(ALL_CASES)}")
    acc, _ = write_hidden_effects(Path(args.out), args.workers, args.seed, args.conditions, effects,
                               args.mesh_size, on_row=lambda row: print(row_line(row), flush=True))
    for k, v in acc.items():
        print(f"{k}: {v}")
    return 0


def _compound_arguments(p) -> None:
    p.add_argument("--workers", type=number(WORKERS), default=2, metavar="N", help="worker processes (default 2)")
    p.add_argument("--seed", type=int, default=14, help="seed of the pairs, strengths and noise (default 14)")
    p.add_argument("--pairs", type=number(Range(1, whole=True)), default=48, metavar="N", help="two-piece cases (default 48)")
    p.add_argument("--no-single", action="store_true", help="skip the single-piece cases of the hidden-effect study")
    p.add_argument("--mesh-size", type=number(POSITIVE), metavar="M", help="diagnosis element size, m (default: the model's)")


def run_compound(args) -> int:
    from gatetherm.validation.compound_study import row_line, write_compound

    figures, _ = write_compound(Path(args.out), args.workers, args.seed, args.pairs, not args.no_single,
                             args.mesh_size, on_row=lambda row: print(row_line(row), flush=True))
    for k, v in figures.items():
        print(f"{k}: {v}")
    return 0


def _case_diagnosis_arguments(p) -> None:
    p.add_argument("--case", metavar="CASE.toml", help="case file (default: the C-frame example)")
    p.add_argument("--seed", type=int, default=10, help="seed of the noise (default 10)")


def run_case_diagnosis(args) -> int:
    from gatetherm.validation.case_diagnosis import C_FRAME, write_case_diagnosis

    line, _ = write_case_diagnosis(Path(args.out), Path(args.case) if args.case else C_FRAME, args.seed,
                                   on_row=lambda r: print(f"{r['scenario']}: {r['verdict']}, "
                                                          f"{' + '.join(r['pieces']) or 'nothing'} named", flush=True))
    print(line)
    return 0


def _calibrate_arguments(p) -> None:
    p.add_argument("--evals", type=number(Range(1, whole=True)), default=150,
                   help="objective evaluations (default 150)")
    p.add_argument("--mesh-size", type=number(POSITIVE), default=0.012, metavar="M",
                   help="element size, m (default 0.012)")


def run_calibrate(args) -> int:
    from gatetherm.validation.calibrate_paper import calibrate

    best = calibrate(args.evals, args.mesh_size, on_better=lambda line: print(line, flush=True))
    print("\n# best parameters (to paste into studies/data/paper.toml)")
    print("\n".join(best))
    return 0


def _zoo_arguments(p) -> None:
    p.add_argument("--machines", metavar="NAME,...", help="machines of the zoo, comma separated (default: all)")
    p.add_argument("--timeout", type=number(POSITIVE), default=300.0, metavar="S",
                   help="time limit of one cell, s (default 300)")


def run_zoo(args) -> int:
    import gatetherm as gt

    machines = [m.strip() for m in args.machines.split(",") if m.strip()] if args.machines else None
    matrix = gt.validate_zoo(args.out, machines, timeout_s=args.timeout,
                             on_cell=lambda m, c, cell: print(f"{m}, {c}: {cell['text']}", flush=True))
    cells = [c for row in matrix.values() for c in row.values()]
    print(f"wrote {args.out}/zoo.md and zoo.json: {len(matrix)} machines x {len(next(iter(matrix.values())))} "
          f"capabilities, {sum(c['status'] == 'ok' for c in cells)} numbers, "
          f"{sum(c['status'] == 'refused' for c in cells)} refusals, {sum(c['status'] == 'failed' for c in cells)} failed")
    return 0


TARGETS = {
    "beam": ("beam theory vs FE: K_i, K_C over l/l4 and beta, error table, series, report", _swept, run_beam),
    "design": ("tie-bar position minimising the 5-h swing of delta; a second tie bar above the arms",
               _swept, run_design),
    "paper": ("the paper's conditions 1-3 in 2-D and 3-D against its reported figures", _paper_arguments,
              run_paper),
    "compensation": ("the paper's compensator, the regression baseline and the piezo on conditions 1-3",
                     add_model_options, run_compensation),
    "rom": ("paper vs regression vs reduced-model compensation: conditions 1-3 in 2-D/3-D, hidden effects",
            _rom_arguments, run_rom),
    "hidden-effects": ("diagnose runs with a hidden catalogue effect, noise only, outside effects, mismatches",
                       _hidden_arguments, run_hidden),
    "compound": ("diagnose runs with two hidden pieces at once (effects, parameters off, sensor faults), "
                 "then the hidden-effect cases", _compound_arguments, run_compound),
    "case-diagnosis": ("diagnose runs of a case file's frame (the C-frame) with hidden pieces of the case",
                       _case_diagnosis_arguments, run_case_diagnosis),
    "zoo": ("every capability on every shipped machine (validation/examples): the matrix zoo.md, zoo.json",
            _zoo_arguments, run_zoo),
    "calibrate": ("refit the default paper model to the paper's figures (a record of the procedure)",
                  _calibrate_arguments, run_calibrate),
}
