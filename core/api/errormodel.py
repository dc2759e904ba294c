"""Thermal-error models of measured channels (:mod:`gatetherm.api`; docs/errormodel.md): fit on one
run or several, predict with a 90 % interval and a drift check, refit as data arrive."""
from __future__ import annotations

import os
from dataclasses import dataclass, field

from gatetherm.checks import POSITIVE, argument, number_argument
from gatetherm.studies.errormodel.fit import FitParams, fit_error_model, fraction_span
from gatetherm.studies.errormodel.model import ErrorModel, check_columns, input_gaps, load_model, predict, score
from gatetherm.studies.errormodel.trust import trust
from gatetherm.studies.errormodel.refit import refit
from gatetherm.studies.run.timeseries import TimeSeries, read_timeseries


@dataclass(frozen=True)
class Prediction:
    """What :func:`errormodel_predict` returns: predictions with their 90 % intervals, scores and drift warnings."""

    predicted: dict
    """Target -> predicted displacement per sample, um."""
    lower: dict
    """Target -> lower end of the 90 % interval per sample, um."""
    upper: dict
    """Target -> upper end of the 90 % interval per sample, um."""
    scores: dict
    """Per target :func:`~gatetherm.studies.errormodel.model.score` (MAE, RMS where measured, um)
    with ``share_outside`` (samples beyond the fitted ranges) and ``share_missed`` (measured
    samples outside the interval)."""
    gaps: dict = field(default_factory=dict)
    """Per column with gaps its :class:`~gatetherm.studies.errormodel.terms.GapReport`."""
    warnings: tuple[str, ...] = ()
    """One line per target that no longer behaves like the fitting data."""


def _read(data, required=("time_s",)):
    argument("data", data, (str, bytes, os.PathLike, TimeSeries), "a time-series file's path or a TimeSeries")
    return read_timeseries(data, required=required) if isinstance(data, (str, bytes)) or hasattr(data, "__fspath__") \
        else data


def _model_argument(model):
    argument("model", model, (ErrorModel, str, os.PathLike), "an ErrorModel or a model.json's path",
             "from errormodel_fit, or 'gatetherm errormodel fit'")


ROBUST = FitParams(drift=True, noisy_cv=True)
"""The API's and the command's default fit: blocked cross-validation within a run (forward chaining,
``cv="chain"``, measured no better on FL_THERMAL: docs/errormodel.md), leave one run out with three
or more runs, a drift term offered with several runs, candidates scored by their expected held-out error
on readings with the sensors' noise."""


def errormodel_fit(data, targets, candidates=None, inputs=(), params: FitParams = ROBUST,
                   span: tuple[float, float] = (0.0, 1.0)) -> ErrorModel:
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

    Returns
    -------
    ErrorModel
        Save it with ``gatetherm.studies.errormodel.model.save_model``.
    """
    runs = list(data) if isinstance(data, (list, tuple)) else [data]
    for i, r in enumerate(runs):
        argument(f"data[{i}]" if isinstance(data, (list, tuple)) else "data", r, (str, os.PathLike, TimeSeries),
                 "a time-series file's path or a TimeSeries", "e.g. errormodel_fit('run.csv', ['delta_um'])")
    for name, names in (("targets", targets), ("candidates", candidates), ("inputs", inputs)):
        if isinstance(names, str) or not (names is None and name == "candidates" or isinstance(names, (list, tuple))):
            raise TypeError(f"{name}: got {type(names).__name__} {str(names)[:40]!r}, expected a list of column "
                            f"names; e.g. {name}=['delta_um']")
    required = ("time_s", *targets, *(candidates or ()), *inputs)
    series = [_read(r, required) for r in runs]
    spans = [fraction_span(ts["time_s"], *span) for ts in series]
    source = ", ".join(str(r) for r in runs if not hasattr(r, "names"))
    return fit_error_model(series, targets, candidates, inputs, params, spans, source=source)


def errormodel_predict(model, data) -> Prediction:
    """Apply a model with its 90 % interval and drift check.

    Parameters
    ----------
    model : ErrorModel or path
        From :func:`errormodel_fit` or a ``model.json``.
    data : path or TimeSeries
        The columns the model reads; targets where measured are scored.

    Returns
    -------
    Prediction
        Predictions and intervals (um), scores, filled gaps and the drift warnings.
    """
    _model_argument(model)
    ts = _read(data)
    model = load_model(model) if not isinstance(model, ErrorModel) else model
    check_columns(model, ts, str(data) if not hasattr(data, "names") else "data")
    gaps = input_gaps(model, ts)
    pred = predict(model, ts)
    checks = trust(model, ts, pred)
    scores = score(pred, ts)
    for name, c in checks.items():
        scores[name].update(share_outside=c["share_outside"], share_missed=c["share_missed"])
    return Prediction(pred, {k: c["lower"] for k, c in checks.items()}, {k: c["upper"] for k, c in checks.items()},
                      scores, gaps, tuple(c["warning"] for c in checks.values() if c["warning"]))


def errormodel_refit(model, data, window_s: float, applied: dict[str, str] | None = None):
    """Refit a model's coefficients on the last ``window_s`` of new data, guarded against fitting its
    own corrections and never silently worse (:mod:`gatetherm.studies.errormodel.refit`).

    Parameters
    ----------
    model : ErrorModel or path
    data : path or TimeSeries
        The run so far: the model's columns and the measured targets, um.
    window_s : float
        Length of the refit window at the end of the data, s.
    applied : dict, optional
        Target -> column holding the correction the control applied, um (the refit fits
        measured + applied); none: the data are uncompensated.

    Returns
    -------
    (ErrorModel, dict)
        The refitted model and per target ``kept``, ``current_mae_um``, ``refit_mae_um``, ``samples``.
    """
    _model_argument(model)
    window_s = number_argument("window_s", window_s, POSITIVE, "e.g. 86400 (a day)")
    argument("applied", applied, (dict, type(None)), "a dict {target: column} or None", 'e.g. {"x_um": "corr_um"}')
    model = load_model(model) if not isinstance(model, ErrorModel) else model
    return refit(model, _read(data), window_s, applied)
