"""A small NC-program reader: a program's axis positions, feeds and spindle speed against time,
as a schedule (a :class:`~gatetherm.studies.run.timeseries.TimeSeries`) that a case's moving
sources and machine elements read.

Read: ``G0`` (rapid: every axis at the rapid rate, the move straight, taking the slowest axis's
time), ``G1`` with ``F`` (feed along the path, mm/min or inch/min), ``G4`` dwell (``X`` or ``U``
in s, ``P`` in ms, the Fanuc convention), ``M3``/``M4``/``M5`` with ``S`` (spindle speed, 1/min;
``M4`` counts negative), ``G90``/``G91`` (absolute, incremental), ``G20``/``G21`` (inch, mm),
``G17``/``G94`` (accepted, no effect), ``M8``/``M9`` (coolant: ignored), ``M2``/``M30`` (end),
``N`` (line numbers) and ``T`` (tool numbers: no time). Comments in ``( )`` or after ``;``.
Anything else (arcs ``G2``/``G3``, cycles, other words) is one :class:`~gatetherm.InputError`
line naming the program's line: the schedule would otherwise miss a move.
"""
from __future__ import annotations

import re
from dataclasses import dataclass

import numpy as np

from gatetherm import InputError
from gatetherm.studies.run.timeseries import MAX_STEPS, TimeSeries, check_steps

AXES = "XYZ"
WORD = re.compile(r"([A-Z])\s*([-+]?(?:\d+\.?\d*|\.\d+))")
COLUMNS = ("x_m", "y_m", "z_m", "vx_m_s", "vy_m_s", "vz_m_s", "feed_m_s", "spindle_rpm")
"""The schedule's columns besides ``time_s``: axis positions (m), axis velocities (m/s), the speed
along the path (m/s) and the spindle's speed (1/min)."""


@dataclass(frozen=True)
class Segment:
    """One block's motion: from ``start`` to ``end`` (m) in ``duration`` s, the spindle at ``spindle``."""

    start: tuple[float, float, float]
    end: tuple[float, float, float]
    duration: float
    spindle: float


def _strip(line: str) -> str:
    return re.sub(r"\([^)]*\)", " ", line).split(";")[0].upper()


def segments(text: str, where: str = "program", rapid: float = 30.0, start=(0.0, 0.0, 0.0)) -> list[Segment]:
    """The motion of an NC program ``text`` block by block from the axis position ``start`` (m);
    ``rapid`` the rapid rate, m/min."""
    pos, feed, spindle, s_word, absolute, unit, motion = list(start), None, 0.0, 0.0, True, 1e-3, None
    out = []
    for number, raw in enumerate(text.splitlines(), 1):
        line = _strip(raw)
        words = WORD.findall(line)
        rest = WORD.sub("", line).strip()
        here = f"{where}, line {number}"
        if rest:
            raise InputError(here, f"cannot read '{rest}'", "write words such as G1 X10 F500 (comments in parentheses)")
        g = [float(v) for k, v in words if k == "G"]
        m = [float(v) for k, v in words if k == "M"]
        vals = {k: float(v) for k, v in words if k not in "GMN"}
        dwell = 4.0 in g
        for group in ({0.0, 1.0}, {20.0, 21.0}, {90.0, 91.0}):
            if len(group & set(g)) > 1:
                raise InputError(here, f"{' and '.join(f'G{c:g}' for c in sorted(group))} in one block contradict",
                                 "keep the one meant")
        for code in g:
            if code in (0.0, 1.0):
                motion = int(code)
            elif code in (20.0, 21.0):
                unit = 0.0254 if code == 20.0 else 1e-3
            elif code in (90.0, 91.0):
                absolute = code == 90.0
            elif code not in (4.0, 17.0, 94.0):
                raise InputError(here, f"G{code:g} is not read" + (" (arcs)" if code in (2.0, 3.0) else ""),
                                 "write the path as G1 lines (a CAM post-processor can)")
        unknown = sorted(set(vals) - set("XYZFSPTU"))
        if unknown:
            raise InputError(here, f"the word {unknown[0]} is not read", "give G0/G1 moves, G4 dwells, F, S, M3/M4/M5")
        for k in ("S", "F"):
            if vals.get(k, 0.0) < 0:
                raise InputError(here, f"{k}{vals[k]:g} is negative", "give the speed as a number >= 0 (M4 turns the "
                                 "spindle backwards)" if k == "S" else "give the feed as a number > 0")
        if "S" in vals:
            s_word = vals["S"]
            spindle = abs(s_word) * np.sign(spindle) if spindle else spindle
        for code in m:
            if code in (3.0, 4.0):
                if not s_word:
                    raise InputError(here, f"M{code:g} starts the spindle without a speed",
                                     "give S (1/min) on or before it, e.g. M3 S8000")
                spindle = abs(s_word) * (1.0 if code == 3.0 else -1.0)
            elif code == 5.0:
                spindle = 0.0
            elif code in (2.0, 30.0):
                return out
            elif code not in (8.0, 9.0):
                raise InputError(here, f"M{code:g} is not read", "M3/M4/M5 (spindle), M8/M9, M2/M30")
        if "F" in vals:
            feed = vals["F"] * unit / 60.0
        if dwell:
            seconds = vals.get("X", vals.get("U", vals.get("P", 0.0) / 1000.0 if "P" in vals else None))
            if seconds is None or seconds < 0:
                raise InputError(here, "a dwell without its time", "G4 X2.5 (s) or G4 P2500 (ms)")
            out.append(Segment(tuple(pos), tuple(pos), float(seconds), spindle))
            continue
        stray = next((k for k in "PU" if k in vals), None)
        if stray:
            raise InputError(here, f"the word {stray} goes with a G4 dwell only", "remove it or give G4")
        target = [(vals[a] * unit if absolute else pos[i] + vals[a] * unit) if a in vals else pos[i]
                  for i, a in enumerate(AXES)]
        if target == pos:
            continue
        if motion is None:
            raise InputError(here, "a move without G0 or G1", "give G0 or G1 before the first move")
        delta = np.subtract(target, pos)
        if motion == 0:
            duration = float(np.max(np.abs(delta))) / (rapid / 60.0)
        else:
            if not feed:
                raise InputError(here, "a G1 move without a feed", "give F (mm/min) on or before it")
            duration = float(np.linalg.norm(delta)) / feed
        out.append(Segment(tuple(pos), tuple(target), duration, spindle))
        pos = target
    return out


