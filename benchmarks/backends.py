"""The sparse backends of ``gatetherm.solvers.linsolve`` on the 3-D frame, interleaved.

    python benchmarks/backends.py [--rounds 3] [--backends pardiso superlu amg] [--json FILE]

Runs the equal-work job of ``benchmarks/peer.py`` (the peer problem on the default 3-D mesh:
300 backward-Euler heat steps, one thermoelastic solve) in a fresh process per backend and
round, the backend forced by ``GATETHERM_SPD_BACKEND``, the order rotating each round; prints
the medians of each part, the wall time and the peak memory, and δ (equal to the printed
digits for every backend). ``superlu`` factors the heat matrix and, above
``DIRECT_LIMIT_3D`` elastic DOFs, solves elasticity by AMG-CG as it does without a Cholesky
backend; ``amg`` forces AMG-CG for elasticity with the best direct heat solver; ``cholmod``
needs cvxopt (GPL-3, not a dependency).
"""
from __future__ import annotations

import argparse
import atexit
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
from peer import interleaved, peer_case, rusage_run, write_table  # noqa: E402  (benchmarks/ is not a package)

PARTS = ("heat_assembly", "heat_factor", "heat_steps", "elastic_setup", "elastic_solve")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--backends", nargs="+", default=["pardiso", "superlu", "amg"])
    ap.add_argument("--json", type=Path, default=HERE / "results" / "backends.json")
    args = ap.parse_args()
    work = Path(tempfile.mkdtemp(prefix="backends-"))
    atexit.register(shutil.rmtree, work, True)
    subprocess.run([sys.executable, "-m", "gatetherm.cli", "mesh", "--dim", "3", "--out", str(work)],
                   check=True, stdout=subprocess.DEVNULL)
    from gatetherm.geometry.mesh import load_mesh

    (work / "peer.toml").write_text(peer_case(load_mesh(work / "mesh.msh").regions))
    runs = {b: [] for b in args.backends}
    for r, b in interleaved(args.backends, args.rounds):
        env = dict(os.environ, **{"GATETHERM_SPD_BACKEND": b})
        res = rusage_run([sys.executable, str(HERE / "peer.py"), "--equal", str(work / "peer.toml")], env=env)
        runs[b].append(res)
        print(f"round {r + 1} {b:8s} wall {res['wall']:6.1f} s  peak {res['rss_gb']:.2f} GB  "
              f"delta {res['delta_um']:.6f} um", flush=True)
    rows = [[b, *(round(statistics.median(x[p] for x in v), 2) for p in (*PARTS, "wall", "rss_gb")),
             f"{v[-1]['delta_um']:.6f}"] for b, v in runs.items()]
    write_table(args.json, ["backend", *PARTS, "wall s", "peak GB", "delta um"], rows,
                [f"medians of {args.rounds} interleaved rounds, s; the peer problem of benchmarks/peer.py"])


if __name__ == "__main__":
    main()
