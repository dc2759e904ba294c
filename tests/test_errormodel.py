"""Thermal-error models (studies/errormodel, issue 23) on synthetic data with a known answer:
the exact lag filter, recovery of sensors, coefficients and time constants, the paper's form,
model.json, gaps, the compensation replay; the CLI's exit codes and one-line messages."""
from __future__ import annotations

import json

import numpy as np
import pytest

from gatetherm import InputError
from gatetherm.cli import main
from gatetherm.studies.control.compensator import CompensatorParams
from gatetherm.studies.errormodel.fit import FitParams, fit_error_model
from gatetherm.studies.errormodel.model import load_model, predict, save_model
from gatetherm.studies.errormodel.replay import replay
from gatetherm.studies.errormodel.terms import GapReport, Term, fill_gaps, lag
from gatetherm.studies.run.timeseries import FORMAT, TimeSeries, write_timeseries

SENSORS = tuple(f"s{i}_degC" for i in range(1, 7))
TAU_S = 600.0


def smooth_walk(rng, n: int, scale: float) -> np.ndarray:
    """A slow random temperature signal, K (a walk smoothed over 2 h of 60-s samples)."""
    w = np.cumsum(rng.normal(0.0, scale, n + 120))
    return np.convolve(w, np.ones(120) / 120, "valid")[:n]


def synthetic(n: int = 1200, step_s: float = 60.0, noise_um: float = 0.05, seed: int = 0) -> TimeSeries:
    """20 h of a machine: speed steps 0/1500/3000/4500/0 rpm and six independent sensor signals;
    ``d_um = 1.5 + 2.0 theta_1 - 0.8 theta_3 + 12 lag_600s[(rpm/4500)^2]`` plus white noise."""
    rng = np.random.default_rng(seed)
    t = step_s * np.arange(n)
    rpm = np.select([t < 2 * 3600, t < 6 * 3600, t < 9 * 3600, t < 12 * 3600, t < 14 * 3600, t < 17 * 3600],
                    [0.0, 1500.0, 0.0, 3000.0, 0.0, 4500.0], 0.0)
    temps = {s: 22.0 + smooth_walk(rng, n, 0.3) for s in SENSORS}
    th = {s: v - v[0] for s, v in temps.items()}
    d = 1.5 + 2.0 * th["s1_degC"] - 0.8 * th["s3_degC"] + 12.0 * lag(t, (rpm / 4500.0) ** 2, TAU_S)
    return TimeSeries({"time_s": t, "spindle_rpm": rpm, **temps, "d_um": d + rng.normal(0.0, noise_um, n)},
                      {"format": FORMAT})


def test_lag_is_exact_for_a_ramp():
    """tau x' = s - x, s = r t, x(0) = 0: x = r (t - tau (1 - exp(-t/tau))), on uniform and uneven samples."""
    tau, r = 300.0, 0.01
    for t in (np.arange(0.0, 3600.0, 15.0), np.cumsum(np.r_[0.0, np.tile([5.0, 40.0, 17.0], 80)])):
        exact = r * (t - tau * (1 - np.exp(-t / tau)))
        assert np.max(np.abs(lag(t, r * t, tau) - exact)) < 1e-12 * r * t[-1]


def test_lag_starts_in_steady_state_and_has_unit_gain():
    t = np.arange(0.0, 36000.0, 60.0)
    x = lag(t, np.full(t.size, 3.0), 900.0)
    assert np.all(x == pytest.approx(3.0, abs=1e-12))


