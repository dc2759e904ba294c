"""Beam theory vs FE: the study set-up, the shear-corrected theory, the error analysis and the
element-exact load cases."""
from __future__ import annotations

import csv
import dataclasses

import numpy as np
import pytest

from gatetherm.frame import beam
from gatetherm.frame.problem import build_model
from gatetherm.frame.loadcases import fe_coefficients
from gatetherm.frame.beam import theory_coefficients
from gatetherm.frame.config import parse_config
from gatetherm.frame.sweeppoint import configure
from gatetherm.studies.sweeps.sweep import plan
from gatetherm.validation import beam_vs_fe as bv

GEOMETRY = dict(h=0.1, depth=0.12, column_height=0.63, l=0.6, l1=0.3, l4=0.3, l_C=0.4, A_C=1e-3, t_C=0.04,
                arm_thickness=0.06, arm_depth=0.06, gap=0.02, tank_wall=0.01, tank_width=0.03,
                tank_bottom=0.02, tank_height=0.2, tank_depth=0.08, sensor_height=0.1)
BASE = parse_config({"geometry": GEOMETRY, "mesh": {"size": 0.03},
                     "material": dict(E=1.2e11, nu=0.26, alpha=1.05e-5, k=48.0, rho=7250.0, c=510.0)}, "test")


@pytest.mark.parametrize("l4", [0.2, 0.45, 0.9])  # the three branches l4 < l1, l1 < l4 < l, l4 > l
def test_shear_theory_without_shear_is_the_beam_theory(l4, monkeypatch):
    cfg = dataclasses.replace(BASE, model=dataclasses.replace(
        BASE.model, frame=dataclasses.replace(BASE.model.frame, l4=l4, column_height=1.0)))
    monkeypatch.setattr(bv, "SHEAR_FACTOR", 1e12)
    assert bv.shear_coefficients(cfg) == pytest.approx(theory_coefficients(cfg.model), rel=1e-9)



def test_shear_theory_with_a_rigid_tie_bar_by_hand():
    """A rigid tie bar (A_C -> inf) shares the bar's expansion equally: K_C = alpha l_C c(l, l4) / c(l4, l4)
    with the Timoshenko compliances c(y, s) = s^2 (3y - s)/(6EI) + s/(kGA) (y >= s)."""
    p = dataclasses.replace(BASE.model.frame, A_C=1e6, l4=0.25)
    cfg = dataclasses.replace(BASE, model=dataclasses.replace(BASE.model, frame=p))
    m = cfg.model.material
    EI, GA = m.E * p.depth * p.h ** 3 / 12, bv.SHEAR_FACTOR * m.E / (2 * (1 + m.nu)) * p.depth * p.h
    c_l = p.l4 ** 2 * (3 * p.l - p.l4) / (6 * EI) + p.l4 / GA
    c_4 = p.l4 ** 3 / (3 * EI) + p.l4 / GA
    assert bv.shear_coefficients(cfg)[1] == pytest.approx(1e6 * m.alpha * p.l_C * c_l / c_4, rel=1e-6)
    assert bv.shear_coefficients(cfg)[1] < theory_coefficients(cfg.model)[1]  # shear does not rotate


