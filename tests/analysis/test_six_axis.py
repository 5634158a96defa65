"""The six-axis hinge model (cpm_nlp.analysis.hinge_chains): every flexure a
six-degree-of-freedom spring at its joint, the loaded pose by minimum potential
energy on the legs' chains (IPOPT), the output compliance by the KKT
linearization.

Checked against an independent derivation (the compliance-matrix method in
numpy from the paper's geometry), against the pseudo-rigid-body model in the
limit of stiff extra axes, against central differences, Newton against IPOPT,
and force balance."""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from cpm_nlp.analysis import compliance as cm
from cpm_nlp.analysis import hinge_types as ht
from cpm_nlp.analysis.hinge_chains import SixAxisModel, six_axis_model
from cpm_nlp.core.kinematics import forward_kinematics
from cpm_nlp.core.solver import SolverConfig
from cpm_nlp.mechanisms.registry import build_model

ROOT = Path(__file__).resolve().parents[2]
PRS3 = {"b": "47.91 mm", "L": "109.215 mm", "alpha0": "45 deg"}
CFG = SolverConfig()


@pytest.fixture(scope="module")
def prs3():
    m = build_model("prs3", PRS3)
    hs = cm.hinge_set(m, None)
    return m, hs, six_axis_model(m, hs)


def _rz(angle):
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def _skew(r):
    return np.array([[0.0, -r[2], r[1]], [r[2], 0.0, -r[0]], [-r[1], r[0], 0.0]])


def _hinge_compliance(k, frame):
    """6 x 6 compliance (f, m) -> (δ, φ) at the hinge centre, base frame, from the
    stiffness per axis and the frame {t, b1, b2} (t along the hinge, b1 its compliant axis)."""
    t, b1, b2 = frame
    Ct = np.outer(t, t) / k["axial"] + np.outer(b2, b2) / k["shear"] + np.outer(b1, b1) / k["shear2"]
    Cr = np.outer(b1, b1) / k["bend"] + np.outer(b2, b2) / k["bend2"] + np.outer(t, t) / k["torsion"]
    C = np.zeros((6, 6))
    C[:3, :3], C[3:, 3:] = Ct, Cr
    return C


def test_home_compliance_equals_the_compliance_matrix_method(prs3):
    """At the unstressed home pose the KKT linearization is the compliance-matrix
    method: each leg the series sum of its two hinges' compliances transported to
    the platform centre, the three legs in parallel.  Geometry from prs3-ruiz.md
    eq 2-3 and section 4 (b, L, alpha0), hinge frames from the joints' axes,
    written out here independently of the chains."""
    m, hs, sm = prs3
    b, L, a0 = 47.91e-3, 109.215e-3, math.radians(45)
    a, pz0 = b + L * math.cos(a0), L * math.sin(a0)
    P0 = np.array([0.0, 0.0, pz0])
    by_name = {h.name: cm.six_axis_stiffness(h) for h in hs.hinges}
    K = np.zeros((6, 6))
    for i in range(3):
        R = _rz(2 * math.pi * i / 3)
        A, B = R @ [a, 0.0, 0.0], R @ [b, 0.0, pz0]
        leg = (B - A) / np.linalg.norm(B - A)
        y = R @ [0.0, 1.0, 0.0]
        # revolute notch at C_i = A_i: compliant axis y_i, along the leg
        rev = (leg, y, np.cross(y, leg))
        # spherical neck at B_i: bend about m, bend2 about n, torsion about l (the leg)
        m_ax, n_ax = R @ [0.0, -1.0, 0.0], R @ [math.sin(a0), 0.0, math.cos(a0)]
        sph = (leg, m_ax, n_ax)
        C_leg = np.zeros((6, 6))
        for name, frame, c in ((f"revolute{i + 1}", rev, A), (f"spherical{i + 1}", sph, B)):
            W = np.eye(6)
            W[3:, :3] = _skew(P0 - c)  # the wrench at P0 seen at the hinge centre
            C_leg += W.T @ _hinge_compliance(by_name[name], frame) @ W
        K += np.linalg.inv(C_leg)
    expected = np.linalg.inv(K)
    z0 = sm.start(m.x_home, m.q_home)
    ok, z, lam, _ = sm.newton(z0, np.zeros(6), m.q_home, None, None)
    assert ok
    C = sm.compliance(z, lam, None, None)
    np.testing.assert_allclose(C, expected, rtol=1e-7, atol=1e-9 * np.max(np.abs(expected)))
    # the numbers a designer reads: lateral 3.49 um/N, vertical 0.0163 um/N at home
    assert C[0, 0] == pytest.approx(3.4880e-6, rel=1e-4)
    assert C[2, 2] == pytest.approx(1.6315e-8, rel=1e-4)


