"""gatetherm's thermal-error models against a random forest and XGBoost on a measured run.

    benchmarks/setup_errormodel.sh            # once: /tmp/venv_bench with scikit-learn, xgboost, gatetherm
    /tmp/venv_bench/bin/python benchmarks/errormodel.py --data fl_thermal_0-80.csv [--test-data LATER.csv]

Splits, in percent of the *record* (``--covered``: the share of the record the file holds, 0.8 for
the shared FL_THERMAL file, the first 80 % of a 46-h record; its authors fit on the first 60 % and
test on the next 20 %): any ``A-B/C-D`` (fit on A..B %, test on C..D %); by default the three
forward-chaining splits of issue 56, ``0-40/40-60``, ``0-60/60-80`` (the protocol) and
``0-50/50-80``. With ``--test-data`` the models are also fitted on all of ``--data`` and tested on
that file. ``--no-peers`` runs gatetherm alone (the peers take minutes on shared cores).

Models, each fitted on the same rows and scored by MAE per channel on the test rows:
``no compensation`` (predicts 0), ``gatetherm`` (``gatetherm.errormodel_fit``'s default fit:
form auto, selection on the latest held-out blocks, input ``spindle_rpm``, at most 4 sensors),
``gatetherm static`` (temperatures only), and the peers of the
dataset's authors on the 16 absolute temperatures: ``rf raw``/``xgb raw``, and ``rf avg8``/``xgb avg8``
on those plus their means over the 8 previous samples (32 features; the first 8 rows of a file have
none).
Seeds are fixed (``random_state=0``); defaults otherwise (100 trees), 2 threads.
``--cv chain`` selects gatetherm's terms by forward chaining instead (docs/errormodel.md);
``--latest-score mean`` scores the candidates on the latest blocks by the mean of their forward-chaining
and blocked errors (not the default: docs/errormodel.md, "Issue 56: ch5 on 0-40 %").
``--peers-from benchmarks/results/errormodel.json`` takes the peers' figures of the same splits as
recorded there (where their environment is missing) and prints the checks against them.
``--smooth-s S`` fixes gatetherm's smoothing of the readings (no choice); ``--inner`` (with
``--no-peers``) fits on each fitting part's first 75 % and tests on its last 25 %: forward chaining
inside what the split lets a fit see.
The column ``in 90 %`` is the share of the test samples inside gatetherm's 90 % interval (as
``predict`` writes it, widened where the model extrapolates).
Prints the table, the acceptance checks of issue 56 and writes ``--json`` (default
``benchmarks/results/errormodel.json``) for ``gatetherm report``.
"""
from __future__ import annotations

import argparse
import dataclasses
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from peer import write_table  # noqa: E402  (the benchmarks' shared table writer)

from gatetherm.api.errormodel import ROBUST  # noqa: E402
from gatetherm.studies.errormodel.fit import fit_error_model  # noqa: E402
from gatetherm.studies.errormodel.model import predict  # noqa: E402
from gatetherm.studies.errormodel.trust import trust  # noqa: E402
from gatetherm.studies.run.timeseries import read_timeseries  # noqa: E402

TARGETS = tuple(f"ch{i}_um" for i in range(1, 6))
SENSORS = tuple(f"t{i}_degC" for i in range(1, 17))
#: The record's thermocouple noise (standard deviation of the second difference / sqrt 6: 0.009-0.012 K).
RESOLUTION_K = 0.01
SPLITS = ("0-40/40-60", "0-60/60-80", "0-50/50-80")
PEERS = ("rf raw", "xgb raw", "rf avg8", "xgb avg8")
PARAMS = dataclasses.replace(ROBUST, max_sensors=4, resolution_K=RESOLUTION_K)


def peer_features(ts, averaged: bool) -> tuple[np.ndarray, int]:
    """The authors' inputs: 16 absolute temperatures, with ``averaged`` also their means over the 8
    samples before each row; and the first usable row."""
    X = np.column_stack([ts[s] for s in SENSORS])
    if not averaged:
        return X, 0
    c = np.vstack([np.zeros((1, X.shape[1])), np.cumsum(X, axis=0)])
    avg = np.full_like(X, np.nan)
    avg[8:] = (c[8:-1] - c[:-9]) / 8.0
    return np.hstack([X, avg]), 8


def peer(name: str):
    if name.startswith("rf"):
        from sklearn.ensemble import RandomForestRegressor
        return RandomForestRegressor(n_estimators=100, random_state=0, n_jobs=2)
    from xgboost import XGBRegressor
    return XGBRegressor(random_state=0, n_jobs=2)


