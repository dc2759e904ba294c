"""Parametric sweeps: a grid of model parameters, evaluated point by point.

A study is data: a base model, fixed overrides (``set``), a grid whose cartesian
product gives the points, the dimension, and what to compute at each point.
Parameter keys are

* ``<section>.<field>`` for the model-file sections ``geometry``, ``mesh``, ``material``,
  ``material.tie_bar``, ``thermal``, ``supply`` and ``model`` (see studies/config.py);
* ``condition``: the paper's condition 1-3 (for the ``run`` computation);
* ``effect.<name>``: a catalogue effect (solvers/effects.py) in its unit;
* ``derived.<name>``: the parameters of :data:`DERIVED`, applied after the direct
  overrides in the table's order (e.g. ``derived.beta`` sets ``A_C`` from eq (26)).

With ``fit_frame`` (default on), the column is raised to hold every tie bar
(``column_height >= l4 + t_C/2``) and, in 3-D, ``t_C`` is raised until the tie-bar
depth ``A_C/t_C`` fits behind the arms. A point whose frame still cannot be built
(e.g. a 2-D tie bar overlapping the arms) is a "skipped" row, not an error.

Every point has a key, a hash of everything its result depends on, so results
can be stored per point and a stopped sweep resumes without recomputing
anything finished (studies/commands/sweep.py does the files and the processes).
"""
from __future__ import annotations

import dataclasses
import hashlib
import itertools
import json
import logging
import time
from concurrent.futures import Executor, as_completed
from dataclasses import dataclass
from typing import Any, Callable

import numpy as np

from geometry.errors import InputError
from geometry.frame import FrameParams, tie_depth, tie_heights, validate
from studies.config import Config, parse_config

log = logging.getLogger(__name__)

SECTIONS = ("geometry", "mesh", "material", "material.tie_bar", "thermal", "supply", "model")
#: What a point can compute, with the result columns each adds (besides "nodes").
COMPUTE = {
    "coefficients": ("Ki_E_fe", "Kc_E_fe", "Ki_F_fe", "Kc_F_fe", "Ki_theory", "Kc_theory",
                     "Ki_norm_fe", "Kc_norm_fe", "Ki_norm_theory", "Kc_norm_theory", "Ki_scale",
                     "Kc_scale", "l_over_l4", "l_over_h", "beta"),
    "run": ("first_peak_um", "first_peak_min", "second_peak_um", "swing_um", "delta_max_um",
            "delta_min_um", "theta_AB_max_K", "theta_C_end_K"),
}
PINHOLE = 0.003
"""Side of the cavity left by ``derived.tank_cavity = false``, m."""


@dataclass(frozen=True)
class PlotSpec:
    """One figure of a study: ``y`` against ``x``, one line per value of ``hue``."""

    x: str
    y: str
    hue: str | None = None


@dataclass(frozen=True)
class Study:
    """A parametric study (the STUDY.toml file mirrors it)."""

    name: str
    dim: int
    base: Config
    fixed: tuple[tuple[str, Any], ...]
    """Overrides applied at every point, (key, value)."""
    grid: tuple[tuple[str, tuple], ...]
    """Swept keys with their values, in file order; the points are the cartesian product."""
    compute: tuple[str, ...]
    plots: tuple[PlotSpec, ...] = ()
    fit_frame: bool = True
    """Raise the column (and the 3-D tie-bar height t_C) so that every tie bar fits."""


@dataclass(frozen=True)
class Task:
    """Everything one point needs, picklable for worker processes."""

    key: str
    params: tuple[tuple[str, Any], ...]
    """The grid values of this point (its table columns)."""
    config: Config
    dim: int
    compute: tuple[str, ...]
    condition: int | None
    effects: tuple[tuple[str, float], ...]
    skip: str = ""
    """Why the frame cannot be built ("" = buildable)."""


# --- derived parameters ---------------------------------------------------------------

def _l_over_h(cfg: Config, v: float) -> dict:
    p = cfg.model.frame
    s = p.l / v / p.h
    return {"h": p.l / v, "tank_wall": p.tank_wall * s, "tank_width": p.tank_width * s}