def test_sweep_study_points_follow_the_definitions():
    studies = bv.studies(BASE, 2)
    tasks = plan(studies["sweep"][0])
    a_values = bv.A_VALUES[2]
    assert len(a_values) >= 20 and a_values[0] == 0.5 and a_values[-1] == 5.0
    assert len(tasks) == len(a_values) * len(bv.BETAS)
    for t in tasks:
        a, b = dict(t.params)["derived.l_over_l4"], dict(t.params)["derived.beta"]
        p = t.config.model.frame
        assert p.l / p.h == pytest.approx(bv.SLENDERNESS, rel=1e-14) and p.l1 == pytest.approx(p.l / 2, rel=1e-15)
        assert p.l / p.l4 == pytest.approx(a, rel=1e-14)
        assert float(beam.beta(p.depth * p.h ** 3 / 12, p.l_C, p.A_C, p.l)) == pytest.approx(b, rel=1e-13)
        assert t.config.model.mesh.size == pytest.approx(p.h / bv.ELEMENTS_ACROSS[2], rel=1e-4)
        assert t.config.model.order == bv.ORDER
        overlaps = abs(p.l4 - p.l) < 0.5 * (p.t_C + p.arm_thickness)
        assert bool(t.skip) is overlaps
        assert p.column_height >= p.l4 + 0.5 * p.t_C - 1e-12
    skipped = sorted({dict(t.params)["derived.l_over_l4"] for t in tasks if t.skip})
    assert skipped == [0.95, 1.0, 1.05]
    assert all(not t.skip for t in plan(bv.studies(BASE, 3)["sweep"][0]))  # 3-D builds them all


def test_three_d_tie_bar_is_raised_to_fit_behind_the_arms():
    cfg, _, _, skip = configure(BASE, {"derived.beta": 0.01, "derived.l_over_l4": 1.0}, 3)
    p = cfg.model.frame
    assert skip == "" and p.A_C / p.t_C <= p.depth - p.arm_depth + 1e-12 and p.t_C > 0.04


@pytest.mark.parametrize("fe, th, ok, gap", [(1.14, 1.0, True, False), (11.6, 10.0, False, True),
                                             (10.9, 10.0, True, False), (11.2, 10.0, True, True),
                                             (0.29, 0.0, True, False), (-0.31, 0.0, False, True)])
def test_tolerance_and_gap_rules(fe, th, ok, gap):
    assert bv.agreement(fe, th) == (ok, gap)


def _row(a, b, **values):
    return {"status": "ok", "derived.l_over_l4": a, "derived.beta": b, **values}


def test_zero_crossings_interpolate_sign_changes():
    rows = [_row(a, 0.01, Ki_norm_fe=v) for a, v in [(0.6, 0.2), (0.8, -0.2), (1.0, -0.1), (1.2, 0.3), (1.5, 0.5)]]
    z = bv.zero_crossings(rows, betas=(0.01,))[0.01]
    assert z["crossings"] == pytest.approx([0.7, 1.05], rel=1e-12)
    assert (z["min"], z["at_min"], z["min_abs"], z["at_min_abs"]) == (-0.2, 0.8, 0.1, 1.0)


def test_error_parts_add_up_and_name_the_main_cause():
    k = dict(Ki_theory=10.0, Ki_E_fe=12.0, Ki_F_fe=12.0, Ki_shear=10.5, Kc_theory=5.0, Kc_E_fe=5.1,
             Kc_F_fe=5.1, Kc_shear=5.0)
    main = [_row(3.0, 0.1, **k)]
    no_tank = [_row(3.0, 0.1, **{**k, "Ki_E_fe": 10.6, "Kc_E_fe": 5.05})]
    e_ki, e_kc = bv.error_rows(main, no_tank)
    parts = [e_ki[f"part_{n.split()[0]}_um_per_K"] for n in bv.PARTS]
    assert parts == pytest.approx([1.4, 0.5, 0.1]) and sum(parts) == pytest.approx(e_ki["error_um_per_K"])
    assert e_ki["main_cause"] == "tank cavity" and e_ki["gap"] and not e_ki["within_tolerance"]
    assert e_kc["within_tolerance"] and not e_kc["gap"] and e_kc["main_cause"] == ""


def test_beam_vs_fe_csv_has_exactly_the_columns_of_the_issue():
    rows = bv.csv_rows([_row(2.0, 0.1, Ki_norm_theory=0.4, Ki_norm_fe=0.41, Kc_norm_theory=1.8, Kc_norm_fe=1.9),
                        {"status": "skipped", "derived.l_over_l4": 1.0, "derived.beta": 0.1}])
    assert len(rows) == 1 and list(rows[0]) == ["l_over_l4", "beta", "Ki_norm_theory", "Ki_norm_fe",
                                                 "Kc_norm_theory", "Kc_norm_fe"]


