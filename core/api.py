"""The public Python API: what a notebook or a script calls (``import gatetherm as gt``).

It composes the layers below for the common tasks and is itself composed by nothing but the
command line (``gatetherm.cli``), whose every command parses its arguments and calls a
function here::

    import gatetherm as gt
    case = gt.load_case("validation/examples/c_frame/case.toml")
    run = gt.run(case)                         # the case's own schedule, or schedule=...
    run.time, run["delta_um"]                  # numpy arrays
    run.field("T", t=run.time[-1])             # nodal fields on demand
    gt.plot.series(run, "delta_um", ax=ax)     # plots take ax= and return it
    run.write("out/")                          # what `gatetherm run` writes

The paper's frame is a case like any other: ``gt.gate_frame(dim=2)``.
"""
from __future__ import annotations

import dataclasses
import logging
import os
import time as _time
from pathlib import Path
from typing import Callable, Mapping

import numpy as np

from gatetherm import InputError
from gatetherm.process import configure
from gatetherm.studies.run.case import Case, load_case
from gatetherm.studies.run.frame_case import gate_frame
from gatetherm.studies.run.scenario import ScenarioRun, run_scenario
from gatetherm.studies.run.schedules import Schedule, condition_schedule, file_schedule

log = logging.getLogger(__name__)

STATE_BUDGET_BYTES = 512e6
"""Heat states a :class:`Run` keeps at every sample up to this size; beyond, only at the field times."""

__all__ = ["Case", "Run", "Schedule", "check_rom", "check_schedules", "compensate", "condition", "configure", "diagnose",
           "gate_frame", "load_case", "reduce", "run", "schedule_file", "write_reduction"]


def condition(number: int, case: Case | None = None, step_s: float = 60.0) -> Schedule:
    """The paper's condition ``number`` (1, 2 or 3): the oil supply unit's set points and pump
    states, sampled every ``step_s`` (s). ``case``: a frame case whose supply unit drives it
    (default: the shipped paper model's)."""
    supply = getattr(getattr(case, "origin", None), "config", None)
    return condition_schedule(number, *(() if supply is None else (supply.supply,)), step_s=step_s)


def schedule_file(path: str | os.PathLike, case: Case, step_s: float = 60.0) -> Schedule:
    """A schedule file (the data format) of the inputs ``case`` reads, sampled every ``step_s``."""
    return file_schedule(path, sorted(case.inputs()), case.held(), case.defaults, step_s)


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
        return self.scenario.columns["time_s"]

    @property
    def columns(self) -> dict[str, np.ndarray]:
        return self.scenario.columns

    def __getitem__(self, name: str) -> np.ndarray:
        if name not in self.columns:
            raise KeyError(f"{name!r}: columns are {', '.join(self.columns)}")
        return self.columns[name]

    @property
    def kept(self) -> list[float]:
        """Times (s) whose full state is kept: :meth:`field` answers at these."""
        return [t for t, _ in self.scenario.result.states]

    def state(self, t: float) -> tuple[float, np.ndarray | None]:
        """(time, heat state) kept nearest ``t`` (s); a time no state is kept near is an error."""
        from gatetherm.studies.run.output import nearest_state

        kept, U = nearest_state(self.scenario, t)
        step = float(np.median(np.diff(self.time))) if len(self.time) > 1 else 1.0
        if abs(kept - t) > 1e-6 * max(step, 1.0):
            raise InputError("t", f"no state kept at {t:g} s (nearest {kept:g} s)",
                             "run with keep=... listing the times whose fields you want")
        return kept, U

    def field(self, name: str, t: float | None = None) -> np.ndarray:
        """The nodal field ``name`` at time ``t`` (default: the last sample): ``"T"`` (°C), ``"u"``
        (m, nodes × 3), ``"sigma_xx"`` … and ``"von_mises"`` (Pa)."""
        from gatetherm.studies.run.output import nodal_fields

        t = float(self.time[-1]) if t is None else float(t)
        _, U = self.state(t)
        fields = nodal_fields(self.scenario.model, U, stress=name not in ("T", "u"))
        if name not in fields:
            raise KeyError(f"{name!r}: fields are {', '.join(fields)}")
        return fields[name]

    def summary(self) -> dict:
        """What ``summary.json`` holds: the case, its size, every probe and relative displacement
        at the last sample, and δ's figures where the case has a δ."""
        from gatetherm.studies.run.output import probe_summary
        from gatetherm.studies.run.simulate import delta_figures

        c, p = self.case, self.case.problem
        out = {"case": c.name, "file": c.source, "dim": p.dim, "order": p.order,
               "analysis": ("prescribed temperature" if p.thermal else "mechanical") if not p.heat else
               ("transient" if c.time else "steady"),
               "nodes": len(c.mesh.points), "elements": len(c.mesh.cells), "schedule": self.scenario.schedule.label,
               "effects": self.scenario.effects.describe(), "wall_time_s": round(self.seconds, 2),
               "march_s": round(self.scenario.result.seconds, 2), **probe_summary(p, self.columns)}
        if "delta_um" in self.columns and len(self.time) > 1:
            out.update(delta_figures(self.time, self["delta_um"]))
        if self.order_check is not None:
            out["order_check"] = self.order_check.summary()
        return out

    def write(self, out: str | os.PathLike, pictures: bool = True, fields_every: float | None = None) -> dict:
        """Write the run directory ``out``: ``timeseries.csv``, ``summary.json``, the fields at
        every ``fields_every`` s (default: the case's field interval) and the last sample
        (``fields/``, ParaView), and the pictures; returns the summary."""
        from gatetherm.studies.run.output import write_json, write_run

        out = Path(out)
        out.mkdir(parents=True, exist_ok=True)
        every = fields_every or (self.case.time.fields if self.case.time else 1.0)
        times = [float(t) for t in self.time]
        fields = {t for t in times if abs(t / every - round(t / every)) < 1e-9} | {times[-1]}
        fields &= set(self.kept)
        sched = self.scenario.schedule
        meta = {"source": "gatetherm", "case": self.case.source, "name": self.case.name, "dim": str(self.case.dim),
                "schedule": sched.label, **({"condition": str(sched.condition)} if sched.condition else {})}
        picture = self._picture_time()
        solved = write_run(out, self.scenario, meta, fields, (picture,) if pictures and picture is not None else ())
        if pictures:
            from gatetherm.validation.plots.run import write_pictures

            write_pictures(self.scenario, out, self.case.name, picture, solved)
        summary = self.summary()
        write_json(out / "summary.json", summary)
        return summary

    def _picture_time(self) -> float | None:
        """When the deformed picture shows the case: δ's first peak where it has one, else the end."""
        if self.scenario.model.elastic is None:
            return None
        figs = self.summary() if "delta_um" in self.columns and len(self.time) > 1 else {}
        peak = figs.get("first_peak_min")
        return peak * 60.0 if peak is not None else float(self.time[-1])



