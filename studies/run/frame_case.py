"""The paper's frame as a case file: its problem on its mesh, and a paper condition as
the schedule file, sampled finely enough (15 s) that the case run matches ``gatetherm
simulate`` to a fraction of the δ sensor's resolution."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from gatetherm import write_text_atomic
from gatetherm.geometry.mesh import FrameMesh
from gatetherm.solvers.frame import frame_problem
from gatetherm.studies.run.case import TimeSettings
from gatetherm.studies.run.casefile import case_toml
from gatetherm.studies.run.config import Config
from gatetherm.studies.run.scenario import condition_schedule
from gatetherm.studies.run.timeseries import FORMAT, TimeSeries, write_timeseries

SCHEDULE_STEP_S = 15.0
"""Sampling of the written schedule, s (the solver's finest step after a pump switch)."""


def write_frame_case(cfg: Config, fm: FrameMesh, condition: int, out: Path) -> None:
    """``out/case.toml`` (mesh ``mesh.msh`` beside it) and ``out/schedule.csv``."""
    sched = condition_schedule(condition, cfg, SCHEDULE_STEP_S)
    rows = [sched.drive(float(t)) for t in sched.times]
    cols = {"time_s": sched.times, **{k: np.array([r[k] for r in rows]) for k in rows[0]}}
    write_timeseries(out / "schedule.csv", TimeSeries(cols, {"format": FORMAT, "schedule": sched.label}))
    problem = frame_problem(cfg.model, fm)
    end = float(sched.times[-1])
    time = TimeSettings(end, 60.0, 60.0, 3600.0, Path("schedule.csv"))
    text = case_toml(problem, f"gate frame {fm.dim}-D, condition {condition}", "mesh.msh",
                     {name: name for name in fm.sensors}, time,
                     f"The paper's gate frame ({cfg.source}) as a case file, written by gatetherm mesh.\n"
                     f"Run it: gatetherm run case.toml --out DIR (δ, θ as gatetherm simulate --condition {condition}).")
    write_text_atomic(out / "case.toml", text)
