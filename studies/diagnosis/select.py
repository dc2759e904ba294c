"""Forward selection of hypotheses with held-out evidence.

Start from the baseline model. The first round fits every hypothesis alone and scores
it on the held-out window (:class:`calibrate.Objective`). Each later round adds every
hypothesis not yet chosen to the chosen ones and refits *all* of them on a surrogate
that needs no model run (:mod:`surrogate`); the best ``screen_top`` sets are then refitted
jointly for real (bounded least squares from the surrogate's values). Every round also
looks one step ahead: every pair of additions is fitted on the surrogate (from the
single fits) and the best two pairs for real, so that two pieces that hide each other (each alone
fits badly, e.g. film coefficients to air and to the oil both off) are found together.
The best addition is kept when it lowers the score (penalty included) by at least
``margin_min`` (a pair: when it also beats the best single addition by it). Rounds stop
when the residual is nowhere significant (training window included), when no addition
clears the margin, or at ``max_pieces``. Then every chosen piece is checked by removing
it and refitting the others: a piece whose removal costs less than the margin is dropped,
and so is a piece that changes no channel by the sensor resolution (a model error below
the resolution is not a finding). If a significant residual remains, one chosen piece may
be swapped for one not chosen (the best swaps on the surrogate, refitted for real, kept
when they gain the margin), and the rounds go on (at most ``swaps`` times). Last, every
piece not chosen is put in place of each chosen one on the surrogate; where that scores
within the margin, the closest are refitted for real, and if they still do, the data
cannot tell the two apart: the chosen piece lists them as alternatives (a proportional
partner, such as α for a gain of the δ sensor, is refitted for real whatever the surrogate says).

A hypothesis whose model run the model refuses (an InputError of the model: a part it leaves
free to move, a singular system; :class:`~calibrate.Refused`) leaves the search with its
reason (:attr:`Selection.dropped`): it is one hypothesis that cannot be, never the end of the
diagnosis. :func:`select_confirmed` runs the selection again without the pieces the model-form
checks reject as stand-ins, so that the next candidates get their turn.
"""
from __future__ import annotations

import dataclasses
import logging
from dataclasses import dataclass, field
from itertools import combinations

import numpy as np

from gatetherm.studies.diagnosis.calibrate import Objective, Refused, Scored, fit_one, refit
from gatetherm.studies.diagnosis.hypotheses import PROPORTIONAL, Piece
from gatetherm.studies.diagnosis.replay import resolution
from gatetherm.studies.diagnosis.surrogate import Surrogate, screen
from gatetherm.studies.diagnosis.backtrack import select_confirmed  # noqa: F401 (its home before)

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class Round:
    """One round of forward selection: every addition tried, best first."""

    trials: tuple[tuple[Piece, Scored], ...]
    """Single additions."""
    pairs: tuple[tuple[tuple[Piece, Piece], Scored], ...]
    """Two-piece additions (look-ahead), best first."""
    added: tuple[Piece, ...]
    """What the round added (nothing, one piece, or a pair)."""
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
    """Pieces chosen, then dropped by the removal check or swapped out."""
    alternatives: dict = field(default_factory=dict)
    """{piece: [pieces that explain the data as well in its place]}."""
    in_place: dict = field(default_factory=dict)
    """{(piece, alternative): the chosen set refitted with the alternative in the piece's place}."""
    best_rejected: tuple[Piece, Scored] | None = None
    """The best addition that did not clear the margin in the last round."""
    dropped: dict = field(default_factory=dict)
    """{piece: why}: hypotheses whose model run the model refused, out of the search."""
    stand_ins: dict = field(default_factory=dict)
    """{piece: (value, why)}: pieces the model-form checks rejected, out of the search
    (:func:`select_confirmed`)."""


def _drop(dropped: dict, refused: Refused, ran=()) -> None:
    """The hypothesis of a refused run that was not in the set that ran (``ran``) leaves the search;
    where two or more new ones are refused together, only that set is skipped."""
    new = [p for p in refused.pieces if p not in ran]
    if len(new) != 1:
        log.info("the model refuses %s together: that set is skipped", " + ".join(p.label for p in new))
        return
    if new[0] not in dropped:
        dropped[new[0]] = str(refused.error)
        log.warning("hypothesis %s dropped: the model refuses it (%s)", new[0].label, refused.error)


def _best_first(trials):
    return sorted(trials, key=lambda t: (t[1].approx, t[1].score))


