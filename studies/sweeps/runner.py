"""Running sweep points: in this process, on local worker processes or on a Dask
cluster; one JSON file per finished point (``DIR/points/<key>.json``, written atomically,
so a restarted sweep recomputes nothing finished and never reads a half-written result),
and the tidy table re-assembled from them."""
from __future__ import annotations

import contextlib
import csv
import io
import json
import logging
import socket
import urllib.parse
from pathlib import Path

from gatetherm import InputError, write_text_atomic

log = logging.getLogger(__name__)

SCHEDULER_TIMEOUT_S = 20.0
"""How long to try to reach a Dask scheduler, s."""


def check_scheduler(scheduler: str) -> None:
    """Refuse a scheduler address that is not ``[tcp://]HOST:PORT`` (or tls, ws, wss) of a port that
    answers, before Dask is touched: a client that fails to connect leaves its event-loop thread
    behind, and the next sweep in the process ran 5 times slower."""
    url = urllib.parse.urlsplit(scheduler if "://" in scheduler else f"tcp://{scheduler}")  # Dask's default
    try:
        host, port = url.hostname, url.port
    except ValueError:
        host = port = None
    if url.scheme not in ("tcp", "tls", "ws", "wss") or not host or not port:
        raise InputError("--scheduler", f"{scheduler!r} is not the address of a Dask scheduler",
                         "give tcp://HOST:PORT (e.g. tcp://127.0.0.1:8786)")
    try:
        socket.create_connection((host, port), timeout=SCHEDULER_TIMEOUT_S).close()
    except OSError as err:
        raise InputError("--scheduler", f"cannot connect to {scheduler} ({err.strerror or err})",
                         "give the address of a running Dask scheduler") from None


@contextlib.contextmanager
def executor(workers: int, scheduler: str | None, n_tasks: int):
    """A concurrent.futures executor for the points, or None to run them in this process."""
    if scheduler:
        try:
            from distributed import Client
        except ImportError:
            raise InputError("--scheduler", "dask.distributed is not installed",
                             "pip install 'dask[distributed]' or leave --scheduler out") from None
        check_scheduler(scheduler)
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
    from gatetherm.studies.sweeps.pool import worker_pool

    with worker_pool(min(workers, n_tasks)) as ex:
        yield ex


def _unusable(record, key: str) -> str:
    """Why a point record read from a file cannot be used ("" if it can)."""
    if not isinstance(record, dict):
        return "not a JSON object"
    if record.get("key") != key:
        return "its key is not its file name"
    if record.get("status") not in ("ok", "skipped") or not isinstance(record.get("note"), str):
        return "no valid status and note"
    results = record.get("results")
    if not isinstance(results, dict) or not all(
            v is None or (isinstance(v, (int, float)) and not isinstance(v, bool)) for v in results.values()):
        return "its results are not a table of numbers"
    return ""


class PointStore:
    """One JSON file per finished point under ``root/points``."""

    def __init__(self, root: Path):
        self.dir = Path(root) / "points"

    def load(self, keys) -> dict[str, dict]:
        """The usable records of ``keys``; a file that is not one (truncated, binary, edited)
        is reported and left to be recomputed."""
        out = {}
        for key in keys:
            path = self.dir / f"{key}.json"
            if not path.is_file():
                continue
            try:
                record = json.loads(path.read_text(encoding="utf-8"))
                why = _unusable(record, key)
            except (OSError, ValueError) as err:  # JSONDecodeError and UnicodeDecodeError are ValueErrors
                why = f"unreadable: {err}"
            if why:
                log.warning("point file %s cannot be used (%s): the point is recomputed", path, why)
            else:
                out[key] = record
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


class PointsFailed(Exception):
    """Some points raised; the finished ones are stored, a rerun retries the rest.
    ``str(err)`` is one line: how many failed, and why the first three did."""

    def __init__(self, failed, total: int):
        def why(err: BaseException) -> str:
            text = str(err) if isinstance(err, InputError) else f"{type(err).__name__}: {err}"
            return " ".join(text.split())

        first = "; ".join(f"point {dict(t.params)}: {why(err)}" for t, err in failed[:3])
        super().__init__(f"{len(failed)} of {total} points failed ({first}); rerun to retry them")


def run_points(named_studies: dict, out: Path, workers: int, scheduler: str | None, progress=None):
    """Plan and run every study (one shared point store under ``out``); the task lists per
    study name and the records by key. Raises :class:`PointsFailed` after storing what finished."""
    from gatetherm.studies.sweeps.sweep import plan

    plans = {name: [plan(s) for s in studies] for name, studies in named_studies.items()}
    jobs = [(tasks, PointStore(out)) for lst in plans.values() for tasks in lst]
    done, failed = run_studies(jobs, workers, scheduler, progress)
    if failed:
        raise PointsFailed(failed, sum(len(tasks) for tasks, _ in jobs))
    return plans, {k: v for d in done for k, v in d.items()}