def test_fit_recovers_sensors_coefficients_and_time_constant():
    ts = synthetic()
    model = fit_error_model(ts, ["d_um"], SENSORS, ["spindle_rpm"])
    m = model.target("d_um")
    assert m.form == "dynamic"
    assert set(m.sensors) == {"s1_degC", "s3_degC"}
    got = {t.label.split(",")[0]: (t, b) for t, b in zip(m.terms, m.coefficients)}
    (lagged, b_lag), = [v for k, v in got.items() if k.startswith("lag(")]
    assert lagged.exponent == 2.0 and lagged.scale == 4500.0
    assert lagged.tau_s == pytest.approx(TAU_S, rel=0.02)
    assert lagged.tau_s / TAU_S - 1 == pytest.approx(0.0012, abs=0.001)  # achieved 600.7 s
    assert b_lag == pytest.approx(12.0, abs=0.05)  # achieved 12.005
    assert got["s1_degC"][1] == pytest.approx(2.0, abs=0.002)  # achieved 1.99984
    assert got["s3_degC"][1] == pytest.approx(-0.8, abs=0.002)  # achieved -0.80010
    assert m.intercept_um == pytest.approx(1.5, abs=0.005)  # achieved 1.5010
    assert m.residual["rms_um"] == pytest.approx(0.05, abs=0.005)  # the noise; achieved 0.0497
    assert m.held_out_mae_um == pytest.approx(0.05 * np.sqrt(2 / np.pi), rel=0.1)  # mean |noise|
    assert m.held_out_mae_um == pytest.approx(0.0404, abs=0.002)


def test_static_fit_is_exact_without_noise():
    ts = synthetic(noise_um=0.0)
    d = 0.3 + 1.25 * (ts["s2_degC"] - ts["s2_degC"][0]) - 0.5 * (ts["s5_degC"] - ts["s5_degC"][0])
    model = fit_error_model(ts.with_columns(d_um=d), ["d_um"], SENSORS, params=FitParams(form="static", resolution_K=0.0))  # exact readings
    m = model.target("d_um")
    assert dict(zip(m.sensors, m.coefficients)) == pytest.approx({"s2_degC": 1.25, "s5_degC": -0.5}, abs=1e-9)
    assert m.residual["max_abs_um"] < 1e-9
    assert [s["sensors"] for s in m.selection] == [0, 1, 2, 3, 4]  # the path spends the budget
    assert m.held_out_mae_um < 1e-9  # and the smallest exact model is kept (two sensors, above)


def test_paper_form_finds_its_three_sensors():
    ts = synthetic(noise_um=0.0)
    th = {s: ts[s] - ts[s][0] for s in SENSORS}
    d = 2.0 * (th["s4_degC"] - th["s2_degC"]) - 0.7 * th["s6_degC"]
    m = fit_error_model(ts.with_columns(d_um=d), ["d_um"], SENSORS, params=FitParams(form="paper", resolution_K=0.0)).target("d_um")
    diff, third = m.terms
    assert (diff.column, diff.other, third.column) == ("s4_degC", "s2_degC", "s6_degC")
    assert m.coefficients == pytest.approx((2.0, -0.7), abs=1e-9)
    assert m.intercept_um == 0.0 and m.held_out_mae_um < 1e-9

    flat = {s: ts[s][0] + 0.001 * th[s] / np.ptp(th[s]) for s in SENSORS}  # each spans 1 mK
    with pytest.raises(InputError, match=r"no two of the \d+ temperature columns differ by 0.5 K .*form 'static'"):
        fit_error_model(ts.with_columns(d_um=d, **flat), ["d_um"], SENSORS, params=FitParams(form="paper"))
    with pytest.raises(InputError, match="needs at least 3 temperature columns"):
        fit_error_model(ts.with_columns(d_um=d), ["d_um"], SENSORS[:2], params=FitParams(form="paper"))


def test_a_difference_is_one_term_for_two_sensors():
    ts = synthetic(noise_um=0.0)
    d = 2.0 * ((ts["s4_degC"] - ts["s4_degC"][0]) - (ts["s2_degC"] - ts["s2_degC"][0]))
    m = fit_error_model(ts.with_columns(d_um=d), ["d_um"], SENSORS,
                        params=FitParams(form="static", differences=True, resolution_K=0.0)).target("d_um")
    (term,) = m.terms
    assert (term.kind, {term.column, term.other}) == ("difference", {"s2_degC", "s4_degC"})
    assert abs(m.coefficients[0]) == pytest.approx(2.0, abs=1e-9) and m.sensors == (term.column, term.other)


