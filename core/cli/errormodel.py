"""``gatetherm errormodel fit|predict|refit``: thermal-error models from a machine's measurements
(docs/errormodel.md; the library is gatetherm.api.errormodel).

``fit`` writes ``DIR/model.json`` and prints per target the form, sensors, time constants,
held-out error and 90 % interval; ``predict`` writes ``DIR/prediction.csv`` (``time_s``,
``<target>_pred``, ``<target>_lo``, ``<target>_hi`` (the 90 % interval), and ``<target>`` where the
file has it), ``DIR/summary.json`` (MAE and RMS per measured target, the drift check, the filled
gaps) and ``DIR/prediction.png``, and prints one warning line per target that no longer behaves
like the fitting data; ``refit`` writes ``DIR/model.json`` with the coefficients refitted on the
data's last window.
"""
from __future__ import annotations

import dataclasses
import logging
from pathlib import Path

import numpy as np

from gatetherm import InputError, write_text_atomic
from gatetherm.api.errormodel import ROBUST, errormodel_fit, errormodel_predict, errormodel_refit
from gatetherm.checks import json_text
from gatetherm.studies.errormodel.fit import CV_KINDS, FIT_FORMS, FitParams
from gatetherm.studies.errormodel.model import check_leakage, load_model, save_model
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
    f.add_argument("--data", required=True, nargs="+", metavar="FILE.csv",
                   help="time-series file(s) (docs/data-format.md); several files are several runs, each its own "
                   "reference (the model's value at a run's start is its zero), held out one run at a time with 3 "
                   "or more")
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
                   help="fitting span as fractions of each run's duration (default 0:1, all)")
    f.add_argument("--cv", choices=CV_KINDS, default=ROBUST.cv,
                   help="held-out error within a run: blocked (every block predicted by the fit on the others; "
                   "default) or chain (the latest blocks, each by the fit on the rows before it)")
    f.add_argument("--no-drift", action="store_true",
                   help="do not offer the slow drift term (hours since the run's start; offered with several runs)")
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
    r = sub.add_parser("refit", help="refit a model's coefficients on the last window of new data")
    r.add_argument("model", metavar="MODEL.json", help="from 'gatetherm errormodel fit'")
    r.add_argument("--data", required=True, metavar="FILE.csv", help="the run so far: the model's columns, the targets")
    r.add_argument("--window-h", type=float, default=24.0, metavar="H",
                   help="refit window at the data's end, h (default 24)")
    r.add_argument("--applied", metavar="COL,...",
                   help="per target (in the model's order) the column of the correction "
                   "the control applied, um: the refit fits measured + applied, not what its own correction left")
    r.add_argument("--out", required=True, metavar="DIR", help="output directory")
    r.set_defaults(func=run_refit)


