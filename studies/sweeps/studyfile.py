"""The study file (STUDY.toml) of ``gatetherm sweep``: ``[study]`` (name, and ``case`` for a case
file, or ``dim``, ``config``, ``compute``, ``fit_frame`` for the paper's frame), ``[set]``,
``[grid]`` and ``[[plot]]`` tables into a :class:`~gatetherm.studies.sweeps.sweep.Study`.
Every table and key is documented in docs/sweep.md (``tests/test_sweep_docs.py`` holds the page
to :data:`KEYS` and :data:`FREE`)."""
from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING, Any

from gatetherm import InputError
from gatetherm.files import parse_toml, read_text

if TYPE_CHECKING:
    from gatetherm.studies.sweeps.sweep import FramePoints, Study


KEYS = {"study": ("name", "case", "dim", "config", "compute", "fit_frame"), "plot": ("x", "y", "hue")}
"""The keys of the study file's tables that have fixed keys (``[[plot]]``: each of them)."""
FREE = {"set": "KEY", "grid": "KEY"}
"""The tables whose keys are the parameters a point sets (a case file's dotted key, ``effect.…``,
or the frame's), by the placeholder docs/sweep.md names them with."""
MAX_POINTS = 10_000
"""Most points a study's grid may have: about three hours of 2-D runs at a second each; planning
them (each point's model file and key) takes seconds."""
TABLES = ("study", "set", "grid", "plot")
"""The study file's tables, in the order docs/sweep.md documents them."""


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


def case_columns(case) -> tuple[str, ...]:
    """The ``run`` result columns of a case study (:func:`~gatetherm.studies.sweeps.evaluate.case_results`)."""
    from gatetherm.studies.run.simulate import column

    p, out = case.problem, []
    for r in p.relative:
        stem = column(p, ("relative", r.name))[0].removesuffix("_um")
        out += [f"{stem}_final_um", f"{stem}_max_um", f"{stem}_min_um"]
    if p.signals.delta and case.time is not None:
        out += ["first_peak_um", "first_peak_min", "second_peak_um", "swing_um"]
    out += [f"{column(p, ('T', pr.name))[0].removesuffix('_degC')}_final_degC" for pr in p.probes if "T" in pr.quantities]
    return tuple(out)


def parse_study(data: dict, source: str = "<study>", base=None, case: str | None = None,
                frame: FramePoints | None = None) -> Study:
    """Build a :class:`Study` from a parsed STUDY.toml (``base``: the frame's model it overrides, None:
    its ``[study] config`` or the paper model; ``case``: a case file it overrides instead). ``frame``: the
    frame's side of a study (:data:`gatetherm.frame.sweeppoint.FRAME`, passed in by the API); without
    it only a case study is read."""
    from gatetherm.studies.sweeps.sweep import COMPUTE, Study

    known = {t: list if t == "plot" else dict for t in TABLES}
    for key, value in data.items():
        if key not in known:
            raise InputError(key, "unknown table", f"known tables: {', '.join(sorted(known))}")
        if not isinstance(value, known[key]):
            raise InputError(key, f"expected {'[[plot]] tables' if key == 'plot' else f'a [{key}] table'}")
    head = dict(data.get("study", {}))
    for key in head:
        if key not in KEYS["study"]:
            raise InputError(f"study.{key}", "unknown key",
                             "known keys: name, case (a case file), or dim, config, compute, fit_frame (the frame)")
    if case is not None:
        return _case_study(data, head, source, case)
    dim = head.get("dim", 2)
    if dim not in (2, 3) or isinstance(dim, bool):
        raise InputError("study.dim", f"must be 2 or 3, got {dim!r}")
    compute = head.get("compute", ["coefficients"])
    if isinstance(compute, str):
        compute = [compute]
    if not isinstance(compute, list) or not compute:
        raise InputError("study.compute", f"expected a non-empty list, got {compute!r}", f"give a list of {', '.join(COMPUTE)}")
    for c in compute:
        if c not in COMPUTE:
            raise InputError("study.compute", f"unknown computation {c!r}", f"choose from {', '.join(COMPUTE)}")
    fit = head.get("fit_frame", True)
    if not isinstance(fit, bool):
        raise InputError("study.fit_frame", f"expected true/false, got {fit!r}")
    if frame is None:
        raise InputError("study.case", "a study of the paper's frame needs gatetherm.frame",
                         "run it with gatetherm.api.sweep (gatetherm sweep), or give a case")
    if base is None:
        base = frame.model(head.get("config"), "--config")
    fixed, grid = _set_and_grid(data, '"geometry.l4" = [0.2, 0.3]')
    columns = {k for k, _ in grid} | {"nodes"} | {c for k in compute for c in COMPUTE[k]}
    plots = _plots(data, columns)
    return Study(str(head.get("name", source)), dim, base, tuple(fixed.items()), tuple(grid),
                 tuple(compute), tuple(plots), fit, frame=frame)


