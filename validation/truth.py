"""The "measured" runs of the studies: the paper frame with something hidden in it.

A run is made on a finer mesh than the diagnosis uses (no inverse crime), with catalogue
effects, parameters off, sensor faults or dimensions off in the model (:func:`truth_with`),
or with a cause outside every hypothesis (:data:`OUTSIDE`): a heat leak at the tie bar,
thermocouples A/B 40 mm off, a drop of the tank oil flow at 2.5 h, a room temperature that
swings and is not recorded, the 3-D frame's run diagnosed with the 2-D section, and a
dimension the diagnosis does not try (the column height). Then Gaussian sensor noise at the
paper's resolution (0.1 µm, 0.05 K) is added and the values rounded to it (:func:`measured`).
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from gatetherm.frame.problem import EFFECTS
from gatetherm.studies.diagnosis.hypotheses import configure
from gatetherm.studies.diagnosis.replay import resolution
from gatetherm.frame.config import Config
from gatetherm.frame.case import FRAME_GEOMETRY, frame_case
from gatetherm.frame.conditions import condition_schedule
from gatetherm.studies.run.scenario import Schedule, run_scenario
from gatetherm.studies.run.simulate import sample_times
from gatetherm.studies.run.timeseries import FORMAT, OUTPUT_COLUMNS, TimeSeries

#: The channels a rig of the paper records (no room temperature).
MEASURED = ("time_s", "oil_degC", "pump", "theta_A_degC", "theta_B_degC", "theta_C_degC", "delta_um")
NOISE_RMS_UM = 0.1 * np.sqrt(1 + 1 / 12)
"""RMS of the added δ noise: Gaussian at the resolution, then rounded to it, µm."""
TRUTH_MESH_FACTOR = 0.75
"""Element size of the "measured" runs relative to the diagnosis mesh."""

#: Causes outside every hypothesis: name -> (parameter, unit, strengths tried).
OUTSIDE = {
    "tie_heat_leak": ("power", "W", (1.0, 2.0)),
    "sensor_height": ("offset", "m", (0.04, -0.04)),
    "flow_drop": ("fraction", "1", (0.3, 0.5)),
    "sine_room": ("amplitude", "K", (1.0,)),
    "three_d": ("—", "", (0.0,)),
    "unmarked_column_height": ("factor", "1", (1.08,)),
}
FLOW_DROP_AT_S = 2.5 * 3600.0
"""When the oil flow drops in the ``flow_drop`` case, s."""
SINE_PERIOD_S = 3 * 3600.0
"""Period of the unrecorded room swing of the ``sine_room`` case, s (about the model's T_room)."""
#: Parameter mismatches (no missing effect; the parameter piece is expected):
#: "mismatch:<ThermalParams field>" -> factors on the model's value.
MISMATCH = {"mismatch:h_oil_on": (1.5,), "mismatch:h_air": (0.6,)}
#: The parameter piece that names each mismatch.
MISMATCH_PIECE = {"mismatch:h_oil_on": "oil_film_on", "mismatch:h_air": "air_film"}
GEOMETRY_OFF = (0.05, 0.10)
"""A dimension the diagnosis tries (:data:`~gatetherm.frame.case.FRAME_GEOMETRY`) is off by
this fraction of its value (drawn uniformly, either sign)."""


@dataclass(frozen=True)
class Case:
    effect: str
    """Catalogue name, an :data:`OUTSIDE` name, a mismatch, a dimension (``geometry.l_C``: the
    strength is a factor on it) or "none" (noise only)."""
    strength: float
    condition: int
    seed: int


def truth_setup(config: Config, condition: int, mesh_factor: float = TRUTH_MESH_FACTOR,
                duration: float | None = None, step_s: float = 60.0) -> tuple[Config, Schedule]:
    """``config`` on the truth mesh (``mesh_factor`` × the model's element size) and the
    condition's schedule, over its duration unless ``duration`` (s) is given."""
    mesh = dataclasses.replace(config.model.mesh, size=config.model.mesh.size * mesh_factor)
    sched = condition_schedule(condition, config.supply, step_s)
    if duration:
        sched = dataclasses.replace(sched, times=sample_times(duration, step_s))
    return dataclasses.replace(config, model=dataclasses.replace(config.model, mesh=mesh)), sched


def truth_with(config: Config, condition: int, values: dict, dim: int = 2, **setup) -> dict[str, np.ndarray]:
    """The noise-free columns with the hypotheses ``values`` ({Piece: value}: effects,
    parameters, sensor faults) in the model, on the truth mesh (:func:`truth_setup`)."""
    cfg, sched = truth_setup(config, condition, **setup)
    return run_scenario(configure(frame_case(cfg, dim), values), sched).columns


def truth(config: Config, case: Case, dim: int = 2, mesh_factor: float = TRUTH_MESH_FACTOR,
          duration: float | None = None) -> dict[str, np.ndarray]:
    """The noise-free columns of a case on the truth mesh (:func:`truth_setup`)."""
    full, sched = truth_setup(config, case.condition, mesh_factor, duration)
    cfg = full.model

    def run(model_cfg, schedule=sched, mesh=None, **kw):
        return run_scenario(frame_case(dataclasses.replace(config, model=model_cfg), dim, mesh=mesh), schedule, **kw)

    if case.effect in EFFECTS:
        return run(cfg, effects={case.effect: case.strength}).columns
    if case.effect == "three_d":
        return truth(config, dataclasses.replace(case, effect="none"), 3, mesh_factor, duration)
    if case.effect in FRAME_GEOMETRY or case.effect.startswith("unmarked_"):
        name = case.effect.removeprefix("geometry.").removeprefix("unmarked_")
        cfg = dataclasses.replace(cfg, frame=cfg.frame.replace(**{name: getattr(cfg.frame, name) * case.strength}))
    elif case.effect == "sine_room":
        drive, room = sched.drive, config.supply.T_room

        def swinging(t):
            return {**drive(t), "ambient_degC": room + case.strength * np.sin(2 * np.pi * t / SINE_PERIOD_S)}
        return run(cfg, dataclasses.replace(sched, drive=swinging)).columns
    elif case.effect == "tie_heat_leak":
        from gatetherm.frame.geometry import part_boxes

        x0, x1, y0, y1, z0, z1 = part_boxes(cfg.frame, dim)["tie_bar"]
        cfg = dataclasses.replace(cfg, source={"tie_bar": -case.strength / ((x1 - x0) * (y1 - y0) * (z1 - z0))})
    elif case.effect == "sensor_height":
        cfg = dataclasses.replace(cfg, frame=cfg.frame.replace(sensor_height=cfg.frame.sensor_height + case.strength))
    elif case.effect in MISMATCH:
        field = case.effect.split(":")[1]
        cfg = dataclasses.replace(cfg, thermal=dataclasses.replace(
            cfg.thermal, **{field: getattr(cfg.thermal, field) * case.strength}))
    elif case.effect == "flow_drop":
        times = sched.times
        k = int(np.searchsorted(times, FLOW_DROP_AT_S))
        first = run(cfg, dataclasses.replace(sched, times=times[:k + 1]), keep_times=[times[k]])
        low = dataclasses.replace(cfg.thermal, flow_rate=cfg.thermal.flow_rate * case.strength)
        rest = run(dataclasses.replace(cfg, thermal=low), dataclasses.replace(sched, times=times[k:]),
                   mesh=first.model.fmesh, U0=first.result.states[0][1]).columns
        return {c: np.concatenate([first.columns[c][:k], rest[c]]) for c in rest}
    elif case.effect != "none":
        raise ValueError(f"unknown case effect {case.effect!r}")
    return run(cfg).columns


def measured(cols: dict[str, np.ndarray], seed: int, condition: int) -> TimeSeries:
    """The rig's channels of ``cols`` with sensor noise at the resolution, rounded to it."""
    return recorded(cols, MEASURED, OUTPUT_COLUMNS, seed,
                    {"source": "hidden-effect study", "condition": str(condition)})


def recorded(cols: dict[str, np.ndarray], keep, sensors, seed: int, metadata: dict) -> TimeSeries:
    """The columns ``keep`` of ``cols``, the ``sensors`` among them with Gaussian noise at
    their resolution, rounded to it."""
    rng = np.random.default_rng(seed)
    out = {}
    for c in keep:
        v = np.asarray(cols[c], dtype=float)
        if c in sensors:
            r = resolution(c)
            v = np.round(np.round((v + rng.normal(0.0, r, len(v))) / r) * r, 6)
        out[c] = v
    return TimeSeries(out, {"format": FORMAT, **metadata})


