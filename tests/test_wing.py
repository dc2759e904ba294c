"""The paper's frame as one wing (issue 52 item 2): generic code reaches the frame only through what
a case carries (its typed origin and parameters) or what the API passes in (a sweep's FRAME)."""
from __future__ import annotations

from pathlib import Path

import pytest

from conftest import FIXED, fixed_case
from gatetherm import InputError
from gatetherm.frame.beam import theory_coefficients
from gatetherm.frame.geometry import part_boxes
from gatetherm.frame import sweeppoint
from gatetherm.geometry.measure import region_volume
from gatetherm.studies.control.actuator import ActuatorParams
from gatetherm.studies.control.methods import Settings, coefficients
from gatetherm.studies.run.origin import ModelParameters, Origin, scheme_digest
from gatetherm.studies.sweeps.studyfile import load_study
from gatetherm.studies.sweeps.sweep import plan

C_FRAME = Path(__file__).resolve().parents[1] / "validation" / "examples" / "c_frame" / "case.toml"


def test_the_frame_case_fills_the_typed_fields():
    case = fixed_case()
    assert isinstance(case.origin, Origin) and isinstance(case.parameters, ModelParameters)
    assert isinstance(case.actuator, ActuatorParams)
    assert case.origin.ORDER == "model.order" and case.origin.supply.T_room == 20.0
    # the model's scheme digest and its problem's agree: the sweep keys a case and a frame point alike
    assert scheme_digest(case.problem) == scheme_digest(case.parameters)


def test_a_case_file_has_an_origin_and_no_beam_model():
    from gatetherm.studies.run.case import load_case

    case = load_case(C_FRAME)
    assert isinstance(case.origin, Origin) and case.parameters is None and case.origin.ORDER == "case.order"
    assert not hasattr(case.origin, "coefficients") and not hasattr(case.origin, "supply")
    with pytest.raises(InputError, match="needs the paper frame's beam model"):
        coefficients(case, None, Settings(k_source="theory"))


def test_the_compensator_gets_the_beam_coefficients_from_the_frame_origin():
    """methods.coefficients imports no frame module: the case's origin gives eqs 22-24 of its parameters."""
    case = fixed_case()
    ki, kc, source = coefficients(case, None, Settings())
    assert source == "theory" and (ki, kc) == theory_coefficients(case.parameters)
    assert ki == pytest.approx(2.8478, abs=1e-4) and kc == pytest.approx(8.2257, abs=1e-4)  # um/K, FIXED_MODEL


@pytest.mark.parametrize("region", ["tie_bar", "arm_L", "column_R", "tie_joint_L"])
def test_region_volume_of_a_box_part_is_its_box(region):
    """geometry.measure.region_volume on the 2-D frame: a part without a cavity is its box times the depth."""
    x0, x1, y0, y1 = part_boxes(FIXED, 2)[region][:4]
    assert region_volume(fixed_case().mesh, region, 0.1) == pytest.approx((x1 - x0) * (y1 - y0) * 0.1, rel=1e-12)


def test_a_frame_study_gets_its_points_from_the_frame(tmp_path):
    """Without the frame's side (what gatetherm.api.sweep passes) a frame study is one line; with it
    the points are the frame's, keyed as before (sweeppoint.point_key)."""
    study = tmp_path / "study.toml"
    study.write_text('[study]\ndim = 2\ncompute = ["coefficients"]\n\n[grid]\n"geometry.l4" = [0.25, 0.3]\n')
    with pytest.raises(InputError, match="needs gatetherm.frame"):
        load_study(study)
    s = load_study(study, sweeppoint.FRAME)
    tasks = plan(s)
    assert s.frame is sweeppoint.FRAME and [t.frame for t in tasks] == [sweeppoint.FRAME] * 2
    cfg, cond, eff, _ = sweeppoint.configure(s.base, {"geometry.l4": 0.25}, 2)
    assert tasks[0].key == sweeppoint.point_key(cfg, 2, ("coefficients",), cond, eff)
