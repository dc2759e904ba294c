"""``gatetherm compensate``: predict delta from temperatures and compensate it with the piezo.

Reads a time-series file (delta_um = the uncompensated thermal displacement), runs the
paper's procedure (studies/compensator.py) and writes, once everything has been computed:
``DIR/compensated.csv`` (the input plus ``u_piezo_um`` = displacement achieved at the
cutting area, ``delta_pred_um``, ``delta_comp_um``), ``DIR/compensation.png``,
``DIR/piezo_loops.png`` (unless --no-actuator) and ``DIR/summary.json`` (last).
"""
from __future__ import annotations

import argparse
import dataclasses
import json
import logging
import math
from pathlib import Path

from geometry.errors import InputError
from geometry.files import write_text_atomic
from studies.actuator import ActuatorParams
from studies.compensator import NEEDED, CompensatorParams, compensate, summarize
from studies.regression import fit_coefficients
from studies.timeseries import read_timeseries, validate_complete, write_timeseries

log = logging.getLogger(__name__)

#: Where K_i, K_C (um/K) can come from besides --Ki/--Kc: name -> f(series) -> (Ki, Kc).
#: The seam for the "theory" and "fe" sources.
K_SOURCES = {"fit": fit_coefficients}


def register(subparsers) -> None:
    p = subparsers.add_parser(
        "compensate",
        help="predict and compensate the thermal displacement of a run (paper section 3.2)",
        description="Predict delta one minute ahead from theta_A, theta_B, theta_C with "
        "adaptive correction factors R_i, R_C and drive the piezo with -delta_et.",
    )
    p.add_argument("--data", required=True, metavar="FILE.csv", help="time-series file (data-format.md)")
    p.add_argument("--out", required=True, metavar="DIR", help="output directory")
    p.add_argument("--Ki", type=float, metavar="UM_PER_K", help="K_i in um/K (with --Kc)")
    p.add_argument("--Kc", type=float, metavar="UM_PER_K", help="K_C in um/K (with --Ki)")
    p.add_argument("--k-source", choices=sorted(K_SOURCES),
                   help="where K_i, K_C come from instead of --Ki/--Kc (default: fit)")
    p.add_argument("--interval-min", type=float, default=5.0, metavar="MIN",
                   help="piezo update interval in minutes (default 5, as in the paper)")
    p.add_argument("--no-actuator", action="store_true",
                   help="ideal piezo: the stroke equals the command")
    p.set_defaults(func=run)


def coefficients(args: argparse.Namespace, ts) -> tuple[float, float, str]:
    """K_i, K_C (um/K) and a label of their source, from the command line."""
    explicit = (args.Ki is not None, args.Kc is not None)
    if any(explicit):
        if not all(explicit) or args.k_source:
            raise InputError("--Ki/--Kc", "give both, and not together with --k-source",
                             "e.g. --Ki 2.1 --Kc 0.8, or --k-source fit")
        if not (math.isfinite(args.Ki) and math.isfinite(args.Kc)):
            raise InputError("--Ki/--Kc", "must be finite numbers", "e.g. --Ki 2.1 --Kc 0.8")
        return args.Ki, args.Kc, "explicit"
    source = args.k_source or "fit"
    return (*K_SOURCES[source](ts), source)


def run(args: argparse.Namespace) -> int:
    if not (math.isfinite(args.interval_min) and args.interval_min > 0):
        raise InputError("--interval-min", f"must be > 0, got {args.interval_min}", "e.g. --interval-min 5")
    out_dir = Path(args.out)
    if out_dir.exists() and not out_dir.is_dir():
        raise InputError("--out", f"{out_dir} exists and is not a directory", "give a directory path")
    ts = read_timeseries(args.data)
    validate_complete(ts, NEEDED, source=args.data)
    params = CompensatorParams(update_interval_s=args.interval_min * 60.0)
    actuator = None if args.no_actuator else ActuatorParams()
    ki, kc, source = coefficients(args, ts)
    if "u_piezo_um" in ts:
        log.warning("%s: the existing u_piezo_um column is replaced", args.data)
    loop = compensate(ts, ki, kc, params, actuator)
    summary = {**summarize(loop, params.settle_s), "Ki_um_per_K": ki, "Kc_um_per_K": kc,
               "k_source": source, "data": str(args.data), "resampled": loop.prediction.resampled,
               "compensator": dataclasses.asdict(params),
               "actuator": dataclasses.asdict(actuator) if actuator else None}
    text = json.dumps(summary, indent=2, allow_nan=False) + "\n"
    out = ts.with_columns(u_piezo_um=loop.stroke_um, delta_pred_um=loop.delta_pred_um,
                          delta_comp_um=loop.delta_comp_um)
    out = dataclasses.replace(out, metadata={
        **out.metadata, "compensation": f"K_i {ki:.6g} um/K, K_C {kc:.6g} um/K ({source}), update "
        f"every {args.interval_min:g} min, {'actuator model' if actuator else 'ideal piezo'}"})

    from validation.compensation_plots import plot_compensation, plot_piezo_loops  # outer layer
    write_timeseries(out_dir / "compensated.csv", out)
    plot_compensation(loop, out_dir / "compensation.png")
    if actuator:
        plot_piezo_loops(actuator, out_dir / "piezo_loops.png")
    write_text_atomic(out_dir / "summary.json", text)
    log.info("swing %.3g um, prediction error band %.3g um, residual band %.3g um",
             summary["swing_um"], summary["prediction_error_band_um"] or math.nan,
             summary["residual_band_um"] or math.nan)
    return 0
