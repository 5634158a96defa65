#!/usr/bin/env bash
# The lowest supported versions of the required dependencies (.ci/constraints-min.txt,
# the minimums of pyproject.toml), installed into a fresh venv, run a quick subset of
# the tests: units, the kinematics of every mechanism and the problem files of one
# paper end to end.  The full suite against them was run by hand (see the file).
#
#   bash .ci/mindeps.sh                 # both phases, in a temporary folder
#   bash .ci/mindeps.sh install DIR     # the venv in DIR and its download only
#   bash .ci/mindeps.sh test DIR        # the tests, with the venv an earlier install made
#
# .ci/run starts the install in the background when CI starts (it is mostly download,
# niced, so the main test step keeps both cores) and runs the tests after the main steps,
# so that this step always runs and CI stays well under its 10 minutes.
set -euo pipefail
repo="$(cd "$(dirname "$0")/.." && pwd)"
phase="${1:-all}"
py="${PYTHON:-python}"

install() {
    local work="$1"
    "$py" -m venv "$work/venv"
    # a download slower than MINDEPS_INSTALL_TIMEOUT seconds is skipped with a note, not failed
    local status=0
    timeout "${MINDEPS_INSTALL_TIMEOUT:-900}" "$work/venv/bin/python" -m pip install -q --no-compile \
        -c "$repo/.ci/constraints-min.txt" casadi numpy scipy pyyaml pint threadpoolctl pytest hypothesis || status=$?
    if [ "$status" -eq 124 ]; then
        echo "note: could not install the lowest supported dependencies in time; their tests were skipped" >&2
        touch "$work/skipped"
        return 0
    fi
    [ "$status" -eq 0 ] || return "$status"
    "$work/venv/bin/python" -m pip install -q --no-deps -e "$repo"
    touch "$work/installed"
}

run_tests() {
    local work="$1"
    if [ -e "$work/skipped" ]; then
        echo "note: the lowest supported dependencies were not installed in time; their tests were skipped" >&2
        return 0
    fi
    [ -e "$work/installed" ] || { echo "error: no installed venv in $work (bash .ci/mindeps.sh install $work)" >&2; return 1; }
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
}

case "$phase" in
    install) install "${2:?usage: mindeps.sh install DIR}" ;;
    test) run_tests "${2:?usage: mindeps.sh test DIR}" ;;
    all)
        work="$(mktemp -d)"
        trap 'rm -rf "$work"' EXIT
        install "$work"
        run_tests "$work"
        ;;
    *) echo "usage: mindeps.sh [install DIR | test DIR]" >&2; exit 2 ;;
esac
