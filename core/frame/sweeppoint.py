"""A point of a study of the paper's frame: its keys (``<section>.<field>``, ``geometry.<field>``,
``condition``, ``effect.<name>``, ``derived.<name>``: :data:`DERIVED`) applied to the base model
(:func:`configure`), the frame raised so that its tie bars fit (:func:`fit_frame`), its key
(:func:`point_key`) and its evaluation (:func:`evaluate_point`: FE and beam-theory coefficients or a
heating run), all offered to the generic sweep as :data:`FRAME`. The study and its points are
:mod:`gatetherm.studies.sweeps.sweep`."""
from __future__ import annotations

import dataclasses
import hashlib
import json
import time
from dataclasses import dataclass
from typing import Any, Callable

import numpy as np

import gatetherm
from gatetherm import InputError
from gatetherm.frame import beam
from gatetherm.frame.beam import beta_area
from gatetherm.frame.build import check_mesh_size
from gatetherm.frame.config import Config, load_config, parse_config
from gatetherm.frame.geometry import FrameParams, tie_depth, tie_heights, validate
from gatetherm.frame.loadcases import fe_coefficients
from gatetherm.studies.run.origin import scheme_digest
from gatetherm.studies.sweeps.evaluate import GMSH_LOCK
from gatetherm.studies.sweeps.sweep import Study, Task, number

SECTIONS = ("geometry", "mesh", "material", "material.tie_bar", "thermal", "supply", "model")
PINHOLE = 0.003
"""Side of the cavity left by ``derived.tank_cavity = false``, m."""


# --- derived parameters ---------------------------------------------------------------

def _l_over_h(cfg: Config, v: float) -> dict:
    p = cfg.model.frame
    s = p.l / v / p.h
    return {"h": p.l / v, "tank_wall": p.tank_wall * s, "tank_width": p.tank_width * s}


def _beta(cfg: Config, v: float) -> dict:
    return {"A_C": beta_area(cfg.model, v)}


def _tank_cavity(cfg: Config, v: bool) -> dict:
    p = cfg.model.frame
    if v:
        return {}
    return {"tank_wall": 0.5 * (p.h - PINHOLE), "tank_width": PINHOLE, "tank_height": PINHOLE,
            "tank_depth": min(PINHOLE, p.tank_depth)}


#: name -> (doc, type, function(config, value) -> geometry changes), applied in this order.
DERIVED: dict[str, tuple[str, type, Callable[[Config, Any], dict]]] = {
    "l_over_h": ("column slenderness: h = l/value, tank_wall and tank_width scaled with h",
                 float, _l_over_h),
    "l1_over_l": ("heated height: l1 = value * l", float, lambda c, v: {"l1": v * c.model.frame.l}),
    "l_over_l4": ("tie-bar height: l4 = l/value", float, lambda c, v: {"l4": c.model.frame.l / v}),
    "beta": ("stiffness ratio of eq (26): A_C = 3 E I l_C / (beta E_C l^3), I = depth h^3/12",
             float, _beta),
    "tank_cavity": (f"false: the tank becomes a {PINHOLE * 1e3:g} mm pinhole at mid-width", bool,
                    _tank_cavity),
}


def fit_frame(p: FrameParams, dim: int) -> FrameParams:
    """Raise ``t_C`` (3-D, tie bar behind the arms) and ``column_height`` so that the tie bars fit."""
    room = p.depth - p.arm_depth
    if dim == 3 and tie_depth(p) > room:
        p = dataclasses.replace(p, t_C=p.A_C / room * (1.0 + 1e-9))
    top = max(p.l + 0.5 * p.arm_thickness, *(y + 0.5 * p.t_C for y in tie_heights(p)))
    return dataclasses.replace(p, column_height=max(p.column_height, top))


# --- from keys to a model -------------------------------------------------------------

def _nest(flat: dict[str, Any]) -> dict:
    out: dict = {}
    for key, value in flat.items():
        *head, last = key.split(".")
        node = out
        for part in head:
            node = node.setdefault(part, {})
        node[last] = value
    return out


