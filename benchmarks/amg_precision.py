"""The AMG V-cycle in single against double precision, on the 3-D frame's elastic system.

    python benchmarks/amg_precision.py [--rounds 3]

A condition-1 run of ``gate_frame(dim=3)`` with its seven field states' displacements, the
elastic right-hand sides it solves recorded: the read-out's adjoint batch and the output-time
fields. Then, per round and precision in turn, the hierarchy built
(``gatetherm.solvers.iterative.AMG(..., single=...)``) and both batches solved by conjugate
gradients to the same tolerance, each from a cold start. Prints the medians of the set-up and
solve times, the iterations, the hierarchy's own memory and how far the solutions of the two
precisions lie apart (docs/performance.md).
"""
from __future__ import annotations

import argparse
import statistics
import time

import numpy as np


def recorded_systems():
    """(matrix, rigid-body modes, node block, [right-hand-side batches]) of the elastic system
    of a 3-D condition-1 run with its field displacements, as the run solves them (the
    thread pools configured as the commands do)."""
    import gatetherm as gt
    from gatetherm.solvers.linsolve import SPDSolver
    from gatetherm.studies.run.output import displacements

    gt.configure()
    seen: dict = {"batches": []}
    submit = SPDSolver.submit

    def recording(self, b):
        if self.what == "elastic system":
            seen.update(A=self._A, modes=seen.get("modes", self.near_null), block=self.block)
            seen["batches"].append(np.array(b, dtype=float, ndmin=2).reshape(len(b), -1))
        return submit(self, b)

    SPDSolver.submit = recording
    try:
        run = gt.run(gt.gate_frame(dim=3), keep=[0.0, 780.0, 3600.0, 7200.0, 10800.0, 14400.0, 18000.0])
        dict(displacements(run.scenario.model, run.scenario.result.states, run.scenario.result.envs))  # each solved
    finally:
        SPDSolver.submit = submit
    seen["A"] = seen["A"].result()  # made here if the helper made it
    return seen["A"], seen["modes"], seen["block"], seen["batches"]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--rounds", type=int, default=3)
    args = ap.parse_args()
    from gatetherm.solvers.iterative import AMG, PCG

    A, modes, block, batches = recorded_systems()
    print(f"elastic system: {A.shape[0]} unknowns; batches of {', '.join(str(b.shape[1]) for b in batches)} "
          "right-hand sides", flush=True)
    res: dict = {}
    for r in range(args.rounds):
        for single in ((True, False) if r % 2 == 0 else (False, True)):
            t0 = time.perf_counter()
            amg = AMG(A, modes, block, single=single)
            t1 = time.perf_counter()
            row = {"setup": t1 - t0, "bytes": amg.nbytes}
            sols, its = [], []
            for b in batches:
                pcg = PCG(A, amg=amg)
                t = time.perf_counter()
                sols.append(pcg(b))
                row[f"solve {b.shape[1]}"] = time.perf_counter() - t
                its.append(pcg.iterations)
            row["iterations"] = its
            res.setdefault(single, []).append((row, sols))
            print(f"round {r + 1} {'single' if single else 'double'}: set-up {row['setup']:.2f} s, "
                  + ", ".join(f"{k} {v:.2f} s" for k, v in row.items() if k.startswith("solve"))
                  + f", iterations {its}", flush=True)
    for single, rows in res.items():
        med = {k: statistics.median(r[k] for r, _ in rows) for k in rows[0][0] if k not in ("iterations",)}
        print(f"{'single' if single else 'double'}: " + ", ".join(
            f"{k} {v / 1e6:.1f} MB" if k == "bytes" else f"{k} {v:.2f} s" for k, v in med.items())
            + f", iterations {rows[0][0]['iterations']}")
    gap = max(float(np.abs(a - b).max() / np.abs(b).max())
              for a, b in zip(res[True][0][1], res[False][0][1]))
    print(f"largest difference of the solutions, relative to the largest value: {gap:.1e}")


if __name__ == "__main__":
    main()
