"""The candidates' temperatures and the case's relative displacements from its reduced model.

The reduced heat model (:func:`gatetherm.studies.run.reduce.build_rom`) carries its M-orthonormal
basis ``V`` (unknowns x states): the full temperature state is ``T0 + V x``. A candidate node's
temperature rise is therefore its row of ``V`` times the reduced state, ``theta_i = V_i x``: the
full-state read-out projected with the basis (:func:`candidate_rows`). This is chosen over adding
the candidates as read-out rows of the linear heat model before the reduction: such rows, left
out of the outputs balanced truncation weighs, would give the very same projected rows; put into
them, thousands of rows would swamp the weighing of the displacements and cost an observability
Gramian with as many right-hand sides. The basis holds every mode's static response, so steady
states are exact at every node; the transients are checked against FE (docs/sensors.md).

A load is marched once (:func:`simulate`): its reduced states (samples x states) and every output
of the reduced model; any candidate's history is then one product with its row.
"""
from __future__ import annotations

import logging
from dataclasses import dataclass

import numpy as np

from gatetherm import InputError
from gatetherm.solvers.fem import complement
from gatetherm.solvers.rom import ReducedModel
from gatetherm.solvers.rom_time import discretise, march_rom, outputs
from gatetherm.studies.run.reduce import series_inputs
from gatetherm.studies.run.schedules import Schedule
from gatetherm.studies.sensors.loads import columns

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class Simulated:
    """One load marched through the reduced model, at its output samples."""

    label: str
    key: str
    """Its noise key (:func:`.screen.load_key`)."""
    columns: dict
    """``time_s`` (s) and the case's inputs."""
    states: np.ndarray
    """Reduced states, samples x states (x = 0: every unknown at T0)."""
    outputs: np.ndarray
    """Every output of the reduced model, samples x outputs (data-format units)."""


def candidate_rows(model, basis: np.ndarray, nodes: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Rows of ``basis`` (the reduction's V over the free unknowns of ``model.heat``) at the mesh
    ``nodes``: (rows, mask of the nodes kept); a node whose temperature is held (a fixed
    temperature) is no candidate."""
    h = model.heat
    free = complement(h.n, h.fixed_dofs)
    dofs = h.basis.nodal_dofs[0][np.asarray(nodes, int)]
    pos = np.searchsorted(free, dofs)
    ok = (pos < free.size) & (free[np.minimum(pos, free.size - 1)] == dofs)
    if not ok.all():
        log.info("%d candidate nodes hold a fixed temperature: left out", int((~ok).sum()))
    return basis[pos[ok]], ok


def output_samples(schedule: Schedule) -> np.ndarray:
    """Indices of the samples a run reports: every ``every``-th step and the last."""
    n = len(schedule.times)
    return np.unique(np.r_[0:n:max(schedule.every, 1), n - 1])


def simulate(rom: ReducedModel, schedule: Schedule, names, key: str, defaults=None,
             _steps: dict | None = None) -> Simulated:
    """March ``schedule`` (the inputs ``names`` of the case; noise key ``key``) through ``rom`` from
    rest (uniform T0)."""
    cols = columns(schedule, names, defaults)
    t = cols["time_s"]
    h = np.diff(t)
    if t.size < 2 or np.ptp(h) > 1e-6 * h[0]:
        raise InputError(f"schedule '{schedule.label}'", "is not sampled at a constant step",
                         "give a schedule at a constant step (a reduced model marches one step length)")
    steps = {} if _steps is None else _steps
    dt = round(float(h[0]), 9)
    if dt not in steps:
        steps[dt] = discretise(rom, dt)
    u, modes = series_inputs(rom, cols)
    X = march_rom(steps[dt], u, modes)
    keep = output_samples(schedule)
    return Simulated(schedule.label, key, {k: v[keep] for k, v in cols.items()}, X[keep], outputs(rom, X, u)[keep])
