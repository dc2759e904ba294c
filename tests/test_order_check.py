"""The element-order check judges a change against its kind's scale over the run and a
resolution floor: a free bar (a body held only against rigid motion) under a linear
temperature field is stress-free, exactly so at P2 (round-off), not at P1; that is no
percentage of zero (the bar is held against x on its left edge, against y on its bottom edge:
it expands freely away from the left edge). Neither shipped machine: a bar written as a user
writes a case."""
from __future__ import annotations

import numpy as np
import pytest

from gatetherm.api import load_case, run
from gatetherm.studies.run.order_check import RESOLUTION, TOLERANCE, scales

BAR = """SetFactory("OpenCASCADE");
Rectangle(1) = {0, 0, 0, 0.5, 0.05};
e = 1e-6;
Physical Surface("bar") = {1};
Physical Curve("left") = {Curve In BoundingBox {-e, -e, -e, e, 0.05 + e, e}};
Physical Curve("bottom") = {Curve In BoundingBox {-e, -e, -e, 0.5 + e, e, e}};
Mesh.MeshSizeMax = 0.01;
"""

CASE = """
[mesh]
file = "bar.geo"
[materials.bar]
E = 2.1e11
nu = 0.3
alpha = 1.2e-5
[temperature]
field = "20 + {gradient}*x"
[supports.left]
type = "normal"
[supports.bottom]
type = "normal"
[probes.end]
point = [0.5, 0.025]
[probes.mid]
point = [0.25, 0.0]
"""


def free_bar(tmp_path, gradient: float):
    (tmp_path / "bar.geo").write_text(BAR)
    (tmp_path / "case.toml").write_text(CASE.format(gradient=gradient))
    return load_case(tmp_path / "case.toml")


def warnings(caplog) -> list[str]:
    return [r.getMessage() for r in caplog.records if r.levelname == "WARNING"]


def test_free_bar_stresses_below_resolution_are_not_judged(tmp_path, caplog):
    """2 K/m over 0.5 m (a 1 K rise): the P1 stresses are ~0.02 MPa, the P2 ones zero to
    round-off; both within the 0.1 MPa floor, so no warning (the old check said -1e7 %).
    The bar expands freely: uy at the end α G x y = 1.2e-5 · 2 · 0.5 · 0.025 m = 0.3 µm at P2."""
    case = free_bar(tmp_path, 2.0)
    with caplog.at_level("WARNING"):
        check = run(case, check_order=True).order_check
    assert warnings(caplog) == []
    stresses = [k for k in check.p1 if k.endswith("_MPa")]
    assert len(stresses) == 8 and set(stresses) <= set(check.below)
    assert max(abs(check.p2[k]) for k in stresses) < 1e-4           # P2: exact (zero)
    assert check.p1["von_mises_end_MPa"] == pytest.approx(0.0167, abs=5e-4)  # band: < RESOLUTION 0.1
    assert check.scale["von_mises_end_MPa"] == RESOLUTION["_MPa"]
    assert check.p2["uy_end_um"] == pytest.approx(0.3, rel=1e-8)
    assert check.worst == "uy_end_um" and abs(check.relative[check.worst]) < TOLERANCE
    assert check.summary()["outputs"]["von_mises_end_MPa"]["below_resolution"] is True


def test_free_bar_stress_above_resolution_is_a_fraction_of_its_own_scale(tmp_path, caplog):
    """40 K/m (a 20 K rise): the P1 stress of 0.385 MPa is above the floor and wrong (P2: zero);
    the warning says -100 % of the output's own scale, never a percentage of zero."""
    case = free_bar(tmp_path, 40.0)
    with caplog.at_level("WARNING"):
        check = run(case, check_order=True).order_check
    [line] = warnings(caplog)
    assert "sigma_xx_end_MPa changes from -0.3848 to" in line and "+100.0 % of 0.3848" in line
    assert "set order = 2 in [case]" in line and "\n" not in line
    assert check.relative["sigma_xx_end_MPa"] == pytest.approx(1.0, abs=1e-9)
    assert max(abs(v) for v in check.relative.values()) <= 1.0 + 1e-9
    assert check.p2["uy_end_um"] == pytest.approx(6.0, rel=1e-8)  # α G x y
    assert "sigma_xy_end_MPa" in check.below


def test_scale_is_the_kind_over_the_run_and_never_below_the_floor():
    """A temperature that peaks 10 K above T_ref mid-run scales every temperature output, not
    the 1 K left at the end; displacements of 0.01 µm get the 0.1 µm floor."""
    series = {"T_a_degC": np.array([20.0, 30.0, 21.0]), "T_b_degC": np.array([20.0, 20.5, 20.2]),
              "ux_p_um": np.array([0.0, 0.01, -0.005])}
    got = scales(series, {"ux_p_um": 0.008}, T_ref=20.0)
    assert got == {"_degC": 10.0, "_um": RESOLUTION["_um"], "_MPa": RESOLUTION["_MPa"]}
