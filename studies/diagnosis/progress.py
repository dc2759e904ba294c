"""Model runs done of those planned: the progress of a diagnosis, and its plan before the search.

Every model run of a diagnosis (a scenario replayed through the case: the baseline, the P2
check, every hypothesis' value tried, every joint refit, the model-form checks) is counted as it
is made (:meth:`Budget.ran`). How many the search will make is known only roughly beforehand:
:meth:`Budget.expect` sets the runs still to come from what the search has left (the first
round's fits of the hypotheses that need runs, the later rounds, the checks), with the runs
per fit and per round measured so far where there are some, else :data:`FIRST_RUNS`, :data:`ROUND_RUNS`
and :data:`CHECK_RUNS` (rough priors: a selection that goes back when the checks reject stand-ins can
take twice the runs planned, and where the plan is reached before the end, a tenth more is planned). ``on_progress(i, n)``
sees ``i`` (runs done) grow by one each run and ``n`` (planned) never below ``i + 1`` until the
diagnosis ends, where ``i == n`` is the number of runs the result reports.
"""
from __future__ import annotations

import logging
from typing import Callable

log = logging.getLogger(__name__)

FIRST_RUNS = 7
"""Model runs of one hypothesis' first fit: a 5-point scan of its range (its model value free) and secant steps."""
ROUND_RUNS = 40
"""Model runs of one later selection round: the best three additions and pairs refitted jointly (36 in the
C-frame's unmarked spindle-length scenario of ``gatetherm validate case-diagnosis``)."""
CHECK_RUNS = 40
"""Model runs after the selection: removal check, swaps, alternatives, model-form checks, uncertainties, shares,
and a selection again without the stand-ins (whose first round is mostly runs made before)."""
LONG_S = 600.0
"""A diagnosis planned to take longer than this (s, at the measured time per run) is announced
with the options that make it cheaper."""


class Budget:
    """Model runs done and planned, reported to ``on_progress(done, planned)`` on every change;
    ``max_pieces``: the most pieces the search chooses (its rounds)."""

    def __init__(self, on_progress: Callable[[int, int], None] | None = None, max_pieces: int = 4, first: int = 1):
        self.on_progress, self.max_pieces = on_progress, max_pieces
        self.done, self.planned = 0, max(first, 1)
        """Runs done; runs planned (``first``: the baseline runs before the search is planned)."""
        self.rounds_left = max(max_pieces - 1, 0)
        """Selection rounds still to come after the first."""
        self.since, self.costs, self.per_round = 0, [], float(ROUND_RUNS)
        """Runs done when the last round ended; the runs each later round took; the runs planned a round."""
        self.shown = (0, 0)

    def _show(self) -> None:
        if self.on_progress is not None and (self.done, self.planned) != self.shown:
            self.shown = (self.done, self.planned)
            self.on_progress(self.done, self.planned)

    def ran(self) -> None:
        """One model run made (where the plan is reached before the end, a tenth more is planned)."""
        self.done += 1
        if self.done >= self.planned:
            self.planned = self.done + max(self.done // 10, 1)
        self._show()

    def expect(self, more: float) -> None:
        """About ``more`` model runs are still to come."""
        self.planned = self.done + max(int(round(more)), 1)
        self._show()

    def later(self) -> float:
        """Runs of what follows the first round: the later rounds and the checks."""
        return self.rounds_left * self.per_round + CHECK_RUNS

    def first_round(self, pool, fit: Callable) -> list:
        """[(piece, fit(piece))] of every hypothesis of ``pool`` (a selection's first round), the plan
        updated after each one that needs runs from the runs its fits took so far."""
        start, n = self.done, sum(p.rerun for p in pool)
        self.expect(n * FIRST_RUNS + self.later())
        out, i = [], 0
        for p in pool:
            out.append((p, fit(p)))
            if p.rerun:
                i += 1
                self.expect((n - i) * (self.done - start) / i + self.later())
        self.since = self.done
        return out

    def round_done(self, chosen: int) -> None:
        """A later selection round ended with ``chosen`` pieces chosen: the rounds left planned at the
        runs a round took so far (at least :data:`ROUND_RUNS`)."""
        self.costs.append(self.done - self.since)
        self.since, self.per_round = self.done, max(ROUND_RUNS, sum(self.costs) / len(self.costs))
        self.rounds_left = max(self.max_pieces - chosen - 1, 0)
        self.expect(self.later())

    def announce(self, pool, per_run: float, order: int, p1_run: float | None = None) -> None:
        """Log the runs a search over ``pool`` plans and roughly how long they take at ``per_run`` seconds
        (:func:`plan_line`): a warning where that is longer than :data:`LONG_S`, else an info line."""
        rerun = sum(p.rerun for p in pool)
        line = plan_line(rerun, len(pool), self.done, per_run, order, self.max_pieces, p1_run)
        long = planned_runs(rerun, self.done, self.max_pieces) * per_run > LONG_S
        log.log(logging.WARNING if long else logging.INFO, line)

    def finish(self) -> None:
        """The diagnosis ended: planned = done."""
        self.planned = self.done
        if self.on_progress is not None:
            self.on_progress(self.done, self.done)


def planned_runs(rerun: int, runs: int, max_pieces: int) -> int:
    """The model runs a search over ``rerun`` hypotheses that need runs is planned to make in all,
    ``runs`` made before it."""
    return runs + rerun * FIRST_RUNS + max(max_pieces - 1, 0) * ROUND_RUNS + CHECK_RUNS


def plan_line(rerun: int, pieces: int, runs: int, per_run: float, order: int, max_pieces: int,
              p1_run: float | None = None) -> str:
    """The announcement of a diagnosis: the runs planned (``runs`` made already), roughly how long at
    ``per_run`` seconds (the baseline run of the model replayed, measured), and what makes it cheaper
    (``p1_run``: the P1 baseline's seconds, where the diagnosis replays with P2 elements)."""
    planned = planned_runs(rerun, runs, max_pieces)
    cheaper = ("--effects none, --parameters NAME,... or --no-sensors try fewer hypotheses (about "
               f"{FIRST_RUNS} runs each of the {rerun} that need runs)")
    if order == 2 and p1_run is not None:
        cheaper += f"; --keep-order replays with P1 elements ({p1_run:.1f} s a run, but see the discretisation check)"
    return (f"diagnosis: about {planned} model runs planned ({pieces} hypotheses, {rerun} of them need model runs), "
            f"{per_run:.1f} s a run (the baseline, P{order}): about {planned * per_run / 60:.0f} min (up to twice that "
            f"where the model-form checks send the selection back); {cheaper}")
