"""A point of a study of the paper's frame: its keys (``<section>.<field>``, ``geometry.<field>``,
``condition``, ``effect.<name>``, ``derived.<name>``: :data:`DERIVED`) applied to the base model
(:func:`configure`), the frame raised so that its tie bars fit (:func:`fit_frame`). The study and its
points are :mod:`gatetherm.studies.sweeps.sweep`."""
from __future__ import annotations

import dataclasses
from typing import Any, Callable

from gatetherm import InputError
from gatetherm.checks import FINITE
from gatetherm.frame.beam import beta_area
from gatetherm.frame.build import check_mesh_size
from gatetherm.frame.config import Config, parse_config
from gatetherm.frame.geometry import FrameParams, tie_depth, tie_heights, validate

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

def _number(key: str, value, typ: type):
    if typ is bool:
        if not isinstance(value, bool):
            raise InputError(key, f"expected true/false, got {value!r}")
        return value
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not FINITE.admits(value):
        raise InputError(key, f"expected a finite number, got {value!r}")
    if typ is int and not float(value).is_integer():
        raise InputError(key, f"expected a whole number, got {value!r}")
    return typ(value)


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
    from gatetherm.frame.problem import TARGETS
    from gatetherm.solvers.effects import resolve
    from gatetherm.studies.run.conditions import CONDITIONS

    sections, geometry, derived, effects, condition = {}, {}, {}, {}, None
    fields = {f.name for f in dataclasses.fields(FrameParams)}
    for key, value in overrides.items():
        head, _, name = key.rpartition(".")
        if key == "condition":
            condition = _number(key, value, int)
            if condition not in CONDITIONS:
                raise InputError(key, f"no condition {condition}", f"choose from {sorted(CONDITIONS)}")
        elif head == "geometry":
            if name not in fields:
                raise InputError(key, "unknown key", f"known keys: {', '.join(sorted(fields))}")
            geometry[name] = _number(key, value, float)
        elif head == "derived":
            if name not in DERIVED:
                raise InputError(key, "unknown derived parameter", f"known: {', '.join(DERIVED)}")
            derived[name] = _number(key, value, DERIVED[name][1])
        elif key.startswith("effect."):
            name = key[len("effect."):]
            resolve(name, TARGETS, key)
            effects[name] = _number(key, value, float)
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
