"""A chosen sensor set as an errormodel ``ErrorModel`` (``model.json``), and its error on loads
it was not fitted on.

The sensors' columns are ``T_<name>_degC`` (what a case run with the chosen ``[probes]`` writes);
their reference temperature is the case's initial temperature T0 (every load starts at rest,
uniform T0). The coefficients are least squares on every training row (sensor noise included);
``held_out_mae_um`` in the file is the leave-one-load-out error of the training loads.
"""
from __future__ import annotations

import dataclasses

import numpy as np

from gatetherm.studies.errormodel.fit import FitParams
from gatetherm.studies.errormodel.model import ErrorModel, TargetModel, predict, residual_stats
from gatetherm.studies.errormodel.terms import Term, evaluate
from gatetherm.studies.sensors.greedy import Design, Step


def lag_terms(training, names, held, params: FitParams) -> list[Term]:
    """The input lags offered (the errormodel's grid): every input that varies over the
    ``training`` loads' columns, scaled by its largest |value| there; a pump with exponent 1 only."""
    out = []
    for n in names:
        values = np.concatenate([c[n] for c in training])
        scale = float(np.max(np.abs(values)))
        if np.ptp(values) == 0 or scale == 0:
            continue
        exps = (1.0,) if n in held else params.exponents
        out += [Term("input", n, tau_s=tau, exponent=p, scale=scale) for p in exps for tau in params.input_taus_s]
    return out


def lag_columns(terms, loads) -> np.ndarray:
    """The lag terms on every row of ``loads`` (column mappings with ``time_s``), stacked."""
    if not terms:
        return np.zeros((sum(len(c["time_s"]) for c in loads), 0))
    return np.vstack([np.column_stack([evaluate(term, c["time_s"], c, {}) for term in terms]) for c in loads])


def error_model(design: Design, step: Step, columns, terms, targets, T0: float, span_s: float, source: str,
                settings: dict, selection=()) -> ErrorModel:
    """The model of ``step`` (its sensors named by ``columns``, in order) for every target; ``span_s``:
    the length of the training loads, s."""
    fitted = []
    for j, (target, c) in enumerate(zip(targets, design.coefficients(step.sensors, step.lags))):
        X = design.Z[:, design.columns(step.sensors, step.lags[j])]
        regressors = tuple(Term("sensor", col) for col in columns) + tuple(terms[k] for k in step.lags[j])
        fitted.append(TargetModel(target, step.form, regressors, tuple(float(v) for v in c[1:]), float(c[0]),
                                  residual_stats(X @ c - design.Y[:, j]), float(step.cv_mae_um[j]),
                                  tuple(selection)))
    return ErrorModel(tuple(fitted), dict.fromkeys(columns, float(T0)),
                      {"start_s": 0.0, "end_s": float(span_s), "samples": len(design.Y), "source": source},
                      settings=dict(settings))


def held_out_mae(model: ErrorModel, loads, truth) -> dict[str, float]:
    """Per target, the MAE (um) of ``model`` over every sample of ``loads`` (column mappings with the
    sensors' columns and the inputs) against ``truth`` (per load: target -> values)."""
    errs = {m.target: [] for m in model.targets}
    for cols, true in zip(loads, truth):
        pred = predict(model, cols)
        for name in errs:
            errs[name].append(np.abs(pred[name] - true[name]))
    return {k: float(np.mean(np.concatenate(v))) for k, v in errs.items()}


FAMILY = ("form", "max_inputs", "exponents", "input_taus_s", "min_gain")
"""The fields of ``FitParams`` a placement uses (the lags stay on their grid; no differences)."""


def settings_of(params: FitParams, **more) -> dict:
    """The fit settings recorded in ``model.json`` and ``summary.json``."""
    return {**{k: v for k, v in dataclasses.asdict(params).items() if k in FAMILY}, **more}
