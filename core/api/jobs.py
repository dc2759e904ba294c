"""A run written into a folder: what ``gatetherm run`` (a case file) and ``gatetherm simulate``
(the paper's frame) do, as one call each (:mod:`gatetherm.api`)."""
from __future__ import annotations

import dataclasses
import os
from typing import Callable, Sequence

from gatetherm.api.case import PATH, Schedule, gate_frame, load_case, schedule_file
from gatetherm.api.run import Run, run
from gatetherm.checks import POSITIVE, argument, number_argument

PUBLIC = ("RunResult", "run_case", "simulate")  # offered as gt.NAME (gatetherm.api finds them here)

FIELD_FILES = ("fields/fields_*.vtu", "fields/fields.pvd", "fields/fields.xdmf", "fields/fields.h5")
"""The field files of a run in its folder (studies.run.output.write_fields)."""
OUTPUTS = ("timeseries.csv", "summary.json", *FIELD_FILES, "channels.png", "oil_temperatures.png", "response.png",
           "deformed.png")
"""What a written run holds; writing it again replaces all of it."""
PICTURE_EVERY_S = 300.0
"""The candidates of the deformed picture (it shows δ's first peak) are kept this often, s."""


def picture_keep(schedule: Schedule, every: float, picture_every: float = PICTURE_EVERY_S) -> list[float]:
    """The sample times whose states a written run needs: the fields every ``every`` s, the
    candidates of the deformed picture (every ``picture_every`` s) and the end."""
    times = [float(t) for t in schedule.times]
    on = [t for t in times if any(abs(t / e - round(t / e)) < 1e-9 for e in (every, picture_every))]
    return sorted(set(on) | {times[-1]})


@dataclasses.dataclass(frozen=True)
class RunResult:
    """A run made by :func:`run_case` or :func:`simulate`, and what was written of it."""

    run: Run
    """The run: its columns, kept states and the case."""
    figures: dict
    """``summary.json``'s content (probes, relative displacements in µm, first peak, wall time in s …)."""
    folder: str | None = None
    """The folder it was written into, as given (None: not written)."""
    frame: bool = False
    """The paper's frame (:func:`simulate`) rather than a case file (:func:`run_case`)."""
    fields_every: float | None = None
    """Interval of the written fields, s (None: the case's own)."""
    released: bool = False
    """Written with ``out=`` as a one-shot run (its elastic solver released as it was written):
    it is not written again."""

    def write(self, out: str | os.PathLike, pictures: bool = True) -> "RunResult":
        """Write the run into ``out`` as one transaction (:func:`gatetherm.outdir.output_dir`):
        ``timeseries.csv``, ``summary.json``, ``fields/`` and, with ``pictures``, the PNGs; the
        files of an earlier run there that this one does not write are removed.

        Returns
        -------
        RunResult
            This result with :attr:`figures` as written and :attr:`folder` ``out``.
        """
        from gatetherm.outdir import output_dir

        argument("out", out, PATH, "a folder's path")
        if self.released:
            from gatetherm import InputError

            raise InputError("out", f"this run was written into '{self.folder}' as a one-shot run",
                             "run it without out= to write it more than once")
        with output_dir(out, OUTPUTS, keep=self.run.case.files) as stage:
            figures = self.run.write(stage, pictures=pictures, fields_every=self.fields_every)
        return dataclasses.replace(self, figures=figures, folder=str(out))

    def summary(self) -> str:
        """The lines ``gatetherm run`` or ``gatetherm simulate`` prints (no final newline)."""
        s = self.figures
        if self.frame:
            figs = {k: (round(v, 2) if isinstance(v, float) else v) for k, v in s.items()}
            return "\n".join([f"wrote {self.folder}/timeseries.csv, summary.json, fields/ and plots",
                              "first peak {first_peak_um} µm at {first_peak_min} min, swing {swing_um} µm, wall time "
                              "{w} s".format(**figs, w=s["wall_time_s"])])
        lines = [f"wrote {self.folder}/timeseries.csv, summary.json and fields/"]
        lines += [f"{name}: " + ", ".join(f"{k} {v:.6g}" for k, v in q.items() if v is not None)
                  for name, q in s["probes"].items()]
        lines += [f"{name}: {v:.6g} um" for name, v in s["relative"].items()]
        lines += [f"{name}: mean {q['mean_W']:.6g} W, max {q['max_W']:.6g} W, energy {q['energy_J']:.6g} J"
                  for name, q in s.get("losses", {}).items()]
        return "\n".join(lines)