def run_peer(name, fit_ts, test_ts, first: int):
    """MAE per target on the rows of ``test_ts`` from ``first`` on (the averages take the 8 rows
    before them), sensors, fit and prediction time of one peer."""
    averaged = name.endswith("avg8")
    Xf, s = peer_features(fit_ts, averaged)
    Xt, st = peer_features(test_ts, averaged)
    rows = slice(max(first, st), None)
    maes, t_fit, t_pred = [], 0.0, 0.0
    for y in TARGETS:
        t0 = time.perf_counter()
        m = peer(name).fit(Xf[s:], fit_ts[y][s:])
        t1 = time.perf_counter()
        p = m.predict(Xt[rows])
        t_pred += time.perf_counter() - t1
        t_fit += t1 - t0
        maes.append(float(np.mean(np.abs(p - test_ts[y][rows]))))
    return maes, "16 all", t_fit, t_pred / len(p)


def run_gatetherm(inputs, fit_ts, test_ts, first: int):
    """MAE per target on the rows from ``first`` on, sensors, fit and prediction time of a gatetherm
    model. It predicts the whole of ``test_ts`` (its lags need the history before the test rows)."""
    t0 = time.perf_counter()
    model = fit_error_model(fit_ts, TARGETS, SENSORS, inputs, PARAMS)
    t1 = time.perf_counter()
    pred = predict(model, test_ts)
    t_pred = (time.perf_counter() - t1) / len(test_ts)
    maes = [float(np.nanmean(np.abs(pred[y][first:] - test_ts[y][first:]))) for y in TARGETS]
    band = trust(model, test_ts, pred)  # the 90 % interval as predict writes it (widened where it extrapolates)
    each = [(test_ts[y][first:] >= band[y]["lower"][first:]) & (test_ts[y][first:] <= band[y]["upper"][first:])
            for y in TARGETS]
    inside = np.concatenate(each)
    print(f"    in the 90 % interval: {inside.mean():.1%} of the test samples "
          f"(ch1 ... ch5: {', '.join(f'{v.mean():.1%}' for v in each)})")
    sensors = " ".join(f"{y[:3]}:" + ",".join(s.split("_")[0] for s in model.target(y).sensors) for y in TARGETS)
    for m in model.targets:
        print(f"    {m.target}: {m.form}, {', '.join(t.label for t in m.terms)}; held-out {m.held_out_mae_um:.2f} um")
    return maes, sensors, t1 - t0, t_pred, float(inside.mean())


def parse_split(text: str) -> tuple[float, float, float, float]:
    """``A-B/C-D`` in percent of the record -> fractions."""
    try:
        (a, b), (c, d) = (tuple(float(v) / 100 for v in half.split("-")) for half in text.split("/"))
    except ValueError:
        raise SystemExit(f"--splits: {text!r} is not A-B/C-D (percent of the record, e.g. 0-60/60-80)") from None
    if not 0 <= a < b <= c < d <= 1:
        raise SystemExit(f"--splits: {text!r}: need 0 <= A < B <= C < D <= 100")
    return a, b, c, d


