"""Wall time of a 5-h condition on the reduced model against the full FE march, and of the reduction.

    python benchmarks/rom.py [--dim 2] [--states 30] [--repeats 51]

Builds the model and its reduced model (timed: assembly, Gramians, balancing), marches each
paper condition once on the full model (the peer) and ``repeats`` times on the reduced model
(300 one-minute steps, exact per-mode stepping, discretisation excluded) right after it, and
prints the medians, their ratio and the reduced run's ratio to the 10-ms target (< 1 meets it).
With ``--fine-step S`` it also runs each condition on the full model with S-second steps and
prints max |δ| differences at the 1-min samples: reduced model vs the 60-s FE run, reduced model
vs the fine run, and the 60-s vs the fine FE run (the FE's own time-stepping error).
"""
from __future__ import annotations

import argparse
import resource
import time

import numpy as np

from gatetherm.solvers.rom_time import discretise, march_rom
from gatetherm.frame.config import load_config
from gatetherm.frame.case import frame_case
from gatetherm.frame.conditions import condition_schedule
from gatetherm.studies.run.reduce import build_rom, check_run, series_inputs
from gatetherm.studies.run.scenario import ScenarioCache, run_scenario

TARGET_MS = 10.0


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--dim", type=int, default=2)
    ap.add_argument("--states", type=int, default=30)
    ap.add_argument("--repeats", type=int, default=51)
    ap.add_argument("--fine-step", type=float, metavar="S", help="also compare with FE runs of S-second steps")
    args = ap.parse_args()
    cfg, cache = load_config(), ScenarioCache()
    case = frame_case(cfg, args.dim)
    t0 = time.perf_counter()
    red = build_rom(case, args.states, cache)
    total = time.perf_counter() - t0
    parts = ", ".join(f"{k} {v:.1f} s" for k, v in red.seconds.items())
    print(f"{args.dim}-D: {red.basis.shape[0]} unknowns -> {red.rom.states} states in {total:.1f} s ({parts}); "
          f"peak RSS {resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1e6:.2f} GB")
    disc = discretise(red.rom, 60.0)
    print(f"{'cond':>4} {'FE march s':>10} {'rom ms':>8} {'FE/rom':>8} {'rom/target':>10}")
    for n in (1, 2, 3):
        fe = run_scenario(case, condition_schedule(n, cfg.supply), cache=cache)
        u, modes = series_inputs(red.rom, fe.result.columns)
        rom_s = []
        for _ in range(args.repeats):
            t = time.perf_counter()
            march_rom(disc, u, modes) @ red.rom.C.T
            rom_s.append(time.perf_counter() - t)
        ms = 1e3 * float(np.median(rom_s))
        print(f"{n:>4} {fe.result.seconds:>10.2f} {ms:>8.3f} {1e3 * fe.result.seconds / ms:>8.0f} {ms / TARGET_MS:>10.3f}")
        if args.fine_step:
            every = int(round(60.0 / args.fine_step))
            fine = run_scenario(case, condition_schedule(n, cfg.supply, args.fine_step), cache=cache)
            sub = {k: v[::every] for k, v in fine.result.columns.items()}
            coarse = fe.result.columns
            print(f"     max |δ| difference, µm: rom vs FE 60 s {check_run(red.rom, str(n), coarse).max_delta_error_um:.3f}, "
                  f"rom vs FE {args.fine_step:g} s {check_run(red.rom, str(n), sub).max_delta_error_um:.3f}, "
                  f"FE 60 s vs {args.fine_step:g} s {np.max(np.abs(coarse['delta_um'] - sub['delta_um'])):.3f}")


if __name__ == "__main__":
    main()
