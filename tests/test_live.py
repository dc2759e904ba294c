"""``gatetherm twin`` and ``gatetherm live`` over real OPC UA on loopback (free ports, each process
bounded in time): the closed loop on the C-frame, the service's corrections against the step-wise
compensator fed the same logged samples, and the faults (a second live on one --out, a sensor NaN
for 2 min, live killed with kill -9 and restarted, the twin killed and restarted)."""
from __future__ import annotations

import json
import os
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

import gatetherm as gt
from gatetherm.studies.run.timeseries import read_timeseries

CASE = Path(__file__).resolve().parents[1] / "validation" / "examples" / "c_frame" / "case.toml"
LIMIT_S = 600.0
"""Wall-clock bound of any one process or wait (a hang fails the test, never a margin)."""


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def gatetherm(*args, out=None) -> subprocess.Popen:
    return subprocess.Popen([sys.executable, "-m", "gatetherm.cli", *map(str, args)], stdout=out or subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True)


def twin(port, *args):
    return gatetherm("twin", CASE, "--endpoint", f"opc.tcp://127.0.0.1:{port}", "--wait", *args)


def live(port, out, *args):
    return gatetherm("live", "--case", CASE, "--method", "rom", "--endpoint", f"opc.tcp://127.0.0.1:{port}",
                     "--out", out, "--quiet", *args)


def finish(p: subprocess.Popen) -> tuple[int, str, str]:
    o, e = p.communicate(timeout=LIMIT_S)
    return p.returncode, o, e


def wait_for(predicate, what: str):
    end = time.monotonic() + LIMIT_S
    while not predicate():
        assert time.monotonic() < end, f"timed out waiting for {what}"
        time.sleep(0.1)


def logged_until(out: Path, t: float):
    def done():
        try:
            rows = (out / "live.csv").read_text().splitlines()
            return float(rows[-1].split(",")[0]) >= t
        except (OSError, ValueError, IndexError):
            return False
    return done


def stepped_offline(ts, states):
    """The rom stepper on the case's schedule fed the rows of live.csv (held rows skipped)."""
    from gatetherm.studies.control.compensator import CompensatorParams
    from gatetherm.studies.control.predictive import PredictiveParams
    from gatetherm.studies.control.stepwise_rom import RomStepper
    from gatetherm.studies.run.reduce import build_rom
    from gatetherm.studies.run.timeseries import TimeSeries

    case = gt.load_case(CASE)
    t = 60.0 * np.arange(361)
    rows = [dict(case.schedule.drive(x)) for x in t]
    plan = TimeSeries({"time_s": t, **{k: np.array([r[k] for r in rows]) for k in rows[0]}})
    s = RomStepper(build_rom(case, states).rom, plan, CompensatorParams(), PredictiveParams())
    out = []
    for k, tk in enumerate(ts.time_s):
        sample = {c: ts[c][k] for c in s.columns}
        out.append((s.skip(tk) if ts["held"][k] else s.step(tk, sample)).offset_um)
    return np.array(out)


def test_twin_and_live_close_the_loop_and_a_second_live_refuses(tmp_path):
    """30 min of machine time at 600x: every period logged, the service's commands those of the
    step-wise compensator on the same samples, the twin's compensated δ within ±3 µm; a second live on
    the same --out refuses in one line."""
    port, out = free_port(), tmp_path / "out"
    a = live(port, out, "--until", 1800, "--states", 10)
    wait_for(lambda: (out / "live.lock").exists() and (out / "live.lock").read_text().strip(), "the lock")
    b = live(port, out, "--until", 1800, "--states", 10)
    code, _, err = finish(b)
    assert code == 2 and err.count("\n") == 1 and "another gatetherm live" in err, err
    tw = twin(port, "--speed", 600, "--until", 1800, "--states", 10)
    code, stdout, err = finish(a)
    assert code == 0, err
    assert finish(tw)[0] == 0
    summary = json.loads((out / "summary.json").read_text())
    assert summary["periods"] == 31 and summary["missed"] == 0 and summary["held"] == 0
    assert summary["monitor"] == "not worse" and summary["worse"] == 0  # the right sign is never fallen back
    assert summary["compensated_band_um"] == pytest.approx(1.1, abs=0.6)  # band: ±3 µm
    ts = read_timeseries(out / "live.csv", required=("time_s",))
    assert np.array_equal(ts.time_s, 60.0 * np.arange(31))
    offline = stepped_offline(ts, 10)
    assert np.max(np.abs(offline - ts["offset_wanted_um"])) < 1e-9
    # the twin applied each written correction from the next sample on
    assert np.max(np.abs(ts["delta_residual_um"][1:] - ts["delta_um"][1:] - ts["offset_um"][:-1])) < 0.2  # δ noise