def _written(make, out, pictures, on_progress) -> tuple[Run, dict | None]:
    """Make the case (``make()``: case, schedule, its input files, the fields' interval, ``run``'s
    settings), run it and, with ``out``, write it there in one transaction opened before the run
    (a folder that cannot be written is refused before any numerics); the pictures are drawn by
    a painter started first, overlapping the work."""
    from gatetherm.outdir import output_dir
    from gatetherm.validation.plots.api import Painter

    with Painter(2 if pictures and out is not None else 0) as painter:
        case, schedule, files, every, settings = make()
        keep = picture_keep(schedule, every)
        if out is None:
            return run(case, schedule, keep=keep, on_step=on_progress, **settings), None
        with output_dir(out, OUTPUTS, keep=files) as stage:
            res = run(case, schedule, keep=keep, on_step=on_progress, **settings)
            return res, res.write(stage, pictures=pictures, painter=painter, release=True,
                                  fields_every=settings.get("fields_every"))


def run_case(path: str | os.PathLike, out: str | os.PathLike | None = None, *, pictures: bool = True,
             on_progress: Callable[[int, int], None] | None = None) -> RunResult:
    """Run a case file over its own schedule (``gatetherm run``), checking a linear-element
    case against quadratic elements (a warning where they differ).

    Parameters
    ----------
    path : str or path
        The case file (``docs/case-file.md``).
    out : str or path, optional
        Also write the run there (:meth:`RunResult.write`), the folder checked and locked
        before the run starts.
    pictures : bool
        Write the PNG pictures with the run.
    on_progress : callable, optional
        ``on_progress(i, n)`` after each of the ``n`` samples.

    Returns
    -------
    RunResult
    """

    def make():
        case = load_case(path)
        return case, case.schedule, case.files, case.time.fields if case.time else 1.0, {"check_order": True}

    res, figures = _written(make, out, pictures, on_progress)
    return RunResult(res, res.summary() if figures is None else figures, None if out is None else str(out),
                     released=out is not None)


def simulate(condition: int | None = None, schedule: str | os.PathLike | None = None, *, dim: int = 2,
             config: str | os.PathLike | None = None, effects: Sequence[str] = (), fields_every: float = 3600.0,
             out: str | os.PathLike | None = None, pictures: bool = True,
             on_progress: Callable[[int, int], None] | None = None) -> RunResult:
    """Run the paper's frame under one of its conditions or a schedule file (``gatetherm simulate``).

    Parameters
    ----------
    condition : int, optional
        The paper's condition 1, 2 or 3 (give this or ``schedule``).
    schedule : str or path, optional
        A schedule file of the frame's inputs (``time_s, oil_degC, pump[, ambient_degC]``).
    dim : int
        2 (plane-stress section) or 3 (solid).
    config : str or path, optional
        A model file (default: the shipped paper model).
    effects : sequence of str
        Effects on top of the model file's, each ``KEY:PARAM=VALUE`` or ``KEY=VALUE`` (KEY: ``KIND@TARGET``;
        ``gatetherm diagnose --list-effects``).
    fields_every : float
        Interval of the written fields, s (at least 60).
    out : str or path, optional
        Also write the run there, the folder checked and locked before the run starts.
    pictures : bool
        Write the PNG pictures with the run.
    on_progress : callable, optional
        ``on_progress(i, n)`` after each of the ``n`` samples.

    Returns
    -------
    RunResult
    """
    from gatetherm import InputError
    from gatetherm.solvers.effects import parse_effect
    from gatetherm.frame.conditions import condition as check_condition

    if (condition is None) == (schedule is None):
        raise InputError("condition/schedule", "give one of the two", "e.g. condition=1")
    argument("schedule", schedule, (*PATH, type(None)), "a schedule file's path or None")
    every = max(number_argument("fields_every", fields_every, POSITIVE, "e.g. 3600"), 60.0)

    def make():
        if condition is not None:
            check_condition(condition)  # 0 is no condition (it would run condition 1)
        case = gate_frame(dim, config, 1 if condition is None else condition)
        pairs = [parse_effect(s, case.targets) for s in effects]
        extra = dict(pairs)  # on top of the model file's
        if len(extra) < len(pairs):
            twice = next(k for i, (k, _) in enumerate(pairs) if k in dict(pairs[:i]))
            raise InputError("--effect", f"{twice} is given more than once", "give each effect once")
        sched = schedule_file(schedule, case) if schedule else case.schedule
        return case, sched, (config, schedule), every, {"effects": extra, "fields_every": every}

    res, figures = _written(make, out, pictures, on_progress)
    return RunResult(res, res.summary() if figures is None else figures, None if out is None else str(out), True,
                     every, out is not None)
