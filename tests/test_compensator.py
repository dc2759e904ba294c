"""Prediction/compensation procedure (eqs 30-38), coefficient fits and ``gatetherm compensate``."""
import json
import logging
from dataclasses import replace

import numpy as np
import pytest

from gatetherm import InputError
from gatetherm import cli
from gatetherm.studies.control.actuator import ActuatorParams
from gatetherm.studies.control.compensator import (CompensatorParams, compensate, extrapolate, held_ratio, predict,
                                 summarize)
from gatetherm.studies.control.regression import THETAS, apply_regression, fit_coefficients, fit_regression
from gatetherm.studies.run.timeseries import TimeSeries, read_timeseries, write_timeseries

EVERY_MIN = CompensatorParams(update_interval_s=60.0)
# 6 samples, 1 min apart: rises dA = 3k, dB = 0.5k, dC = k, so delta = 2(dA - dB) - dC = 4k exactly
HAND = """# format: gatetherm-timeseries/1
# note: delta = 2 (theta_A - theta_B) - 1 theta_C exactly
time_s,oil_degC,pump,theta_A_degC,theta_B_degC,theta_C_degC,delta_um
0,40,1,20,20,20,0
60,40,1,23,20.5,21,4
120,40,1,26,21,22,8
180,40,1,29,21.5,23,12
240,40,1,32,22,24,16
300,40,1,35,22.5,25,20
"""


def series(t, dA, dB, dC, delta):
    n = len(t)
    return TimeSeries({"time_s": t, "oil_degC": np.full(n, 40.0), "pump": np.ones(n),
                       "theta_A_degC": 20 + np.asarray(dA, float), "theta_B_degC": 20 + np.asarray(dB, float),
                       "theta_C_degC": 20 + np.asarray(dC, float), "delta_um": delta})


def peaked(k, ri=1.2, rc=0.8):
    """delta = ri*2*dtheta - rc*theta_C, first positive peak at k = 15 for ri = rc = 1."""
    dth, thc = 5 * (1 - np.exp(-k / 5)), 0.1 * k
    th_b = 3 * (1 - np.exp(-k / 40))
    return series(k * 60.0, dth + th_b, th_b, thc, ri * 2 * dth - rc * thc)


def test_hand_file_gives_unit_factors_and_zero_error(tmp_path):
    (tmp_path / "hand.csv").write_text(HAND)
    pr = predict(read_timeseries(tmp_path / "hand.csv"), 2.0, 1.0, EVERY_MIN)
    assert pr.R_i.tolist() == [1.0] * 6 and pr.R_C.tolist() == [1.0] * 6
    assert np.isnan(pr.delta_pred_um[:2]).all()
    assert pr.delta_pred_um[2:].tolist() == [8.0, 12.0, 16.0, 20.0]  # no prediction error at all
    assert pr.u_um.tolist() == [0.0, 0.0, -8.0, -12.0, -16.0, -20.0]
    assert pr.peak_index is None and not pr.resampled
    with pytest.raises(InputError, match="do not vary independently"):  # dtheta = 2.5 theta_C here
        fit_coefficients(read_timeseries(tmp_path / "hand.csv"))
    assert fit_coefficients(peaked(np.arange(60.0), 1.0, 1.0)) == pytest.approx((2.0, 1.0), rel=1e-12)


def test_extrapolation_and_prediction_hand_example():
    assert extrapolate(2.0, 3.5) == 5.0  # theta(n+1) + [theta(n+1) - theta(n)]
    # dtheta = 0, 1, 1.5; theta_C = 0, .5, 1 -> delta_th = 0, 1.5, 2; delta = 0, 3, 3
    ts = series(np.array([0, 60, 120, 180.0]), [0, 1, 2, 4], [0, 0, 0.5, 1], [0, 0.5, 1, 1.5], [0, 3, 3, 6])
    pr = predict(ts, 2.0, 1.0, EVERY_MIN)
    assert pr.delta_th_um.tolist() == [0.0, 1.5, 2.0, 4.5]
    assert pr.R_i.tolist() == [1.0, 1.0, 2.0, 1.5]  # R_i(2) held (delta_th = 0), 3/1.5, 3/2
    # delta_et(3) = 2 * 2 * (2*1 - 0) - (2*0.5 - 0) = 7; delta_et(4) = 1.5 * 2 * (3 - 1) - (2 - 0.5) = 4.5
    np.testing.assert_array_equal(pr.delta_pred_um, [np.nan, np.nan, 7.0, 4.5])


