"""Selection rules of the error model's latest-blocks choice compared on the same candidates (issue 56).

    python benchmarks/errormodel_rules.py --data fl_thermal_0-80.csv [--origins 0.75] [--simulated]

For each split of ``benchmarks/errormodel.py`` (fit on A..B % of the record, test on C..D %) and for
each *inner* split (fit on the first ``origin`` of the fitting part, test on the rest of it: fitting
data only), the default fit (``ROBUST``, the benchmark's settings) is made with the readings as they
are and smoothed over 300 s; every model its latest-blocks rule chooses from (``fit._latest``'s pool,
recorded as the fit runs) is scored by its forward-chaining error, its blocked error and its MAE on
the test rows. Then each rule picks, from the same pools, the fewest terms within ``min_gain`` of its
lowest score, and the smoothing of the lowest score summed over the channels (``joint``, the default)
or per channel: ``chain`` (the default), ``mean`` (``latest_score="mean"``), ``geo``, ``blocked``, ``max``.
Prints per rule the test MAE (ch5 and the mean) of each split and the inner mean per split and over
all. ``--simulated``: the same rules on the five simulated runs of ``benchmarks/errormodel_runs.py``
(0.05 K / 0.1 um of noise, fit on each run's first 60 %, test on its last 40 % against the noise-free
delta). docs/errormodel.md, "Issue 56: ch5 on 0-40 and the rules tried", gives the figures.
"""
from __future__ import annotations

import argparse
import contextlib
import dataclasses
import logging
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import errormodel as bench  # noqa: E402

from gatetherm.studies.errormodel import fit as fitmod, select  # noqa: E402
from gatetherm.studies.errormodel.tune import held_out, variances  # noqa: E402
from gatetherm.studies.run.timeseries import read_timeseries  # noqa: E402

log = logging.getLogger("errormodel_rules")
SMOOTHINGS = (0.0, 300.0)
SCORES = {"chain": lambda c, b: c, "mean": lambda c, b: (c + b) / 2, "geo": lambda c, b: float(np.sqrt(c * b)),
          "blocked": lambda c, b: b, "max": max}


@contextlib.contextmanager
def recording_pools(into: list):
    """Record the arguments of every ``fit._latest`` call (the pool of one target) while the fit runs."""
    original = fitmod._latest

    def spy(pool, data, y_all, rows, params):
        into.append((pool, data, y_all, rows, params))
        return original(pool, data, y_all, rows, params)

    fitmod._latest = spy
    try:
        yield into
    finally:
        fitmod._latest = original


def scored_pools(fit_ts, test_ts, first: int, targets, sensors, inputs, params, truth=None) -> list[dict]:
    """Every candidate of every target's pool, per smoothing: forward-chaining and blocked error and
    MAE on the rows of ``test_ts`` from ``first`` on (``test_ts`` starts where ``fit_ts`` does; the
    terms are evaluated on it with the fit's reference). ``truth``: per target the values to score
    against (default the target columns of ``test_ts``)."""
    out = []
    t_fit = np.asarray(fit_ts["time_s"])
    for s in SMOOTHINGS:
        calls = []
        p = dataclasses.replace(params, smooth_s=s, smooth_grid_s=())
        with recording_pools(calls):
            fitmod.fit_error_model(test_ts, targets, sensors, inputs, p, span=(t_fit[0], t_fit[-1]))
        for y, (pool, data, y_all, rows, prm) in zip(targets, calls):
            measured = np.asarray(test_ts[y] if truth is None else truth[y], float)[first:]
            for form, models in pool.items():
                for terms in models:
                    X = np.column_stack([np.ones(data.time.size)] + [data.column(t) for t in terms])
                    var, eye = variances(terms, data, prm), np.eye(X.shape[1])
                    err = {cv: held_out(X[rows], y_all[rows], data, rows, dataclasses.replace(prm, cv=cv),
                                        var).error(eye) for cv in ("chain", "blocked")}
                    c = select.noisy_least_squares(X[rows], y_all[rows], var)
                    out.append({"smooth": s, "target": y, "form": form, "n": len(terms), **err,
                                "test": float(np.nanmean(np.abs(X[first:] @ c - measured)))})
    return out


