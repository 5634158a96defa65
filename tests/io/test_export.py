"""Export: serialized CasADi Functions loaded by a Python without cpm_nlp,
C code compiled with gcc (as a shared library and straight into a program);
exported and in-process results agree to 1e-12 relative."""

import ctypes
import hashlib
import json
import re
import shutil
import subprocess
import sys
import textwrap
from pathlib import Path

import casadi as ca
import numpy as np
import pytest

import cpm_nlp as cn
from cpm_nlp.core.pose_checks import STATUSES, code_of
from cpm_nlp.core.result import Status
from tests.conftest import PAPER_PRS3, PROBLEMS, ROOT

GCC = shutil.which("gcc")
needs_gcc = pytest.mark.skipif(GCC is None, reason="gcc is not installed")
LIMITS = {"s": ["-3 mm", "3 mm"], "beta_m": ["-1.5 deg", "1.5 deg"]}
RTOL, ATOL = 1e-12, 1e-18


@pytest.fixture(scope="module")
def model():
    return cn.build_model("prs3", PAPER_PRS3, LIMITS)


@pytest.fixture(scope="module")
def fns(model):
    return cn.functions(model)


@pytest.fixture(scope="module")
def actuators():
    """Inside the limits, outside them (beta_m), and out of reach."""
    rng = np.random.default_rng(21)
    q = rng.uniform(-2.5e-3, 2.5e-3, (40, 3))
    q[5] = [0.3, -0.3, 0.0]
    return q


@pytest.fixture(scope="module")
def tasks(model):
    rng = np.random.default_rng(22)
    t = np.column_stack(
        [
            model.derived["pz0"] + rng.uniform(-2e-3, 2e-3, 40),
            rng.uniform(-4e-3, 4e-3, 40),
            rng.uniform(-4e-3, 4e-3, 40),
        ]
    )
    t[3, 0] = 0.2  # unreachable
    return t


@pytest.fixture(scope="module")
def exported(model, tmp_path_factory):
    base = tmp_path_factory.mktemp("export")
    manifests = {fmt: cn.export_kinematics(model, base / fmt, fmt=fmt) for fmt in ("casadi", "c")}
    return base, manifests


def in_process(fns, q, t, x0):
    """Reference values from the in-process Functions, keyed like the exported outputs."""
    fk = [{k: np.asarray(v).ravel() for k, v in fns.fk(q=qi, x0=x0).items()} for qi in q]
    ik = [{k: np.asarray(v).ravel() for k, v in fns.ik(t=ti).items()} for ti in t]
    sol = [r for r in ik if r["status"][0] == 0]
    jac = [{k: np.asarray(v).ravel(order="F") for k, v in fns.jacobian(x=r["x"], q=r["q"]).items()} for r in sol]
    return fk, ik, jac, [(r["x"], r["q"]) for r in sol]


def assert_close(got, want):
    for name in want:
        np.testing.assert_allclose(got[name], want[name], rtol=RTOL, atol=ATOL, err_msg=name)


def test_in_process_functions_agree_with_solvers(model, fns, actuators):
    """The exported formulation (fast_newton + kernel checks) is the toolkit's:
    same poses and statuses as the single Newton solve."""
    for qi in actuators[:15]:
        got = fns.fk(q=qi, x0=fns.x_home)
        single = cn.forward_kinematics(model, qi, cn.SolverConfig("newton"))
        assert STATUSES[int(got["status"])] is single.status
        if single.ok:
            np.testing.assert_allclose(np.asarray(got["x"]).ravel(), single.x, rtol=0, atol=1e-13)


