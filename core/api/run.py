"""Runs of a case: the public API's core (:mod:`gatetherm.api`); cases, schedules: :mod:`gatetherm.api.case`."""
from __future__ import annotations

import dataclasses
import fnmatch
import logging
import os
import time as _time
from pathlib import Path
from typing import Callable, Iterable, Mapping, Sequence

import numpy as np

from gatetherm import InputError, UnknownName
from gatetherm.api.case import PATH, Case, Schedule, _case  # noqa: F401 - PATH, _case: for the API's modules
from gatetherm.api.case import beam_coefficients, condition, gate_frame, load_case, nc_schedule, \
    schedule_file  # noqa: F401 - for the API's modules
from gatetherm.checks import POSITIVE, Range, argument, number_argument
from gatetherm.options import SolverOptions  # noqa: F401 - offered (PUBLIC)
from gatetherm.process import configure  # noqa: F401 - offered (PUBLIC)
from gatetherm.studies.run.scenario import ScenarioRun, run_scenario

PUBLIC = ("Run", "SolverOptions", "configure", "run")  # offered as gt.NAME (gatetherm.api finds them here)

log = logging.getLogger(__name__)

STATE_BUDGET_BYTES = 512e6
"""Heat states a :class:`Run` keeps at every sample up to this size; beyond, only at the field times."""

WRITTEN = ("timeseries.csv", "summary.json", "fields/fields_*.vtu", "fields/fields.pvd", "fields/fields.xdmf",
           "fields/fields.h5", "channels.png", "oil_temperatures.png", "response.png", "deformed.png")
"""What :meth:`Run.write` may write into its folder (paths relative to it)."""


