"""What a ``live`` service of an error model costs to start: the modules it imports, their CPU time
and the process's memory; and the wall time of ``gatetherm --help``.

    python benchmarks/live_imports.py [--runs 5] [--python PYTHON ...]

A service as ``benchmarks/live_many.py`` starts one (``--method errormodel``): a fresh interpreter
imports asyncua, ``gatetherm`` and ``gt.live``, then what ``gt.live`` imports on its way to stepping an
error model (the method registry and its ``errormodel`` method, the model's loader and stepper, the
service's journal, guards, map reader and runner). Printed per interpreter (``--python``, default
this one; give two, e.g. two checkouts' venvs, to compare them: their runs interleaved): the
medians of ``--runs`` runs of the process's CPU seconds (from its start: the interpreter's
own start-up included), its peak RSS (MB), the modules imported and whether scikit-fem, pyMOR,
gmsh, pyvista, ``scipy.signal``, ``scipy.optimize``, ``scipy.stats`` are among them; and the median
wall time of ``python -m gatetherm.cli --help``.
"""
from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
import time

HEAVY = ("skfem", "pymor", "gmsh", "pyvista", "scipy.signal", "scipy.optimize", "scipy.stats")

SERVICE = f"""
import json, resource, sys, time
import asyncua
import gatetherm as gt
gt.live
from gatetherm.studies.control import method as methods
methods.get("errormodel")
from gatetherm.studies.errormodel.model import load_model
from gatetherm.studies.control.stepwise import error_model_stepper
from gatetherm.studies.control.compensator import CompensatorParams
from gatetherm.validation.live import journal, service
from gatetherm.validation.live.axis import Axis, AxisStepper
from gatetherm.validation.live.nodes import default_map, read_map
from gatetherm.validation.live.runner import serve_until_signal
from gatetherm.validation.live.twin import endpoint_url
r = resource.getrusage(resource.RUSAGE_SELF)
print(json.dumps({{"cpu_s": r.ru_utime + r.ru_stime, "rss_mb": r.ru_maxrss / 1024, "modules": len(sys.modules),
                  "heavy": [m for m in {HEAVY!r} if m in sys.modules]}}))
"""


def _service(python: str) -> dict:
    return json.loads(subprocess.run([python, "-c", SERVICE], check=True, capture_output=True, text=True).stdout)


def _help_s(python: str) -> float:
    t = time.perf_counter()
    subprocess.run([python, "-m", "gatetherm.cli", "--help"], check=True, capture_output=True)
    return time.perf_counter() - t


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--python", action="append", help="an interpreter (repeat to compare; default this one)")
    a = ap.parse_args()
    pythons = a.python or [sys.executable]
    services = {p: [] for p in pythons}
    helps = {p: [] for p in pythons}
    for _ in range(a.runs):  # interleaved: the computer's load falls on every interpreter alike
        for p in pythons:
            services[p].append(_service(p))
            helps[p].append(_help_s(p))
    for p in pythons:
        runs = services[p]
        med = {k: statistics.median(r[k] for r in runs) for k in ("cpu_s", "rss_mb", "modules")}
        print(f"{p}: a service's imports {med['cpu_s']:.2f} CPU-s, {med['rss_mb']:.0f} MB RSS, "
              f"{med['modules']:.0f} modules (heavy: {', '.join(runs[0]['heavy']) or 'none'}); "
              f"gatetherm --help {statistics.median(helps[p]):.2f} s wall "
              f"(medians of {a.runs}; CPU-s {min(r['cpu_s'] for r in runs):.2f}-{max(r['cpu_s'] for r in runs):.2f}, "
              f"--help {min(helps[p]):.2f}-{max(helps[p]):.2f} s)")


if __name__ == "__main__":
    main()
