"""``gatetherm sweep``: run a parametric study file; one tidy table and the plots it asks for.

Files: ``DIR/points/<key>.json`` (one per finished point, written atomically, so a
restarted sweep recomputes nothing finished and never reads a half-written result),
``DIR/table.csv`` (re-assembled from the point files after every run), ``DIR/study.json``
and the PNGs of the study's ``[[plot]]`` tables.
"""
from __future__ import annotations

import contextlib
import csv
import io
import json
import logging
import os
import sys
import tomllib
from pathlib import Path
from typing import TYPE_CHECKING, Any

from gatetherm import InputError
from gatetherm import write_text_atomic

if TYPE_CHECKING:
    from gatetherm.studies.run.config import Config
    from gatetherm.studies.sweeps.sweep import Study

log = logging.getLogger(__name__)

SCHEDULER_TIMEOUT_S = 20.0
"""How long to try to reach a Dask scheduler, s."""


# --- the study file ---------------------------------------------------------------------

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
    from gatetherm.studies.run.config import load_config
    from gatetherm.studies.sweeps.sweep import COMPUTE, PlotSpec, Study

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
    p = Path(path)
    if not p.is_file():
        raise InputError("STUDY.toml", f"no such file '{path}'", "give a study file")
    try:
        data = tomllib.loads(p.read_text(encoding="utf-8"))
    except tomllib.TOMLDecodeError as err:
        raise InputError(str(p), f"not valid TOML ({err})") from None
    from gatetherm.studies.run.config import load_config

    data.setdefault("study", {}).setdefault("name", p.stem)
    config = data["study"].pop("config", None)
    base = load_config(None if config is None else p.parent / config)
    return parse_study(data, str(p), base)


def register(sub) -> None:
    p = sub.add_parser("sweep", help="run a parametric study (grid of parameters); table and plots",
                       description="Evaluate every point of the grid in STUDY.toml (see "
                       "studies/data/example_sweep.toml); resumes where a stopped run left off.")
    p.add_argument("study", metavar="STUDY.toml", help="study file")
    p.add_argument("--out", required=True, metavar="DIR", help="output directory")
    add_parallel_options(p)
    p.add_argument("--no-plots", action="store_true", help="write the table only")
    p.set_defaults(func=run)


def add_parallel_options(p) -> None:
    """``--workers`` and ``--scheduler``, shared by the commands that run many points."""
    p.add_argument("--workers", type=int, default=os.cpu_count() or 1, metavar="N",
                   help="local worker processes (default: the CPU count; 1 = in this process)")
    p.add_argument("--scheduler", metavar="ADDRESS",
                   help="run the points on an existing Dask cluster, e.g. tcp://10.0.0.5:8786")


@contextlib.contextmanager
def executor(workers: int, scheduler: str | None, n_tasks: int):
    """A concurrent.futures executor for the points, or None to run them in this process."""
    if scheduler:
        try:
            from distributed import Client
        except ImportError:
            raise InputError("--scheduler", "dask.distributed is not installed",
                             "pip install 'dask[distributed]' or leave --scheduler out") from None
        try:
            client = Client(scheduler, timeout=SCHEDULER_TIMEOUT_S)
        except (OSError, TimeoutError, ValueError) as err:
            raise InputError("--scheduler", f"cannot connect to {scheduler} ({err})",
                             "give the address of a running Dask scheduler") from None
        try:
            yield client.get_executor()
        finally:
            client.close()
        return
    if workers < 1:
        raise InputError("--workers", f"must be >= 1, got {workers}")
    if workers == 1 or n_tasks <= 1:
        yield None
        return
    from concurrent.futures import ProcessPoolExecutor

    with ProcessPoolExecutor(max_workers=min(workers, n_tasks)) as ex:
        yield ex


