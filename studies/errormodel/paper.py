"""The paper's form, ``delta = K_i (theta_a - theta_b) - K_C theta_c`` (eq 21, no intercept),
with its three sensors searched exhaustively among the candidates by held-out error."""
from __future__ import annotations

import numpy as np

from gatetherm import InputError
from gatetherm.studies.errormodel import select
from gatetherm.studies.errormodel.model import TargetModel, residual_stats
from gatetherm.studies.errormodel.terms import Term


def fit_paper_form(cv: select.CrossValidation, name: str, base: list[Term], B: np.ndarray, y_all: np.ndarray,
                   rows: np.ndarray, min_span_K: float) -> TargetModel:
    """The paper's form for target ``name``: every triple of the plain sensors among the ``base``
    terms (a < b, c neither; a difference or third sensor spanning less than ``min_span_K`` left out) scored
    by ``cv``; the best, fitted on ``rows`` (``B``: the base columns after a column of ones), with
    the ten best triples as its selection."""
    plain = [j for j, b in enumerate(base) if b.kind == "sensor" and b.tau_s is None]
    p = len(base) + 1

    def W(a, b, c):
        w = np.zeros((p, 2))
        w[a + 1, 0], w[b + 1, 0], w[c + 1, 1] = 1.0, -1.0, 1.0
        return w

    pairs = [(a, b) for n, a in enumerate(plain) for b in plain[n + 1:]
             if select.informative(B[rows] @ W(a, b, a)[:, 0], min_span_K)]
    triples = [(a, b, c) for a, b in pairs for c in plain
               if c not in (a, b) and select.informative(B[rows, c + 1], min_span_K)]
    if len(plain) < 3:
        raise InputError("candidates", "the paper's form needs at least 3 temperature columns", "name 3 or more")
    if not triples:
        raise InputError("candidates", f"no two of the {len(plain)} temperature columns differ by {min_span_K:g} K "
                         f"(ten sensor resolutions) with a third spanning as much, in the fitting span: the paper's "
                         f"form has nothing to weigh", "name other thermocouples, or use form 'static' or 'dynamic'")
    ranked = select.exhaustive(cv, ((abc, W(*abc)) for abc in triples))
    cv_mae, (a, b, c) = ranked[0]
    X = B[:, [a + 1, b + 1, c + 1]]
    X = np.column_stack([X[:, 0] - X[:, 1], X[:, 2]])
    var = np.array([cv.D[a + 1] + cv.D[b + 1], cv.D[c + 1]])  # the noise of theta_a - theta_b and theta_c
    k = select.noisy_least_squares(X[rows], y_all[rows], var)
    if k[0] < 0:  # orient the difference so that K_i > 0
        a, b, k[0] = b, a, -k[0]
        X[:, 0] *= -1
    terms = (Term("difference", base[a].column, other=base[b].column), Term("sensor", base[c].column))
    selection = tuple({"form": "paper", "terms": [f"{base[i].column}-{base[j].column}", base[m].column],
                       "sensors": 3, "cv_mae_um": e} for e, (i, j, m) in ranked[:10])
    return TargetModel(name, "paper", terms, (float(k[0]), float(k[1])), 0.0,
                       residual_stats(X[rows] @ k - y_all[rows]), float(cv_mae), selection,
                       float(np.sqrt(var @ k**2)))
