#!/usr/bin/env bash
# The lowest supported versions of the required dependencies (.ci/constraints-min.txt,
# the minimums of pyproject.toml), installed into a fresh venv, run a quick subset of
# the tests: units, the kinematics of every mechanism and the problem files of one
# paper end to end.  The full suite against them was run by hand (see the file).
set -euo pipefail
repo="$(cd "$(dirname "$0")/.." && pwd)"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
py="${PYTHON:-python}"
"$py" -m venv "$work/venv"
# a download slower than MINDEPS_INSTALL_TIMEOUT seconds is skipped with a note, not failed
status=0
timeout "${MINDEPS_INSTALL_TIMEOUT:-900}" "$work/venv/bin/python" -m pip install -q \
    -c "$repo/.ci/constraints-min.txt" casadi numpy scipy pyyaml pint threadpoolctl pytest hypothesis || status=$?
if [ "$status" -eq 124 ]; then
    echo "note: could not install the lowest supported dependencies in time; their tests were skipped" >&2
    exit 0
fi
[ "$status" -eq 0 ] || exit "$status"
"$work/venv/bin/python" -m pip install -q --no-deps -e "$repo"
"$work/venv/bin/python" - <<'PY'
import casadi, numpy, scipy, yaml, pint, threadpoolctl
print("mindeps: casadi", casadi.__version__, "numpy", numpy.__version__, "scipy", scipy.__version__,
      "pyyaml", yaml.__version__, "pint", pint.__version__, "threadpoolctl", threadpoolctl.__version__)
PY
cd "$repo"
"$work/venv/bin/python" -m pytest -q -p no:cacheprovider -o addopts="" tests/core/test_units.py \
    tests/mechanisms/prs3/test_prs3_kinematics.py tests/mechanisms/rpr/test_rpr_kinematics.py \
    tests/mechanisms/pantograph/test_pantograph_kinematics.py tests/mechanisms/prc3/test_prc3_kinematics.py \
    tests/mechanisms/prs3/test_prs3_paper.py