def run(case: Case, schedule: Schedule | None = None, effects: Mapping[str, float] | None = None, *,
        keep=None, on_step: Callable[[int, int], None] | None = None, check_order: bool = False) -> Run:
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
    check_order : bool
        A linear-element case on a small mesh: solve its final state once more with quadratic
        elements and warn (one log line naming the output and the fix) where they differ by more
        than :data:`gatetherm.studies.run.order_check.TOLERANCE`.

    Returns
    -------
    Run
    """
    t0 = _time.perf_counter()
    schedule = case.schedule if schedule is None else schedule
    times = [float(t) for t in schedule.times]
    if keep is None:
        n = len(case.mesh.points) * case.problem.order ** case.dim
        every = case.time.fields if case.time else 1.0
        keep = times if len(times) * n * 8 <= STATE_BUDGET_BYTES else \
            [t for t in times if abs(t / every - round(t / every)) < 1e-9] + [times[-1]]
    scenario = run_scenario(case, schedule, effects, keep_times=sorted(set(map(float, keep)) | {times[-1]}),
                            on_step=on_step)
    check = None
    if check_order:
        from gatetherm.studies.run.order_check import order_check

        check = order_check(case, scenario)
    return Run(case, scenario, _time.perf_counter() - t0, check)


def reduce(case: Case, states: int = 30):
    """The reduced heat model of ``case`` (its effects on): balanced truncation to ``states`` states.

    Returns
    -------
    Reduction
        ``.rom`` the :class:`~gatetherm.solvers.rom.ReducedModel` (``gatetherm.studies.run.reduce.write_rom``
        keeps it as ``rom.npz``), with the error bounds, Hankel singular values and timings of its making.
    """
    from gatetherm.studies.run.reduce import build_rom

    return build_rom(case, states)


def check_schedules(case: Case) -> list[Schedule]:
    """What a reduced model of ``case`` is checked on: its own schedule and, where the case reads
    only the inputs they drive (the oil supply, the pump, the room), the paper's conditions 1-3."""
    from gatetherm.solvers.frame import AMBIENT, PUMP, SUPPLY

    out = [case.schedule] if len(case.schedule.times) > 1 else []
    if case.inputs() and case.inputs() <= {SUPPLY, PUMP, AMBIENT}:
        out += [condition(n, case) for n in (1, 2, 3) if condition(n, case).label != case.schedule.label]
    return sorted(out, key=lambda s: (s.condition is None, s.condition or 0))


