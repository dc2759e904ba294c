"""How the cost of a condition grows with the mesh: time per part and peak memory, per solver path.

    python benchmarks/scaling.py [--dims 3 2] [--factors 1 2 4 8] [--big] [--paths direct iterative]
                                 [--rounds 1] [--json FILE]

For each dimension, node factor f and solver path, condition 1 of the paper (5 h, 60-s steps)
runs in a fresh process on the default frame meshed with the element size divided by
f^(1/dim), so that the node count grows about f-fold: meshing, heat assembly, elastic set-up,
adjoint solves (the δ and θ read-out), heat step set-up (factors or AMG hierarchies), time
stepping, and the elastic solves of the six output times (one batch, as ``gatetherm simulate``
does); files and pictures are not included. The path is forced with ``GATETHERM_SOLVER``
(``direct``: sparse Cholesky factors; ``iterative``: AMG-preconditioned CG; ``auto``: as a
command chooses, :mod:`gatetherm.solvers.plan`); 3-D runs both, 2-D only ``auto``. ``--big``
adds the factor 25 in 3-D (1.05 million nodes, 20 × the default: the node count grows as f^0.93;
iterative only, its factors would not fit).
Peak memory is the process's (``wait4``); δ's first peak and swing are printed so that the
paths can be compared. With ``--rounds N`` the sizes are run N times in turn and medians are
printed. Last, the fitted growth exponent of each part, of the total and of the peak memory
per path: the slope of log(value) against log(nodes), least squares over the sizes.

The table is also written to ``--json`` (default ``benchmarks/results/scaling.json``),
which ``gatetherm report`` shows.
"""
from __future__ import annotations

import argparse
import json
import os
import statistics
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
from peer import rusage_run, write_table  # noqa: E402  (benchmarks/ is not a package)

PARTS = ("mesh", "heat_assembly", "elastic_setup", "adjoint_solves", "heat_factor", "steps", "output_solves")
DEFAULT_SIZE = {2: "size", 3: "size_3d"}
BIG = 25.0
"""The ``--big`` factor (3-D, iterative path): 1.05 million nodes, 20 × the default (the node count grows as
f^0.93 of the factor f: 0.78 million at 20)."""


def mesh_file(dim: int, factor: float, folder) -> tuple[Path, float]:
    """A configuration file in ``folder`` meshing the ``dim``-D frame with about ``factor`` × the
    default nodes (the element size divided by factor^(1/dim)), and that element size (m)."""
    from gatetherm.frame.geometry import MeshParams

    key = DEFAULT_SIZE[dim]
    size = getattr(MeshParams(), key) / factor ** (1.0 / dim)
    path = Path(folder) / "mesh.toml"
    path.write_text(f"[mesh]\n{key} = {size!r}\n")
    return path, size


def job(dim: int, factor: float) -> dict:
    """Condition 1 on the refined mesh; part times (s) and node counts."""
    from gatetherm.process import configure
    from gatetherm.frame.config import load_config
    from gatetherm.studies.run.output import displacements
    from gatetherm.frame.case import frame_case
    from gatetherm.studies.run.scenario import prepare
    from gatetherm.studies.run.simulate import delta_figures, run_model

    configure()  # the process settings of a command
    with tempfile.TemporaryDirectory() as tmp:
        path, size = mesh_file(dim, factor, tmp)
        cfg = load_config(path)
        t = time.perf_counter()
        case = frame_case(cfg, dim)  # meshed (gmsh, in a process of its own)
        mesh_s = time.perf_counter() - t
        schedule = case.schedule
        p = prepare(case)
        out_times = schedule.times[::60]
        res = run_model(p.model, schedule.drive, schedule.times, keep_times=out_times, solver=p.solver,
                        solve_at=out_times)  # as ``simulate``: beside the march where a helper solves
        model, factor_s = p.model, p.solver.factor_seconds
        del p  # the heat factors go, as in ``simulate``, before the output-time elastic solves
        t = time.perf_counter()
        dict(displacements(model, res.states, res.envs, res.solved))  # each waited for (or solved here)
        parts = dict(model.timings, mesh=mesh_s, heat_factor=factor_s, steps=res.seconds - factor_s,
                     output_solves=time.perf_counter() - t)
    el = model.elastic
    figs = delta_figures(res.columns["time_s"], res.columns["delta_um"])
    return {"nodes": len(model.fmesh.points), "elastic_dofs": 0 if el is None else len(el.free),
            "size_m": size, **{k: round(parts[k], 3) for k in PARTS},
            "first_peak_um": figs["first_peak_um"], "swing_um": figs["swing_um"]}


