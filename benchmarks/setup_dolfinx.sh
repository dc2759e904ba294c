#!/usr/bin/env bash
# The DOLFINx peer of benchmarks/peer.py, in an environment of its own (benchmark-only:
# gatetherm never imports it). DOLFINx 0.11 installs with pip as dolfinx-solver-real, a
# Python 3.12 wheel bundling PETSc with MUMPS (no hypre).
#   usage: benchmarks/setup_dolfinx.sh [DIR]     (default /tmp/venv_dolfinx)
set -eu
V=${1:-/tmp/venv_dolfinx}
PY=$(ls -d "$(pyenv root 2>/dev/null || echo "$HOME/.pyenv")"/versions/3.12*/bin/python 2>/dev/null | head -1)
[ -n "$PY" ] || PY=$(command -v python3.12) || { echo "no Python 3.12 found (pyenv or python3.12)"; exit 1; }
"$PY" -m venv "$V"
"$V/bin/pip" install -q dolfinx-solver-real==0.11.0.post0 gmsh meshio scipy
"$V/bin/python" -c "import dolfinx_solver, dolfinx; print('dolfinx', dolfinx.__version__)"