def test_cavity_stiffness_ratio_of_a_centred_hole():
    cfg, *_ = configure(BASE, {"geometry.tank_wall": 0.035, "geometry.tank_width": 0.03}, 2)
    assert bv.cavity_stiffness_ratio(cfg, 2) == pytest.approx(1 - 0.3 ** 3, rel=1e-12)
    assert bv.cavity_stiffness_ratio(cfg, 3) == pytest.approx(1 - 0.3 ** 3 * 0.08 / 0.12, rel=1e-12)


def test_element_exact_tie_load_keeps_out_of_the_column():
    """Regression values of the load cases on a thin tie bar (P1, 3 cm mesh); a nodal tie
    load, which also heats the column nodes at the joints, gave K_C = 2.899 µm/K here."""
    cfg, *_ = configure(BASE, {"derived.beta": 1.0, "derived.l_over_l4": 3.0, "derived.l1_over_l": 0.5}, 2)
    c = fe_coefficients(build_model(cfg.model, 2))
    assert c.Ki_E * 1e6 == pytest.approx(12.9031, rel=2e-3)
    assert c.Kc_E * 1e6 == pytest.approx(1.50315, rel=2e-3)


def test_slender_frame_without_cavity_matches_the_theory():
    """l/h = 12, no tank cavity, P2: FE within 3 % of eqs (22)-(24) and within 1 % at the tips."""
    cfg, *_ = configure(BASE, {"derived.l_over_h": 12.0, "derived.l1_over_l": 0.5, "derived.beta": 0.1,
                               "derived.l_over_l4": 2.0, "derived.tank_cavity": False, "model.order": 2,
                               "mesh.size": 0.6 / 12 / 4}, 2)
    c = fe_coefficients(build_model(cfg.model, 2))
    ki, kc = theory_coefficients(cfg.model)
    assert c.Ki_E * 1e6 == pytest.approx(ki, rel=0.03) and c.Kc_E * 1e6 == pytest.approx(kc, rel=0.03)
    assert c.Ki_F == pytest.approx(c.Ki_E, rel=0.01) and c.Kc_F == pytest.approx(c.Kc_E, rel=0.01)


@pytest.mark.slow
def test_validate_beam_2d_meets_the_acceptance(tmp_path):
    """The whole `gatetherm validate beam --dim 2` (about 3 min on 2 cores)."""
    from gatetherm.cli import main

    assert main(["validate", "beam", "--dim", "2", "--out", str(tmp_path), "--workers", "2"]) == 0
    with open(tmp_path / "beam_vs_fe.csv", newline="") as fh:
        rows = list(csv.DictReader(fh))
    assert list(rows[0]) == ["l_over_l4", "beta", "Ki_norm_theory", "Ki_norm_fe", "Kc_norm_theory", "Kc_norm_fe"]
    assert len({r["l_over_l4"] for r in rows}) >= 20 and {float(r["beta"]) for r in rows} == set(bv.BETAS)
    for b in (0.01, 0.03, 0.1):  # K_i passes near zero for l/l4 in 0.7-1.3
        ki = [float(r["Ki_norm_fe"]) for r in rows if float(r["beta"]) == b and 0.7 <= float(r["l_over_l4"]) <= 1.3]
        assert min(ki) < 0.06
    with open(tmp_path / "errors.csv", newline="") as fh:
        errors = list(csv.DictReader(fh))
    bad = [e for e in errors if e["within_tolerance"] == "False"]
    assert all(e["main_cause"] for e in bad)  # every gap beyond tolerance is attributed
    for name in ("fig7_Ki.png", "fig8_Kc.png", "report.md", "errors.md", "slenderness.csv", "mesh.csv",
                 "effective.csv"):
        assert (tmp_path / name).stat().st_size > 0
    assert np.isfinite(float(errors[0]["theory_shear_um_per_K"]))
