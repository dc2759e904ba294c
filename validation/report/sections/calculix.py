"""CalculiX section: the 3-D frame's thermoelastic state exported to CalculiX (``gatetherm
export ccx``) and solved by ``ccx``, an independent FE code, on the same mesh, materials,
supports and temperatures; δ between the probes against gatetherm's."""
from __future__ import annotations

import json
import os
import shutil
import subprocess
import time

from gatetherm.validation.report.result import Result, table
from gatetherm.validation import paper_model

TOLERANCE = 5e-3
"""Acceptance of the issue: |δ_ccx / δ − 1| within 0.5 %."""


def compute(ctx) -> Result:
    from gatetherm import write_text_atomic
    from gatetherm.studies.run.ccx import export_state, relative_from_dat
    from gatetherm.frame.case import frame_case

    s = ctx.scope
    cfg = paper_model(size_3d=s["size_3d"])
    t = 60.0 * s["time_min"]
    case = frame_case(cfg, 3, s["condition"])
    inp, info = export_state(case, case.schedule, t,
                             f"gatetherm condition {s['condition']}, t = {s['time_min']:g} min")
    write_text_atomic(ctx.work / "job.inp", inp)
    write_text_atomic(ctx.work / "gatetherm.json", json.dumps(info, indent=2) + "\n")
    mesh = (f"{info['vertices']} vertices, {info['elements']} tetrahedra "
            f"({'C3D10' if info['order'] == 2 else 'C3D4'})")
    exe = shutil.which("ccx")
    if exe is None:
        return Result(notes=(f"CalculiX (`ccx`, Debian calculix-ccx) is not installed: `job.inp` ({mesh}) is "
                             "written; run `ccx job` beside it.",), files=(("job.inp", "the CalculiX deck"),))
    t0 = time.perf_counter()
    run = subprocess.run([exe, "job"], cwd=ctx.work, capture_output=True, text=True, timeout=3600,
                         env={**os.environ, "OMP_NUM_THREADS": str(max(ctx.workers, 1))})
    seconds = time.perf_counter() - t0
    write_text_atomic(ctx.work / "ccx.log", run.stdout + run.stderr)
    if run.returncode != 0 or "ERROR" in run.stdout:
        raise RuntimeError(f"ccx failed (exit {run.returncode}); see {ctx.work / 'ccx.log'}")
    (ctx.work / "job.frd").unlink(missing_ok=True)  # the full result file: large, not used
    ccx = relative_from_dat((ctx.work / "job.dat").read_text(), info)
    rows = []
    for name, g in info["relative_m"].items():
        rel = ccx[name] / g - 1.0
        rows.append((name, f"{g * 1e6:.6f}", f"{ccx[name] * 1e6:.6f}", f"{rel:+.1e}",
                     "yes" if abs(rel) <= TOLERANCE else "NO"))
    version = next((ln.strip().split(",")[0] for ln in run.stdout.splitlines() if "Version" in ln), "ccx")
    tab = table(f"δ between the probes at {s['time_min']:g} min of condition {s['condition']}, 3-D: gatetherm "
                "against CalculiX (µm)", ("output", "gatetherm", "CalculiX", "CalculiX / gatetherm − 1",
                                         f"within {TOLERANCE:.1%}"), rows,
                note=f"Same mesh ({mesh}), materials, supports and temperature field; {version}; ccx took "
                     f"{seconds:.1f} s.")
    return Result(tables=(tab,), files=(("job.inp", "the CalculiX deck"), ("job.dat", "CalculiX's probe "
                                                                                     "displacements"),
                                         ("ccx.log", "CalculiX's output")))
