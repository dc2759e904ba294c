"""Machine elements' losses (solvers/elements/) and their sources in a case file: each formula
against its hand calculation, each expression against its function, and an insulated block
heated by a bearing's Palmgren loss at P/(m c)."""
from __future__ import annotations

import math
import shutil
from pathlib import Path

import numpy as np
import pytest

import gatetherm as gt
from gatetherm import InputError
from gatetherm.solvers import elements as el
from gatetherm.solvers.expr import Value

DATA = Path(__file__).resolve().parent / "data"
POINTS = [dict(n=6000.0, nu=22.0, load=2000.0), dict(n=50.0, nu=10.0, load=500.0),
          dict(n=-12000.0, nu=8.0, load=-800.0)]
"""Three operating points: fast (ν n ≥ 2000), slow (ν n < 2000), reversed."""


def test_palmgren_at_the_issue_point_by_hand():
    """ν n = 132 000: M0 = 1e-7 · 2 · 132000^(2/3) · 82.5³ N·mm, M1 = 0.0004 · 2000 · 82.5 N·mm."""
    m0 = 1e-7 * 2.0 * 132000.0 ** (2 / 3) * 82.5 ** 3
    m = (m0 + 0.0004 * 2000.0 * 82.5) * 1e-3
    assert el.palmgren_torque(6000.0, 22.0, 0.0825, 2.0, 0.0004, 2000.0) == pytest.approx(m, rel=1e-14)
    P = el.bearing_loss(6000.0, 22.0, 0.0825, 2.0, 0.0004, 2000.0)
    assert P == pytest.approx(m * 2 * math.pi * 100.0, rel=1e-14)
    assert P == pytest.approx(224.400, abs=1e-3)  # the acceptance block's power, W
    # below ν n = 2000 the speed term is 160e-7 f0 dm³ whatever the speed
    slow = el.palmgren_torque(np.array([1.0, 90.0]), 22.0, 0.0825, 2.0, 0.0, 0.0)
    np.testing.assert_allclose(slow, 160e-7 * 2.0 * 82.5 ** 3 * 1e-3, rtol=1e-14)


@pytest.mark.parametrize("point", POINTS)
def test_every_expression_is_its_function(point):
    n, nu, load = point["n"], point["nu"], point["load"]
    env = {"speed": n, "visc": nu, "F": load, "T": 12.0, "eta": 0.93, "v": n / 60000.0}

    def ev(text):
        return Value.of(text)(env)
    assert ev(el.bearing_text("speed", "visc", 0.07, 1.7, 3e-4, "F")) == pytest.approx(
        el.bearing_loss(n, nu, 0.07, 1.7, 3e-4, load), rel=1e-12)
    assert ev(el.ball_screw_nut_text("speed", 0.01, 0.04, 1500.0, "F", 0.9)) == pytest.approx(
        el.ball_screw_nut_loss(n, 0.01, 0.04, 1500.0, load, 0.9), rel=1e-12)
    assert ev(el.guide_text("v", "F", 0.003, 8.0)) == pytest.approx(el.guide_loss(n / 60000.0, load, 0.003, 8.0),
                                                                    rel=1e-12)
    assert ev(el.motor_text("speed", "T", "eta", 25.0)) == pytest.approx(el.motor_loss(n, 12.0, 0.93, 25.0), rel=1e-12)


def test_element_formulas_by_hand():
    """A 10-mm lead, 40-mm screw with 1500 N preload at 3000 1/min and no load: the makers' drag
    torque 0.05 (l/(π d))^(-1/2) Fp l/(2π); a guide μ F v + seal v; a motor at 90 %."""
    tp = 0.05 * (0.01 / (math.pi * 0.04)) ** -0.5 * 1500.0 * 0.01 / (2 * math.pi)
    assert el.ball_screw_nut_loss(3000.0, 0.01, 0.04, 1500.0, 0.0, 0.9) == pytest.approx(tp * 100 * math.pi, rel=1e-14)
    assert el.guide_loss(0.5, 4000.0, 0.003, 10.0) == pytest.approx(0.5 * (12.0 + 10.0), rel=1e-14)
    assert el.motor_loss(3000.0, 10.0, 0.9, 0.0) == pytest.approx(10.0 * 100 * math.pi / 9.0, rel=1e-14)


BLOCK = """
[mesh]
file = "two_names.geo"
[materials.plate]
k = 50.0
rho = 7800.0
c = 460.0
thickness = 0.1
[sources.plate]
kind = "bearing"
speed = "n_spindle"
dm = 0.0825
f0 = 2.0
f1 = 0.0004
viscosity = 22.0
load = 2000.0
[probes.corner]
point = "corner"
[time]
end = 600.0
step = 60.0
schedule = "speed.csv"
"""


