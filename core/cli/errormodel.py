"""``gatetherm errormodel fit|predict``: thermal-error models from a machine's measurements
(docs/errormodel.md; the library is gatetherm.studies.errormodel).

``fit`` writes ``DIR/model.json`` and prints per target the form, sensors, time constants and
held-out error; ``predict`` writes ``DIR/prediction.csv`` (``time_s``, ``<target>_pred``, and
``<target>`` where the file has it), ``DIR/summary.json`` (MAE and RMS per measured target, the
filled gaps) and ``DIR/prediction.png``.
"""
from __future__ import annotations

import dataclasses
import logging

import numpy as np

from gatetherm import InputError, write_text_atomic
from gatetherm.checks import json_text
from gatetherm.studies.errormodel.fit import FIT_FORMS, FitParams, fit_error_model, fraction_span
from gatetherm.studies.errormodel.model import (check_columns, check_leakage, input_gaps, load_model, predict,
                                               save_model, score)
from gatetherm.studies.run.timeseries import TimeSeries, read_timeseries, write_timeseries

log = logging.getLogger(__name__)

FIT_OUTPUTS = ("model.json",)
PREDICT_OUTPUTS = ("prediction.csv", "summary.json", "prediction.png")


def _names(text: str | None, option: str, example: str) -> tuple[str, ...] | None:
    if text is None:
        return None
    names = tuple(n.strip() for n in text.split(",") if n.strip())
    if not names:
        raise InputError(option, "no column named", f"e.g. {option} {example}")
    return names


def _span(text: str) -> tuple[float, float]:
    try:
        lo, hi = (float(v) for v in text.split(":"))
    except ValueError:
        raise InputError("--fit-span", f"{text!r} is not START:END", "fractions of the run, e.g. 0:0.6") from None
    return lo, hi


def register(subparsers) -> None:
    p = subparsers.add_parser("errormodel", help="fit thermal-error models to measured displacements, or apply one",
                              description="Fit per target a thermal-error model (temperature sensors chosen by "
                              "held-out error, operating inputs through first-order lags) or apply a fitted one.")
    sub = p.add_subparsers(dest="action", metavar="ACTION", required=True)
    f = sub.add_parser("fit", help="fit models and write DIR/model.json")
    f.add_argument("--data", required=True, metavar="FILE.csv", help="time-series file (docs/data-format.md)")
    f.add_argument("--targets", required=True, metavar="COL,...", help="displacement columns to model (um)")
    f.add_argument("--out", required=True, metavar="DIR", help="output directory")
    f.add_argument("--candidates", metavar="COL,...", help="temperature columns to choose from (default: every *_degC)")
    f.add_argument("--inputs", metavar="COL,...", help="operating inputs for lag terms, e.g. spindle_rpm")
    f.add_argument("--max-sensors", type=int, default=4, metavar="N", help="sensors per target (default 4)")
    f.add_argument("--max-inputs", type=int, default=2, metavar="N", help="input lag terms per target (default 2)")
    f.add_argument("--form", choices=FIT_FORMS, default="auto", help="model form (default auto: static or dynamic "
                   "by held-out error; paper: K_i (theta_a - theta_b) - K_C theta_c)")
    f.add_argument("--differences", action="store_true", help="also offer sensor differences theta_a - theta_b")
    f.add_argument("--fit-span", default="0:1", metavar="START:END",
                   help="fitting span as fractions of the run's duration (default 0:1, all)")
    f.add_argument("--resolution-K", type=float, default=FitParams.resolution_K, metavar="K",
                   help="the temperature sensors' resolution, also their noise's standard deviation (default 0.05 K, "
                   "a thermocouple): a term spanning less than 10 of these gets no weight, and the coefficients are "
                   "fitted for readings with this noise (docs/errormodel.md)")
    f.set_defaults(func=run_fit)
    q = sub.add_parser("predict", help="apply DIR/model.json to a data file")
    q.add_argument("model", metavar="MODEL.json", help="from 'gatetherm errormodel fit'")
    q.add_argument("--data", required=True, metavar="FILE.csv",
                   help="time-series file with the columns the model reads")
    q.add_argument("--out", required=True, metavar="DIR", help="output directory")
    q.set_defaults(func=run_predict)


