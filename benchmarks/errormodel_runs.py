"""Error models on several simulated runs of one machine (issue 56): leave one run out, and noise.

    python benchmarks/errormodel_runs.py [--json benchmarks/results/errormodel_runs.json]

The machine is the test headstock (``tests/data/headstock``: a 2-D housing on a bed, front and
rear bearing losses) with thirteen thermocouples (its TH, TR, TB and ten more on the bed and the
housing) and its room temperature a schedule column. Five runs of 8 h, each of another duty
cycle and room (:data:`RUNS`), are simulated by ``gatetherm.run``. Then, for each run held out:

* ``gatetherm``: ``fit_error_model`` on the other four runs (each its own reference, leave one run
  out inside; at most 4 sensors, the bearing power ``front_W`` through lags, 0.05 K resolution),
  predicting the held-out run from its own start;
* ``fixed 6``: the best fixed set of 6 sensors chosen on *all five* runs (forward selection by
  leave-one-run-out error, so it has seen the held-out run), its coefficients least squares on the
  other four: the error a designer's six-sensor choice reaches at best;
* noise: the ``gatetherm`` model fitted on noise-free runs applied to the held-out run read with
  0.05 K on every thermocouple and 0.1 um on delta (5 draws), scored against the noise-free delta;
* measured: both fitted on the four runs read with that noise (one draw) and applied to the
  held-out run read with it (5 draws), scored against the noise-free delta (fixed 6 by plain least
  squares, as a designer fits it; its six sensors still chosen on all noise-free runs).

MAE (um) of delta (relative to the run's start) per held-out run and their mean, and the share of
the held-out run's measured delta (the 5 draws) inside the measured fit's 90 % interval (a duty
cycle and room the fit has not seen: how sure the model says it is, checked); prints the
acceptance checks: gatetherm's mean at most fixed 6's, and with noise at most 1.2 x without.
"""
from __future__ import annotations

import argparse
import dataclasses
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(Path(__file__).resolve().parent))
from peer import write_table  # noqa: E402

import gatetherm as gt  # noqa: E402
from gatetherm.studies.errormodel import select  # noqa: E402
from gatetherm.api.errormodel import ROBUST  # noqa: E402
from gatetherm.studies.errormodel.fit import _fit, fit_error_model  # noqa: E402
from gatetherm.studies.errormodel.model import predict  # noqa: E402
from gatetherm.studies.errormodel.trust import trust  # noqa: E402
from gatetherm.studies.run.timeseries import FORMAT, TimeSeries, write_timeseries  # noqa: E402

EXTRA = {"S1": (0.2, 0.12), "S2": (0.6, 0.2), "S3": (1.0, 0.1), "S4": (1.5, 0.15), "S5": (0.95, 0.3),
         "S6": (1.35, 0.3), "S7": (1.15, 0.5), "S8": (1.38, 0.5), "S9": (1.2, 0.4), "S10": (0.92, 0.5)}
SENSORS = ("theta_A_degC", "theta_B_degC", *(f"T_{p}_degC" for p in ("TR", *EXTRA)))
"""TH and TB are the case's signals theta_A and theta_B."""
HOURS = 8.0


