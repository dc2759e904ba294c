"""``gatetherm compensate``: predict delta from temperatures and compensate it with the piezo.

Takes a time-series file (``--data``; delta_um = the uncompensated thermal displacement) or
simulates one of the paper's conditions on the model (``--condition N``, with ``--dim`` and
``--config``), runs the paper's procedure (studies/compensator.py) and writes, once
everything has been computed: ``DIR/compensated.csv`` (the input plus ``u_piezo_um`` =
displacement achieved at the cutting area, ``delta_pred_um``, ``delta_comp_um``),
``DIR/compensation.png``, ``DIR/piezo_loops.png`` (unless --no-actuator) and
``DIR/summary.json`` (last).

K_i, K_C (um/K): ``--Ki/--Kc``, or ``--k-source`` theory (default: beam theory of the model
given by --config, the paper's procedure), fe (FE load cases on that model at --dim, read
at the tips F) or fit (least squares on the run itself).
"""
from __future__ import annotations

import argparse
import dataclasses
import json
import logging
import math
from pathlib import Path

from gatetherm import InputError, write_text_atomic
from gatetherm.solvers.beam import theory_coefficients
from gatetherm.studies.cli.options import add_model_options
from gatetherm.studies.control.actuator import ActuatorParams
from gatetherm.studies.control.compensator import NEEDED, CompensatorParams, compensate, summarize
from gatetherm.studies.control.regression import fit_coefficients
from gatetherm.studies.run.timeseries import FORMAT, read_timeseries, validate_complete, write_timeseries

log = logging.getLogger(__name__)

#: Where K_i, K_C (um/K) can come from besides --Ki/--Kc:
#: name -> f(series, config, model) -> (Ki, Kc), ``model()`` building the FE model on first use.
K_SOURCES = {
    "theory": lambda ts, cfg, model: theory_coefficients(cfg.model),
    "fe": lambda ts, cfg, model: _tips(model()),
    "fit": lambda ts, cfg, model: fit_coefficients(ts),
}
DEFAULT_K_SOURCE = "theory"
WRITTEN = ("u_piezo_um", "delta_pred_um", "delta_comp_um")
"""Columns compensate adds to its input. Those of an earlier compensation (a file with its
``compensation`` metadata) and ``u_piezo_um`` are replaced with a warning; in any other
file a column of these names is refused, since it would be lost."""
#: What a run writes into --out; a rerun replaces all of it.
OUTPUTS = ("compensated.csv", "compensation.png", "piezo_loops.png", "summary.json")


def _tips(model) -> tuple[float, float]:
    from gatetherm.solvers.reduced import tip_coefficients_um  # the FE stack, imported on use

    return tip_coefficients_um(model)


def register(subparsers) -> None:
    p = subparsers.add_parser(
        "compensate",
        help="predict and compensate the thermal displacement of a run (paper section 3.2)",
        description="Predict delta one minute ahead from theta_A, theta_B, theta_C with "
        "adaptive correction factors R_i, R_C and drive the piezo with -delta_et.",
    )
    src = p.add_mutually_exclusive_group(required=True)
    src.add_argument("--data", metavar="FILE.csv", help="time-series file (docs/data-format.md)")
    src.add_argument("--condition", type=int, metavar="N",
                     help="simulate the paper's condition 1, 2 or 3 on the model and compensate it")
    src.add_argument("--case", metavar="CASE.toml",
                     help="run a case file whose [signals] map theta_A, theta_B, theta_C and delta, and compensate "
                     "it (K from --Ki/--Kc or --k-source fit)")
    add_model_options(p)
    p.add_argument("--out", required=True, metavar="DIR", help="output directory")
    p.add_argument("--Ki", type=float, metavar="UM_PER_K", help="K_i in um/K (with --Kc)")
    p.add_argument("--Kc", type=float, metavar="UM_PER_K", help="K_C in um/K (with --Ki)")
    p.add_argument("--k-source", choices=sorted(K_SOURCES),
                   help=f"where K_i, K_C come from instead of --Ki/--Kc (default: {DEFAULT_K_SOURCE}, "
                   "the beam theory of the --config model)")
    p.add_argument("--interval-min", type=float, default=5.0, metavar="MIN",
                   help="piezo update interval in minutes (default 5, as in the paper)")
    p.add_argument("--no-actuator", action="store_true",
                   help="ideal piezo: the stroke equals the command")
    p.set_defaults(func=run)


def coefficients(args: argparse.Namespace, ts, cfg, model) -> tuple[float, float, str]:
    """K_i, K_C (um/K) and a label of their source, from the command line."""
    explicit = (args.Ki is not None, args.Kc is not None)
    if any(explicit):
        if not all(explicit) or args.k_source:
            raise InputError("--Ki/--Kc", "give both, and not together with --k-source",
                             "e.g. --Ki 2.1 --Kc 0.8, or --k-source fit")
        if not (math.isfinite(args.Ki) and math.isfinite(args.Kc)):
            raise InputError("--Ki/--Kc", "must be finite numbers", "e.g. --Ki 2.1 --Kc 0.8")
        return args.Ki, args.Kc, "explicit"
    source = args.k_source or ("fit" if args.case else DEFAULT_K_SOURCE)
    if args.case and source != "fit":
        raise InputError("--k-source", f"'{source}' needs the paper frame's model; a case file has no beam theory",
                         "use --k-source fit or --Ki/--Kc")
    return (*K_SOURCES[source](ts, cfg, model), source)


