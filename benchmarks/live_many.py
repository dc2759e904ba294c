"""N machines compensated at a 1-s period on one computer, measured: one ``twin`` process serving
all N machines (each in its own OPC UA namespace) and one ``live`` process per machine.

    python benchmarks/live_many.py [--machines 100] [--seconds 240] [--method errormodel|rom] [--poll 0.05]

The C-frame (validation/examples/c_frame/case.toml) on loopback. ``--method errormodel`` (default):
every service steps an error model fitted once on the case's simulated run (``--model``: no case to
load, a service starts in ~1 CPU-s); ``rom``: every service loads the case (meshed: ~3 CPU-s) and
steps its reduced model (built once, put in every service's --out as a restart would find it). A 1-s period:
the twin runs at 60x with its 60-s step and each service steps every 60 s of the machine's clock
(the methods' sampling), so every machine publishes a sample and its service reads it, steps,
logs (row and state synced to disk) and writes the correction once per wall second; the machines'
samples are spread evenly over the second. The services are started ``--batch`` at a time (each
waits for the twin's clock, reading about once a second); the twin starts its clock once all are
connected. Runs ``--seconds`` of wall time after all services
are connected, then prints, from every machine's ``live.csv`` (the twin's ``published_unix_s``
is read into it through each service's map file) and the wall time each service handled each row
(``handled.csv``, from ``gt.live``'s ``on_period``): the periods logged, held, missed and late
(handled more than one period after the sample was published), the median and 95th percentile
of the step latency (publication to correction written, ms), the CPU (% of one core, over the
steady part) and memory (RSS) of the twin and the services, and the load of the computer.
Writes benchmarks/results/live_many_N<machines>.json.
"""
from __future__ import annotations

import argparse
import json
import os
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

CASE = Path(__file__).resolve().parents[1] / "validation" / "examples" / "c_frame" / "case.toml"
SPEED, STEP = 60.0, 60.0
"""Machine seconds per wall second and per sample: one period per wall second."""


def _map(directory: Path, i: int, machines: int, names) -> Path:
    from gatetherm.validation.live.nodes import machine_namespace

    ns = machine_namespace(i, machines)
    p = directory / f"map{i + 1:03d}.toml"
    p.write_text("[read]\n" + "".join(f'{n} = "nsu={ns};s={n}"\n' for n in names)
                 + f'[write]\noffset_um = "nsu={ns};s=offset_um"\n')
    return p


def _unfrozen() -> None:
    """``--no-freeze``: the twin's and the services' heaps not frozen (as before), for comparison."""
    import contextlib

    from gatetherm.validation.live import runner, twin

    runner.frozen_heap = twin.frozen_heap = contextlib.nullcontext


def role_twin(a) -> None:
    import gatetherm as gt
    from gatetherm.studies.run.reduce import load_rom
    from live_many_records import record_gc

    record_gc(Path(a.dir) / "gc.csv")
    if a.no_freeze:
        _unfrozen()
    res = gt.twin(str(CASE), a.endpoint, SPEED, until=a.until, rom=load_rom(Path(a.dir) / "rom" / "rom.npz"),
                  wait=True, machines=a.machines, step_s=STEP)
    res["rusage"] = _rusage()
    (Path(a.dir) / "twin.json").write_text(json.dumps(res))


def role_live(a) -> None:
    import gatetherm as gt
    from live_many_records import record_gc

    out = Path(a.dir) / f"m{a.index + 1:03d}"
    record_gc(out / "gc.csv")
    os.nice(a.service_nice)  # behind the twin, which stands for the machines' own controls
    if a.no_freeze:
        _unfrozen()
    handled = open(out / "handled.csv", "w", buffering=1)

    def on_period(row):
        handled.write(f"{row['time_s']!r},{time.time()!r}\n")

    rom = a.method == "rom"
    gt.live(str(CASE) if rom else None, "rom", model=None if rom else Path(a.dir) / "model.json", endpoint=a.endpoint,
            out=out, map=Path(a.dir) / f"map{a.index + 1:03d}.toml", period=STEP, until=a.until, states=a.states,
            on_period=on_period, poll=a.poll)
    handled.close()
    (out / "rusage.json").write_text(json.dumps(_rusage()))
    # every service ends in the same second here (a fleet does not): the interpreter's teardown, a full
    # collection of each service's heap (gc.csv), would stall the machines still in their last period
    os._exit(0)


def _rusage() -> dict:
    r = resource.getrusage(resource.RUSAGE_SELF)
    return {"cpu_s": r.ru_utime + r.ru_stime}