def configure(base: Config, overrides: dict[str, Any], dim: int, fit: bool = True):
    """``(config, condition, effects, skip)`` of one point; bad keys raise InputError."""
    from gatetherm.frame.conditions import CONDITIONS
    from gatetherm.frame.problem import TARGETS
    from gatetherm.solvers.effects import resolve

    sections, geometry, derived, effects, condition = {}, {}, {}, {}, None
    fields = {f.name for f in dataclasses.fields(FrameParams)}
    for key, value in overrides.items():
        head, _, name = key.rpartition(".")
        if key == "condition":
            condition = number(key, value, int)
            if condition not in CONDITIONS:
                raise InputError(key, f"no condition {condition}", f"choose from {sorted(CONDITIONS)}")
        elif head == "geometry":
            if name not in fields:
                raise InputError(key, "unknown key", f"known keys: {', '.join(sorted(fields))}")
            geometry[name] = number(key, value, float)
        elif head == "derived":
            if name not in DERIVED:
                raise InputError(key, "unknown derived parameter", f"known: {', '.join(DERIVED)}")
            derived[name] = number(key, value, DERIVED[name][1])
        elif key.startswith("effect."):
            name = key[len("effect."):]
            resolve(name, TARGETS, key)
            effects[name] = number(key, value, float)
        elif head in SECTIONS:
            sections[key] = value
        else:
            raise InputError(key, "unknown parameter", "use <section>.<field> with a section of "
                             f"{', '.join(SECTIONS)}, or condition, effect.<name>, derived.<name>")
    cfg = parse_config(_nest(sections), base.source, base) if sections else base

    def with_frame(c: Config, changes: dict) -> Config:
        frame = dataclasses.replace(c.model.frame, **changes)
        return dataclasses.replace(c, model=dataclasses.replace(c.model, frame=frame))

    cfg = with_frame(cfg, geometry)
    for name, (_, typ, rule) in DERIVED.items():
        if name in derived:
            if typ is float and not derived[name] > 0:
                raise InputError(f"derived.{name}", f"must be > 0, got {derived[name]}")
            cfg = with_frame(cfg, rule(cfg, derived[name]))
    if fit:
        cfg = with_frame(cfg, dataclasses.asdict(fit_frame(cfg.model.frame, dim)))
    try:
        validate(cfg.model.frame, dim)
        skip = ""
    except InputError as err:
        skip = str(err)
    if not skip:
        check_mesh_size(cfg.model.frame, cfg.model.mesh, dim)  # a point too big for memory fails the study now
    return cfg, condition, tuple(sorted(effects.items())), skip


# --- a point: its key and its evaluation ----------------------------------------------------

def point_key(cfg: Config, dim: int, compute, condition, effects) -> str:
    """Hash of everything a point's result depends on: the gatetherm version, the numerical
    scheme, the final model (without the thermal and supply data when nothing is run),
    dimension, computations, condition, effects."""
    model = dataclasses.asdict(cfg.model)
    data = {"model": model, "supply": dataclasses.asdict(cfg.supply), "effects": cfg.effects,
            "version": gatetherm.__version__, "scheme": scheme_digest(cfg.model)}
    if "run" not in compute:
        for name in ("thermal", "source", "joint_conductance", "scheme"):
            model.pop(name, None)
        data.pop("supply")
        condition = None
    blob = json.dumps({**data, "dim": dim, "compute": sorted(compute), "condition": condition,
                       "effect_values": effects}, sort_keys=True, default=repr)
    return hashlib.sha256(blob.encode()).hexdigest()[:20]


def point(cfg: Config, study: Study, params: tuple, overrides: dict[str, Any]) -> Task:
    """The point of the frame study ``study`` (on its model ``cfg``) at ``overrides``; bad keys raise."""
    cfg, cond, eff, skip = configure(cfg, overrides, study.dim, study.fit_frame)
    if "run" in study.compute and cond is None:
        raise InputError("condition", "the 'run' computation needs a heating condition",
                         "add condition = [1, 2, 3] to [grid] or condition = 1 to [set]")
    key = point_key(cfg, study.dim, study.compute, cond, eff)
    return Task(key, params, cfg, study.dim, study.compute, cond, eff, skip, frame=study.frame)


