"""Compensation says how sure it is (issue qactl, a new user's gantry): on the lathe headstock of
tests/data/headstock, not the paper frame.

* a ram whose two thermocouples read alike (a second probe 14 mm from TH as theta_B): the K_i, K_C
  fit gives the difference no weight and the regression's two coefficients are bounded by the
  sensors' noise, each said in one warning line (output and summary.json);
* the rom method's update budget used up before the record ends is warned of, with the time;
* an error model fitted with ``--fit-span 0:0.7`` on the record is checked on its last 30 %
  (its fit ends where that span starts, up to round-off);
* the two residual figures of the printed lines say which is which.
"""
from __future__ import annotations

import json
import logging
import shutil
from pathlib import Path

import numpy as np
import pytest

import gatetherm as gt
from gatetherm.cli import main
from gatetherm.studies.control.methods import Settings, compensate, overlaps
from gatetherm.studies.control.predictive import PredictiveParams
from gatetherm.studies.control.regression import fit_coefficients_noted, fit_regression
from gatetherm.studies.run.timeseries import FORMAT, TimeSeries, write_timeseries

DATA = Path(__file__).resolve().parent / "data" / "headstock"
THETAS = ("theta_A_degC", "theta_B_degC", "theta_C_degC")
COLUMNS = ("time_s", *THETAS, "delta_um")


def cli(*argv) -> int:
    return main([str(a) for a in argv])


@pytest.fixture(scope="module")
def twin(tmp_path_factory):
    """The headstock with theta_B read 14 mm from TH (a symmetric ram: theta_A ~ theta_B), and its own run."""
    d = tmp_path_factory.mktemp("twin")
    for name in ("headstock.geo", "schedule.csv"):
        shutil.copy(DATA / name, d / name)
    text = (DATA / "case.toml").read_text()
    text = text.replace('[probes.TB]', '[probes.TH2]\npoint = [1.14, 0.54]\nquantities = ["T"]\n[probes.TB]')
    text = text.replace('theta_B = "TB"', 'theta_B = "TH2"')
    (d / "case.toml").write_text(text)
    case = gt.load_case(d / "case.toml")
    run = gt.run(case, keep=())
    return d / "case.toml", case, TimeSeries({n: run[n] for n in (*COLUMNS, "front_W", "rear_W")}, {"format": FORMAT})


def test_the_twin_thermocouples_read_alike(twin):
    _, _, ts = twin
    diff = ts["theta_A_degC"] - ts["theta_B_degC"]
    assert np.ptp(diff) == pytest.approx(0.0353, abs=0.005)  # band: < 0.5 K, 10 resolutions of 0.05 K
    assert np.ptp(ts["theta_A_degC"]) == pytest.approx(3.64, abs=0.02)  # band: > 0.5 K, each alone is informative


def test_k_fit_gives_the_difference_no_weight(twin):
    _, _, ts = twin
    ki, kc, warning = fit_coefficients_noted(ts)
    assert ki == 0.0  # no weight: the difference is within 10 resolutions
    assert warning == "K_i, K_C fit: no weight for theta_A - theta_B (spans 0.0353 K): under 10 sensor resolutions (0.5 K)"
    # K_C alone: the least squares of delta on -theta_C, a closed form
    x = -(ts["theta_C_degC"] - ts["theta_C_degC"][0])
    assert kc == pytest.approx(float(x @ ts["delta_um"] / (x @ x)), rel=1e-12)
    _, _, none = fit_coefficients_noted(ts, resolution_K=0.001)  # a finer sensor resolves it
    assert none == "" or "bounded" in none


def test_regression_coefficients_are_bounded_by_the_noise(twin):
    _, _, ts = twin
    with_noise = fit_regression(ts, THETAS)
    exact = fit_regression(ts, THETAS, resolution_K=0.0)  # plain least squares: the absurd pair
    a, b = exact.coefficients[:2]
    assert a == pytest.approx(36.3, abs=0.5) and b == pytest.approx(-38.7, abs=0.5)  # the user's +-2.49e5 in small
    assert "bounded by the sensor noise (0.05 K) (least squares would fit the noise): theta_A_degC" in with_noise.warning
    assert "(least squares alone: 36.32)" in with_noise.warning and exact.warning == ""

    def noise_um(model):  # what 0.05 K of noise on each reading adds to the prediction (the error model's noise_um)
        return 0.05 * float(np.linalg.norm(model.coefficients))

    assert noise_um(exact) == pytest.approx(2.67, abs=0.02)  # band: > 1 um, 10 times delta's resolution
    assert noise_um(with_noise) == pytest.approx(0.13, abs=0.01)  # band: < 0.2 um
    assert all(abs(c) < 3 for c in with_noise.coefficients)

def test_compensate_says_what_was_dropped_or_bounded(twin):
    _, case, ts = twin
    paper = compensate(ts, case, Settings("paper")).summary
    assert paper["k_source"] == "fit" and paper["Ki_um_per_K"] == 0.0
    assert len(paper["warnings"]) == 1 and "no weight for theta_A - theta_B" in paper["warnings"][0]
    assert paper["sensor_noise_um"] == pytest.approx(0.05 * abs(paper["Kc_um_per_K"]), rel=1e-12)  # K_i = 0
    assert paper["Kc_um_per_K"] == pytest.approx(-2.70, abs=0.01)
    mlr = compensate(ts, case, Settings("mlr", force=True)).summary
    assert max(abs(v) for k, v in mlr["regression"].items() if k != "intercept_um") < 5
    assert len(mlr["warnings"]) == 1 and "bounded by the sensor noise" in mlr["warnings"][0]
    coefficients = [v for k, v in mlr["regression"].items() if k != "intercept_um"]
    assert mlr["sensor_noise_um"] == pytest.approx(0.05 * np.linalg.norm(coefficients), rel=1e-12)