def test_fit_is_deterministic_and_model_json_round_trips(tmp_path):
    ts = synthetic()
    a = fit_error_model(ts, ["d_um"], SENSORS, ["spindle_rpm"])
    b = fit_error_model(ts, ["d_um"], SENSORS, ["spindle_rpm"])
    save_model(tmp_path / "a.json", a)
    save_model(tmp_path / "b.json", b)
    assert (tmp_path / "a.json").read_text() == (tmp_path / "b.json").read_text()
    back = load_model(tmp_path / "a.json")
    assert np.array_equal(predict(back, ts)["d_um"], predict(a, ts)["d_um"])
    data = json.loads((tmp_path / "a.json").read_text())["targets"]["d_um"]
    assert {t["unit"] for t in data["terms"]} == {"um/K", "um"} and data["held_out_mae_um"] > 0


def test_fit_span_and_prediction_beyond_it():
    """Fitted on the first 15 h only, the model predicts the last 5 h (4500 rpm seen) to the noise."""
    ts = synthetic()
    model = fit_error_model(ts, ["d_um"], SENSORS, ["spindle_rpm"], span=(0.0, 15 * 3600.0))
    assert model.fit_span["samples"] == 901
    late = ts.time_s > 15 * 3600
    mae = np.mean(np.abs(predict(model, ts)["d_um"][late] - ts["d_um"][late]))
    assert mae == pytest.approx(0.0404, abs=0.003)  # mean |noise| 0.040


def test_gaps_are_filled_or_left_unpredicted():
    t = np.arange(0.0, 3000.0, 60.0)
    v = 20 + 0.01 * t
    v[5:7] = np.nan  # 180 s gap: bridged
    v[20:30] = np.nan  # 660 s gap: too long
    filled, long, report = fill_gaps(t, v, 300.0)
    assert filled[5:7] == pytest.approx(20 + 0.01 * t[5:7])
    assert not long[:20].any() and long[20:30].all() and report == GapReport(12, 660.0, 10)
    ts = synthetic(n=200)
    model = fit_error_model(ts, ["d_um"], SENSORS[:2], params=FitParams(form="static"))
    s = model.target("d_um").sensors[0]
    x = np.array(ts[s])
    x[50] = np.nan
    x[100:110] = np.nan
    pred = predict(model, ts.with_columns(**{s: x}))["d_um"]
    assert np.isfinite(pred[50]) and np.isnan(pred[100:110]).all() and np.isfinite(pred[110:]).all()


def test_bad_fit_requests():
    ts = synthetic(n=200)
    with pytest.raises(InputError, match="column nope_degC"):
        fit_error_model(ts, ["d_um"], ["nope_degC"])
    with pytest.raises(InputError, match="valid samples"):
        fit_error_model(ts, ["d_um"], SENSORS, span=(0.0, 600.0))
    with pytest.raises(InputError, match="form"):
        FitParams(form="neural")
    with pytest.raises(InputError, match="kind"):
        Term("pressure", "p")


def test_replay_keeps_only_the_forecast_error():
    """An exact model in the loop with an ideal piezo: at the update instants the compensated
    displacement is the one-sample forecast error, far below the swing."""
    ts = synthetic(noise_um=0.0)
    model = fit_error_model(ts, ["d_um"], SENSORS, ["spindle_rpm"])
    loop = replay(model, ts, "d_um", CompensatorParams())
    at = np.isin(loop.t_s, loop.update_t_s) & (loop.t_s > 600)
    swing = np.ptp(ts["d_um"])
    assert np.max(np.abs(loop.delta_comp_um[at])) < 0.05 * swing
    assert np.max(np.abs(loop.delta_comp_um[at])) / swing == pytest.approx(0.0152, abs=0.003)


