"""The 3-D frame's four heat step factors: one PARDISO analysis shared, against a handle each.

    python benchmarks/shared_analysis.py [--rounds 3]

Condition 1 marches with four step matrices (θ dt 7.5 s and 30 s, the pump on and off), of one
pattern. Per round, in turn and each in a fresh process: the four factored by
``gatetherm.solvers.pardiso.Analyses`` (one analysis, four numeric factors) and each by the
extension class with a handle of its own (``pardiso._alone``), in the heat solver's METIS
order. Prints the medians of the resident memory the four add (``/proc/self/statm``), the time
to make them and of one solve, and how far the two solutions lie apart (docs/performance.md).
"""
from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
import time

import numpy as np


def _resident() -> float:
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * 4096 / 1e6


def job(way: str) -> dict:
    """Factor the four step matrices ``way`` ("shared" or "alone"); MB added, s, one solve's s."""
    import scipy.sparse as sp

    import gatetherm as gt
    from gatetherm.solvers import pardiso
    from gatetherm.solvers.linsolve import nd_order
    from gatetherm.solvers.model import build

    case = gt.gate_frame(3)
    heat = build(case.problem, case.mesh).heat
    n = heat.n_solid
    mats = []
    for mode in ((True,), (False,)):
        K = heat.K(mode)
        for theta_dt in (7.5, 30.0):
            U = sp.triu((heat.M / theta_dt + K)[:n, :n], format="csr")
            U.sort_indices()
            mats.append(U)
    order = nd_order((heat.M + heat.K((True,)))[:n, :n].tocsr())
    shared = pardiso.Analyses()
    before, t0 = _resident(), time.perf_counter()
    solves = [shared.factor(U, order) if way == "shared" else pardiso._alone(U, order) for U in mats]
    made, added = time.perf_counter() - t0, _resident() - before
    b = np.random.default_rng(0).normal(size=n)
    t0 = time.perf_counter()
    x = [solve(b) for solve in solves for _ in range(5)]
    return {"MB": added, "made_s": made, "solve_ms": 1e3 * (time.perf_counter() - t0) / len(x), "x": x[-1][:1000].tolist()}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--job", choices=("shared", "alone"), help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.job:
        print(json.dumps(job(args.job)))
        return
    res: dict = {"shared": [], "alone": []}
    for r in range(args.rounds):
        for way in (("shared", "alone") if r % 2 == 0 else ("alone", "shared")):
            out = subprocess.run([sys.executable, __file__, "--job", way], check=True, capture_output=True, text=True)
            res[way].append(json.loads(out.stdout.strip().splitlines()[-1]))
            print(f"round {r + 1} {way}: {res[way][-1]['MB']:.0f} MB, made in {res[way][-1]['made_s']:.2f} s, "
                  f"a solve {res[way][-1]['solve_ms']:.1f} ms", flush=True)
    med = {w: {k: statistics.median(v[k] for v in runs) for k in ("MB", "made_s", "solve_ms")} for w, runs in res.items()}
    apart = max(np.abs(np.subtract(a["x"], b["x"])).max() for a, b in zip(res["shared"], res["alone"]))
    for w, m in med.items():
        print(f"{w}: the four factors add {m['MB']:.0f} MB ({m['MB'] / 4:.0f} MB each), made in {m['made_s']:.2f} s, "
              f"a solve {m['solve_ms']:.1f} ms")
    print(f"shared / alone: memory {med['shared']['MB'] / med['alone']['MB']:.2f} ×, set-up "
          f"{med['shared']['made_s'] / med['alone']['made_s']:.2f} ×; solutions apart by {apart:.1e} K")


if __name__ == "__main__":
    main()
