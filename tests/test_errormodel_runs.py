"""Error models that hold on data they have never seen (issue 56): forward chaining, several runs
each its own reference, leave one run out, 90 % intervals calibrated on held-out data, the drift
warning and the guarded refit; on synthetic data with a known answer."""
from __future__ import annotations

import json

import numpy as np
import pytest

import gatetherm as gt
from gatetherm.cli import main
from gatetherm.studies.errormodel import select
from gatetherm.studies.errormodel.fit import FitParams, fit_error_model
from gatetherm.studies.errormodel.model import load_model, predict
from gatetherm.studies.errormodel.trust import trust
from gatetherm.studies.errormodel.terms import Term, anchor_value, lag, noise_sd
from gatetherm.studies.run.timeseries import FORMAT, TimeSeries, write_timeseries

SENSORS = ("s1_degC", "s2_degC", "s3_degC")


def run(seed: int, start_K: float, speed: float, k1: float = 2.0, noise_um: float = 0.05, n: int = 600) -> TimeSeries:
    """10 h of 60-s samples of a machine started at ``start_K`` above 20 degC, at ``speed`` rpm
    from 1 h to 7 h, three sensors heated by it and each wandering of its own:
    ``d = k1 theta_1 - 0.8 theta_3`` since the start, plus an axis offset of 7 um per K of the start
    temperature and white noise."""
    rng = np.random.default_rng(seed)
    t = 60.0 * np.arange(n)
    rpm = np.where((t >= 3600) & (t < 7 * 3600), speed, 0.0)
    heat = lag(t, (rpm / 4500.0) ** 2, 3000.0)
    walk = [np.convolve(np.cumsum(rng.normal(0.0, 0.15, n + 60)), np.ones(60) / 60, "valid")[:n] for _ in range(3)]
    temps = {"s1_degC": 20 + start_K + 3.0 * heat + walk[0],
             "s2_degC": 20 + start_K + 1.0 * heat + walk[1],
             "s3_degC": 20 + start_K + 2.0 * lag(t, heat, 3000.0) + walk[2]}
    th = {k: v - v[0] for k, v in temps.items()}
    d = 7.0 * start_K + k1 * th["s1_degC"] - 0.8 * th["s3_degC"]
    return TimeSeries({"time_s": t, "spindle_rpm": rpm, **temps, "d_um": d + rng.normal(0.0, noise_um, n)},
                      {"format": FORMAT})


RUNS = [run(1, 0.0, 4500.0), run(2, 3.0, 3000.0), run(3, 1.5, 4000.0), run(4, 5.0, 2000.0)]


def test_forward_chaining_predicts_each_latest_block_from_the_rows_before_it():
    """Z = 1, y = row index: each later block is predicted by the mean of the rows before it,
    (lo - 1) / 2, so its error is sum |i - (lo - 1)/2| over the block; K = 4 tests blocks 3 and 4."""
    n = 40
    y = np.arange(n, dtype=float)
    cv = select.CrossValidation(np.ones((n, 1)), y, folds=(4,), chain=True)
    assert cv.blocks == [(20, 30), (30, 40)]
    exact = sum(np.abs(np.arange(lo, hi) - (lo - 1) / 2).sum() for lo, hi in cv.blocks) / 20
    assert cv.error(np.eye(1)) == pytest.approx(exact, rel=1e-12)  # 15.0
    assert exact == pytest.approx(17.5)  # blocks: 10.5..19.5 and 15.5..24.5, means 15 and 20
    blocked = select.CrossValidation(np.ones((n, 1)), y, folds=(4,))
    assert blocked.error(np.eye(1)) < cv.error(np.eye(1))  # the later blocks lie beyond what chaining fits


def test_several_runs_each_their_own_reference_leave_one_run_out():
    model = fit_error_model(RUNS[:3], ["d_um"], SENSORS, (), FitParams(cv="chain", drift=True))
    m = model.target("d_um")
    assert model.run_reference and model.fit_span["runs"] == 3
    assert set(m.sensors) == {"s1_degC", "s3_degC"}
    coef = {t.label: b for t, b in zip(m.terms, m.coefficients)}
    assert coef["s1_degC"] == pytest.approx(2.0, abs=0.02)  # the 7 um/K axis offsets of the runs are not fitted
    assert coef["s3_degC"] == pytest.approx(-0.8, abs=0.02)
    assert "drift (h)" not in coef  # offered, did not earn its place
    # a fourth run, started warmer than any: zero at its start, within the noise after it
    new = RUNS[3]
    p = predict(model, new)["d_um"]
    assert p[0] == 0.0
    err = np.mean(np.abs(p - (new["d_um"] - new["d_um"][0])))
    assert err == pytest.approx(0.057, abs=0.01)  # band: < 0.1 (noise 0.05 um, its first sample's too)
    assert m.held_out_mae_um == pytest.approx(0.044, abs=0.005)  # leave one run out; band: < 0.1


