"""Forward selection that goes back when the model-form checks reject its pieces as stand-ins
(:func:`select_confirmed`; the selection itself: :mod:`select`)."""
from __future__ import annotations

import logging

from gatetherm.studies.diagnosis.hypotheses import Piece

log = logging.getLogger(__name__)

LATER = ("named with other pieces by a later selection without the stand-ins, which does not explain the run "
         "either: the cause may lie outside the hypotheses")
"""Why a piece that a later selection named, and that did not replace the earlier named set, is a stand-in."""


def select_confirmed(pick, judge, candidates: list[Piece], tries: int = 3):
    """Forward selection that goes back when the model-form checks reject its pieces.

    ``pick(pool, dropped)`` selects from ``pool`` (:func:`select`, ``dropped`` the pieces the
    model refused so far); ``judge(selection)`` gives ``(named, stand_ins, checks)`` of the chosen
    set (:func:`~gatetherm.studies.diagnosis.checks.confirm`: ``named`` {piece: value} that hold,
    ``stand_ins`` {piece: (value, why)} that do not). While the judge rejects stand-ins, they
    leave the candidates and the selection runs again on the rest (the model runs made so far
    are kept), ``tries`` selections at most: a pair of stand-ins chosen first no longer hides the
    piece that alone explains the data (issue 51). A later selection replaces the first only where
    it explains the run: no stand-in, no significant residual left (``selection.final.explains``)
    and holding on every phase fitted on the others (``checks.holds``, or no checks); else its
    pieces are stand-ins too (:data:`LATER`), whether the first named pieces or none. Each try
    draws from fewer candidates: a set that only partly explains the run after the first was
    rejected is no better evidence than the first, and where the cause lies outside every
    hypothesis, several such sets fit in part. Naming them would name more wrong causes, each
    looking confirmed (the C-frame's unmarked spindle length: conductivity, then, once a source
    factor joined the hypotheses, a third selection's source ×0.90 + expansion ×1.10 + conductivity
    ×0.85, holding on every phase; 3-D data on the 2-D frame: every piece of the first selection a
    stand-in, then conductivity alone, leaving a significant residual).

    Returns
    -------
    (Selection, dict, checks)
        The selection kept (every stand-in rejected on the way in its :attr:`Selection.stand_ins`,
        every refused piece in :attr:`Selection.dropped`), its named pieces and their checks.
    """
    pool, rejected, dropped, best = list(candidates), {}, {}, None
    for i in range(tries):
        sel = pick(pool, dropped)
        dropped = sel.dropped
        named, stand, chk = judge(sel)
        rejected.update(stand)
        explains = not stand and sel.final.explains and (chk is None or chk.holds)
        if best is None or (named and explains):
            best = (sel, named, chk)
        else:  # the earlier named set stays: this one does not explain the run either
            rejected.update({p: (v, LATER) for p, v in named.items() if p not in best[1]})
        if not stand:
            break
        pool = [p for p in pool if p not in stand and p not in dropped]
        if i + 1 < tries:
            log.info("model-form checks rejected %s as stand-ins: selecting again from the %d other candidates",
                     " + ".join(p.label for p in stand), len(pool))
    sel, named, chk = best
    sel.stand_ins = {p: v for p, v in rejected.items() if p not in named}
    sel.dropped = dropped
    return sel, named, chk
