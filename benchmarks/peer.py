"""gatetherm against DOLFINx on gatetherm's own 3-D frame mesh, interleaved.

    python benchmarks/peer.py [--rounds 3] [--dolfinx /tmp/venv_dolfinx/bin/python] [--json FILE]

Three jobs, each a fresh process, run in turn ``--rounds`` times (the order rotating), so
that the load of these shared cores falls on all of them alike:

* ``dolfinx``: benchmarks/dolfinx_frame.py (set up by benchmarks/setup_dolfinx.sh): the peer
  problem, 300 backward-Euler heat steps of 60 s + one thermoelastic solve;
* ``equal``: the same problem through gatetherm's API (``--equal`` below): the case of
  :func:`peer_case` on the same mesh file, 300 backward-Euler steps, one elastic solve;
* ``simulate``: ``gatetherm simulate --condition 1 --dim 3`` end to end (mesh, model, the
  5-h condition with Crank–Nicolson and Rannacher start-up, fields, pictures, files).

Prints per job the medians of wall time, CPU time and peak memory (``wait4`` of each
process), the ratios gatetherm / DOLFINx (end to end: ``simulate`` over ``dolfinx``; equal
work: ``equal`` over ``dolfinx``) and the agreement of T_A, T_B and δ between ``equal`` and
DOLFINx. BLAS threads are whatever each process sets (gatetherm: one, see gatetherm.cli).
The table is also written to ``--json`` (default ``benchmarks/results/peer.json``), which
``gatetherm report`` shows.
"""
from __future__ import annotations

import argparse
import atexit
import json
import os
import platform
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from datetime import date
from pathlib import Path

HERE = Path(__file__).resolve().parent
LOAD_AT_START = os.getloadavg()[0]
"""Load average (1 min) when the benchmark started: these cores are shared."""
MATERIAL = {"k": 48.0, "rho": 7250.0, "c": 510.0, "E": 1.2e11, "nu": 0.26, "alpha": 1.05e-5}


def peer_case(regions, steps: int = 300) -> str:
    """The peer problem as a case file on ``mesh.msh`` beside it."""
    mat = "".join(f"[materials.{r}]\n" + "".join(f"{k} = {v!r}\n" for k, v in MATERIAL.items()) for r in regions)
    probes = "".join(f'[probes.{p}]\npoint = "{p}"\nquantities = ["T"]\n' for p in ("A", "B", "F_L", "F_R"))
    return (f'[mesh]\nfile = "mesh.msh"\n{mat}[initial]\ntemperature = 20.0\n'
            '[thermal.free_surface]\nfilm = 8.0\nambient = 20.0\n[thermal.tank_wall]\nfilm = 260.0\nambient = 40.0\n'
            f'[supports.mounting_face]\ntype = "clamped"\n{probes}'
            f'[time]\nend = {60.0 * steps!r}\nstep = 60.0\nfields = {60.0 * steps!r}\n'
            '[time.scheme]\ntheta = 1.0\nrestart = 1\n')