def exponent(nodes, seconds) -> float:
    """Slope of log(seconds) against log(nodes)."""
    return float(np.polyfit(np.log(nodes), np.log(np.maximum(seconds, 1e-3)), 1)[0])


def write(runs: dict, rounds: int, out: Path) -> None:
    """The table of the jobs run so far (medians, fitted exponents) printed and written to ``out``."""
    runs = {k: v for k, v in runs.items() if v}
    columns = ["dim", "path", "nodes", "elastic DOFs", *PARTS, "total s", "wall s", "CPU s", "system s", "peak GB",
               "first peak um", "swing um"]
    rows, notes = [], []
    for d, path in dict.fromkeys((d, path) for d, path, _ in runs):
        keys = [k for k in runs if k[:2] == (d, path)]
        med = [{k: statistics.median(x[k] for x in runs[key]) for k in (*PARTS, "wall", "cpu", "sys", "rss_gb")}
               | {k: runs[key][0][k] for k in ("nodes", "elastic_dofs", "first_peak_um", "swing_um")} for key in keys]
        for m in med:
            rows.append([d, path, m["nodes"], m["elastic_dofs"], *(round(m[k], 2) for k in PARTS),
                         round(sum(m[k] for k in PARTS), 2), round(m["wall"], 1), round(m["cpu"], 1), round(m["sys"], 1), round(m["rss_gb"], 2),
                         m["first_peak_um"], m["swing_um"]])
        if len(med) > 1:
            n = [m["nodes"] for m in med]
            fits = {k: exponent(n, [m[k] for m in med]) for k in (*PARTS, "wall", "cpu", "sys", "rss_gb")}
            rows.append([d, path, "exponent", "", *(f"{fits[k]:.2f}" for k in PARTS),
                         f"{exponent(n, [sum(m[k] for k in PARTS) for m in med]):.2f}",
                         f"{fits['wall']:.2f}", f"{fits['cpu']:.2f}", f"{fits['sys']:.2f}", f"{fits['rss_gb']:.2f}", "", ""])
    notes.append(f"medians of {rounds} round(s); times in s; 'exponent': slope of log(part) against "
                 "log(nodes); condition 1 (5 h, 300 steps of 60 s), six output-time elastic solves, no files; "
                 "path: GATETHERM_SOLVER of the run; CPU s: the job process's user + system time (wait4), the figure "
                 "to read when the shared cores are loaded; system s: its system part (on a virtual machine whose "
                 "host takes back freed memory, mostly the first touch of new memory: docs/performance.md)")
    write_table(out, columns, rows, notes)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--dims", type=int, nargs="+", default=[3, 2])
    ap.add_argument("--factors", type=float, nargs="+", default=[1, 2, 4, 8])
    ap.add_argument("--big", action="store_true", help=f"add the factor {BIG:g} in 3-D (about a million nodes, iterative)")
    ap.add_argument("--paths", nargs="+", default=["direct", "iterative"], choices=["direct", "iterative", "auto"],
                    help="3-D solver paths (2-D runs auto)")
    ap.add_argument("--rounds", type=int, default=1)
    ap.add_argument("--json", type=Path, default=HERE / "results" / "scaling.json")
    ap.add_argument("--job", nargs=2, type=float, metavar=("DIM", "FACTOR"), help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.job:
        print(json.dumps(job(int(args.job[0]), args.job[1])))
        return
    runs = {(d, path, f): [] for d in args.dims for path in (args.paths if d == 3 else ["auto"])
            for f in [*args.factors, *([BIG] if args.big and d == 3 and path != "direct" else [])]}
    for r in range(args.rounds):
        for d, path, f in runs:
            env = dict(os.environ, GATETHERM_SOLVER=path)
            res = rusage_run([sys.executable, __file__, "--job", str(d), str(f)], env=env)
            runs[d, path, f].append(res)
            print(f"round {r + 1} {d}-D {path} x{f:g}: {res['nodes']} nodes, total {sum(res[k] for k in PARTS):.1f} s, "
                  f"CPU {res['cpu']:.1f} s, peak {res['rss_gb']:.2f} GB, first peak {res['first_peak_um']} um, swing {res['swing_um']} um, "
                  f"load {os.getloadavg()[0]:.1f}", flush=True)
            write(runs, r + 1, args.json)  # so far: a run stopped early keeps what it measured


if __name__ == "__main__":
    main()