def test_interval_holds_about_ninety_percent_of_held_out_samples():
    model = fit_error_model(RUNS, ["d_um"], SENSORS, (), FitParams(cv="chain"))
    iv = model.target("d_um").interval
    assert iv["half_width_um"] == pytest.approx(1.645 * 0.05 * np.sqrt(2), rel=0.15)  # noise of y - y[0]
    assert iv["coverage"] == pytest.approx(0.9, abs=0.03)  # band: 0.85-0.95
    assert iv["calibration"] == "runs"
    fresh = run(9, 2.0, 3500.0)
    inside = trust(model, fresh)["d_um"]
    # a new run, anchored on its one first sample (its noise shifts the whole run): 8.3 % outside
    # (17.8 % when the interval was the pooled quantile of the final model's held-out residuals)
    assert inside["share_missed"] == pytest.approx(0.083, abs=0.02) and inside["warning"] is None


def test_the_interval_of_several_runs_is_calibrated_on_each_run_as_a_new_one():
    """Each run predicted by the whole fit made on the others; the half-width the largest of the runs'
    own 90 % quantiles (conformal over 4 runs), recomputed here from those fits."""
    from gatetherm.studies.errormodel.fit import _fit

    params = FitParams(cv="chain")
    model = fit_error_model(RUNS, ["d_um"], SENSORS, (), params)
    q = []
    for i, r in enumerate(RUNS):
        inner = _fit([x for j, x in enumerate(RUNS) if j != i], ["d_um"], SENSORS, (), params, None)
        y = np.asarray(r["d_um"]) - r["d_um"][0]
        q.append(np.quantile(np.abs(predict(inner, r)["d_um"] - y), 0.9))
    assert model.target("d_um").interval["half_width_um"] == pytest.approx(max(q), rel=1e-12)
    assert model.target("d_um").held_out_mae_um == _fit(RUNS, ["d_um"], SENSORS, (), params, None).target(
        "d_um").held_out_mae_um  # the model itself is the same


def test_two_runs_chain_on_one_clock():
    """Two runs (forward chaining across both): the second continues the first on the interval's clock,
    so no horizon is negative and the fit's length is both runs."""
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)
        model = fit_error_model(RUNS[:2], ["d_um"], SENSORS, (), FitParams(cv="chain"))
    iv = model.target("d_um").interval
    assert iv["fit_length_s"] == pytest.approx(2 * 599 * 60.0 + 60.0) and np.isfinite(iv["half_width_um"])


def test_drift_warning_when_the_machine_leaves_the_fitting_data():
    model = fit_error_model(RUNS, ["d_um"], SENSORS, (), FitParams(cv="chain"))
    odd = run(5, 1.0, 4500.0, k1=3.0)  # the machine changed: s1 weighs 3 um/K now
    hot = odd.with_columns(s1_degC=odd["s1_degC"] + np.linspace(0.0, 30.0, len(odd)))  # and s1 far beyond its range
    result = gt.errormodel_predict(model, hot)
    assert len(result.warnings) == 1 and result.warnings[0].startswith("d_um: the record is unlike the fitting data")
    assert result.scores["d_um"]["share_outside"] > 0.5
    assert gt.errormodel_predict(model, RUNS[0]).warnings == ()


def test_refit_fits_the_raw_error_not_what_its_correction_left():
    model = fit_error_model(RUNS, ["d_um"], SENSORS, (), FitParams(cv="chain"))
    later = run(6, 2.0, 4000.0, k1=2.6, n=1400)  # the machine's s1 coefficient grew from 2.0 to 2.6 um/K
    applied = predict(model, later)["d_um"]
    measured = later.with_columns(d_um=later["d_um"] - applied, applied_um=applied)  # what the correction left
    new, report = gt.errormodel_refit(model, measured, 20 * 3600.0, {"d_um": "applied_um"})
    coef = dict(zip((t.label for t in new.target("d_um").terms), new.target("d_um").coefficients))
    assert not report["d_um"]["kept"]
    assert coef["s1_degC"] == pytest.approx(2.6, abs=0.05)
    assert report["d_um"]["refit_mae_um"] < 0.5 * report["d_um"]["current_mae_um"]
    # without the applied column the refit would learn the residual; never silently worse keeps the old model
    _, blind = gt.errormodel_refit(model, measured, 20 * 3600.0)
    assert blind["d_um"]["current_mae_um"] > blind["d_um"]["refit_mae_um"] or blind["d_um"]["kept"]