def run_fit(args) -> int:
    from gatetherm.outdir import output_dir

    targets = _names(args.targets, "--targets", "ch1_um,ch2_um")
    candidates = _names(args.candidates, "--candidates", "t1_degC,t2_degC")
    inputs = _names(args.inputs, "--inputs", "spindle_rpm") or ()
    check_leakage(targets, candidates, inputs, ("--targets", "--candidates", "--inputs"))
    named = {**{c: "--inputs" for c in inputs}, **{c: "--candidates" for c in candidates or ()},
             **{c: "--targets" for c in targets}}
    runs = [read_timeseries(d, required=("time_s", *targets, *(candidates or ()), *inputs), named_by=named)
            for d in args.data]
    params = dataclasses.replace(ROBUST, max_sensors=args.max_sensors, max_inputs=args.max_inputs, form=args.form,
                       differences=args.differences, resolution_K=args.resolution_K, cv=args.cv,
                       drift=not args.no_drift)
    lo, hi = _span(args.fit_span)
    with output_dir(args.out, FIT_OUTPUTS, keep=tuple(args.data)) as out:
        model = errormodel_fit(runs, targets, candidates, inputs, params, (lo, hi))
        model = dataclasses.replace(model, fit_span={**model.fit_span, "source": ", ".join(args.data)})
        save_model(out / "model.json", model)
    held = "leave one run out" if len(runs) >= 3 else args.cv
    print(f"wrote {Path(args.out) / 'model.json'} (fitted on {len(runs)} run(s), {model.fit_span['samples']} samples; "
          f"held-out error: {held}; readings smoothed over {model.settings.get('smooth_s', 0.0):g} s)")
    for m in model.targets:
        taus = ", ".join(f"{t.tau_s:.0f} s" for t in m.terms if t.tau_s is not None) or "none"
        drift = next((f"; drift {b:.3g} um/h" for t, b in zip(m.terms, m.coefficients) if t.kind == "drift"), "")
        iv = m.interval
        band = (f"; 90 % interval +-{iv['half_width_um']:.3g} um (held-out samples inside: "
                f"{iv['coverage']:.0%})" if iv.get("coverage") is not None else "")
        print(f"{m.target}: {m.form}; sensors {', '.join(m.sensors)}; time constants {taus}{drift}; "
              f"held-out MAE {m.held_out_mae_um:.3g} um, fit RMS {m.residual['rms_um']:.3g} um, "
              f"sensor noise {m.noise_um:.2g} um{band}")
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
    result = errormodel_predict(model, ts)
    cols = {"time_s": ts.time_s}
    for name, p in result.predicted.items():
        cols[f"{name}_pred"] = p
        cols[f"{name}_lo"], cols[f"{name}_hi"] = result.lower[name], result.upper[name]
        if name in ts:
            cols[name] = ts[name]
    summary = {"model": str(args.model), "data": str(args.data), "targets": result.scores,
               "warnings": list(result.warnings)}
    summary["gaps"] = {k: dataclasses.asdict(g) for k, g in result.gaps.items()}
    with output_dir(args.out, PREDICT_OUTPUTS, keep=(args.data, args.model)) as out:
        source = {"source": f"gatetherm errormodel predict {args.model}"}
        write_timeseries(out / "prediction.csv", TimeSeries(cols, source))
        save(plot_model_prediction(model, ts), out / "prediction.png")
        write_text_atomic(out / "summary.json", json_text(summary, "summary.json", indent=2))
    print(f"wrote {Path(args.out) / 'prediction.csv'}, prediction.png, summary.json")
    for name, g in result.gaps.items():
        print(f"{name}: {g.filled} missing samples filled (longest gap {g.longest_s:.0f} s), "
              f"{g.unpredicted} in gaps over {model.max_gap_s:.0f} s not predicted")
    for name, e in result.scores.items():
        if "mae_um" in e:
            inside = "" if e["share_missed"] is None else f", {1 - e['share_missed']:.0%} inside the 90 % interval"
            print(f"{name}: MAE {e['mae_um']:.3g} um, RMS {e['rms_um']:.3g} um over {e['samples']} samples{inside}")
    for w in result.warnings:
        print(f"warning: {w}")
    return 0


def run_refit(args) -> int:
    from gatetherm.outdir import output_dir

    model = load_model(args.model)
    applied = _names(args.applied, "--applied", "ch1_applied_um")
    if applied is not None and len(applied) != len(model.names):
        raise InputError("--applied", f"{len(applied)} columns for {len(model.names)} targets",
                         f"one per target, in the order {', '.join(model.names)}")
    ts = read_timeseries(args.data, required=("time_s",))
    if not args.window_h > 0:
        raise InputError("--window-h", f"{args.window_h} is not > 0", "e.g. --window-h 24")
    new, report = errormodel_refit(model, ts, args.window_h * 3600.0,
                                   dict(zip(model.names, applied)) if applied else None)
    with output_dir(args.out, FIT_OUTPUTS, keep=(args.data, args.model)) as out:
        save_model(out / "model.json", new)
    print(f"wrote {Path(args.out) / 'model.json'} (refitted on the last {args.window_h:g} h)")
    for name, r in report.items():
        verdict = "kept the current coefficients" if r["kept"] else "refitted"
        print(f"{name}: {verdict}: on the window's last quarter {r['refit_mae_um']:.3g} um refitted against "
              f"{r['current_mae_um']:.3g} um current ({r['samples']} samples)")
    return 0
