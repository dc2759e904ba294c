"""A fitted thermal-error model in the compensation loop of :mod:`~gatetherm.studies.control.compensator`.

The controller samples the run every ``sample_interval_s`` (resampling linearly), evaluates the
model, forecasts one sample ahead by the paper's extrapolation (33) and drives the piezo with
``-prediction`` every ``update_interval_s``, as for the paper's method; the measured target
column is the uncompensated displacement. For a model of the paper's form, ``correction=True``
runs the paper's own procedure instead (eqs 30-38, on-line factors R_i, R_C from the measured
displacement) with the model's sensors as A, B, C and its coefficients as K_i, K_C.
"""
from __future__ import annotations

import numpy as np

from gatetherm import InputError
from gatetherm.studies.control import actuator as piezo
from gatetherm.studies.control.compensator import (ClosedLoop, CompensatorParams, close_loop, external_prediction,
                                                   predict as paper_predict)
from gatetherm.studies.errormodel.model import ErrorModel, check_columns, predict
from gatetherm.studies.run.timeseries import TimeSeries

LOOP_COLUMNS = ("time_s", "delta_um")


def loop_target(model: ErrorModel, target: str | None) -> str:
    """``target``, or the model's only target if None; InputError if it has none of that name or several."""
    if target is None:
        if len(model.names) != 1:
            raise InputError("--target", f"the model has {len(model.names)} targets",
                             f"name one of {', '.join(model.names)}")
        return model.names[0]
    return model.target(target).target


def replay(model: ErrorModel, ts: TimeSeries, target: str, params: CompensatorParams,
           actuator: piezo.ActuatorParams | None = None, correction: bool = False) -> ClosedLoop:
    """Compensate the measured ``target`` of ``ts`` with the model's prediction.

    Parameters
    ----------
    model : ErrorModel
        A fitted model with a model of ``target``.
    ts : TimeSeries
        ``time_s`` (s), the columns the model reads and ``target`` (um, the uncompensated
        displacement, every sample).
    target : str
        The compensated channel.
    params : CompensatorParams
        Controller sampling and piezo update intervals.
    actuator : ActuatorParams, optional
        Piezo model; None = ideal (stroke = command).
    correction : bool
        Paper-form models only: the paper's on-line correction factors R_i, R_C (eqs 30-38).

    Returns
    -------
    ClosedLoop
        Its ``delta_um`` is the target, ``delta_comp_um`` what the machine would keep, um.
    """
    m = model.target(target)
    check_columns(model, ts)
    if target not in ts:
        raise InputError(f"{getattr(ts, 'source', '') or 'data'}: column {target}",
                         "missing; the compensation loop needs the measured displacement",
                         f"give a file with a {target} column")
    loop_ts = TimeSeries({"time_s": ts.time_s, "delta_um": ts[target]}, dict(ts.metadata))
    if correction:
        if m.form != "paper":
            raise InputError(f"target {target}", f"the on-line correction R needs the paper's form, not {m.form}",
                             "fit with --form paper, or compensate without the correction")
        diff, third = m.terms
        loop_ts = loop_ts.with_columns(theta_A_degC=ts[diff.column], theta_B_degC=ts[diff.other],
                                       theta_C_degC=ts[third.column])
        return close_loop(loop_ts, paper_predict(loop_ts, m.coefficients[0], -m.coefficients[1], params),
                          params, actuator)
    pred = predict(model, ts)[target]
    if np.isnan(pred).any():
        raise InputError(f"{target} prediction", "undefined where a used column has a long gap",
                         "fill the gap or cut the run")
    return close_loop(loop_ts, external_prediction(loop_ts, pred, params, ahead=True, needed=LOOP_COLUMNS),
                      params, actuator)
