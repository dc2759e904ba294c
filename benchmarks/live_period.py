"""What one period of ``gatetherm live`` costs, to judge how many machines one computer serves at a
1-s period: the OPC UA round trip (one read of the sample, one write of the offset) against a twin
on loopback, and the service's own work (rom step, the row flushed and synced, the state saved).

    python benchmarks/live_period.py [--periods 200] [--states 30]

Serves the C-frame's twin in this process (a thread, its clock nearly stopped), runs the service's period
``periods`` times and prints the medians of the wall time (ms): the sum is what one ``live`` process
spends per period, most of the service's part waiting for the two syncs to disk (the row, the
state). Handled one after another, 1000 / sum machines fit in a 1-s period; separate processes
(one ``live`` per machine) overlap their syncs. The twins' own cost is not counted. Writes
benchmarks/results/live_period.json. An estimate from the parts, not a run of 100 processes.
"""
from __future__ import annotations

import argparse
import asyncio
import json
import tempfile
import threading
import time
from pathlib import Path

import numpy as np

import gatetherm as gt
from gatetherm.studies.control.compensator import CompensatorParams
from gatetherm.studies.control.predictive import PredictiveParams
from gatetherm.studies.control.stepwise_rom import RomStepper
from gatetherm.studies.run.timeseries import TimeSeries
from gatetherm.validation.live.journal import Journal
from gatetherm.validation.live.nodes import default_map
from gatetherm.validation.live.link import _connect, _sample, _write
from gatetherm.validation.live.service import LiveParams, Service
from gatetherm.validation.live.twin import TwinParams, serve

CASE = Path(__file__).resolve().parents[1] / "validation" / "examples" / "c_frame" / "case.toml"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--periods", type=int, default=200)
    ap.add_argument("--states", type=int, default=30)
    ap.add_argument("--port", type=int, default=48999)
    args = ap.parse_args()
    case = gt.load_case(CASE)
    rom = gt.reduce(case, args.states).rom
    url = f"opc.tcp://127.0.0.1:{args.port}"
    published = ("theta_A_degC", "theta_B_degC", "theta_C_degC", "delta_um")
    stop = threading.Event()
    twin = threading.Thread(target=lambda: asyncio.run(serve(rom, case.schedule, url, TwinParams(speed=0.01),
                                                             published, stop.is_set)), daemon=True)
    twin.start()
    t = 60.0 * np.arange(361)
    rows = [dict(case.schedule.drive(x)) for x in t]
    plan = TimeSeries({"time_s": t, **{k: np.array([r[k] for r in rows]) for k in rows[0]}})
    stepper = RomStepper(rom, plan, CompensatorParams(), PredictiveParams())
    inputs = tuple(sorted(case.inputs()))
    nodes = default_map((*inputs, *stepper.columns, "delta_residual_um"))
    read = tuple(n for n in nodes.read if n != "time_s")
    with tempfile.TemporaryDirectory() as tmp:
        journal = Journal(Path(tmp), ("time_s", *read, "offset_um", "offset_wanted_um", "delta_forecast_um", "held",
                                      "limited"), {"source": "benchmark"})
        svc = Service(stepper, journal, LiveParams(), read)

        async def run():
            for _ in range(100):
                try:
                    client, resolved = await _connect(url, nodes, 5.0)
                    break
                except OSError:
                    await asyncio.sleep(0.1)
            io, work, k = [], [], 0
            while k < min(args.periods, 360):
                t0 = time.perf_counter()
                sample = await _sample(client, resolved, read, nodes.factor)
                await _write(resolved, nodes, svc.written)
                t1 = time.perf_counter()
                if sample is None:
                    continue
                ts = sample.pop("time_s")
                t2 = time.perf_counter()
                svc.period(60.0 * k, k, sample)  # the twin's clock nearly stopped: its sample stands for period k
                work.append(time.perf_counter() - t2)
                io.append(t1 - t0)
                k += 1
            await client.disconnect()
            return 1e3 * np.array(io), 1e3 * np.array(work)

        io, work = asyncio.run(run())
        journal.close()
    stop.set()
    res = {"opcua_read_write_ms": float(np.median(io)), "service_period_ms": float(np.median(work)),
           "periods": int(io.size), "rom_states": args.states}
    res["total_ms"] = res["opcua_read_write_ms"] + res["service_period_ms"]
    res["machines_in_1_s_one_after_another"] = int(1000.0 / res["total_ms"])
    print(f"one period: OPC UA read + write {res['opcua_read_write_ms']:.2f} ms, service (rom step, row synced, state "
          f"saved) {res['service_period_ms']:.2f} ms (wall, medians of {res['periods']}); one after another "
          f"~{res['machines_in_1_s_one_after_another']} machines fit in a 1-s period (the twins' cost not counted)")
    out = Path(__file__).parent / "results" / "live_period.json"
    out.write_text(json.dumps(res, indent=2) + "\n")
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
