"""The diagnosis's search, on a surrogate objective (analytic columns, no model runs): a hypothesis
the model refuses is dropped with its reason and the search goes on; stand-ins that the model-form
checks reject send the selection back to the next candidates (issue 51)."""
from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from gatetherm import InputError
from gatetherm.studies.diagnosis.calibrate import Objective, Refused, Scored
from gatetherm.studies.diagnosis.hypotheses import Piece, model_side
from gatetherm.studies.diagnosis.progress import Budget
from gatetherm.studies.diagnosis.backtrack import LATER
from gatetherm.studies.diagnosis.select import Selection, select, select_confirmed

HOUR = 3600.0
T = np.arange(0.0, 6 * HOUR + 1, 300.0)
CHANNELS = ("delta_um", "theta_A_degC")


def piece(name: str, hi: float = 2.0) -> Piece:
    return Piece("effect", name, "rate", "K/h", 0.0, hi, False, None, f"surrogate {name}")


DRIFT, FILM, JOINT, FREE = piece("ambient_drift"), piece("air_film"), piece("joint_resistance"), piece("free_part")
SHAPES = {  # per unit value: (δ µm, θ_A K) along the run
    DRIFT: (-1.5 * T / HOUR, T / HOUR),
    FILM: (np.sqrt(T / HOUR) * 2.0, 0.8 * np.sqrt(T / HOUR)),
    JOINT: (-2.5 * (T / HOUR) ** 1.5 / 6 ** 0.5, np.zeros_like(T)),
    FREE: (np.cos(T / HOUR), np.zeros_like(T)),
}


class Surrogate(Objective):
    """Columns linear in the values of the pieces; ``FREE`` is refused like a part left free to move."""

    def __init__(self, truth: dict):
        rep = SimpleNamespace(times=T, runs=0, config=None, budget=Budget())
        y = self.columns(truth)
        super().__init__(rep, y, CHANNELS, {"delta_um": 0.1, "theta_A_degC": 0.05}, T <= 0.6 * T[-1])
        self.refused = 0

    @staticmethod
    def columns(values: dict) -> dict:
        cols = {"delta_um": np.zeros_like(T), "theta_A_degC": 20.0 + np.zeros_like(T)}
        for p, v in values.items():
            cols = {c: cols[c] + v * s for c, s in zip(CHANNELS, SHAPES[p])}
        return cols

    def model_columns(self, values: dict) -> dict:
        if FREE in values:
            self.refused += 1
            raise Refused([p for p, _ in model_side(values)], InputError(
                "supports", "the part made of region spindle is free to move (translation x)", "hold it"))
        return self.columns(values)


def test_a_refused_hypothesis_is_dropped_with_its_reason_and_the_search_goes_on():
    obj = Surrogate({DRIFT: 0.5})
    sel = select(obj, [FREE, FILM, DRIFT, JOINT], margin=10.0)
    assert list(sel.final.values) == [DRIFT] and sel.final.explains
    assert sel.final.values[DRIFT] == pytest.approx(0.5, abs=1e-3)  # band: ± 10 %
    assert list(sel.dropped) == [FREE] and "free_part" not in [p.label for r in sel.rounds for p, _ in r.trials]
    assert sel.dropped[FREE] == ("supports: the part made of region spindle is free to move (translation x); "
                                 "hold it")
    assert obj.refused == 1  # tried once, never again
    err = Refused([FREE], InputError("supports", "free", "hold it"))  # unexpected elsewhere: still one line
    assert isinstance(err, InputError) and str(err) == "supports: free; hold it" and err.pieces == (FREE,)


def test_rejected_stand_ins_send_the_selection_back_to_the_next_candidates():
    """The first selection takes air film + joint resistance; the checks reject both as stand-ins;
    the selection runs again without them and names the room's drift (the paper frame's case of
    issue 51)."""
    obj = Surrogate({DRIFT: 0.51})
    calls = []

    def pick(pool, dropped):
        calls.append(list(pool))
        if FILM in pool:  # the first selection: the stand-in pair, as the paper frame's did
            sel = select(obj, [FILM, JOINT], margin=10.0, dropped=dropped)
            assert set(sel.final.values) == {FILM, JOINT}
            return sel
        return select(obj, pool, margin=10.0, dropped=dropped)

    def judge(sel):
        stand = {p: (v, "does not hold on a phase") for p, v in sel.final.values.items() if p in (FILM, JOINT)}
        named = {p: v for p, v in sel.final.values.items() if p not in stand}
        return named, stand, None

    sel, named, _ = select_confirmed(pick, judge, [FREE, FILM, DRIFT, JOINT])
    assert calls == [[FREE, FILM, DRIFT, JOINT], [FREE, DRIFT]]
    assert list(named) == [DRIFT] and named[DRIFT] == pytest.approx(0.51, abs=1e-3)  # band: ± 10 %
    assert set(sel.stand_ins) == {FILM, JOINT} and list(sel.dropped) == [FREE]