def test_near_zero_denominators_hold_the_last_factor(caplog):
    assert held_ratio(3.0, 0.5, 1.7, 1.0) == (1.7, True)
    assert held_ratio(3.0, 1.0, 1.7, 1.0) == (1.7, True)  # at the threshold: held
    assert held_ratio(3.0, -1.5, 1.7, 1.0) == (-2.0, False)
    assert held_ratio(3.0, 1.5, 1.7, 1.0, (0.5, 1.5)) == (1.5, False)
    # phase 1: delta_th = 0, 3, 0.5, 4, 6 -> R_i(4) keeps R_i(3) = 3.3/3
    ts = series(np.arange(5) * 60.0, [0, 1.5, 0.25, 2, 3], np.zeros(5), np.zeros(5), [0, 3.3, 3.5, 4.8, 6.0])
    with caplog.at_level(logging.DEBUG, logger="gatetherm.studies.control.compensator"):
        pr = predict(ts, 2.0, 1.0, EVERY_MIN)
    np.testing.assert_allclose(pr.R_i, [1, 1, 1.1, 1.1, 1.2], rtol=1e-15)
    assert "|delta_th| = 0.5 um at or below threshold, R_i held" in caplog.text
    assert "R_i held at 2 samples" in caplog.text
    # phase 2 with K_C = 0: |K_C theta_C| is always 0, so R_C stays 1 for the whole run
    pr = predict(peaked(np.arange(40.0)), 2.0, 0.0, EVERY_MIN)
    assert pr.peak_index is not None and np.all(pr.R_C == 1.0)
    # phase 2 with a slowly warming tie bar: R_C held at 1 until |K_C theta_C| > 1 um (theta_C > 10 K)
    k = np.arange(40.0)
    ts = peaked(k).with_columns(theta_C_degC=20 + 0.5 * k)
    pr = predict(ts, 2.0, 0.1, EVERY_MIN)
    warm = np.flatnonzero(0.1 * 0.5 * k > 1.0)[0]  # k = 21
    assert pr.peak_index < warm and np.all(pr.R_C[: warm + 1] == 1.0) and pr.R_C[warm + 1] != 1.0


def test_peak_freezes_R_i_then_R_C_adapts():
    k = np.arange(60.0)
    ts = peaked(k)
    d_ab = ts["theta_A_degC"] - ts["theta_B_degC"]
    th_c, delta = ts["theta_C_degC"] - 20, ts["delta_um"]
    j = int(np.argmax(delta))
    assert j == 17 and delta[j] > 0
    pr = predict(ts, 2.0, 1.0, EVERY_MIN)
    assert pr.peak_index == j
    assert pr.R_i[j + 1] == pytest.approx(delta[j] / (2 * d_ab[j] - th_c[j]), rel=1e-15)  # eq (34)
    assert np.unique(pr.R_i[j + 1:]).size == 1 and np.unique(pr.R_i[: j + 2]).size > 5  # frozen after j
    assert np.all(pr.R_C[: j + 2] == 1.0) and np.all(pr.R_C[j + 2:] != 1.0)
    c = np.arange(j + 1, len(k) - 1)
    expected = (pr.R_i[j + 1] * 2 * d_ab[c] - delta[c]) / (1.0 * th_c[c])  # eq (37)
    np.testing.assert_allclose(pr.R_C[c + 1], expected, rtol=1e-14)
    pred = pr.R_i[c + 1] * 2 * (2 * d_ab[c] - d_ab[c - 1]) - pr.R_C[c + 1] * (2 * th_c[c] - th_c[c - 1])
    np.testing.assert_allclose(pr.delta_pred_um[c + 1], pred, rtol=1e-14)  # eq (38)
    # a drop threshold only delays the recognition; the peak and the frozen R_i are the same
    late = predict(ts, 2.0, 1.0, replace(EVERY_MIN, peak_drop_um=0.05))
    assert late.peak_index == j and late.R_i[-1] == pr.R_i[j + 1]
    # never positive: no peak, R_C stays 1
    neg = predict(ts.with_columns(delta_um=-np.abs(delta)), 2.0, 1.0, EVERY_MIN)
    assert neg.peak_index is None and np.all(neg.R_C == 1.0)


