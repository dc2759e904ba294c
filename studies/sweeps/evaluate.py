"""Evaluating sweep points: the FE and beam-theory coefficients or a heating run of one
:class:`~studies.sweep.Task`, and running many tasks in this process or on an executor.

studies/sweeps/sweep.py turns a study into tasks and the records into a table.
"""
from __future__ import annotations

import dataclasses
import logging
import threading
import time
from concurrent.futures import Executor, as_completed
from typing import Any, Callable

import numpy as np

import gatetherm
from gatetherm.frame.config import Config
from gatetherm.studies.run.origin import scheme_digest
from gatetherm.studies.sweeps.sweep import Task

log = logging.getLogger(__name__)
_GMSH = threading.Lock()
"""gmsh is process-global: threaded workers (e.g. Dask's) mesh one point at a time."""


def _coefficients(model, cfg: Config) -> dict[str, float]:
    """FE (element-exact load cases, at E and at F) and beam-theory K_i, K_C in um/K, and normalised."""
    from gatetherm.frame import beam
    from gatetherm.frame.loadcases import fe_coefficients

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
    from gatetherm.studies.run.scenario import prepare, run_scenario

    record = {"key": task.key, "params": dict(task.params), "status": "skipped", "note": task.skip,
              "results": {}, "seconds": 0.0, "version": gatetherm.__version__}
    if task.skip:
        return {**record, "scheme": scheme_digest(task.config.model)}
    t0 = time.perf_counter()
    effects = dict(task.effects)
    if task.case is not None:
        from gatetherm.studies.run.case import load_case

        with _GMSH:
            case = load_case(task.case, overrides=dict(task.overrides))
        run = run_scenario(case, effects=effects)
        res = {**case_results(case, run.columns), "nodes": int(len(case.mesh.points))}
        return {**record, "status": "ok", "results": res, "seconds": round(time.perf_counter() - t0, 3),
                "scheme": scheme_digest(case.problem)}
    from gatetherm.frame.case import frame_case

    cfg, dim = task.config, task.dim
    with _GMSH:
        case = frame_case(cfg, dim, task.condition or 1)
    res: dict[str, Any] = {}
    if "run" in task.compute:
        run = run_scenario(case, effects=effects)
        model, res = run.model, _run(run.columns)
    else:
        model = prepare(case, effects).model
    if "coefficients" in task.compute:
        res.update(_coefficients(model, dataclasses.replace(cfg, model=model.config)))
    res["nodes"] = int(len(model.fmesh.points))
    record.update(status="ok", results=res, seconds=round(time.perf_counter() - t0, 3),
                  scheme=scheme_digest(task.config.model))
    return record


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