def _proc(pid: int) -> tuple[float, float, float]:
    """CPU seconds, RSS and PSS (MB; PSS: the shared libraries' pages split among the processes
    that map them) of a running process, from /proc."""
    try:
        stat = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
        rss = int(Path(f"/proc/{pid}/statm").read_text().split()[1]) * os.sysconf("SC_PAGE_SIZE") / 2**20
        pss = next(int(line.split()[1]) for line in Path(f"/proc/{pid}/smaps_rollup").read_text().splitlines()
                   if line.startswith("Pss:")) / 1024
        return (int(stat[11]) + int(stat[12])) / os.sysconf("SC_CLK_TCK"), rss, pss
    except (OSError, IndexError, ValueError, StopIteration):
        return float("nan"), float("nan"), float("nan")


def _busy() -> tuple[float, float]:
    """The whole computer's busy and total CPU seconds (/proc/stat)."""
    v = [int(x) for x in Path("/proc/stat").read_text().splitlines()[0].split()[1:]]
    tick = os.sysconf("SC_CLK_TCK")
    return (sum(v) - v[3] - v[4]) / tick, sum(v) / tick


def _uptime() -> str:
    return subprocess.run(["uptime"], capture_output=True, text=True).stdout.strip()


def _started(directory: Path, machines: int) -> bool:
    return all((directory / f"m{i + 1:03d}" / "handled.csv").exists()
               and (directory / f"m{i + 1:03d}" / "handled.csv").stat().st_size > 0 for i in range(machines))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--machines", type=int, default=100)
    ap.add_argument("--seconds", type=float, default=240.0, help="wall seconds of the measured run (default 240)")
    ap.add_argument("--states", type=int, default=30)
    ap.add_argument("--method", choices=("errormodel", "rom"), default="errormodel")
    ap.add_argument("--poll", type=float, default=0.05, help="the services' wait between reads, s (default 0.05)")
    ap.add_argument("--port", type=int, default=48850)
    ap.add_argument("--batch", type=int, default=10, help="services started at a time (default 10)")
    ap.add_argument("--keep", type=Path, help="keep the run's directories here")
    ap.add_argument("--service-nice", type=int, default=0,
                    help="the services' niceness above the twin's (default 0: the same): the twin stands for N "
                         "machines' own controls, one process against N services in the scheduler")
    ap.add_argument("--no-freeze", action="store_true", help="the heaps not frozen (as before 7 Dec 2026), to compare")
    ap.add_argument("--role", choices=("twin", "live"), help=argparse.SUPPRESS)
    ap.add_argument("--index", type=int, help=argparse.SUPPRESS)
    ap.add_argument("--dir", help=argparse.SUPPRESS)
    ap.add_argument("--until", type=float, help=argparse.SUPPRESS)
    ap.add_argument("--endpoint", help=argparse.SUPPRESS)
    a = ap.parse_args()
    if a.role:
        return role_twin(a) if a.role == "twin" else role_live(a)
    import gatetherm as gt
    from gatetherm.api.live import SENSORS
    from gatetherm.studies.run.reduce import cached_rom

    n = a.machines
    load_before = _uptime()
    print(f"before: {load_before}")
    directory = Path(tempfile.mkdtemp(prefix="gatetherm-live-many-")) if a.keep is None else a.keep
    directory.mkdir(parents=True, exist_ok=True)
    case = gt.load_case(CASE)
    t0 = time.perf_counter()
    cached_rom(case, a.states, directory / "rom")
    print(f"reduced model ({a.states} states) built in {time.perf_counter() - t0:.0f} s")
    if a.method == "errormodel":
        _fit(case, directory / "model.json")
    names = ("time_s", *sorted(case.inputs()), *SENSORS, "delta_residual_um", "published_unix_s")
    for i in range(n):
        _map(directory, i, n, names)
        out = directory / f"m{i + 1:03d}"
        out.mkdir(exist_ok=True)
        for f in ("rom.npz", "rom.key") if a.method == "rom" else ():
            shutil.copy(directory / "rom" / f, out / f)
    until = STEP * round(a.seconds * SPEED / STEP)
    endpoint = f"opc.tcp://127.0.0.1:{a.port}"
    common = [sys.executable, __file__, "--dir", str(directory), "--until", repr(until), "--endpoint", endpoint,
              "--machines", str(n), "--states", str(a.states), "--poll", repr(a.poll), "--method", a.method,
              "--service-nice", str(a.service_nice), *(("--no-freeze",) if a.no_freeze else ())]
    logs = open(directory / "processes.log", "w")
    t_launch = time.time()
    twin = subprocess.Popen([*common, "--role", "twin"], stdout=logs, stderr=subprocess.STDOUT)
    lives = []
    for first in range(0, n, a.batch):  # started a batch at a time: 100 imports at once thrash 2 cores
        batch = range(first, min(first + a.batch, n))
        lives += [subprocess.Popen([*common, "--role", "live", "--index", str(i)], stdout=logs,
                                   stderr=subprocess.STDOUT) for i in batch]
        end = time.time() + 600
        while time.time() < end and not all((directory / f"m{i + 1:03d}" / "live.csv").exists() for i in batch):
            time.sleep(0.5)
    print(f"{n} services launched in {time.time() - t_launch:.0f} s")
    procs = [twin, *lives]
    samples = []  # (wall, busy, total, [(cpu, rss) per process])
    started = ended = twin_ended = None
    while any(p.poll() is None for p in procs):
        if all(p.poll() is not None for p in lives):
            ended = ended or time.time()
            if time.time() - ended > 30 and twin.poll() is None:
                twin.terminate()  # every service ended (or failed) 30 s ago: the twin would wait for ever
        if twin.poll() is not None:
            twin_ended = twin_ended or time.time()
            if time.time() - twin_ended > 30:
                for p in lives:  # a service still reconnecting to a twin that has ended: SIGTERM, state saved
                    if p.poll() is None:
                        p.terminate()
        if started is None and _started(directory, n):
            started = time.time()
            print(f"all {n} services stepping {started - t_launch:.0f} s after launch")
        if started is not None and all(p.poll() is None for p in procs):
            samples.append((time.time(), *_busy(), [_proc(p.pid) for p in procs]))
        time.sleep(2.0)
    load_after = _uptime()
    print(f"after: {load_after}")
    codes = [p.returncode for p in procs]
    res = summarize(directory, n, until, samples, codes)
    res.update({"machines": n, "method": a.method, "seconds": a.seconds, "heap_frozen": not a.no_freeze, "service_nice": a.service_nice, "until_s": until, "states": a.states, "poll_s": a.poll,
                "speed": SPEED, "step_s": STEP, "uptime_before": load_before, "uptime_after": load_after,
                "startup_s": None if started is None else started - t_launch,
                "arrangement": "one twin process serving all machines, one live process per machine",
                "command": " ".join(["python benchmarks/live_many.py", *sys.argv[1:]])})
    report(res)
    out = Path(__file__).parent / "results" / f"live_many_N{n}.json"
    out.write_text(json.dumps(res, indent=2) + "\n")
    print(f"wrote {out}")
    if a.keep is None:
        shutil.rmtree(directory, ignore_errors=True)


