"""Evaluating sweep points: a case point's run (a frame point is evaluated by the frame:
:func:`gatetherm.frame.sweeppoint.evaluate_point`), and running many tasks in this process or on
an executor.

studies/sweeps/sweep.py turns a study into tasks and the records into a table.
"""
from __future__ import annotations

import logging
import threading
import time
from concurrent.futures import Executor, as_completed
from typing import Any, Callable

import gatetherm
from gatetherm.studies.run.origin import scheme_digest
from gatetherm.studies.sweeps.sweep import Task

log = logging.getLogger(__name__)
GMSH_LOCK = threading.Lock()
"""gmsh is process-global: threaded workers (e.g. Dask's) mesh one point at a time."""


def case_results(case, cols: dict) -> dict[str, float]:
    """A case study's ``run`` results: the final, largest and smallest value of every relative
    displacement (µm), δ's figures where the case has a δ, and the final temperature of every probe."""
    from gatetherm.studies.run.simulate import column, delta_figures

    p, out = case.problem, {}
    for r in p.relative:
        name, _ = column(p, ("relative", r.name))
        stem = name.removesuffix("_um")
        out.update({f"{stem}_final_um": float(cols[name][-1]), f"{stem}_max_um": float(cols[name].max()),
                    f"{stem}_min_um": float(cols[name].min())})
    if "delta_um" in cols and len(cols["time_s"]) > 1:
        out.update(delta_figures(cols["time_s"], cols["delta_um"]))
    for pr in p.probes:
        name, _ = column(p, ("T", pr.name))
        if name in cols:
            out[f"{name.removesuffix('_degC')}_final_degC"] = float(cols[name][-1])
    return out


def evaluate(task: Task) -> dict[str, Any]:
    """The result record of one point: key, params, status, note, results, seconds."""
    from gatetherm.studies.run.scenario import run_scenario

    record = {"key": task.key, "params": dict(task.params), "status": "skipped", "note": task.skip,
              "results": {}, "seconds": 0.0, "version": gatetherm.__version__}
    if task.case is None:  # a point of the paper's frame: the frame evaluates it
        return task.frame.evaluate(task, record)
    from gatetherm.studies.run.case import load_case

    t0 = time.perf_counter()
    with GMSH_LOCK:
        case = load_case(task.case, overrides=dict(task.overrides))
    run = run_scenario(case, effects=dict(task.effects))
    res = {**case_results(case, run.columns), "nodes": int(len(case.mesh.points))}
    return {**record, "status": "ok", "results": res, "seconds": round(time.perf_counter() - t0, 3),
            "scheme": scheme_digest(case.problem)}


def execute(tasks: list[Task], on_result: Callable[[dict], None], executor: Executor | None = None
            ) -> list[tuple[Task, BaseException]]:
    """Evaluate ``tasks`` (in this process without an executor) and hand every record to
    ``on_result`` as soon as it is done; returns the points that failed, with the error
    (the other points are still worth having)."""
    failed = []

    def fail(t: Task, err: BaseException) -> None:
        log.info("point %s failed: %s", dict(t.params), err)  # the caller reports the failures in one line
        failed.append((t, err))

    if executor is None:
        for t in tasks:
            try:
                rec = evaluate(t)
            except Exception as err:
                fail(t, err)
                continue
            on_result(rec)
        return failed
    futures = {executor.submit(evaluate, t): t for t in tasks}
    for fut in as_completed(futures):
        if fut.exception() is None:
            on_result(fut.result())
        else:
            fail(futures[fut], fut.exception())
    return failed
