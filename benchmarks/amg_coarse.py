"""Where an AMG hierarchy stops coarsening: pyamg's 500 node blocks against gatetherm's
``max_coarse`` (√ of the blocks, if more), on the elastic and heat step systems of a large 3-D frame.

    python benchmarks/amg_coarse.py [--factor 25] [--rounds 1] [--solves 20]

Condition 1 of the 3-D frame, meshed for about ``--factor`` times the default nodes, is run as
``benchmarks/scaling.py`` does on the iterative path but in this one process, with the systems
and right-hand sides it solves recorded: the elastic system's (the read-out's adjoint batch, then
the output-time fields) and the most used heat step matrix's first ``--solves``. Then, per round
and system, a hierarchy with each coarsest-level bound (in turn, the order reversed every other
round) is built and the right-hand sides are solved in sequence as the run solves them (each
from the Galerkin projection onto the last solutions). Prints the levels, the medians of set-up
and solve seconds, the iterations, and how far the solutions lie apart (docs/performance.md).
"""
from __future__ import annotations

import argparse
import os
import statistics
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))


def recorded(factor: float, keep: int) -> dict[str, tuple]:
    """``{"elastic": (A, modes, block, rtol, [b]), "heat": (...)}``: the elastic system and the most
    used heat step system of a condition-1 run, with (at most ``keep`` of) their right-hand sides."""
    import gatetherm.process
    from gatetherm.solvers import iterative, linsolve
    from gatetherm.solvers.heat import HEAT_RTOL
    from scaling import job

    seen: dict = {}
    init, call = iterative.AMG.__init__, iterative.PCG.__call__

    def recording_init(self, A, near_null=None, block=1, *args, **kw):
        seen[id(A)] = (A, near_null, block, [])
        init(self, A, near_null, block, *args, **kw)

    def recording_call(self, b):
        rec = seen.get(id(self.amg.A))
        if rec is not None and len(rec[3]) < keep:
            rec[3].append(np.array(b, dtype=float))
        return call(self, b)

    os.environ["GATETHERM_SOLVER"] = "iterative"
    gatetherm.process.can_fork = lambda: False  # the elastic solves here, not in a helper: recorded
    iterative.AMG.__init__, iterative.PCG.__call__ = recording_init, recording_call
    try:
        job(3, factor)
    finally:
        iterative.AMG.__init__, iterative.PCG.__call__ = init, call
    elastic = next(r for r in seen.values() if r[1] is not None)
    heat = max((r for r in seen.values() if r[1] is None), key=lambda r: len(r[3]))
    return {"elastic": elastic[:3] + (linsolve.RTOL, elastic[3]), "heat": heat[:3] + (HEAT_RTOL, heat[3])}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--factor", type=float, default=25.0)
    ap.add_argument("--rounds", type=int, default=1)
    ap.add_argument("--solves", type=int, default=20)
    args = ap.parse_args()
    from gatetherm.solvers.iterative import AMG, PCG

    bounds = (500, None)  # None: gatetherm's
    for name, (A, modes, block, rtol, bs) in recorded(args.factor, args.solves).items():
        print(f"{name}: {A.shape[0]} unknowns, {sum(np.shape(b)[1] if np.ndim(b) == 2 else 1 for b in bs)} "
              f"right-hand sides in {len(bs)} calls", flush=True)
        res: dict = {m: [] for m in bounds}
        for r in range(args.rounds):
            for m in (bounds if r % 2 == 0 else bounds[::-1]):
                t0 = time.perf_counter()
                amg = AMG(A, modes, block, coarsest=m)
                t1 = time.perf_counter()
                pcg = PCG(A, rtol=rtol, amg=amg, split=False)
                xs = [pcg(b) for b in bs]
                res[m].append((t1 - t0, time.perf_counter() - t1, pcg.iterations, xs))
                print(f"  round {r + 1}, coarsest bound {m or 'gatetherm'}: levels {[lv.A.shape[0] for lv in amg.ml.levels]}, "
                      f"set-up {t1 - t0:.2f} s, solves {res[m][-1][1]:.2f} s, {pcg.iterations} iterations", flush=True)
        for m, rows in res.items():
            print(f"  bound {m or 'gatetherm'}: set-up {statistics.median(r[0] for r in rows):.2f} s, solves "
                  f"{statistics.median(r[1] for r in rows):.2f} s, iterations {rows[0][2]}")
        gap = max(float(np.abs(a - b).max() / np.abs(b).max()) for a, b in zip(res[500][0][3], res[None][0][3]))
        print(f"  largest difference of the solutions, relative to the largest value: {gap:.1e}", flush=True)


if __name__ == "__main__":
    main()
