"""Compensation of a run by one of three methods, on any case: the one place that composes them.

* ``paper``: the paper's adaptive predictor (:mod:`.compensator`) with K_i, K_C given, from the
  beam theory (``theory``, a model with the paper frame's beam parameters), from FE load cases
  (``fe``, ditto) or fitted on the run itself (``fit``);
* ``mlr``: a static regression of δ on θ_A, θ_B, θ_C fitted on the case's own schedule, forecasting
  one sample ahead from the extrapolated temperatures (the paper's latency);
* ``rom``: a Kalman filter on the case's reduced model and predictive control (:mod:`.predictive`);
* ``errormodel``: a thermal-error model fitted on measured data (``gatetherm errormodel fit``,
  :mod:`gatetherm.studies.errormodel`), replayed on one of its targets.

The actuator is the case's (``[actuator]``; the paper frame's piezo), or ideal (None): the
correction sent to the machine's control as an offset.

Before a correction is returned, its benefit on the record's held-out last 30 % is measured
(:mod:`.benefit`): one that would leave δ worse than no compensation is refused with one line
naming a better choice, or, with ``force``, applied with a warning in the summary.

Never silently unsure: what a fit on the record dropped or bounded for the sensors' noise
(:mod:`.regression`: K_i, K_C of ``--k-source fit``, the mlr regression) and a rom update budget
used up before the record ends are each one line in the summary's ``warnings`` (a list; the CLI
prints each as ``warning: ...``).
"""
from __future__ import annotations

import dataclasses
import logging
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from gatetherm import InputError
from gatetherm.solvers.expr import Value
from gatetherm.studies.control import benefit as held
from gatetherm.studies.control.actuator import ActuatorParams
from gatetherm.studies.control.compensator import (NEEDED, ClosedLoop, CompensatorParams, close_loop, compensate as
                                                   paper_loop, external_prediction, summarize)
from gatetherm.studies.control.observer import ObserverParams
from gatetherm.studies.control.predictive import THERMOCOUPLES, PredictiveParams, budget_warning, rom_prediction
from gatetherm.studies.control.regression import (RESOLUTION_K, THETAS, fit_coefficients_noted, fit_regression,
                                                  prediction_noise_um, regression_forecast)
from gatetherm.studies.run.case import Case
from gatetherm.studies.run.scenario import ScenarioCache, prepare, run_scenario
from gatetherm.studies.run.timeseries import TimeSeries, validate_complete

log = logging.getLogger(__name__)

METHODS = ("paper", "mlr", "rom", "errormodel")
K_SOURCES = ("theory", "fe", "fit")


@dataclass(frozen=True)
class Settings:
    """How a run is compensated."""

    method: str = "paper"
    """"paper", "mlr" or "rom"."""
    params: CompensatorParams = CompensatorParams()
    Ki: float | None = None
    """K_i, um/K (paper; with Kc), else from :attr:`k_source`."""
    Kc: float | None = None
    k_source: str | None = None
    """"theory", "fe" or "fit" (default: theory where the case has beam parameters, else fit)."""
    states: int = 30
    """rom: states of the reduced model built."""
    control: PredictiveParams = PredictiveParams()
    observer: ObserverParams = ObserverParams()
    sensors: tuple[str, ...] = THERMOCOUPLES
    """rom: temperature columns the observer reads."""
    model: object = None
    """errormodel: the fitted :class:`~gatetherm.studies.errormodel.model.ErrorModel`."""
    target: str | None = None
    """errormodel: the compensated channel (default: the model's only one)."""
    correction: bool = False
    """errormodel of the paper's form: the on-line R_i, R_C of eqs 30–38."""
    force: bool = False
    """Apply a correction that would leave δ worse on the held-out span (with a warning) instead of refusing it."""
    held_out: float = held.HELD_OUT
    """Fraction of the record, at its end, on which the benefit is checked, dimensionless."""
    resolution_K: float = RESOLUTION_K
    """Thermocouple resolution (noise standard deviation), K: bounds the K_i, K_C and mlr fits
    (:mod:`.regression`)."""


@dataclass(frozen=True)
class Compensation:
    """A compensated run."""

    loop: ClosedLoop
    summary: dict
    label: str
    """What was done, for metadata: method, K or model, update rule."""
    head: str
    """One line for the terminal."""
    extra: dict = field(default_factory=dict)