def test_cli_prints_the_warning_and_which_residual_is_which(twin, tmp_path, capsys):
    path, _, _ = twin
    assert cli("compensate", "--case", path, "--method", "mlr", "--no-actuator", "--force",
               "--out", tmp_path / "mlr") == 0
    lines = capsys.readouterr().out.splitlines()
    summary = json.loads((tmp_path / "mlr" / "summary.json").read_text())
    assert [ln for ln in lines if ln.startswith("warning: regression baseline")] == \
        [f"warning: {summary['warnings'][0]}"]
    assert "residual band" in lines[1] and "over the whole run after 10 min, as applied" in lines[1]
    assert lines[2].startswith("held-out last 30 % (a separate check, not the correction applied above):")
    assert "regression fitted on the first 70 % of the model's run" in lines[2]


def test_rom_budget_used_up_is_warned_with_its_time(twin, caplog):
    """300 W in the bed the reduced model does not know of: forecast errors re-trigger updates, and a
    budget of 20 runs out at 4.85 h of the 8-h record (the user's 60 ran out at 4.8 h of 6 h)."""
    _, case, _ = twin
    run = gt.run(case, effects={"heat_source@bed": 300.0}, keep=())
    ts = TimeSeries({n: run[n] for n in (*COLUMNS, "front_W", "rear_W")}, {"format": FORMAT})
    short = compensate(ts, case, Settings("rom", states=10, control=PredictiveParams(max_updates=20), force=True))
    s = short.summary
    assert s["updates"] == 20
    out = s["budget_exhausted_s"]
    assert out == short.loop.update_t_s[-1] == pytest.approx(17460.0, abs=600)  # band: < 28800 s, the record's end
    [line] = s["warnings"]
    assert line.startswith(f"rom: the update budget of 20 was used up at {out / 3600:.2f} h of the record's 8.00 h")
    assert "give --max-updates" in line
    # the live form (step by step) warns at the same update, one sample before it acts
    from gatetherm.studies.control.compensator import CompensatorParams, controller_grid
    from gatetherm.studies.control.stepwise_rom import RomStepper
    from gatetherm.studies.run.reduce import build_rom

    params = CompensatorParams()
    grid = controller_grid(ts, params, extra=("front_W", "rear_W"))[0]
    stepper = RomStepper(build_rom(case, 10).rom, grid, params, PredictiveParams(max_updates=20))
    with caplog.at_level(logging.WARNING, logger="gatetherm.studies.control.stepwise_rom"):
        for c, t in enumerate(grid.time_s):
            stepper.step(float(t), {k: grid[k][c] for k in grid.names})
    [record] = [r for r in caplog.records if r.name.endswith("stepwise_rom") and "update budget" in r.getMessage()]
    assert record.getMessage().startswith(f"update budget of 20 used up at t = {out - 60:g} s")
    ample = compensate(ts, case, Settings("rom", states=10, control=PredictiveParams(max_updates=200), force=True))
    assert ample.summary["budget_exhausted_s"] is None and ample.summary["warnings"] == []
    assert ample.summary["updates"] < 200

def test_a_fit_ending_at_the_held_out_start_is_not_overlap():
    t = np.arange(0.0, 21600.0 + 1, 120.0)
    start = float(t[0] + (1 - 0.3) * (t[-1] - t[0]))
    assert not overlaps(15120.0, 15119.999999999998, t)  # the user's figures: round-off, no overlap
    assert not overlaps(0.7 * 21600.0, start, t) and not overlaps(start, 0.7 * 21600.0, t)
    assert overlaps(start + 120.0, start, t)  # one sample into the held-out span is overlap
    assert overlaps(start + 2.0, start, t)  # band: tolerance 1.2 s, a hundredth of the sample interval


def test_refit_advice_can_be_followed(twin, tmp_path, capsys):
    _, _, ts = twin
    six = TimeSeries({n: ts[n][ts.time_s <= 21600.0] for n in COLUMNS}, {"format": FORMAT})
    data = tmp_path / "meas.csv"
    write_timeseries(data, six)
    args = ("errormodel", "fit", "--data", data, "--targets", "delta_um", "--candidates", ",".join(THETAS))
    assert cli(*args, "--out", tmp_path / "whole") == 0
    assert cli("compensate", "--model", tmp_path / "whole" / "model.json", "--data", data, "--no-actuator",
               "--out", tmp_path / "c1") == 0
    out = capsys.readouterr().out
    assert "unchecked" in out and "refit it with --fit-span 0:0.7" in out
    assert cli(*args, "--fit-span", "0:0.7", "--out", tmp_path / "part") == 0
    assert cli("compensate", "--model", tmp_path / "part" / "model.json", "--data", data, "--no-actuator",
               "--out", tmp_path / "c2") == 0
    summary = json.loads((tmp_path / "c2" / "summary.json").read_text())
    end = json.loads((tmp_path / "part" / "model.json").read_text())["fit_span"]["end_s"]
    assert end >= summary["benefit"]["start_s"] and end - summary["benefit"]["start_s"] < 1e-6  # the same instant
    assert summary["benefit"]["verdict"] != "unchecked", summary["benefit"]
    assert summary["benefit"]["basis"].startswith("as applied")



