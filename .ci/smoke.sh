#!/usr/bin/env bash
# Smoke test of an installed wheel, as a user would run it: build the sdist and the
# wheel (from the sdist), install the wheel with its extras into a fresh venv, and
# run from a temporary directory outside the checkout: --version, examples, solve
# (ipopt and newton presets), reproduce --json (parsed) and -o, export, a small
# sweep and its plot.  Usage: bash .ci/smoke.sh (from anywhere).
#
# SMOKE_DEPS=reuse (what .ci/run sets): the venv also sees the site-packages of the
# Python running this script, so the wheel's dependencies that the test step has
# just installed are not downloaded again (this machine keeps no pip cache; pip
# still checks them against the wheel's metadata); cpm_nlp itself must come from
# the wheel (checked below).
# Without it, the venv is isolated and pip downloads every dependency.
set -euo pipefail
repo="$(cd "$(dirname "$0")/.." && pwd)"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
py="${PYTHON:-python}"

step() { echo "smoke: [$(date +%T)] $*" >&2; }

step "build sdist and wheel"
"$py" -m pip install -q build
"$py" -m build -o "$work/dist" "$repo" > "$work/build.log" 2>&1 || { cat "$work/build.log" >&2; exit 1; }
wheel="$(ls "$work"/dist/cpm_nlp-*.whl)"

step "install $(basename "$wheel") into a fresh venv"
"$py" -m venv "$work/venv"
if [ "${SMOKE_DEPS:-}" = reuse ]; then
    # the running Python's site-packages, after the venv's own (its .pth files, such as an
    # editable install of cpm_nlp, are not read); the wheel is installed over what is there
    venv_site="$("$work/venv/bin/python" -c 'import sysconfig; print(sysconfig.get_paths()["purelib"])')"
    "$py" -c 'import sysconfig; p = sysconfig.get_paths(); print("\n".join(dict.fromkeys([p["purelib"], p["platlib"]])))' \
        > "$venv_site/_cpm_nlp_smoke_reuse.pth"
    "$work/venv/bin/python" -m pip install -q --no-deps --force-reinstall "$wheel"
fi
"$work/venv/bin/python" -m pip install -q "$wheel[sweep,plot]"
export PATH="$work/venv/bin:$PATH"
cd "$work"
mkdir user && cd user  # the user's own directory: no problems/ or configs/ here

where="$(python -c 'import cpm_nlp; print(cpm_nlp.__file__)')"
case "$where" in "$work/venv/"*) ;; *) echo "smoke: cpm_nlp imported from $where, not the wheel" >&2; exit 1 ;; esac

step "cpm-nlp --version"
cpm-nlp --version | grep -q "^cpm-nlp [0-9]"

step "solve a user's problem file with the shipped ipopt and newton presets"
cat > my_fk.yaml <<'YAML'
problem: forward_kinematics
mechanism:
  type: prs3
  parameters: {b: 47.91 mm, L: 109.215 mm, alpha0: 45 deg}
inputs: {s1: 1.0 mm, s2: 0.5 mm, s3: -0.3 mm}
solver: ipopt
YAML
cpm-nlp solve my_fk.yaml --json > fk.json
cpm-nlp solve my_fk.yaml --set solver=newton -o fk_newton.json -q
python - <<'PY'
import json
for f in ("fk.json", "fk_newton.json"):
    r = json.load(open(f))
    assert r["status"] == "solved", (f, r["status"], r.get("message"))
PY

step "reproduce --json over the shipped files (and -o)"
cpm-nlp reproduce --json -o reproduce.json > reproduce_stdout.json
python - <<'PY'
import json
doc = json.load(open("reproduce_stdout.json"))
assert doc == json.load(open("reproduce.json"))
s = doc["summary"]
assert s["figures"] == len(doc["figures"]) > 100 and s["unexpected"] == 0, s
assert {r["category"] for r in doc["figures"]} >= {"published", "derived", "read_off_matrix", "consistency"}
print(f"smoke: reproduce: {s['figures']} figures, {s['agree_independent']} independent agreements, 0 unexpected")
PY

step "compliance from the wheel: Table 2 forces, the six-axis cutting force, a file mechanism's hinges"
cpm-nlp examples compl > /dev/null
cpm-nlp solve compl/problems/prs3_table2_forces.yaml --json > forces.json
cpm-nlp solve compl/problems/prs3_cutting_force.yaml --json > cutting.json
cpm-nlp solve compl/problems/prs3_file_table2_forces.yaml --json > file_forces.json
python - <<'PY'
import json
f, c, ff = (json.load(open(n)) for n in ("forces.json", "cutting.json", "file_forces.json"))
assert f["status"] == c["status"] == ff["status"] == "solved", (f["status"], c["status"], ff["status"])
assert abs(f["values"]["F1"] - 20) < 1 and abs(ff["values"]["F1"] - f["values"]["F1"]) < 1e-9
assert c["values"]["hinge_model"] == "all" and abs(c["values"]["d_px"]) > 1e-7
print(f"smoke: F1 = {f['values']['F1']:.3f} N, cutting-force deflection px = {c['values']['d_px'] * 1e6:.3f} um")
PY
rm -rf compl

step "export"
cpm-nlp export my_fk.yaml --out exported > /dev/null
test -s exported/manifest.json

step "examples, a small sweep and its plot"
cpm-nlp examples ex > /dev/null
cd ex
cpm-nlp sweep problems/sweep_prs3_requirements.yaml -q --workers 1 -o sweep.csv \
    --set "sweep.parameters={mechanism.parameters.L: {from: 100 mm, to: 120 mm, count: 3}}"
test "$(grep -vc '^#' sweep.csv)" -eq 4  # header and 3 points
cpm-nlp plot sweep.csv -o sweep.png > /dev/null
test -s sweep.png
step "ok"
