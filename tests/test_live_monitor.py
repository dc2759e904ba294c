"""The never-worse monitor of ``live`` (validation/live/monitor.py), the gradient along an axis
(validation/live/axis.py) against a closed form, and the thin ``live``/``twin`` command lines."""
from __future__ import annotations

import ast
import json
import math
import sys
from pathlib import Path

import numpy as np
import pytest

from gatetherm import InputError
from gatetherm.studies.control.compensator import CompensatorParams
from gatetherm.studies.control.regression import LinearModel
from gatetherm.studies.control.stepwise import PaperStepper, RegressionStepper
from gatetherm.studies.run.timeseries import read_timeseries
from gatetherm.validation.live.axis import Axis, AxisStepper, line
from gatetherm.validation.live.journal import Journal
from gatetherm.validation.live.monitor import Monitor
from gatetherm.validation.live.service import Guards, LiveParams, Service

COLUMNS = ("theta_A_degC", "theta_B_degC", "theta_C_degC", "delta_um")
LOGGED = ("time_s", *COLUMNS, "delta_residual_um", "offset_um", "offset_wanted_um", "delta_forecast_um", "held",
          "limited", "worse")
PARAMS = CompensatorParams(update_interval_s=60.0)  # an update every period
ROOT = Path(__file__).resolve().parents[1]


def sample(k: int, applied: float | None, sign: float = 1.0) -> dict:
    """δ = 2 (θ_A − θ_B) − θ_C exactly (K_i = 2, K_C = 1): 0.18 k µm; the machine's compensated δ is
    δ + sign · the correction applied (sign −1: a map with the offset's sign wrong)."""
    a, c = 20.0 + 0.1 * k, 20.0 + 0.02 * k
    d = 2 * (a - 20.0) - (c - 20.0)
    out = dict(zip(COLUMNS, (a, 20.0, c, d)))
    if applied is not None:
        out["delta_residual_um"] = d + sign * applied
    return out


def service(path, monitor=Monitor(window=5, margin_um=0.1), guards=Guards(max_change_um=0.5)):
    return Service(PaperStepper(2.0, 1.0, PARAMS), Journal(path, LOGGED, {"source": "test"}),
                   LiveParams(guards=guards, monitor=monitor), COLUMNS)


def run(svc, ks, sign=1.0, reported=True):
    return [svc.period(60.0 * k, k, sample(k, svc.written if reported else None, sign)) for k in ks]


@pytest.mark.parametrize("reported", [True, False])
def test_a_right_correction_is_never_judged_worse(tmp_path, reported):
    """The exact model, applied with the right sign: the residual is the forecast's one-period lag
    (0.18 µm at most here) against δ up to 7 µm; no verdict in 40 periods, with the machine's own
    compensated δ or the ideal estimate δ + the offset held."""
    svc = service(tmp_path)
    rows = run(svc, range(40), reported=reported)
    assert svc.watch.worse is None and not any(r["worse"] for r in rows) and svc.counts["worse"] == 0
    assert rows[-1]["offset_um"] == pytest.approx(-0.18 * 40, abs=1e-9)


def test_a_wrong_sign_is_warned_once_flagged_ramped_to_zero_and_kept_across_a_restart(tmp_path, caplog):
    svc = service(tmp_path)
    rows = run(svc, range(12), sign=-1.0)
    flags = [r["worse"] for r in rows]
    # period 4 fills the window of 5: δ 0.72 µm with −0.72 µm applied the wrong way: 1.44 > 0.72 + 0.1 µm
    assert flags == [0, 0, 0, 0, 1, 1, 1, 1, 1, 1, 1, 1]
    w = svc.watch.worse
    assert (w["t_s"], w["compensated_um"], w["uncompensated_um"]) == pytest.approx((240.0, 1.44, 0.72), abs=1e-9)
    # the compensator's own command goes on (logged), the one written ramps to 0 at 0.5 µm per period
    written = [r["offset_um"] for r in rows]
    assert written[:5] == pytest.approx([0.0, -0.36, -0.54, -0.72, -0.22], abs=1e-9)
    assert written[5:] == pytest.approx([0.0] * 7, abs=1e-12)
    assert rows[6]["offset_wanted_um"] == pytest.approx(-0.18 * 7, abs=1e-9)
    events = (tmp_path / "events.log").read_text()
    assert events.count("compensation makes delta worse") == 1
    assert sum("worse" in r.message for r in caplog.records) == 1
    svc.journal.close()
    again = service(tmp_path)  # a restart into the same --out stays fallen back
    row = again.period(720.0, 12, sample(12, again.written, -1.0))
    assert row["worse"] == 1 and row["offset_um"] == 0.0 and again.counts["worse"] == 9
    assert "resumed fallen back" in (tmp_path / "events.log").read_text()
    ts = read_timeseries(tmp_path / "live.csv", required=("time_s",))
    assert list(ts["worse"]) == [0, 0, 0, 0] + [1] * 9


