"""Replay a measured run through a model and line the outputs up with the measurement.

The case is driven by the file's own columns (every input its values read; an input it
gives a default may be missing) at the file's sample times; every measured output channel
that the model also produces is compared. A :class:`Replayer` re-assembles only when a
hypothesis changes the model itself, and reruns the model only when a hypothesis changes
the model (sensor-side effects act on a kept run), so
the hundred-odd runs of a diagnosis cost well under a second each with the 2-D model.

Residuals are *measured minus model*, in the channel's unit, and are judged
against the sensor resolution: 0.1 µm for displacements, 0.05 K for
thermocouples (the paper's sensors).
"""
from __future__ import annotations

import logging
import time

import numpy as np

from gatetherm import InputError
from gatetherm.studies.diagnosis.progress import Budget
from gatetherm.studies.run.case import Case
from gatetherm.studies.run.scenario import ScenarioCache, measured_schedule, run_scenario
from gatetherm.studies.run.timeseries import OUTPUT_COLUMNS, TimeSeries

log = logging.getLogger(__name__)

#: Sensor resolution by column-unit suffix: differential transformer 0.1 µm, thermocouples 0.05 K.
RESOLUTION = {"_um": 0.1, "_degC": 0.05}
DELTA = "delta_um"
#: Columns that are inputs or compensation, never compared.
NOT_COMPARED = ("time_s", "oil_degC", "pump", "ambient_degC", "u_piezo_um")


def resolution(column: str) -> float:
    """Resolution of a channel (its unit: µm or K)."""
    return next(r for suffix, r in RESOLUTION.items() if column.endswith(suffix))


def unit(column: str) -> str:
    return "µm" if column.endswith("_um") else "K"


def label(column: str) -> str:
    """Short readable channel name: δ, θ_A, T_C3 …"""
    if column == DELTA:
        return "δ"
    stem = column.removesuffix("_degC").removesuffix("_um")
    return stem.replace("theta_", "θ_")


def compared_channels(ts: TimeSeries, model_columns, inputs=()) -> tuple[str, ...]:
    """Measured output channels the model also produces: δ, θ_A, θ_B, θ_C, then
    further sensors in file order (not the ``inputs`` that drive the model); at least one
    sample each."""
    first = [c for c in OUTPUT_COLUMNS if c in ts]
    rest = [c for c in ts.names if c not in first and c not in NOT_COMPARED and c not in inputs
            and c.endswith(tuple(RESOLUTION))]
    out = tuple(c for c in first + rest if c in model_columns and np.isfinite(ts[c]).any())
    if not out:
        raise InputError("--data", "no output channel the model can replay",
                         f"give at least one of {', '.join(OUTPUT_COLUMNS)}")
    return out


class Replayer:
    """Runs a case through the inputs of the measured series ``ts`` at its sample times (the
    scenario path, one :class:`~gatetherm.studies.run.scenario.ScenarioCache` for all hypotheses)."""

    def __init__(self, case: Case, ts: TimeSeries, cache: int = 4, budget: Budget | None = None):
        self.config = case
        self.budget = Budget() if budget is None else budget
        """The model runs done and planned (:mod:`progress`; a budget may count the runs of several replayers)."""
        self.seconds = 0.0
        """Wall time of the last model run, s."""
        self.schedule = measured_schedule(case, ts)
        self.times = self.schedule.times
        self.drive = self.schedule.drive
        self.has_ambient = any(k in ts for k in room_inputs(case))
        self.cache = ScenarioCache(cache)

    @property
    def dim(self) -> int:
        return self.config.dim

    @property
    def runs(self) -> int:
        """Model runs made so far."""
        return self.cache.runs

    def run(self, case: Case | None = None) -> dict[str, np.ndarray]:
        """Output columns (data-format names and units) of ``case`` (default: the replayer's,
        which must be a variant of it on the same mesh)."""
        before, t0 = self.runs, time.perf_counter()
        try:
            return run_scenario(case or self.config, self.schedule, cache=self.cache).columns
        finally:  # a run the model refuses counts too
            if self.runs > before:
                self.seconds = time.perf_counter() - t0
                self.budget.ran()


def room_inputs(case: Case) -> set[str]:
    """The inputs the room's temperature (the films' ambient) reads."""
    p = case.problem
    values = [f.ambient for f in p.films] + ([p.faces.ambient] if p.faces else [])
    return set().union(*(v.names() for v in values)) - {"t"} if values else set()


def residuals(ts: TimeSeries, cols: dict[str, np.ndarray], channels) -> dict[str, np.ndarray]:
    """Measured minus model per channel (NaN where the measurement is missing)."""
    return {c: np.asarray(ts[c], dtype=float) - cols[c] for c in channels}
