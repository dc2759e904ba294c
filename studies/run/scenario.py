"""The one scenario path: apply effects → build (or reuse) the model → run → observe (the
observation-side effects, then the case's sensor faults).

Every command, study and API function runs a :class:`~gatetherm.studies.run.case.Case`
through :func:`run_scenario` (or, when it needs the assembled model without a run,
:func:`prepare`), so that effects act the same everywhere. What drives a run is a
:class:`~gatetherm.studies.run.schedules.Schedule` (the case's own by default); a case
without a transient is solved once, in steady state.
"""
from __future__ import annotations

import dataclasses
import logging
import time
from collections import OrderedDict
from dataclasses import dataclass
from typing import Callable, Mapping

import numpy as np

from gatetherm import InputError
from gatetherm.geometry.measure import region_volume
from gatetherm.solvers.effects import ActiveEffects, apply_effects, checked, resolve
from gatetherm.solvers.heat import HeatSolver, environment
from gatetherm.solvers.model import Model, build
from gatetherm.solvers.sensors import apply_faults
from gatetherm.studies.run.case import Case
from gatetherm.studies.run.schedules import STEADY, Schedule, file_schedule, series_schedule  # noqa: F401
from gatetherm.studies.run.simulate import RunResult, check_temperatures, loss_columns, output_columns, run_model
from gatetherm.studies.run.timeseries import TimeSeries

log = logging.getLogger(__name__)


def active(case: Case, effects: Mapping[str, float] | None = None) -> ActiveEffects:
    """The case's effects, then ``effects`` (these win), resolved against its names; each of
    ``effects`` checked against its kind (InputError naming ``effects[KEY]``)."""
    for key, value in dict(effects or {}).items():
        where = f"effects[{key!r}]"
        checked(resolve(key, case.targets, where), value, where)
    return ActiveEffects({**case.effects, **dict(effects or {})}, case.targets)


def effective(case: Case, eff: ActiveEffects) -> Case:
    """``case`` with the model-side effects of ``eff`` in its problem."""
    thickness = case.problem.thickness

    def volume(region: str) -> float:
        return region_volume(case.mesh, region, thickness.get(region, 1.0))

    problem = apply_effects(case.problem, eff, volume)
    return case if problem is case.problem else dataclasses.replace(case, problem=problem)


def measured_schedule(case: Case, ts: TimeSeries, label: str = "measured inputs") -> Schedule:
    """The inputs a case reads, from a series (a measured run), sampled at its own times."""
    return series_schedule(ts, sorted(case.inputs()), case.held(), case.defaults, label)


SPAN_RATIO = 20.0
"""A record spanning this many times less (or 2.5 × this more) than its case's ``[time] end``
is taken for one whose ``time_s`` is not in seconds (minutes: 60 ×; milliseconds: 1000 ×)."""


def span_note(case: Case, ts: TimeSeries, label: str, warn: bool = False) -> str:
    """A warning where a record's span is far from its case's ``[time] end`` (``time_s`` written in
    minutes, hours or milliseconds), else ''; logged with ``warn``."""
    span = float(ts.time_s[-1] - ts.time_s[0]) if len(ts.time_s) else 0.0
    if case.time is None or span <= 0.0:
        return ""
    end = case.time.end
    if span * SPAN_RATIO <= end:
        how = f"1/{end / span:.3g} of"
        fix = "a record in minutes? give time_s in seconds (minutes × 60)"
    elif span >= 2.5 * SPAN_RATIO * end:
        how = f"{span / end:.3g} ×"
        fix = "a record in milliseconds? give time_s in seconds (ms / 1000)"
    else:
        return ""
    note = f"{label}: time_s spans {span:g} s, {how} the [time] end of case {case.name!r}, {end:g} s; {fix}"
    if warn:
        log.warning("%s", note)
    return note


class ScenarioCache:
    """Assembled models with their heat solvers (factorisations), and finished runs, by what
    they depend on; the least recently used are dropped beyond ``size``. A study that runs one
    case many times (a diagnosis) passes one cache to every :func:`run_scenario`."""

    def __init__(self, size: int = 3):
        self.size = size
        self.runs = 0
        """Model runs made (cache misses)."""
        self._models: OrderedDict = OrderedDict()
        self._results: OrderedDict = OrderedDict()

    def _lru(self, store: OrderedDict, key, make):
        if key in store:
            store.move_to_end(key)
            return store[key]
        value = store[key] = make()
        while len(store) > self.size:
            store.popitem(last=False)
        return value

    def model(self, case: Case) -> tuple[Model, HeatSolver | None]:
        return self._lru(self._models, (repr(case.problem), id(case.mesh)), lambda: _build(case))

    def result(self, key, make: Callable[[], tuple[RunResult, Model]], fresh: bool = False
               ) -> tuple[RunResult, Model]:
        """The run of ``key``, made where not kept (``fresh``: made in any case, and kept)."""
        def counted():
            self.runs += 1
            return make()
        if fresh:
            self._results.pop(key, None)
        return self._lru(self._results, key, counted)


@dataclass(frozen=True)
class Prepared:
    """A model ready to run: effects applied and assembled."""

    model: Model
    solver: HeatSolver | None
    effects: ActiveEffects
    """The case's effects, then the caller's."""