def _beta(cfg: Config, v: float) -> dict:
    p, m = cfg.model.frame, cfg.model
    E_C = (m.tie_material or m.material).E
    I = p.depth * p.h ** 3 / 12.0
    return {"A_C": 3.0 * m.material.E * I * p.l_C / (v * E_C * p.l ** 3)}


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
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not np.isfinite(value):
        raise InputError(key, f"expected a number, got {value!r}")
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
    from solvers.effects import CATALOGUE
    from studies.conditions import CONDITIONS

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
        elif head == "effect":
            if name not in CATALOGUE:
                raise InputError(key, "unknown effect", f"known: {', '.join(CATALOGUE)}")
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
    return cfg, condition, tuple(sorted(effects.items())), skip


def point_key(cfg: Config, dim: int, compute, condition, effects) -> str:
    """Hash of everything a point's result depends on: the final model (without the
    thermal and supply data when nothing is run), dimension, computations, condition, effects."""
    model = dataclasses.asdict(cfg.model)
    data = {"model": model, "supply": dataclasses.asdict(cfg.supply), "effects": cfg.effects}
    if "run" not in compute:
        for name in ("thermal", "source", "joint_conductance"):
            model.pop(name, None)
        data.pop("supply")
        condition = None
    blob = json.dumps({**data, "dim": dim, "compute": sorted(compute), "condition": condition,
                       "effect_values": effects}, sort_keys=True, default=repr)
    return hashlib.sha256(blob.encode()).hexdigest()[:20]


def plan(study: Study) -> list[Task]:
    """The points of ``study`` in grid order (last key varying fastest); bad keys raise."""
    keys = [k for k, _ in study.grid]
    tasks = []
    for values in itertools.product(*(v for _, v in study.grid)):
        params = tuple(zip(keys, values))
        overrides = {**dict(study.fixed), **dict(params)}
        cfg, cond, eff, skip = configure(study.base, overrides, study.dim, study.fit_frame)
        if "run" in study.compute and cond is None:
            raise InputError("condition", "the 'run' computation needs a heating condition",
                             "add condition = [1, 2, 3] to [grid] or condition = 1 to [set]")
        key = point_key(cfg, study.dim, study.compute, cond, eff)
        tasks.append(Task(key, params, cfg, study.dim, study.compute, cond, eff, skip))
    if tasks and all(t.skip for t in tasks):
        raise InputError(study.name, f"no point of the study can be built ({tasks[0].skip})",
                         "change the grid")
    return tasks


# --- the study file -------------------------------------------------------------------

def _flatten(table: dict, prefix: str = "") -> dict[str, Any]:
    """``{"geometry": {"l4": v}}`` and ``{"geometry.l4": v}`` both give ``{"geometry.l4": v}``."""
    out = {}
    for key, value in table.items():
        if isinstance(value, dict):
            out.update(_flatten(value, f"{prefix}{key}."))
        else:
            out[f"{prefix}{key}"] = value
    return out


def _scalar(key: str, value):
    if isinstance(value, (bool, int, float, str)):
        return value
    raise InputError(key, f"expected a number, true/false or a string, got {value!r}")


