"""``gatetherm diagnose``: where a model and a measured run disagree, which catalogue
effect the model misses, and how much better it gets with it.

Writes, once everything is computed: ``DIR/residuals.png``, ``DIR/scores.png``,
``DIR/before_after.png`` and ``DIR/model.toml`` (when a hypothesis is adopted),
``DIR/report.md``, and last ``DIR/diagnosis.json``. ``--list-effects [--json]``
prints the effect catalogue instead.
"""
from __future__ import annotations

import argparse
import dataclasses
import json
import logging
from pathlib import Path

from gatetherm import InputError
from gatetherm.solvers.effects import CATALOGUE, catalogue_json
from gatetherm.checks import POSITIVE
from gatetherm.studies.cli.options import add_model_options, number

log = logging.getLogger(__name__)

#: What a run writes into --out; a rerun replaces all of it.
OUTPUTS = ("residuals.png", "scores.png", "before_after.png", "model.toml", "report.md", "diagnosis.json")


def register(sub) -> None:
    p = sub.add_parser("diagnose", help="find where a model and a measured run disagree and name the missing effect",
                       description="Replay a measured run (gatetherm time-series file) through the model, locate "
                       "significant residuals, recalibrate, fit every catalogue effect on a training window, score "
                       "them on the held-out rest and name the one that explains the data, if any.")
    p.add_argument("--data", metavar="MEASURED.csv", help="measured run in the gatetherm time-series format")
    add_model_options(p, dims=(2,))
    p.add_argument("--out", metavar="DIR", help="output directory")
    p.add_argument("--train-fraction", type=float, default=0.6, metavar="F",
                   help="fit on the first F of the run, score on the rest (default 0.6: 3 h of 5 h)")
    p.add_argument("--effects", metavar="NAME,...", help="candidate effects (default: the whole catalogue)")
    p.add_argument("--mesh-size", type=number(POSITIVE), metavar="M",
                   help="element size of the diagnosis mesh, m (default: the model file's)")
    p.add_argument("--list-effects", action="store_true", help="list the effect catalogue and exit")
    p.add_argument("--json", action="store_true", help="with --list-effects: print JSON")
    p.set_defaults(func=run)


def list_effects(as_json: bool) -> str:
    if as_json:
        return json.dumps(catalogue_json(), indent=2)
    rows = [f"{'effect':<18} {'parameter':<12} {'plausible range':<17} {'unit':<9} acts on"]
    for e in CATALOGUE.values():
        rows += [f"{e.name:<18} {e.param:<12} {f'{e.lo:g} … {e.hi:g}':<17} {e.unit:<9} {e.acts_on}",
                 f"{'':<19}{e.doc}"]
    return "\n".join(rows)


def settings_from(args):
    """Workflow settings from the command line (checked by :func:`studies.discrepancy.diagnose`)."""
    from gatetherm.studies.diagnosis.discrepancy import Settings

    names = tuple(e.strip() for e in (args.effects or "").split(",") if e.strip())
    return Settings(train_fraction=args.train_fraction, effects=names or tuple(CATALOGUE))


def run(args: argparse.Namespace) -> int:
    if args.list_effects:
        print(list_effects(args.json))
        return 0
    if args.json:
        raise InputError("--json", "only goes with --list-effects", "add --list-effects or drop --json")
    if not args.data or not args.out:
        raise InputError("--data/--out", "both are required", "e.g. gatetherm diagnose --data run.csv --out diag")
    from gatetherm.outdir import output_dir
    from gatetherm.studies.run.config import load_config
    from gatetherm.studies.diagnosis.discrepancy import adopted_config, diagnose
    from gatetherm.studies.run.timeseries import read_timeseries

    settings = settings_from(args)
    cfg = load_config(args.config)
    mesh = cfg.model.mesh if args.mesh_size is None else dataclasses.replace(cfg.model.mesh, size=args.mesh_size)
    ts = read_timeseries(args.data)
    with output_dir(args.out, OUTPUTS, keep=(args.config, args.data)) as out:
        diag = diagnose(cfg, ts, args.dim, mesh, settings)
        _write(args, cfg, diag, adopted_config(cfg, diag), out)
    s = diag.summary()
    print(f"verdict: {diag.verdict}" + (f" ({diag.named_effect})" if diag.named_effect else "")
          + f"; runner-up {diag.runner_up}, margin {s['margin'] if s['margin'] is None else round(s['margin'], 1)}")
    if s["rms_after_um"] is not None:
        print(f"held-out RMS of delta: {s['rms_before_um']:.3g} um -> {s['rms_after_um']:.3g} um")
    print(f"wrote {out}/report.md, diagnosis.json ({diag.runs} model runs, {diag.seconds:.0f} s)")
    return 0


def _write(args, cfg, diag, adopted, out: Path) -> None:
    from gatetherm import write_text_atomic
    from gatetherm.studies.diagnosis.report import report_markdown
    from gatetherm.studies.run.config import config_toml
    from gatetherm.studies.run.output import write_json
    from gatetherm.validation.plots.discrepancy import plot_before_after, plot_residuals, plot_scores

    files = {"residuals": "residuals.png"}
    plot_residuals(diag, out / files["residuals"])
    if diag.candidates:
        files["scores"] = "scores.png"
        plot_scores(diag, out / files["scores"])
    if adopted is not None:
        files["before_after"] = "before_after.png"
        plot_before_after(diag, out / files["before_after"])
        files["model"] = str(out / "model.toml")
        head = (f"gatetherm diagnose of {args.data}: verdict {diag.verdict}"
                + (f", effect {diag.named_effect}" if diag.named_effect else "") + f"\nbase model: {cfg.source}")
        write_text_atomic(out / "model.toml", config_toml(adopted, head))
    write_text_atomic(out / "report.md", report_markdown(diag, str(args.data), cfg.source, files))
    write_json(out / "diagnosis.json", {**diag.summary(), "data": str(args.data), "config": cfg.source,
                                        "model_file": files.get("model"), "mesh_size": args.mesh_size})