def _round(obj: Objective, current: Scored, pool: list[Piece], top: int, fits: dict, pair_top: int = 3,
           dropped: dict | None = None) -> Round:
    """Every single addition (fitted for real in the first round, else on the surrogate with
    the best ``top`` refitted for real), then every pair of additions on the surrogate
    (starting from the single fits), the best ``pair_top`` pairs refitted for real (three
    since the frame's dimensions joined the pool: with two, a dimension's pair, which the
    surrogate ranks too well, took the place of the hidden pair in a compound case). A piece
    whose run the model refuses goes to ``dropped`` and out of the round."""
    ctx, dropped = current.values, {} if dropped is None else dropped

    def tried(fit):  # a Scored, or None where the model refuses the set (its new pieces dropped)
        try:
            return fit()
        except Refused as err:
            _drop(dropped, err, ctx)
            return None

    if not ctx:  # the plan of the model runs updated after every fit (:meth:`~.progress.Budget.first_round`)
        singles = obj.replayer.budget.first_round(pool, lambda p: tried(lambda: obj.scored(fit_one(obj, {}, p))))
        singles = [(p, s) for p, s in singles if s is not None]
        fits.update({frozenset([p]): s for p, s in singles})
    sur = Surrogate(obj, ctx)
    if ctx:
        screened = sorted(((p, screen(sur, ctx, {p: None})) for p in pool if sur.usable(p)),
                          key=lambda ps: ps[1].score)
        singles = [(p, tried(lambda p=p: obj.scored(fit_one(obj, ctx, p)))) for p in pool if not sur.usable(p)]
        for i, (p, s) in enumerate(screened):
            singles.append((p, tried(lambda s=s: _real(obj, s, fits)) if i < top else s))
        singles = [(p, s) for p, s in singles if s is not None and p not in dropped]
    singles = _best_first(singles)
    lead = [(p, s) for p, s in singles if sur.usable(p)]
    pairs = sorted((((p, q), screen(sur, ctx, {p: sp.values[p], q: sq.values[q]}))
                    for (p, sp), (q, sq) in combinations(lead, 2)), key=lambda t: t[1].score)
    pairs = [(pq, tried(lambda s=s: _real(obj, s, fits)) if i < pair_top else s) for i, (pq, s) in enumerate(pairs)]
    pairs = [(pq, s) for pq, s in pairs if s is not None and not set(pq) & set(dropped)]
    return Round(tuple(singles), tuple(_best_first(pairs)), (), current.score)


def _real(obj: Objective, screened: Scored, fits: dict) -> Scored:
    """A set screened on the surrogate, refitted jointly for real from the surrogate's values."""
    s = fits[frozenset(screened.values)] = obj.scored(refit(obj, screened.values, max_nfev=5))
    return s


def select(obj: Objective, candidates: list[Piece], margin: float, max_pieces: int = 4, top: int = 3,
           swaps: int = 2, dropped: dict | None = None) -> Selection:
    """Forward selection from the baseline over ``candidates`` (module docstring); ``dropped``: refused before."""
    base = obj.scored({})
    sel = Selection(base, base, [], dropped=dict(dropped or {}))
    fits: dict[frozenset, Scored] = {}
    current = base
    for _ in range(swaps + 1):
        current = _forward(obj, sel, current, candidates, margin, max_pieces, top, fits)
        current = _removal(obj, sel, current, fits, margin)
        if current.explains or not current.values:
            break
        swapped = _swap(obj, sel, current, candidates, margin)
        if swapped is None:
            break
        current = swapped
    sel.final = current
    _alternatives(obj, sel, candidates, margin)
    return sel


def _forward(obj: Objective, sel: Selection, current: Scored, candidates, margin: float, max_pieces: int, top: int,
             fits: dict) -> Scored:
    """Rounds of additions: the best pair when it gains the margin over the best single
    addition (and there is room for two), else the best single one when it gains the margin."""
    while len(current.values) < max_pieces and not current.explains:
        pool = [p for p in candidates if p not in current.values and p not in sel.removed and p not in sel.dropped]
        if not pool:
            break
        rnd = _round(obj, current, pool, top, fits, dropped=sel.dropped)
        if not rnd.trials:
            log.info("round %d: every addition was refused by the model", len(sel.rounds) + 1)
            break
        p, one = rnd.trials[0]
        gain = current.score - one.score
        pair = rnd.pairs[0] if rnd.pairs and not rnd.pairs[0][1].approx else None
        if pair and len(current.values) + 2 <= max_pieces and one.score - pair[1].score >= margin \
                and current.score - pair[1].score >= 2 * margin:
            added, best = pair
        elif gain >= margin:
            added, best = (p,), one
        else:
            log.info("round %d: no addition gains the margin (best: %s, %.1f)", len(sel.rounds) + 1, p.label, gain)
            sel.rounds.append(rnd)
            sel.best_rejected = (p, one)
            break
        log.info("round %d: added %s (gain %.1f), %d model runs so far", len(sel.rounds) + 1,
                 " + ".join(q.label for q in added), current.score - best.score, obj.replayer.runs)
        sel.rounds.append(dataclasses.replace(rnd, added=added))
        current = best  # fitted jointly already
        sel.order += list(added)
        obj.replayer.budget.round_done(len(current.values))
    return current