def parse_study(data: dict, source: str = "<study>", base: Config | None = None) -> Study:
    """Build a :class:`Study` from a parsed STUDY.toml (``base``: the model it overrides)."""
    from studies.config import load_config

    known = {"study", "set", "grid", "plot"}
    for key in data:
        if key not in known:
            raise InputError(key, "unknown table", f"known tables: {', '.join(sorted(known))}")
    head = dict(data.get("study", {}))
    for key in head:
        if key not in ("name", "dim", "config", "compute", "fit_frame"):
            raise InputError(f"study.{key}", "unknown key",
                             "known keys: name, dim, config, compute, fit_frame")
    dim = head.get("dim", 2)
    if dim not in (2, 3) or isinstance(dim, bool):
        raise InputError("study.dim", f"must be 2 or 3, got {dim!r}")
    compute = head.get("compute", ["coefficients"])
    if isinstance(compute, str):
        compute = [compute]
    for c in compute:
        if c not in COMPUTE:
            raise InputError("study.compute", f"unknown computation {c!r}", f"choose from {', '.join(COMPUTE)}")
    fit = head.get("fit_frame", True)
    if not isinstance(fit, bool):
        raise InputError("study.fit_frame", f"expected true/false, got {fit!r}")
    if base is None:
        base = load_config(head.get("config"))
    fixed = {k: _scalar(f"set.{k}", v) for k, v in _flatten(data.get("set", {})).items()}
    grid = []
    for key, values in _flatten(data.get("grid", {})).items():
        if not isinstance(values, list) or not values:
            raise InputError(f"grid.{key}", "expected a non-empty list of values", f'e.g. "{key}" = [1, 2]')
        if key in fixed:
            raise InputError(f"set.{key}", "is also swept in [grid]", "keep it in one of the two")
        grid.append((key, tuple(_scalar(f"grid.{key}", v) for v in values)))
    if not grid:
        raise InputError("grid", "no swept parameter", 'add e.g. "geometry.l4" = [0.2, 0.3] under [grid]')
    columns = {k for k, _ in grid} | {"nodes"} | {c for k in compute for c in COMPUTE[k]}
    plots = []
    for i, spec in enumerate(data.get("plot", [])):
        if not isinstance(spec, dict):
            raise InputError(f"plot[{i + 1}]", "expected a table", "write [[plot]] with x, y and hue")
        for key, value in spec.items():
            if key not in ("x", "y", "hue"):
                raise InputError(f"plot[{i + 1}].{key}", "unknown key", "known keys: x, y, hue")
            if value not in columns:
                raise InputError(f"plot[{i + 1}].{key}", f"{value!r} is not a table column",
                                 f"choose from {', '.join(sorted(columns))}")
        if "x" not in spec or "y" not in spec:
            raise InputError(f"plot[{i + 1}]", "needs x and y")
        plots.append(PlotSpec(spec["x"], spec["y"], spec.get("hue")))
    return Study(str(head.get("name", source)), dim, base, tuple(fixed.items()), tuple(grid),
                 tuple(compute), tuple(plots), fit)


def load_study(path) -> Study:
    """Read a STUDY.toml; a relative ``study.config`` is taken from the study file's folder."""
    import tomllib
    from pathlib import Path

    from studies.config import load_config

    p = Path(path)
    if not p.is_file():
        raise InputError("STUDY.toml", f"no such file '{path}'", "give a study file")
    try:
        data = tomllib.loads(p.read_text(encoding="utf-8"))
    except tomllib.TOMLDecodeError as err:
        raise InputError(str(p), f"not valid TOML ({err})") from None
    data.setdefault("study", {}).setdefault("name", p.stem)
    config = data["study"].pop("config", None)
    base = load_config(None if config is None else p.parent / config)
    return parse_study(data, str(p), base)


# --- evaluation ---------------------------------------------------------------------------

def _coefficients(model, cfg: Config) -> dict[str, float]:
    """FE (element-exact load cases, at E and at F) and beam-theory K_i, K_C in um/K, and normalised."""
    from solvers import beam
    from solvers.reduced import exact_coefficients
    from studies.compensator import theory_coefficients

    p, m = cfg.model.frame, cfg.model
    tie = m.tie_material or m.material
    c = exact_coefficients(model)
    ki_th, kc_th = theory_coefficients(m)
    ki_s = float(beam.ki_scale(m.material.alpha, p.l, p.h)) * 1e6
    kc_s = float(beam.kc_scale(tie.alpha, p.l_C)) * 1e6
    out = {"Ki_E_fe": c.Ki_E * 1e6, "Kc_E_fe": c.Kc_E * 1e6, "Ki_F_fe": c.Ki_F * 1e6,
           "Kc_F_fe": c.Kc_F * 1e6, "Ki_theory": ki_th, "Kc_theory": kc_th}
    out.update({"Ki_norm_fe": out["Ki_E_fe"] / ki_s, "Kc_norm_fe": out["Kc_E_fe"] / kc_s,
                "Ki_norm_theory": ki_th / ki_s, "Kc_norm_theory": kc_th / kc_s,
                "Ki_scale": ki_s, "Kc_scale": kc_s, "l_over_l4": p.l / p.l4, "l_over_h": p.l / p.h,
                "beta": float(beam.beta(p.depth * p.h ** 3 / 12.0 * m.material.E / tie.E, p.l_C,
                                        p.A_C, p.l))})
    return out