@pytest.mark.slow
def test_closed_loop_six_hours_at_120x_matches_offline_compensation(tmp_path):
    """The issue's acceptance: twin --speed 120 --until 21600 and live --method rom --period 60."""
    port, out = free_port(), tmp_path / "out"
    a = live(port, out, "--until", 21600)
    tw = twin(port, "--speed", 120, "--until", 21600)
    code, _, err = finish(a)
    assert code == 0, err
    assert finish(tw)[0] == 0
    summary = json.loads((out / "summary.json").read_text())
    assert summary["periods"] == 361 and summary["missed"] == 0 and summary["monitor"] == "not worse"
    assert summary["compensated_band_um"] < 3.0
    ts = read_timeseries(out / "live.csv", required=("time_s",))
    comp = gt.compensate(ts, gt.load_case(CASE), "rom", actuator=None)  # = compensate --data live.csv --no-actuator
    residual = ts["delta_um"][1:] + ts["offset_um"][:-1]
    assert np.max(np.abs(comp.loop.delta_comp_um[1:] - residual)) < 0.1


@pytest.mark.slow
def test_faults_nan_kill_9_and_twin_restart(tmp_path):
    """A sensor NaN for 2 min (held, logged); live killed with kill -9 and restarted into the same --out
    (resumes, log intact, no duplicated period, the missed ones counted); the twin killed and restarted
    (live reconnects, the correction never jumps by more than the limit)."""
    port, out, until = free_port(), tmp_path / "out", 14400
    a = live(port, out, "--until", until)
    tw = twin(port, "--speed", 300, "--until", until, "--fault", "theta_A_degC:1200:1320")
    wait_for(logged_until(out, 1800), "t = 1800 s")
    os.kill(a.pid, signal.SIGKILL)
    a.wait(timeout=LIMIT_S)
    killed = float((out / "live.csv").read_text().splitlines()[-1].split(",")[0])
    time.sleep(2.0)  # ~600 s of machine time without the service (more while it starts again)
    a = live(port, out, "--until", until)
    wait_for(lambda: json.loads((out / "state.json").read_text())["counts"]["restarts"] == 1
             and logged_until(out, killed + 600)(), "the restarted service's rows")
    tw.kill()
    tw.wait(timeout=LIMIT_S)
    last = float((out / "live.csv").read_text().splitlines()[-1].split(",")[0])
    time.sleep(2.0)
    tw = twin(port, "--speed", 300, "--until", until, "--start", last + 600)
    code, _, err = finish(a)
    assert code == 0, err
    finish(tw)
    summary = json.loads((out / "summary.json").read_text())
    ts = read_timeseries(out / "live.csv", required=("time_s",))
    steps = np.diff(ts.time_s) / 60.0
    assert np.all(steps >= 1) and np.allclose(steps, np.round(steps))  # no duplicated period
    assert summary["missed"] == int(np.sum(np.round(steps) - 1)) > 0 and summary["restarts"] == 1
    assert summary["reconnects"] >= 1
    nan = (ts.time_s >= 1200) & (ts.time_s <= 1320)
    assert nan.sum() == 3 and np.all(ts["held"][nan] == 1) and np.isnan(ts["theta_A_degC"][nan]).all()
    assert np.all(ts["held"][~nan] == 0)
    events = (out / "events.log").read_text()
    assert "theta_A_degC missing" in events and "connection lost" in events and "reconnected" in events
    assert np.max(np.abs(np.diff(ts["offset_um"]))) <= 5.0 + 1e-9  # the change limit per period


