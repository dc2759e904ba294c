"""The loads a placement is trained and judged on: duty cycles of a case's inputs.

The inputs are the case's schedule columns (:meth:`~gatetherm.studies.run.case.Case.inputs`); each
varies within a stated range ``[lo, hi]`` (by default the range it spans over the schedules the
case knows) from a rest value: a temperature column (``*_degC``) rests at the case's initial
temperature T0 (clipped into its range: a machine at rest is at one temperature), any other input
at ``lo``; a pump state (held) is on (1) or off (0), resting off, between 0 and 1 unless stated
(``1:1``: always on, ``0:0``: always off).

A generated family (:func:`duty_cycles`) cycles through three kinds, every input at once, with
times and levels drawn from a seeded generator (the same seed and label give the same loads):

* ``step``: each input switches at its own time in the first 30 % of the run to a level in the
  upper half of its range (a pump: on), and back to rest at a time in 50-90 %;
* ``ramp``: each input rises linearly from rest to such a level over 20-50 % of the run, holds,
  and falls back linearly to rest by the end (a pump is on from the start of the rise to the end
  of the fall);
* ``random``: a piecewise-constant duty cycle, segments of 5-25 % of the run, each input at a
  level drawn uniformly from its range in every segment (a pump on or off with even odds).
"""
from __future__ import annotations

import zlib
from dataclasses import dataclass

import numpy as np

from gatetherm import InputError
from gatetherm.studies.run.conditions import TableDrive
from gatetherm.studies.run.schedules import Schedule

KINDS = ("step", "ramp", "random")


@dataclass(frozen=True)
class InputRange:
    """How one input of a case may vary in a generated duty cycle."""

    name: str
    """The schedule column."""
    lo: float
    """Lowest value, the input's unit."""
    hi: float
    """Highest value, the input's unit."""
    rest: float
    """Its value at rest, where every generated load starts."""
    held: bool = False
    """A pump state: 0 or 1, kept between samples."""


def columns(schedule: Schedule, names, defaults=None) -> dict[str, np.ndarray]:
    """``time_s`` (the schedule's times) and each input of ``names`` at those times (a name the
    drive lacks takes its value from ``defaults``)."""
    rows = [schedule.drive(float(t)) for t in schedule.times]
    defaults = dict(defaults or {})
    out = {"time_s": np.asarray(schedule.times, float)}
    for n in names:
        if n not in rows[0] and n not in defaults:
            raise InputError(f"schedule '{schedule.label}', column {n}", "missing: the case reads it",
                             "give every input the case reads")
        out[n] = np.array([r.get(n, defaults.get(n)) for r in rows], float)
    return out


def input_ranges(case, schedules, given=None) -> tuple[InputRange, ...]:
    """The range of every input of ``case``: ``given`` ({name: (lo, hi)}) where stated, else the
    span of its values over ``schedules``; rest values as the module docstring says."""
    names = sorted(case.inputs())
    given = dict(given or {})
    for k, (lo, hi) in given.items():
        if k not in names:
            raise InputError(f"--range {k}", "is not an input of the case", f"inputs: {', '.join(names) or 'none'}")
        if not (np.isfinite(lo) and np.isfinite(hi) and lo <= hi):
            raise InputError(f"--range {k}", f"{lo:g}:{hi:g} is not LO:HI with LO <= HI", f"e.g. --range {k}=0:200")
    for k, (lo, hi) in given.items():
        if k in case.held() and not {lo, hi} <= {0.0, 1.0}:
            raise InputError(f"--range {k}", f"{lo:g}:{hi:g}: a pump state is 0 (off) or 1 (on)",
                             f"give {k}=1:1 (always on), {k}=0:0 or {k}=0:1")
    todo = [n for n in names if n not in given and n not in case.held()]
    if todo and not schedules:
        raise InputError(f"--range {todo[0]}", "not given, and the case has no schedule to take it from",
                         f"give --range {todo[0]}=LO:HI")
    seen = [columns(s, names, case.defaults) for s in schedules]
    out = []
    for n in names:
        held = n in case.held()
        lo, hi = given[n] if n in given else (0.0, 1.0) if held else \
            (min(float(c[n].min()) for c in seen), max(float(c[n].max()) for c in seen))
        rest = float(np.clip(case.problem.T0, lo, hi)) if n.endswith("_degC") and not held else lo
        out.append(InputRange(n, float(lo), float(hi), rest, held))
    return tuple(out)


def _level(r: InputRange, rng, upper: bool = False) -> float:
    if r.held:  # within its stated states
        return r.hi if upper else float(rng.integers(int(r.lo), int(r.hi) + 1))
    return float(rng.uniform(r.lo + 0.5 * (r.hi - r.lo) if upper else r.lo, r.hi))


def _profile(kind: str, r: InputRange, t: np.ndarray, rng) -> np.ndarray:
    end = float(t[-1])
    v = np.full(t.size, r.rest)
    if kind == "step":
        on, off, level = rng.uniform(0, 0.3 * end), rng.uniform(0.5 * end, 0.9 * end), _level(r, rng, True)
        v[(t >= on) & (t < off)] = level
    elif kind == "ramp":
        a = rng.uniform(0, 0.2 * end)
        b = a + rng.uniform(0.2, 0.5) * end
        d = rng.uniform(b, end)
        c = rng.uniform(b, d)
        level = _level(r, rng, True)
        if r.held:
            v[(t >= a) & (t < d)] = level
        else:
            v = np.interp(t, [0.0, a, b, c, d, end + 1.0], [r.rest, r.rest, level, level, r.rest, r.rest])
    else:
        start = 0.0
        while start < end:
            length = rng.uniform(0.05, 0.25) * end
            v[(t >= start) & (t < start + length)] = _level(r, rng)
            start += length
    return v


def seed_of(seed: int, label: str) -> list[int]:
    """The generator seed of a family: ``seed`` and the label's CRC-32 (the same for the same inputs)."""
    return [int(seed), zlib.crc32(label.encode())]


def duty_cycles(ranges, count: int, duration_s: float, step_s: float, seed: int = 0,
                label: str = "training") -> list[Schedule]:
    """``count`` generated loads (module docstring) of ``duration_s`` sampled every ``step_s`` (s)."""
    if not duration_s >= 2 * step_s > 0:
        raise InputError("duration_s", f"{duration_s:g} s is not two or more {step_s:g}-s steps (step_s) of a "
                         "generated duty cycle", "give a longer duration_s or a shorter step_s, both > 0")
    rng = np.random.default_rng(seed_of(seed, label))
    t = np.arange(int(round(duration_s / step_s)) + 1) * float(step_s)
    held = frozenset(r.name for r in ranges if r.held)
    out = []
    for i in range(count):
        kind = KINDS[i % len(KINDS)]
        cols = {r.name: _profile(kind, r, t, rng) for r in ranges}
        out.append(Schedule(TableDrive(t, cols, held), t, f"{label} {i + 1}: {kind}"))
    return out