class PointStore:
    """One JSON file per finished point under ``root/points``."""

    def __init__(self, root: Path):
        self.dir = Path(root) / "points"

    def load(self, keys) -> dict[str, dict]:
        out = {}
        for key in keys:
            path = self.dir / f"{key}.json"
            if path.is_file():
                try:
                    out[key] = json.loads(path.read_text(encoding="utf-8"))
                except (json.JSONDecodeError, UnicodeDecodeError):
                    log.warning("unreadable point file %s: it will be recomputed", path)
        return out

    def save(self, record: dict) -> None:
        write_text_atomic(self.dir / f"{record['key']}.json", json.dumps(record, indent=1, sort_keys=True) + "\n")


def _cell(v) -> str:
    if v is None:
        return ""
    return repr(float(v)) if isinstance(v, float) else str(v)


def write_table(path: Path, columns: list[str], rows: list[dict]) -> None:
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(columns)
    for r in rows:
        w.writerow([_cell(r.get(c)) for c in columns])
    write_text_atomic(path, buf.getvalue())


def run_studies(jobs, workers: int, scheduler: str | None, progress=None):
    """Evaluate the unfinished points of several ``(tasks, store)`` jobs in one pool.
    Returns ``(records per job, failures)``."""
    from gatetherm.studies.sweeps.evaluate import execute

    done = [store.load(t.key for t in tasks) for tasks, store in jobs]
    keys = [{t.key for t in tasks} for tasks, _ in jobs]
    todo, owner = [], {}
    for i, (tasks, store) in enumerate(jobs):
        for t in tasks:
            if t.key not in done[i] and t.key not in owner:
                todo.append(t)
                owner[t.key] = i
    n_done = [0]
    log.info("%d points to compute, %d already done", len(todo), sum(map(len, done)))

    def finished(rec: dict) -> None:
        i = owner[rec["key"]]
        jobs[i][1].save(rec)
        done[i][rec["key"]] = rec
        for j, (_, store) in enumerate(jobs):  # the same point in another study: share it
            if j != i and rec["key"] in keys[j]:
                if store.dir != jobs[i][1].dir:
                    store.save(rec)
                done[j][rec["key"]] = rec
        n_done[0] += 1
        if progress:
            progress(n_done[0], len(todo))

    with executor(workers, scheduler, len(todo)) as ex:
        failed = execute(todo, finished, ex)
    return done, failed


def run(args) -> int:
    from gatetherm.studies.sweeps.sweep import plan, table

    study = load_study(args.study)
    tasks = plan(study)
    out = Path(args.out)
    store = PointStore(out)
    from gatetherm.studies.cli.simulate import Progress

    (records,), failed = run_studies([(tasks, store)], args.workers, args.scheduler,
                                     Progress(f"sweep {study.name}"))
    columns, rows = table(tasks, records)
    write_table(out / "table.csv", columns, rows)
    write_text_atomic(out / "study.json", json.dumps(
        {"name": study.name, "dim": study.dim, "config": study.base.source, "compute": list(study.compute),
         "set": dict(study.fixed), "grid": {k: list(v) for k, v in study.grid}}, indent=2) + "\n")
    n_skip = sum(r["status"] == "skipped" for r in rows)
    print(f"wrote {out / 'table.csv'}: {len(rows)} points, {len(rows) - n_skip - len(failed)} done, "
          f"{n_skip} skipped (frame cannot be built), {len(failed)} failed")
    if not args.no_plots and study.plots:
        from gatetherm.validation.plots.sweep import plot_xy

        for spec in study.plots:
            path = out / f"{spec.y}_vs_{spec.x}{'_by_' + spec.hue if spec.hue else ''}.png".replace("/", "_")
            others = [k for k, _ in study.grid if k not in (spec.x, spec.hue)]
            plot_xy(rows, spec.x, spec.y, spec.hue, path, study.name, lines_by=others)
            print(f"wrote {path}")
    for t, err in failed:
        print(f"gatetherm: point {dict(t.params)} failed: {err}", file=sys.stderr)
    return 1 if failed else 0
