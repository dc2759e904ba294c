"""Process settings of a command, measured: ``gatetherm simulate --condition 1 --dim 3`` with
one and with two BLAS threads (``GATETHERM_BLAS_THREADS``), or with and without numpy's
huge-page advice (``--huge-pages``: ``NUMPY_MADVISE_HUGEPAGE=1``, numpy's default, against
gatetherm's, off), or with glibc's malloc keeping freed memory for reuse (gatetherm's) and
returning it (``--malloc``: arrays of 4 MiB and more when freed, the heap trimmed past 64 MiB,
the settings before), interleaved.

    python benchmarks/blas_threads.py [--rounds 3] [--threads 1 2] [--huge-pages | --malloc] [--json FILE]

Prints the medians of wall time, CPU time, its system part, peak memory and page faults per
setting; the defaults of :func:`gatetherm.process.configure` are chosen from these tables
(docs/performance.md).
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

RETURNED = "BENCHMARK_MALLOC_RETURNED"
COMMAND = f"""import os, sys
import gatetherm.process as p
if os.environ.get({RETURNED!r}):  # configure's keep_freed(True) made keep_freed(False)
    p.keep_freed = lambda keep, made=p.keep_freed: made(False)
from gatetherm.cli import main
sys.exit(main(sys.argv[1:]))"""
"""The command, run as ``python -m gatetherm.cli`` runs it; with :data:`RETURNED` set, malloc as it was set before."""


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--threads", type=int, nargs="+", default=[1, 2])
    ap.add_argument("--huge-pages", action="store_true", help="numpy's huge-page advice on and off, one BLAS thread")
    ap.add_argument("--malloc", action="store_true", help="freed memory kept for reuse and returned, one BLAS thread")
    ap.add_argument("--json", type=Path)
    args = ap.parse_args()
    name = "huge_pages" if args.huge_pages else "malloc" if args.malloc else "blas_threads"
    settings = ({"huge pages advised": {"NUMPY_MADVISE_HUGEPAGE": "1"}, "not advised": {}} if args.huge_pages else
                {"freed memory returned": {RETURNED: "1"}, "kept": {}} if args.malloc else
                {f"{n} BLAS threads": {"GATETHERM_BLAS_THREADS": str(n)} for n in args.threads})
    env = {k: v for k, v in os.environ.items() if k not in ("NUMPY_MADVISE_HUGEPAGE", "GATETHERM_BLAS_THREADS")}
    work = Path(tempfile.mkdtemp(prefix="blas-"))
    atexit.register(shutil.rmtree, work, True)
    runs = {n: [] for n in settings}
    for r, n in interleaved(settings, args.rounds):
        cmd = [sys.executable, "-c", COMMAND, "simulate", "--condition", "1", "--dim", "3",
               "--out", str(work / f"r{r}-{len(runs[n])}")]
        res = rusage_run(cmd, env={**env, **settings[n]})
        res["faults"] /= 1e6
        runs[n].append(res)
        print(f"round {r + 1} {n}: wall {res['wall']:.1f} s, CPU {res['cpu']:.1f} s (system {res['sys']:.1f} s), "
              f"peak {res['rss_gb']:.2f} GB, {res['faults']:.2f} million page faults, load {os.getloadavg()[0]:.1f}",
              flush=True)
    rows = [[n, *(round(statistics.median(x[m] for x in v), 2) for m in ("wall", "cpu", "sys", "rss_gb", "faults"))]
            for n, v in runs.items()]
    write_table(args.json or HERE / "results" / f"{name}.json",
                ["setting", "wall s", "CPU s", "system s", "peak GB", "page faults, millions"],
                rows, [f"medians of {args.rounds} interleaved rounds of gatetherm simulate --condition 1 --dim 3"])


if __name__ == "__main__":
    main()
