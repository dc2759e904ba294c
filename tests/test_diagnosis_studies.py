"""Issue 27's acceptance checks as the hidden-effect study runs them: the paper frame on 12-mm
elements, condition 2, the study's strengths and noise seeds (``gatetherm validate hidden-effects
--conditions 2 --mesh-size 0.012 --effects ...``, docs/diagnosis.md). Each case is one blind
diagnosis of 3–54 min on the shared cores: all slow."""
from __future__ import annotations

import pytest

from gatetherm.validation import paper_model
from gatetherm.validation.hidden_effects import cases, run_case

MESH = 0.012


def _row(effect: str, k: int = 0) -> dict:
    case = [c for c in cases(conditions=(2,)) if c.effect == effect][k]
    return run_case(case, paper_model(size=MESH))


#: Hidden dimension -> (factor hidden, value fitted, held-out δ RMS before, after in µm) of the study's run.
#: (l4, h, tank_wall re-pinned on 12-07 after the diagnosis changes: verdicts unchanged, h after 0.1116 → 0.1076;
#: tank_wall's fitted value 0.01362 → 0.01364 on a fresh install of the same code, SciPy 1.17.1, gmsh 4.15.2)
GEOMETRY = {
    "geometry.l4": (1.0888, 0.3693, 1.672, 0.1040),
    "geometry.l_C": (0.9350, 0.3750, 0.7865, 0.09998),
    "geometry.A_C": (1.0503, 6.173e-4, 0.5915, 0.1105),
    "geometry.h": (1.0899, 0.2454, 2.905, 0.1076),
    "geometry.tank_wall": (0.9348, 0.01364, 0.1387, 0.1060),
}


@pytest.mark.slow
@pytest.mark.parametrize("key", list(GEOMETRY))
def test_a_hidden_dimension_is_named_as_itself(key):
    """Tie-bar height, length and section, column width, tank wall off by 5–10 %: named as that
    dimension and nothing else, explained, the change fitted within a fifth (the band; achieved
    1.4–9.0 %), δ down to the noise."""
    row = _row(key)
    factor, fitted, before, after = GEOMETRY[key]
    model = getattr(paper_model().model.frame, key.removeprefix("geometry."))
    assert row["strength"] == pytest.approx(factor, abs=5e-5)
    assert (row["verdict"], row["pieces"], row["wrong_names"], row["missed"]) == ("explained", [f"geometry:{key}"], [],
                                                                                  [])
    value = next(iter(row["fitted"].values()))
    assert abs(value - model * factor) <= 0.2 * abs(model * factor - model) and row["within_20pct"]  # the band
    assert value == pytest.approx(fitted, rel=4e-4)  # achieved (4 digits)
    # after: the residual at the noise floor, where the fit stops; it moves by 2.6e-3 from machine to
    # machine with the same libraries (geometry.h 0.1076 here, 0.1079 on another EPYC host)
    assert (row["rms_before_um"], row["rms_after_um"]) == (pytest.approx(before, rel=1e-3),
                                                           pytest.approx(after, rel=5e-3))


#: (effect, which of its cases) -> held-out δ RMS before, after (µm): the same before the model-form
#: checks and the geometry hypotheses (main at e9484fb) and after them.
CATALOGUE = {
    ("ambient_drift", 0): (0.3968, 0.1078),
    ("ambient_drift", 1): (0.8752, 0.1155),
    ("joint_resistance", 0): (2.296, 0.1107),
}


@pytest.mark.slow
@pytest.mark.parametrize("effect, k", list(CATALOGUE))
def test_a_catalogue_effect_found_before_is_still_found(effect, k):
    row = _row(effect, k)
    assert (row["verdict"], row["pieces"], row["wrong_names"], row["missed"]) == ("explained", [f"effect:{effect}"], [],
                                                                                  [])
    before, after = CATALOGUE[effect, k]
    assert (row["rms_before_um"], row["rms_after_um"]) == (pytest.approx(before, rel=1e-3),
                                                           pytest.approx(after, rel=1e-3))


#: (cause outside every hypothesis, which of its cases) -> held-out δ RMS before (µm) of the study's run.
OUTSIDE = {
    ("flow_drop", 0): 4.441,
    ("flow_drop", 1): 2.146,
    ("sine_room", 0): 0.2221,
    ("three_d", 0): 1.296,
    ("unmarked_column_height", 0): 0.6509,
}


@pytest.mark.slow
@pytest.mark.parametrize("effect, k", list(OUTSIDE))
def test_a_cause_outside_every_hypothesis_names_nothing(effect, k):
    """An oil-flow drop, an unrecorded room swing, 3-D data on the 2-D model, a dimension not marked:
    no effect, no sensor fault, no parameter named, and not explained."""
    row = _row(effect, k)
    assert (row["verdict"], row["pieces"], row["wrong_names"]) == ("unexplained", [], [])
    assert row["rms_before_um"] == pytest.approx(OUTSIDE[effect, k], rel=1e-3)
