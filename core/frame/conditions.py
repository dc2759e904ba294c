"""The paper's experiments as oil-supply schedules: :data:`CONDITIONS` (conditions 1-3),
:func:`condition`, a condition as a :class:`~gatetherm.studies.run.schedules.Schedule`
(:func:`condition_schedule`), and the paper's conditions 1-3 as the held-out loads of a case
driven by the oil supply's inputs (:func:`paper_conditions`, the sensor study's default, passed in
by the API). The supply unit's model (segments, first-order approach to the set point) is generic:
:mod:`gatetherm.studies.run.conditions`.
"""
from __future__ import annotations

from gatetherm import InputError
from gatetherm.studies.run.conditions import HOUR, Condition, Segment, SupplyParams, condition_drive
from gatetherm.studies.run.schedules import Schedule
from gatetherm.studies.run.simulate import sample_times
from gatetherm.studies.run.timeseries import AMBIENT, PUMP, SUPPLY


def _alternating(T0: float | None, name: str) -> Condition:
    return Condition(name, tuple(Segment(k * HOUR, k % 2 == 0, 40.0) for k in range(5)), T0)


CONDITIONS: dict[int, Condition] = {
    1: _alternating(40.0, "oil pre-heated to 40 °C; pump on at 0, then OFF/ON/OFF/ON hourly"),
    2: _alternating(None, "heater and pump start at 0 from 20 °C oil; then pump OFF/ON/OFF/ON hourly"),
    3: Condition("as 2; oil forced to 20 °C at 1 h, 40 °C again at 2 h; pump off 3–4 h",
                 (Segment(0, True, 40.0), Segment(HOUR, True, 20.0), Segment(2 * HOUR, True, 40.0),
                  Segment(3 * HOUR, False, 40.0), Segment(4 * HOUR, True, 40.0)), None),
}


def condition(number: int) -> Condition:
    if number not in CONDITIONS:
        raise InputError("--condition", f"no condition {number}",
                         f"choose one of {', '.join(map(str, CONDITIONS))} or give a schedule file")
    return CONDITIONS[number]


def condition_schedule(number: int, supply: SupplyParams = SupplyParams(), step_s: float = 60.0) -> Schedule:
    """The paper's condition ``number`` (its oil supply unit ``supply``), sampled every ``step_s``."""
    cond = condition(number)
    return Schedule(condition_drive(cond, supply), sample_times(cond.duration, step_s),
                    f"condition {number}: {cond.name}", number)


def paper_conditions(case) -> list[Schedule]:
    """The paper's conditions 1-3 (driven by the case's oil supply unit: the frame's model file's, else the
    default) if the case reads only the frame's inputs (oil supply, pump, room), else none."""
    if not case.inputs() or not case.inputs() <= {SUPPLY, PUMP, AMBIENT} or PUMP not in case.inputs():
        return []
    supply = getattr(case.origin, "supply", None)  # the paper frame's oil supply unit (its model file's)
    return [condition_schedule(n, *(() if supply is None else (supply,))) for n in (1, 2, 3)]