@dataclasses.dataclass(frozen=True)
class Run:
    """A finished run of a case: its columns in the data format, and heat states for fields.

    ``run["delta_um"]`` is a column (numpy array), ``run.time`` the sample times (s);
    :meth:`field` gives a nodal field at a kept time, :meth:`write` the run directory."""

    case: Case
    scenario: ScenarioRun
    seconds: float
    """Wall time of the run, s (model build included)."""
    order_check: object = None
    """A linear-element case: its final outputs at P1 and P2 on the same mesh
    (:class:`~gatetherm.studies.run.order_check.OrderCheck`), if checked."""

    @property
    def time(self) -> np.ndarray:
        """Sample times, s from the start."""
        return self.scenario.columns["time_s"]

    @property
    def columns(self) -> dict[str, np.ndarray]:
        """Every column of the run in the data format (``docs/data-format.md``), name → array."""
        return self.scenario.columns

    def __getitem__(self, name: str) -> np.ndarray:
        if name not in self.columns:
            raise UnknownName("name", f"{name!r} is not a column of the run", f"columns: {', '.join(self.columns)}")
        return self.columns[name]

    @property
    def kept(self) -> list[float]:
        """Times (s) whose full state is kept: :meth:`field` answers at these."""
        return [t for t, _ in self.scenario.result.states]

    def state(self, t: float) -> tuple[float, np.ndarray | None]:
        """(time, heat state) kept nearest ``t`` (s); a time no state is kept near is an error."""
        from gatetherm.studies.run.output import nearest_state

        t = number_argument("t", t, fix="give a time of the run, s (one of run.kept)")
        kept, U = nearest_state(self.scenario, t)
        step = float(np.median(np.diff(self.time))) if len(self.time) > 1 else 1.0
        if abs(kept - t) > 1e-6 * max(step, 1.0):
            raise InputError("t", f"no state kept at {t:g} s (nearest {kept:g} s)",
                             "run with keep=... listing the times whose fields you want")
        return kept, U

    def field(self, name: str, t: float | None = None) -> np.ndarray:
        """A nodal field at a kept time.

        Parameters
        ----------
        name : str
            ``"T"`` (°C), ``"u"`` (m, nodes × 3), ``"sigma_xx"`` … and ``"von_mises"`` (Pa).
        t : float, optional
            Time, s (default: the last sample); one of :attr:`kept`.

        Returns
        -------
        numpy.ndarray
            One value (a row for ``"u"``) per mesh node.
        """
        from gatetherm.studies.run.output import nodal_fields

        argument("name", name, str, 'a field\'s name, e.g. "T"')
        t = float(self.time[-1]) if t is None else number_argument("t", t, fix="give one of run.kept, s")
        _, U = self.state(t)
        fields = nodal_fields(self.scenario.model, U, stress=name not in ("T", "u"))
        if name not in fields:
            raise UnknownName("name", f"{name!r} is not a field of the run", f"fields: {', '.join(fields)}")
        return fields[name]

    def summary(self) -> dict:
        """What ``summary.json`` holds: the case, its size, every probe and relative displacement
        at the last sample, δ's figures where the case has a δ, and every machine element's loss
        (mean, largest, last, energy; its column ``P_REGION_W`` holds it over time)."""
        from gatetherm.studies.run.output import probe_summary
        from gatetherm.studies.run.simulate import delta_figures, loss_summary

        c, p = self.case, self.case.problem
        out = {"case": c.name, "file": c.source, "dim": p.dim, "order": p.order,
               "analysis": ("prescribed temperature" if p.thermal else "mechanical") if not p.heat else
               ("transient" if c.time else "steady"),
               "nodes": len(c.mesh.points), "elements": len(c.mesh.cells), "schedule": self.scenario.schedule.label,
               "effects": self.scenario.effects.describe(), "wall_time_s": round(self.seconds, 2),
               "march_s": round(self.scenario.result.seconds, 2), **probe_summary(p, self.columns),
               **loss_summary(p, self.columns)}
        if "delta_um" in self.columns and len(self.time) > 1:
            out.update(delta_figures(self.time, self["delta_um"]))
        if self.order_check is not None:
            out["order_check"] = self.order_check.summary()
        return out

    def write(self, out: str | os.PathLike, pictures: bool = True, fields_every: float | None = None,
              painter=None, release: bool = False) -> dict:
        """Write the run directory that ``gatetherm run`` writes.

        Parameters
        ----------
        out : str or path
            The folder: ``timeseries.csv``, ``summary.json``, ``fields/`` (ParaView) and the pictures.
        pictures : bool
            Write ``channels.png`` and ``deformed.png``.
        fields_every : float, optional
            Interval of the fields, s (default: the case's field interval); the last sample always.
        painter : Painter, optional
            Draws the pictures while the fields are written
            (:class:`~gatetherm.validation.plots.painter.Painter`, made before the run; default:
            drawn here, in turn).
        release : bool
            Nothing more is asked of the run's model after these fields (a one-shot run, as the
            command's): the helper process solving its displacements ends once they are in, its
            memory (0.3 GB on the 3-D frame) free for the pictures. A later solve sets the
            solver up again in this process.

        Returns
        -------
        dict
            The summary (:meth:`summary`).
        """
        from gatetherm.studies.run.output import write_json, write_run

        out = Path(argument("out", out, PATH, "a folder's path"))
        argument("pictures", pictures, bool, "True or False")
        if fields_every is not None:
            number_argument("fields_every", fields_every, POSITIVE, "an interval, s, e.g. 3600")
        self._refuse_overwriting(out)
        out.mkdir(parents=True, exist_ok=True)
        fields = field_times(self.time, fields_every or _fields_every(self.case)) & set(self.kept)
        sched = self.scenario.schedule
        meta = {"source": "gatetherm", "case": self.case.source, "name": self.case.name, "dim": str(self.case.dim),
                "schedule": sched.label, **({"condition": str(sched.condition)} if sched.condition else {})}
        picture = self._picture_time()
        later = None
        if pictures and painter is not None:  # the plots of the columns at once, the deformed one later
            from gatetherm.validation.plots.pictures import prepare_pictures, write_pictures

            if picture is not None:
                prepare_pictures(self.scenario, painter)  # while the fields are solved (if not done before)
            later = ("deformed.png",)
            write_pictures(self.scenario, out, self.case.name, None, painter=painter)

        def draw(solved):
            from gatetherm.validation.plots.pictures import write_pictures

            write_pictures(self.scenario, out, self.case.name, picture, solved, painter=painter, only=later)

        write_run(out, self.scenario, meta, fields, (picture,) if pictures and picture is not None else (),
                  draw if pictures else None, release)
        if pictures and painter is not None:
            painter.finish()
        summary = self.summary()
        write_json(out / "summary.json", summary)
        return summary

    def _refuse_overwriting(self, out: Path) -> None:
        """InputError if a file the case reads (its schedule, mesh, the case file) is one that
        :meth:`write` would write into ``out`` (the command line refuses the same)."""
        root = out.resolve()
        for f in self.case.files:
            try:
                rel = Path(f).resolve().relative_to(root).as_posix()
            except ValueError:
                continue
            if any(fnmatch.fnmatch(rel, w) for w in WRITTEN):
                raise InputError("out", f"writing into '{out}' would overwrite the case's input '{f}'",
                                 "choose another folder")

    def _picture_time(self) -> float | None:
        """When the deformed picture shows the case: δ's first peak where it has one, else the end."""
        if self.scenario.model.elastic is None:
            return None
        figs = self.summary() if "delta_um" in self.columns and len(self.time) > 1 else {}
        peak = figs.get("first_peak_min")
        return peak * 60.0 if peak is not None else float(self.time[-1])



