"""The elastic AMG hierarchy made by pyamg's solver against gatetherm's level-by-level build.

    python benchmarks/amg_setup.py [--rounds 3]

The 3-D frame's elastic system and the right-hand sides a condition-1 run solves with it
(``amg_precision.recorded_systems``). Per round, in turn: the hierarchy of
``gatetherm.solvers.iterative.AMG`` made by pyamg's ``smoothed_aggregation_solver`` with its
energy minimisation (``smooth="energy"``) and by ``gatetherm.solvers.aggregation.hierarchy``
(the default), once timed and once under tracemalloc (the set-up's peak above its start), then
every batch solved by conjugate gradients from a cold start. Prints the medians, the
iterations, and how far the two hierarchies' prolongators lie apart (docs/performance.md).
"""
from __future__ import annotations

import argparse
import statistics
import time
import tracemalloc

from amg_precision import recorded_systems


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--rounds", type=int, default=3)
    args = ap.parse_args()
    from gatetherm.solvers.iterative import AMG, PCG
    from gatetherm.solvers.linsolve import RTOL

    A, modes, block, batches = recorded_systems()
    print(f"elastic system: {A.shape[0]} unknowns, {len(batches)} batches", flush=True)
    ways = {"pyamg": {"smooth": "energy"}, "gatetherm": {}}
    res: dict = {w: [] for w in ways}
    made = {}
    for r in range(args.rounds):
        for way in (list(ways) if r % 2 == 0 else list(ways)[::-1]):
            t0 = time.perf_counter()
            amg = AMG(A, modes, block, **ways[way])
            setup = time.perf_counter() - t0
            del amg
            tracemalloc.start()
            amg = AMG(A, modes, block, **ways[way])
            peak = tracemalloc.get_traced_memory()[1]
            tracemalloc.stop()
            pcg = PCG(A, modes, block, RTOL, amg=amg, split=False)
            t0 = time.perf_counter()
            for b in batches:
                pcg(b if b.shape[1] > 1 else b[:, 0])
            solve = time.perf_counter() - t0
            res[way].append({"setup": setup, "peak": peak / 1e6, "solve": solve, "its": pcg.iterations})
            made[way] = amg
            print(f"round {r + 1} {way}: set-up {setup:.2f} s, peak {peak / 1e6:.0f} MB above its start, "
                  f"{pcg.iterations} iterations in {solve:.2f} s", flush=True)
    med = {way: {k: statistics.median(v[k] for v in runs) for k in ("setup", "peak", "solve")}
           for way, runs in res.items()}
    for way, m in med.items():
        print(f"{way}: set-up {m['setup']:.2f} s, peak {m['peak']:.0f} MB, solves {m['solve']:.2f} s, "
              f"iterations {sorted({v['its'] for v in res[way]})}, hierarchy {made[way].nbytes / 1e6:.1f} MB")
    for k, (a, b) in enumerate(zip(made["pyamg"].ml.levels[:-1], made["gatetherm"].ml.levels[:-1])):
        Pa, Pb = a.P.astype(float).tocsr(), b.P.astype(float).tocsr()
        print(f"level {k}: P {Pa.shape[0]} × {Pa.shape[1]}, {Pa.nnz} and {Pb.nnz} nonzeros, apart by "
              f"{abs(Pa - Pb).max() / abs(Pa).max():.1e} (relative to the largest)")
    ours, theirs = med["gatetherm"], med["pyamg"]
    print(f"gatetherm / pyamg: set-up {ours['setup'] / theirs['setup']:.2f} ×, peak {ours['peak'] / theirs['peak']:.2f} ×")


if __name__ == "__main__":
    main()