def run_fit(args) -> int:
    from gatetherm.outdir import output_dir

    targets = _names(args.targets, "--targets", "ch1_um,ch2_um")
    candidates = _names(args.candidates, "--candidates", "t1_degC,t2_degC")
    inputs = _names(args.inputs, "--inputs", "spindle_rpm") or ()
    check_leakage(targets, candidates, inputs, ("--targets", "--candidates", "--inputs"))
    ts = read_timeseries(args.data, required=("time_s", *targets, *(candidates or ()), *inputs))
    params = FitParams(max_sensors=args.max_sensors, max_inputs=args.max_inputs, form=args.form,
                       differences=args.differences, resolution_K=args.resolution_K)
    span = fraction_span(ts.time_s, *_span(args.fit_span))
    with output_dir(args.out, FIT_OUTPUTS, keep=(args.data,)) as out:
        model = fit_error_model(ts, targets, candidates, inputs, params, span, source=str(args.data))
        save_model(out / "model.json", model)
    print(f"wrote {args.out}/model.json (fitted on {span[0]:g} .. {span[1]:g} s, {model.fit_span['samples']} samples)")
    for m in model.targets:
        taus = ", ".join(f"{t.tau_s:.0f} s" for t in m.terms if t.tau_s is not None) or "none"
        print(f"{m.target}: {m.form}; sensors {', '.join(m.sensors)}; time constants {taus}; "
              f"held-out MAE {m.held_out_mae_um:.3g} um, fit RMS {m.residual['rms_um']:.3g} um, "
              f"sensor noise {m.noise_um:.2g} um")
        if m.form == "paper":
            best = "; ".join(f"{' and '.join(s['terms'])}: {s['cv_mae_um']:.3g} um" for s in m.selection[:3])
            print(f"  best triples, held-out MAE: {best}")
            continue
        by_sensors = {}
        for s in m.selection:
            if s["form"] == m.form:
                by_sensors[s["sensors"]] = min(s["cv_mae_um"], by_sensors.get(s["sensors"], np.inf))
        curve = ", ".join(f"{k}: {v:.3g} um" for k, v in sorted(by_sensors.items()))
        print(f"  forward path, held-out MAE by sensors: {curve}")
    return 0


def run_predict(args) -> int:
    from gatetherm.outdir import output_dir
    from gatetherm.validation.plots import save
    from gatetherm.validation.plots.errormodel import plot_model_prediction

    model = load_model(args.model)
    ts = read_timeseries(args.data, required=("time_s",))
    check_columns(model, ts, str(args.data))
    gaps = input_gaps(model, ts)
    pred = predict(model, ts)
    cols = {"time_s": ts.time_s}
    for name, p in pred.items():
        cols[f"{name}_pred"] = p
        if name in ts:
            cols[name] = ts[name]
    summary = {"model": str(args.model), "data": str(args.data), "targets": score(pred, ts)}
    summary["gaps"] = {k: dataclasses.asdict(g) for k, g in gaps.items()}
    with output_dir(args.out, PREDICT_OUTPUTS, keep=(args.data, args.model)) as out:
        source = {"source": f"gatetherm errormodel predict {args.model}"}
        write_timeseries(out / "prediction.csv", TimeSeries(cols, source))
        save(plot_model_prediction(model, ts), out / "prediction.png")
        write_text_atomic(out / "summary.json", json_text(summary, "summary.json", indent=2))
    print(f"wrote {args.out}/prediction.csv, prediction.png, summary.json")
    for name, g in gaps.items():
        print(f"{name}: {g.filled} missing samples filled (longest gap {g.longest_s:.0f} s), "
              f"{g.unpredicted} in gaps over {model.max_gap_s:.0f} s not predicted")
    for name, e in summary["targets"].items():
        if "mae_um" in e:
            print(f"{name}: MAE {e['mae_um']:.3g} um, RMS {e['rms_um']:.3g} um over {e['samples']} samples")
    return 0