def test_small_loads_follow_the_linearization_and_newton_agrees_with_ipopt(prs3):
    """At a prestressed pose (actuators moved), IPOPT's loaded pose minus the unloaded
    one equals C f for a small load, and Newton on the KKT finds the same pose."""
    m, hs, sm = prs3
    q = np.array([1.0e-3, 0.6e-3, 1.4e-3])
    sol = forward_kinematics(m, q, CFG)
    assert sol.ok
    ok, z_u, lam_u, _ = sm.newton(sm.start(sol.x, sol.q), np.zeros(6), q, None, None)
    assert ok
    C = sm.compliance(z_u, lam_u, None, None)
    f = np.array([1e-3, -2e-3, 1e-3, 1e-5, 0.0, -1e-5])  # 1 mN and 10 uN*m
    ok_i, z_i, *_ = sm.ipopt(z_u, f, q, None, None)
    ok_n, z_n, _, _ = sm.newton(z_u, f, q, None, None)
    assert ok_i and ok_n
    d = z_i[:6] - z_u[:6]
    np.testing.assert_allclose(d, C @ f, rtol=1e-4, atol=1e-6 * np.max(np.abs(C @ f)))
    np.testing.assert_allclose(z_i[:6], z_n[:6], rtol=0, atol=1e-12)


def test_stiff_extra_axes_give_the_pseudo_rigid_body_model(prs3):
    """With every axis the kinematics does not move made 1e8 times stiffer, the
    six-axis compliance with actuator springs equals J (K_q + K_a)^-1 J^T, and the
    held actuators' forces at a commanded pose equal the energy method's F."""
    m, hs, _ = prs3
    sm = _rebuilt(m, hs, scale=1e8)
    q = np.array([0.935e-3] * 3)
    sol = forward_kinematics(m, q, CFG)
    ok, z, lam, _ = sm.newton(sm.start(sol.x, sol.q), np.zeros(6), q, None, None)
    assert ok
    sp = cm.static_point(m, hs, sol.x, sol.q)
    F = sm.actuator_reactions(z, lam, np.zeros(6))
    np.testing.assert_allclose(F, sp.F, rtol=1e-6)
    ka = np.full(3, 2e5)
    C6 = sm.compliance(z, lam, ka, F)
    Ck = cm.output_compliance(sp, ka)
    np.testing.assert_allclose(C6[2:5, 2:5], Ck[2:5, 2:5], rtol=1e-5, atol=1e-9 * np.max(np.abs(Ck)))


def _rebuilt(m, hs, scale):
    """The six-axis model with the library's extra-axis stiffnesses times ``scale``."""
    original = cm.six_axis_stiffness

    def scaled(h):
        out = original(h)
        if out is None:
            return None
        return {a: (v if a in h.k else v * scale) for a, v in out.items()}

    import cpm_nlp.analysis.hinge_chains as hc

    hc.six_axis_stiffness = scaled
    try:
        return SixAxisModel(m, hs, m.mechanism.part(hc.LegChains).of(m))
    finally:
        hc.six_axis_stiffness = original


def test_closures_and_energy_gradient_match_central_differences(prs3):
    m, hs, sm = prs3
    rng = np.random.default_rng(3)
    z = sm.start(m.x_home, m.q_home) + 1e-3 * rng.standard_normal(sm.nz) * np.where(sm.rest == 0, 1e-2, 1)
    lam = rng.standard_normal(sm.ng)
    par = np.concatenate([rng.standard_normal(6), np.zeros(9)])
    gl, g, H, A, V = (np.asarray(v, dtype=float) for v in sm.kkt(z, lam, par))
    h = 1e-7
    A_fd = np.column_stack(
        [
            (np.asarray(sm.closure_fn(z + h * e)) - np.asarray(sm.closure_fn(z - h * e))).ravel() / (2 * h)
            for e in np.eye(sm.nz)
        ]
    )
    np.testing.assert_allclose(A, A_fd, rtol=1e-6, atol=1e-8)

    def lag(zz):
        return float(sm.kkt(zz, lam, par)[4]) + float(lam @ np.asarray(sm.closure_fn(zz), dtype=float).ravel())

    g_fd = np.array([(lag(z + h * e) - lag(z - h * e)) / (2 * h) for e in np.eye(sm.nz)])
    np.testing.assert_allclose(gl.ravel(), g_fd, rtol=1e-5, atol=1e-5 * np.max(np.abs(g_fd)))
    H_fd = np.column_stack(
        [
            (np.asarray(sm.kkt(z + h * e, lam, par)[0]) - np.asarray(sm.kkt(z - h * e, lam, par)[0])).ravel() / (2 * h)
            for e in np.eye(sm.nz)
        ]
    )
    np.testing.assert_allclose(H, H_fd, rtol=1e-5, atol=1e-5 * np.max(np.abs(H)))