def test_insulated_block_heats_at_the_bearing_loss(tmp_path):
    """No film: the block's mean temperature rises at P/(m c), P Palmgren's loss at 6000 1/min
    (the issue's acceptance: within 0.5 %); the run reports the loss as P_plate_W."""
    shutil.copy(DATA / "two_names.geo", tmp_path)
    (tmp_path / "c.toml").write_text(BLOCK)
    (tmp_path / "speed.csv").write_text("time_s,n_spindle\n0,6000\n600,6000\n")
    run = gt.run(gt.load_case(tmp_path / "c.toml"))
    P = el.bearing_loss(6000.0, 22.0, 0.0825, 2.0, 0.0004, 2000.0)
    np.testing.assert_allclose(run["P_plate_W"], P, rtol=1e-12)
    rate = (run["T_corner_degC"][-1] - 20.0) / 600.0  # uniform source, insulated: uniform temperature
    expected = P / (7800.0 * 0.1 * 460.0)  # m c of the 1 m² × 0.1 m plate
    err = abs(rate / expected - 1)
    assert err == pytest.approx(0.0, abs=1e-9)  # band: < 0.005


def test_a_factor_on_an_element_loss_is_the_diagnosis_parameter_of_its_source(tmp_path):
    """``factor`` scales the element's loss; the diagnosis offers it as ``source_REGION`` (a factor
    on the loss), whose value 1.4 is the loss × 1.4 (a new user's machine: issue 51)."""
    from gatetherm.studies.run.parameters import case_parameters

    shutil.copy(DATA / "two_names.geo", tmp_path)
    (tmp_path / "c.toml").write_text(BLOCK.replace("[sources.plate]\n", "[sources.plate]\nfactor = 1.25\n"))
    (tmp_path / "speed.csv").write_text("time_s,n_spindle\n0,6000\n600,6000\n")
    case = gt.load_case(tmp_path / "c.toml")
    P = el.bearing_loss(6000.0, 22.0, 0.0825, 2.0, 0.0004, 2000.0)
    np.testing.assert_allclose(gt.run(case)["P_plate_W"], 1.25 * P, rtol=1e-12)
    (param,) = [q for q in case_parameters(case) if q.name == "source_plate"]
    np.testing.assert_allclose(gt.run(case.with_overrides(param.overrides(1.4)))["P_plate_W"], 1.4 * 1.25 * P,
                               rtol=1e-12)


@pytest.mark.parametrize("body, where", [
    ('kind = "bearing"\npower = 10.0\ndm = 0.05\nspeed = 100.0\nviscosity = 10.0', "sources.plate.power"),
    ('kind = "guide"\nspeed = 0.1\ndm = 0.05', "sources.plate.dm"),
    ('kind = "gear"\nspeed = 0.1', "sources.plate.kind"),
    ('speed = 0.1\npower = 3.0', "sources.plate.speed"),
    ('factor = 2.0\npower = 3.0', "sources.plate.factor"),
    ('kind = "motor"\nspeed = 3000.0\ntorque = 2.0\nefficiency = 1.5', "sources.plate.efficiency"),
    ('kind = "motor"\nspeed = 3000.0\ntorque = 2.0\nefficiency = "3/2"', "sources.plate.efficiency: '3/2' is 1.5"),
])
def test_bad_element_source_is_one_line(tmp_path, body, where):
    shutil.copy(DATA / "two_names.geo", tmp_path)
    text = BLOCK.split("[sources.plate]")[0] + "[sources.plate]\n" + body + "\n[time]\nend = 60.0\n"
    (tmp_path / "c.toml").write_text(text)
    with pytest.raises(InputError) as err:
        gt.load_case(tmp_path / "c.toml")
    assert where in str(err.value) and "\n" not in str(err.value)


def test_bad_bearing_through_the_cli_is_one_line_and_exit_2(tmp_path, capsys):
    from gatetherm.cli import main

    shutil.copy(DATA / "two_names.geo", tmp_path)
    (tmp_path / "c.toml").write_text(BLOCK.replace('type = "angular_contact_oil"\n', "").replace(
        "dm = 0.0825", 'dm = 0.0825\ntype = "tapered"'))
    (tmp_path / "speed.csv").write_text("time_s,n_spindle\n0,6000\n600,6000\n")
    assert main(["run", str(tmp_path / "c.toml"), "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "sources.plate.type" in err and "angular_contact_oil" in err
