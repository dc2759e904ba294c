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
import json
import logging
from pathlib import Path

from gatetherm import InputError
from gatetherm.checks import POSITIVE
from gatetherm.cli.options import add_model_options, number, refuse_model_options

log = logging.getLogger(__name__)

#: What a run writes into --out; a rerun replaces all of it.
OUTPUTS = ("residuals.png", "scores.png", "before_after.png", "model.toml", "report.md", "diagnosis.json")

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


def list_effects(config, as_json: bool, uncertain=()) -> str:
    from gatetherm.studies.diagnosis.hypotheses import catalogue
    from gatetherm.studies.run.timeseries import OUTPUT_COLUMNS

    pieces = catalogue(config, OUTPUT_COLUMNS, uncertain)
    if as_json:
        return json.dumps([p.describe() for p in pieces], indent=2)
    rows = [f"{'kind':<10} {'name':<34} {'parameter':<12} {'plausible range':<23} {'unit':<9}"]
    for p in pieces:
        rows.append(f"{p.kind:<10} {p.label:<34} {p.param:<12} {f'{p.lo:.4g} … {p.hi:.4g}':<23} {p.unit:<9}")
        if p.kind != "sensor":
            rows.append(f"{'':<11}{p.doc}")
    rows.append("Sensor faults are tried on every compared channel of the file (further T_<name>_degC too).")
    return "\n".join(rows)


def _names(text: str | None, default: tuple) -> tuple:
    if text is None:
        return default
    return () if text.strip() == "none" else tuple(e.strip() for e in text.split(",") if e.strip())


def settings_from(args):
    """Workflow settings from the command line (checked by :func:`diagnose`)."""
    from gatetherm.studies.diagnosis.discrepancy import Settings

    return Settings(train_fraction=args.train_fraction, effects=_names(args.effects, None),
                    parameters=_names(args.parameters, None), sensors=not args.no_sensors,
                    uncertain=_names(args.uncertain, ()), refine=not args.keep_order)


def load_model(args):
    """The case of --case, or the paper's frame of --config/--dim (checked against the other options)."""
    import gatetherm as gt

    if args.case is None:
        if args.mesh_factor is not None:
            raise InputError("--mesh-factor", "goes with --case only", "give --mesh-size for the paper model")
        case = gt.gate_frame(args.dim, args.config)
        if args.mesh_size is not None:
            case = case.with_overrides({"mesh.size" if args.dim == 2 else "mesh.size_3d": args.mesh_size})
        return case
    refuse_model_options(args)
    if args.mesh_size is not None:
        raise InputError("--case/--mesh-size", "a case file gives its own mesh", "set [mesh] in the case file instead")
    case = gt.load_case(args.case, args.mesh_factor or 1.0)
    if case.time is None:
        raise InputError(f"{args.case}: time", "a diagnosed case needs [time] (a transient run)",
                         "add [time] with end and step; the run's times come from --data")
    return case


