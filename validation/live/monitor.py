"""The never-worse monitor of ``gatetherm live``: the batch commands refuse a method that makes δ
worse on the held-out part of a record (:mod:`gatetherm.studies.control.benefit`); beside a machine
the same comparison runs on the samples as they come.

Where the machine reports its measured δ (``delta_um``, uncompensated, as the twin does), every
good period adds a pair to a running window: the uncompensated δ and the compensated residual,
the machine's own ``delta_residual_um`` where it reports one (what the correction really left, so
a wrong sign or scale in the map shows), else ``delta_um`` plus the correction held over that
period (an ideal axis offset). Rule: once the window holds :attr:`Monitor.window` pairs, the
compensation is **worse** when the largest |residual| over the window exceeds the largest |δ| over
it by more than :attr:`Monitor.margin_um` (the largest |δ|, as :mod:`~gatetherm.studies.control.benefit`
judges it). The verdict is warned once (the log and ``events.log``), shown on the status page
(``worse`` among the counts), flagged in every later row of ``live.csv`` (``worse`` = 1) and kept
in the state, so a restart into the same ``--out`` stays fallen back; then
:attr:`Monitor.fallback` applies: ``"zero"`` (default) ramps the correction to zero at the change
limit per period (``Guards.max_change_um``), ``"hold"`` holds the value written at the verdict,
``"warn"`` only warns and flags. There is no automatic return: fix the cause, then start with a
fresh ``--out``.
"""
from __future__ import annotations

import logging
import math
from dataclasses import dataclass

from gatetherm import InputError

log = logging.getLogger(__name__)

FALLBACKS = ("zero", "hold", "warn")


@dataclass(frozen=True)
class Monitor:
    """When ``live`` judges its compensation worse than none, and what it does then."""

    window: int = 30
    """Good periods with a measured δ compared (the last ones; 30 min at a 60-s period)."""
    margin_um: float = 1.0
    """How far the compensated residual's largest |δ| over the window may exceed the uncompensated
    one's before the compensation counts as worse, µm (ten readings' resolution)."""
    fallback: str = "zero"
    """After a worse verdict: ``"zero"`` (ramp the correction to 0 at ``max_change_um`` per period),
    ``"hold"`` (keep the value written at the verdict) or ``"warn"`` (warn and flag only)."""

    def __post_init__(self):
        if isinstance(self.window, bool) or not isinstance(self.window, int) or self.window < 2:
            raise InputError("monitor window (--window)", f"{self.window!r} is not a whole number of periods >= 2", "e.g. 30")
        if not (math.isfinite(self.margin_um) and self.margin_um >= 0):
            raise InputError("monitor margin (--margin)", f"{self.margin_um!r} is not a number of um >= 0", "e.g. 1.0")
        if self.fallback not in FALLBACKS:
            raise InputError("monitor fallback (--fallback)", f"{self.fallback!r} is not one of {', '.join(FALLBACKS)}",
                             "e.g. zero")


class Watch:
    """The running comparison and its verdict (JSON-ready state)."""

    def __init__(self, monitor: Monitor, state: dict | None = None):
        s = state or {}
        self.m = monitor
        self.pairs: list[list[float]] = [list(p) for p in s.get("pairs", [])]
        self.worse: dict | None = s.get("worse")
        """The verdict (``t_s``, ``compensated_um``, ``uncompensated_um``, ``held_um``) or None."""

    def add(self, t: float, uncompensated: float, compensated: float, written: float) -> dict | None:
        """One good period's pair (µm); the verdict if it turns worse now, else None."""
        if self.worse is not None or not (math.isfinite(uncompensated) and math.isfinite(compensated)):
            return None
        self.pairs = (self.pairs + [[float(uncompensated), float(compensated)]])[-self.m.window:]
        if len(self.pairs) < self.m.window:
            return None
        unc = max(abs(u) for u, _ in self.pairs)
        comp = max(abs(c) for _, c in self.pairs)
        if comp > unc + self.m.margin_um:
            self.worse = {"t_s": float(t), "compensated_um": comp, "uncompensated_um": unc, "held_um": float(written)}
            log.warning("compensation makes delta worse: largest |residual| %.2f um > %.2f um uncompensated over "
                        "the last %d periods; fallback: %s", comp, unc, self.m.window, self.m.fallback)
            return self.worse
        return None

    def command(self, wanted: float) -> float:
        """The command to pass on: the compensator's ``wanted`` unless fallen back."""
        if self.worse is None or self.m.fallback == "warn":
            return wanted
        return 0.0 if self.m.fallback == "zero" else self.worse["held_um"]

    def state(self) -> dict:
        return {"pairs": self.pairs, "worse": self.worse}
