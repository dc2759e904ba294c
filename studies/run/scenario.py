"""The one scenario path: apply effects → build (or reuse) the model → run → observe
(the catalogue's observation-side effects, then the model's sensor faults, ``sensors``).

Every command and study runs a model through :func:`run_scenario` (or, when it needs
the assembled model without a run, :func:`prepare`), so that the effects of a model
file act the same everywhere. The model is the paper's frame (a model file's
:class:`~gatetherm.studies.run.config.Config`) or any frame of a case file
(:class:`~gatetherm.studies.run.case.Case`). What drives a run is a :class:`Schedule`:
a paper condition, a schedule file, the inputs of a measured series, or a case's time
settings; a case without them is solved once, in steady state.
"""
from __future__ import annotations

import logging
import time
from collections import OrderedDict
from dataclasses import dataclass
from typing import Callable, Mapping

import numpy as np

from gatetherm.geometry.mesh import FrameMesh
from gatetherm import InputError
from gatetherm.solvers.effects import CATALOGUE, ActiveEffects, apply_effects, drive_effects
from gatetherm.solvers.frame import ModelConfig, build_model
from gatetherm.solvers.heat import Drive, HeatSolver, environment
from gatetherm.solvers.model import Model, build
from gatetherm.solvers.problem import inputs
from gatetherm.studies.run.case import Case
from gatetherm.solvers.sensors import apply_faults
from gatetherm.studies.run.conditions import TableDrive, condition, condition_drive, filled, table_drive
from gatetherm.studies.run.config import Config
from gatetherm.studies.run.simulate import RunResult, check_temperatures, output_columns, run_model, sample_times
from gatetherm.studies.run.timeseries import INPUT_COLUMNS, TimeSeries, check_steps, read_timeseries

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class Schedule:
    """What drives a run and when it is sampled."""

    drive: Drive
    """Model inputs (supply oil, pump, room) as a function of time, s from the start."""
    times: np.ndarray
    """Sample times, s from the start (the first is 0)."""
    label: str
    """What the schedule is, for file metadata and reports."""
    condition: int | None = None
    """The paper's condition number, if it is one."""
    every: int = 1
    """Report every ``every``-th step (the output interval of a case whose step is smaller)."""


def condition_schedule(number: int, cfg: Config, step_s: float = 60.0) -> Schedule:
    """The paper's condition ``number`` driven by ``cfg``'s supply unit, sampled every ``step_s``."""
    cond = condition(number)
    return Schedule(condition_drive(cond, cfg.supply), sample_times(cond.duration, step_s),
                    f"condition {number}: {cond.name}", number)


def series_schedule(ts: TimeSeries, cfg: Config, label: str) -> Schedule:
    """The inputs of a series (oil, pump, room if recorded), sampled at its own times."""
    t = np.asarray(ts.time_s - ts.time_s[0], dtype=float)
    amb = ts["ambient_degC"] if "ambient_degC" in ts else None
    return Schedule(table_drive(t, ts["oil_degC"], ts["pump"], amb, cfg.supply.T_room), t, label)


def case_schedule(case: Case) -> Schedule:
    """The time steps of a case (one sample, t = 0, for a steady case) and its schedule
    file's columns (linear between samples; the columns a fluid reads as its pump keep
    their last sample)."""
    t = case.time
    if t is None:
        return Schedule(lambda _: {}, np.zeros(1), "steady state")
    times = np.linspace(0.0, t.end, int(round(t.end / t.step)) + 1)
    if t.schedule is None:
        return Schedule(lambda _: {}, times, "no schedule", every=int(round(t.output / t.step)))
    ts = read_timeseries(t.schedule, required=("time_s",))
    return Schedule(_case_drive(case, ts, [k for k in ts.names if k != "time_s"]), times, f"schedule {t.schedule}",
                    every=int(round(t.output / t.step)))


def case_series_schedule(case: Case, ts: TimeSeries, label: str) -> Schedule:
    """The inputs a case reads, from a series (a measured run), sampled at its own times."""
    need = sorted(inputs(case.problem))
    missing = [k for k in need if k not in ts]
    if missing:
        raise InputError(f"{label}, column {missing[0]}", "missing: the case reads it",
                         f"record every input of {case.path.name}: {', '.join(need)}")
    drive = _case_drive(case, ts, need)
    return Schedule(drive, drive.time, label)


def _case_drive(case: Case, ts: TimeSeries, names) -> TableDrive:
    """The columns ``names`` of ``ts`` as a case's drive (a fluid's pump columns held)."""
    held = {n for f in case.problem.fluids for n in f.pump.names()}
    time = np.asarray(ts.time_s - ts.time_s[0], float)
    return TableDrive(time, {k: filled(k, time, ts[k], hold=k in held) for k in names}, frozenset(held))


def file_schedule(path, cfg: Config, step_s: float = 60.0) -> Schedule:
    """A schedule file (data format, input columns), sampled every ``step_s`` over its length
    (at least one step, at most :data:`~gatetherm.studies.run.timeseries.MAX_STEPS`)."""
    ts = read_timeseries(path, required=INPUT_COLUMNS)
    span = float(ts.time_s[-1] - ts.time_s[0])
    if span < step_s:
        raise InputError(str(path), f"the schedule spans {span:g} s, less than one {step_s:g}-s step",
                         "give at least two rows a step or more apart")
    check_steps(span, step_s, f"{path}, column time_s")
    s = series_schedule(ts, cfg, f"schedule {path}")
    return Schedule(s.drive, sample_times(span, step_s), s.label)