@pytest.mark.slow
def test_a_wrong_sign_on_the_twin_is_caught_by_the_never_worse_monitor(tmp_path):
    """``gt.live`` through the library against a twin, its map scaling the offset by −1 (a control
    taking the offset with the other sign) and reading the twin's compensated δ: the monitor
    (a window of 10 periods) judges the compensation worse once, flags every later row and ramps
    the correction to zero, after which the twin's compensated δ is its uncompensated δ."""
    port, out, path = free_port(), tmp_path / "out", tmp_path / "map.toml"
    path.write_text('[read]\ndelta_residual_um = "nsu=urn:gatetherm:machine;s=delta_residual_um"\n'
                    '[scale]\noffset_um = -1.0\n')
    tw = twin(port, "--speed", 600, "--until", 1800, "--states", 10)
    try:
        res = gt.live(gt.load_case(CASE), "rom", endpoint=f"opc.tcp://127.0.0.1:{port}", out=out, map=path,
                      until=1800, states=10, monitor={"window": 10})
    finally:
        assert finish(tw)[0] == 0
    assert res["periods"] == 31 and res["monitor"] == "worse"
    ts = read_timeseries(out / "live.csv", required=("time_s",))
    first = int(np.argmax(ts["worse"] == 1))
    assert first >= 9 and np.all(ts["worse"][first:] == 1) and np.all(ts["worse"][:first] == 0)
    verdict = res["worse_verdict"]
    assert verdict["compensated_um"] > verdict["uncompensated_um"] + 1.0
    zero = np.flatnonzero(ts["offset_um"] == 0.0)
    assert zero[-1] == len(ts.time_s) - 1 and ts["offset_um"][-1] == 0.0
    back = zero[zero > first][1:]  # the twin applies a correction from the next sample on
    assert np.max(np.abs(ts["delta_residual_um"][back] - ts["delta_um"][back])) < 0.2  # δ noise
    assert (out / "events.log").read_text().count("compensation makes delta worse") == 1
    print(f"verdict at t = {verdict['t_s']:g} s: {verdict['compensated_um']:.2f} um > "
          f"{verdict['uncompensated_um']:.2f} um; worse from row {first}, zero from row {zero[zero > first][0]}")


@pytest.mark.slow
def test_an_axis_model_writes_the_gradient_and_reference_to_the_twins_nodes(tmp_path):
    """A two-probe error model along an axis (δ(s) = 0.5 + 2 s + (1.5 + 4 s) θ_A-rise, µm, probes at
    0 and 1 m), stepped by ``gt.live`` against a twin: every logged row has the closed form's
    gradient for its offset (gradient = −(2 + 4 r) with offset = −(0.5 + 1.5 r)), and the twin's
    ``gradient_um_per_m`` and ``reference_m`` nodes hold the last values logged."""
    import asyncio
    import threading

    from gatetherm.studies.errormodel.model import ErrorModel, TargetModel
    from gatetherm.studies.errormodel.terms import Term
    from gatetherm.validation.live.service import Guards

    def probe(name, s):
        return TargetModel(name, "static", (Term("sensor", "theta_A_degC"),), (1.5 + 4.0 * s,), 0.5 + 2.0 * s)

    model = ErrorModel((probe("delta_p0_um", 0.0), probe("delta_p1_um", 1.0)), {"theta_A_degC": 20.0},
                       {"start_s": 0.0, "end_s": 1.0, "samples": 2})
    port, out, seen, done = free_port(), tmp_path / "out", {}, threading.Event()

    def watch():  # a second client on the twin: the values of the written nodes as they change
        from asyncua import Client

        async def run():
            end = time.monotonic() + LIMIT_S
            while not done.is_set() and time.monotonic() < end:
                try:
                    async with Client(f"opc.tcp://127.0.0.1:{port}", timeout=5) as c:
                        idx = await c.get_namespace_index("urn:gatetherm:machine")
                        from asyncua import ua
                        nodes = {n: c.get_node(ua.NodeId(n, idx)) for n in ("gradient_um_per_m", "reference_m")}
                        while not done.is_set():
                            seen.update({n: await v.read_value() for n, v in nodes.items()})
                            await asyncio.sleep(0.02)
                except (OSError, asyncio.TimeoutError, ConnectionError):
                    await asyncio.sleep(0.2)
        asyncio.run(run())

    tw = twin(port, "--speed", 120, "--until", 1200, "--states", 10)
    thread = threading.Thread(target=watch, daemon=True)
    thread.start()
    try:
        res = gt.live(None, endpoint=f"opc.tcp://127.0.0.1:{port}", out=out, model=model,
                      axis={"delta_p0_um": 0.0, "delta_p1_um": 1.0}, until=1200, guards=Guards(max_change_um=100.0))
    finally:
        done.set()
        thread.join(timeout=LIMIT_S)
        assert finish(tw)[0] == 0
    assert res["periods"] == 21 and res["limited"] == 0
    ts = read_timeseries(out / "live.csv", required=("time_s",))
    on = ts["offset_um"] != 0.0  # before the first update both commands are 0
    r = (-ts["offset_um"][on] - 0.5) / 1.5
    assert on.sum() >= 15 and np.all(ts["gradient_um_per_m"][~on] == 0.0)
    assert np.max(np.abs(ts["gradient_um_per_m"][on] - -(2.0 + 4.0 * r))) < 1e-9 and np.all(ts["reference_m"] == 0.0)
    assert np.ptp(ts["gradient_um_per_m"][on]) > 0.05  # it moved with θ_A (0.24 um/m in 20 min)
    assert seen["gradient_um_per_m"] == ts["gradient_um_per_m"][-1] and seen["reference_m"] == 0.0
    print(f"gradient {ts['gradient_um_per_m'][-1]:.3f} um/m at offset {ts['offset_um'][-1]:.3f} um; "
          f"the twin's node {seen['gradient_um_per_m']:.3f}")