def test_casadi_files_load_without_cpm_nlp(exported, fns, actuators, tasks, tmp_path):
    """A Python with only casadi on its path loads the files and gets the same numbers."""
    folder = exported[0] / "casadi"
    manifest = json.loads((folder / "manifest.json").read_text())
    assert [f["file"] for f in manifest["functions"]] == ["prs3_fk.casadi", "prs3_ik.casadi", "prs3_jacobian.casadi"]
    fk_ref, ik_ref, jac_ref, poses = in_process(fns, actuators, tasks, fns.x_home)
    inputs = {
        "q": actuators.tolist(),
        "t": tasks.tolist(),
        "x0": fns.x_home.tolist(),
        "poses": [[x.tolist(), q.tolist()] for x, q in poses],
    }
    (tmp_path / "inputs.json").write_text(json.dumps(inputs))
    script = textwrap.dedent(
        f"""
        import importlib.util, json, sys
        sys.path.insert(0, {str(Path(ca.__file__).parent.parent)!r})
        assert importlib.util.find_spec("cpm_nlp") is None, "cpm_nlp must not be importable here"
        import casadi
        inp = json.load(open("inputs.json"))
        fk = casadi.Function.load({str(folder / "prs3_fk.casadi")!r})
        ik = casadi.Function.load({str(folder / "prs3_ik.casadi")!r})
        jac = casadi.Function.load({str(folder / "prs3_jacobian.casadi")!r})
        def flat(d, order="C"):
            return {{k: [float(v) for v in casadi.DM(d[k]).full().ravel(order=order)] for k in d}}
        out = {{
            "names": [fk.name_in(), fk.name_out(), ik.name_in(), jac.name_in(), jac.name_out()],
            "fk": [flat(fk(q=q, x0=inp["x0"])) for q in inp["q"]],
            "ik": [flat(ik(t=t)) for t in inp["t"]],
            "jac": [flat(jac(x=x, q=q), "F") for x, q in inp["poses"]],
        }}
        print(json.dumps(out))
        """
    )
    run = subprocess.run(
        [sys.executable, "-I", "-S", "-c", script], cwd=tmp_path, capture_output=True, text=True, check=False
    )
    assert run.returncode == 0, run.stderr
    out = json.loads(run.stdout)
    assert out["names"][0] == ["q", "x0"] and out["names"][2] == ["t"] and out["names"][3] == ["x", "q"]
    assert out["names"][1][0] == "x" and out["names"][1][-1] == "status"
    assert out["names"][4] == ["J", "J_inv", "Phi_x", "Phi_q"]
    for got, want in zip(out["fk"], fk_ref):
        assert_close(got, want)
    for got, want in zip(out["ik"], ik_ref):
        assert_close(got, want)
    for got, want in zip(out["jac"], jac_ref):
        assert_close(got, want)
    statuses = {STATUSES[int(r["status"][0])] for r in out["fk"] + out["ik"]}
    assert {Status.SOLVED, Status.OUTSIDE_JOINT_LIMITS, Status.NOT_CONVERGED, Status.UNREACHABLE} <= statuses


def test_manifest(exported, model):
    for fmt in ("casadi", "c"):
        folder = exported[0] / fmt
        m = json.loads((folder / "manifest.json").read_text())
        assert m["format"] == fmt and m["casadi"]["version"] == ca.__version__
        assert m["mechanism"]["parameters"]["b"] == {"value": pytest.approx(47.91e-3, rel=1e-15), "unit": "m"}
        assert m["mechanism"]["parameters"]["alpha0"]["unit"] == "rad"
        assert m["mechanism"]["joint_limits"]["beta_m2"]["high"] == pytest.approx(np.radians(1.5))
        assert m["mechanism"]["home"]["x"][2] == pytest.approx(model.derived["pz0"])
        assert m["status_codes"]["0"]["status"] == "solved" and len(m["status_codes"]) == len(STATUSES)
        fk = m["functions"][0]
        assert fk["inputs"][0] == {
            "name": "q",
            "shape": [3, 1],
            "meaning": "actuated joints",
            "elements": ["s1", "s2", "s3"],
            "units": ["m", "m", "m"],
        }
        assert fk["outputs"][0]["elements"] == ["px", "py", "pz", "psi", "theta", "phi"]
        assert fk["outputs"][0]["units"] == ["m", "m", "m", "rad", "rad", "rad"]
        jac = m["functions"][2]["outputs"][0]
        assert jac["name"] == "J" and jac["shape"] == [6, 3] and jac["storage"] == "column-major"
        for name, digest in m["files"].items():
            assert hashlib.sha256((folder / name).read_bytes()).hexdigest() == digest
    casadi_manifest = json.loads((exported[0] / "casadi" / "manifest.json").read_text())
    assert "load with the CasADi version that wrote them (" + ca.__version__ + ")" in casadi_manifest["casadi"]["note"]


