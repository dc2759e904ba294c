"""Reduced models of a case: made, checked against full FE runs, written (:mod:`gatetherm.api`)."""
from __future__ import annotations

import dataclasses
import os
from pathlib import Path

from gatetherm.api.run import Case, Schedule, _case, condition
from gatetherm.checks import Range, argument, whole_argument

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
    from gatetherm.solvers.frame import AMBIENT, PUMP, SUPPLY

    _case(case)
    out = [case.schedule] if len(case.schedule.times) > 1 else []
    if case.inputs() and case.inputs() <= {SUPPLY, PUMP, AMBIENT}:
        out += [condition(n, case) for n in (1, 2, 3) if condition(n, case).label != case.schedule.label]
    return sorted(out, key=lambda s: (s.condition is None, s.condition or 0))


def check_rom(case: Case, rom, schedules=None) -> list:
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


def write_reduction(out: str | os.PathLike, red, checks, case: Case, states: int, seconds: float) -> dict:
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
        The summary: states, bounds (µm), the static-gain error, timings and checks.
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
               "checks": {c.schedule: dataclasses.asdict(c) for c in checks}}
    if checks:
        summary["max_delta_error_um"] = max(c.max_delta_error_um for c in checks)
    write_json(out / "summary.json", summary)
    return summary
