"""Compensation of a run by one of the methods, on any case: the one place that composes them.

The methods are :mod:`gatetherm.studies.control.method` (one module each):

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

from gatetherm import InputError
from gatetherm.studies.control import benefit as held
from gatetherm.studies.control import method as registry
from gatetherm.studies.control.actuator import ActuatorParams, stroke_range
from gatetherm.studies.control.compensator import NEEDED, ClosedLoop, CompensatorParams, compensate as paper_loop, \
    summarize
from gatetherm.studies.control.method.errormodel import SAME_INSTANT, overlaps  # noqa: F401 - offered here too
from gatetherm.studies.control.observer import ObserverParams
from gatetherm.studies.control.predictive import THERMOCOUPLES, PredictiveParams
from gatetherm.studies.control.regression import RESOLUTION_K, fit_coefficients_noted
from gatetherm.studies.run.case import Case
from gatetherm.studies.run.scenario import ScenarioCache, prepare, span_note
from gatetherm.studies.run.timeseries import TimeSeries

log = logging.getLogger(__name__)

K_SOURCES = ("theory", "fe", "fit")


def __getattr__(name: str):
    """``METHODS``: every method's name, in order (:mod:`gatetherm.studies.control.method`, read when asked:
    a method registered later is in it)."""
    if name == "METHODS":
        return registry.names()
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


@dataclass(frozen=True)
class Settings:
    """How a run is compensated."""

    method: str = "paper"
    """A method's name (:data:`METHODS`)."""
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


def compensated_case(case: Case) -> Case:
    """``case``, where its own run can be compensated by θ (``[time]`` and ``[signals]`` with θ_A, θ_B,
    θ_C and δ), else InputError naming its file."""
    if not case.problem.signals.complete or case.time is None:
        raise InputError(f"{case.source}: signals", "a compensated case needs [time] and [signals] with theta_A, "
                         "theta_B, theta_C and delta", "map them to its probes and a relative displacement, or "
                         "compensate its δ with an error model of its temperatures (gatetherm errormodel fit, then "
                         "compensate --model)")
    return case


def coefficients(case: Case | None, ts: TimeSeries, s: Settings, cache: ScenarioCache | None = None
                 ) -> tuple[float, float, str]:
    """K_i, K_C (um/K) and their source (``explicit`` or a :data:`K_SOURCES` entry)."""
    return coefficients_noted(case, ts, s, cache)[:3]


def coefficients_noted(case, ts, s: Settings, cache) -> tuple[float, float, str, str]:
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
               cache: ScenarioCache | None = None, source: str = "--data", rom_source: str | None = None,
               borrowed: str = "") -> Compensation:
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
    borrowed : str
        Where ``actuator`` is not the machine's own: what it is, said with the commands it clips.

    Returns
    -------
    Compensation
    """
    s = settings
    method = registry.get(s.method)
    held.span_start(ts.time_s, s.held_out)  # a bad fraction fails before any work
    out = method.batch(registry.Job(ts, case, s, actuator, rom, rom_dir, cache, source, rom_source))
    b = out.benefit
    if b is None:
        check_loop, basis = out.checked
        b = held.unchecked(out.loop, s.held_out, basis) if check_loop is None else \
            held.benefit(check_loop, s.held_out, basis)
    model = f"{out.model} of case {case.name!r}" if out.model and case is not None else ""
    span = span_note(case, ts, source) if model else ""  # the case's time scale matters to what it predicts
    length, every = float(ts.time_s[-1] - ts.time_s[0]), s.params.update_interval_s
    if not span and length < 3 * every:  # a thermal record holds hours; a few updates are no benefit to judge
        span = (f"{source}: time_s spans {length:g} s, less than three of the actuator's {every / 60:g}-min update "
                "intervals: a record in minutes? give time_s in seconds (minutes × 60)")
    return _checked(ts, out.loop, b, s, actuator, out.extra, out.label, out.head, out.notes, model, span, borrowed)


def refitted(make, basis: str):
    """(the loop of the benefit check, its basis), or (None, why) where the refit on the shorter record fails."""
    try:
        return make(), basis
    except InputError as err:
        return None, f"{basis} failed: {err}"


def _checked(ts, loop, b: held.Benefit, s: Settings, actuator, extra, label, head, notes=(), model: str = "",
             scale: str = "", borrowed: str = "") -> Compensation:
    """The compensation with its held-out benefit, refused (InputError) where it would make δ worse
    unless forced (:func:`.benefit.guard`); ``scale``: a record's time scale in doubt (said, and the
    likelier cause of a refusal); ``borrowed``: what the actuator is where not the machine's."""
    name = registry.get(s.method).title or s.method
    b = held.as_applied(b, loop)
    better = _better(ts, s, actuator) if b.verdict == "worse" and not s.force else ""
    better = f"{better} ({scale})" if better and scale else better
    notes = (*notes, scale) if scale else notes
    b, warning = held.guard(b, name, s.force, better)
    early = held.over_record(loop, s.params.settle_s, name, model)
    notes = (*notes, early) if early else notes
    if loop.saturated_updates:  # the correction applied (a separate check's loop clips its own)
        notes = (*notes, f"{loop.saturated_updates} of {loop.update_t_s.size} piezo commands outside the reachable "
                 "{:.3g} .. {:.3g} um; clipped".format(*stroke_range(actuator)) + (f": {borrowed}" if borrowed else ""))
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