def test_replay_with_the_papers_correction():
    """A paper-form model replayed with the on-line R of eqs 30-38: for exact data R_i stays 1 and
    the loop keeps the same forecast error as without the correction."""
    ts = synthetic(noise_um=0.0)
    th = {s: ts[s] - ts[s][0] for s in SENSORS}
    ts = ts.with_columns(d_um=2.0 * (th["s4_degC"] - th["s2_degC"]) - 0.7 * th["s6_degC"])
    model = fit_error_model(ts, ["d_um"], SENSORS, params=FitParams(form="paper", resolution_K=0.0))  # exact
    with_r = replay(model, ts, "d_um", CompensatorParams(), correction=True)
    plain = replay(model, ts, "d_um", CompensatorParams())
    late = with_r.t_s > 600
    assert np.nanmax(np.abs(with_r.prediction.R_i[2:] - 1.0)) < 1e-6
    assert np.max(np.abs(with_r.delta_comp_um[late])) == pytest.approx(np.max(np.abs(plain.delta_comp_um[late])),
                                                                      rel=1e-6)
    static = fit_error_model(ts, ["d_um"], SENSORS, params=FitParams(form="static"))
    with pytest.raises(InputError, match="paper's form"):
        replay(static, ts, "d_um", CompensatorParams(), correction=True)


def cli(*argv) -> int:
    return main([str(a) for a in argv])


def _write(tmp_path, ts, name="run.csv"):
    write_timeseries(tmp_path / name, ts)
    return tmp_path / name


def test_cli_fit_predict_compensate(tmp_path, capsys):
    data = _write(tmp_path, synthetic())
    assert cli("errormodel", "fit", "--data", data, "--targets", "d_um", "--inputs", "spindle_rpm",
        "--fit-span", "0:0.75", "--out", tmp_path / "fit") == 0
    out = capsys.readouterr().out
    assert "d_um: dynamic; sensors s1_degC, s3_degC" in out and "forward path, held-out MAE by sensors" in out
    model = tmp_path / "fit" / "model.json"
    assert f"wrote {model} (fitted on 1 run(s)" in out  # the final file, not the hidden stage's
    assert cli("errormodel", "predict", model, "--data", data, "--out", tmp_path / "pred") == 0
    assert f"wrote {tmp_path / 'pred' / 'prediction.csv'}, prediction.png" in capsys.readouterr().out
    summary = json.loads((tmp_path / "pred" / "summary.json").read_text())
    assert summary["targets"]["d_um"]["mae_um"] == pytest.approx(0.04, abs=0.01)
    assert (tmp_path / "pred" / "prediction.png").stat().st_size > 0
    head = [ln for ln in (tmp_path / "pred" / "prediction.csv").read_text().splitlines() if not ln.startswith("#")][0]
    assert head == "time_s,d_um_pred,d_um_lo,d_um_hi,d_um"
    assert cli("compensate", "--model", model, "--data", data, "--no-actuator",
               "--out", tmp_path / "comp") == 0
    assert json.loads((tmp_path / "comp" / "summary.json").read_text())["method"] == "errormodel"
    ts = synthetic()
    s1 = np.array(ts["s1_degC"])
    s1[100:103] = np.nan
    gappy = _write(tmp_path, ts.with_columns(s1_degC=s1), "gappy.csv")
    assert cli("errormodel", "predict", model, "--data", gappy, "--out", tmp_path / "pred") == 0
    assert "s1_degC: 3 missing samples filled (longest gap 240 s), 0 in gaps over 300 s" in capsys.readouterr().out
    summary = json.loads((tmp_path / "pred" / "summary.json").read_text())
    assert summary["gaps"] == {"s1_degC": {"filled": 3, "longest_s": 240.0, "unpredicted": 0}}


BAD_FILES = {
    "missing column": ("time_s,s1_degC\n0,20\n60,21\n", "--targets: 'd_um' is not a column of"),
    "text in a number": ("time_s,s1_degC,d_um\n0,20,1\n60,warm,2\n", "non-numeric value 'warm'"),
    "time not increasing": ("time_s,s1_degC,d_um\n0,20,1\n60,21,2\n60,22,3\n", "not after the previous"),
    "empty file": ("", "no header row"),
}


