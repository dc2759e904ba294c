"""Thermal-error models of measured channels (:mod:`gatetherm.api`; docs/errormodel.md): fit on one
run or several, predict with a 90 % interval and a drift check, refit as data arrive."""
from __future__ import annotations

import dataclasses
import logging
import os
from typing import Callable, Mapping, Sequence

import numpy as np

from gatetherm import InputError
from gatetherm.api.errormodel_results import FIT_OUTPUTS, PREDICT_OUTPUTS, ErrorModelFit, Prediction, \
    Refit  # noqa: F401
from gatetherm.checks import POSITIVE, argument, number_argument
from gatetherm.studies.errormodel.fit import CV_KINDS, FIT_FORMS, FitParams, fit_error_model, fraction_span  # noqa: F401
from gatetherm.studies.errormodel.model import ErrorModel, check_columns, check_leakage, input_gaps, load_model, \
    predict, score
from gatetherm.studies.errormodel.trust import trust
from gatetherm.studies.errormodel.refit import refit
from gatetherm.studies.run.timeseries import TimeSeries, read_timeseries

PUBLIC = ("ErrorModelFit", "Prediction", "Refit", "errormodel_fit", "errormodel_predict", "errormodel_refit")

log = logging.getLogger(__name__)


def _is_path(data) -> bool:
    return isinstance(data, (str, bytes)) or hasattr(data, "__fspath__")


def _read(data, required=("time_s",), named_by=None):
    argument("data", data, (str, bytes, os.PathLike, TimeSeries), "a time-series file's path or a TimeSeries")
    return read_timeseries(data, required=required, named_by=named_by) if _is_path(data) else data


def _model(model) -> ErrorModel:
    """An ErrorModel from a model, a fit's result or a ``model.json`` path."""
    if isinstance(model, (ErrorModelFit, Refit)):
        return model.model
    argument("model", model, (ErrorModel, str, os.PathLike), "an ErrorModel or a model.json's path",
             "from errormodel_fit, or 'gatetherm errormodel fit'")
    return model if isinstance(model, ErrorModel) else load_model(model)


ROBUST = FitParams(drift=True, noisy_cv=True, smooth_grid_s=(300.0,), anchor_s=600.0, choose_latest=True)
"""The API's and the command's default fit: within a run, the model (terms, form, the readings'
smoothing) chosen by its forward-chaining error on the fitting span's latest blocks among the models on
the blocked-cross-validation selection path (``choose_latest``); leave one run out with three or more
runs (readings not smoothed there); a drift term offered with several runs; candidates scored by their
expected held-out error on readings with the sensors' noise; each run referenced on its first 600 s
(docs/errormodel.md, "Sensor noise", "Data never seen")."""


