"""Cases and schedules: what the public API runs (:mod:`gatetherm.api`)."""
from __future__ import annotations

import os
from pathlib import Path
from typing import Mapping


from gatetherm import InputError
from gatetherm.checks import POSITIVE, Range, argument, number_argument, whole_argument
from gatetherm.geometry.mesh import FrameMesh
from gatetherm.studies.run.case import Case
from gatetherm.studies.run.case import load_case as _load_case
from gatetherm.frame.config import Config
from gatetherm.frame.case import gate_frame as _gate_frame
from gatetherm.frame.conditions import CONDITIONS, condition_schedule
from gatetherm.frame.conditions import condition as _condition
from gatetherm.studies.run.schedules import Schedule, file_schedule

PUBLIC = ("Case", "Schedule", "beam_coefficients", "condition", "gate_frame", "load_case", "nc_schedule",
          "schedule_file")  # offered as gt.NAME (gatetherm.api finds them here)

__all__ = ["Case", "Schedule", "beam_coefficients", "condition", "gate_frame", "load_case", "nc_schedule",
           "schedule_file"]

DIMS = Range(2, 3, whole=True)
NUMBERS = Range(min(CONDITIONS), max(CONDITIONS), whole=True)
PATH = (str, os.PathLike)


def _case(case, name: str = "case") -> Case:
    return argument(name, case, Case, "a Case", "make one with gt.load_case(path) or gt.gate_frame()")


def gate_frame(dim: int = 2, config: Config | str | os.PathLike | None = None, condition: int = 1, *,
               mesh: FrameMesh | None = None) -> Case:
    whole_argument("dim", dim, DIMS, "gate_frame(dim=2): a plane-stress section, or dim=3: the solid")
    argument("config", config, (*PATH, Config, type(None)), "a model file's path, a Config or None",
             "None gives the shipped paper model")
    whole_argument("condition", condition, NUMBERS, "one of the paper's conditions")
    argument("mesh", mesh, (FrameMesh, type(None)), "a FrameMesh of this frame or None")
    return _gate_frame(int(dim), config, int(condition), mesh=mesh)


gate_frame.__doc__ = _gate_frame.__doc__


def load_case(path: str | os.PathLike, mesh_factor: float = 1.0, overrides: dict | None = None) -> Case:
    number_argument("mesh_factor", mesh_factor, POSITIVE, "e.g. 0.5 for elements half as large")
    argument("overrides", overrides, (Mapping, type(None)), "a dict {dotted key: value} or None",
             'e.g. {"thermal.free.film": 8.0}')
    for key in overrides or {}:
        argument("overrides key", key, str, 'a dotted key of the case file, e.g. "thermal.free.film"')
    return _load_case(path, float(mesh_factor), dict(overrides) if overrides is not None else None)


load_case.__doc__ = _load_case.__doc__


def condition(number: int, case: Case | None = None, step_s: float = 60.0) -> Schedule:
    """The paper's condition ``number``: the oil supply unit's set points and pump states.

    Parameters
    ----------
    number : int
        1, 2 or 3 (``docs/paper.md``).
    case : Case, optional
        A frame case whose supply unit drives it (default: the shipped paper model's); a case
        read from a case file has none and is refused.
    step_s : float
        Sample interval, s.

    Returns
    -------
    Schedule
        5 h of ``oil_degC`` (°C), ``pump`` (0/1) and ``ambient_degC`` (°C) samples; a step that
        does not divide the 5 h is refused (the schedule would end short of them).
    """
    number = whole_argument("number", number, NUMBERS, "one of the paper's conditions")
    argument("case", case, (Case, type(None)), "a frame Case or None")
    step_s = number_argument("step_s", step_s, POSITIVE, "e.g. 60")
    duration = _condition(number).duration
    if abs(duration / step_s - round(duration / step_s)) > 1e-9 * duration / step_s:
        raise InputError("step_s", f"{step_s:g} s does not divide the condition's {duration:g} s",
                         "give a divisor of it, e.g. 60")
    supply = getattr(getattr(case, "origin", None), "config", None)
    if case is not None and supply is None:
        raise InputError("case", f"{case.name!r} has no oil supply unit of the paper's model (a case file's "
                         "sources are its own)", "give a frame case (gt.gate_frame), or drive the case by its own "
                         "schedule ([time] schedule)")
    return condition_schedule(number, *(() if supply is None else (supply.supply,)), step_s=step_s)


