"""How a study scores a blind diagnosis against what was hidden.

A named piece is *right* when it is a hidden piece, or when a hidden piece is in its group
of equivalents (the data cannot tell them apart, and the report says so); every other named
piece is a *wrong name*. A hidden piece that is neither named nor in the group of a named
piece is *missed*. The two are counted separately: a wrong name sends a user to fix what is
fine, a miss only leaves the cause open. Where the cause lies outside every hypothesis,
nothing can be right: every named piece is a wrong name, and the verdict must not be
``explained``.
"""
from __future__ import annotations


def score(named: list[str], groups: dict[str, list[str]], hidden: list[str]) -> dict:
    """``named``: keys of the named pieces; ``groups``: {named key: keys of its equivalents};
    ``hidden``: keys of the hidden pieces (empty: outside every hypothesis, or noise only).
    Returns the named keys that are wrong, the hidden keys missed, and the hidden keys found
    only as an equivalent."""
    right = {k for k in named if k in hidden or set(groups.get(k, ())) & set(hidden)}
    covered = set(named) | {m for k in named for m in groups.get(k, ())}
    return {"wrong_names": [k for k in named if k not in right], "missed": [h for h in hidden if h not in covered],
            "as_equivalent": [h for h in hidden if h not in named and h in covered]}


def row_groups(d) -> dict[str, list[str]]:
    """{named key: keys of its equivalents} of a diagnosis."""
    return {g.piece.key: [q.key for q in g.members] for g in d.groups}