def run(args: argparse.Namespace) -> int:
    if args.list_effects:
        print(list_effects(load_model(args), args.json, _names(args.uncertain, ())))
        return 0
    if args.json:
        raise InputError("--json", "only goes with --list-effects", "add --list-effects or drop --json")
    if not args.data or not args.out:
        raise InputError("--data/--out", "both are required", "e.g. gatetherm diagnose --data run.csv --out diag")
    from gatetherm.outdir import output_dir
    from gatetherm.studies.diagnosis.discrepancy import adopted_case, diagnose
    from gatetherm.studies.run.scenario import measured_schedule
    from gatetherm.studies.run.timeseries import read_timeseries

    settings = settings_from(args)
    case = load_model(args)
    ts = read_timeseries(args.data, required=("time_s",))
    measured_schedule(case, ts, str(args.data))  # every input the case reads is in the file
    with output_dir(args.out, OUTPUTS, keep=(args.config, args.data, *case.files)) as out:
        diag = diagnose(case, ts, settings)
        _write(args, case, diag, adopted_case(case, diag), out)
    s = diag.summary()
    print(f"verdict: {diag.verdict}")
    for r in diag.pieces:
        print(f"  {r.piece.kind} {r.piece.label}: {r.piece.param} = {r.value:.4g} ± {r.sigma:.2g} {r.piece.unit}, "
              f"{100 * r.share:.0f} % of the held-out residual"
              + (f" (or: {', '.join(q.label for q in r.alternatives)})" if r.alternatives else ""))
    for g in diag.groups:
        print(f"  cannot be told apart: {g.sentence()}")
    for p, v, why in diag.stand_ins:
        print(f"  stand-in, not a cause: {p.label} {p.param} = {v:.4g} {p.unit} ({why})")
    for p, why in diag.dropped:
        print(f"  dropped, the model refuses it: {p.label} ({why})")
    if diag.cause:
        print(f"  what kind of cause would fit: {diag.cause}")
    if s["best_rejected"]:
        print(f"best rejected: {s['best_rejected']} (gain {s['margin']:.1f} < margin {diag.margin_min:g})")
    if s["rms_after_um"] is not None:
        print(f"held-out RMS of delta: {s['rms_before_um']:.3g} um -> {s['rms_after_um']:.3g} um")
    if diag.too_coarse:
        print(order_warning(diag, ts.metadata))
    print(f"wrote {args.out}/report.md, diagnosis.json ({diag.runs} model runs, {diag.seconds:.0f} s)")
    return 0


def order_warning(diag, metadata: dict) -> str:
    """The warning of a model whose discretisation error exceeds the resolution; where it was replayed
    with P2 and the data are gatetherm's own run (metadata ``source: gatetherm``), the hint to --keep-order."""
    made = metadata.get("source", "").startswith("gatetherm")
    return (f"warning: the model's discretisation error (P2 - P1) exceeds the resolution on "
            f"{', '.join(diag.too_coarse)}; " + ("the diagnosis replayed it with P2 elements" if diag.order == 2 else
                                                "refine the mesh (--mesh-factor) or set order = 2")
            + ("; the data are a run gatetherm simulated (source: gatetherm): if on this mesh with P1, they carry the "
               "same discretisation error, and --keep-order replays with P1" if made and diag.order == 2 else "")
            + " (report.md, 1. Replay)")


def _write(args, case, diag, adopted, out: Path) -> None:
    from gatetherm import write_text_atomic
    from gatetherm.studies.diagnosis.report import report_markdown
    from gatetherm.studies.run.output import write_json
    from gatetherm.validation.plots import save
    from gatetherm.validation.plots.discrepancy import DPI, plot_before_after, plot_residuals, plot_scores

    files = {"residuals": "residuals.png"}
    save(plot_residuals(diag), out / files["residuals"], DPI)
    if diag.rounds:
        files["scores"] = "scores.png"
        save(plot_scores(diag), out / files["scores"], DPI)
    if adopted is not None:
        files["before_after"] = "before_after.png"
        save(plot_before_after(diag), out / files["before_after"], DPI)
    text = None if adopted is None else adopted.origin.model_file(adopted, (
        f"gatetherm diagnose of {args.data}: verdict {diag.verdict}, pieces "
        + ", ".join(r.piece.label for r in diag.pieces) + f"\nbase model: {case.source}"))
    if text is not None:
        files["model"] = str(Path(args.out) / "model.toml")
        write_text_atomic(out / "model.toml", text)
    write_text_atomic(out / "report.md", report_markdown(diag, str(args.data), case.source, files))
    write_json(out / "diagnosis.json", {**diag.summary(), "data": str(args.data), "config": case.source,
                                        "case": args.case, "model_file": files.get("model"),
                                        "mesh_size": args.mesh_size, "mesh_factor": args.mesh_factor})