def coefficients(case: Case | None, ts: TimeSeries, s: Settings, cache: ScenarioCache | None = None
                 ) -> tuple[float, float, str]:
    """K_i, K_C (um/K) and their source (``explicit`` or a :data:`K_SOURCES` entry)."""
    return _coefficients(case, ts, s, cache)[:3]


def _coefficients(case, ts, s: Settings, cache) -> tuple[float, float, str, str]:
    """:func:`coefficients` and the fit's warning ('' unless fitted and something was dropped or bounded)."""
    if s.Ki is not None or s.Kc is not None:
        if s.Ki is None or s.Kc is None or s.k_source:
            raise InputError("--Ki/--Kc", "give both, and not together with --k-source",
                             "e.g. --Ki 2.1 --Kc 0.8, or --k-source fit")
        if not (abs(s.Ki) <= 1e6 and abs(s.Kc) <= 1e6):  # finite and below 1 m/K (NaN fails too)
            raise InputError("--Ki/--Kc", f"got {s.Ki:g}, {s.Kc:g}, must be within ±1e+06 um/K", "e.g. --Ki 2.1 --Kc 0.8")
        return s.Ki, s.Kc, "explicit", ""
    # the paper frame's origin offers its beam theory and FE load cases (gatetherm.frame.case.FrameOrigin)
    beam = getattr(case.origin, "coefficients", None) if case is not None and case.parameters is not None else None
    source = s.k_source or ("theory" if beam else "fit")
    if source == "fit":
        ki, kc, note = fit_coefficients_noted(ts, s.resolution_K)
        return ki, kc, source, note
    if not beam:
        raise InputError("--k-source", f"'{source}' needs the paper frame's beam model; this case has none",
                         "use --k-source fit or --Ki/--Kc")
    return (*beam(case, source, lambda: prepare(case, cache=cache).model), source, "")


def compensate(ts: TimeSeries, case: Case | None = None, settings: Settings = Settings(),
               actuator: ActuatorParams | None = None, *, rom=None, rom_dir: Path | None = None,
               cache: ScenarioCache | None = None, source: str = "--data", rom_source: str | None = None
               ) -> Compensation:
    """Compensate the series ``ts`` (δ the uncompensated thermal displacement).

    Parameters
    ----------
    ts : TimeSeries
        The run: θ_A, θ_B, θ_C and δ (and for ``rom`` the inputs the reduced model reads).
    case : Case, optional
        The model: the K sources ``theory``/``fe``, the ``mlr`` training run (its own schedule) and the
        ``rom`` reduced model come from it.
    settings : Settings
    actuator : ActuatorParams, optional
        None: ideal (the command is applied exactly).
    rom : ReducedModel, optional
        ``rom``: this reduced model (read from ``rom_source``) instead of one built from ``case``
        (kept in ``rom_dir``).
    source : str
        What the series is, for messages (a file name).

    Returns
    -------
    Compensation
    """
    s, params = settings, settings.params
    if s.method not in METHODS:
        raise InputError("--method", f"unknown method {s.method!r}", f"choose from {', '.join(METHODS)}")
    held.span_start(ts.time_s, s.held_out)  # a bad fraction fails before any work
    every = f"update every {params.update_interval_s / 60:g} min"
    checked = None  # the loop of the benefit check where it differs from the applied one, and its basis
    if s.method == "errormodel":
        from gatetherm.studies.errormodel.replay import loop_target, replay

        if s.model is None:
            raise InputError("--model", "the errormodel method needs a fitted model", "give --model MODEL.json")
        target = loop_target(s.model, s.target)
        loop = replay(s.model, ts, target, params, actuator, s.correction)
        extra = {"target": target, "correction": s.correction}
        label = head = f"error model, {target} ({s.model.target(target).form} form" \
            f"{', on-line R' if s.correction else ''}), {every}"
        checked = _model_check(s.model, loop, s.held_out, source)
        return _checked(ts, loop, checked, s, actuator, extra, label, head)
    validate_complete(ts, NEEDED)
    if s.method == "paper":
        ki, kc, source, note = _coefficients(case, ts, s, cache)
        notes = [note] if note else []
        loop = paper_loop(ts, ki, kc, params, actuator)
        if source == "fit":
            before = held.before(ts, s.held_out)
            checked = _refitted(lambda: paper_loop(ts, *fit_coefficients_noted(before, s.resolution_K)[:2], params,
                                                   actuator),
                                f"K_i, K_C fitted on the first {100 * (1 - s.held_out):.0f} % of the record")
        else:
            checked = loop, f"as applied (K_i, K_C from {source}, nothing fitted on the record)"
        noise = prediction_noise_um((ki, kc), s.resolution_K, difference_first=True)
        extra = {"Ki_um_per_K": ki, "Kc_um_per_K": kc, "k_source": source, "sensor_noise_um": noise}
        label = f"K_i {ki:.6g} um/K, K_C {kc:.6g} um/K ({source}), {every}"
        head = f"K_i {ki:.4g}, K_C {kc:.4g} um/K ({source}; {s.resolution_K:g}-K sensor noise adds ±{noise:.2g} um)"
    elif s.method == "mlr":
        if case is None:
            raise InputError("--method mlr", "needs a model to train on", "give --case, or the frame's --config/--dim")
        train = run_scenario(case, cache=cache).series({})
        mlr = fit_regression(train, THETAS, s.resolution_K)
        notes = [f"{mlr.warning} (on the model's own run, {case.schedule.label})"] if mlr.warning else []
        loop = close_loop(ts, external_prediction(ts, regression_forecast(mlr, ts), params), params, actuator)
        checked = _refitted(lambda: close_loop(ts, external_prediction(ts, regression_forecast(
            fit_regression(held.before(train, s.held_out), THETAS, s.resolution_K), ts), params), params, actuator),
            f"regression fitted on the first {100 * (1 - s.held_out):.0f} % of the model's run")
        noise = prediction_noise_um(mlr.coefficients, s.resolution_K)
        extra = {"regression": {"intercept_um": mlr.intercept_um, **dict(zip(mlr.features, mlr.coefficients))},
                 "sensor_noise_um": noise}
        label = f"regression on theta_A, theta_B, theta_C ({case.schedule.label} of the model), 1-sample forecast, " \
            + every
        head = f"mlr ({label}; {s.resolution_K:g}-K sensor noise adds ±{noise:.2g} um)"
    else:
        loop, extra, label = _rom_loop(ts, case, s, actuator, rom, rom_dir, cache, source, rom_source)
        notes = [extra.pop("budget_warning")] if extra.get("budget_warning") else []
        head = f"rom ({label})"
        checked = loop, "as applied (the reduced model and its causal Kalman filter fit nothing on the record)"
    check_loop, basis = checked
    b = held.unchecked(loop, s.held_out, basis) if check_loop is None else held.benefit(check_loop, s.held_out, basis)
    return _checked(ts, loop, b, s, actuator, extra, label, head, notes)