def test_exact_model_keeps_unit_factors_through_the_peak():
    k = np.arange(60.0)
    pr = predict(peaked(k, 1.0, 1.0), 2.0, 1.0, EVERY_MIN)
    d = pr.delta_um
    assert pr.peak_index == 15
    np.testing.assert_allclose(pr.R_i[2:], 1.0, rtol=1e-13)
    np.testing.assert_allclose(pr.R_C[pr.peak_index + 2:], 1.0, rtol=1e-12)
    # with unit factors the error is what the one-step extrapolation misses: the 2nd difference
    np.testing.assert_allclose(d[2:] - pr.delta_pred_um[2:], d[2:] - 2 * d[1:-1] + d[:-2], atol=1e-12)


def test_commands_are_held_between_updates():
    k = np.arange(23.0)
    pr = predict(peaked(k), 2.0, 1.0, CompensatorParams())  # 5 min
    blocks = (np.arange(23) // 5) * 5
    np.testing.assert_array_equal(pr.u_um, -np.nan_to_num(pr.delta_pred_um[blocks]))
    assert pr.u_um[:5].tolist() == [0.0] * 5 and pr.u_um[5] == -pr.delta_pred_um[5]
    with pytest.raises(InputError, match="whole multiple"):
        CompensatorParams(update_interval_s=150.0)


def test_off_grid_data_are_resampled(caplog):
    fine = np.arange(0, 3001, 30.0)  # 30 s sampling of a linear run
    ts = series(fine, fine / 20, fine / 120, fine / 60, fine / 15)
    with caplog.at_level(logging.INFO):
        loop = compensate(ts, 2.0, 1.0, EVERY_MIN)
    assert loop.prediction.resampled and len(loop.prediction.t_s) == 51
    assert "resampled linearly" in caplog.text
    assert len(loop.delta_comp_um) == len(fine)
    np.testing.assert_allclose(loop.prediction.R_i[2:], 1.0, rtol=1e-12)
    on_grid = fine % 60 == 0
    np.testing.assert_allclose(loop.delta_comp_um[on_grid][2:], 0.0, atol=1e-12)
    # between the minute samples the held stroke lags by half a minute of drift: 2 um
    np.testing.assert_allclose(loop.delta_comp_um[~on_grid][2:], 2.0, atol=1e-12)


def test_closed_loop_with_actuator_and_summary():
    k = np.arange(121.0)
    ts = peaked(k)  # delta 0 .. ~8.6 um and back: inside the piezo range
    ideal = compensate(ts, 2.0, 1.0, CompensatorParams(), None)
    reset = compensate(ts, 2.0, 1.0, CompensatorParams(), ActuatorParams())
    direct = compensate(ts, 2.0, 1.0, CompensatorParams(), ActuatorParams(strategy="direct"))
    np.testing.assert_allclose(reset.stroke_um, ideal.stroke_um, atol=1e-12)
    assert reset.saturated_updates == 0 and np.all(np.isnan(ideal.voltage_V))
    apart = peaked(k, 1.2, 2.0)  # delta ends at -12 um: commands towards the workpiece
    ideal_apart = compensate(apart, 2.0, 1.0, CompensatorParams(), None)
    both = compensate(apart, 2.0, 1.0, CompensatorParams(), ActuatorParams())
    np.testing.assert_allclose(both.stroke_um, ideal_apart.stroke_um, atol=1e-12)  # reach both ways
    zero_ref = compensate(apart, 2.0, 1.0, CompensatorParams(), ActuatorParams(bias_voltage_V=0.0))
    ok = ideal_apart.u_um <= 0  # a 0 V reference can only pull the tool away
    np.testing.assert_allclose(zero_ref.stroke_um[ok], ideal_apart.stroke_um[ok], atol=1e-12)
    assert np.all(zero_ref.stroke_um[~ok] == 0) and 10 < ideal_apart.u_um.max() < 23
    assert zero_ref.saturated_updates == np.sum(ideal_apart.u_um[::5] > 0) > 10
    assert np.max(np.abs(direct.stroke_um - reset.stroke_um)) > 0.3  # hysteresis without reset
    s_ideal, s_direct = summarize(ideal), summarize(direct)
    d = ts["delta_um"]
    assert s_ideal["swing_um"] == pytest.approx(d.max() - d.min(), rel=1e-15)
    late = k >= 10
    assert s_ideal["residual_band_um"] == pytest.approx(np.max(np.abs(ideal.delta_comp_um[late])), rel=1e-15)
    assert s_ideal["prediction_error_band_um"] == pytest.approx(
        np.max(np.abs(d - ideal.delta_pred_um)[late]), rel=1e-15)
    assert s_direct["residual_band_um"] > s_ideal["residual_band_um"]
    at = late & (k % 5 == 0)  # at an update the ideal stroke cancels the prediction made for it
    assert s_ideal["residual_at_updates_um"] == pytest.approx(
        np.max(np.abs(d - ideal.delta_pred_um)[at]), rel=1e-12)
    assert s_ideal["residual_at_updates_um"] <= s_ideal["prediction_error_band_um"]
    assert s_ideal["peak_time_s"] == 17 * 60.0 and s_ideal["R_i_final"] == ideal.prediction.R_i[-1]


def test_regression_baseline_fits_one_run_and_applies_to_another():
    k = np.arange(0, 300.0, 5)
    a = peaked(k).with_columns(T_leg_degC=20 + 0.01 * k ** 1.5)
    model = fit_regression(a)
    assert model.features == ("theta_A_degC", "theta_B_degC", "theta_C_degC", "T_leg_degC")
    b = peaked(k, 1.0, 1.0).with_columns(T_leg_degC=21 + 0.02 * k ** 1.2)
    pred = apply_regression(model, b)
    assert pred.shape == k.shape and np.all(np.isfinite(pred))
    th_b = k ** 1.2 / 10
    exact = series(k * 60, 3 * k, th_b, np.sqrt(k), 1.5 + 2 * (3 * k - th_b) - np.sqrt(k)
                   ).with_columns(T_leg_degC=20 + 0.01 * k ** 1.5)
    fit = fit_regression(exact)
    np.testing.assert_allclose(apply_regression(fit, exact), exact["delta_um"], atol=1e-9)
    with pytest.raises(InputError, match="T_leg_degC"):
        apply_regression(model, peaked(k))
    # theta_C is the mean of the tie-bar points: the last one adds nothing and is left out
    c1 = 20 + 0.5 * k ** 0.8
    tie = exact.with_columns(T_C1_degC=c1, T_C2_degC=2 * exact["theta_C_degC"] - c1)
    assert fit_regression(tie).features == THETAS + ("T_leg_degC", "T_C1_degC")
    three = fit_regression(tie, THETAS)  # the paper's sensors only: eq (21) with an intercept
    assert three.features == THETAS
    np.testing.assert_allclose(three.coefficients + (three.intercept_um,), (2, -2, -1, 1.5), atol=1e-9)


# ---- the command line --------------------------------------------------------------------

@pytest.fixture
def gatetherm(monkeypatch, capsys):
    monkeypatch.setattr(cli, "COMMAND_MODULES", ("compensate",))  # only this command's parser

    def run(*argv):
        code = cli.main([str(a) for a in argv])
        return code, capsys.readouterr().err
    return run


def test_cli_hand_file(tmp_path, gatetherm):
    (tmp_path / "hand.csv").write_text(HAND)
    out = tmp_path / "out"
    code, err = gatetherm("compensate", "--data", tmp_path / "hand.csv", "--out", out, "--Ki", 2, "--Kc", 1,
                          "--interval-min", 1, "--no-actuator")
    assert code == 0, err
    summary = json.loads((out / "summary.json").read_text())
    assert summary["R_i_final"] == 1.0 and summary["R_C_final"] == 1.0 and summary["swing_um"] == 20.0
    assert summary["prediction_error_band_um"] is None  # the run is shorter than the 10 min settling
    comp = read_timeseries(out / "compensated.csv")
    assert comp.names[-3:] == ("u_piezo_um", "delta_pred_um", "delta_comp_um")
    np.testing.assert_array_equal(comp["delta_pred_um"][2:], comp["delta_um"][2:])
    assert comp["delta_comp_um"].tolist() == [0.0, 4.0, 0.0, 0.0, 0.0, 0.0]
    assert sorted(p.name for p in out.iterdir()) == ["compensated.csv", "compensation.png", "summary.json"]
    # the same rows 5 min apart: resampled to 1 min, zero error after 10 min
    rows = HAND.splitlines()
    slow = rows[:3] + [f"{300 * i}," + r.split(",", 1)[1] for i, r in enumerate(rows[3:])]
    (tmp_path / "slow.csv").write_text("\n".join(slow) + "\n")
    code, err = gatetherm("compensate", "--data", tmp_path / "slow.csv", "--out", out, "--Ki", 2, "--Kc", 1)
    assert code == 0, err
    summary = json.loads((out / "summary.json").read_text())
    assert summary["resampled"] and summary["k_source"] == "explicit"
    assert summary["prediction_error_band_um"] < 1e-12 and summary["residual_band_um"] < 1e-12
    assert (out / "piezo_loops.png").stat().st_size > 10_000


def test_cli_fitted_coefficients(tmp_path, gatetherm):
    write_timeseries(tmp_path / "run.csv", peaked(np.arange(121.0), 1.0, 1.0))
    code, err = gatetherm("compensate", "--data", tmp_path / "run.csv", "--out", tmp_path / "o",
                          "--k-source", "fit")
    assert code == 0, err
    summary = json.loads((tmp_path / "o" / "summary.json").read_text())
    assert summary["k_source"] == "fit" and summary["peak_time_s"] == 900.0
    assert (summary["Ki_um_per_K"], summary["Kc_um_per_K"]) == pytest.approx((2.0, 1.0), rel=1e-12)
    assert summary["R_i_final"] == pytest.approx(1.0, rel=1e-9)


@pytest.mark.parametrize("edit, args, message", [
    (lambda s: s.replace("\n180,", "\n120,"), (),
     "line 7 (data row 4), column time_s: time 120 s is not after the previous 120 s"),
    (lambda s: s.replace("22,8\n", "22,\n"), (),
     "data row 3 (time_s = 120), column delta_um: value missing"),
    (lambda s: s, ("--Ki", "2"), "--Ki/--Kc: give both"),
    (lambda s: s, ("--Ki", "2", "--Kc", "1", "--k-source", "fit"), "--Ki/--Kc: give both"),
    (lambda s: s, ("--interval-min", "2.5"), "update interval: 150 s is not a whole multiple"),
    (lambda s: s, ("--interval-min", "0"), "--interval-min: must be > 0"),
    (lambda s: s, ("--out", "bad.csv"), "exists and is not a directory"),
])
def test_cli_errors_one_line_exit_2_nothing_written(tmp_path, monkeypatch, gatetherm, edit, args, message):
    monkeypatch.chdir(tmp_path)
    data = tmp_path / "bad.csv"
    data.write_text(edit(HAND))
    out = tmp_path / "out"
    code, err = gatetherm("compensate", "--data", data, "--out", out, *args)  # a later --out wins
    assert code == 2
    assert err.count("\n") == 1 and err.startswith("gatetherm: error: ") and message in err
    assert "Traceback" not in err and not out.exists() and data.read_text() == edit(HAND)