def test_the_other_fallbacks_hold_or_only_warn(tmp_path):
    hold = service(tmp_path / "hold", Monitor(window=5, margin_um=0.1, fallback="hold"))
    rows = run(hold, range(8), sign=-1.0)
    assert [r["offset_um"] for r in rows[4:]] == pytest.approx([-0.72] * 4, abs=1e-9)  # the value at the verdict
    warn = service(tmp_path / "warn", Monitor(window=5, margin_um=0.1, fallback="warn"))
    rows = run(warn, range(8), sign=-1.0)
    assert rows[4]["worse"] == 1 and rows[-1]["offset_um"] == pytest.approx(-0.5 * 7 * 0 - 0.18 * 8, abs=1e-9)


@pytest.mark.parametrize("kwargs, message", [
    ({"window": 1}, "monitor window"), ({"margin_um": -1.0}, "monitor margin"), ({"fallback": "off"}, "monitor fallback"),
])
def test_bad_monitor_settings_are_input_errors(kwargs, message):
    with pytest.raises(InputError, match=message):
        Monitor(**kwargs)


def probe_model(s: float) -> LinearModel:
    """δ at position s (m) along the axis: (0.5 + 2 s) + (1.5 + 4 s) θ_A-rise, µm: linear in s."""
    return LinearModel(("theta_A_degC",), (1.5 + 4.0 * s,), 0.5 + 2.0 * s)


def test_the_gradient_along_an_axis_is_the_closed_form(tmp_path):
    """Three probes at 0, 0.4 and 1.0 m, reference 0.25 m: with θ_A rising 0.1 K per period the
    forecast rise after period k is 0.1 (k + 1) K, so the command is −δ(s) there: offset
    −(0.5 + 2 s0 + (1.5 + 4 s0) 0.1 (k + 1)) µm at s0, gradient −(2 + 4 · 0.1 (k + 1)) µm/m."""
    positions = {"delta_p0_um": 0.0, "delta_p1_um": 0.4, "delta_p2_um": 1.0}
    axis = Axis(positions, reference_m=0.25)
    stepper = AxisStepper({k: RegressionStepper(probe_model(s), PARAMS) for k, s in positions.items()}, axis)
    logged = (*LOGGED[:-1], "worse", "gradient_um_per_m", "reference_m")
    svc = Service(stepper, Journal(tmp_path, logged, {"source": "test"}),
                  LiveParams(guards=Guards(max_change_um=100.0)), ("theta_A_degC",))
    rows = [svc.period(60.0 * k, k, {"theta_A_degC": 20.0 + 0.1 * k}) for k in range(6)]
    s0, rise = 0.25, 0.1 * (np.arange(6) + 1)
    offset = -(0.5 + 2 * s0 + (1.5 + 4 * s0) * rise)
    gradient = -(2.0 + 4.0 * rise)
    got = np.array([[r["offset_um"], r["gradient_um_per_m"], r["reference_m"]] for r in rows[1:]])
    assert np.max(np.abs(got[:, 0] - offset[1:])) < 1e-12 and np.max(np.abs(got[:, 1] - gradient[1:])) < 1e-12
    assert np.all(got[:, 2] == 0.25)
    assert (rows[0]["offset_um"], rows[0]["gradient_um_per_m"]) == (0.0, 0.0)  # no forecast yet: the commands are 0
    ts = read_timeseries(tmp_path / "live.csv", required=("time_s",))
    assert np.allclose(ts["gradient_um_per_m"][1:], gradient[1:], atol=1e-12)
    # a held sample holds the gradient; the state round-trips
    row = svc.period(360.0, 6, {"theta_A_degC": math.nan})
    assert row["held"] == 1 and row["gradient_um_per_m"] == rows[-1]["gradient_um_per_m"]
    state = json.loads((tmp_path / "state.json").read_text())
    assert set(state["stepper"]["probes"]) == set(positions)