def _refitted(make, basis: str):
    """(the loop of the benefit check, its basis), or (None, why) where the refit on the shorter record fails."""
    try:
        return make(), basis
    except InputError as err:
        return None, f"{basis} failed: {err}"


def _checked(ts, loop, b: held.Benefit, s: Settings, actuator, extra, label, head, notes=()) -> Compensation:
    """The compensation with its held-out benefit, refused (InputError) where it would make δ worse
    unless forced (:func:`.benefit.guard`)."""
    name = "error model" if s.method == "errormodel" else s.method
    better = _better(ts, s, actuator) if b.verdict == "worse" and not s.force else ""
    b, warning = held.guard(b, name, s.force, better)
    summary = {**summarize(loop, s.params.settle_s), "method": s.method, **extra,
               "resampled": loop.prediction.resampled, "compensator": dataclasses.asdict(s.params),
               "actuator": dataclasses.asdict(actuator) if actuator else None, "benefit": b.as_dict(),
               **({"warning": warning} if warning else {}), "warnings": list(notes)}
    return Compensation(loop, summary, label, head, extra)


def _better(ts, s: Settings, actuator) -> str:
    """The better choice named by a refusal: the paper method with K fitted on the record before the
    held-out span where that beats no compensation there, else no compensation."""
    if s.method != "paper" and all(n in ts for n in NEEDED):
        try:
            loop = paper_loop(ts, *fit_coefficients_noted(held.before(ts, s.held_out), s.resolution_K)[:2], s.params,
                              actuator)
        except InputError:
            loop = None
        if loop is not None:
            b = held.benefit(loop, s.held_out, "")
            if b.verdict == "better":
                return f"use --method paper --k-source fit (δ {b.held_out_um:.2f} um there)"
    return "leave the axis uncompensated"


