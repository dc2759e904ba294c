"""Piezo stack model: play operators, dead band, reset strategy, inverse, closed-loop drive."""
from dataclasses import replace

import numpy as np
import pytest

from gatetherm import InputError
from gatetherm.studies.control.actuator import (ActuatorParams, apply_commands, dead_band_um, hysteresis_cost_um, load_factor,
                              loaded_stroke, loop_width_um, play, reset_curve, reset_state, saturated_commands,
                              step, stroke_range, sweep, voltage_for, weights)

PRELOADED = ActuatorParams()
UNLOADED = replace(PRELOADED, preload_N=0.0)


def test_play_operator_hand_values():
    # half width 2: follows the input only once the play is taken up
    z = 0.0
    out = []
    for v in (1.0, 3.0, 5.0, 4.0, 2.0, 0.0):
        z = float(play(z, v, 2.0))
        out.append(z)
    assert out == [0.0, 1.0, 3.0, 3.0, 3.0, 2.0]


def test_derived_values():
    assert load_factor(PRELOADED) == pytest.approx(87.5 / (87.5 + 32.34), rel=1e-15)
    assert dead_band_um(UNLOADED) == 3.0
    assert dead_band_um(PRELOADED) == pytest.approx(3.0 * np.exp(-5.8), rel=1e-15)  # 0.00908 um
    w, r = weights(PRELOADED), np.array(PRELOADED.play_thresholds_V)
    assert np.sum(w * (150 - 2 * r)) == pytest.approx(150.0, rel=1e-15)
    # full stroke at 150 V: 40 um free x load factor, less the (tiny) dead band
    assert reset_curve(PRELOADED, 150.0) == pytest.approx(40 * load_factor(PRELOADED) - 3 * np.exp(-5.8))
    assert float(reset_curve(PRELOADED, 150.0)) == pytest.approx(29.19652, abs=1e-5)


def test_unloaded_dead_band_at_start():
    volts = np.linspace(0, 30, 31)
    x = sweep(replace(UNLOADED, strategy="direct"), volts)
    first = int(np.argmax(x > 0))
    # no motion until the loaded stroke has taken up the 3 um seating gap (at ~23 V)
    assert np.all(x[:first] == 0) and volts[first] == 23.0
    assert loaded_stroke(UNLOADED, 22.0) < 3.0 < loaded_stroke(UNLOADED, 23.0)
    assert sweep(replace(PRELOADED, strategy="direct"), [1.0])[0] > 0  # preloaded: moves at once


def test_direct_loop_open_3_04_um_preloaded_6_03_um_unloaded():
    width_pre = loop_width_um(replace(PRELOADED, strategy="direct"))
    width_un = loop_width_um(replace(UNLOADED, strategy="direct"))
    print(f"open loop, direct drive: preloaded {width_pre:.4f} um, unloaded {width_un:.4f} um")
    assert width_pre == pytest.approx(3.04343, abs=1e-5)  # ~10 % of the 29.2 um stroke: hysteresis
    assert width_un == pytest.approx(6.03435, abs=1e-5)  # hysteresis + the 3 um dead band
    assert width_un - width_pre == pytest.approx(3.0 - dead_band_um(PRELOADED), abs=0.01)


@pytest.mark.parametrize("params", [PRELOADED, UNLOADED], ids=["preloaded", "unloaded"])
def test_reset_loop_closes_within_dead_band(params):
    p = replace(params, strategy="reset")
    width = loop_width_um(p)
    assert width <= dead_band_um(p) and width == 0.0
    # the same voltage gives the same stroke whatever came before; it is the reset curve
    volts = np.random.default_rng(1).uniform(0, 150, 50)
    x = sweep(p, volts)
    np.testing.assert_allclose(x, reset_curve(p, volts), rtol=0, atol=1e-12)
    assert len({sweep(p, [before, 60.0])[-1] for before in (0.0, 30.0, 60.0, 90.0, 150.0)}) == 1


