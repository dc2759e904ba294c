"""What drives a run and when it is sampled: a :class:`Schedule`.

A schedule is a drive (the inputs a case's values read, by name, as a function of time) and
the sample times. It comes from a case's ``[time]`` settings and schedule file, from one of
the paper's conditions (the oil supply unit's set points: :mod:`gatetherm.frame.conditions`),
or from the inputs recorded in a time series (a measured run replayed at its own sample times).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Mapping

import numpy as np

from gatetherm import InputError
from gatetherm.solvers.heat import Drive
from gatetherm.studies.run.conditions import TableDrive, filled
from gatetherm.studies.run.simulate import sample_times
from gatetherm.studies.run.timeseries import TimeSeries, check_steps, read_timeseries


@dataclass(frozen=True)
class Schedule:
    """What drives a run and when it is sampled."""

    drive: Drive
    """Model inputs as a function of time, s from the start."""
    times: np.ndarray
    """Sample times, s from the start (the first is 0)."""
    label: str
    """What the schedule is, for file metadata and reports."""
    condition: int | None = None
    """The paper's condition number, if it is one."""
    every: int = 1
    """Report every ``every``-th step (the output interval of a case whose step is smaller)."""


STEADY = Schedule(lambda _: {}, np.zeros(1), "steady state")
"""One state at t = 0, in equilibrium with the inputs."""


def series_drive(ts: TimeSeries, needed, held=(), defaults: Mapping[str, float] | None = None,
                 label: str = "--data") -> TableDrive:
    """The inputs ``needed`` from the columns of ``ts`` (linear between samples, the ``held`` ones
    keeping their last sample; missing samples filled), at its own times; an input the file
    lacks takes its value from ``defaults`` or is one line naming the column."""
    defaults = dict(defaults or {})
    missing = [k for k in needed if k not in ts and k not in defaults]
    if missing:
        raise InputError(f"{label}, column {missing[0]}", "missing: the case reads it",
                         f"record every input it reads: {', '.join(sorted(needed))}")
    time = np.asarray(ts.time_s - ts.time_s[0], float)
    cols = {k: filled(k, time, ts[k], hold=k in held) if k in ts else np.full_like(time, defaults[k]) for k in needed}
    return TableDrive(time, cols, frozenset(held))


def series_schedule(ts: TimeSeries, needed, held=(), defaults=None, label: str = "measured inputs") -> Schedule:
    """A recorded series' inputs (:func:`series_drive`), sampled at its own times."""
    drive = series_drive(ts, needed, held, defaults, label)
    return Schedule(drive, drive.time, label)


def timed_schedule(end: float, step: float, output: float, drive: Drive, label: str) -> Schedule:
    """Steps of ``step`` over ``end`` (s), reported every ``output``."""
    times = np.linspace(0.0, end, int(round(end / step)) + 1)
    return Schedule(drive, times, label, every=int(round(output / step)))


def file_schedule(path, needed, held=(), defaults=None, step_s: float = 60.0) -> Schedule:
    """A schedule file (data format) of the inputs ``needed``, sampled every ``step_s`` over its
    length (at least one step, at most :data:`~gatetherm.studies.run.timeseries.MAX_STEPS`)."""
    ts = read_timeseries(path, required=("time_s",))
    span = float(ts.time_s[-1] - ts.time_s[0])
    if span < step_s:
        raise InputError(str(path), f"the schedule spans {span:g} s, less than one {step_s:g}-s step",
                         "give at least two rows a step or more apart")
    check_steps(span, step_s, f"{path}, column time_s")
    drive = series_drive(ts, needed, held, defaults, str(path))
    return Schedule(drive, sample_times(span, step_s), f"schedule {path}")