def nc_schedule(path: str | os.PathLike, step_s: float = 1.0, rapid: float = 30.0, out: str | os.PathLike | None = None,
                repeat: int = 1):
    """An NC program's axis positions, feeds and spindle speed against time: a schedule for a
    case's moving sources and machine elements (``docs/model.md``, NC programs).

    Parameters
    ----------
    path : str or path
        The program: G0/G1 moves with F (mm/min, or inch/min after G20), G4 dwells (X in s, P in
        ms), M3/M4/M5 with S (1/min), G90/G91; anything else (arcs, cycles), an M3/M4 before any S,
        a negative S or F and contradicting G codes in one block are refused by line.
    step_s : float
        Sample interval, s (the program's end is the last sample).
    rapid : float
        The rapid rate of G0 moves, m/min.
    out : str or path, optional
        Also write the schedule there (the data format: a case's ``[time] schedule``); never the
        program itself.
    repeat : int
        Run the program this many times back to back (each from where the last ended); at most
        ``MAX_STEPS`` (10⁶) samples in all.

    Returns
    -------
    TimeSeries
        ``time_s``; ``x_m``, ``y_m``, ``z_m`` (axis positions, m); ``vx_m_s``, ``vy_m_s``, ``vz_m_s``
        (axis velocities, m/s); ``feed_m_s`` (speed along the path, m/s); ``spindle_rpm`` (1/min,
        negative for M4).
    """
    from gatetherm.files import read_text
    from gatetherm.studies.run.ncprogram import nc_series
    from gatetherm.studies.run.timeseries import write_timeseries

    step_s, rapid = number_argument("step_s", step_s, POSITIVE, "e.g. 1.0"), number_argument("rapid", rapid, POSITIVE,
                                                                                             "e.g. 30.0")
    if out is not None and Path(argument("out", out, PATH, "a file's path or None")).resolve() == Path(path).resolve():
        raise InputError("out", f"{out} is the program itself: writing the schedule would destroy it",
                         "give another file, e.g. program.csv")
    if isinstance(repeat, bool) or not isinstance(repeat, int) or repeat < 1:
        raise InputError("repeat", f"{repeat!r} is not a whole number of runs", "give 1 or more")
    ts = nc_series(read_text(path, "", "give an NC program (a text file)"), step_s, str(path), rapid, repeat)
    if out is not None:
        write_timeseries(out, ts)
    return ts


def beam_coefficients(case: Case, source: str = "theory") -> tuple[float, float]:
    """The paper's predictor coefficients, δ = K_i (θ_A − θ_B) − K_C θ_C, of the paper's frame.

    Parameters
    ----------
    case : Case
        A frame from :func:`gate_frame` (a case file has no beam model).
    source : str
        ``"theory"``: the beam theory (eqs. 22–29) on the frame's dimensions; ``"fe"``: the FE
        frame under the theory's two load cases (θ_A − θ_B = 1 K over the heated height, +1 K on
        the tie bar), δ at the tips.

    Returns
    -------
    tuple of float
        K_i, K_C in µm/K.
    """
    from gatetherm.studies.control.methods import Settings, coefficients

    _case(case)
    if source not in ("theory", "fe"):
        raise InputError("source", f"unknown source {source!r}", "choose 'theory' or 'fe'")
    ki, kc, _ = coefficients(case, None, Settings(k_source=source))
    return float(ki), float(kc)


def schedule_file(path: str | os.PathLike, case: Case, step_s: float = 60.0) -> Schedule:
    """A schedule file of the inputs ``case`` reads.

    Parameters
    ----------
    path : str or path
        A time-series file (``docs/data-format.md``) with a column for every input the case reads.
    case : Case
        The case it drives.
    step_s : float
        Sample interval, s (linear between the file's samples; a pump keeps its last one).

    Returns
    -------
    Schedule
    """
    _case(case)
    step_s = number_argument("step_s", step_s, POSITIVE, "e.g. 60")
    return file_schedule(path, sorted(case.inputs()), case.held(), case.defaults, step_s)