def errormodel_fit(data: str | os.PathLike | TimeSeries | Sequence[str | os.PathLike | TimeSeries],
                   targets: Sequence[str], candidates: Sequence[str] | None = None, inputs: Sequence[str] = (),
                   params: FitParams = ROBUST, span: tuple[float, float] = (0.0, 1.0), *,
                   named_as: tuple[str, str, str] = ("targets", "candidates", "inputs"),
                   on_progress: Callable[[int, int], None] | None = None, **settings) -> ErrorModelFit:
    """Fit a thermal-error model per target on one measured run or several.

    Parameters
    ----------
    data : path, TimeSeries, or a list of them
        The runs (docs/data-format.md): ``time_s`` (s), the targets (um), temperatures (degC),
        inputs. Several runs are each their own reference and, three or more, held out one at a time.
    targets : sequence of str
        Displacement columns, um.
    candidates : sequence of str, optional
        Temperature columns to choose from (default every ``*_degC``).
    inputs : sequence of str
        Operating inputs for lag terms, e.g. ``("spindle_rpm",)``.
    params : FitParams
        Budgets, cross-validation, drift term, noise; default :data:`ROBUST` (``cv="chain"`` selects
        by the latest held-out blocks, each predicted from the rows before it).
    span : (float, float)
        Fitting span as fractions of each run's duration.
    named_as : (str, str, str)
        How messages name ``targets``, ``candidates`` and ``inputs`` (the command: its options).
    on_progress : callable, optional
        ``on_progress(i, n)`` after each data file read and after the fit (``i`` up to ``n``, the
        files plus one).
    **settings
        Fields of :class:`~gatetherm.studies.errormodel.fit.FitParams` replacing those of ``params``
        (``max_sensors``, ``max_inputs``, ``form``, ``differences``, ``resolution_K`` in K, ``cv``,
        ``drift`` …).

    Returns
    -------
    ErrorModelFit
        ``.model`` (the :class:`~gatetherm.studies.errormodel.model.ErrorModel`), ``.write(out)``
        (``out/model.json``) and ``.summary()``.

    Raises
    ------
    TypeError
        A setting that is not a field of FitParams.
    InputError
        A target among the candidates or inputs, a missing column, a bad setting.
    """
    fields = {f.name for f in dataclasses.fields(FitParams)}
    unknown = sorted(set(settings) - fields)
    if unknown:
        raise TypeError(f"{unknown[0]}: not a setting of the fit; choose from {', '.join(sorted(fields))}")
    params = dataclasses.replace(params, **settings) if settings else params
    for name, names in (("targets", targets), ("candidates", candidates), ("inputs", inputs)):
        if isinstance(names, str) or not (names is None and name != "targets" or isinstance(names, (list, tuple))):
            raise TypeError(f"{name}: got {type(names).__name__} {str(names)[:40]!r}, expected a list of column "
                            f"names; e.g. {name}=['delta_um']")
    targets, inputs = tuple(targets), tuple(inputs or ())
    check_leakage(targets, candidates, inputs, tuple(named_as))
    named = {**{c: named_as[2] for c in inputs}, **{c: named_as[1] for c in candidates or ()},
             **{c: named_as[0] for c in targets}}
    runs = list(data) if isinstance(data, (list, tuple)) else [data]
    for i, r in enumerate(runs):
        argument(f"data[{i}]" if isinstance(data, (list, tuple)) else "data", r, (str, os.PathLike, TimeSeries),
                 "a time-series file's path or a TimeSeries", "e.g. errormodel_fit('run.csv', ['delta_um'])")
    required = ("time_s", *targets, *(candidates or ()), *inputs)
    series = []
    for r in runs:
        series.append(_read(r, required, named))
        if on_progress is not None:
            on_progress(len(series), len(runs) + 1)
    for j, ts in enumerate(series):  # a run given twice: its held-out error would be in-sample
        same = next((i for i in range(j) if _same_record(series[i], ts, ("time_s", *targets))), None)
        if same is not None:
            raise InputError(f"data[{j}]", f"is the same record as data[{same}] ({runs[same]}): a run left out "
                             "would be fitted all the same", "give each run once")
    for t in targets:
        if t.endswith("_degC"):
            log.warning("targets %s: a temperature column, predicted as a displacement in um", t)
    spans = [fraction_span(ts["time_s"], *span) for ts in series]
    source = ", ".join(str(r) for r in runs if not hasattr(r, "names"))
    model = fit_error_model(series, targets, candidates, inputs, params, spans, source=source)
    if on_progress is not None:
        on_progress(len(runs) + 1, len(runs) + 1)
    how = "leave one run out" if len(runs) >= 3 else \
        f"{params.cv}, chosen on the latest forward-chaining blocks" if params.choose_latest else params.cv
    return ErrorModelFit(model, len(runs), how,
                         tuple(str(r) for r in runs if _is_path(r)))