def _effects(effects) -> dict[str, float] | None:
    """``effects`` checked: None or a mapping of effect keys (str) to finite numbers."""
    argument("effects", effects, (Mapping, type(None)), "a dict {key: value} or None",
             '{KIND@TARGET: value}; gatetherm diagnose --list-effects lists them')
    if effects is None:
        return None
    for key, value in effects.items():
        argument("effects key", key, str, "an effect's key, KIND@TARGET")
        number_argument(f"effects[{key!r}]", value, fix="give the effect's parameter, a finite number")
    return dict(effects)


def _times(name: str, values, rng: Range) -> list[float]:
    """``values``: an iterable of numbers (not a string) each in ``rng``."""
    if isinstance(values, (str, bytes)) or not isinstance(values, Iterable):
        argument(name, values, (list, tuple), "a sequence of times, s")
    return [number_argument(f"{name}[{i}]", v, rng, "give times within the run, s") for i, v in enumerate(values)]


def field_times(times, every: float) -> set[float]:
    """The sample times of the fields written every ``every`` s: its multiples, and the end."""
    times = [float(t) for t in times]
    return {t for t in times if abs(t / every - round(t / every)) < 1e-9} | {times[-1]}


def _fields_every(case: Case) -> float:
    return case.time.fields if case.time else 1.0


def run(case: Case, schedule: Schedule | None = None, effects: Mapping[str, float] | None = None, *,
        keep: Sequence[float] | None = None, on_step: Callable[[int, int], None] | None = None,
        check_order: bool = False,
        fields_every: float | None = None) -> Run:
    """Run ``case``.

    Parameters
    ----------
    case : Case
        From :func:`load_case` or :func:`gate_frame`.
    schedule : Schedule, optional
        What drives it (default: its own: the case file's ``[time]`` and schedule, or the frame's
        condition); :func:`condition`, :func:`schedule_file`.
    effects : mapping, optional
        Effects switched on, ``{key: value}`` (``gatetherm diagnose --list-effects``).
    keep : sequence of float, optional
        Times (s) whose heat state is kept for :meth:`Run.field` (default: every sample while they
        take less than :data:`STATE_BUDGET_BYTES`, else the case's field times and the end).
    on_step : callable, optional
        ``on_step(i, n)`` after each of the ``n`` samples.
    fields_every : float, optional
        The interval (s) of the fields :meth:`Run.write` will write (default: the case's): where
        the elastic solver runs in a helper process (a large 3-D model), their displacements,
        and that of the deformed picture's state (δ's first peak), are solved there during the
        march.
    check_order : bool
        A linear-element case on a small mesh: solve its final state once more with quadratic
        elements and warn (one log line naming the output and the fix) where they differ by more
        than :data:`gatetherm.studies.run.order_check.TOLERANCE`.

    Returns
    -------
    Run
    """
    t0 = _time.perf_counter()
    _case(case)
    argument("schedule", schedule, (Schedule, type(None)), "a Schedule or None",
             "make one with gt.condition(n) or gt.schedule_file(path, case)")
    effects = _effects(effects)
    argument("on_step", on_step, (Callable, type(None)), "a function on_step(i, n) or None")
    argument("check_order", check_order, bool, "True or False")
    if fields_every is not None:
        number_argument("fields_every", fields_every, POSITIVE, "an interval, s, e.g. 3600")
    schedule = case.schedule if schedule is None else schedule
    times = [float(t) for t in schedule.times]
    if keep is not None:
        keep = _times("keep", keep, Range(times[0], times[-1], unit="s"))
    fields = field_times(times, fields_every or _fields_every(case))
    if keep is None:
        n = len(case.mesh.points) * case.problem.order ** case.dim
        keep = times if len(times) * n * 8 <= STATE_BUDGET_BYTES else fields
    scenario = run_scenario(case, schedule, effects, keep_times=sorted(set(map(float, keep)) | {times[-1]}),
                            on_step=on_step, solve_at=fields, solve_first_peak=True)  # Run.write's picture
    check = None
    if check_order:
        from gatetherm.studies.run.order_check import order_check

        check = order_check(case, scenario)
    return Run(case, scenario, _time.perf_counter() - t0, check)
