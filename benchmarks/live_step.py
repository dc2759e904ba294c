"""Wall time of one compensator step, as ``gatetherm live`` takes it every period: rom (Kalman update,
forecast over the horizon, the command) and a fitted error model.

    python benchmarks/live_step.py [--states 30]

Runs the C-frame case once (its schedule, 6 h), builds its reduced model, fits an error model on
the run, then steps each stepper over the 361 samples of the run and prints the median and the
95th percentile of one step (ms) against the issue's targets (rom < 2 ms, error model < 0.5 ms).
On a shared machine the percentile also measures the other processes: stalls of ~10 ms every few
steps that are not the garbage collector (the same with it off) but the scheduler.
Writes benchmarks/results/live_step.json.
"""
from __future__ import annotations

import argparse
import json
import platform
import time
from pathlib import Path

import numpy as np

import gatetherm as gt
from gatetherm.studies.control.compensator import CompensatorParams, controller_grid
from gatetherm.studies.control.predictive import PredictiveParams
from gatetherm.studies.control.stepwise import error_model_stepper
from gatetherm.studies.control.stepwise_rom import RomStepper
from gatetherm.studies.errormodel.fit import FitParams, fit_error_model

CASE = Path(__file__).resolve().parents[1] / "validation" / "examples" / "c_frame" / "case.toml"
TARGETS_MS = {"rom": 2.0, "errormodel": 0.5}


def timed(stepper, ts) -> np.ndarray:
    cols = ts.columns
    out = []
    for c, t in enumerate(ts.time_s):
        sample = {k: cols[k][c] for k in cols}
        t0 = time.perf_counter()
        stepper.step(float(t), sample)
        out.append(time.perf_counter() - t0)
    return 1e3 * np.array(out)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--states", type=int, default=30)
    args = ap.parse_args()
    case = gt.load_case(CASE)
    params = CompensatorParams()
    ts = gt.run(case, keep=()).scenario.series({})
    ts = controller_grid(ts, params, extra=("spindle_W", "ambient_degC"))[0]
    rom = gt.reduce(case, args.states).rom
    model = fit_error_model(ts, ("delta_um",), inputs=("spindle_W",), params=FitParams(form="dynamic"))
    steppers = {"rom": RomStepper(rom, ts, params, PredictiveParams()),
                "errormodel": error_model_stepper(model, "delta_um", params)}
    results = {}
    for name, stepper in steppers.items():
        ms = timed(stepper, ts)
        results[name] = {"median_ms": float(np.median(ms)), "p95_ms": float(np.percentile(ms, 95)),
                         "max_ms": float(ms.max()), "steps": int(ms.size), "target_ms": TARGETS_MS[name]}
        r = results[name]
        print(f"{name:>10}: one step median {r['median_ms']:.3f} ms, 95th percentile {r['p95_ms']:.3f} ms, "
              f"max {r['max_ms']:.3f} ms over {r['steps']} steps (target < {r['target_ms']:g} ms: median "
              f"{'met' if r['median_ms'] < r['target_ms'] else 'NOT met'}, 95th percentile "
              f"{'met' if r['p95_ms'] < r['target_ms'] else 'NOT met'})")
    results["machine"] = {"python": platform.python_version(), "processor": platform.processor() or platform.machine(),
                          "rom_states": args.states}
    out = Path(__file__).parent / "results" / "live_step.json"
    out.write_text(json.dumps(results, indent=2) + "\n")
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
