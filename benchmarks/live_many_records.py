"""Which periods of ``benchmarks/live_many.py`` were late, and why: its records taken apart.

Every row of every machine's ``live.csv`` carries the twin's ``published_unix_s``; ``handled.csv``
the wall time its service wrote the correction; the twin's clock start (``twin.json``) gives the
time each sample was due (machine *i* of N publishes *i*/N of a period after machine 1). So every
period splits into the twin's lag (published - due: the twin's loop) and the service's latency
(written - published: reading, stepping, logging, writing). ``gc.csv`` (twin) and ``m*/gc.csv``
(services) hold the collections of garbage that took > 20 ms or were of the oldest generation
(wall time at the start, generation, ms), recorded by the benchmark's roles through ``gc.callbacks``;
those while the clock ran are counted.

A late period is put in one class, first match: ``startup`` (in the first 3 s of the clock), ``end``
(in the last 2 s: the first services to end tear down while the last machines step),
``twin`` (published more than half a period late), ``burst`` (in a wall second in which 10 % or
more of the machines were late: a common cause, the twin answering or the computer), ``single``
(a machine alone: its service). A collection of garbage in the twin or in the late service
between the due time and the write is counted beside (``gc``).
"""
from __future__ import annotations

import collections
import gc
import json
import time
from pathlib import Path

import numpy as np

STARTUP_S, END_S, TWIN_LATE, BURST = 3.0, 2.0, 0.5, 0.10


def record_gc(path: Path):
    """Log this process's slow or full collections of garbage to ``path`` (CSV: wall s, generation, ms)."""
    f = open(path, "w", buffering=1)
    f.write("wall_s,generation,ms\n")
    start = {}

    def callback(phase, info):
        if phase == "start":
            start["t"], start["w"] = time.perf_counter(), time.time()
        elif "t" in start:
            ms = 1e3 * (time.perf_counter() - start["t"])
            if ms > 20.0 or info["generation"] == 2:
                f.write(f"{start['w']!r},{info['generation']},{ms:.3f}\n")
    gc.callbacks.append(callback)
    return f


def _gc(path: Path, start: float, end: float) -> np.ndarray:
    """The collections logged in ``path`` that began between ``start`` and ``end`` (wall s)."""
    if not path.exists() or path.stat().st_size < 25:
        return np.zeros((0, 3))
    g = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    return g[(g[:, 0] >= start) & (g[:, 0] <= end)]


def _rows(out: Path, i: int, n: int, u0: float, t0: float, speed: float, step: float):
    lines = [x for x in (out / "live.csv").read_text().splitlines() if x and not x.startswith("#")]
    head = lines[0].split(",")
    it, ip = head.index("time_s"), head.index("published_unix_s")
    handled = dict(np.loadtxt(out / "handled.csv", delimiter=",", ndmin=2).tolist())
    for line in lines[1:]:
        cells = line.split(",")
        t = float(cells[it])
        due = u0 + (t - t0) / speed + i * step / speed / n
        yield i, t, due, float(cells[ip]), handled.get(t, np.nan)


def _q(x: np.ndarray) -> dict:
    x = x[np.isfinite(x)]
    if not x.size:
        return {}
    return {"median": float(np.median(x)), "p95": float(np.percentile(x, 95)), "p99": float(np.percentile(x, 99)),
            "max": float(x.max())}


