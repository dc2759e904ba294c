"""Parametric sweeps: a grid of model parameters, evaluated point by point.

A study is data: a base model, fixed overrides (``set``), a grid whose cartesian
product gives the points, the dimension, and what to compute at each point.

The base is a case file (``[study] case``) or the paper's frame (a model file). On a case,
a key is any key of the case file by dotted path (``materials.column.k``,
``thermal.free.film``, ``sources.spindle.power``, ``mesh.parameters.h``, ``time.schedule``)
or ``effect.<key>`` (an effect, ``gatetherm diagnose --case … --list-effects``), and the
point computes ``run``: the case run on its own schedule, the final, largest and smallest
value of every relative displacement and the final temperature of every probe. On the
frame, keys are

* ``<section>.<field>`` for the model-file sections ``geometry``, ``mesh``, ``material``,
  ``material.tie_bar``, ``thermal``, ``supply`` and ``model`` (see core/frame/config.py);
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
anything finished (studies/sweeps/runner.py does the files and the processes).
Evaluating the points is in studies/sweeps/evaluate.py. A study of the frame has its points made
and evaluated by the frame (:class:`FramePoints`: :data:`gatetherm.frame.sweeppoint.FRAME`, passed
in by the API); nothing here imports the frame.
"""
from __future__ import annotations

import dataclasses
import hashlib
import itertools
import json
from dataclasses import dataclass
from typing import Any, Protocol

from gatetherm import InputError
import gatetherm
from gatetherm.checks import FINITE
from gatetherm.studies.run.origin import scheme_digest

#: What a point can compute, with the result columns each adds (besides "nodes").
COMPUTE = {
    "coefficients": ("Ki_E_fe", "Kc_E_fe", "Ki_F_fe", "Kc_F_fe", "Ki_theory", "Kc_theory",
                     "Ki_norm_fe", "Kc_norm_fe", "Ki_norm_theory", "Kc_norm_theory", "Ki_scale",
                     "Kc_scale", "l_over_l4", "l_over_h", "beta"),
    "run": ("first_peak_um", "first_peak_min", "second_peak_um", "swing_um", "delta_max_um",
            "delta_min_um", "theta_AB_max_K", "theta_C_end_K"),
}
MADE_BY = ("version", "scheme")
"""Table columns naming what computed a point: gatetherm version and scheme digest
(:func:`~gatetherm.studies.run.origin.scheme_digest`), both part of the point key."""


def number(key: str, value, typ: type):
    """``value`` of the study key ``key`` as ``typ`` (bool, int or float), else InputError."""
    if typ is bool:
        if not isinstance(value, bool):
            raise InputError(key, f"expected true/false, got {value!r}")
        return value
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not FINITE.admits(value):
        raise InputError(key, f"expected a finite number, got {value!r}")
    if typ is int and not float(value).is_integer():
        raise InputError(key, f"expected a whole number, got {value!r}")
    return typ(value)


class FramePoints(Protocol):
    """The paper frame's side of a study (:data:`gatetherm.frame.sweeppoint.FRAME`): its model
    file, its keys applied to it, its points evaluated."""

    def model(self, path, key: str):
        """The frame's model file at ``path`` (None: the shipped paper model); ``key`` names it in errors."""

    def point(self, study: "Study", params: tuple, overrides: dict) -> "Task":
        """The point of ``study`` at ``overrides`` (``params``: its grid values), its keys checked."""

    def evaluate(self, task: "Task", record: dict) -> dict:
        """``record`` (key, params, status …) completed with the point's results."""


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
    base: Any
    """The paper frame's model file (:class:`gatetherm.frame.config.Config`; None: a study of :attr:`case`)."""
    fixed: tuple[tuple[str, Any], ...]
    """Overrides applied at every point, (key, value)."""
    grid: tuple[tuple[str, tuple], ...]
    """Swept keys with their values, in file order; the points are the cartesian product."""
    compute: tuple[str, ...]
    plots: tuple[PlotSpec, ...] = ()
    fit_frame: bool = True
    """Raise the column (and the 3-D tie-bar height t_C) so that every tie bar fits."""
    case: str | None = None
    """A case file whose keys the grid sets (instead of the frame's :attr:`base`)."""
    columns: tuple[str, ...] = ()
    """The result columns of a case study's ``run`` (its relative displacements and probes)."""
    frame: FramePoints | None = None
    """A study of the frame: who makes and evaluates its points (:data:`gatetherm.frame.sweeppoint.FRAME`)."""