def _fit(case, path: Path) -> None:
    """An error model of δ fitted on the case's simulated run (as benchmarks/live_step.py)."""
    import gatetherm as gt
    from gatetherm.studies.control.compensator import CompensatorParams, controller_grid
    from gatetherm.studies.errormodel.fit import FitParams, fit_error_model
    from gatetherm.studies.errormodel.model import save_model

    t0 = time.perf_counter()
    ts = controller_grid(gt.run(case, keep=()).scenario.series({}), CompensatorParams(),
                         extra=("spindle_W", "ambient_degC"))[0]
    save_model(path, fit_error_model(ts, ("delta_um",), inputs=("spindle_W",), params=FitParams(form="dynamic")))
    print(f"error model fitted in {time.perf_counter() - t0:.0f} s")


def summarize(directory: Path, n: int, until: float, samples, codes) -> dict:
    from gatetherm.studies.run.timeseries import read_timeseries

    expected = int(round(until / STEP)) + 1
    rows = held = missed = late = 0
    lat, per_machine_p95 = [], []
    for i in range(n):
        out = directory / f"m{i + 1:03d}"
        try:
            ts = read_timeseries(out / "live.csv", required=("time_s",))
            summary = json.loads((out / "summary.json").read_text())
        except Exception:  # noqa: BLE001 - a service that did not finish counts as all missed
            missed += expected
            continue
        handled = dict(np.loadtxt(out / "handled.csv", delimiter=",", ndmin=2).tolist())
        rows += len(ts.time_s)
        held += int(np.nansum(ts["held"]))
        missed += expected - len(ts.time_s)
        ms = np.array([1e3 * (handled[t] - p) for t, p in zip(ts.time_s, ts["published_unix_s"]) if t in handled])
        late += int((ms > 1e3 * STEP / SPEED).sum())
        lat.append(ms)
        per_machine_p95.append(float(np.percentile(ms, 95)) if ms.size else float("nan"))
        del summary
    lat = np.concatenate(lat) if lat else np.array([np.nan])
    from live_many_records import analyse

    res = {"periods_expected": expected * n, "rows": rows, "held": held, "missed": missed, "late": late,
           "latency_ms": {"median": float(np.median(lat)), "p95": float(np.percentile(lat, 95)),
                          "p99": float(np.percentile(lat, 99)), "max": float(lat.max())},
           "worst_machine_p95_ms": float(np.nanmax(per_machine_p95)) if per_machine_p95 else None,
           "exit_codes_nonzero": sum(c != 0 for c in codes), "twin_exit_code": codes[0]}
    res["periods"] = analyse(directory, n, SPEED, STEP)
    twin = directory / "twin.json"
    res["twin"] = json.loads(twin.read_text()) if twin.exists() else None
    if len(samples) >= 2:
        (w0, b0, t0, p0), (w1, b1, t1, p1) = samples[0], samples[-1]  # all processes running
        cpu = [(a1[0] - a0[0]) / (w1 - w0) for a0, a1 in zip(p0, p1)]
        rss = [max(s[3][k][1] for s in samples) for k in range(len(p0))]
        pss = [max(s[3][k][2] for s in samples) for k in range(len(p0))]
        res["steady"] = {"wall_s": w1 - w0, "computer_busy_pct_of_2_cores": 100 * (b1 - b0) / (t1 - t0),
                         "twin_cpu_pct": 100 * cpu[0], "services_cpu_pct_total": 100 * float(np.nansum(cpu[1:])),
                         "service_cpu_pct_median": 100 * float(np.nanmedian(cpu[1:])),
                         "twin_rss_MB": rss[0], "service_rss_MB_median": float(np.nanmedian(rss[1:])),
                         "rss_MB_total": float(np.nansum(rss)), "twin_pss_MB": pss[0],
                         "service_pss_MB_median": float(np.nanmedian(pss[1:])), "pss_MB_total": float(np.nansum(pss))}
    return res