def apply_rule(rows: list[dict], targets, score, per_channel: bool, min_gain: float = 0.03) -> dict:
    """Per target the candidate a rule keeps (module docstring)."""
    def pick(cands):
        v = [score(c["chain"], c["blocked"]) for c in cands]
        ok = [(c["n"], i) for i, c in enumerate(cands) if v[i] <= min(v) * (1 + min_gain)]
        return cands[min(ok)[1]]

    kept = {s: {y: pick([c for c in rows if c["smooth"] == s and c["target"] == y]) for y in targets}
            for s in SMOOTHINGS}
    value = {s: {y: score(kept[s][y]["chain"], kept[s][y]["blocked"]) for y in targets} for s in SMOOTHINGS}
    if per_channel:
        return {y: kept[min(SMOOTHINGS, key=lambda s: value[s][y])][y] for y in targets}
    return kept[min(SMOOTHINGS, key=lambda s: sum(value[s].values()))]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--data", required=True, help="the FL_THERMAL file of benchmarks/errormodel.py")
    ap.add_argument("--covered", type=float, default=0.8)
    ap.add_argument("--origins", default="0.75", help="inner origins, fractions of each fitting part (default 0.75)")
    ap.add_argument("--simulated", action="store_true", help="also the five simulated headstock runs")
    args = ap.parse_args()
    logging.basicConfig(level=logging.WARNING)
    ts = read_timeseries(args.data, required=("time_s", "spindle_rpm", *bench.TARGETS, *bench.SENSORS))
    origins = [float(v) for v in args.origins.split(",")]
    cases = {}
    for name in bench.SPLITS:
        a, b, c, d = (f / args.covered for f in bench.parse_split(name))
        part = bench.rows_between(ts, a, b)
        args_ = (bench.TARGETS, bench.SENSORS, ("spindle_rpm",), bench.PARAMS)
        cases[name] = scored_pools(part, bench.rows_between(ts, 0.0, d), round(c * len(ts)), *args_)
        for o in origins:
            cut = round(o * len(part))
            cases[f"{name} inner {o:g}"] = scored_pools(part.slice(slice(0, cut)), part, cut, *args_)
    for rule in SCORES:
        for per_channel in (False, True):
            kept = {k: apply_rule(v, bench.TARGETS, SCORES[rule], per_channel) for k, v in cases.items()}
            mae = {k: [v[y]["test"] for y in bench.TARGETS] for k, v in kept.items()}
            outer = "  ".join(f"{n}: ch5 {mae[n][-1]:5.2f} mean {np.mean(mae[n]):5.2f}" for n in bench.SPLITS)
            inner = [k for k in cases if " inner " in k]
            by_split = "  ".join(f"{n}: {np.mean([np.mean(mae[k]) for k in inner if k.startswith(n)]):5.2f}"
                                 for n in bench.SPLITS)
            print(f"{rule:7s} {'per channel' if per_channel else 'joint':11s} | {outer} | inner {by_split}  all "
                  f"{np.mean([mae[k] for k in inner]):.3f}")
    if args.simulated:
        simulated()


def simulated() -> None:
    """The rules on the five simulated headstock runs (module docstring), one line per rule."""
    import tempfile

    import errormodel_runs as sim

    with tempfile.TemporaryDirectory() as tmp:
        runs = sim.simulate(Path(tmp))
    params = dataclasses.replace(bench.ROBUST, max_sensors=4, resolution_K=0.05)
    pools = []
    for k, clean in enumerate(runs):
        ts = sim.noisy(clean, k)
        t = np.asarray(ts["time_s"])
        first = int(np.searchsorted(t, t[0] + 0.6 * (t[-1] - t[0]), side="right"))
        pools.append(scored_pools(ts.slice(slice(0, first)), ts, first, ("delta_um",), sim.SENSORS, ("front_W",),
                                  params, truth={"delta_um": clean["delta_um"]}))
    for rule, score in SCORES.items():
        maes = [apply_rule(p, ("delta_um",), score, False)["delta_um"]["test"] for p in pools]
        print(f"simulated runs, {rule:7s}: mean {np.mean(maes):.4f} um ({', '.join(f'{v:.3f}' for v in maes)})")


if __name__ == "__main__":
    main()
