"""The live service's guards and journal without a network (validation/live/service.py, journal.py,
nodes.py): a NaN or a jump holds the correction, the change and the size are limited, missed
periods are stepped and counted, a restart cuts a half-written row and resumes bit-identically, the
map file's bad keys are one line."""
from __future__ import annotations

import json
import math

import numpy as np
import pytest

from gatetherm import InputError
from gatetherm.studies.control.compensator import CompensatorParams
from gatetherm.studies.control.stepwise import PaperStepper
from gatetherm.studies.run.timeseries import read_timeseries
from gatetherm.validation.live.journal import Journal, lock
from gatetherm.validation.live.nodes import default_node, read_map
from gatetherm.validation.live.service import Guards, LiveParams, Service

COLUMNS = ("theta_A_degC", "theta_B_degC", "theta_C_degC", "delta_um")
LOGGED = ("time_s", *COLUMNS, "offset_um", "offset_wanted_um", "delta_forecast_um", "held", "limited")
PARAMS = CompensatorParams(update_interval_s=60.0)  # an update every period


def sample(k: int) -> dict:
    """δ = 2 (θ_A − θ_B) − θ_C exactly (K_i = 2, K_C = 1), θ_A rising 0.1 K per period."""
    a, c = 20.0 + 0.1 * k, 20.0 + 0.02 * k
    return dict(zip(COLUMNS, (a, 20.0, c, 2 * (a - 20.0) - (c - 20.0))))


def service(tmp_path, guards=Guards()):
    return Service(PaperStepper(2.0, 1.0, PARAMS), Journal(tmp_path, LOGGED, {"source": "test"}),
                   LiveParams(guards=guards), COLUMNS)


def test_nan_and_jump_hold_the_correction_and_limits_clip_it(tmp_path):
    svc = service(tmp_path, Guards(max_change_um=0.25, max_offset_um=0.5))
    rows = [svc.period(60.0 * k, k, sample(k)) for k in range(4)]
    # exact model: the forecast is δ(k+1) = 0.18 (k+1) µm, the command its negative, limited to 0.25 µm per period
    assert [r["offset_wanted_um"] for r in rows] == pytest.approx([0.0, -0.36, -0.54, -0.72], abs=1e-12)
    assert [r["offset_um"] for r in rows] == pytest.approx([0.0, -0.25, -0.5, -0.5], abs=1e-12)  # ±0.5 µm
    bad = {**sample(4), "theta_B_degC": math.nan}
    assert svc.period(240.0, 4, bad)["held"] == 1
    jump = {**sample(5), "delta_um": sample(5)["delta_um"] + 25.0}  # > 10 µm per period
    assert svc.period(300.0, 5, jump)["held"] == 1
    row = svc.period(480.0, 8, sample(8))  # periods 6 and 7 without a sample
    assert row["held"] == 0 and svc.counts == {"periods": 7, "missed": 2, "held": 2, "limited": 4, "reconnects": 0,
                                               "restarts": 0, "worse": 0}
    events = (tmp_path / "events.log").read_text()
    assert "theta_B_degC missing" in events and "delta_um jumped +25" in events and "2 period(s)" in events
    ts = read_timeseries(tmp_path / "live.csv", required=("time_s",))
    assert np.array_equal(ts.time_s, [0, 60, 120, 180, 240, 300, 480]) and np.isnan(ts["theta_B_degC"][4])


def test_restart_cuts_a_half_written_row_and_resumes_identically(tmp_path):
    one, two = tmp_path / "one", tmp_path / "two"
    svc = service(one)
    ref = [svc.period(60.0 * k, k, sample(k))["offset_um"] for k in range(10)]
    svc = service(two)
    for k in range(5):
        svc.period(60.0 * k, k, sample(k))
    svc.journal.close()
    with open(two / "live.csv", "a") as f:  # killed while writing the next row
        f.write("300,20.5,20,20.1")
    again = service(two)
    assert again.counts["restarts"] == 1 and again.next == 5
    got = [again.period(60.0 * k, k, sample(k))["offset_um"] for k in range(5, 10)]
    assert got == ref[5:]  # bit-identical
    ts = read_timeseries(two / "live.csv", required=("time_s",))
    assert np.array_equal(ts.time_s, 60.0 * np.arange(10))
    state = json.loads((two / "state.json").read_text())
    assert state["next"] == 10 and state["stepper"]["count"] == 10


def test_a_second_lock_refuses_in_one_line(tmp_path):
    fd = lock(tmp_path)
    with pytest.raises(InputError, match="another gatetherm live") as err:
        lock(tmp_path)
    assert "\n" not in str(err.value)
    import os

    os.close(fd)
    os.close(lock(tmp_path))  # free again


@pytest.mark.parametrize("text, message", [
    ('[read]\ntheta_A_degC = 3\n', r"\[read\] theta_A_degC: is not a node id"),
    ('[write]\nspeed = "ns=2;s=x"\n', r"\[write\] speed: is not a correction variable"),
    ('[scale]\noffset_um = 0\n', r"\[scale\] offset_um: 0 is not a non-zero number"),
    ('[nodes]\n', r"\[nodes\]: unknown table"),
])
def test_bad_map_files_are_one_line(tmp_path, text, message):
    path = tmp_path / "map.toml"
    path.write_text(text)
    with pytest.raises(InputError, match=message):
        read_map(path, COLUMNS)


