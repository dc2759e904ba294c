"""``gatetherm compensate``: predict delta from temperatures and compensate it with the piezo.

Takes a time-series file (``--data``; delta_um = the uncompensated thermal displacement) or
simulates one of the paper's conditions on the model (``--condition N``, with ``--dim`` and
``--config``), runs the paper's procedure (studies/compensator.py) and writes, once
everything has been computed: ``DIR/compensated.csv`` (the input plus ``u_piezo_um`` =
displacement achieved at the cutting area, ``delta_pred_um``, ``delta_comp_um``),
``DIR/compensation.png``, ``DIR/piezo_loops.png`` (unless --no-actuator) and
``DIR/summary.json`` (last).

``--method`` paper (default) is that procedure. K_i, K_C (um/K): ``--Ki/--Kc``, or
``--k-source`` theory (default: beam theory of the model given by --config, the paper's
procedure), fe (FE load cases on that model at --dim, read at the tips F) or fit (least squares
on the run itself).

``--method mlr``: the industry baseline, a static regression of delta on theta_A, theta_B,
theta_C fitted on condition 1 of the --config/--dim model, forecasting one sample ahead from the
extrapolated temperatures (the paper's latency), updated every --interval-min.

``--method rom``: a Kalman filter on the reduced model estimates the thermal state from the
inputs, the --sensors columns and delta; the controller forecasts delta over the hold from the
known schedule and commands the minimax value (studies/control/predictive.py), updating when the
forecast residual would exceed a threshold planned for the --max-updates budget (``--updates
event``, default) or every --interval-min (``--updates fixed``). For --data it takes the file's
oil_degC, pump (and ambient_degC) columns as the schedule known in advance. The reduced model is
--rom FILE (from ``gatetherm reduce``), or built from --config/--dim with --states states and
kept as DIR/rom.npz (reused by a later run with the same model, dimension and states, which
DIR/rom.key records).
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
from gatetherm.studies.control.compensator import (NEEDED, CompensatorParams, close_loop, compensate,
                                                   external_prediction, summarize)
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
METHODS = ("paper", "mlr", "rom")
THERMOCOUPLES = ("theta_A_degC", "theta_B_degC", "theta_C_degC")
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
    p.add_argument("--method", choices=METHODS, default="paper",
                   help="paper (default): the paper's procedure; mlr: regression baseline; rom: Kalman filter "
                   "and predictive control on the reduced model")
    p.add_argument("--rom", metavar="ROM.npz", help="rom: reduced model from 'gatetherm reduce' (default: build "
                   "one from --config/--dim and keep it in DIR)")
    p.add_argument("--states", type=int, default=30, metavar="N", help="rom: states when building (default 30)")
    p.add_argument("--updates", choices=("event", "fixed"), default="event",
                   help="rom: event-triggered within the budget (default) or every --interval-min")
    p.add_argument("--max-updates", type=int, default=60, metavar="N", help="rom: update budget (default 60)")
    p.add_argument("--sensors", default=",".join(THERMOCOUPLES), metavar="COL,...",
                   help="rom: temperature columns the observer reads (default the paper's three)")
    p.add_argument("--model", metavar="MODEL.json", help="replay a model from 'gatetherm errormodel fit' instead of "
                   "--method (the --data file needs only time_s, the model's columns and --target)")
    p.add_argument("--target", metavar="COL", help="--model: the compensated channel (default: the model's only one)")
    p.add_argument("--correction", action="store_true", help="--model of the paper's form: on-line R_i, R_C (eqs 30-38)")
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
        ts, what = read_timeseries(args.data, **({"required": ("time_s",)} if args.model else {})), str(args.data)
        if args.model is None:
            validate_complete(ts, NEEDED, source=args.data)
        clash = [name for name in WRITTEN[1:] if name in ts]
        if clash and "compensation" not in ts.metadata:
            raise InputError(f"{args.data}, column {clash[0]}", "compensate writes a column of this name "
                             "and the file is not from an earlier compensate", "rename the column so that it is kept")
    elif args.condition is not None:
        condition(args.condition)  # a bad number fails before the model is built
    if args.model is not None:  # a bad model file or --target fails before --out is touched
        from gatetherm.studies.errormodel.model import load_model
        from gatetherm.studies.errormodel.replay import loop_target

        loop_target(load_model(args.model), args.target)
    if args.case is not None and args.method != "paper":
        raise InputError("--method", f"{args.method} works on the paper frame's model, not on a case file",
                         "use --method paper with --case")
    with output_dir(args.out, OUTPUTS, keep=(args.config, args.data, args.case)) as out_dir:
        if args.condition is not None:
            ts, what = _simulated(args, cfg, cache), f"condition {args.condition}"
        elif args.case is not None:
            ts, what = _case_series(args.case), str(args.case)
        return _compensate(args, cfg, ts, what, params, model, cache, out_dir)


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


def _compensate(args, cfg, ts, what, params, model, cache, out_dir: Path) -> int:
    actuator = None if args.no_actuator else ActuatorParams()
    replaced = [name for name in WRITTEN if name in ts]
    if replaced:
        log.warning("%s: the existing columns %s are replaced", what, ", ".join(replaced))
    if args.model is not None:  # a fitted error model (studies/errormodel/replay.py)
        from gatetherm.studies.errormodel.model import load_model
        from gatetherm.studies.errormodel.replay import loop_target, replay

        em = load_model(args.model)
        target = loop_target(em, args.target)
        loop = replay(em, ts, target, params, actuator, args.correction)
        extra = {"method": "errormodel", "model": args.model, "target": target, "correction": args.correction}
        label = head = f"error model {args.model}, {target} ({em.target(target).form} form" \
            f"{', on-line R' if args.correction else ''}), update every {args.interval_min:g} min"
    elif args.method == "paper":
        ki, kc, source = coefficients(args, ts, cfg, model)
        loop = compensate(ts, ki, kc, params, actuator)
        extra = {"Ki_um_per_K": ki, "Kc_um_per_K": kc, "k_source": source}
        label = f"K_i {ki:.6g} um/K, K_C {kc:.6g} um/K ({source}), update every {args.interval_min:g} min"
        head = f"K_i {ki:.4g}, K_C {kc:.4g} um/K ({source})"
    elif args.method == "mlr":
        from gatetherm.studies.control.regression import THETAS, fit_regression, regression_forecast
        from gatetherm.studies.run.scenario import condition_schedule, run_scenario

        train = run_scenario(cfg, args.dim, condition_schedule(1, cfg), cache=cache).series({})
        mlr = fit_regression(train, THETAS)
        loop = close_loop(ts, external_prediction(ts, regression_forecast(mlr, ts), params), params, actuator)
        extra = {"regression": {"intercept_um": mlr.intercept_um, **dict(zip(mlr.features, mlr.coefficients))}}
        label = "regression on theta_A, theta_B, theta_C (condition 1 of the model), 1-sample forecast, update " \
            f"every {args.interval_min:g} min"
        head = f"mlr ({label})"
    else:
        loop, extra, label = _rom_loop(args, ts, cfg, cache, params, actuator)
        head = f"rom ({label})"
    summary = {**summarize(loop, params.settle_s), "method": args.method, **extra,
               "data": args.data, "case": args.case,
               "condition": args.condition, "config": cfg.source, "dim": args.dim,
               "resampled": loop.prediction.resampled, "compensator": dataclasses.asdict(params),
               "actuator": dataclasses.asdict(actuator) if actuator else None}
    text = json.dumps(summary, indent=2, allow_nan=False) + "\n"
    out = ts.with_columns(u_piezo_um=loop.stroke_um, delta_pred_um=loop.delta_pred_um,
                          delta_comp_um=loop.delta_comp_um)
    out = dataclasses.replace(out, metadata={
        **out.metadata, "compensation": f"{'' if args.method == 'paper' else args.method + ': '}{label}, "
        f"{'actuator model' if actuator else 'ideal piezo'}"})

    from gatetherm.validation.plots.compensation import plot_compensation, plot_piezo_loops  # outer layer
    write_timeseries(out_dir / "compensated.csv", out)
    plot_compensation(loop, out_dir / "compensation.png")
    if actuator:
        plot_piezo_loops(actuator, out_dir / "piezo_loops.png")
    write_text_atomic(out_dir / "summary.json", text)
    print(f"wrote {out_dir}/compensated.csv, compensation.png, "
          f"{'piezo_loops.png, ' if actuator else ''}summary.json")
    print(f"{what}: {head}; swing {summary['swing_um']:.2f} um, "
          f"prediction error band {_um(summary['prediction_error_band_um'])}, "
          f"residual band {_um(summary['residual_band_um'])} "
          f"({_um(summary['residual_at_updates_um'])} at the update instants), {summary['updates']} updates")
    return 0


def _rom_loop(args, ts, cfg, cache, params, actuator):
    """The rom method's closed loop, its summary entries and a label."""
    from gatetherm.studies.control.predictive import PredictiveParams, rom_prediction
    from gatetherm.studies.control.observer import ObserverParams
    from gatetherm.studies.run.reduce import cached_rom, load_rom

    if not 2 <= args.states <= 200:
        raise InputError("--states", f"{args.states} is outside 2..200", "e.g. --states 30")
    sensors = tuple(s.strip() for s in args.sensors.split(",") if s.strip())
    if not sensors:
        raise InputError("--sensors", "no column named", "e.g. --sensors theta_A_degC,theta_B_degC")
    control = PredictiveParams(mode=args.updates, max_updates=args.max_updates, interval_s=params.update_interval_s)
    if args.rom:
        rom, where = load_rom(args.rom), args.rom
    else:
        rom, where = cached_rom(cfg, args.dim, args.states, Path(args.out), cache), str(Path(args.out) / "rom.npz")
    pr, cmds = rom_prediction(ts, rom, params, control, ObserverParams(), sensors, cfg.supply.T_room)
    loop = close_loop(ts, pr, params, actuator)
    extra = {"rom": where, "rom_states": rom.states, "sensors": list(sensors), "threshold_um": cmds.threshold_um,
             "predictive": dataclasses.asdict(control), "observer": dataclasses.asdict(ObserverParams())}
    how = f"threshold {cmds.threshold_um:.2f} um" if cmds.threshold_um is not None else \
        f"every {args.interval_min:g} min"
    return loop, extra, f"reduced model ({rom.states} states), Kalman filter on {', '.join(sensors)}, {how}"