def report(r: dict) -> None:
    from live_many_records import report as report_periods

    lat, s, tw = r["latency_ms"], r.get("steady", {}), r.get("twin") or {}
    on_time = r["periods_expected"] - r["missed"] - r["late"]
    print(f"{r['machines']} machines ({r['method']}), 1-s period, {r['seconds']:g} s ({r['until_s']:g} s of machine time at "
          f"{r['speed']:g}x): {r['rows']} of {r['periods_expected']} periods logged, {r['missed']} missed, "
          f"{r['late']} late (> 1 s), {r['held']} held by a guard; on time: {on_time} "
          f"({100 * on_time / r['periods_expected']:.1f} %)")
    print(f"step latency (sample published -> correction written): median {lat['median']:.0f} ms, 95th "
          f"percentile {lat['p95']:.0f} ms, 99th {lat['p99']:.0f} ms, max {lat['max']:.0f} ms; the worst "
          f"machine's 95th percentile {r['worst_machine_p95_ms']:.0f} ms")
    if tw:
        lag = tw["publish_lag_ms"]
        print(f"twin: {tw['served']} samples served, publication behind its time: median {lag['median']:.0f} ms, "
              f"95th percentile {lag['p95']:.0f} ms, max {lag['max']:.0f} ms")
    if s:
        print(f"steady {s['wall_s']:.0f} s: twin {s['twin_cpu_pct']:.0f} % of a core, {s['twin_rss_MB']:.0f} MB; "
              f"services {s['services_cpu_pct_total']:.0f} % in all (median {s['service_cpu_pct_median']:.1f} % each), "
              f"{s['service_rss_MB_median']:.0f} MB each (RSS; PSS {s['service_pss_MB_median']:.0f} MB); in all "
              f"{s['rss_MB_total'] / 1024:.1f} GB RSS, {s['pss_MB_total'] / 1024:.1f} GB PSS; the computer "
              f"{s['computer_busy_pct_of_2_cores']:.0f} % busy (2 cores, other work included)")
    print(f"startup (launch to every service stepping): {r['startup_s']:.0f} s; processes with a non-zero exit: "
          f"{r['exit_codes_nonzero']}")
    report_periods(r.get("periods") or {})


if __name__ == "__main__":
    main()