def prepare(case: Case, effects: Mapping[str, float] | None = None, *, cache: ScenarioCache | None = None) -> Prepared:
    """Apply the effects of ``case`` and ``effects`` (these win) and build or reuse the model."""
    eff = active(case, effects)
    model, solver = assembled(effective(case, eff), cache)
    return Prepared(model, solver, eff)


def assembled(target: Case, cache: ScenarioCache | None = None) -> tuple[Model, HeatSolver | None]:
    """The model of ``target`` (its effects already in its problem: :func:`effective`) and its heat
    solver, from ``cache`` where it holds them."""
    return _build(target) if cache is None else cache.model(target)


def _build(case: Case) -> tuple[Model, HeatSolver | None]:
    """The model of a case, with a heat solver of its own."""
    t0 = time.perf_counter()
    model = build(case.problem, case.mesh, case.parameters)
    log.debug("built %s in %.2f s", case.name, time.perf_counter() - t0)
    return model, HeatSolver(model.heat) if model.heat is not None else None


def _once(p: Prepared, schedule: Schedule) -> RunResult:
    """A steady problem: the outputs of its one state at t = 0; or one without a heat solve
    (a prescribed temperature, or none): its outputs at every time of the schedule (the
    loads' values change), states kept at t = 0 and at the end."""
    t0 = time.perf_counter()
    model = p.model
    times = schedule.times if model.heat is None else schedule.times[:1]
    envs = {float(t): environment(schedule.drive, float(t)) for t in times}
    if model.heat is None:
        rows = model.static(list(envs.values()))
        keys = tuple(rows[0])
        Y, states = np.array([[r[k] for k in keys] for r in rows]), [(float(t), None) for t in {times[0], times[-1]}]
    else:
        states = [(0.0, p.solver.steady(envs[0.0]))]
        check_temperatures(states[0][1], 0.0)
        keys, Y = model.readout.keys, model.read(states[0][1], envs[0.0])[None, :]
    drive = schedule.drive
    cols = {"time_s": np.asarray(times, float), **{k: np.array([drive(float(t))[k] for t in times])
                                                   for k in drive(0.0)}}
    cols.update(loss_columns(model.problem, cols))
    cols.update(output_columns(model.problem, keys, Y))
    return RunResult(cols, sorted(states, key=lambda s: s[0]), time.perf_counter() - t0, envs)


@dataclass(frozen=True)
class ScenarioRun:
    """A finished scenario."""

    columns: dict[str, np.ndarray]
    """What the sensors report, in the data format (observation-side effects applied)."""
    result: RunResult
    """The model's own columns, kept states and march time."""
    model: Model
    effects: ActiveEffects
    schedule: Schedule
    seconds: float
    """Wall time of prepare and run, s."""

    def series(self, metadata: dict[str, str]) -> TimeSeries:
        return TimeSeries(self.columns, metadata)


def run_scenario(case: Case, schedule: Schedule | None = None, effects: Mapping[str, float] | None = None, *,
                 cache: ScenarioCache | None = None, keep_times=(), on_step: Callable[[int, int], None] | None = None,
                 U0: np.ndarray | None = None, solve_at=(), solve_first_peak: bool = False,
                 on_state: Callable | None = None) -> ScenarioRun:
    """Run ``case`` (its effects, plus ``effects``) through ``schedule`` (default: its own); keep
    full states at ``keep_times`` (their displacement fields at ``solve_at``, and with
    ``solve_first_peak`` δ's first peak's, solved during the march where it can:
    :func:`~gatetherm.studies.run.simulate.run_model`; ``on_state`` as there). With a ``cache`` the model, its
    factorisations and (for a plain run from the initial state) the run itself are reused; with ``on_state``
    the run is made (its states are wanted) and kept."""
    t0 = time.perf_counter()
    schedule = case.schedule if schedule is None else schedule
    eff = active(case, effects)
    target = effective(case, eff)

    def run(p: Prepared) -> RunResult:
        try:
            if p.model.heat is None or len(schedule.times) == 1:
                return _once(p, schedule)
            return run_model(p.model, schedule.drive, schedule.times, keep_times, on_step, U0=U0, solver=p.solver,
                             solve_at=solve_at, solve_first_peak=solve_first_peak, on_state=on_state)
        except InputError as err:  # a temperature out of range, a film that does not settle: named with the file
            raise (err.at(case.source) if err.field == "temperature" or err.field.startswith("film of ") else err) \
                from None

    if cache is not None and U0 is None and not keep_times:
        key = (repr(target.problem), id(case.mesh), schedule.label, schedule.times.tobytes())

        def make() -> tuple[RunResult, Model]:
            model, solver = cache.model(target)
            return run(Prepared(model, solver, eff)), model

        result, model = cache.result(key, make, fresh=on_state is not None)  # a kept run: observed again
    else:
        model, solver = assembled(target, cache)
        result = run(Prepared(model, solver, eff))
    cols = apply_faults(eff.observe(result.columns, target.problem), case.sensors)
    if schedule.every > 1:  # every output interval, and the end of the run
        n = len(next(iter(cols.values())))
        cols = {k: v[np.unique(np.r_[0:n:schedule.every, n - 1])] for k, v in cols.items()}
    return ScenarioRun(cols, result, model, eff, schedule, time.perf_counter() - t0)


__all__ = ["STEADY", "Prepared", "ScenarioCache", "ScenarioRun", "Schedule", "active", "assembled", "effective",
           "file_schedule", "measured_schedule", "prepare", "run_scenario", "span_note"]