def _um(value) -> str:
    return "n/a" if value is None else f"{value:.2f} um"


def run(args: argparse.Namespace) -> int:
    from gatetherm.outdir import output_dir
    from gatetherm.studies.run.conditions import condition
    from gatetherm.studies.run.config import load_config
    from gatetherm.studies.run.scenario import ScenarioCache, condition_schedule, prepare

    if not (math.isfinite(args.interval_min) and args.interval_min > 0):
        raise InputError("--interval-min", f"must be > 0, got {args.interval_min}", "e.g. --interval-min 5")
    params = CompensatorParams(update_interval_s=args.interval_min * 60.0)
    cfg = load_config(args.config)

    cache = ScenarioCache()

    def model():  # the FE model with the model file's effects, built on first use
        return prepare(cfg, args.dim, condition_schedule(args.condition or 1, cfg).drive, cache=cache).model

    if args.data is not None:
        ts, what = read_timeseries(args.data), str(args.data)
        validate_complete(ts, NEEDED, source=args.data)
        clash = [name for name in WRITTEN[1:] if name in ts]
        if clash and "compensation" not in ts.metadata:
            raise InputError(f"{args.data}, column {clash[0]}", "compensate writes a column of this name "
                             "and the file is not from an earlier compensate", "rename the column so that it is kept")
    elif args.condition is not None:
        condition(args.condition)  # a bad number fails before the model is built
    with output_dir(args.out, OUTPUTS, keep=(args.config, args.data, args.case)) as out_dir:
        if args.condition is not None:
            ts, what = _simulated(args, cfg, cache), f"condition {args.condition}"
        elif args.case is not None:
            ts, what = _case_series(args.case), str(args.case)
        return _compensate(args, cfg, ts, what, params, model, out_dir)


def _case_series(path):
    """The time series of a case's run; its signals must map the compensator's channels."""
    from gatetherm.studies.run.case import load_case
    from gatetherm.studies.run.scenario import case_schedule, run_scenario

    case = load_case(path)
    if not case.problem.signals.complete or case.time is None:
        raise InputError(f"{path}: signals", "a compensated case needs [time] and [signals] with theta_A, theta_B, "
                         "theta_C and delta", "map them to the case's probes and relative displacement")
    run = run_scenario(case, case.mesh.dim, case_schedule(case))
    return run.series({"format": FORMAT, "source": "gatetherm compensate", "case": str(path)})


def _simulated(args, cfg, cache):
    from gatetherm.studies.run.scenario import condition_schedule, run_scenario

    sim = run_scenario(cfg, args.dim, condition_schedule(args.condition, cfg), cache=cache)
    return sim.series({"format": FORMAT, "source": "gatetherm compensate", "schedule": sim.schedule.label,
                       "dim": str(args.dim), "config": cfg.source, "condition": str(args.condition)})


def _compensate(args, cfg, ts, what, params, model, out_dir: Path) -> int:
    actuator = None if args.no_actuator else ActuatorParams()
    ki, kc, source = coefficients(args, ts, cfg, model)
    replaced = [name for name in WRITTEN if name in ts]
    if replaced:
        log.warning("%s: the existing columns %s are replaced", what, ", ".join(replaced))
    loop = compensate(ts, ki, kc, params, actuator)
    summary = {**summarize(loop, params.settle_s), "Ki_um_per_K": ki, "Kc_um_per_K": kc,
               "k_source": source, "data": args.data, "case": args.case,
               "condition": args.condition, "config": cfg.source, "dim": args.dim,
               "resampled": loop.prediction.resampled, "compensator": dataclasses.asdict(params),
               "actuator": dataclasses.asdict(actuator) if actuator else None}
    text = json.dumps(summary, indent=2, allow_nan=False) + "\n"
    out = ts.with_columns(u_piezo_um=loop.stroke_um, delta_pred_um=loop.delta_pred_um,
                          delta_comp_um=loop.delta_comp_um)
    out = dataclasses.replace(out, metadata={
        **out.metadata, "compensation": f"K_i {ki:.6g} um/K, K_C {kc:.6g} um/K ({source}), update "
        f"every {args.interval_min:g} min, {'actuator model' if actuator else 'ideal piezo'}"})

    from gatetherm.validation.plots.compensation import plot_compensation, plot_piezo_loops  # outer layer
    write_timeseries(out_dir / "compensated.csv", out)
    plot_compensation(loop, out_dir / "compensation.png")
    if actuator:
        plot_piezo_loops(actuator, out_dir / "piezo_loops.png")
    write_text_atomic(out_dir / "summary.json", text)
    print(f"wrote {out_dir}/compensated.csv, compensation.png, "
          f"{'piezo_loops.png, ' if actuator else ''}summary.json")
    print(f"{what}: K_i {ki:.4g}, K_C {kc:.4g} um/K ({source}); swing {summary['swing_um']:.2f} um, "
          f"prediction error band {_um(summary['prediction_error_band_um'])}, "
          f"residual band {_um(summary['residual_band_um'])} "
          f"({_um(summary['residual_at_updates_um'])} at the update instants)")
    return 0