def analyse(directory: Path, n: int, speed: float, step: float) -> dict:
    """The periods taken apart (module docstring); {} without the twin's record."""
    twin = directory / "twin.json"
    if not twin.exists():
        return {}
    tw = json.loads(twin.read_text())
    u0, t0, per = tw["clock_start_unix_s"], tw["start_s"], step / speed
    rows = []
    for i in range(n):
        out = directory / f"m{i + 1:03d}"
        if (out / "live.csv").exists() and (out / "handled.csv").exists():
            rows += list(_rows(out, i, n, u0, t0, speed, step))
    if not rows:
        return {}
    m, t, due, pub, done = np.array(rows).T
    m = m.astype(int)
    twin_lag, service, total = pub - due, done - pub, done - due
    sec = np.floor(due - u0).astype(int)
    last = float(np.nanmax(done))
    tgc = _gc(directory / "gc.csv", u0, last)
    sgc = {i: _gc(directory / f"m{i + 1:03d}" / "gc.csv", u0, last) for i in range(n)}
    parts = ((0, 10), (10, 30), (30, 60), (60, 90), (90, int(sec.max()) + 1))
    res = {"twin_lag_ms_median_by_part": {f"{a}-{b} s": float(np.median(1e3 * twin_lag[(sec >= a) & (sec < b)]))
                                          for a, b in parts if np.any((sec >= a) & (sec < b))},
           "latency_from_due_ms": _q(1e3 * total), "twin_lag_ms": _q(1e3 * twin_lag),
           "service_latency_ms": _q(1e3 * service), "late_from_due": int(np.sum(total > per)),
           "gc_twin": _gcsum(tgc), "gc_twin_before_clock": _gcsum(_gc(directory / "gc.csv", 0.0, u0)), "gc_services": _gcsum(np.concatenate(list(sgc.values()) or [np.zeros((0, 3))]))}
    for name, late in (("late", service > per), ("late_from_due", total > per)):
        per_sec = collections.Counter(sec[late])
        classes = collections.Counter()
        with_gc = 0
        for k in np.flatnonzero(late):
            c = ("startup" if due[k] - u0 < STARTUP_S else "end" if t[k] > t.max() - END_S * speed
                 else "twin" if twin_lag[k] > TWIN_LATE * per
                 else "burst" if per_sec[sec[k]] >= BURST * n else "single")
            classes[c] += 1
            g = np.vstack([tgc, sgc[m[k]]])
            with_gc += bool(np.any((g[:, 0] >= due[k]) & (g[:, 0] <= done[k]))) if g.size else 0
        res[f"{name}_by_class"] = {**dict(classes), "with_gc": with_gc}
        res[f"{name}_worst_seconds"] = [[int(s), c] for s, c in per_sec.most_common(5)]
        res[f"{name}_worst_machines"] = [[int(i) + 1, c] for i, c in collections.Counter(m[late]).most_common(5)]
    return res


def _gcsum(g: np.ndarray) -> dict:
    full = g[g[:, 1] == 2] if g.size else g
    return {"full_collections": int(len(full)), "full_max_ms": float(full[:, 2].max()) if len(full) else 0.0,
            "slow_over_100ms": int(np.sum(g[:, 2] > 100)) if g.size else 0}


def report(r: dict) -> None:
    """Print the analysis."""
    if not r:
        return
    q = r["latency_from_due_ms"]
    print(f"from the period's due time to the correction written: median {q['median']:.0f} ms, 95th percentile "
          f"{q['p95']:.0f} ms, 99th {q['p99']:.0f} ms, max {q['max']:.0f} ms; late (> 1 period): {r['late_from_due']}")
    print(f"of which the twin's lag (due -> published): median {r['twin_lag_ms']['median']:.0f} ms, max "
          f"{r['twin_lag_ms']['max']:.0f} ms; the service's (published -> written): median "
          f"{r['service_latency_ms']['median']:.0f} ms, max {r['service_latency_ms']['max']:.0f} ms")
    print("the twin's lag, median by part of the run (wall s after the clock's start): "
          + ", ".join(f"{k} {v:.0f} ms" for k, v in r["twin_lag_ms_median_by_part"].items()))
    for name in ("late", "late_from_due"):
        print(f"{name}: by class {r[f'{name}_by_class']}; worst wall seconds after the clock's start "
              f"[second, periods] {r[f'{name}_worst_seconds']}; worst machines {r[f'{name}_worst_machines']}")
    for who, key in (("twin", "gc_twin"), ("services", "gc_services"), ("twin, before the clock", "gc_twin_before_clock")):
        g = r[key]
        print(f"garbage collections while the clock ran ({who}): {g['full_collections']} full, the longest "
              f"{g['full_max_ms']:.0f} ms; {g['slow_over_100ms']} over 100 ms" if "before" not in who else
              f"garbage collections of the twin before the clock started: {g['full_collections']} full, the longest "
              f"{g['full_max_ms']:.0f} ms (wall)")