def _run(model, task: Task, drive, effects) -> dict[str, float | None]:
    from studies.conditions import CONDITIONS
    from studies.simulate import delta_figures, run_model, sample_times

    cols = effects.observe(run_model(model, drive, sample_times(CONDITIONS[task.condition].duration)).columns)
    d = cols["delta_um"]
    dab = cols["theta_A_degC"] - cols["theta_B_degC"]
    return {**delta_figures(cols["time_s"], d), "delta_max_um": float(d.max()),
            "delta_min_um": float(d.min()), "theta_AB_max_K": float(np.max(dab - dab[0])),
            "theta_C_end_K": float(cols["theta_C_degC"][-1] - cols["theta_C_degC"][0])}


def evaluate(task: Task) -> dict[str, Any]:
    """The result record of one point: key, params, status, note, results, seconds."""
    record = {"key": task.key, "params": dict(task.params), "status": "skipped", "note": task.skip,
              "results": {}, "seconds": 0.0}
    if task.skip:
        return record
    from solvers.effects import ActiveEffects, apply_effects
    from solvers.model import build_model
    from studies.conditions import CONDITIONS, condition_drive

    t0 = time.perf_counter()
    eff = ActiveEffects(dict(task.effects))
    cond = CONDITIONS[task.condition] if task.condition else CONDITIONS[1]
    model_cfg, drive = apply_effects(task.config.model, condition_drive(cond, task.config.supply),
                                     eff, task.dim)
    model = build_model(model_cfg, task.dim)
    res: dict[str, Any] = {"nodes": int(len(model.fmesh.points))}
    if "coefficients" in task.compute:
        res.update(_coefficients(model, dataclasses.replace(task.config, model=model_cfg)))
    if "run" in task.compute:
        res.update(_run(model, task, drive, eff))
    record.update(status="ok", results=res, seconds=round(time.perf_counter() - t0, 3))
    return record


def execute(tasks: list[Task], on_result: Callable[[dict], None], executor: Executor | None = None
            ) -> list[tuple[Task, BaseException]]:
    """Evaluate ``tasks`` (serially without an executor) and hand every record to
    ``on_result`` as soon as it is done; returns the points that failed, with the error."""
    failed = []
    if executor is None:
        for t in tasks:
            try:
                on_result(evaluate(t))
            except InputError:
                raise
            except Exception as err:  # keep going: the other points are still worth having
                log.error("point %s failed: %s", dict(t.params), err)
                failed.append((t, err))
        return failed
    futures = {executor.submit(evaluate, t): t for t in tasks}
    for fut in as_completed(futures):
        err = fut.exception()
        if err is None:
            on_result(fut.result())
        else:
            log.error("point %s failed: %s", dict(futures[fut].params), err)
            failed.append((futures[fut], err))
    return failed


def table(tasks: list[Task], records: dict[str, dict]) -> tuple[list[str], list[dict]]:
    """Columns and rows (grid order) of the tidy table: parameters, status, note, results.
    Points without a record yet are rows with status "pending"."""
    rows, result_cols = [], {}
    for t in tasks:
        rec = records.get(t.key, {"status": "pending", "note": "", "results": {}})
        rows.append({**dict(t.params), "status": rec["status"], "note": rec["note"], **rec["results"]})
        result_cols.update(dict.fromkeys(rec["results"]))
    params = [k for k, _ in tasks[0].params] if tasks else []
    return params + ["status", "note"] + list(result_cols), rows