def test_cli_fit_several_runs_predict_and_refit(tmp_path, capsys):
    files = []
    for k, ts in enumerate(RUNS[:3]):
        files.append(str(tmp_path / f"run{k}.csv"))
        write_timeseries(files[-1], ts)
    odd = RUNS[3].with_columns(s1_degC=RUNS[3]["s1_degC"] + np.linspace(0.0, 30.0, len(RUNS[3])))
    write_timeseries(tmp_path / "odd.csv", odd)
    assert main(["errormodel", "fit", "--data", *files, "--targets", "d_um",
                 "--out", str(tmp_path / "fit")]) == 0
    out = capsys.readouterr().out
    assert "fitted on 3 run(s)" in out and "leave one run out" in out and "90 % interval" in out
    assert main(["errormodel", "predict", str(tmp_path / "fit" / "model.json"), "--data", str(tmp_path / "odd.csv"),
                 "--out", str(tmp_path / "pred")]) == 0
    out = capsys.readouterr().out
    assert sum(line.startswith("warning: d_um: the record is unlike the fitting data") for line in out.splitlines()) == 1
    summary = json.loads((tmp_path / "pred" / "summary.json").read_text())
    assert len(summary["warnings"]) == 1
    assert main(["errormodel", "refit", str(tmp_path / "fit" / "model.json"), "--data", files[0], "--window-h", "8",
                 "--out", str(tmp_path / "refit")]) == 0
    assert "d_um:" in capsys.readouterr().out
    assert load_model(tmp_path / "refit" / "model.json").run_reference
    assert main(["errormodel", "refit", str(tmp_path / "fit" / "model.json"), "--data", files[0],
                 "--window-h", "-1", "--out", str(tmp_path / "bad")]) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and "--window-h" in err


def test_expected_error_on_noisy_readings_is_the_folded_normal_mean():
    assert select.noisy_mae(np.array([0.0]), 0.3)[0] == pytest.approx(0.3 * np.sqrt(2 / np.pi), rel=1e-12)
    assert select.noisy_mae(np.array([-5.0, 5.0]), 0.1) == pytest.approx([5.0, 5.0], rel=1e-12)  # |r| >> sd
    rng = np.random.default_rng(0)
    r = np.array([0.2, -0.5])
    sampled = np.abs(r[:, None] + rng.normal(0.0, 0.4, (2, 200000))).mean(axis=1)
    assert select.noisy_mae(r, 0.4) == pytest.approx(sampled, abs=0.003)


def test_a_drift_across_runs_earns_its_place():
    """0.3 um/h of drift in every run (e.g. a slowly creeping axis): the drift term is kept, at 0.3 um/h."""
    drifting = [r.with_columns(d_um=r["d_um"] + 0.3 * r["time_s"] / 3600.0) for r in RUNS]
    m = fit_error_model(drifting, ["d_um"], SENSORS, (), FitParams(drift=True)).target("d_um")
    coef = {t.label: b for t, b in zip(m.terms, m.coefficients)}
    assert coef["drift (h)"] == pytest.approx(0.3, abs=0.01)
    assert coef["s1_degC"] == pytest.approx(2.0, abs=0.02)


