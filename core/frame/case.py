"""The paper's gate frame as an ordinary case: its mesh, problem, inputs and signals made
from a model file's parameters (:func:`gate_frame`), and written as a case file a user can
copy (:func:`write_frame_case`).

The frame's case names what its effects act on (the tie-bar joints, the mounting face, the
piezo's arm) and which of its parameters a diagnosis may move; everything else treats it as
any other case.
"""
from __future__ import annotations

import dataclasses
import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from gatetherm import InputError, write_text_atomic
from gatetherm.frame.beam import theory_coefficients
from gatetherm.frame.build import build_mesh
from gatetherm.frame.conditions import condition, condition_schedule
from gatetherm.frame.config import Config, config_toml, load_config, parse_config
from gatetherm.frame.geometry import FrameParams
from gatetherm.frame.loadcases import tip_coefficients_um
from gatetherm.frame.problem import AMBIENT, GEOMETRY_FREE, check_mesh, frame_problem, frame_targets
from gatetherm.geometry.mesh import FrameMesh
from gatetherm.studies.control.actuator import ActuatorParams
from gatetherm.studies.run.case import Case, TimeSettings, nested
from gatetherm.studies.run.casefile import case_toml
from gatetherm.studies.run.parameters import GEOMETRY, SHIFT, Parameter, geometry
from gatetherm.studies.run.timeseries import FORMAT, TimeSeries, write_timeseries

SCHEDULE_STEP_S = 15.0
"""Sampling of the written schedule, s (the solver's finest step after a pump switch)."""
#: The frame's dimensions a diagnosis moves unless told otherwise (``geometry.NAME``: what they are).
FRAME_GEOMETRY = {
    "geometry.l4": "height of the tie-bar centreline above the mounting face",
    "geometry.l_C": "tie-bar length (clear span between the columns)",
    "geometry.A_C": "tie-bar cross-section",
    "geometry.h": "column width (distance between the sensor faces A and B)",
    "geometry.tank_wall": "wall thickness between face A and the oil tank",
}


def gate_frame(dim: int = 2, config: Config | str | os.PathLike | None = None, condition: int = 1, *,
               mesh: FrameMesh | None = None) -> Case:
    """The paper's gate frame as a case, driven by condition ``condition``.

    Parameters
    ----------
    dim : int
        2 (plane-stress section) or 3 (solid).
    config : Config, path or None
        Its parameters: a model file (path), a :class:`~gatetherm.frame.config.Config`,
        or None for the shipped paper model.
    condition : int
        The paper's condition (1, 2 or 3) that drives it by default.
    mesh : FrameMesh, optional
        A mesh of this frame already made (checked against its geometry).

    Returns
    -------
    Case
    """
    cfg = config if isinstance(config, Config) else load_config(config)
    return frame_case(cfg, dim, condition, mesh)


def frame_case(cfg: Config, dim: int, number: int = 1, mesh: FrameMesh | None = None) -> Case:
    """The frame of ``cfg`` in ``dim`` dimensions (on ``mesh``, else meshed) under condition ``number``."""
    cond = condition(number)
    from_file = not cfg.source.startswith(("gatetherm:", "defaults"))
    try:
        fm = build_mesh(cfg.model.frame, dim, cfg.model.mesh) if mesh is None else check_mesh(mesh, cfg.model.frame, dim)
    except InputError as err:  # a [mesh] size the budgets refuse: name the model file, as its other keys are
        raise err.at(cfg.source) if from_file and err.field.startswith("mesh.") else err from None
    problem = frame_problem(cfg.model, fm)
    return Case(f"gate frame {dim}-D", problem, fm, TimeSettings(cond.duration, 60.0, 60.0, 3600.0),
                condition_schedule(number, cfg.supply), FrameOrigin(cfg, dim, number), frame_targets(cfg.model, fm.regions),
                defaults={AMBIENT: cfg.supply.T_room}, actuator=ActuatorParams(), parameters=cfg.model,
                effects=dict(cfg.effects), sensors=dict(cfg.sensors),
                path=Path(cfg.source) if from_file else None, source=cfg.source)