class ScenarioCache:
    """Assembled models with their heat solvers (factorisations), and finished runs, by
    what they depend on; the least recently used are dropped beyond ``size``. A study that
    runs one frame many times (a diagnosis) passes one cache to every :func:`run_scenario`."""

    def __init__(self, fmesh: FrameMesh | None = None, size: int = 3):
        self.fmesh = fmesh
        """The mesh every model of the cache is built on (None: each meshes its own frame)."""
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

    def model(self, cfg: ModelConfig | Case, dim: int) -> tuple[Model, HeatSolver | None]:
        return self._lru(self._models, (repr(cfg.problem if isinstance(cfg, Case) else cfg), dim),
                         lambda: _build(cfg, dim, self.fmesh))

    def result(self, key, make: Callable[[], tuple[RunResult, Model]]) -> tuple[RunResult, Model]:
        def counted():
            self.runs += 1
            return make()
        return self._lru(self._results, key, counted)


@dataclass(frozen=True)
class Prepared:
    """A model ready to run: effects applied and assembled."""

    model: Model
    solver: HeatSolver | None
    drive: Drive
    """The schedule's drive with the drive-side effects applied."""
    effects: ActiveEffects
    """The model file's effects, then the caller's."""


def prepare(config: Config | Case, dim: int, drive: Drive, effects: Mapping[str, float] | None = None, *,
            cache: ScenarioCache | None = None, mesh: FrameMesh | None = None) -> Prepared:
    """Apply the effects of ``config`` and ``effects`` (these win) and build or reuse the model."""
    eff = ActiveEffects({**config.effects, **dict(effects or {})})
    if isinstance(config, Case):
        frame_only = [k for k in eff.values if CATALOGUE[k].acts_on == "model"]
        if frame_only:
            raise InputError("--effect", f"{frame_only[0]} acts on the paper frame's model, not on a case file",
                             "model it in the case (materials, supports, sources) instead")
        model_cfg, drive = config, drive_effects(drive, eff)
    else:
        model_cfg, drive = apply_effects(config.model, drive, eff)
    model, solver = _build(model_cfg, dim, mesh) if cache is None else cache.model(model_cfg, dim)
    return Prepared(model, solver, drive, eff)


def _build(cfg: ModelConfig | Case, dim: int, fmesh: FrameMesh | None) -> tuple[Model, HeatSolver | None]:
    """The model of a case, or of a frame configuration on ``fmesh`` (None: its own mesh),
    with a heat solver of its own."""
    model = build(cfg.problem, cfg.mesh) if isinstance(cfg, Case) else build_model(cfg, dim, fmesh)
    return model, HeatSolver(model.heat) if model.heat is not None else None


def _once(p: Prepared, schedule: Schedule) -> RunResult:
    """A prescribed-temperature or steady problem: the outputs of its one state at t = 0."""
    t0 = time.perf_counter()
    model = p.model
    if model.heat is None:
        values, state = model.static(), None
        keys = tuple(values)
        Y = np.array([[values[k] for k in keys]])
    else:
        state = p.solver.steady(environment(p.drive, 0.0))
        check_temperatures(state, 0.0)
        keys, Y = model.readout.keys, model.read(state)[None, :]
    cols = {"time_s": np.zeros(1), **{k: np.array([v]) for k, v in p.drive(0.0).items()}}
    cols.update(output_columns(model.problem, keys, Y))
    return RunResult(cols, [(0.0, state)], time.perf_counter() - t0)


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


def run_scenario(config: Config | Case, dim: int, schedule: Schedule, effects: Mapping[str, float] | None = None, *,
                 cache: ScenarioCache | None = None, mesh: FrameMesh | None = None, keep_times=(),
                 on_step: Callable[[int, int], None] | None = None, U0: np.ndarray | None = None) -> ScenarioRun:
    """Run ``config`` (its model and its effects, plus ``effects``) in ``dim`` dimensions
    through ``schedule``; keep full states at ``keep_times``. With a ``cache`` the model,
    its factorisations and (for a plain run from the initial state) the run itself are reused."""
    t0 = time.perf_counter()
    eff = ActiveEffects({**config.effects, **dict(effects or {})})

    def run(p: Prepared) -> RunResult:
        if p.model.heat is None or len(schedule.times) == 1:
            return _once(p, schedule)
        return run_model(p.model, p.drive, schedule.times, keep_times, on_step, U0=U0, solver=p.solver)

    if cache is not None and U0 is None and not keep_times:
        what = config.problem if isinstance(config, Case) else apply_effects(config.model, schedule.drive, eff)[0]
        drive_side = tuple(sorted((k, v) for k, v in eff.values.items() if CATALOGUE[k].acts_on == "drive"))
        key = (repr(what), dim, drive_side, schedule.label, schedule.times.tobytes())

        def make() -> tuple[RunResult, Model]:
            p = prepare(config, dim, schedule.drive, effects, cache=cache)
            return run(p), p.model

        result, model = cache.result(key, make)  # a kept run is observed again without building the model
    else:
        p = prepare(config, dim, schedule.drive, effects, cache=cache, mesh=mesh)
        result, model = run(p), p.model
    cols = apply_faults(eff.observe(result.columns), config.sensors)
    if schedule.every > 1:  # every output interval, and the end of the run
        n = len(next(iter(cols.values())))
        cols = {k: v[np.unique(np.r_[0:n:schedule.every, n - 1])] for k, v in cols.items()}
    return ScenarioRun(cols, result, model, eff, schedule, time.perf_counter() - t0)
