"""``gatetherm errormodel fit|predict|refit``: thermal-error models from a machine's measurements
(docs/errormodel.md; the library is gatetherm.api.errormodel).

``fit`` writes ``DIR/model.json`` and prints per target the form, sensors, time constants,
held-out error and 90 % interval; ``predict`` writes ``DIR/prediction.csv`` (``time_s``,
``<target>_pred``, ``<target>_lo``, ``<target>_hi`` (the 90 % interval), and ``<target>`` where the
file has it), ``DIR/summary.json`` (MAE and RMS per measured target, the drift check, the filled
gaps) and ``DIR/prediction.png``, and prints one warning line per target whose record is unlike
the fitting data; ``refit`` writes ``DIR/model.json`` with the coefficients refitted on the
data's last window.
"""
from __future__ import annotations

from gatetherm.api import InputError
from gatetherm.api.errormodel import CV_KINDS, FIT_FORMS, FIT_OUTPUTS, PREDICT_OUTPUTS, ROBUST, errormodel_fit, \
    errormodel_predict, errormodel_refit
from gatetherm.cli.options import Progress

ORDER = 100  # its place in `gatetherm --help` (gatetherm.cli finds the command here)

__all__ = ["FIT_OUTPUTS", "PREDICT_OUTPUTS", "register"]


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
                   help="held-out error within a run that orders the forward selection: blocked (every block "
                   "predicted by the fit on the others; default) or chain (the latest blocks, each by the fit on the "
                   "rows before it); the model on the path is then chosen by its forward-chaining error")
    f.add_argument("--no-drift", action="store_true",
                   help="do not offer the slow drift term (hours since the run's start; offered with several runs)")
    f.add_argument("--resolution-K", type=float, default=ROBUST.resolution_K, metavar="K",
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
    targets = _names(args.targets, "--targets", "ch1_um,ch2_um")
    candidates = _names(args.candidates, "--candidates", "t1_degC,t2_degC")
    inputs = _names(args.inputs, "--inputs", "spindle_rpm") or ()
    lo, hi = _span(args.fit_span)
    fit = errormodel_fit(list(args.data), targets, candidates, inputs, span=(lo, hi),
                         named_as=("--targets", "--candidates", "--inputs"), on_progress=Progress("errormodel fit"),
                         max_sensors=args.max_sensors, max_inputs=args.max_inputs, form=args.form,
                         differences=args.differences, resolution_K=args.resolution_K, cv=args.cv,
                         drift=not args.no_drift)
    fit.write(args.out)
    print(fit.summary(args.out))
    return 0


def run_predict(args) -> int:
    result = errormodel_predict(args.model, args.data)
    result.write(args.out)
    print(result.summary(args.out))
    return 0


def run_refit(args) -> int:
    applied = _names(args.applied, "--applied", "ch1_applied_um")
    if not args.window_h > 0:
        raise InputError("--window-h", f"{args.window_h} is not > 0", "e.g. --window-h 24")
    result = errormodel_refit(args.model, args.data, args.window_h * 3600.0, applied, named_as="--applied")
    result.write(args.out)
    print(result.summary(args.out))
    return 0
