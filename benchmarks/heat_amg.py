"""The heat steps' AMG hierarchy: energy-minimising against Jacobi-smoothed prolongation, and
one hierarchy shared by the pump modes of a step length.

    python benchmarks/heat_amg.py [--factor 8] [--rounds 2] [--solves 100]

Condition 1 of the 3-D frame, meshed for about ``--factor`` times the default nodes, is marched
on the iterative path (as ``benchmarks/scaling.py`` does) with the heat step systems and their
right-hand sides recorded. Then, per round and in turn, the most used step matrix's first
``--solves`` right-hand sides are solved in sequence (each started from the Galerkin projection
onto the last solutions, as in a march) with: a hierarchy of its own with Jacobi-smoothed
prolongation (pyamg's ``("jacobi", {"weighting": "local"})``, gatetherm's before 2026-12-06), one
with energy-minimising prolongation (``gatetherm.solvers.iterative.AMG``'s), and the latter
hierarchy of the same step length's matrix in the other pump mode (what
:class:`~gatetherm.solvers.heat.HeatSolver` does). Prints the medians of set-up and solve
seconds and the iterations (docs/performance.md).
"""
from __future__ import annotations

import argparse
import os
import statistics
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))


def recorded(factor: float, keep: int) -> list[tuple]:
    """``(matrix, right-hand sides (k, n))`` of each heat step solver of a condition-1 march, most
    used first, at most ``keep`` right-hand sides each."""
    from gatetherm.solvers import iterative
    from scaling import job

    seen: dict = {}
    call = iterative.PCG.__call__

    def recording(self, b):
        rec = seen.setdefault(id(self), (self.A, []))
        if np.ndim(b) == 1 and len(rec[1]) < keep:  # a step's (2-D: the bordered fluids' columns)
            rec[1].append(np.array(b))
        return call(self, b)

    os.environ["GATETHERM_SOLVER"] = "iterative"
    iterative.PCG.__call__ = recording
    try:
        job(3, factor)
    finally:
        iterative.PCG.__call__ = call
    return sorted(((A, np.array(bs)) for A, bs in seen.values()), key=lambda s: -len(s[1]))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--factor", type=float, default=8.0)
    ap.add_argument("--rounds", type=int, default=2)
    ap.add_argument("--solves", type=int, default=100)
    args = ap.parse_args()
    from gatetherm.solvers.iterative import AMG, PCG
    from gatetherm.solvers.heat import HEAT_RTOL

    systems = recorded(args.factor, args.solves)
    A, bs = systems[0]
    other = next(B for B, _ in systems[1:] if abs(B - A).max() < 1e-3 * abs(A).max())  # the other pump mode
    print(f"heat step matrix: {A.shape[0]} unknowns, {len(bs)} right-hand sides; the other mode's differs by "
          f"{abs(other - A).max() / abs(A).max():.1e} of its largest entry", flush=True)
    variants = {"jacobi": lambda: AMG(A, smooth=("jacobi", {"weighting": "local"})), "energy": lambda: AMG(A),
                "energy, the other mode's": lambda: AMG(other)}
    res: dict = {k: [] for k in variants}
    for r in range(args.rounds):
        for name in (list(variants) if r % 2 == 0 else list(variants)[::-1]):
            t0 = time.perf_counter()
            pcg = PCG(A, rtol=HEAT_RTOL, amg=variants[name](), split=False)
            t1 = time.perf_counter()
            for b in bs:
                pcg(b)
            res[name].append((t1 - t0, time.perf_counter() - t1, pcg.iterations))
            print(f"round {r + 1} {name}: set-up {t1 - t0:.2f} s, {len(bs)} solves {res[name][-1][1]:.2f} s, "
                  f"{pcg.iterations} iterations", flush=True)
    for name, rows in res.items():
        print(f"{name}: set-up {statistics.median(r[0] for r in rows):.2f} s, solves "
              f"{statistics.median(r[1] for r in rows):.2f} s, iterations {rows[0][2]} "
              f"({rows[0][2] / len(bs):.2f} a solve)")


if __name__ == "__main__":
    main()
