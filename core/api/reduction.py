"""Reduced models of a case: made, checked against full FE runs, written (:mod:`gatetherm.api`)."""
from __future__ import annotations

import dataclasses
import math
import os
from pathlib import Path
from typing import Sequence

from gatetherm.api.run import Case, Schedule, _case, condition
from gatetherm.checks import Range, argument, whole_argument
from gatetherm.solvers.rom import ReducedModel, Reduction

PUBLIC = ("ReductionRun", "check_rom", "check_schedules", "reduce", "reduce_case", "write_reduction")

STATES = Range(2, 200, whole=True)
"""States a reduced model may have (``gatetherm reduce --states``)."""


def reduce(case: Case, states: int = 30):
    """The reduced heat model of ``case`` (its effects on): balanced truncation.

    Parameters
    ----------
    case : Case
        Any case with a transient heat solve.
    states : int
        States of the reduced model.

    Returns
    -------
    Reduction
        ``.rom`` the :class:`~gatetherm.solvers.rom.ReducedModel` (``gatetherm.studies.run.reduce.write_rom``
        keeps it as ``rom.npz``), with the error bounds, Hankel singular values and timings of its making.
        Where a film follows the temperature (a correlation, radiation), ``.held`` is the constant it is
        held at (the law's mean over the case's own run) and ``.rom.notes`` what that costs on that run.
    """
    from gatetherm.studies.run.reduce import build_rom

    _case(case)
    states = whole_argument("states", states, STATES, "e.g. 30")
    return build_rom(case, states)


def check_schedules(case: Case) -> list[Schedule]:
    """What a reduced model of ``case`` is checked on (:func:`check_rom`'s default).

    Parameters
    ----------
    case : Case

    Returns
    -------
    list of Schedule
        Its own schedule and, where the case reads only the inputs they drive (the oil supply,
        the pump, the room), the paper's conditions 1-3.
    """
    from gatetherm.studies.run.timeseries import AMBIENT, PUMP, SUPPLY

    _case(case)
    out = [case.schedule] if len(case.schedule.times) > 1 else []
    if case.inputs() and case.inputs() <= {SUPPLY, PUMP, AMBIENT}:
        frame = case if getattr(case.origin, "config", None) is not None else None  # else: the paper's supply unit
        out += [condition(n, frame) for n in (1, 2, 3) if condition(n, frame).label != case.schedule.label]
    return sorted(out, key=lambda s: (s.condition is None, s.condition or 0))


def check_rom(case: Case, rom: ReducedModel, schedules: Sequence[Schedule] | None = None) -> list:
    """The reduced model ``rom`` of ``case`` against full FE runs.

    Parameters
    ----------
    case : Case
        The case it was reduced from.
    rom : ReducedModel
        ``reduce(case).rom``, or one read with ``gatetherm.studies.run.reduce.load_rom``.
    schedules : list of Schedule, optional
        What to run (default :func:`check_schedules`).

    Returns
    -------
    list
        Per schedule, the largest error of every output (δ in µm, temperatures in K).
    """
    from gatetherm.studies.run.reduce import check
    from gatetherm.solvers.rom import ReducedModel
    from gatetherm.studies.run.scenario import ScenarioCache

    _case(case)
    argument("rom", rom, ReducedModel, "a ReducedModel", "gt.reduce(case).rom, or one read with load_rom")
    return check(case, rom, check_schedules(case) if schedules is None else schedules, ScenarioCache())


def write_reduction(out: str | os.PathLike, red: Reduction, checks: Sequence, case: Case, states: int,
                    seconds: float) -> dict:
    """Write a reduction: ``out/rom.npz``, ``out/rom.key`` and, last, ``out/summary.json``.

    Parameters
    ----------
    out : str or path
        The folder.
    red : Reduction
        :func:`reduce`'s result.
    checks : list
        :func:`check_rom`'s result (may be empty).
    case : Case
        The case it was reduced from.
    states : int
        Its states (in the key that later runs reuse it by).
    seconds : float
        Wall time of the reduction, s.

    Returns
    -------
    dict
        The summary: states, bounds (µm), the static-gain error, timings, checks and ``notes``.
    """
    from gatetherm.studies.run.output import write_json
    from gatetherm.solvers.rom import Reduction
    from gatetherm.studies.run.reduce import rom_key, save_rom

    argument("red", red, Reduction, "a Reduction", "what gt.reduce(case, states) returns")
    _case(case)
    out = Path(out)
    save_rom(red.rom, rom_key(case, states), out)
    summary = {"states": red.rom.states, "dim": case.dim, "model": case.source, "nodes_full": int(red.basis.shape[0]),
               "inputs": [dataclasses.asdict(u) for u in red.rom.inputs], "outputs": list(red.rom.outputs),
               "modes": list(red.rom.modes), "error_bound_bt": red.error_bound,
               "static_gain_error": red.static_gain_error, "hankel_singular_values": red.hankel,
               "reduction_seconds": round(seconds, 2), "seconds": {k: round(v, 2) for k, v in red.seconds.items()},
               "checks": {c.schedule: dataclasses.asdict(c) for c in checks}, "notes": list(red.rom.notes)}
    if checks:
        summary["max_delta_error_um"] = max(c.max_delta_error_um for c in checks)
    write_json(out / "summary.json", summary)
    return summary


OUTPUTS = ("rom.npz", "rom.key", "summary.json")
"""What :meth:`ReductionRun.write` writes; writing again replaces all of it."""


