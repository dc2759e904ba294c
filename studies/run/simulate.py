"""Run a frame model through a schedule and collect what the sensors see.

Consumes the heat-step generator; per step it reads the sensor temperatures
(a sparse probe) and the displacement outputs (fixed weight vectors), so a
run costs one heat solve per step and no elastic solve.
"""
from __future__ import annotations

import logging
import time as _time
from dataclasses import dataclass, field
from typing import Callable

import numpy as np
from scipy.signal import find_peaks

from gatetherm.solvers.heat import Drive, HeatSolver, TimeScheme, march
from gatetherm.solvers.model import FrameModel

log = logging.getLogger(__name__)

#: Smallest prominence (µm) of a δ peak that counts, ten times the sensor resolution.
PEAK_PROMINENCE_UM = 1.0


@dataclass(frozen=True)
class RunResult:
    """Columns in the units of the time-series format, plus saved states."""

    columns: dict[str, np.ndarray]
    states: list[tuple[float, np.ndarray]] = field(default_factory=list)
    seconds: float = 0.0


def sample_times(duration_s: float, step_s: float = 60.0) -> np.ndarray:
    n = int(round(duration_s / step_s))
    return np.linspace(0.0, n * step_s, n + 1)


def run_model(model: FrameModel, drive: Drive, times: np.ndarray, keep_times=(),
              on_step: Callable[[int, int], None] | None = None, scheme: TimeScheme | None = None,
              U0: np.ndarray | None = None, solver: HeatSolver | None = None) -> RunResult:
    """March ``model`` over ``times`` (s) under ``drive`` from ``U0`` (default: uniform T0)
    with ``scheme`` (default: the model's); keep full states at ``keep_times``. A
    ``solver`` of ``model.heat`` carries its factorisations over from earlier runs."""
    keep = {float(t) for t in keep_times}
    rows, states = [], []
    t0 = _time.perf_counter()
    scheme = model.config.scheme if scheme is None else scheme
    steps = march(solver or HeatSolver(model.heat), drive, np.asarray(times, float), scheme, U0)
    for i, (t, U) in enumerate(steps):
        u = drive(t)
        temps = model.temperatures(U)
        disp = model.displacements(U)
        rows.append((t, u.T_supply, float(u.pump), u.T_amb, temps, disp))
        if t in keep:
            states.append((t, U.copy()))
        if on_step:
            on_step(i + 1, len(times))
    cols: dict[str, np.ndarray] = {
        "time_s": np.array([r[0] for r in rows]),
        "oil_degC": np.array([r[1] for r in rows]),
        "pump": np.array([r[2] for r in rows]),
        "ambient_degC": np.array([r[3] for r in rows]),
        "theta_A_degC": np.array([r[4]["A"] for r in rows]),
        "theta_B_degC": np.array([r[4]["B"] for r in rows]),
        "theta_C_degC": np.array([r[4]["C"] for r in rows]),
        "delta_um": np.array([r[5]["delta"] for r in rows]) * 1e6,
    }
    cols["delta_E_um"] = np.array([r[5]["delta_E"] for r in rows]) * 1e6
    for name in list(rows[0][4]):
        if name not in ("A", "B", "C"):
            cols[f"T_{'tank_' if name in ('oil', 'wall') else ''}{name}_degC"] = np.array([r[4][name] for r in rows])
    secs = _time.perf_counter() - t0
    log.info("marched %d steps in %.2f s", len(rows) - 1, secs)
    return RunResult(cols, states, secs)


def delta_figures(time_s: np.ndarray, delta_um: np.ndarray) -> dict[str, float | None]:
    """The paper's figures of a δ history: first and second positive peak (µm)
    and time of the first (min), full swing (µm)."""
    peaks, _ = find_peaks(np.concatenate([[-np.inf], delta_um, [-np.inf]]),
                          prominence=PEAK_PROMINENCE_UM)
    peaks = [p - 1 for p in peaks if delta_um[p - 1] > 0]
    first = peaks[0] if peaks else None
    return {
        "first_peak_um": float(delta_um[first]) if first is not None else None,
        "first_peak_min": float(time_s[first] / 60.0) if first is not None else None,
        "second_peak_um": float(delta_um[peaks[1]]) if len(peaks) > 1 else None,
        "swing_um": float(delta_um.max() - delta_um.min()),
    }