def errormodel_predict(model: ErrorModel | ErrorModelFit | str | os.PathLike,
                       data: str | os.PathLike | TimeSeries) -> Prediction:
    """Apply a model with its 90 % interval and drift check.

    Parameters
    ----------
    model : ErrorModel, ErrorModelFit or path
        From :func:`errormodel_fit` or a ``model.json``.
    data : path or TimeSeries
        The columns the model reads; targets where measured are scored.

    Returns
    -------
    Prediction
        Predictions and intervals (um), scores, filled gaps and the drift warnings; ``.write(out)``
        (``prediction.csv``, ``summary.json``, ``prediction.png``) and ``.summary()``.
    """
    sources = (str(model) if _is_path(model) else "", str(data) if _is_path(data) else "")
    argument("data", data, (str, bytes, os.PathLike, TimeSeries), "a time-series file's path or a TimeSeries")
    model = _model(model)
    ts = _read(data)
    check_columns(model, ts, str(data) if not hasattr(data, "names") else "data")
    gaps = input_gaps(model, ts)
    pred = predict(model, ts)
    checks = trust(model, ts, pred)
    scores = score(pred, ts)
    for name, c in checks.items():
        scores[name].update(share_outside=c["share_outside"], share_missed=c["share_missed"])
    return Prediction(pred, {k: c["lower"] for k, c in checks.items()}, {k: c["upper"] for k, c in checks.items()},
                      scores, gaps, tuple(c["warning"] for c in checks.values() if c["warning"]), model, ts, sources)


def errormodel_refit(model: ErrorModel | ErrorModelFit | str | os.PathLike, data: str | os.PathLike | TimeSeries,
                     window_s: float, applied: Mapping[str, str] | Sequence[str] | None = None, *,
                     named_as: str = "applied") -> Refit:
    """Refit a model's coefficients on the last ``window_s`` of new data, guarded against fitting its
    own corrections and never silently worse (:mod:`gatetherm.studies.errormodel.refit`).

    Parameters
    ----------
    model : ErrorModel, ErrorModelFit or path
        From :func:`errormodel_fit` or a ``model.json``.
    data : path or TimeSeries
        The run so far: the model's columns and the measured targets, um.
    window_s : float
        Length of the refit window at the end of the data, s.
    applied : dict or sequence of str, optional
        Target -> column holding the correction the control applied, um (the refit fits
        measured + applied), or the columns in the order of the model's targets; none: the data
        are uncompensated.
    named_as : str
        How messages name ``applied`` (the command: ``--applied``).

    Returns
    -------
    Refit
        Unpacks as ``(model, report)``: the refitted model and per target ``kept``,
        ``current_mae_um``, ``refit_mae_um``, ``samples``; ``.write(out)`` (``out/model.json``)
        and ``.summary()``.
    """
    files = tuple(str(f) for f in (data, model) if _is_path(f))
    window_s = number_argument("window_s", window_s, POSITIVE, "e.g. 86400 (a day)")
    argument("applied", applied, (dict, list, tuple, type(None)), "a dict {target: column}, a column per target or None",
             'e.g. {"x_um": "corr_um"}')
    model = _model(model)
    if applied is not None and not isinstance(applied, dict):
        applied = tuple(applied)
        if len(applied) != len(model.names):
            raise InputError(named_as, f"{len(applied)} columns for {len(model.names)} targets",
                             f"one per target, in the order {', '.join(model.names)}")
        applied = dict(zip(model.names, applied))
    ts = _read(data)
    new, report = refit(model, ts, window_s, applied)
    span = float(ts.time_s[-1] - ts.time_s[0]) if len(ts.time_s) else window_s
    return Refit(new, report, min(window_s, span), files)  # the window used: all of a shorter file


def _same_record(a: TimeSeries, b: TimeSeries, columns) -> bool:
    """Whether ``a`` and ``b`` hold the same samples of ``columns``."""
    return all(c in a.columns and c in b.columns and a[c].shape == b[c].shape
               and np.array_equal(a[c], b[c], equal_nan=True) for c in columns)