C_DRIVER = r"""
#include <stdio.h>
#include "prs3_kinematics.h"
/* reads "q1 q2 q3 t1 t2 t3" lines; prints every output of fk, ik and (at the ik pose) jacobian */
static void show(const char* tag, const double* v, int n) {
    int i;
    printf("%s", tag);
    for (i = 0; i < n; ++i) printf(" %.17g", v[i]);
    printf("\n");
}
int main(void) {
    double q[3], t[3], x0[6] = HOME;
    double x[6], passive[12], s[6], xi[6], qi[3], pi_[12], si[7], J[18], Ji[9], Px[36], Pq[18];
    while (scanf("%lf %lf %lf %lf %lf %lf", q, q + 1, q + 2, t, t + 1, t + 2) == 6) {
        if (prs3_fk_eval(q, x0, x, passive, s, s + 1, s + 2, s + 3, s + 4, s + 5)) return 2;
        show("fk", x, 6); show("fkp", passive, 12); show("fks", s, 6);
        if (prs3_ik_eval(t, xi, qi, pi_, si, si + 1, si + 2, si + 3, si + 4, si + 5, si + 6)) return 2;
        show("ik", xi, 6); show("ikq", qi, 3); show("ikp", pi_, 12); show("iks", si, 7);
        if (prs3_jacobian_eval(xi, qi, J, Ji, Px, Pq)) return 2;
        show("J", J, 18); show("Ji", Ji, 9); show("Px", Px, 36); show("Pq", Pq, 18);
        /* NULL outputs are skipped */
        if (prs3_fk_eval(q, x0, NULL, NULL, NULL, NULL, NULL, NULL, NULL, s)) return 2;
        show("st", s, 1);
    }
    return 0;
}
"""


@pytest.fixture(scope="module")
def c_build(exported, fns, tmp_path_factory):
    """The exported C compiled once (C99, position-independent) and linked twice: a shared
    library, and a program with the source's object linked in."""
    folder = exported[0] / "c"
    build = tmp_path_factory.mktemp("cbuild")
    obj = build / "prs3_kinematics.o"
    cc = [GCC, "-O2", "-std=c99", "-fPIC"]
    subprocess.run([*cc, "-c", str(folder / "prs3_kinematics.c"), "-o", str(obj)], check=True)
    lib = build / "libprs3_kinematics.so"
    subprocess.run([GCC, "-shared", str(obj), "-o", str(lib)], check=True)
    home = "{" + ", ".join(repr(float(v)) for v in fns.x_home) + "}"
    (build / "driver.c").write_text(C_DRIVER.replace("HOME", home))
    exe = build / "driver"
    subprocess.run([*cc, "-I", str(folder), str(build / "driver.c"), str(obj), "-lm", "-o", str(exe)], check=True)
    return lib, exe


@needs_gcc
def test_c_program_matches_in_process(c_build, fns, actuators, tasks):
    _, exe = c_build
    stdin = "\n".join(" ".join(repr(float(v)) for v in np.r_[q, t]) for q, t in zip(actuators, tasks))
    run = subprocess.run([str(exe)], input=stdin, capture_output=True, text=True, check=True)
    rows: dict[str, list[np.ndarray]] = {}
    for line in run.stdout.splitlines():
        tag, *vals = line.split()
        rows.setdefault(tag, []).append(np.array([float(v) for v in vals]))
    names = ("residual", "branch_margin", "round_trip_error", "cond1", "limit_margin", "status")
    for k, (q, t) in enumerate(zip(actuators, tasks)):
        fk = {n: np.asarray(v).ravel() for n, v in fns.fk(q=q, x0=fns.x_home).items()}
        assert_close({"x": rows["fk"][k], "passive": rows["fkp"][k]}, {"x": fk["x"], "passive": fk["passive"]})
        assert_close(dict(zip(names, rows["fks"][k])), {n: fk[n][0] for n in names})
        assert rows["st"][k][0] == fk["status"][0]
        ik = {n: np.asarray(v).ravel() for n, v in fns.ik(t=t).items()}
        assert_close({"x": rows["ik"][k], "q": rows["ikq"][k]}, {"x": ik["x"], "q": ik["q"]})
        assert_close(dict(zip(("reach",) + names, rows["iks"][k])), {n: ik[n][0] for n in ("reach",) + names})
        jac = fns.jacobian(x=rows["ik"][k], q=rows["ikq"][k])
        for tag, name in (("J", "J"), ("Ji", "J_inv"), ("Px", "Phi_x"), ("Pq", "Phi_q")):
            np.testing.assert_allclose(rows[tag][k], np.asarray(jac[name]).ravel(order="F"), rtol=RTOL, atol=ATOL)
    codes = {int(r[-1]) for r in rows["fks"]} | {int(r[-1]) for r in rows["iks"]}
    assert {code_of(Status.SOLVED), code_of(Status.OUTSIDE_JOINT_LIMITS), code_of(Status.UNREACHABLE)} <= codes