def test_the_gradient_change_is_limited_per_period(tmp_path):
    """The closed form above with the gradient's change limited to 1 µm/m per period (the offset's
    limit out of the way): from 0, the gradient written is max(−(2 + 0.4 (k + 1)), −k) µm/m, i.e.
    −1, −2, −3 (limited), then −4.0 and −4.4 as wanted; the offset is the closed form's throughout."""
    positions = {"delta_p0_um": 0.0, "delta_p1_um": 0.4, "delta_p2_um": 1.0}
    axis = Axis(positions, reference_m=0.25)
    stepper = AxisStepper({k: RegressionStepper(probe_model(s), PARAMS) for k, s in positions.items()}, axis)
    logged = (*LOGGED[:-1], "worse", "gradient_um_per_m", "reference_m")
    guards = Guards(max_change_um=100.0, max_gradient_change_um_per_m=1.0)
    assert Guards().max_gradient_change_um_per_m == 5.0  # the documented default
    svc = Service(stepper, Journal(tmp_path, logged, {"source": "test"}), LiveParams(guards=guards), ("theta_A_degC",))
    rows = [svc.period(60.0 * k, k, {"theta_A_degC": 20.0 + 0.1 * k}) for k in range(6)]
    k = np.arange(1, 6)
    wanted = -(2.0 + 4.0 * 0.1 * (k + 1))
    written = np.maximum(wanted, -1.0 * k)
    got = np.array([r["gradient_um_per_m"] for r in rows[1:]])
    assert np.max(np.abs(got - written)) < 1e-12 and list(got[:3]) == [-1.0, -2.0, -3.0]
    assert [r["limited"] for r in rows] == [0, 1, 1, 1, 0, 0]
    offset = -(0.5 + 2 * 0.25 + (1.5 + 4 * 0.25) * 0.1 * (k + 1))
    assert np.max(np.abs(np.array([r["offset_um"] for r in rows[1:]]) - offset)) < 1e-12
    events = (tmp_path / "events.log").read_text()
    assert "gradient -2.800 -> -1.000 um/m" in events and events.count("gradient") == 3
    with pytest.raises(InputError, match="must be > 0"):
        from gatetherm.validation.live.service import check

        check(LiveParams(guards=Guards(max_gradient_change_um_per_m=0.0)))


def test_the_line_and_the_axis_checks():
    assert line([0.0, 2.0], [1.0, 5.0], 1.0) == pytest.approx((3.0, 2.0), abs=1e-12)
    assert all(math.isnan(v) for v in line([0.0, 1.0], [1.0, math.nan], 0.0))
    assert Axis({"a": 0.3, "b": 0.1}).s0 == 0.1
    for positions, message in [({"a": 0.0}, "1 probe position"), ({"a": 0.2, "b": 0.2}, "all at one position")]:
        with pytest.raises(InputError, match=message):
            Axis(positions)


def test_axis_needs_a_model_and_bad_axis_text_is_one_line(capsys, tmp_path, monkeypatch):
    from gatetherm import cli

    monkeypatch.chdir(tmp_path)
    for argv, message in [(("--case", "c.toml", "--axis", "delta_um=0", "--axis", "d2=1"), "--axis: needs a fitted"),
                          (("--model", "m.json", "--axis", "delta_um"), "--axis delta_um: is not TARGET=S")]:
        code = cli.main(["live", "--endpoint", "opc.tcp://127.0.0.1:4840", "--out", "D", *argv])
        err = capsys.readouterr().err
        assert code == 2 and err.count("\n") == 1 and message in err, err


@pytest.mark.parametrize("name", ["live", "twin"])
def test_the_live_and_twin_command_lines_are_thin(name):
    """They import only gatetherm.api, gatetherm.cli.* and the standard library (issue 52)."""
    tree = ast.parse((ROOT / "core" / "cli" / f"{name}.py").read_text(encoding="utf-8"))
    found = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            found |= {a.name for a in node.names}
        elif isinstance(node, ast.ImportFrom) and node.level == 0:
            found.add(node.module)
    outside = {m for m in found if not (m == "gatetherm.api" or m.startswith("gatetherm.cli")
                                        or m.split(".")[0] in sys.stdlib_module_names or m == "__future__")}
    assert found and not outside, outside