def test_back_tracking_stops_without_stand_ins_and_keeps_a_named_set():
    """No stand-in: one selection. A later selection that names nothing does not replace an earlier
    one that named a piece."""
    obj = Surrogate({DRIFT: 0.5})
    n = []

    def pick(pool, dropped):
        n.append(len(pool))
        return select(obj, pool, margin=10.0, dropped=dropped)

    sel, named, _ = select_confirmed(pick, lambda s: (dict(s.final.values), {}, None), [DRIFT, FILM])
    assert n == [2] and list(named) == [DRIFT]
    first = []

    def judge(s):  # the drift holds, and the film is always a stand-in
        if not first:
            first.append(1)
            return {DRIFT: 0.5}, {FILM: (1.0, "implausible")}, None
        return {}, {}, None

    sel, named, _ = select_confirmed(pick, judge, [DRIFT, FILM])
    assert named == {DRIFT: 0.5} and list(sel.stand_ins) == [FILM]


def test_a_later_set_that_does_not_hold_either_does_not_replace_the_named_one():
    """A cause outside the hypotheses: the first selection names the film (its partner the joint a
    stand-in), the retry names the film with the drift, and neither set holds on every phase: the
    first stays named, the drift is listed as a stand-in (as the C-frame's unmarked spindle length:
    conductivity, then conductivity + source + expansion). A retry whose set holds replaces it."""
    def pick_with(explains_later: bool):
        def pick(pool, dropped):
            values = {FILM: 1.2, JOINT: 0.4} if JOINT in pool else {FILM: 1.1, DRIFT: 0.3}
            s = Scored(values, 0.0, 0.0, {}, explains_later and JOINT not in pool)
            return Selection(s, s, list(values))
        return pick

    def judge(sel):
        stand = {p: (v, "implausible") for p, v in sel.final.values.items() if p == JOINT}
        named = {p: v for p, v in sel.final.values.items() if p != JOINT}
        return named, stand, SimpleNamespace(holds=not stand)  # the retry holds on every phase

    sel, named, chk = select_confirmed(pick_with(False), judge, [FILM, JOINT, DRIFT])
    assert named == {FILM: 1.2} and not chk.holds  # the retry holds, but leaves a significant residual
    assert sel.stand_ins == {JOINT: (0.4, "implausible"), DRIFT: (0.3, LATER)}
    sel, named, chk = select_confirmed(pick_with(True), judge, [FILM, JOINT, DRIFT])
    assert named == {FILM: 1.1, DRIFT: 0.3} and chk.holds and set(sel.stand_ins) == {JOINT}


def test_a_later_set_that_only_partly_explains_does_not_replace_a_first_that_named_nothing():
    """3-D data on the 2-D frame (tests/test_diagnosis_studies.py, three_d): every piece of the
    first selection is a stand-in, the retry names one piece that leaves a significant residual.
    Nothing is named (the verdict: unexplained) and the retry's piece is a stand-in too; a retry
    that explains the run is named (issue 51's room drift)."""
    def pick_with(explains_later: bool):
        def pick(pool, dropped):
            values = {FILM: 1.2, JOINT: 0.4} if JOINT in pool else {DRIFT: 0.3}
            s = Scored(values, 0.0, 0.0, {}, explains_later and JOINT not in pool)
            return Selection(s, s, list(values))
        return pick

    def judge(sel):
        stand = {p: (v, "implausible") for p, v in sel.final.values.items() if p in (FILM, JOINT)}
        return {p: v for p, v in sel.final.values.items() if p not in stand}, stand, SimpleNamespace(holds=True)

    sel, named, _ = select_confirmed(pick_with(False), judge, [FILM, JOINT, DRIFT])
    assert named == {} and sel.stand_ins == {FILM: (1.2, "implausible"), JOINT: (0.4, "implausible"),
                                             DRIFT: (0.3, LATER)}
    sel, named, _ = select_confirmed(pick_with(True), judge, [FILM, JOINT, DRIFT])
    assert named == {DRIFT: 0.3} and set(sel.stand_ins) == {FILM, JOINT}