@pytest.mark.parametrize("case", sorted(BAD_FILES))
def test_cli_bad_data_files_are_one_line_exit_2(tmp_path, capsys, case):
    text, needle = BAD_FILES[case]
    (tmp_path / "bad.csv").write_text(text)
    got = cli("errormodel", "fit", "--data", tmp_path / "bad.csv", "--targets", "d_um", "--out", tmp_path / "o")
    err = capsys.readouterr().err
    assert got == 2 and err.count("\n") == 1 and needle in err and "Traceback" not in err, err
    assert not (tmp_path / "o").exists()


def test_cli_predict_refuses_a_file_without_a_model_column(tmp_path, capsys):
    ts = synthetic(n=300)
    model = fit_error_model(ts, ["d_um"], SENSORS, params=FitParams(form="static"))
    save_model(tmp_path / "model.json", model)
    used = model.target("d_um").sensors[0]
    data = _write(tmp_path, TimeSeries({k: v for k, v in ts.columns.items() if k != used}, {"format": FORMAT}))
    assert cli("errormodel", "predict", tmp_path / "model.json", "--data", data, "--out", tmp_path / "p") == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and f"column {used}: missing; the model reads it" in err, err


def test_cli_resolution_sets_the_noise_rule(tmp_path, capsys):
    """--resolution-K: the sensors' noise the coefficients are fitted for, printed as the noise it adds."""
    data = _write(tmp_path, synthetic(n=400))
    args = ("errormodel", "fit", "--data", data, "--targets", "d_um", "--form", "static", "--out", tmp_path / "f")
    assert cli(*args, "--resolution-K", "-1") == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "resolution_K: -1.0 is not >= 0" in err, err
    assert cli(*args, "--resolution-K", "0") == 0
    assert "sensor noise 0 um" in capsys.readouterr().out
    assert cli(*args) == 0  # 0.05 K, smoothed over 300 s: 0.05 K x sqrt((1 - a)/(1 + a)) x |K|
    model = load_model(tmp_path / "f" / "model.json")
    m = model.target("d_um")
    a = np.exp(-60.0 / model.settings["smooth_s"]) if model.settings["smooth_s"] else 0.0
    sd = 0.05 * np.sqrt((1 - a) / (1 + a))
    assert m.noise_um == pytest.approx(sd * np.linalg.norm(m.coefficients), rel=1e-9)
    assert {"s1_degC", "s3_degC"} <= set(m.sensors)  # the two in d_um (a static form adds s4 for the missing lag)
    assert model.settings["smooth_s"] == 300.0 and m.noise_um == pytest.approx(0.0324, abs=0.003)  # achieved 0.0324


def test_forward_interval_grows_with_the_horizon():
    """Held-out residuals exactly 1 + h / L (h since the fold's last fitting row, L its length): the
    scores are all 1, so the half-width is 1 um and every block is inside; the interval then grows as
    1 + h / fit_length on a file that continues the fitting run, and from a later file's first sample."""
    from gatetherm.studies.errormodel.trust import calibrate_forward, horizon_factor

    t = np.arange(100.0)
    blocks = [(50, 75), (75, 100)]
    res = [(1.0 + (t[lo:hi] - t[lo - 1]) / (t[lo - 1] - t[0])) * np.where(np.arange(hi - lo) % 2, 1, -1)
           for lo, hi in blocks]
    iv = calibrate_forward(res, blocks, t)
    assert iv["half_width_um"] == pytest.approx(1.0) and iv["coverage"] == 1.0 and iv["samples"] == 25
    assert iv["fit_end_s"] == 99.0 and iv["fit_length_s"] == 99.0
    assert horizon_factor(iv, np.arange(0.0, 199.0)) == pytest.approx(np.r_[np.ones(100), 1 + np.arange(1, 100) / 99])
    assert horizon_factor(iv, np.arange(500.0, 599.0)) == pytest.approx(1 + np.arange(99) / 99)
    assert horizon_factor({}, t) == pytest.approx(np.ones(100))  # a constant interval (leave one run out)