def check_rom(case: Case, rom, schedules=None) -> list:
    """The reduced model ``rom`` of ``case`` against full FE runs of ``schedules`` (default
    :func:`check_schedules`): the largest error of every output per schedule."""
    from gatetherm.studies.run.reduce import check
    from gatetherm.studies.run.scenario import ScenarioCache

    return check(case, rom, check_schedules(case) if schedules is None else schedules, ScenarioCache())


def write_reduction(out: str | os.PathLike, red, checks, case: Case, states: int, seconds: float) -> dict:
    """``out/rom.npz``, ``out/rom.key`` and, last, ``out/summary.json``; returns the summary."""
    from gatetherm.studies.run.output import write_json
    from gatetherm.studies.run.reduce import rom_key, save_rom

    out = Path(out)
    save_rom(red.rom, rom_key(case, states), out)
    summary = {"states": red.rom.states, "dim": case.dim, "model": case.source, "nodes_full": int(red.basis.shape[0]),
               "inputs": [dataclasses.asdict(u) for u in red.rom.inputs], "outputs": list(red.rom.outputs),
               "modes": list(red.rom.modes), "error_bound_bt": red.error_bound,
               "static_gain_error": red.static_gain_error, "hankel_singular_values": red.hankel,
               "reduction_seconds": round(seconds, 2), "seconds": {k: round(v, 2) for k, v in red.seconds.items()},
               "checks": {c.schedule: dataclasses.asdict(c) for c in checks}}
    if checks:
        summary["max_delta_error_um"] = max(c.max_delta_error_um for c in checks)
    write_json(out / "summary.json", summary)
    return summary


def compensate(series, case: Case | None = None, method: str = "paper", *, actuator="case", **settings):
    """Compensate a run: predict δ and drive the actuator with the command.

    Parameters
    ----------
    series : TimeSeries or Run
        The run (θ_A, θ_B, θ_C and δ, the uncompensated thermal displacement; for ``rom`` the
        inputs the reduced model reads): a :class:`Run`, or a measured file read with
        ``gatetherm.studies.run.timeseries.read_timeseries``.
    case : Case, optional
        The model (default: a Run's own case): the paper method's beam-theory or FE K, the mlr
        training run (its own schedule) and the rom reduced model come from it.
    method : str
        ``"paper"``, ``"mlr"`` or ``"rom"``.
    actuator : ActuatorParams, None or "case"
        The actuator in the loop (``"case"``: the case's ``[actuator]``, the frame's piezo; None:
        ideal, the command sent to the control as an offset).
    **settings
        Fields of :class:`gatetherm.studies.control.methods.Settings` (``Ki``, ``Kc``,
        ``k_source``, ``states``, ``params``, ``control``, ``sensors``); ``rom=`` a reduced model.

    Returns
    -------
    Compensation
        ``.loop`` (the compensated δ, the strokes, the updates), ``.summary`` (bands, updates).
    """
    from gatetherm.studies.control.methods import Settings, compensate as methods_compensate

    if isinstance(series, Run):
        case = case or series.case
        series = series.scenario.series({"source": "gatetherm.api.compensate"})
    rom = settings.pop("rom", None)
    chosen = (case.actuator if case is not None else None) if actuator == "case" else actuator
    return methods_compensate(series, case, Settings(method=method, **settings), chosen, rom=rom)


def diagnose(case: Case, measured, **settings):
    """Where ``case`` and a measured run disagree, and the missing pieces that explain it.

    Parameters
    ----------
    case : Case
        The model: a case file's, or the paper frame's.
    measured : TimeSeries or path
        The measurement: every input the case reads, and the channels to compare.
    **settings
        Fields of :class:`gatetherm.studies.diagnosis.discrepancy.Settings` (``train_fraction``,
        ``effects``, ``parameters``, ``sensors``, ``max_pieces`` …).

    Returns
    -------
    Diagnosis
        ``.verdict``, ``.pieces`` (each with its fitted value), ``.summary()``.
    """
    from gatetherm.studies.diagnosis.discrepancy import Settings, diagnose as run_diagnosis
    from gatetherm.studies.run.timeseries import TimeSeries, read_timeseries

    ts = measured if isinstance(measured, TimeSeries) else read_timeseries(measured, required=("time_s",))
    return run_diagnosis(case, ts, Settings(**settings))
