"""Replay a measured run through a model and line the outputs up with the measurement.

The model is driven by the file's own inputs (oil, pump, ambient when present; for a
case file, the schedule columns its values read) at the file's sample times; every
measured output channel that the model also produces is compared. A :class:`Replayer`
meshes the frame once (a case brings its mesh) and re-assembles
only when a hypothesis changes the model itself, and reruns the model only when a
hypothesis changes the model or the drive (sensor-side effects act on a kept run), so
the hundred-odd runs of a diagnosis cost well under a second each with the 2-D model.

Residuals are *measured minus model*, in the channel's unit, and are judged
against the sensor resolution: 0.1 µm for displacements, 0.05 K for
thermocouples (the paper's sensors).
"""
from __future__ import annotations

import dataclasses
import logging

import numpy as np

from gatetherm.geometry.build import build_mesh
from gatetherm import InputError
from gatetherm.geometry.frame import MeshParams
from gatetherm.studies.run.case import Case
from gatetherm.studies.run.config import Config
from gatetherm.studies.run.scenario import ScenarioCache, case_series_schedule, run_scenario, series_schedule
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
    """Runs ``config`` (a model file at ``dim`` on ``mesh``, or a case on its own mesh)
    through the inputs of the measured series ``ts`` (the scenario path, one mesh and one
    :class:`~gatetherm.studies.run.scenario.ScenarioCache` for all hypotheses)."""

    def __init__(self, config: Config | Case, ts: TimeSeries, dim: int = 2, mesh: MeshParams | None = None,
                 cache: int = 4):
        if isinstance(config, Case):
            self.config, self.dim, self.fmesh = config, config.mesh.dim, config.mesh
            self.schedule = case_series_schedule(config, ts, "measured inputs")
        else:
            self.config = dataclasses.replace(config, model=dataclasses.replace(
                config.model, mesh=mesh or config.model.mesh))
            self.dim = dim
            self.schedule = series_schedule(ts, config, "measured inputs")
            self.fmesh = build_mesh(self.config.model.frame, dim, self.config.model.mesh)
        self.times = self.schedule.times
        self.drive = self.schedule.drive
        self.has_ambient = "ambient_degC" in ts
        self.cache = ScenarioCache(self.fmesh, cache)

    @property
    def case(self) -> bool:
        """The model is a case file's frame."""
        return isinstance(self.config, Case)

    @property
    def runs(self) -> int:
        """Model runs made so far."""
        return self.cache.runs

    def run(self, config: Config | None = None) -> dict[str, np.ndarray]:
        """Output columns (data-format names and units) of ``config`` (default: the replayer's,
        which must be a variant of it on the same frame and mesh)."""
        return run_scenario(config or self.config, self.dim, self.schedule, cache=self.cache).columns


def residuals(ts: TimeSeries, cols: dict[str, np.ndarray], channels) -> dict[str, np.ndarray]:
    """Measured minus model per channel (NaN where the measurement is missing)."""
    return {c: np.asarray(ts[c], dtype=float) - cols[c] for c in channels}