def test_force_balance_of_a_vertical_load(prs3):
    """A vertical load on the home pose: the legs at 45 deg carry it to the horizontal
    sliders, whose forces add up to the load (each leg's axial force has equal vertical
    and horizontal parts; the hinges' moments are second order for 1 N)."""
    m, hs, sm = prs3
    ok, z_u, lam_u, _ = sm.newton(sm.start(m.x_home, m.q_home), np.zeros(6), m.q_home, None, None)
    f = np.array([0.0, 0.0, 1.0, 0.0, 0.0, 0.0])
    ok, z, lam, *_ = sm.ipopt(z_u, f, m.q_home, None, None)
    assert ok
    F = sm.actuator_reactions(z, lam, f)
    np.testing.assert_allclose(F, [-1 / 3] * 3, rtol=1e-3)


def test_cutting_force_file_with_the_actuators_held():
    """problems/prs3_cutting_force.yaml: 1 N in x, y and z with the actuators held: the
    platform deflects (six-axis hinges), by the compliance C f to within the nonlinearity."""
    out = subprocess.run(
        [sys.executable, "-m", "cpm_nlp", "solve", str(ROOT / "problems/prs3_cutting_force.yaml"), "--json"],
        capture_output=True,
        text=True,
        check=True,
    )
    v = json.loads(out.stdout)["values"]
    assert v["hinge_model"] == "all"
    d, lin = np.array(v["deflection"]), np.array(v["deflection_linear"])
    assert np.linalg.norm(d[:3]) > 1e-6  # micrometres, not zero
    np.testing.assert_allclose(d, lin, rtol=1e-3, atol=1e-3 * np.max(np.abs(lin)))


def test_six_axis_needs_chains(tmp_path):
    """hinge_axes: all on a mechanism whose hinges are not in its legs' chains (the built-in
    rpr: its R and U angles are passive expressions of its file, its legs S-P-S) is bad input:
    exit 2, one message naming the hinge's key and what to do."""
    f = tmp_path / "p.yaml"
    f.write_text(
        "problem: platform_compliance\n"
        "mechanism: {type: rpr, parameters: {r1: 40 mm, r2: 80 mm, P0: 40 mm}}\n"
        "inputs: {hinge_axes: all}\n"
    )
    out = subprocess.run([sys.executable, "-m", "cpm_nlp", "solve", str(f)], capture_output=True, text=True)
    assert out.returncode == 2, out.stderr
    assert "inputs.hinges.R" in out.stderr and "chains" in out.stderr and "Traceback" not in out.stderr
    assert "hinge_axes: kinematic" in out.stderr


def test_filleted_neck_against_adaptive_quadrature():
    """The filleted_rod hinge (prs3-ruiz.md section 5's spherical joint: t_sph = 3 mm neck,
    l_sph = 5 mm straight, R_sph = 4 mm fillets) against scipy's adaptive quadrature of
    the revolved profile, and the plain rod as r -> 0."""
    from scipy.integrate import quad

    E, nu = 72e9, 0.33
    G = E / (2 * (1 + nu))
    d, length, r = 3e-3, 5e-3, 4e-3

    def inertia(x):
        s = abs(x) - length / 2
        D = d if s <= 0 else d + 2 * (r - math.sqrt(r**2 - s**2))
        return math.pi * D**4 / 64

    half = length / 2 + r
    c_bend = quad(lambda x: 1 / (E * inertia(x)), -half, half, points=[-length / 2, length / 2], limit=200)[0]
    k = cm.HINGE_TYPES["filleted_rod"].six_axis(E, G, {"d": d, "l": length, "r": r})
    assert k["bend"] == pytest.approx(1 / c_bend, rel=1e-8)
    assert k["torsion"] == pytest.approx(1 / (c_bend * E / (2 * G)), rel=1e-8)  # J = 2 I
    assert k["bend"] / k["torsion"] == pytest.approx(1 + nu)  # the printed K_Rsph/K_Tsph = 1.336
    rod = cm.HINGE_TYPES["circular_rod"].six_axis(E, G, {"d": d, "l": length})
    thin = cm.HINGE_TYPES["filleted_rod"].six_axis(E, G, {"d": d, "l": length, "r": 1e-12})
    for axis in ht.SIX_AXES:
        assert thin[axis] == pytest.approx(rod[axis], rel=1e-6)


