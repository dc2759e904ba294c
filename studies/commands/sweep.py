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
import tomllib
from pathlib import Path

from geometry.errors import InputError
from geometry.files import write_text_atomic

log = logging.getLogger(__name__)


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
            client = Client(scheduler, timeout=20)
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
    from studies.sweep import execute

    done = [store.load(t.key for t in tasks) for tasks, store in jobs]
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
        for j, (tasks, store) in enumerate(jobs):  # same point in another study: share it
            if j != i and rec["key"] in {t.key for t in tasks}:
                store.save(rec)
                done[j][rec["key"]] = rec
        n_done[0] += 1
        if progress:
            progress(n_done[0], len(todo))

    with executor(workers, scheduler, len(todo)) as ex:
        failed = execute(todo, finished, ex)
    return done, failed


def run(args) -> int:
    from studies.sweep import load_study, plan, table

    study = load_study(args.study)
    tasks = plan(study)
    out = Path(args.out)
    store = PointStore(out)
    from studies.commands.simulate import Progress

    (records,), failed = run_studies([(tasks, store)], args.workers, args.scheduler,
                                     Progress(f"sweep {study.name}"))
    columns, rows = table(tasks, records)
    write_table(out / "table.csv", columns, rows)
    write_text_atomic(out / "study.json", json.dumps(
        {"name": study.name, "dim": study.dim, "config": study.base.source, "compute": list(study.compute),
         "set": dict(study.fixed), "grid": {k: list(v) for k, v in study.grid}}, indent=2) + "\n")
    n_skip = sum(r["status"] == "skipped" for r in rows)
    print(f"wrote {out / 'table.csv'}: {len(rows)} points, {len(rows) - n_skip - len(failed)} computed, "
          f"{n_skip} skipped (frame cannot be built), {len(failed)} failed")
    if not args.no_plots and study.plots:
        from validation.sweep_plots import plot_xy

        for spec in study.plots:
            path = out / f"{spec.y}_vs_{spec.x}{'_by_' + spec.hue if spec.hue else ''}.png".replace("/", "_")
            plot_xy(rows, spec.x, spec.y, spec.hue, path, study.name)
            print(f"wrote {path}")
    for t, err in failed:
        print(f"failed: {dict(t.params)}: {err}")
    return 1 if failed else 0
