"""``gatetherm compensate``: predict delta from temperatures and compensate it with the piezo.

Takes a time-series file (``--data``; delta_um = the uncompensated thermal displacement), runs a
case file (``--case``) or simulates one of the paper's conditions on the frame (``--condition N``,
with ``--dim`` and ``--config``), compensates it (``gatetherm.studies.control.methods``) and
writes, once everything has been computed: ``DIR/compensated.csv`` (the input plus ``u_piezo_um`` =
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
input columns (those the reduced model reads) as the schedule known in advance. The reduced model
is --rom FILE (from ``gatetherm reduce``), or built from the case (or --config/--dim) with --states
states and kept as DIR/rom.npz (reused by a later run with the same model and states, which
DIR/rom.key records).

The actuator is the case's ``[actuator]`` (the frame's: the paper's piezo), ideal without one or
with ``--no-actuator``. The mlr regression is fitted on the model's own schedule (the frame's:
condition 1).

Never silently worse: before anything is written, the correction's benefit is measured on the
held-out last ``--held-out`` (30 %) of the record, what the method fits fitted on the part before
it (gatetherm.studies.control.benefit). A correction that would leave δ there worse than no
compensation is refused in one line naming the figures and a better choice (exit 2), unless
``--force``: then it is written with a warning, printed and in summary.json (``benefit``,
``warning``); so is one within the 0.1-um resolution of no compensation (``no-gain``) or one that
cannot be checked. Every summary.json has ``benefit``. The first printed line's residual band is the
correction as applied over the whole run; the held-out line says whether its figure is that same
correction or a separate check refitted before the held-out span (mlr, --k-source fit).

Never silently unsure: what the K_i, K_C fit (--k-source fit) or the mlr regression dropped or
bounded for the thermocouples' noise (0.05 K), a rom update budget used up before the record
ends (with the time), commands clipped at the actuator's reach, a correction worse than none
earlier in the record (and whether its prediction misses δ by more than δ itself: a record of
another machine) and a record whose time_s is far from the case's [time] (minutes written as
seconds) are each printed as one ``warning:`` line and listed in summary.json's ``warnings``.
"""
from __future__ import annotations

import argparse
import math

from gatetherm.api import COMPENSATE_OUTPUTS as OUTPUTS  # noqa: F401 - what a run writes into --out
from gatetherm.api import K_SOURCES, THERMOCOUPLES, InputError, compensate_run
from gatetherm.cli.options import Progress, add_model_options, refuse_model_options

ORDER = 60  # its place in `gatetherm --help` (gatetherm.cli finds the command here)


def register(subparsers) -> None:
    p = subparsers.add_parser(
        "compensate",
        help="predict and compensate the thermal displacement of a run (paper section 3.2)",
        description="Predict delta one minute ahead from theta_A, theta_B, theta_C (paper), a regression (mlr) "
        "or a reduced model with a Kalman filter (rom), and drive the actuator with the command.",
    )
    src = p.add_mutually_exclusive_group()
    src.add_argument("--data", metavar="FILE.csv", help="time-series file (docs/data-format.md)")
    src.add_argument("--condition", type=int, metavar="N",
                     help="simulate the paper's condition 1, 2 or 3 on the frame and compensate it")
    p.add_argument("--case", metavar="CASE.toml",
                   help="the model: a case file whose [signals] map theta_A, theta_B, theta_C and delta; without "
                   "--data its own run is compensated")
    add_model_options(p)
    p.add_argument("--out", required=True, metavar="DIR", help="output directory")
    p.add_argument("--Ki", type=float, metavar="UM_PER_K", help="K_i in um/K (with --Kc)")
    p.add_argument("--Kc", type=float, metavar="UM_PER_K", help="K_C in um/K (with --Ki)")
    p.add_argument("--k-source", choices=K_SOURCES,
                   help="where K_i, K_C come from instead of --Ki/--Kc (default: theory, the frame's beam theory; "
                   "fit for a case file)")
    p.add_argument("--interval-min", type=float, default=5.0, metavar="MIN",
                   help="actuator update interval in minutes (default 5, as in the paper)")
    p.add_argument("--no-actuator", action="store_true",
                   help="ideal actuator: the stroke equals the command")
    from gatetherm.api import METHOD_SUMMARIES  # read now: every method registered (studies/control/method/)

    p.add_argument("--method", choices=tuple(METHOD_SUMMARIES), default="paper",
                   help="; ".join(f"{name}{' (default)' if name == 'paper' else ''}: {summary}"
                                  for name, summary in METHOD_SUMMARIES.items()))
    p.add_argument("--rom", metavar="ROM.npz", help="rom: reduced model from 'gatetherm reduce' (default: build "
                   "one from the model and keep it in DIR)")
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
    p.add_argument("--held-out", type=float, default=0.3, metavar="FRACTION",
                   help="the last part of the record on which the correction's benefit is checked, what the method "
                   "fits fitted before it (default 0.3)")
    p.add_argument("--force", action="store_true", help="apply a correction that would leave delta worse than no "
                   "compensation on the held-out span (default: refuse it), with a warning in summary.json")
    p.set_defaults(func=run)


def _check(args) -> None:
    """The options' own checks, before anything is read."""
    if not (math.isfinite(args.interval_min) and args.interval_min > 0):
        raise InputError("--interval-min", f"must be > 0, got {args.interval_min}", "e.g. --interval-min 5")
    if args.model is not None and args.method != "paper":
        raise InputError("--model/--method", f"--model replays a fitted error model: --method {args.method} would "
                         "be ignored", "drop --method, or drop --model")
    if not (math.isfinite(args.held_out) and 0 < args.held_out < 1):
        raise InputError("--held-out", f"{args.held_out:g} is not a fraction in (0, 1)", "e.g. --held-out 0.3")
    if args.model is not None and args.data is None:
        raise InputError("--model", "replays a fitted model on recorded data", "give --data FILE.csv")
    if args.data is None and args.condition is None and args.case is None:
        raise InputError("--data/--condition/--case", "give what to compensate",
                         "a time-series file, one of the paper's conditions, or a case file (its own run)")
    if args.case is not None and args.condition is not None:
        raise InputError("--case/--condition", "the paper's conditions drive the frame's oil supply",
                         "compensate a case's own run (--case alone) or a recorded file (--data)")
    if args.case is not None:
        refuse_model_options(args)


def run(args: argparse.Namespace) -> int:
    _check(args)
    sensors = tuple(s.strip() for s in args.sensors.split(",") if s.strip())
    result = compensate_run(args.data, args.case, condition=args.condition, dim=args.dim, config=args.config,
                            method=args.method, interval_min=args.interval_min, updates=args.updates,
                            max_updates=args.max_updates, ideal=args.no_actuator, rom=args.rom, model=args.model,
                            out=args.out, on_progress=Progress("compensate"), Ki=args.Ki, Kc=args.Kc,
                            k_source=args.k_source, states=args.states, sensors=sensors, target=args.target,
                            correction=args.correction, force=args.force, held_out=args.held_out)
    print(result.wrote(args.out))  # written into --out by compensate_run, the directory locked before the run
    print(result.summary())
    return 0