def _model_check(model, loop, fraction: float, source: str) -> held.Benefit:
    """An error model's benefit: as applied, unless it was fitted on this record into the held-out span."""
    fitted_on = str(model.fit_span.get("source", ""))
    start = held.span_start(loop.t_s, fraction)
    same = bool(fitted_on) and _same_file(fitted_on, source)
    if same and overlaps(float(model.fit_span.get("end_s", -np.inf)), start, loop.t_s):
        return held.unchecked(loop, fraction, f"the error model was fitted on this record ({fitted_on}) into its "
                              f"last {fraction * 100:.0f} %; refit it with --fit-span 0:{1 - fraction:g}")
    if same:
        return held.benefit(loop, fraction, f"as applied (the error model was fitted on this record before its last "
                            f"{fraction * 100:.0f} %)")
    return held.benefit(loop, fraction, f"as applied (the error model was fitted on {fitted_on or 'other data'})")


#: Fraction of a sample interval within which a fit's end and the held-out start count as the same instant.
SAME_INSTANT = 0.01


def overlaps(end_s: float, start_s: float, t_s) -> bool:
    """True if a fit ending at ``end_s`` reaches into a held-out span starting at ``start_s`` (s) by more
    than :data:`SAME_INSTANT` of the record's median sample interval: a fit to ``--fit-span 0:0.7``
    ends where the last 30 % starts, up to round-off (15120 s against 15119.999999999998 s)."""
    t = np.asarray(t_s, float)
    step = float(np.median(np.diff(t))) if t.size > 1 else 0.0
    return end_s > start_s + SAME_INSTANT * step


def _same_file(a: str, b: str) -> bool:
    try:
        return Path(a).resolve() == Path(b).resolve()
    except (OSError, ValueError):
        return a == b


def _rom_loop(ts, case, s: Settings, actuator, rom, rom_dir, cache, source: str, where: str | None):
    """The rom method's closed loop, its summary entries and a label."""
    from gatetherm.studies.run.reduce import build_rom, cached_rom

    if not 2 <= s.states <= 200:
        raise InputError("--states", f"{s.states} is outside 2..200", "e.g. --states 30")
    if not s.sensors:
        raise InputError("--sensors", "no column named", "e.g. --sensors theta_A_degC,theta_B_degC")
    control = dataclasses.replace(s.control, interval_s=s.params.update_interval_s)
    if rom is None:
        if case is None:
            raise InputError("--method rom", "needs a reduced model", "give --rom FILE or a model (--case)")
        if rom_dir is not None:
            rom, where = cached_rom(case, s.states, rom_dir, cache), str(Path(rom_dir) / "rom.npz")
        else:
            rom = build_rom(case, s.states, cache).rom
    missing = [n for n in ("delta_um", *s.sensors) if n not in rom.outputs]
    if missing:
        raise InputError(f"{where or 'reduced model'}: outputs", f"no {missing[0]!r}",
                         f"its outputs: {', '.join(rom.outputs[:12])}{' …' if len(rom.outputs) > 12 else ''}")
    read = set().union(*(Value.of(u.text).names() for u in rom.inputs), *(Value.of(p).names() for p in rom.pumps))
    lacking = sorted(read - {"t"} - set(ts.names) - set(rom.defaults))
    if lacking:
        raise InputError(f"{source}, column {lacking[0]}", f"missing: the reduced model {where or ''} reads it",
                         "record it, or give a reduced model of the inputs recorded")
    pr, cmds = rom_prediction(ts, rom, s.params, control, s.observer, s.sensors)
    loop = close_loop(ts, pr, s.params, actuator)
    extra = {"rom": where, "rom_states": rom.states, "sensors": list(s.sensors), "threshold_um": cmds.threshold_um,
             "predictive": dataclasses.asdict(control), "observer": dataclasses.asdict(s.observer),
             "budget_exhausted_s": None}
    if cmds.exhausted_at is not None:
        extra["budget_exhausted_s"] = float(pr.t_s[cmds.exhausted_at])
        extra["budget_warning"] = budget_warning(loop.t_s, loop.delta_comp_um, extra["budget_exhausted_s"],
                                                 control.max_updates)
    how = f"threshold {cmds.threshold_um:.2f} um" if cmds.threshold_um is not None else \
        f"every {s.params.update_interval_s / 60:g} min"
    return loop, extra, f"reduced model ({rom.states} states), Kalman filter on {', '.join(s.sensors)}, {how}"
