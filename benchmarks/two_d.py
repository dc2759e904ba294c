"""The 2-D default condition end to end, its pictures drawn by the painter against in turn.

    python benchmarks/two_d.py [--rounds 5]

Four variants of ``gatetherm simulate --condition 1 --out DIR``, each a fresh process, run in
turn ``--rounds`` times (interleaved: these 2 cores are shared): as shipped (the pictures drawn
by :class:`gatetherm.validation.plots.painter.Painter`'s two processes while the run computes
and writes), ``in turn`` (the same command in a process whose painter cannot fork: the pictures
drawn one after another after the fields, as before the painter), ``--no-pictures`` and ``no
gc.freeze`` (:func:`gatetherm.cli.main` called without :func:`gatetherm.cli.console`'s freeze:
the interpreter's collections on the way out). Prints
the wall-time medians, the ratios to ``in turn`` and whether the PNGs of the first two are the
same bytes (docs/performance.md, "The 2-D default condition").
"""
from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

CLI = "from gatetherm.cli import console; console()"
UNFROZEN = "import sys; from gatetherm.cli import main; sys.exit(main())"  # the collections on the way out
IN_TURN = "import gatetherm.validation.plots.painter as p; p._can_fork = lambda: False; " + CLI


def variants(work: Path) -> dict[str, list[str]]:
    args = ["simulate", "--condition", "1", "--out"]
    return {"painter": [sys.executable, "-c", CLI, *args, str(work / "painter")],
            "in turn": [sys.executable, "-c", IN_TURN, *args, str(work / "in_turn")],
            "no pictures": [sys.executable, "-c", CLI, *args, str(work / "none"), "--no-pictures"],
            "no gc.freeze": [sys.executable, "-c", UNFROZEN, *args, str(work / "unfrozen")]}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rounds", type=int, default=5)
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        runs = variants(work)
        seen = {name: [] for name in runs}
        for _ in range(args.rounds):
            for name, cmd in runs.items():
                t0 = time.perf_counter()
                subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
                seen[name].append(time.perf_counter() - t0)
        same = all((work / "painter" / p.name).read_bytes() == p.read_bytes() for p in (work / "in_turn").glob("*.png"))
    base = statistics.median(seen["in turn"])
    print(f"medians of {args.rounds} interleaved rounds, load {os.getloadavg()[0]:.2f} at the end:")
    for name, times in seen.items():
        med = statistics.median(times)
        print(f"  {name:12s} {med:.2f} s ({med / base:.2f} x in turn; runs {', '.join(f'{t:.2f}' for t in times)})")
    print(f"PNGs of the painter and in turn the same bytes: {same}")


if __name__ == "__main__":
    main()
