"""Forward selection of hypotheses with held-out evidence.

Start from the baseline model. Each round fits every hypothesis not yet chosen *added*
to the chosen ones (which keep their values; sensor offsets, gains and drifts are
re-solved) and scores it on the held-out window (:class:`calibrate.Objective`). In the
first round every hypothesis is fitted alone; later, a hypothesis that needs model runs
is first screened by superposing its first-round runs on the current model, and only the
best ``screen_top`` of those are fitted for real. The best addition is kept when it
lowers the score (penalty included) by at least ``margin_min``; then all chosen
hypotheses are refitted jointly. Rounds stop when the held-out residual is nowhere
significant, when no addition clears the margin, or at ``max_pieces``. Then every
chosen piece is checked by removing it and refitting the others: a piece whose removal
costs less than the margin is dropped. Last, a close runner-up of the round that added
a piece is swapped in for it and refitted: if that scores within the margin, the data
cannot tell the two apart and the piece lists it as an alternative.
"""
from __future__ import annotations

import logging
from dataclasses import dataclass, field

from gatetherm.studies.diagnosis.calibrate import Objective, Scored, fit_one, refit, superposed
from gatetherm.studies.diagnosis.hypotheses import Piece

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class Round:
    """One round of forward selection: every addition tried, best first."""

    trials: tuple[tuple[Piece, Scored], ...]
    added: Piece | None
    before: float
    """Score of the chosen set before the round."""


@dataclass
class Selection:
    """The outcome: the chosen set, how it was reached and what was checked."""

    base: Scored
    final: Scored
    order: list[Piece]
    """Chosen pieces in the order they were added."""
    rounds: list[Round] = field(default_factory=list)
    removed: list[Piece] = field(default_factory=list)
    """Pieces chosen, then dropped by the removal check."""
    alternatives: dict = field(default_factory=dict)
    """{piece: [pieces that explain the data as well in its place]}."""
    best_rejected: tuple[Piece, Scored] | None = None
    """The best addition that did not clear the margin in the last round."""


def _round(obj: Objective, current: Scored, pool: list[Piece], top: int) -> list[tuple[Piece, Scored]]:
    ctx = current.values
    trials, screened = [], []
    for p in pool:
        if not p.rerun or not ctx:
            trials.append((p, obj.scored(fit_one(obj, ctx, p))))
        else:
            s = superposed(obj, ctx, p)
            screened.append((p, s)) if s is not None else trials.append((p, obj.scored(fit_one(obj, ctx, p))))
    screened.sort(key=lambda ps: ps[1].score)
    for i, (p, s) in enumerate(screened):
        trials.append((p, obj.scored(fit_one(obj, ctx, p, start=s.values[p])) if i < top else s))
    return sorted(trials, key=lambda ps: (ps[1].approx, ps[1].score))


def select(obj: Objective, candidates: list[Piece], margin: float, max_pieces: int = 4, top: int = 3) -> Selection:
    base = obj.scored({})
    sel = Selection(base, base, [])
    fits: dict[frozenset, Scored] = {}
    current = base
    while len(current.values) < max_pieces:
        pool = [p for p in candidates if p not in current.values and p not in sel.removed]
        if not pool:
            break
        trials = _round(obj, current, pool, top)
        if not current.values:
            fits.update({frozenset([p]): s for p, s in trials})
        p, best = trials[0]
        gain = current.score - best.score
        log.info("round %d: best addition %s (gain %.1f), %d model runs so far", len(sel.rounds) + 1, p.label, gain,
                 obj.replayer.runs)
        if gain < margin:
            sel.rounds.append(Round(tuple(trials), None, current.score))
            sel.best_rejected = (p, best)
            break
        sel.rounds.append(Round(tuple(trials), p, current.score))
        current = obj.scored(refit(obj, best.values))
        fits[frozenset(current.values)] = current
        sel.order.append(p)
        if current.explains:
            break
    current = _removal(obj, sel, current, fits, margin)
    sel.final = current
    _alternatives(obj, sel, margin)
    return sel


def _removal(obj: Objective, sel: Selection, current: Scored, fits: dict, margin: float) -> Scored:
    while len(current.values) >= 2:
        costs = []
        for p in current.values:
            rest = frozenset(current.values) - {p}
            if rest not in fits:
                fits[rest] = obj.scored(refit(obj, {q: current.values[q] for q in rest}))
            costs.append((fits[rest].score - current.score, p, fits[rest]))
        cost, p, without = min(costs, key=lambda c: c[0])
        if cost >= margin:
            break
        log.info("removal check: %s not needed (removing it costs %.1f)", p.label, cost)
        sel.removed.append(p)
        sel.order.remove(p)
        current = without
    return current


def _alternatives(obj: Objective, sel: Selection, margin: float, most: int = 2) -> None:
    final = sel.final
    for rnd in sel.rounds:
        p = rnd.added
        if p is None or p not in final.values:
            continue
        mine = next(s for q, s in rnd.trials if q == p)
        close = [(q, s) for q, s in rnd.trials if q != p and q not in final.values and s.score - mine.score < margin]
        for q, s in close[:most]:
            rest = {r: v for r, v in final.values.items() if r != p}
            swapped = obj.scored(refit(obj, {**rest, q: s.values[q]}))
            if swapped.score - final.score < margin:
                sel.alternatives.setdefault(p, []).append(q)
                log.info("%s and %s explain the data equally well (scores %.1f, %.1f)", p.label, q.label,
                         final.score, swapped.score)
