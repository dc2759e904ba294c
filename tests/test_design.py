"""The design study: tie-bar position range, grids, optimum, and the second tie bar."""
from __future__ import annotations

import numpy as np
import pytest

from gatetherm.frame import design as ds
from gatetherm.frame.config import parse_config
from gatetherm.studies.sweeps.sweep import plan
from gatetherm.studies.sweeps.evaluate import evaluate

GEOMETRY = dict(h=0.15, depth=0.12, column_height=0.63, l=0.6, l1=0.25, l4=0.3, l_C=0.4, A_C=6e-4, t_C=0.04,
                arm_thickness=0.06, arm_depth=0.06, gap=0.02, tank_wall=0.015, tank_width=0.05,
                tank_bottom=0.02, tank_height=0.21, tank_depth=0.08, sensor_height=0.125)
BASE = parse_config({"geometry": GEOMETRY, "mesh": {"size": 0.03},
                     "material": dict(E=1.2e11, nu=0.26, alpha=1.05e-5, k=48.0, rho=7250.0, c=510.0),
                     "thermal": dict(h_air=8.0, h_oil_on=250.0, h_oil_off=40.0, oil_rho_c=1.7e6, flow_rate=3.3e-5),
                     "supply": dict(tau_heat=500.0, tau_cool=600.0)}, "test")
#: 5-h swing of delta (um), condition 1, measured with this code (P1, 3 cm mesh).
SWING = {(0.3, 0.0): 54.831, (0.5, 0.0): 15.722, (0.3, 0.66): 8.246}


def test_position_range_stays_clear_of_base_and_arms():
    assert ds.position_range(BASE, 2) == pytest.approx((0.03, 0.6 - 0.05 - 0.01), rel=1e-12)
    assert ds.position_range(BASE, 3) == pytest.approx((0.03, 0.6), rel=1e-12)
    grid = ds.first_grid(BASE, 2)
    assert len(grid) == ds.N_POSITIONS and all(not t.skip for t in plan(ds.position_study(BASE, 2, grid)))


def test_refined_grid_lies_between_the_neighbours_of_the_best():
    fine = ds.refined_grid([0.1, 0.2, 0.3, 0.4], 0.3)
    assert len(fine) == ds.N_REFINE and fine.min() > 0.2 and fine.max() < 0.4
    assert ds.refined_grid([0.1, 0.2, 0.3], 0.3).max() < 0.3  # at the end of the grid


def _rows(values):
    return [{"status": "ok", "geometry.l4": l4, "condition": c, "swing_um": s}
            for l4, swings in values.items() for c, s in zip(ds.CONDITIONS, swings)]


def test_optimum_minimises_the_worst_condition():
    best = ds.optimum(_rows({0.2: (30, 20, 40), 0.3: (25, 22, 33), 0.4: (20, 21, 35)}))
    assert best["l4"] == 0.3 and best["worst_swing_um"] == 33
    assert best["per_condition"] == {1: 0.4, 2: 0.2, 3: 0.3}


def test_second_tie_bar_study_raises_the_column_for_every_point():
    heights = ds.second_heights(BASE)
    assert heights[0] == pytest.approx(0.6 + 0.05 + 0.01) and heights == tuple(sorted(heights))
    tasks = plan(ds.second_study(BASE, 2, (0.3, 0.5)))
    assert len(tasks) == 2 * (1 + len(heights)) * len(ds.CONDITIONS) and not any(t.skip for t in tasks)
    assert [t.config.model.frame.column_height for t in tasks] == pytest.approx([heights[-1] + 0.02] * len(tasks))
    rows = [{"status": "ok", "geometry.l4": 0.3, "geometry.l4_2": l42, "condition": c, "swing_um": s}
            for l42, s in ((0.0, 40.0), (0.7, 10.0)) for c in ds.CONDITIONS]
    summary = ds.second_summary(rows)
    assert [r["reduction_vs_one_bar"] for r in summary] == [0.0, 0.75]


def test_swing_regression_and_the_second_tie_bar():
    """Condition 1: raising the tie bar towards the arms, or adding one above them, cuts the swing."""
    got = {}
    for (l4, l42), want in SWING.items():
        study = ds.second_study(BASE, 2, (l4,)) if l42 else ds.position_study(BASE, 2, [l4])
        task = next(t for t in plan(study) if t.condition == 1 and dict(t.params).get("geometry.l4_2", 0.0) == l42)
        got[(l4, l42)] = evaluate(task)["results"]["swing_um"]
        assert got[(l4, l42)] == pytest.approx(want, rel=5e-3)
    assert got[(0.5, 0.0)] < got[(0.3, 0.0)] and got[(0.3, 0.66)] < 0.5 * got[(0.3, 0.0)]
    assert np.isfinite(list(got.values())).all()


@pytest.mark.slow
def test_validate_design_2d(tmp_path):
    """The whole `gatetherm validate design` on the paper model (a few minutes on 2 cores)."""
    import csv

    from gatetherm.cli import main

    assert main(["validate", "design", "--out", str(tmp_path), "--workers", "2"]) == 0
    with open(tmp_path / "second_tie_bar.csv", newline="") as fh:
        second = list(csv.DictReader(fh))
    assert max(float(r["reduction_vs_one_bar"]) for r in second) > 0.3  # paper's conclusion 3
    for name in ("report.md", "positions.csv", "design_position.png", "design_second.png",
                 "design_histories.png"):
        assert (tmp_path / name).stat().st_size > 0