def _replacements(obj: Objective, current: Scored, pool) -> list[tuple[Piece, Piece, Scored]]:
    """Every set with one chosen piece replaced by one of ``pool``, refitted on the surrogate, best first."""
    sur = Surrogate(obj, current.values)
    tried = []
    for p in current.values:
        rest = {r: v for r, v in current.values.items() if r != p}
        tried += [(p, q, screen(sur, rest, {q: None})) for q in pool if sur.usable(q)]
    return sorted(tried, key=lambda t: t[2].score)


def _swap(obj: Objective, sel: Selection, current: Scored, candidates, margin: float, top: int = 2) -> Scored | None:
    """Replace one chosen piece by one not chosen, if that (refitted) lowers the score by the margin."""
    pool = [q for q in candidates if q not in current.values and q not in sel.removed and q not in sel.dropped]
    for p, q, s in _replacements(obj, current, pool)[:top]:
        try:
            real = obj.scored(refit(obj, s.values, max_nfev=5))
        except Refused as err:
            _drop(sel.dropped, err, current.values)
            continue
        if current.score - real.score >= margin:
            log.info("swap: %s for %s (gain %.1f)", q.label, p.label, current.score - real.score)
            sel.removed.append(p)
            sel.order[sel.order.index(p)] = q
            return real
    return None


def _contribution(obj: Objective, values: dict, p: Piece) -> float:
    """The largest change ``p`` makes to a compared channel, the others kept, in units of
    the channel's resolution."""
    res = obj.residuals(values, solve=False)[0]
    without = obj.residuals({q: v for q, v in values.items() if q != p}, solve=False)[0]
    return max(float(np.nanmax(np.abs(res[c] - without[c]))) / resolution(c) for c in obj.channels)


def _removal(obj: Objective, sel: Selection, current: Scored, fits: dict, margin: float) -> Scored:
    """Drop, one at a time, a piece that changes no channel by the resolution, or (of two or more)
    whose removal, the others refitted, costs less than the margin."""
    while current.values:
        costs = []
        for p in current.values:
            rest = frozenset(current.values) - {p}
            if rest not in fits:
                try:
                    fits[rest] = obj.scored(refit(obj, {q: current.values[q] for q in rest}) if rest else {})
                except Refused:  # the others alone are refused: p is needed
                    fits[rest] = None
            if fits[rest] is None:
                costs.append((True, np.inf, p, None))
                continue
            small = _contribution(obj, current.values, p) < 1.0
            costs.append((not small, fits[rest].score - current.score, p, fits[rest]))
        needed, cost, p, without = min(costs, key=lambda c: c[:2])
        if needed and (cost >= margin or len(current.values) < 2):
            break
        log.info("removal check: %s not needed (%s)", p.label,
                 f"removing it costs {cost:.1f}" if needed else "it changes no channel by the resolution")
        sel.removed.append(p)
        sel.order.remove(p)
        current = without
    return current


def _alternatives(obj: Objective, sel: Selection, candidates, margin: float, most: int = 2,
                  max_nfev: int = 10) -> None:
    """For every chosen piece, the pieces that, put in its place and refitted, score within the
    margin of the chosen set: screened on the surrogate, the closest ``most`` refitted for real.
    A :data:`~gatetherm.studies.diagnosis.hypotheses.PROPORTIONAL` partner is refitted for real
    first, whatever the surrogate says (it adds changes made on the baseline model, so it misses
    the product of α with the effect of another chosen piece)."""
    final = sel.final
    pool = [q for q in candidates if q not in final.values and q not in sel.dropped]
    tried: dict[Piece, int] = {}

    def partners(p: Piece, q: Piece) -> bool:
        return frozenset({p.key, q.key}) in PROPORTIONAL

    for p, q, s in sorted(_replacements(obj, final, pool), key=lambda t: not partners(t[0], t[1])):
        if (s.score - final.score >= margin and not partners(p, q)) or tried.get(p, 0) >= most:
            continue
        tried[p] = tried.get(p, 0) + 1
        try:
            swapped = obj.scored(refit(obj, s.values, max_nfev=max_nfev))
        except Refused as err:
            _drop(sel.dropped, err, final.values)
            continue
        if swapped.score - final.score < margin:
            sel.alternatives.setdefault(p, []).append(q)
            sel.in_place[p, q] = swapped.values
            log.info("%s and %s explain the data equally well (scores %.1f, %.1f)", p.label, q.label,
                     final.score, swapped.score)


def physical_in_place(sel: Selection) -> dict:
    """The chosen set with each sensor fault that has a physical equivalent (an effect, a
    parameter, a dimension) replaced by it, at its value refitted in the fault's place: the
    model-form checks then judge the physical piece, not a fault the data cannot tell from it
    (a δ gain at the end of its range stands for an α well inside its own)."""
    values = dict(sel.final.values)
    for p, alts in sel.alternatives.items():
        q = next((a for a in alts if a.kind != "sensor"), None)
        if p.kind == "sensor" and q is not None and p in values and q not in values:
            values = {(q if k == p else k): (sel.in_place[p, q][q] if k == p else v) for k, v in values.items()}
    return values