def _case_study(data: dict, head: dict, source: str, path: str) -> Study:
    from gatetherm.studies.run.case import load_case
    from gatetherm.studies.sweeps.sweep import Study

    for key in ("dim", "config", "fit_frame"):
        if key in head:
            raise InputError(f"study.{key}", "applies to the paper's frame, not to a case", "remove it")
    compute = head.get("compute", ["run"])
    if compute not in (["run"], "run"):
        raise InputError("study.compute", f"{compute!r}: a case study computes run only", 'use compute = ["run"]')
    fixed, grid = _set_and_grid(data, '"thermal.free.film" = [6.0, 10.0]')
    case = load_case(path)
    results = case_columns(case)
    columns = {k for k, _ in grid} | {"nodes"} | set(results)
    plots = _plots(data, columns)
    return Study(str(head.get("name", source)), case.dim, None, tuple(fixed.items()), tuple(grid), ("run",),
                 tuple(plots), False, str(path), results)


def _set_and_grid(data: dict, example: str) -> tuple[dict, list]:
    """The fixed values of ``[set]`` and the swept ``(key, values)`` of ``[grid]``, checked."""
    fixed = {k: _scalar(f"set.{k}", v) for k, v in _flatten(data.get("set", {})).items()}
    grid = []
    for key, values in _flatten(data.get("grid", {})).items():
        if not isinstance(values, list) or not values:
            raise InputError(f"grid.{key}", "expected a non-empty list of values", f'e.g. "{key}" = [1, 2]')
        if key in fixed:
            raise InputError(f"set.{key}", "is also swept in [grid]", "keep it in one of the two")
        grid.append((key, tuple(_scalar(f"grid.{key}", v) for v in values)))
    if not grid:
        raise InputError("grid", "no swept key", f"add e.g. {example} under [grid]")
    points = math.prod(len(v) for _, v in grid)
    if points > MAX_POINTS:
        raise InputError("grid", f"{' x '.join(str(len(v)) for _, v in grid)} = {points} points, more than the "
                         f"budget of {MAX_POINTS}", "sweep fewer values, or split the study into several files")
    return fixed, grid


def _plots(data: dict, columns: set) -> list:
    """The ``[[plot]]`` specs, each naming table columns as x, y and (optionally) hue."""
    from gatetherm.studies.sweeps.sweep import PlotSpec

    plots = []
    for i, spec in enumerate(data.get("plot", [])):
        if not isinstance(spec, dict) or "x" not in spec or "y" not in spec:
            raise InputError(f"plot[{i + 1}]", "needs x and y", "write [[plot]] with x, y and hue")
        for key, value in spec.items():
            if key not in KEYS["plot"]:
                raise InputError(f"plot[{i + 1}].{key}", "unknown key", "known keys: x, y, hue")
            if value not in columns:
                raise InputError(f"plot[{i + 1}].{key}", f"{value!r} is not a table column",
                                 f"choose from {', '.join(sorted(columns))}")
        plots.append(PlotSpec(spec["x"], spec["y"], spec.get("hue")))
    return plots


def load_study(path, frame: FramePoints | None = None) -> Study:
    """Read a STUDY.toml; a relative ``study.config`` or ``study.case`` is taken from the study file's folder.
    ``frame``: the frame's side of a study (:data:`gatetherm.frame.sweeppoint.FRAME`, passed in by the
    API); without it only a case study is read."""
    p = Path(path)
    data = parse_toml(read_text(p, "STUDY.toml", "give a study file"), str(p), "fix the study file's syntax")
    try:
        head = data.setdefault("study", {})
        if not isinstance(head, dict):
            raise InputError("study", "expected a [study] table")
        if not isinstance(head.setdefault("name", p.stem), str):
            raise InputError("study.name", f"expected a string, got {head['name']!r}", 'e.g. name = "tie-bar height"')
        case = head.pop("case", None)
        if case is not None:
            if not isinstance(case, str):
                raise InputError("study.case", f"expected a file name, got {case!r}")
            return parse_study(data, str(p), case=str(p.parent / case))
        config = head.pop("config", None)
        if config is not None and not isinstance(config, str):
            raise InputError("study.config", f"expected a file name, got {config!r}")
        if frame is None:
            raise InputError("study.case", "a study of the paper's frame needs gatetherm.frame",
                             "run it with gatetherm.api.sweep (gatetherm sweep), or give a case")
        base = frame.model(None if config is None else p.parent / config, "study.config")
        return parse_study(data, str(p), base, frame=frame)
    except InputError as err:
        raise err.at(str(p)) from None