def nc_series(text: str, step_s: float = 1.0, where: str = "program", rapid: float = 30.0,
              repeat: int = 1) -> TimeSeries:
    """The schedule of an NC program ``text`` run ``repeat`` times back to back (each run from where
    the last ended): the columns :data:`COLUMNS` every ``step_s`` seconds (and at its end), each
    the value at that instant (velocities: of the block then running, a block's start belonging
    to it)."""
    segs: list[Segment] = []
    for i in range(repeat):
        segs += segments(text, where, rapid, segs[-1].end if segs else (0.0, 0.0, 0.0))
        if i == 0:  # the budget before the repeats are parsed: a program run 10^9 times is no hang
            once = sum(s.duration for s in segs)
            if once > 0:
                check_steps(once * repeat, step_s, f"{where} run {repeat} times")
            if len(segs) * repeat > MAX_STEPS:
                raise InputError(f"{where} run {repeat} times", f"{len(segs) * repeat} blocks, more than {MAX_STEPS}",
                                 "give fewer repeats")
    segs = [s for s in segs if s.duration > 0]
    if not segs:
        raise InputError(where, "has no move or dwell", "give G0/G1 moves or G4 dwells")
    ends = np.cumsum([s.duration for s in segs])
    starts = ends - [s.duration for s in segs]
    t = np.arange(0.0, ends[-1], step_s)
    t = np.r_[t, ends[-1]] if ends[-1] - t[-1] > 1e-9 * step_s else t
    k = np.minimum(np.searchsorted(ends, t, side="right"), len(segs) - 1)
    a, b = np.array([segs[i].start for i in k]), np.array([segs[i].end for i in k])
    dur = np.array([segs[i].duration for i in k])
    frac = np.clip((t - starts[k]) / dur, 0.0, 1.0)[:, None]
    v = (b - a) / dur[:, None]
    cols = {"time_s": t, **{f"{c}_m": (a + frac * (b - a))[:, i] for i, c in enumerate("xyz")},
            **{f"v{c}_m_s": v[:, i] for i, c in enumerate("xyz")}, "feed_m_s": np.linalg.norm(v, axis=1),
            "spindle_rpm": np.array([segs[i].spindle for i in k])}
    return TimeSeries(cols, {"source": f"NC program {where}"})
