"""Compensation and diagnosis of a run or a measurement (:mod:`gatetherm.api`)."""
from __future__ import annotations

import os

from gatetherm.api.run import PATH, Case, Run, _case
from gatetherm.api.boundary import settings_argument
from gatetherm.checks import argument
from gatetherm.studies.control.actuator import ActuatorParams
from gatetherm.studies.run.timeseries import TimeSeries

PUBLIC = ("compensate", "diagnose")  # offered as gt.NAME (gatetherm.api finds them here)


def compensate(series: TimeSeries | Run, case: Case | None = None, method: str = "paper", *,
               actuator: ActuatorParams | str | None = "case", **settings):
    """Compensate a run: predict δ and drive the actuator with the command, never silently worse.

    Before the correction is returned, its benefit is measured on the record's held-out last 30 %
    (what the method fits, fitted on the record before it; docs/errormodel.md): a correction that would
    leave δ there worse than no compensation raises :class:`gatetherm.InputError` naming the figures
    and a better choice, unless ``force=True``, which returns it with a warning.

    Parameters
    ----------
    series : TimeSeries or Run
        The run (θ_A, θ_B, θ_C and δ, the uncompensated thermal displacement; for ``rom`` the
        inputs the reduced model reads): a :class:`Run`, or a measured file read with
        ``gatetherm.studies.run.timeseries.read_timeseries``.
    case : Case, optional
        The model (default: a Run's own case): the paper method's beam-theory or FE K, the mlr
        training run (its own schedule) and the rom reduced model come from it.
    method : str
        ``"paper"``, ``"mlr"`` or ``"rom"``.
    actuator : ActuatorParams, None or "case"
        The actuator in the loop (``"case"``: the case's ``[actuator]``, the frame's piezo; None:
        ideal, the command sent to the control as an offset).
    **settings
        Fields of :class:`gatetherm.studies.control.methods.Settings` (``Ki``, ``Kc``,
        ``k_source``, ``states``, ``params``, ``control``, ``sensors``, ``force``: apply a correction
        that would make δ worse, ``held_out``: the checked fraction, default 0.3, ``resolution_K``: the
        thermocouples' noise that bounds the fits, K); ``rom=`` a reduced model.

    Returns
    -------
    Compensation
        ``.loop`` (the compensated δ, the strokes, the updates), ``.summary`` (bands, updates;
        ``benefit``: ``held_out_um`` and ``uncompensated_um``, the largest |δ| on the held-out span with
        and without it, um, ``verdict`` better, no-gain, worse or unchecked, ``forced``; ``warning`` where forced
        or unchecked; ``warnings``, a list of one-line notes: what the K_i, K_C or mlr fit dropped or bounded
        for the thermocouples' noise, ``resolution_K`` (default 0.05 K), a rom update budget used up
        before the record ends, whose time is ``budget_exhausted_s``, s, a correction worse than none
        earlier in the record (and whether the model's prediction misses δ by more than δ itself), a
        record whose time_s is far from the case's [time] (minutes as seconds); paper and mlr: ``sensor_noise_um``, what
        the thermocouples' noise adds to the prediction, one standard deviation, um).
    """
    from gatetherm.api.compensation import _refuse_unused
    from gatetherm.studies.control.methods import Settings, compensate as methods_compensate
    from gatetherm.studies.run.timeseries import TimeSeries

    argument("case", case, (Case, type(None)), "a Case or None", "make one with gt.load_case(path) or gt.gate_frame()")
    argument("series", series, (Run, TimeSeries), "a Run or a TimeSeries", "gt.run(case), or read_timeseries(path)")
    if isinstance(series, Run):
        case = case or series.case
        series = series.scenario.series({"source": "gatetherm.api.compensate"})
    rom = settings.pop("rom", None)
    chosen = (case.actuator if case is not None else None) if actuator == "case" else actuator
    settings_argument(Settings, settings, "compensate")
    s = Settings(method=method, **settings)
    _refuse_unused(s, rom=rom)
    return methods_compensate(series, case, s, chosen, rom=rom)


def diagnose(case: Case, measured: TimeSeries | str | os.PathLike, **settings):
    """Where ``case`` and a measured run disagree, and the missing pieces that explain it.

    Parameters
    ----------
    case : Case
        The model: a case file's, or the paper frame's.
    measured : TimeSeries or path
        The measurement: every input the case reads, and the channels to compare.
    **settings
        Fields of :class:`gatetherm.studies.diagnosis.discrepancy.Settings` (``train_fraction``,
        ``effects``, ``parameters``, ``sensors``, ``max_pieces``, ``uncertain``: dimensions to try
        besides those the case marks, e.g. ``("mesh.parameters.table_height",)`` …).

    Returns
    -------
    Diagnosis
        ``.verdict``, ``.pieces`` (each with its fitted value), ``.groups`` (what the data cannot
        tell from a named piece, and what would), ``.stand_ins`` (pieces that make the model fit
        but fail a model-form check), ``.dropped`` (hypotheses whose model run the model refused,
        with its one-line reason: dropped, the diagnosis went on), ``.cause`` (what kind of cause
        would fit what stays unexplained), ``.summary()``; docs/diagnosis.md.
    """
    from gatetherm.studies.diagnosis.discrepancy import Settings, diagnose as run_diagnosis
    from gatetherm.studies.run.scenario import span_note
    from gatetherm.studies.run.timeseries import TimeSeries, read_timeseries

    _case(case)
    argument("measured", measured, (TimeSeries, *PATH), "a TimeSeries or a time-series file's path")
    settings_argument(Settings, settings, "diagnose")
    ts = measured if isinstance(measured, TimeSeries) else read_timeseries(measured, required=("time_s",))
    span_note(case, ts, ts.source or "measured", warn=True)
    return run_diagnosis(case, ts, Settings(**settings))