def _mesh_inputs(cfg: Config) -> tuple:
    f = cfg.model.frame
    return (dataclasses.replace(f, **{k: getattr(Config().model.frame, k) for k in GEOMETRY_FREE}), cfg.model.mesh)


@dataclass(frozen=True)
class FrameOrigin:
    """The frame's generator and its parameters, to make the case again with keys of its model
    file changed (``geometry.l4``, ``thermal.h_air``, ``material.k`` …)."""

    config: Config = field(repr=False)
    dim: int = 2
    condition: int = 1
    ORDER = "model.order"
    """The key of the element order."""

    def remake(self, overrides: dict, previous: Case | None = None) -> Case:
        cfg = parse_config(nested(overrides), self.config.source, base=self.config)
        reuse = previous is not None and _mesh_inputs(cfg) == _mesh_inputs(self.config)
        made = frame_case(cfg, self.dim, self.condition, previous.mesh if reuse else None)
        return made if previous is None else dataclasses.replace(made, schedule=previous.schedule)

    def parameters(self, case: Case) -> tuple[Parameter, ...]:
        return frame_parameters(self.config) + frame_geometry(self.config, FRAME_GEOMETRY)

    def uncertain(self, case: Case, keys) -> tuple[Parameter, ...]:
        """Further dimensions as parameters (``--uncertain geometry.NAME``)."""
        return frame_geometry(self.config, keys)

    def model_file(self, case: Case, header: str = "") -> str:
        """The model file of ``case`` (made by this origin): its parameters, effects and sensor faults."""
        return config_toml(dataclasses.replace(self.config, effects=case.effects, sensors=case.sensors), header)

    @property
    def supply(self):
        """The oil supply unit of the model file (:class:`~gatetherm.studies.run.conditions.SupplyParams`)."""
        return self.config.supply

    def coefficients(self, case: Case, source: str, model) -> tuple[float, float]:
        """The compensator's (K_i, K_C), um/K, of the frame ``case``: ``source`` ``"theory"`` the beam
        theory of its parameters, else the FE load cases at the tips F on ``model()`` (its assembled model)."""
        if source == "theory":
            return theory_coefficients(case.parameters)
        return tip_coefficients_um(model())


def frame_parameters(cfg: Config) -> tuple[Parameter, ...]:
    """The frame's parameters a diagnosis may move: film coefficients to the room and in the tank,
    the initial temperature, and the material's k, α and ρc (the tie bar's own material by the
    same factor)."""
    m, th = cfg.model, cfg.model.thermal

    def thermal(name, key, rng, doc):
        v = getattr(th, key)
        return Parameter(name, key, "W/(m2 K)", v, v * rng[0], v * rng[1], True, doc,
                         lambda x: {f"thermal.{key}": x})

    def material(name, key, unit, rng, doc):
        v = m.material.rho * m.material.c if key == "rho_c" else getattr(m.material, key)
        field_ = "c" if key == "rho_c" else key

        def write(x):
            value = x / m.material.rho if key == "rho_c" else x
            out = {f"material.{field_}": value}
            if m.tie_material is not None:  # the tie bar's own material moves by the same factor
                out[f"material.tie_bar.{field_}"] = getattr(m.tie_material, field_) * value / getattr(m.material,
                                                                                                      field_)
            return out
        return Parameter(name, key, unit, v, v * rng[0], v * rng[1], True, doc, write)

    return (
        thermal("air_film", "h_air", (0.4, 2.5), "film coefficient of the free surfaces to room air"),
        thermal("oil_film_on", "h_oil_on", (0.2, 5.0), "tank-wall film coefficient, pump on"),
        thermal("oil_film_off", "h_oil_off", (0.2, 5.0), "tank-wall film coefficient, pump off"),
        Parameter("initial_offset", "T0", "degC", th.T0, th.T0 - SHIFT, th.T0 + SHIFT, False,
                  "initial temperature of frame and oil (room unchanged): the frame was not in equilibrium at the "
                  "start", lambda x: {"thermal.T0": x}),
        material("conductivity", "k", "W/(m K)", (0.6, 1.6), "thermal conductivity of the frame material"),
        material("expansion", "alpha", "1/K", (0.8, 1.25), "thermal expansion coefficient of the frame material "
                 "(with one material, δ is proportional to it: the data cannot tell it from a gain of the δ sensor)"),
        material("heat_capacity", "rho_c", "J/(m3 K)", (0.8, 1.25), "volumetric heat capacity ρc of the frame "
                 "material"),
    )