def _solve_file(tmp_path, text, *sets):
    f = tmp_path / "p.yaml"
    f.write_text(text)
    cmd = [sys.executable, "-m", "cpm_nlp", "solve", str(f), "--json"]
    for s in sets:
        cmd += ["--set", s]
    return subprocess.run(cmd, capture_output=True, text=True)


RPS3 = f"""problem: platform_compliance
mechanism: {{file: {ROOT / "problems/mechanisms/rps3.yaml"}}}
inputs:
  material: Al 7075-T6
  hinges:
    base: {{joints: a, type: circular_notch, t: 1 mm, r: 5 mm, w: 10 mm}}
  load: {{px: 0.1 N, pz: 0.1 N, psi: 0.01 N*m}}
"""


def test_a_file_mechanism_of_the_gallery(tmp_path):
    """The 3-RPS of the gallery with notch hinges given in the problem file: its chains come
    from its legs; C is symmetric positive definite and the loaded pose follows C f."""
    out = _solve_file(tmp_path, RPS3)
    assert out.returncode == 0, out.stderr
    v = json.loads(out.stdout)["values"]
    assert v["hinge_model"] == "all"
    C = np.array(v["C"])
    np.testing.assert_allclose(C, C.T, atol=1e-12 * np.max(np.abs(C)))
    assert np.all(np.linalg.eigvalsh(C) > 0)
    np.testing.assert_allclose(v["deflection"], v["deflection_linear"], rtol=1e-3, atol=1e-3 * np.max(np.abs(C)))


RPR = f"""problem: platform_compliance
mechanism: {{file: {ROOT / "problems/mechanisms/rpr.yaml"}, parameters: {{r1: 40 mm, r2: 80 mm, P0: 40 mm}}}}
inputs:
  material: Al 7075-T6
  k_actuator: 1e5 N/m
  hinges:
    R: {{joints: theta_R, type: circular_notch, t: 0.4 mm, r: 4 mm, w: 12 mm}}
  load: {{P: 1 N}}
"""


def test_hinges_the_chains_cannot_place_fall_back_to_the_kinematic_model(tmp_path):
    """The RPR file writes its R and U joints as expressions (its legs are S-P-S), so its
    hinges (its Table 1 R and U, the R given again here) are not in the chains: the default
    says so and uses the kinematic model; asking for hinge_axes: all is bad input (exit 2, the
    key path, what to do)."""
    out = _solve_file(tmp_path, RPR)
    assert out.returncode == 0, out.stderr
    res = json.loads(out.stdout)
    assert res["values"]["hinge_model"] == "kinematic"
    assert "cannot place" in res["message"]
    bad = _solve_file(tmp_path, RPR, "inputs.hinge_axes=all")
    assert bad.returncode == 2 and "Traceback" not in bad.stderr
    assert "inputs.hinges.R" in bad.stderr and "hinge_axes: kinematic" in bad.stderr


@pytest.mark.parametrize(
    ("setting", "needle"),
    [
        ("inputs.hinge_axes=kinematc", "did you mean 'kinematic'"),
        ("inputs.hinge_axes=six", "expected one of 'all', 'kinematic'"),
        ("inputs.hinges.spherical.r=-4 mm", "inputs.hinges.spherical.r"),
        ("inputs.load={px: 1 N*m}", "is not a force"),
    ],
)
def test_bad_input_of_the_six_axis_kind(setting, needle):
    """One clear message and exit 2, the input file untouched."""
    path = ROOT / "problems/prs3_cutting_force.yaml"
    before = path.read_bytes()
    out = subprocess.run(
        [sys.executable, "-m", "cpm_nlp", "solve", str(path), "--set", setting], capture_output=True, text=True
    )
    assert out.returncode == 2 and needle in out.stderr and "Traceback" not in out.stderr
    assert len(out.stderr.strip().splitlines()) == 1
    assert path.read_bytes() == before


def test_a_load_beyond_reach_is_reported_not_converged():
    """10^9 N: IPOPT does not find the loaded pose; the result says so (exit 1), no number."""
    out = subprocess.run(
        [sys.executable, "-m", "cpm_nlp", "solve", str(ROOT / "problems/prs3_cutting_force.yaml"), "--json"]
        + ["--set", "inputs.load={px: 1e9 N}"],
        capture_output=True,
        text=True,
    )
    assert out.returncode == 1
    res = json.loads(out.stdout)
    assert res["status"] == "not_converged" and "deflection" not in res["values"]
