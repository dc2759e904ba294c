"""Wall time of the paper's conditions at the default mesh, in parts, against targets.

    python benchmarks/conditions.py [--dims 2 3] [--conditions 1 2 3]

Prints, per dimension and condition: meshing, assembly, elastic set-up,
adjoint solves, heat factorisations, time stepping (300 steps with δ every
step) and the total, and the ratio of the total to the target
(2-D: 15 s, 3-D: 90 s at ≥ 50 000 nodes; ratio < 1 meets it). Each condition
builds its own model through the scenario path, as one ``gatetherm simulate``
run does (writing files and pictures is not included).
"""
from __future__ import annotations

import argparse

from gatetherm.studies.run.config import load_config
from gatetherm.studies.run.scenario import condition_schedule, prepare
from gatetherm.studies.run.simulate import run_model

TARGET_S = {2: 15.0, 3: 90.0}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--dims", type=int, nargs="+", default=[2, 3])
    ap.add_argument("--conditions", type=int, nargs="+", default=[1, 2, 3])
    args = ap.parse_args()
    cfg = load_config()
    print(f"{'dim':>3} {'cond':>4} {'nodes':>7} {'mesh':>6} {'heat asm':>8} {'elastic':>8} "
          f"{'adjoint':>8} {'factor':>7} {'steps':>6} {'total':>7} {'ratio':>6}")
    for dim in args.dims:
        for c in args.conditions:
            schedule = condition_schedule(c, cfg)
            p = prepare(cfg, dim, schedule.drive)
            tm = p.model.timings
            res = run_model(p.model, p.drive, schedule.times, solver=p.solver)
            factor = p.solver.factor_seconds
            total = sum(tm.values()) + res.seconds
            print(f"{dim:>3} {c:>4} {len(p.model.fmesh.points):>7} {tm['mesh']:>6.2f} {tm['heat_assembly']:>8.2f} "
                  f"{tm['elastic_setup']:>8.2f} {tm['adjoint_solves']:>8.2f} {factor:>7.2f} "
                  f"{res.seconds - factor:>6.2f} {total:>7.2f} {total / TARGET_S[dim]:>6.2f}", flush=True)


if __name__ == "__main__":
    main()