def test_cli_a_run_without_a_column_is_one_line_naming_its_file(tmp_path, capsys):
    good, bad = tmp_path / "good.csv", tmp_path / "bad.csv"
    write_timeseries(good, RUNS[0])
    write_timeseries(bad, TimeSeries({n: RUNS[1][n] for n in ("time_s", "s1_degC", "d_um")}, {"format": FORMAT}))
    assert main(["errormodel", "fit", "--data", str(good), str(bad), "--targets", "d_um",
                 "--candidates", "s1_degC,s3_degC", "--out", str(tmp_path / "fit")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "bad.csv" in err[0] and "s3_degC" in err[0]


def test_anchor_is_the_line_through_the_first_readings_and_averages_their_noise():
    """A line is its own anchor; the anchor's weights on m equally spaced readings have the
    squared sum 2 (2m - 1) / (m (m + 1)) (the variance of a fitted line's intercept), 0.345 for m = 10."""
    t = 60.0 * np.arange(30)
    assert anchor_value(t, 3.0 + 0.01 * t, 540.0) == pytest.approx(3.0, abs=1e-12)
    weights = np.array([anchor_value(t, np.eye(30)[k], 540.0) for k in range(30)])  # linear in the readings
    assert np.count_nonzero(weights) == 10
    assert weights @ weights == pytest.approx(2 * 19 / 110, rel=1e-12)
    assert anchor_value(t, t, 0.0) == 0.0  # no window: the first reading


def test_smoothed_readings_are_read_alike_by_fit_predict_and_the_stepper():
    """A model fitted with smooth_s reads its temperatures through that lag in predict, and the
    one-sample-at-a-time stepper of a control gives the same values to round-off; the noise rule
    counts the smoothed noise (sqrt((1 - a) / (1 + a)) of a reading's, 0.32 for 300 s at 60 s)."""
    from gatetherm.studies.control.compensator import CompensatorParams
    from gatetherm.studies.control.stepwise import ErrorModelStepper

    params = FitParams(smooth_s=300.0)
    model = fit_error_model(RUNS[0], ["d_um"], SENSORS, ("spindle_rpm",), params)
    assert model.settings["smooth_s"] == 300.0
    a = np.exp(-60.0 / 300.0)
    assert noise_sd(Term("sensor", "s1_degC"), 0.05, 60.0, 300.0) == pytest.approx(0.05 * np.sqrt((1 - a) / (1 + a)))
    assert np.sqrt((1 - a) / (1 + a)) == pytest.approx(0.3157, abs=1e-4)
    batch = predict(model, RUNS[0])["d_um"]
    stepper = ErrorModelStepper(model, "d_um", CompensatorParams(sample_interval_s=60.0))
    cols = RUNS[0].columns
    steps = [stepper._value(t, {k: cols[k][i] for k in cols}) for i, t in enumerate(RUNS[0].time_s)]
    assert np.max(np.abs(np.array(steps) - batch)) < 1e-9
    plain = predict(fit_error_model(RUNS[0], ["d_um"], SENSORS, ("spindle_rpm",)), RUNS[0])["d_um"]
    assert np.max(np.abs(plain - batch)) > 0.01  # the smoothing is in use


def test_anchor_cuts_the_noise_and_the_held_out_error_refuses_a_smoothing_that_costs():
    """Fitted on three noise-free runs, applied to the fourth read with 0.05 K of noise. The run's
    zero taken from one reading offsets the whole run; the anchor on the first 600 s lowers the
    error on noisy readings. Here the displacement follows the readings at once, so a 300-s
    smoothing lags it by more than the noise it removes: the held-out error says so; the grid (the
    API's default) is not tried with three or more runs and keeps the readings unsmoothed."""
    clean = [run(k + 1, s, v, noise_um=0.0) for k, (s, v) in enumerate([(0.0, 4500.0), (3.0, 3000.0), (1.5, 4000.0),
                                                                         (5.0, 2000.0)])]
    truth = np.asarray(clean[3]["d_um"]) - clean[3]["d_um"][0]
    rng = np.random.default_rng(7)
    draws = [clean[3].with_columns(**{s: clean[3][s] + rng.normal(0.0, 0.05, len(clean[3])) for s in SENSORS})
             for _ in range(5)]
    out = {}
    for name, params in (("plain", FitParams(drift=True, noisy_cv=True)),
                         ("anchor", FitParams(drift=True, noisy_cv=True, anchor_s=600.0)),
                         ("smooth", FitParams(drift=True, noisy_cv=True, smooth_s=300.0, anchor_s=600.0)),
                         ("grid", FitParams(drift=True, noisy_cv=True, smooth_grid_s=(300.0,), anchor_s=600.0))):
        model = fit_error_model(clean[:3], ["d_um"], SENSORS, (), params)
        exact = np.mean(np.abs(predict(model, clean[3])["d_um"] - truth))
        noisy = np.mean([np.mean(np.abs(predict(model, d)["d_um"] - truth)) for d in draws])
        out[name] = (exact, noisy, model.settings["smooth_s"], model.target("d_um").held_out_mae_um)
    assert out["plain"][1] == pytest.approx(0.1005, abs=0.002)  # noise-free 0.0024 um
    assert out["anchor"][1] == pytest.approx(0.0944, abs=0.002)  # band: below plain's
    assert out["anchor"][1] < out["plain"][1]
    assert out["smooth"][1] == pytest.approx(0.179, abs=0.004)  # worse: the lag costs more than the noise
    assert out["smooth"][3] == pytest.approx(0.164, abs=0.004) and out["anchor"][3] == pytest.approx(0.099, abs=0.003)
    # the grid is not tried with three or more runs (docs/errormodel.md, "Several runs"): as anchor
    assert out["grid"][2] == 0.0 and out["grid"][:2] == out["anchor"][:2]
    assert "smooth_held_out_um" not in model.settings  # the grid's model, the loop's last