def _room_and_duty(k: int, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    h = t / 3600.0
    front = [np.select([h < 2, h < 3, h < 5, h < 6], [60.0, 0.0, 90.0, 20.0], 60.0),
             np.select([h < 1, h < 4, h < 5], [90.0, 40.0, 0.0], 70.0),
             100.0 * h / HOURS,
             np.full(t.size, 30.0),
             np.where(np.floor(h) % 2 == 0, 80.0, 0.0)][k]
    room = [np.full(t.size, 20.0), np.full(t.size, 22.0), 20.0 + 2.0 * np.sin(2 * np.pi * h / 24.0),
            18.0 + 0.5 * h, np.where(h < 4, 21.0, 23.0)][k]
    return front, room


RUNS = ("duty 60/0/90/20/60 W, room 20 C", "duty 90/40/0/70 W, room 22 C", "duty ramp 0-100 W, room 20 C + 2 K daily",
        "duty 30 W, room 18 C rising 0.5 K/h", "duty 80/0 W hourly, room 21 C then 23 C")


def simulate(folder: Path) -> list[TimeSeries]:
    """The five runs (time, the thirteen temperatures, front_W, delta_um)."""
    src = ROOT / "tests" / "data" / "headstock"
    (folder / "headstock.geo").write_text((src / "headstock.geo").read_text())
    text = (src / "case.toml").read_text().replace('ambient = 20.0', 'ambient = "room_degC"')
    text += "".join(f"[probes.{p}]\npoint = [{x}, {y}]\nquantities = [\"T\"]\n" for p, (x, y) in EXTRA.items())
    text = text.replace('schedule = "schedule.csv"', 'schedule = "run0.csv"')
    t = np.arange(0.0, HOURS * 3600.0 + 1, 120.0)
    for k in range(len(RUNS)):
        front, room = _room_and_duty(k, t)
        write_timeseries(folder / f"run{k}.csv", TimeSeries({"time_s": t, "front_W": front, "rear_W": front * 25 / 60,
                                                            "room_degC": room}, {"format": FORMAT}))
    (folder / "case.toml").write_text(text)
    case = gt.load_case(folder / "case.toml")
    out = []
    for k in range(len(RUNS)):
        r = gt.run(case, gt.schedule_file(folder / f"run{k}.csv", case), keep=())
        out.append(TimeSeries({n: np.asarray(r[n]) for n in ("time_s", "front_W", *SENSORS, "delta_um")},
                              {"format": FORMAT}))
    return out


def truth(ts) -> np.ndarray:
    d = np.asarray(ts["delta_um"], float)
    return d - d[0]


def noisy(ts, seed: int) -> TimeSeries:
    rng = np.random.default_rng(seed)
    return ts.with_columns(**{s: ts[s] + rng.normal(0.0, 0.05, len(ts)) for s in SENSORS},
                           delta_um=ts["delta_um"] + rng.normal(0.0, 0.1, len(ts)))


def fixed_six(runs) -> tuple[str, ...]:
    """The six sensors a forward selection by leave-one-run-out error picks on all runs."""
    X = np.vstack([np.column_stack([np.asarray(r[s]) - r[s][0] for s in SENSORS]) for r in runs])
    y = np.concatenate([truth(r) for r in runs])
    Z = np.column_stack([np.ones(len(y)), X])
    edges = np.cumsum([0] + [len(r) for r in runs])
    cv = select.CrossValidation(Z, y, blocks=list(zip(edges[:-1], edges[1:])))
    cands = [select.Candidate(j, np.eye(Z.shape[1])[:, j + 1], frozenset((s,)), False) for j, s in enumerate(SENSORS)]
    path = select.forward(cv, cands, np.eye(Z.shape[1])[:, :1], 6, 0)
    return tuple(SENSORS[j] for j in path[6].chosen)


def fixed_mae(fit_runs, test_runs, sensors, clean) -> float:
    """MAE (um) on ``test_runs`` against the noise-free ``clean`` run's delta of least squares on the
    fixed ``sensors`` fitted on ``fit_runs``."""
    X = np.vstack([np.column_stack([np.ones(len(r))] + [np.asarray(r[s]) - r[s][0] for s in sensors])
                   for r in fit_runs])
    c = np.linalg.lstsq(X, np.concatenate([truth(r) for r in fit_runs]), rcond=None)[0]
    out = []
    for r in test_runs:
        p = np.column_stack([np.ones(len(r))] + [np.asarray(r[s]) - r[s][0] for s in sensors]) @ c
        out.append(np.mean(np.abs((p - p[0]) - truth(clean))))
    return float(np.mean(out))


def ours_mae(model, test_runs, clean) -> float:
    return float(np.mean([np.mean(np.abs(predict(model, r)["delta_um"] - truth(clean))) for r in test_runs]))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--json", default=str(ROOT / "benchmarks" / "results" / "errormodel_runs.json"))
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        runs = simulate(Path(tmp))
    six = fixed_six(runs)
    print(f"fixed 6 (chosen on all runs): {', '.join(six)}")
    params = dataclasses.replace(ROBUST, max_sensors=4)
    res = {key: [] for key in ("ours", "fixed", "dirty", "ours_m", "fixed_m", "inside")}
    rows = []
    measured = [noisy(r, 100 + k) for k, r in enumerate(runs)]
    for k, name in enumerate(RUNS):
        rest = [r for j, r in enumerate(runs) if j != k]
        draws = [noisy(runs[k], seed) for seed in range(5)]
        model = fit_error_model(rest, ["delta_um"], SENSORS, ("front_W",), params)
        m = model.target("delta_um")
        res["ours"].append(ours_mae(model, [runs[k]], runs[k]))
        res["fixed"].append(fixed_mae(rest, [runs[k]], six, runs[k]))
        res["dirty"].append(ours_mae(model, draws, runs[k]))
        noisy_model = fit_error_model([r for j, r in enumerate(measured) if j != k], ["delta_um"], SENSORS,
                                      ("front_W",), params)
        res["ours_m"].append(ours_mae(noisy_model, draws, runs[k]))
        res["fixed_m"].append(fixed_mae([r for j, r in enumerate(measured) if j != k], draws, six, runs[k]))
        res["inside"].append(float(np.mean([1.0 - trust(noisy_model, d)["delta_um"]["share_missed"] for d in draws])))
        print(f"held out {name}: gatetherm {res['ours'][-1]:.3f} um ({', '.join(t.label for t in m.terms)}; "
              f"90 % +-{m.interval['half_width_um']:.3f} um, held-out inside {m.interval['coverage']:.0%}), "
              f"fixed 6 {res['fixed'][-1]:.3f} um; with noise {res['dirty'][-1]:.3f} um; fitted and applied with "
              f"noise: gatetherm {res['ours_m'][-1]:.3f} um "
              f"({', '.join(s[:-5] for s in noisy_model.target('delta_um').sensors)}), "
              f"fixed 6 {res['fixed_m'][-1]:.3f} um; the held-out run's measured δ inside its 90 % interval "
              f"{res['inside'][-1]:.1%} (+-{noisy_model.target('delta_um').interval['half_width_um']:.3f} um)")
        rows.append([name, round(res["ours"][-1], 3), ", ".join(s[:-5] for s in m.sensors), round(res["fixed"][-1], 3),
                     round(res["dirty"][-1], 3), round(res["dirty"][-1] / res["ours"][-1], 2),
                     round(res["ours_m"][-1], 3), round(res["fixed_m"][-1], 3), f"{res['inside'][-1]:.1%}"])
    mean = {k: float(np.mean(v)) for k, v in res.items()}
    rows.append(["mean", round(mean["ours"], 3), "", round(mean["fixed"], 3), round(mean["dirty"], 3),
                 round(mean["dirty"] / mean["ours"], 2), round(mean["ours_m"], 3), round(mean["fixed_m"], 3),
                 f"{mean['inside']:.1%}"])
    six_names = ", ".join(s[:-5] for s in six)
    cost = {}  # a fit on four measured runs, with and without its intervals calibrated on each run as a new one
    for name, fit in (("without", lambda: _fit(measured[:4], ["delta_um"], SENSORS, ("front_W",), params, None)),
                      ("with", lambda: fit_error_model(measured[:4], ["delta_um"], SENSORS, ("front_W",), params))):
        times = []
        for _ in range(3):
            t0 = time.perf_counter()
            fit()
            times.append(time.perf_counter() - t0)
        cost[name] = float(np.median(times))
    notes = [f"leave one run out, noise-free: gatetherm (<= 4 sensors) mean {mean['ours']:.3f} um against the best "
             f"fixed 6 ({six_names}, chosen on all runs) {mean['fixed']:.3f} um: "
             f"{'PASS' if mean['ours'] <= mean['fixed'] else 'FAIL'}",
             f"leave one run out, fitted and applied with 0.05 K / 0.1 um noise: gatetherm {mean['ours_m']:.3f} um "
             f"against fixed 6 {mean['fixed_m']:.3f} um: {'PASS' if mean['ours_m'] <= mean['fixed_m'] else 'FAIL'}",
             f"noise 0.05 K / 0.1 um on a noise-free fit: mean {mean['dirty']:.3f} um = "
             f"{mean['dirty'] / mean['ours']:.2f} x noise-free (needed <= 1.2): "
             f"{'PASS' if mean['dirty'] <= 1.2 * mean['ours'] else 'FAIL'}",
             f"a fit on four runs: {cost['without']:.2f} s with the interval of the chosen model's own held-out "
             f"residuals, {cost['with']:.2f} s calibrated on each run as a new one (x{cost['with'] / cost['without']:.2f}; "
             "median of 3)"]
    for n in notes:
        print(n)
    write_table(Path(args.json), ["held-out run", "gatetherm um", "sensors", "fixed 6 um", "with noise um",
                                  "noise x", "noisy fit: gatetherm um", "noisy fit: fixed 6 um", "noisy fit: in 90 %"],
                rows, notes)


if __name__ == "__main__":
    main()