def equal_work(case_path: str) -> dict:
    """The peer problem through the API, the process set up as a command sets it up
    (:func:`gatetherm.configure`): model, 300 steps, one elastic solve; part times."""
    t0 = time.perf_counter()
    import gatetherm as gt

    gt.configure()
    from gatetherm.solvers.heat import HeatSolver, march
    from gatetherm.solvers.model import build
    from gatetherm.studies.run.case import load_case

    case = load_case(case_path)
    parts = {"mesh_read": time.perf_counter() - t0}
    model = build(case.problem, case.mesh)
    parts.update(model.timings)
    sched = case.schedule
    t = time.perf_counter()
    solver = HeatSolver(model.heat)
    *_, (_, U) = march(solver, sched.drive, sched.times, case.problem.scheme)
    parts["heat_steps"] = time.perf_counter() - t
    parts["heat_factor"] = solver.factor_seconds
    t = time.perf_counter()
    u = model.displacement_field(U)
    parts["elastic_solve"] = time.perf_counter() - t
    y = dict(zip(model.readout.keys, model.read(U)))
    el, pts = model.elastic, {p.name: p.xyz for p in case.problem.probes}
    delta = (el.point_functional(pts["F_L"], 0) - el.point_functional(pts["F_R"], 0)) @ u
    return {"tool": "gatetherm", "T_A": y[("T", "A")], "T_B": y[("T", "B")], "delta_um": delta * 1e6,
            **{k: round(v, 3) for k, v in parts.items()}, "total": round(time.perf_counter() - t0, 3)}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--dolfinx", default="/tmp/venv_dolfinx/bin/python", help="python of setup_dolfinx.sh")
    ap.add_argument("--json", type=Path, default=HERE / "results" / "peer.json", help="table written here")
    ap.add_argument("--equal", metavar="CASE.toml", help=argparse.SUPPRESS)  # the equal-work job itself
    args = ap.parse_args()
    if args.equal:
        print(json.dumps(equal_work(args.equal)))
        return
    work = Path(tempfile.mkdtemp(prefix="peer-"))
    atexit.register(shutil.rmtree, work, True)
    gt = [sys.executable, "-m", "gatetherm.cli"]
    subprocess.run([*gt, "mesh", "--dim", "3", "--out", str(work / "m")], check=True, stdout=subprocess.DEVNULL)
    from gatetherm.geometry.mesh import load_mesh

    (work / "m" / "peer.toml").write_text(peer_case(load_mesh(work / "m" / "mesh.msh").regions))
    jobs = {"dolfinx": [args.dolfinx, str(HERE / "dolfinx_frame.py"), str(work / "m" / "mesh.msh")],
            "equal": [sys.executable, __file__, "--equal", str(work / "m" / "peer.toml")],
            "simulate": [*gt, "simulate", "--condition", "1", "--dim", "3", "--out", str(work / "sim")]}
    results: dict[str, list[dict]] = {k: [] for k in jobs}
    names = list(jobs)
    for r, name in interleaved(names, args.rounds):
        t0 = time.perf_counter()
        res = rusage_run(jobs[name])
        results[name].append(res)
        print(f"round {r + 1} {name:8s} wall {res['wall']:7.1f} s  CPU {res['cpu']:7.1f} s  "
              f"peak {res['rss_gb']:.2f} GB  load {os.getloadavg()[0]:.1f}  ({time.perf_counter() - t0:.0f} s)",
              flush=True)
    med = {k: {m: statistics.median(r[m] for r in v) for m in ("wall", "cpu", "rss_gb")} for k, v in results.items()}
    rows = [[k, round(m["wall"], 1), round(m["cpu"], 1), round(m["rss_gb"], 2)] for k, m in med.items()]
    rows += [[f"ratio {k} / dolfinx", *(round(med[k][m] / med["dolfinx"][m], 2) for m in ("wall", "cpu", "rss_gb"))]
             for k in ("simulate", "equal")]
    d, g = results["dolfinx"][-1], results["equal"][-1]

    def parts(res):
        return ", ".join(f"{k} {v}" for k, v in res.items() if isinstance(v, float)
                         and k not in ("T_A", "T_B", "delta_um", "wall", "cpu", "sys", "rss_gb"))

    notes = [f"medians of {args.rounds} interleaved rounds; simulate: gatetherm simulate --condition 1 --dim 3 end "
             "to end; equal: the DOLFINx problem (300 backward-Euler steps + 1 elastic solve) through gatetherm's API",
             f"agreement: T_A {abs(d['T_A'] - g['T_A']):.1e} K, T_B {abs(d['T_B'] - g['T_B']):.1e} K, delta "
             f"{abs(d['delta_um'] - g['delta_um']):.1e} um (DOLFINx {d['delta_um']:.6f} um, gatetherm {g['delta_um']:.6f} um)",
             f"parts, last round (s): DOLFINx {parts(d)}", f"parts, last round (s): gatetherm {parts(g)}"]
    write_table(args.json, ["job", "wall s", "CPU s", "peak GB"], rows, notes)


def interleaved(names, rounds: int):
    """``(round, name)`` over ``rounds`` rounds of ``names``, the order rotating each round, so
    that the load of the shared cores falls on every job alike."""
    names = list(names)
    for r in range(rounds):
        k = r % len(names)
        for name in names[k:] + names[:k]:
            yield r, name


def rusage_run(cmd, env=None) -> dict:
    """Run ``cmd`` to its end: wall and CPU seconds (``sys``: the system's part), peak resident memory
    (GB), page faults (``faults``, minor), last JSON line."""
    t0 = time.perf_counter()
    p = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, env=env)
    out = p.stdout.read()  # stderr too: one pipe cannot fill while the other is read
    _, status, usage = os.wait4(p.pid, 0)
    wall = time.perf_counter() - t0
    if os.waitstatus_to_exitcode(status):
        raise RuntimeError(f"{' '.join(cmd[:4])} failed: {out[-2000:]}")
    line = next((ln for ln in reversed(out.splitlines()) if ln.startswith("{")), "{}")
    return {"wall": wall, "cpu": usage.ru_utime + usage.ru_stime, "sys": usage.ru_stime, "rss_gb": usage.ru_maxrss / 1e6,
            "faults": usage.ru_minflt, **json.loads(line)}


def write_table(path: Path, columns: list, rows: list, notes: list[str]) -> None:
    """Print a table and write it with the date, machine and command as JSON to ``path``
    (``gatetherm report`` shows it)."""
    notes = [*notes, f"load average {LOAD_AT_START:.1f} at the start, {os.getloadavg()[0]:.1f} at the end"]
    widths = [max(len(str(c)), *(len(str(r[i])) for r in rows)) for i, c in enumerate(columns)]
    print("\n" + "  ".join(f"{c:>{w}}" for c, w in zip(columns, widths)))
    for r in rows:
        print("  ".join(f"{str(v):>{w}}" for v, w in zip(r, widths)))
    for n in notes:
        print(n)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps({"date": date.today().isoformat(), "machine": machine(),
                                "command": command_line(),
                                "columns": columns, "rows": rows, "notes": notes}, indent=1) + "\n")
    print(f"wrote {path}")


def command_line() -> str:
    """This benchmark's command line, each absolute path argument by its file name only: what a
    reader reruns beside their own copy of the file, with no path of this machine in it."""
    args = [Path(a).name if a.startswith("/") else a for a in sys.argv[1:]]
    return " ".join(["python", f"benchmarks/{Path(sys.argv[0]).name}", *args])


def machine() -> str:
    """CPU model, cores and memory of this machine, one line."""
    cpu = next((ln.split(":", 1)[1].strip() for ln in Path("/proc/cpuinfo").read_text().splitlines()
                if ln.startswith("model name")), platform.processor())
    mem = os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES") / 2**30
    return f"{cpu}, {os.cpu_count()} cores, {mem:.0f} GiB, Python {platform.python_version()}"


if __name__ == "__main__":
    main()