def frame_geometry(cfg: Config, keys) -> tuple[Parameter, ...]:
    """The frame's dimensions ``keys`` (``geometry.NAME`` of its model file) as geometry parameters, each
    within :data:`~gatetherm.studies.run.parameters.GEOMETRY` of its value, narrowed to what makes a
    valid frame."""
    free = sorted(f.name for f in dataclasses.fields(FrameParams) if f.name not in GEOMETRY_FREE)
    out = []
    for key in keys:
        name = key.removeprefix("geometry.")
        value = getattr(cfg.model.frame, name, 0.0) if key.startswith("geometry.") and name in free else 0.0
        if not value:
            raise InputError("--uncertain", f"'{key}' is not a dimension of the frame with a value",
                             f"give geometry.NAME, NAME one of {', '.join(free)}")
        rng = tuple(_admissible(cfg, key, value, f) for f in GEOMETRY)
        doc = FRAME_GEOMETRY.get(key, f"frame dimension {name} (FrameParams)")
        out.append(geometry(key, value, "m2" if name.startswith("A_") else "m", doc, rng))
    return tuple(out)


def _admissible(cfg: Config, key: str, value: float, factor: float) -> float:
    """``factor``, or the largest step towards 1 from it (of four) that still makes a valid frame."""
    for f in np.linspace(factor, 1.0, 5)[:-1]:
        try:
            parse_config(nested({key: value * f}), cfg.source, base=cfg)
            return float(f)
        except InputError:
            continue
    return 1.0


def write_frame_case(case: Case, number: int, out: Path) -> None:
    """``out/case.toml`` (mesh ``mesh.msh`` beside it) and ``out/schedule.csv`` of a frame case:
    condition ``number`` sampled every :data:`SCHEDULE_STEP_S`, finely enough that the case run
    matches the frame's own run to a fraction of the δ sensor's resolution."""
    sched = condition_schedule(number, case.origin.config.supply, SCHEDULE_STEP_S)
    rows = [sched.drive(float(t)) for t in sched.times]
    cols = {"time_s": sched.times, **{k: np.array([r[k] for r in rows]) for k in rows[0]}}
    write_timeseries(out / "schedule.csv", TimeSeries(cols, {"format": FORMAT, "schedule": sched.label}))
    end = float(sched.times[-1])
    time = TimeSettings(end, 60.0, 60.0, 3600.0, Path("schedule.csv"))
    text = case_toml(case.problem, f"gate frame {case.dim}-D, condition {number}", "mesh.msh",
                     {name: name for name in case.mesh.sensors}, time,
                     f"The paper's gate frame ({case.source}) as a case file, written by gatetherm mesh.\n"
                     f"Run it: gatetherm run case.toml --out DIR (δ, θ as gatetherm simulate --condition {number}).")
    write_text_atomic(out / "case.toml", text)


def condition_runs(cfg: Config, dim: int, conditions=(1, 2, 3), cache=None, mesh: FrameMesh | None = None,
                   **kw) -> dict:
    """{condition: :class:`~gatetherm.studies.run.scenario.ScenarioRun`} of the paper's conditions on
    the frame of ``cfg`` in ``dim`` dimensions, meshed once (``kw``: of ``run_scenario``)."""
    from gatetherm.studies.run.scenario import run_scenario

    case = frame_case(cfg, dim, 1, mesh)
    return {n: run_scenario(case, condition_schedule(n, cfg.supply), cache=cache, **kw) for n in conditions}