def test_a_map_overrides_the_default_layout(tmp_path):
    path = tmp_path / "map.toml"
    path.write_text('[read]\ndelta_um = "ns=3;s=DB1.delta"\n[write]\noffset_um = "ns=3;s=DB1.off"\n'
                    '[scale]\noffset_um = 0.001\n')
    m = read_map(path, COLUMNS)
    assert m.read["delta_um"] == "ns=3;s=DB1.delta" and m.read["theta_A_degC"] == default_node("theta_A_degC")
    assert m.write == {"offset_um": "ns=3;s=DB1.off"} and m.factor("offset_um") == 0.001 and m.factor("x") == 1.0


def test_a_lost_connection_holds_then_ramps_to_zero_at_the_stated_rate(tmp_path):
    """No server on the port: the correction saved in the state (2 µm) holds for hold_s, then falls at
    ramp_um_per_s; the service is stopped once it reaches 0."""
    import asyncio
    import socket
    import time

    from gatetherm.validation.live import service as sv
    from gatetherm.validation.live.nodes import default_map

    svc = service(tmp_path)
    svc.period(0.0, 0, sample(0))
    state = {**svc.journal.state, "offset_um": 2.0}
    svc.journal.save(state)
    svc.journal.close()
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]  # closed again: nothing listens
    g = Guards(hold_s=0.5, ramp_um_per_s=1.0, retry_first_s=0.1, retry_max_s=0.2, timeout_s=1.0)
    journal = Journal(tmp_path, LOGGED, {"source": "test"})
    stepper = PaperStepper(2.0, 1.0, PARAMS)

    async def run():
        stop = asyncio.Event()

        async def watch():
            while "ramped to 0.000 um" not in (tmp_path / "events.log").read_text():
                await asyncio.sleep(0.05)
            stop.set()

        task = asyncio.create_task(watch())
        counts = await asyncio.wait_for(sv.serve(stepper, journal, f"opc.tcp://127.0.0.1:{port}",
                                                 default_map(COLUMNS), LiveParams(guards=g), COLUMNS, None, stop),
                                        timeout=600)
        await task
        return counts

    t0 = time.monotonic()
    run_counts = asyncio.run(run())
    took = time.monotonic() - t0
    journal.close()
    events = (tmp_path / "events.log").read_text()
    ramps = [float(line.split("ramped to ")[1].split()[0]) for line in events.splitlines() if "ramped to" in line]
    assert "connection lost" in events and ramps[-1] == 0.0 and all(np.diff(ramps) < 0)
    assert took >= 0.5 + 2.0  # held for hold_s, then 2 µm at 1 µm/s: the rate bounds it from below
    assert run_counts["reconnects"] == 0


@pytest.mark.parametrize("argv, message", [
    (("twin", "case.toml", "--endpoint", "opc.tcp://127.0.0.1:4840", "--speed", "0"), "--speed: must be > 0"),
    (("twin", "case.toml", "--endpoint", "http://127.0.0.1:4840"), "--endpoint: 'http://127.0.0.1:4840' is not"),
    (("live", "--case", "case.toml", "--endpoint", "localhost:4840", "--out", "D"), "--endpoint: 'localhost:4840'"),
    (("live", "--endpoint", "opc.tcp://127.0.0.1:4840", "--out", "D"), "--case/--model: give the machine's case"),
    (("twin", "--fault", "theta_A_degC:5", "c.toml", "--endpoint", "opc.tcp://h:1"), "--fault theta_A_degC:5: is not"),
])
def test_bad_command_lines_are_one_line_exit_2(argv, message, capsys, monkeypatch, tmp_path):
    from gatetherm import cli

    monkeypatch.chdir(tmp_path)
    code = cli.main(list(argv))
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1 and message in err, err


def test_the_twins_actuator_drive_equals_the_batch_piezo_drive():
    """Each new offset written to the twin is one more command of the sequence: the stroke achieved
    equals apply_commands on the whole sequence (the paper's piezo driven directly, with hysteresis)."""
    from gatetherm.studies.control.actuator import ActuatorParams, apply_commands
    from gatetherm.validation.live.twin import Drive

    from dataclasses import replace

    piezo = replace(ActuatorParams(), strategy="direct")  # stepping straight to each voltage: hysteresis shows
    commands = [-3.0, -7.5, -7.5, -12.0, -4.0, 1.0]
    drive, ideal = Drive(piezo), Drive(None)
    got = [drive(c) for c in commands]
    distinct = [-3.0, -7.5, -12.0, -4.0, 1.0]
    want = apply_commands(piezo, distinct)[1]
    assert np.max(np.abs(np.array(got)[[0, 1, 3, 4, 5]] - want)) < 1e-12 and got[2] == got[1]
    assert np.max(np.abs(want - distinct)) > 0.05  # not ideal
    assert [ideal(c) for c in commands] == commands