def test_forward_interval_is_a_quantile_over_blocks():
    """The width is the conformal quantile over the held-out blocks, not over their pooled samples:
    the ceil(0.9 (B + 1))-th smallest of the blocks' 90 % quantiles, so one block in ten that misses
    by 5 um sets it (pooled, its samples are the top 10 % and would give 1.4 um)."""
    from gatetherm.studies.errormodel.trust import block_quantile, calibrate_forward

    assert block_quantile(np.arange(1.0, 21.0)) == 19.0  # ceil(0.9 x 21) = 19th of 20
    assert block_quantile([3.0, 1.0, 2.0]) == 3.0  # ceil(0.9 x 4) = 4 > 3 blocks: the largest
    t = np.arange(200.0)
    blocks = [(100 + 10 * k, 110 + 10 * k) for k in range(10)]
    res = [np.full(10, 5.0 if k == 4 else 1.0) * (1 + (t[lo:hi] - t[lo - 1]) / (t[lo - 1] - t[0]))
           for k, (lo, hi) in enumerate(blocks)]
    iv = calibrate_forward(res, blocks, t)
    assert iv["half_width_um"] == pytest.approx(5.0) and iv["blocks"] == 10
    assert np.quantile(np.r_[np.ones(90), np.full(10, 5.0)], 0.9) == pytest.approx(1.4)  # the pooled quantile
    assert iv["coverage"] == pytest.approx(80 / 90)  # blocks 2..10 checked; block 5 (before any 5-um block) misses


def test_choose_latest_picks_on_forward_chaining():
    """choose_latest: held_out_mae_um is the forward-chaining error of the model kept (the model's own
    chain error, recomputed), the interval is calibrated forward and holds the later hours."""
    from gatetherm.studies.errormodel.trust import trust

    ts = synthetic(n=1200)
    fit = ts.slice(slice(0, 900))
    model = fit_error_model(fit, ["d_um"], SENSORS, ("spindle_rpm",),
                            FitParams(resolution_K=0.0, choose_latest=True))
    m = model.target("d_um")
    assert {"s1_degC", "s3_degC"} <= set(m.sensors) and m.form == "dynamic"
    assert m.interval["growth"] == "horizon" and m.interval["fit_length_s"] == pytest.approx(899 * 60.0)
    p = predict(model, ts)["d_um"]
    band = trust(model, ts, {"d_um": p})["d_um"]
    y = np.asarray(ts["d_um"])[900:]
    inside = np.mean((y >= band["lower"][900:]) & (y <= band["upper"][900:]))
    assert inside == pytest.approx(1.0, abs=0.005)  # band: >= 0.85 (noise only: the model is exact; wider later)
    assert m.held_out_mae_um == pytest.approx(0.0418, abs=0.003)  # white noise of 0.05 um: E|e| = 0.0399
    assert m.interval["coverage"] == pytest.approx(0.929, abs=0.01)  # band: 0.85-0.95 (forward, in the fitting span)
    # white noise of 0.05 um: 1.645 x 0.05 = 0.082 um; the largest of the 16 blocks' 90 % quantiles is a little wider
    assert m.interval["half_width_um"] == pytest.approx(0.0907, abs=0.004) and m.interval["blocks"] == 16


def test_latest_score_mean_is_half_chain_half_blocked():
    """latest_score="mean" (not the default; docs/errormodel.md, "Issue 56"): the kept model's
    held_out_mae_um is the mean of its forward-chaining and blocked errors, recomputed here."""
    from gatetherm.studies.errormodel import select
    from gatetherm.studies.errormodel.model import _term_values

    fit = synthetic(n=900)
    params = FitParams(resolution_K=0.0, choose_latest=True, latest_score="mean")
    model = fit_error_model(fit, ["d_um"], SENSORS, ("spindle_rpm",), params)
    values, _, _ = _term_values(model, fit)  # the kept terms' columns on the fitting rows
    X = np.column_stack([np.ones(len(fit))] + list(values["d_um"]))
    y = np.asarray(fit["d_um"])
    errs = [select.CrossValidation(X, y, params.folds, chain=c).error(np.eye(X.shape[1])) for c in (True, False)]
    assert model.target("d_um").held_out_mae_um == pytest.approx(np.mean(errs), rel=1e-6)
    with pytest.raises(InputError, match="latest_score"):
        FitParams(latest_score="blocked")