@pytest.mark.slow
def test_one_twin_serves_several_machines_each_in_its_namespace(tmp_path):
    """``twin --machines 3``: one process, machine i in ``urn:gatetherm:machine:i``. A service on
    machine 2 through a map file; the test writes offsets 0 and 5 µm to machines 1 and 3: read
    at one machine time, their compensated δ differs by exactly 5 µm (one model, ideal offsets);
    the twin serves 3 × 21 samples and the service logs 21 periods, none missed."""
    import asyncio
    import threading

    from gatetherm.studies.errormodel.model import ErrorModel, TargetModel
    from gatetherm.studies.errormodel.terms import Term

    model = ErrorModel((TargetModel("delta_um", "static", (Term("sensor", "theta_A_degC"),), (1.5,), 0.5),),
                       {"theta_A_degC": 20.0}, {"start_s": 0.0, "end_s": 1.0, "samples": 2})
    port, out, diffs, done = free_port(), tmp_path / "out", [], threading.Event()
    ns = [f"urn:gatetherm:machine:{i}" for i in (1, 2, 3)]
    (tmp_path / "m2.toml").write_text("[read]\n" + "".join(f'{n} = "nsu={ns[1]};s={n}"\n' for n in (
        "time_s", "theta_A_degC", "delta_um", "delta_residual_um")) + f'[write]\noffset_um = "nsu={ns[1]};s=offset_um"\n')

    def others():  # machines 1 and 3: offsets 0 and 5 um written, their compensated delta read at one time
        from asyncua import Client, ua

        async def run():
            end = time.monotonic() + LIMIT_S
            while not done.is_set() and time.monotonic() < end:
                try:
                    async with Client(f"opc.tcp://127.0.0.1:{port}", timeout=5) as c:
                        idx = [await c.get_namespace_index(u) for u in (ns[0], ns[2])]
                        node = {(i, n): c.get_node(ua.NodeId(n, i)) for i in idx
                                for n in ("time_s", "delta_residual_um", "offset_um")}
                        for i, value in zip(idx, (0.0, 5.0)):
                            await node[i, "offset_um"].write_value(ua.DataValue(ua.Variant(value, ua.VariantType.Double)))
                        order = [node[idx[0], "time_s"], node[idx[1], "time_s"], node[idx[0], "delta_residual_um"],
                                 node[idx[1], "delta_residual_um"], node[idx[0], "time_s"], node[idx[1], "time_s"]]
                        while not done.is_set():
                            t1, t3, r1, r3, u1, u3 = await c.read_values(order)
                            if np.isfinite(t1) and t1 == t3 == u1 == u3:
                                diffs.append(r3 - r1)
                            await asyncio.sleep(0.01)
                except (OSError, asyncio.TimeoutError, ConnectionError):
                    await asyncio.sleep(0.2)
        asyncio.run(run())

    tw = twin(port, "--speed", 120, "--until", 1200, "--states", 10, "--machines", 3)
    thread = threading.Thread(target=others, daemon=True)
    thread.start()
    try:
        res = gt.live(None, endpoint=f"opc.tcp://127.0.0.1:{port}", out=out, model=model, map=tmp_path / "m2.toml",
                      until=1200)
    finally:
        done.set()
        thread.join(timeout=LIMIT_S)
        code, stdout, _ = finish(tw)
    assert code == 0 and "served 63 samples of 3 machines, t = 0 .. 1200 s" in stdout, stdout
    assert res["periods"] == 21 and res["missed"] == 0 and res["rows"] == 21
    assert len(diffs) >= 10 and np.max(np.abs(np.array(diffs) - 5.0)) < 1e-9, diffs[:5]