@dataclasses.dataclass(frozen=True)
class ReductionRun:
    """A reduced model made by :func:`reduce_case`, its checks and the folder it was written into."""

    case: Case
    """The case it was reduced from."""
    reduction: object
    """:func:`reduce`'s result (``.rom``, ``.error_bound`` in µm, ``.basis`` …)."""
    checks: list
    """Per checked schedule, the largest error of every output (δ in µm, temperatures in K)."""
    states: int
    """States asked for."""
    seconds: float
    """Wall time of the reduction, s."""
    files: tuple = ()
    """Input files the written folder must keep (the model file, the case's files, the checked schedules)."""
    folder: str | None = None
    """The folder it was written into, as given (None: not written)."""

    def write(self, out: str | os.PathLike) -> "ReductionRun":
        """Write ``out/rom.npz``, ``out/rom.key`` and, last, ``out/summary.json``
        (:func:`write_reduction`) in one transaction.

        Returns
        -------
        ReductionRun
            This result with :attr:`folder` ``out``.
        """
        from gatetherm.outdir import output_dir

        with output_dir(out, OUTPUTS, keep=self.files) as stage:
            write_reduction(stage, self.reduction, self.checks, self.case, self.states, self.seconds)
        return dataclasses.replace(self, folder=str(out))

    def summary(self) -> str:
        """The lines ``gatetherm reduce`` prints (no final newline)."""
        red, b = self.reduction, self.reduction.error_bound
        lines = [f"wrote {self.folder}/rom.npz, summary.json: {red.rom.states} states from {red.basis.shape[0]} "
                 f"unknowns in {self.seconds:.1f} s; BT bound (µm; 0.1 K) "
                 + ", ".join(f"{m} {v:.3g}".strip() for m, v in b.items())]
        lines += [f"warning: {note}" for note in red.rom.notes]
        for c in self.checks:
            theta = "" if math.isnan(c.max_theta_error_K) else f", θ {c.max_theta_error_K:.3f} K"  # a case without θ
            lines.append(f"{c.schedule.split(':')[0]}: max |δ_rom − δ_FE| = {c.max_delta_error_um:.3f} µm{theta}; "
                         f"reduced run {c.rom_ms:.2f} ms (FE {c.fe_seconds:.1f} s)")
            lines.append("  largest error per output: " + ", ".join(f"{k} {v:.3g}" for k, v in c.errors.items()))
        return "\n".join(lines)


def reduce_case(case: Case | str | os.PathLike | None = None, *, dim: int = 2, config: str | os.PathLike | None = None,
                states: int = 30, check: Sequence[str | os.PathLike] = (), check_fe: bool = True,
                out: str | os.PathLike | None = None,
                on_progress=None) -> ReductionRun:
    """A reduced heat model of a case (or the paper's frame), checked against full FE runs:
    what ``gatetherm reduce`` does.

    Parameters
    ----------
    case : Case or str or path, optional
        A case, or a case file's path (default: the paper's frame of ``dim`` and ``config``).
    dim : int
        The frame's 2 or 3 (without ``case``).
    config : str or path, optional
        The frame's model file (without ``case``).
    states : int
        States of the reduced model, 2 ... 200.
    check : sequence of str or path
        Schedule files to check it on as well, sampled at the case's ``[time]`` step (else 60 s).
    check_fe : bool
        Check it on :func:`check_schedules` and ``check`` (False: no full FE run at all).
    out : str or path, optional
        Also write it there (:meth:`ReductionRun.write`), the folder checked and locked before
        the reduction starts.
    on_progress : callable, optional
        ``on_progress(i, n)`` after the reduction (i = 1) and after each of the checks (n = 1 +
        the number of checked schedules).

    Returns
    -------
    ReductionRun
    """
    import time

    from gatetherm.api.case import PATH, gate_frame, load_case, schedule_file
    from gatetherm.checks import argument
    from gatetherm.outdir import output_dir
    from gatetherm.studies.run.reduce import build_rom, check as check_one
    from gatetherm.studies.run.scenario import ScenarioCache

    states = whole_argument("states", states, STATES, "e.g. 30")
    argument("case", case, (Case, *PATH, type(None)), "a Case, a case file's path or None")
    argument("check_fe", check_fe, bool, "True or False")
    for i, f in enumerate(check):
        argument(f"check[{i}]", f, PATH, "a schedule file's path")
    if not isinstance(case, Case):
        case = load_case(case) if case is not None else gate_frame(dim, config)
    step = case.time.step if case.time else 60.0  # a check file at the case's own step
    schedules = [*check_schedules(case), *(schedule_file(f, case, step) for f in check)] if check_fe else []
    files = (config, *case.files, *check)
    progress = on_progress or (lambda i, n: None)

    def made() -> ReductionRun:
        t0, cache, checks = time.perf_counter(), ScenarioCache(), []
        red = build_rom(case, states, cache)  # its model, and a full run it made, serve the checks
        seconds = time.perf_counter() - t0
        progress(1, 1 + len(schedules))
        for i, s in enumerate(schedules):
            checks += check_one(case, red.rom, [s], cache)
            progress(2 + i, 1 + len(schedules))
        return ReductionRun(case, red, checks, states, seconds, files)

    if out is None:
        return made()
    with output_dir(out, OUTPUTS, keep=files) as stage:
        result = made()
        write_reduction(stage, result.reduction, result.checks, case, states, result.seconds)
    return dataclasses.replace(result, folder=str(out))
