"""``gatetherm diagnose``: where a model and a measured run disagree, which pieces the model
misses (catalogue effects, existing parameters off, sensor faults), and how much better
it gets with them.

Writes, once everything is computed: ``DIR/residuals.png``, ``DIR/scores.png``,
``DIR/before_after.png`` and ``DIR/model.toml`` (when pieces were found),
``DIR/report.md``, and last ``DIR/diagnosis.json``. ``--list-effects [--json]``
prints the hypotheses instead. ``--case CASE.toml`` replays the run through a case file (any
machine) instead of the paper's frame; no ``model.toml`` is written then (the report lists the
values to put into the case file).
"""
from __future__ import annotations

import argparse

from gatetherm.api import DIAGNOSE_OUTPUTS as OUTPUTS  # noqa: F401 - what a run writes into --out
from gatetherm.api import POSITIVE, InputError, diagnose_run, diagnosis_hypotheses, diagnosis_model
from gatetherm.cli.options import Progress, add_model_options, number, refuse_model_options

ORDER = 90  # its place in `gatetherm --help` (gatetherm.cli finds the command here)

DIM_HELP = ("2-D section (default) or 3-D solid. A 3-D diagnosis replays the 3-D model for every hypothesis "
            "(about 100 runs, each up to a 3-D condition's build and march, about 25 s at the default 3-D mesh by the "
            "scaling table in docs/performance.md: tens of minutes, not timed). A 2-D diagnosis of a 3-D "
            "measurement also sees the 2-D/3-D model-form difference as a significant residual; the pieces it "
            "names then make the section model fit, they are not faults of the machine (docs/diagnosis.md)")


def register(sub) -> None:
    p = sub.add_parser("diagnose", help="find where a model and a measured run disagree and name the missing pieces",
                       description="Replay a measured run (gatetherm time-series file) through the model, locate "
                       "significant residuals, then select, by forward selection with held-out evidence, the "
                       "catalogue effects, existing parameters and sensor faults that explain them.")
    p.add_argument("--data", metavar="MEASURED.csv", help="measured run in the gatetherm time-series format")
    add_model_options(p, dim_help=DIM_HELP)
    p.add_argument("--case", metavar="CASE.toml",
                   help="replay through a case file's frame instead of the paper model: the file gives the inputs the "
                   "case reads and the channels its [signals] and probes produce (the case needs [time])")
    p.add_argument("--out", metavar="DIR", help="output directory")
    p.add_argument("--train-fraction", type=float, default=0.6, metavar="F",
                   help="fit on the first F of the run, score on the rest (default 0.6: 3 h of 5 h)")
    p.add_argument("--effects", metavar="NAME,...", help="candidate catalogue effects (default: all; 'none': no effect)")
    p.add_argument("--parameters", metavar="NAME,...",
                   help="candidate existing parameters (default: all; 'none': no parameter)")
    p.add_argument("--no-sensors", action="store_true", help="do not try sensor faults")
    p.add_argument("--uncertain", metavar="KEY,...",
                   help="dimensions to try as hypotheses besides those the model marks: geometry.NAME of the paper "
                   "frame (it marks geometry.l4, l_C, A_C, h, tank_wall), mesh.parameters.NAME of a case file (it "
                   "marks those of [case] uncertain); each new value meshes the model again")
    p.add_argument("--mesh-size", type=number(POSITIVE), metavar="M",
                   help="element size of the diagnosis mesh (2-D or 3-D, as --dim), m (default: the model file's)")
    p.add_argument("--mesh-factor", type=number(POSITIVE), metavar="F",
                   help="with --case: mesh the case's geometry with its element sizes times F (e.g. 0.5 when the "
                   "discretisation check of the report exceeds the resolution)")
    p.add_argument("--keep-order", action="store_true",
                   help="replay with the model's own element order even where its discretisation error (P2 - P1) "
                   "exceeds the resolution (default: then with P2 elements); e.g. for a run gatetherm simulated on "
                   "the same mesh")
    p.add_argument("--list-effects", action="store_true",
                   help="list the hypotheses (effects, parameters, sensor faults) and exit")
    p.add_argument("--json", action="store_true", help="with --list-effects: print JSON")
    p.set_defaults(func=run)


def _names(text: str | None, default: tuple, option: str) -> tuple:
    """The names of a comma-separated list (``none``: none; absent: ``default``); one naming
    nothing (``""``, ``","``) is refused: it would mean none or all without a word."""
    if text is None:
        return default
    names = tuple(e.strip() for e in text.split(",") if e.strip())
    if not names:
        raise InputError(option, f"{text!r} names nothing", f"give names separated by commas, or '{option} none'")
    return () if names == ("none",) else names


def settings_from(args) -> dict:
    """Workflow settings from the command line (checked by :func:`gatetherm.api.diagnose_run`)."""
    return dict(train_fraction=args.train_fraction, effects=_names(args.effects, None, "--effects"),
                parameters=_names(args.parameters, None, "--parameters"), sensors=not args.no_sensors,
                uncertain=_names(args.uncertain, (), "--uncertain"), refine=not args.keep_order)


def load_model(args):
    """The case of --case, or the paper's frame of --config/--dim (checked against the other options)."""
    if args.case is not None:
        refuse_model_options(args)
    return diagnosis_model(args.case, dim=args.dim, config=args.config, mesh_size=args.mesh_size,
                           mesh_factor=args.mesh_factor)


def run(args: argparse.Namespace) -> int:
    if args.list_effects:
        print(diagnosis_hypotheses(load_model(args), _names(args.uncertain, (), "--uncertain"), args.json))
        return 0
    if args.json:
        raise InputError("--json", "only goes with --list-effects", "add --list-effects or drop --json")
    if not args.data or not args.out:
        raise InputError("--data/--out", "both are required", "e.g. gatetherm diagnose --data run.csv --out diag")
    record = {"case": args.case, "mesh_size": args.mesh_size, "mesh_factor": args.mesh_factor}
    result = diagnose_run(load_model(args), args.data, out=args.out, config=args.config, record=record,
                          on_progress=Progress("diagnose: model runs"), **settings_from(args))
    print(result.summary())  # written into --out by diagnose_run, the directory locked before the diagnosis
    print(result.wrote(args.out))
    return 0
