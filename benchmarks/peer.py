"""gatetherm against DOLFINx on gatetherm's own 3-D frame mesh, interleaved.

    python benchmarks/peer.py [--rounds 3] [--dolfinx /tmp/venv_dolfinx/bin/python] [--size M]

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
DOLFINx. BLAS threads are whatever each process sets (gatetherm: one, see studies/cli).
"""
from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
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
    """The peer problem through the API: model, 300 steps, one elastic solve; part times."""
    from threadpoolctl import threadpool_limits

    with threadpool_limits(1):
        t0 = time.perf_counter()
        from gatetherm.solvers.heat import HeatSolver, march
        from gatetherm.solvers.model import build
        from gatetherm.studies.run.case import load_case
        from gatetherm.studies.run.scenario import case_schedule

        case = load_case(case_path)
        parts = {"mesh_read": time.perf_counter() - t0}
        model = build(case.problem, case.mesh)
        parts.update(model.timings)
        sched = case_schedule(case)
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
    ap.add_argument("--equal", metavar="CASE.toml", help=argparse.SUPPRESS)  # the equal-work job itself
    args = ap.parse_args()
    if args.equal:
        print(json.dumps(equal_work(args.equal)))
        return
    work = Path(tempfile.mkdtemp(prefix="peer-"))
    gt = [sys.executable, "-m", "gatetherm.studies.cli"]
    subprocess.run([*gt, "mesh", "--dim", "3", "--out", str(work / "m")], check=True, stdout=subprocess.DEVNULL)
    from gatetherm.geometry.mesh import load_mesh

    (work / "m" / "peer.toml").write_text(peer_case(load_mesh(work / "m" / "mesh.msh").regions))
    jobs = {"dolfinx": [args.dolfinx, str(HERE / "dolfinx_frame.py"), str(work / "m" / "mesh.msh")],
            "equal": [sys.executable, __file__, "--equal", str(work / "m" / "peer.toml")],
            "simulate": [*gt, "simulate", "--condition", "1", "--dim", "3", "--out", str(work / "sim")]}
    results: dict[str, list[dict]] = {k: [] for k in jobs}
    names = list(jobs)
    for r in range(args.rounds):
        for name in names[r % len(names):] + names[:r % len(names)]:
            t0 = time.perf_counter()
            res = rusage_run(jobs[name])
            results[name].append(res)
            print(f"round {r + 1} {name:8s} wall {res['wall']:7.1f} s  CPU {res['cpu']:7.1f} s  "
                  f"peak {res['rss_gb']:.2f} GB  load {os.getloadavg()[0]:.1f}  ({time.perf_counter() - t0:.0f} s)",
                  flush=True)
    med = {k: {m: statistics.median(r[m] for r in v) for m in ("wall", "cpu", "rss_gb")} for k, v in results.items()}
    print(f"\n{'job':10s} {'wall s':>8s} {'CPU s':>8s} {'peak GB':>8s}   (medians of {args.rounds})")
    for k, m in med.items():
        print(f"{k:10s} {m['wall']:8.1f} {m['cpu']:8.1f} {m['rss_gb']:8.2f}")
    for label, k in (("end to end (simulate / dolfinx)", "simulate"), ("equal work (equal / dolfinx)", "equal")):
        print(f"{label:34s} wall {med[k]['wall'] / med['dolfinx']['wall']:.2f}  "
              f"CPU {med[k]['cpu'] / med['dolfinx']['cpu']:.2f}  memory {med[k]['rss_gb'] / med['dolfinx']['rss_gb']:.2f}")
    d, g = results["dolfinx"][-1], results["equal"][-1]
    print(f"agreement: T_A {abs(d['T_A'] - g['T_A']):.1e} K, T_B {abs(d['T_B'] - g['T_B']):.1e} K, "
          f"delta {abs(d['delta_um'] - g['delta_um']):.1e} um (DOLFINx delta {d['delta_um']:.6f} um, "
          f"gatetherm {g['delta_um']:.6f} um)")
    print("parts, last round (s): dolfinx " + ", ".join(f"{k} {v}" for k, v in d.items() if isinstance(v, float)
                                                      and k not in ("T_A", "T_B", "delta_um", "wall")))
    print("                       gatetherm " + ", ".join(f"{k} {v}" for k, v in g.items() if isinstance(v, float)
                                                        and k not in ("T_A", "T_B", "delta_um", "wall")))


def rusage_run(cmd) -> dict:
    """Run ``cmd`` to its end: wall and CPU seconds, peak resident memory (GB), last JSON line."""
    t0 = time.perf_counter()
    p = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    out = p.stdout.read()
    err = p.stderr.read()
    _, status, usage = os.wait4(p.pid, 0)
    wall = time.perf_counter() - t0
    if os.waitstatus_to_exitcode(status):
        raise RuntimeError(f"{' '.join(cmd[:4])} failed: {err[-2000:]}")
    line = next((ln for ln in reversed(out.splitlines()) if ln.startswith("{")), "{}")
    return {"wall": wall, "cpu": usage.ru_utime + usage.ru_stime, "rss_gb": usage.ru_maxrss / 1e6, **json.loads(line)}


if __name__ == "__main__":
    main()
