#!/usr/bin/env bash
# The peers of benchmarks/errormodel.py (a random forest and XGBoost), in an environment of their
# own (benchmark-only: gatetherm never imports them). The venv sees the system's packages, and
# gatetherm is installed into it from this worktree without dependencies.
#   usage: benchmarks/setup_errormodel.sh [DIR]     (default /tmp/venv_bench)
set -eu
V=${1:-/tmp/venv_bench}
ROOT=$(cd "$(dirname "$0")/.." && pwd)
python3 -m venv --system-site-packages "$V"
"$V/bin/pip" install -q "scikit-learn>=1.4" "xgboost>=2.0"
"$V/bin/pip" install -q -e "$ROOT" --no-deps
"$V/bin/python" -c "import sklearn, xgboost, gatetherm; print('scikit-learn', sklearn.__version__, \
'xgboost', xgboost.__version__, 'gatetherm', gatetherm.__file__)"