def _coefficients(model, cfg: Config) -> dict[str, float]:
    """FE (element-exact load cases, at E and at F) and beam-theory K_i, K_C in um/K, and normalised."""
    p, m = cfg.model.frame, cfg.model
    tie = m.tie_material or m.material
    c = fe_coefficients(model)
    ki_th, kc_th = beam.theory_coefficients(m)
    ki_s = float(beam.ki_scale(m.material.alpha, p.l, p.h)) * 1e6
    kc_s = float(beam.kc_scale(tie.alpha, p.l_C)) * 1e6
    out = {"Ki_E_fe": c.Ki_E * 1e6, "Kc_E_fe": c.Kc_E * 1e6, "Ki_F_fe": c.Ki_F * 1e6,
           "Kc_F_fe": c.Kc_F * 1e6, "Ki_theory": ki_th, "Kc_theory": kc_th}
    out.update({"Ki_norm_fe": out["Ki_E_fe"] / ki_s, "Kc_norm_fe": out["Kc_E_fe"] / kc_s,
                "Ki_norm_theory": ki_th / ki_s, "Kc_norm_theory": kc_th / kc_s,
                "Ki_scale": ki_s, "Kc_scale": kc_s, "l_over_l4": p.l / p.l4, "l_over_h": p.l / p.h,
                "beta": beam.frame_beta(m)})
    return out


def _run(cols: dict) -> dict[str, float | None]:
    from gatetherm.studies.run.simulate import delta_figures

    d = cols["delta_um"]
    dab = cols["theta_A_degC"] - cols["theta_B_degC"]
    return {**delta_figures(cols["time_s"], d), "delta_max_um": float(d.max()),
            "delta_min_um": float(d.min()), "theta_AB_max_K": float(np.max(dab - dab[0])),
            "theta_C_end_K": float(cols["theta_C_degC"][-1] - cols["theta_C_degC"][0])}


def evaluate_point(task: Task, record: dict) -> dict[str, Any]:
    """``record`` of the frame point ``task`` completed: status, results, seconds, scheme."""
    from gatetherm.frame.case import frame_case
    from gatetherm.studies.run.scenario import prepare, run_scenario

    if task.skip:
        return {**record, "scheme": scheme_digest(task.config.model)}
    t0 = time.perf_counter()
    cfg, dim = task.config, task.dim
    with GMSH_LOCK:
        case = frame_case(cfg, dim, task.condition or 1)
    res: dict[str, Any] = {}
    if "run" in task.compute:
        run = run_scenario(case, effects=dict(task.effects))
        model, res = run.model, _run(run.columns)
    else:
        model = prepare(case, dict(task.effects)).model
    if "coefficients" in task.compute:
        res.update(_coefficients(model, dataclasses.replace(cfg, model=model.config)))
    res["nodes"] = int(len(model.fmesh.points))
    return {**record, "status": "ok", "results": res, "seconds": round(time.perf_counter() - t0, 3),
            "scheme": scheme_digest(task.config.model)}


@dataclass(frozen=True)
class FramePoints:
    """The frame's side of a sweep (:class:`gatetherm.studies.sweeps.sweep.FramePoints`): its model file,
    its points and their evaluation. Stateless; :data:`FRAME` is the one to pass."""

    def model(self, path, key: str) -> Config:
        return load_config(path, key)

    def point(self, study: Study, params: tuple, overrides: dict[str, Any]) -> Task:
        return point(study.base, study, params, overrides)

    def evaluate(self, task: Task, record: dict) -> dict[str, Any]:
        return evaluate_point(task, record)


FRAME = FramePoints()
"""The paper frame's points, for :class:`~gatetherm.studies.sweeps.sweep.Study` ``frame=``."""
