"""The output-time fields of a 3-D run solved in two processes against one.

    python benchmarks/two_processes.py [--rounds 3]

A condition-1 run of ``gate_frame(dim=3)`` keeping the seven field and picture states (its elastic
solver AMG-CG in this process, not in a helper), then per
round, in turn: their displacements (``studies.run.output.displacements``: one AMG-CG call of
seven right-hand sides) with the later half solved by a forked copy of the solver
(``PCG._in_two``, as a command does) and all in this process (``gatetherm.solvers.iterative
.can_fork`` answering no), each from the same Galerkin start. Prints the medians, the
iterations and how far the two solutions lie apart (docs/performance.md, "2026-12-04").
"""
from __future__ import annotations

import argparse
import os
import statistics
import time

import numpy as np


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--rounds", type=int, default=3)
    args = ap.parse_args()
    import gatetherm as gt
    import gatetherm.process
    import gatetherm.solvers.iterative as iterative
    from gatetherm.process import can_fork
    from gatetherm.studies.run.output import displacements

    gt.configure()
    os.environ["GATETHERM_SPD_BACKEND"] = "amg"  # the elastic solver AMG-CG, set up here (no helper process),
    gatetherm.process.can_fork = lambda: False  # so that this process holds it
    try:
        run = gt.run(gt.gate_frame(dim=3), keep=[0.0, 780.0, 3600.0, 7200.0, 10800.0, 14400.0, 18000.0])
    finally:
        gatetherm.process.can_fork = can_fork
    model, result = run.scenario.model, run.scenario.result
    pcg = model.elastic.solve._solve
    start = pcg.kept
    times: dict[str, list[float]] = {"two processes": [], "one process": []}
    iterations, fields = {}, {}
    try:
        for r in range(args.rounds):
            for name in (("two processes", "one process") if r % 2 == 0 else ("one process", "two processes")):
                iterative.can_fork = can_fork if name == "two processes" else (lambda: False)
                pcg.seed(start)
                before = pcg.iterations
                t0 = time.perf_counter()
                u = dict(displacements(model, result.states, result.envs))  # each solved
                times[name].append(time.perf_counter() - t0)
                iterations[name] = pcg.iterations - before
                fields[name] = np.column_stack(list(u.values()))
    finally:
        iterative.can_fork = can_fork
    two, one = (statistics.median(times[k]) for k in ("two processes", "one process"))
    diff = np.abs(fields["two processes"] - fields["one process"]).max() / np.abs(fields["one process"]).max()
    print(f"{fields['one process'].shape[1]} fields of {fields['one process'].shape[0]} unknowns, "
          f"medians of {args.rounds} rounds:")
    for k in times:
        print(f"  {k:14s} {statistics.median(times[k]):6.2f} s  {iterations[k]} iterations  "
              f"(runs {', '.join(f'{t:.2f}' for t in times[k])})")
    print(f"two / one: {two / one:.2f} x; largest difference of the fields {diff:.1e} of their largest value")


if __name__ == "__main__":
    main()