@dataclass(frozen=True)
class Task:
    """Everything one point needs, picklable for worker processes."""

    key: str
    params: tuple[tuple[str, Any], ...]
    """The grid values of this point (its table columns)."""
    config: Any
    """A frame point's model file (None: a case point)."""
    dim: int
    compute: tuple[str, ...]
    condition: int | None
    effects: tuple[tuple[str, float], ...]
    skip: str = ""
    """Why the frame cannot be built ("" = buildable)."""
    case: str | None = None
    """A case study's case file."""
    overrides: tuple[tuple[str, Any], ...] = ()
    """A case study's keys of the case file at this point."""
    frame: FramePoints | None = None
    """A frame point: who evaluates it (the study's :attr:`Study.frame`)."""



def case_point(study: Study, base, overrides: dict[str, Any]) -> Task:
    """A point of a case study on its ``base`` case: its keys checked by reading the case with
    them (meshing again when a key of ``[mesh]`` changes), and its key: the digest of the case
    file, the files it names, the overrides, effects, computations and the gatetherm version."""
    from gatetherm.solvers.effects import resolve

    effects, keys = {}, {}
    for key, value in overrides.items():
        if key.startswith("effect."):
            effects[key[len("effect."):]] = number(key, value, float)
        else:
            keys[key] = value
    case = base.with_overrides(keys)
    for k in effects:
        resolve(k, case.targets, f"effect.{k}")
    digest = hashlib.sha256()
    for f in sorted(case_files(case)):
        digest.update(f.read_bytes())
    blob = json.dumps({"keys": keys, "effects": effects, "compute": sorted(study.compute), "files": digest.hexdigest(),
                       "version": gatetherm.__version__, "scheme": scheme_digest(case.problem)}, sort_keys=True,
                      default=repr)
    return Task(hashlib.sha256(blob.encode()).hexdigest()[:20], (), None, case.dim, study.compute, None,
                tuple(sorted(effects.items())), case=study.case, overrides=tuple(keys.items()))


def case_files(case) -> list:
    """The files a case reads: the case file, its mesh or geometry, its schedule."""
    from pathlib import Path

    doc = case.origin.document
    base = Path(case.origin.path).parent
    files = [Path(case.origin.path), base / doc["mesh"]["file"]]
    if case.time is not None and case.time.schedule is not None:
        files.append(Path(case.time.schedule))
    return [f for f in files if f.is_file()]


def plan(study: Study) -> list[Task]:
    """The points of ``study`` in grid order (last key varying fastest); bad keys raise."""
    from gatetherm.studies.run.case import load_case

    keys = [k for k, _ in study.grid]
    tasks = []
    base = load_case(study.case) if study.case is not None else None
    for values in itertools.product(*(v for _, v in study.grid)):
        params = tuple(zip(keys, values))
        overrides = {**dict(study.fixed), **dict(params)}
        if base is not None:
            task = case_point(study, base, overrides)
            tasks.append(dataclasses.replace(task, params=params))
            continue
        if study.frame is None:
            raise InputError(study.name, "a study of the paper's frame needs the frame's points",
                             "give Study(frame=gatetherm.frame.sweeppoint.FRAME), or run it with gatetherm.api.sweep")
        tasks.append(study.frame.point(study, params, overrides))
    if tasks and all(t.skip for t in tasks):
        raise InputError(study.name, f"no point of the study can be built ({tasks[0].skip})",
                         "change the grid")
    return tasks


def table(tasks: list[Task], records: dict[str, dict], results=()) -> tuple[list[str], list[dict]]:
    """Columns and rows (grid order) of the tidy table: parameters, status, note, then the
    results in the order of :data:`COMPUTE` (a case study's: ``results``). Points without a record
    are "pending" rows."""
    rows = []
    for t in tasks:
        rec = records.get(t.key, {"status": "pending", "note": "", "results": {}})
        made = {k: rec.get(k, "") for k in MADE_BY}
        rows.append({**dict(t.params), "status": rec["status"], "note": rec["note"], **rec["results"], **made})
    params = [k for k, _ in tasks[0].params] if tasks else []
    results = ["nodes"] + ([c for k in (tasks[0].compute if tasks else ()) for c in COMPUTE[k]]
                           if not (tasks and tasks[0].case) else list(results))
    extra = [k for r in rows for k in r if k not in params + results + ["status", "note", *MADE_BY]]
    return params + ["status", "note"] + results + list(dict.fromkeys(extra)) + list(MADE_BY), rows
