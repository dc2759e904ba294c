"""BLAS threads of a command, measured: ``gatetherm simulate --condition 1 --dim 3`` with
one and with two BLAS threads (``GATETHERM_BLAS_THREADS``), interleaved.

    python benchmarks/blas_threads.py [--rounds 3] [--threads 1 2] [--json FILE]

Prints the medians of wall time, CPU time and peak memory per thread count; the default of
``gatetherm.process.BLAS_THREADS`` is chosen from this table (docs/performance.md).
"""
from __future__ import annotations

import argparse
import atexit
import os
import shutil
import statistics
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
from peer import interleaved, rusage_run, write_table  # noqa: E402  (benchmarks/ is not a package)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--threads", type=int, nargs="+", default=[1, 2])
    ap.add_argument("--json", type=Path, default=HERE / "results" / "blas_threads.json")
    args = ap.parse_args()
    work = Path(tempfile.mkdtemp(prefix="blas-"))
    atexit.register(shutil.rmtree, work, True)
    runs = {n: [] for n in args.threads}
    for r, n in interleaved(args.threads, args.rounds):
        cmd = [sys.executable, "-m", "gatetherm.cli", "simulate", "--condition", "1", "--dim", "3",
               "--out", str(work / f"r{r}-t{n}")]
        res = rusage_run(cmd, env=dict(os.environ, GATETHERM_BLAS_THREADS=str(n)))
        runs[n].append(res)
        print(f"round {r + 1} threads {n}: wall {res['wall']:.1f} s, CPU {res['cpu']:.1f} s, "
              f"peak {res['rss_gb']:.2f} GB, load {os.getloadavg()[0]:.1f}", flush=True)
    rows = [[n, *(round(statistics.median(x[m] for x in v), 2) for m in ("wall", "cpu", "rss_gb"))]
            for n, v in runs.items()]
    write_table(args.json, ["BLAS threads", "wall s", "CPU s", "peak GB"], rows,
                [f"medians of {args.rounds} interleaved rounds of gatetherm simulate --condition 1 --dim 3"])


if __name__ == "__main__":
    main()