def rows_between(ts, lo, hi):
    n = len(ts)
    return ts.slice(slice(round(lo * n), round(hi * n)))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--data", required=True,
                    help="the measured run (time_s, spindle_rpm, ch1_um..ch5_um, t1..t16_degC)")
    ap.add_argument("--covered", type=float, default=0.8, help="share of the record the file holds (default 0.8)")
    ap.add_argument("--splits", default=",".join(SPLITS), help=f"A-B/C-D,... in percent (default {','.join(SPLITS)})")
    ap.add_argument("--no-peers", action="store_true", help="run gatetherm only")
    ap.add_argument("--cv", choices=("blocked", "chain"), default=ROBUST.cv,
                    help="gatetherm's held-out error within the fitting span (default: the API's)")
    ap.add_argument("--latest-score", choices=("chain", "mean"), default=ROBUST.latest_score,
                    help="gatetherm's score on the latest blocks: forward chaining, or its mean with the blocked error")
    ap.add_argument("--test-data", help="also fit on all of --data and test on this file (a later part)")
    ap.add_argument("--smooth-s", type=float, metavar="S",
                    help="gatetherm's readings smoothed over S s, no choice (default: the API's choice)")
    ap.add_argument("--inner", action="store_true",
                    help="forward chaining inside each fitting part: fit on its first 75 %%, test on its last 25 %%")
    ap.add_argument("--peers-from", metavar="JSON",
                    help="take the peers' rows of these splits from a results file written with the peers (e.g. "
                         "benchmarks/results/errormodel.json), for the checks, instead of running them")
    ap.add_argument("--json", default=str(Path(__file__).resolve().parent / "results" / "errormodel.json"))
    args = ap.parse_args()
    global PARAMS
    PARAMS = dataclasses.replace(PARAMS, cv=args.cv, latest_score=args.latest_score)
    if args.smooth_s is not None:
        PARAMS = dataclasses.replace(PARAMS, smooth_s=args.smooth_s, smooth_grid_s=())
    if args.inner and not args.no_peers:
        raise SystemExit("--inner: gatetherm only (add --no-peers)")
    ts = read_timeseries(args.data, required=("time_s", "spindle_rpm", *TARGETS, *SENSORS))
    cases = []
    for name in [s for s in args.splits.split(",") if s]:
        a, b, c, d = (f / args.covered for f in parse_split(name))
        if d > 1 + 1e-9:
            raise SystemExit(f"--splits: {name} reaches beyond the file (it holds {args.covered:.0%} of the record)")
        if args.inner:  # the fitting part's first 75 % -> its last 25 %
            part = rows_between(ts, a, b)
            cut = round(0.75 * len(part))
            cases.append((f"{name} inner", part.slice(slice(0, cut)), part, cut))
            continue
        cases.append((name, rows_between(ts, a, b), rows_between(ts, 0.0, d), round(c * len(ts))))
    if args.test_data:
        later = read_timeseries(args.test_data, required=("time_s", "spindle_rpm", *TARGETS, *SENSORS))
        cases.append(("all/--test-data", ts, later, 0))
    columns = ["split", "model", *TARGETS, "mean", "sensors", "fit s", "predict us/sample", "in 90 %"]
    rows, notes = [], []
    for name, fit_ts, test_ts, first in cases:
        print(f"{name}: fit on {len(fit_ts)} samples, test on {len(test_ts) - first}")
        tail = test_ts.slice(slice(first, None))
        result = {"no compensation": ([float(np.mean(np.abs(tail[y]))) for y in TARGETS], "-", 0.0, 0.0, None)}
        for label, inputs in (("gatetherm", ("spindle_rpm",)), ("gatetherm static", ())):
            print(f"  {label}:")
            result[label] = run_gatetherm(inputs, fit_ts, test_ts, first)
        for p in () if args.no_peers or args.peers_from else PEERS:
            result[p] = (*run_peer(p, fit_ts, test_ts, first), None)
        if args.peers_from:
            result.update(recorded_peers(Path(args.peers_from), name))
        for label, (maes, sensors, t_fit, t_pred, inside) in result.items():
            rows.append([name, label, *[round(m, 2) for m in maes], round(float(np.mean(maes)), 2), sensors,
                         round(t_fit, 2), round(t_pred * 1e6, 2), "-" if inside is None else f"{inside:.1%}"])
        if all(p in result for p in PEERS):
            notes.append(check(name, result) + (f" (peers as recorded in {args.peers_from})" if args.peers_from else ""))
            print(notes[-1])
    notes.append(one_sample_latency(fit_error_model(ts, TARGETS, SENSORS, ("spindle_rpm",), PARAMS), ts))
    print(notes[-1])
    write_table(Path(args.json), columns, rows, notes)


def recorded_peers(path: Path, split: str) -> dict:
    """The peers' results of ``split`` as a results file of this script recorded them (seeds fixed:
    the same figures a run in their environment gives): label -> (MAE per target, sensors, fit s,
    predict s per sample, None)."""
    import json

    data = json.loads(path.read_text())
    col = {c: k for k, c in enumerate(data["columns"])}
    out = {r[col["model"]]: ([float(r[col[y]]) for y in TARGETS], r[col["sensors"]], float(r[col["fit s"]]),
                             float(r[col["predict us/sample"]]) * 1e-6, None)
           for r in data["rows"] if r[col["split"]] == split and r[col["model"]] in PEERS}
    if set(out) != set(PEERS):
        raise SystemExit(f"--peers-from {path}: no peers' rows for the split {split}")
    return out


def one_sample_latency(model, ts) -> str:
    """Median time of one ``predict`` call on a one-sample series (all five channels), one line."""
    one = ts.slice(slice(len(ts) - 1, None))
    times = []
    for _ in range(200):
        t0 = time.perf_counter()
        predict(model, one)
        times.append(time.perf_counter() - t0)
    return (f"one predict call on one sample, all {len(TARGETS)} channels: median {np.median(times) * 1e6:.0f} us "
            f"(200 calls; the bound is 1 ms)")


def check(name, result) -> str:
    """Issue 56's acceptance check on one split, one line: the mean at most 0.6 x the better peer's
    (the peer of the lowest mean), no channel worse than that peer's."""
    ours = np.array(result["gatetherm"][0])
    best = min(PEERS, key=lambda p: np.mean(result[p][0]))
    per_channel = np.array(result[best][0])
    ratio = ours.mean() / np.mean(result[best][0])
    ok = bool(np.all(ours <= per_channel)) and ratio <= 0.6
    worst = int(np.argmax(ours / per_channel))
    return (f"{name}: {'PASS' if ok else 'FAIL'}: gatetherm mean MAE {ours.mean():.2f} um = {ratio:.2f} x the best "
            f"peer's ({best}, {np.mean(result[best][0]):.2f} um; needed <= 0.6); channel by channel at most the best peer's: "
            f"{'yes' if np.all(ours <= per_channel) else 'no'} (closest {TARGETS[worst]}: {ours[worst]:.2f} vs "
            f"{per_channel[worst]:.2f} um)")


if __name__ == "__main__":
    main()