@needs_gcc
def test_c_shared_library_through_ctypes(c_build, fns, actuators):
    lib = ctypes.CDLL(str(c_build[0]))
    f = lib.prs3_fk_eval
    dp = ctypes.POINTER(ctypes.c_double)
    f.argtypes = [dp] * 10
    f.restype = ctypes.c_int
    for q in actuators[:10]:
        qa, x0 = np.ascontiguousarray(q), np.ascontiguousarray(fns.x_home)
        x, status = np.empty(6), np.empty(1)
        ptr = lambda a: a.ctypes.data_as(dp)  # noqa: E731
        null = ctypes.cast(None, dp)
        assert f(ptr(qa), ptr(x0), ptr(x), null, null, null, null, null, null, ptr(status)) == 0
        ref = fns.fk(q=q, x0=fns.x_home)
        assert status[0] == float(ref["status"])
        np.testing.assert_allclose(x, np.asarray(ref["x"]).ravel(), rtol=RTOL, atol=ATOL)


@needs_gcc
def test_docs_c_example_compiles_and_runs(exported, fns, tmp_path):
    """The C program of docs/site/howto/export-c.md (written there by a heredoc), checked
    against the FK it exports (tests/test_docs.py only checks that it runs)."""
    page = (ROOT / "docs" / "site" / "howto" / "export-c.md").read_text()
    block = re.search(r"cat > main\.c <<'EOF_C'\n(.*?)^EOF_C$", page, flags=re.S | re.M)
    assert block, "the export how-to has a C example"
    (tmp_path / "main.c").write_text(block.group(1))
    folder = exported[0] / "c"
    exe = tmp_path / "fk"
    subprocess.run(
        [
            GCC,
            "-O2",
            "-I",
            str(folder),
            str(tmp_path / "main.c"),
            str(folder / "prs3_kinematics.c"),
            "-lm",
            "-o",
            str(exe),
        ],
        check=True,
    )
    out = subprocess.run([str(exe)], capture_output=True, text=True, check=True).stdout
    ref = fns.fk(q=[1e-3, 0.5e-3, -0.3e-3], x0=fns.x_home)
    x = np.asarray(ref["x"]).ravel()
    assert f"pz = {x[2]:.9f} m" in out and f"psi = {x[3]:.9f} rad" in out


def test_cli_export_writes_all_or_nothing(cli, tmp_path):
    out = tmp_path / "exp"
    run = cli("export", str(PROBLEMS / "prs3_forward_kinematics.yaml"), "--what", "fk,jacobian", "--out", str(out))
    assert run.code == 0, run.err
    assert sorted(p.name for p in out.iterdir()) == ["manifest.json", "prs3_fk.casadi", "prs3_jacobian.casadi"]
    m = json.loads((out / "manifest.json").read_text())
    assert m["mechanism"]["joint_limits"]["s1"] == {"low": -0.003, "high": 0.003, "unit": "m"}
    assert m["cpm_nlp"]["problem_file"].endswith("prs3_forward_kinematics.yaml")
    # bad input: one message, exit 2, nothing written
    for args, message in [
        (
            ("--what", "fk,jacobain"),
            "error: --what: unknown function 'jacobain'; expected a comma-separated list of "
            "fk, ik, jacobian; did you mean 'jacobian'?\n",
        ),
        (("--format", "C"), "error: --format: unknown format 'C'; expected one of: casadi, c; did you mean 'c'?\n"),
        (("--set", "mechanism.parameters.b=-1 mm"), None),
    ]:
        target = tmp_path / "bad"
        run = cli("export", str(PROBLEMS / "prs3_forward_kinematics.yaml"), "--out", str(target), *args)
        assert run.code == 2 and run.err.count("\n") == 1, run.err
        if message:
            assert run.err == message
        assert not target.exists()
    run = cli("export", str(PROBLEMS / "prs3_forward_kinematics.yaml"), "--out", str(tmp_path / "no" / "such"))
    assert run.code == 2 and run.err == f"error: --out: directory {tmp_path / 'no'} does not exist\n"
    assert not any(p.name.startswith(".cpm_nlp_export_") for p in tmp_path.iterdir())


def test_load_exported_checks_the_casadi_version(exported, tmp_path):
    loaded = cn.load_exported(exported[0] / "casadi")
    assert sorted(loaded) == ["prs3_fk", "prs3_ik", "prs3_jacobian"]
    copy = tmp_path / "old"
    shutil.copytree(exported[0] / "casadi", copy)
    m = json.loads((copy / "manifest.json").read_text())
    m["casadi"]["version"] = "3.5.5"
    (copy / "manifest.json").write_text(json.dumps(m))
    with pytest.raises(cn.InputError, match=r"written by CasADi 3\.5\.5; this is CasADi " + re.escape(ca.__version__)):
        cn.load_exported(copy)
    with pytest.raises(cn.InputError, match="only 'casadi' files load"):
        cn.load_exported(exported[0] / "c")