def test_direct_drive_remembers_history():
    p = replace(PRELOADED, strategy="direct")
    up, down = sweep(p, [75.0]), sweep(p, [150.0, 75.0])[-1]
    assert down - up[0] == pytest.approx(3.04343, abs=1e-5)  # mid-loop, the widest point
    state, x = step(p, reset_state(p), 150.0)
    state, _ = step(p, state, 0.0)
    assert state == reset_state(p)  # a full return to 0 V wipes the memory


def test_inverse_is_exact_and_clipped():
    for p in (PRELOADED, UNLOADED):
        volts = np.linspace(0.5, 150, 40)
        x = reset_curve(p, volts)
        moving = x > 0
        np.testing.assert_allclose(voltage_for(p, x[moving]), volts[moving], rtol=0, atol=1e-9)
        np.testing.assert_allclose(reset_curve(p, voltage_for(p, x)), x, atol=1e-12)
    assert voltage_for(PRELOADED, [-1.0, 0.0, 100.0]).tolist() == [0.0, 0.0, 150.0]


def test_apply_commands_reset_hits_targets_direct_does_not():
    commands = np.array([-5.0, -20.0, -28.0, -12.0, -3.0, -15.0])
    volts, achieved = apply_commands(PRELOADED, commands)
    np.testing.assert_allclose(achieved, commands, atol=1e-12)
    assert np.all((volts > 0) & (volts < 150))
    _, direct = apply_commands(replace(PRELOADED, strategy="direct"), commands)
    err = direct - commands
    np.testing.assert_allclose(err[:3], 0, atol=1e-12)  # rising voltages: on the reset curve
    assert err[3] < -1.0 and err[4] < -0.5  # falling: the descending branch moves the tool further


def test_default_range_works_both_ways_and_covers_the_paper_swing():
    # zero compensation at 50 V: x_bias = (150/231) * 62.4 V * load factor * 40/150 um/V - dead band
    x_bias = 150 / 231 * 62.4 * load_factor(PRELOADED) * 40 / 150 - dead_band_um(PRELOADED)
    assert float(reset_curve(PRELOADED, 50.0)) == pytest.approx(x_bias, rel=1e-14)
    lo, hi = stroke_range(PRELOADED)
    assert hi == pytest.approx(3 * x_bias, rel=1e-14) and hi == pytest.approx(23.64067, abs=1e-5)
    assert lo == pytest.approx(-3 * (float(reset_curve(PRELOADED, 150.0)) - x_bias), rel=1e-14)
    assert lo == pytest.approx(-63.94890, abs=1e-5)
    # the paper's compensated range, +44 um approach .. -16 um apart, with its +-7 um band
    assert lo < -(44 + 7) and hi > 16 + 7
    assert hysteresis_cost_um(PRELOADED) == pytest.approx(3 * 3.04343, abs=1e-4)  # at the cutting area


def test_apply_commands_saturates_and_transmits():
    _, achieved = apply_commands(PRELOADED, [5.0, -40.0, 20.0])
    np.testing.assert_allclose(achieved, [5.0, -40.0, 20.0], atol=1e-12)  # both ways from the bias
    commands = [30.0, -80.0, -10.0]
    _, achieved = apply_commands(PRELOADED, commands)
    np.testing.assert_allclose(achieved, [*stroke_range(PRELOADED)[::-1], -10.0], atol=1e-12)  # clipped
    assert saturated_commands(PRELOADED, commands).tolist() == [True, True, False]  # said by compensate, once
    zero_ref = replace(PRELOADED, bias_voltage_V=0.0, transmission=1.0)
    _, achieved = apply_commands(zero_ref, [5.0, -40.0])
    assert achieved[0] == 0.0  # cannot push the tool towards the workpiece from a 0 V reference
    assert achieved[1] == pytest.approx(-29.19652, abs=1e-5)  # full stroke
    biased = replace(PRELOADED, bias_voltage_V=75.0, transmission=2.0)
    _, achieved = apply_commands(biased, [25.0, -32.0])
    np.testing.assert_allclose(achieved, [25.0, -32.0], atol=1e-12)


def test_bad_parameters():
    with pytest.raises(InputError, match="strategy"):
        ActuatorParams(strategy="fast")
    with pytest.raises(InputError, match="voltage"):
        sweep(PRELOADED, [10.0, 151.0])
