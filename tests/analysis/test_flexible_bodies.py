"""Flexible bodies in the six-axis hinge model (stiffness.bodies / inputs.bodies): the 3-PRS
with its legs as beams, against the compliance-matrix method written out in numpy (each leg
its two hinges and the beam's cantilever closed form in series), AD against central
differences, the forces against the energy's derivative, the problem file, and bad input."""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from cpm_nlp.analysis import compliance as cm
from cpm_nlp.analysis.hinge_chains import six_axis_model
from cpm_nlp.analysis.hinge_models import six_axis_point
from cpm_nlp.core.kinematics import forward_kinematics
from cpm_nlp.core.solver import SolverConfig
from cpm_nlp.mechanisms.registry import build_model

ROOT = Path(__file__).resolve().parents[2]
PRS3 = {"b": "47.91 mm", "L": "109.215 mm", "alpha0": "45 deg"}
E, NU = 72e9, 0.33  # Ruiz et al. section 4
SIDE = 10e-3  # the 10 x 10 mm^2 legs, section 4


def _legs(n=2, model="distributed", theory="timoshenko"):
    return {
        "leg": {
            "between": ["alpha", "beta_m"],
            "section": {"b": "10 mm", "h": "10 mm"},
            "elements": n,
            "stiffness": model,
            "beam": theory,
        }
    }


@pytest.fixture(scope="module")
def prs3():
    m = build_model("prs3", PRS3)
    hs = cm.hinge_set(m, None, bodies=_legs())
    return m, hs, six_axis_model(m, hs)


def _rz(angle):
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def _skew(r):
    return np.array([[0.0, -r[2], r[1]], [r[2], 0.0, -r[0]], [-r[1], r[0], 0.0]])


def _hinge_compliance(k, frame):
    t, b1, b2 = frame
    Ct = np.outer(t, t) / k["axial"] + np.outer(b2, b2) / k["shear"] + np.outer(b1, b1) / k["shear2"]
    Cr = np.outer(b1, b1) / k["bend"] + np.outer(b2, b2) / k["bend2"] + np.outer(t, t) / k["torsion"]
    C = np.zeros((6, 6))
    C[:3, :3], C[3:, 3:] = Ct, Cr
    return C


def _beam_compliance(length, x, y):
    """The Timoshenko cantilever's tip compliance of a square a x a section, base axes (x along
    the beam, y, z = x × y), written out: L/EA, L^3/3EI + L/(kappa G A), L^2/2EI, L/GJ, L/EI."""
    G = E / (2 * (1 + NU))
    A, inertia = SIDE**2, SIDE**4 / 12
    J = SIDE**4 * (1 / 3 - 0.21 * (1 - 1 / 12))  # Roark Table 10.7 case 4, a = c
    kappa = 10 * (1 + NU) / (12 + 11 * NU)  # Cowper 1966, rectangle
    z = np.cross(x, y)
    lat = length**3 / (3 * E * inertia) + length / (kappa * G * A)
    Ct = np.outer(x, x) * length / (E * A) + (np.outer(y, y) + np.outer(z, z)) * lat
    Cr = np.outer(x, x) * length / (G * J) + (np.outer(y, y) + np.outer(z, z)) * length / (E * inertia)
    c = length**2 / (2 * E * inertia)
    Ctr = c * (np.outer(y, z) - np.outer(z, y))  # F_y turns the tip about +z, F_z about -y
    C = np.zeros((6, 6))
    C[:3, :3], C[3:, 3:], C[:3, 3:], C[3:, :3] = Ct, Cr, Ctr, Ctr.T
    return C


def test_home_compliance_with_flexible_legs_equals_the_compliance_matrix_method(prs3):
    """At the unstressed home pose: each leg the revolute hinge at C_i, the beam C_iB_i (its
    cantilever compliance at B_i) and the spherical hinge at B_i in series, carried to the
    platform centre; the three legs in parallel.  Geometry from prs3-ruiz.md eq 2-3 and section 4."""
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
        rev = (leg, y, np.cross(y, leg))
        sph = (leg, R @ [0.0, -1.0, 0.0], R @ [math.sin(a0), 0.0, math.cos(a0)])
        C_leg = np.zeros((6, 6))
        parts = [
            (_hinge_compliance(by_name[f"revolute{i + 1}"], rev), A),
            (_hinge_compliance(by_name[f"spherical{i + 1}"], sph), B),
            (_beam_compliance(L, leg, y), B),
        ]
        for C_part, c in parts:
            W = np.eye(6)
            W[3:, :3] = _skew(P0 - c)  # the wrench at P0 seen at c
            C_leg += W.T @ C_part @ W
        K += np.linalg.inv(C_leg)
    expected = np.linalg.inv(K)
    ok, z, lam, _ = sm.newton(sm.start(m.x_home, m.q_home), np.zeros(6), m.q_home, None, None)
    assert ok
    C = sm.compliance(z, lam, None, None)
    np.testing.assert_allclose(C, expected, rtol=1e-7, atol=1e-9 * np.max(np.abs(expected)))
    # flexible legs: the lateral compliance 4.74 um/N (3.49 with rigid legs), vertical 0.0264 um/N (0.0163)
    assert C[0, 0] == pytest.approx(4.7365e-6, rel=1e-4)
    assert C[2, 2] == pytest.approx(2.6421e-8, rel=1e-4)


def test_lumped_elements_converge_to_the_distributed_compliance(prs3):
    m, _, sm = prs3

    def compliance(n, model):
        hs = cm.hinge_set(m, None, bodies=_legs(n, model))
        s = six_axis_model(m, hs)
        ok, z, lam, _ = s.newton(s.start(m.x_home, m.q_home), np.zeros(6), m.q_home, None, None)
        assert ok
        return s.compliance(z, lam, None, None)

    ref = compliance(1, "distributed")
    errs = [abs(compliance(n, "lumped")[2, 2] / ref[2, 2] - 1) for n in (2, 4, 8)]
    assert errs[0] > errs[1] > errs[2] and errs[2] < 2e-3


def test_closures_and_energy_gradient_with_beams_match_central_differences(prs3):
    m, hs, sm = prs3
    rng = np.random.default_rng(5)
    z = sm.start(m.x_home, m.q_home) + 1e-4 * rng.standard_normal(sm.nz) * np.where(sm.rest == 0, 1e-2, 1)
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
    H_fd = np.column_stack(
        [
            (np.asarray(sm.kkt(z + h * e, lam, par)[0]) - np.asarray(sm.kkt(z - h * e, lam, par)[0])).ravel() / (2 * h)
            for e in np.eye(sm.nz)
        ]
    )
    np.testing.assert_allclose(H, H_fd, rtol=1e-5, atol=1e-5 * np.max(np.abs(H)))


def test_forces_are_the_energy_derivative_and_K_q_its_second():
    """At a Table 2 stroke, F = dV/ds and K_q = dF/ds, both against central differences of
    equilibria solved at s ± h (each leg, all three actuators moved together)."""
    m = build_model("prs3", PRS3)
    hs = cm.hinge_set(m, None, bodies=_legs(2))
    sm = six_axis_model(m, hs)
    cfg = SolverConfig()

    def at(s):
        sol = forward_kinematics(m, np.asarray(s, dtype=float), cfg)
        sp, _ = six_axis_point(sm, m, sol.x, sol.q, np.zeros(6))
        return sp

    s0 = np.array([0.935e-3, 0.9e-3, 0.95e-3])
    sp = at(s0)
    h = 1e-7
    for j in range(3):
        e = np.eye(3)[j] * h
        dV = (at(s0 + e).energy - at(s0 - e).energy) / (2 * h)
        assert sp.F[j] == pytest.approx(dV, rel=1e-5)
        dF = (at(s0 + e).F - at(s0 - e).F) / (2 * h)
        np.testing.assert_allclose(sp.K_q[:, j], dF, rtol=1e-4)


def test_table2_with_flexible_legs_file():
    """The shipped problem: the legs' bending lowers the notch stress towards the FEM's
    (169.25 MPa, Ruiz et al. Table 2) from the rigid legs' 177.6 MPa; the file's reproduce rows
    hold."""
    out = subprocess.run(
        [sys.executable, "-m", "cpm_nlp", "solve", str(ROOT / "problems/prs3_table2_flexible_legs.yaml"), "--json"],
        capture_output=True,
        text=True,
    )
    assert out.returncode == 0, out.stderr
    v = json.loads(out.stdout)["values"]
    assert v["stress_max"][0] == pytest.approx(169.26e6, rel=1e-3)
    assert v["F1"][0] == pytest.approx(19.435, rel=1e-3)
    assert v["dz_at_allowable"] == pytest.approx(2.1635e-3, rel=1e-3)
    assert all(s > 0 for s in v["beam_stress_max"])
    rep = subprocess.run(
        [sys.executable, "-m", "cpm_nlp", "reproduce", str(ROOT / "problems/prs3_table2_flexible_legs.yaml")],
        capture_output=True,
        text=True,
    )
    assert rep.returncode == 0, rep.stderr
    assert "0 unexpected" in rep.stdout


FLEX = """problem: platform_compliance
mechanism: {type: prs3, parameters: {b: 47.91 mm, L: 109.215 mm, alpha0: 45 deg}}
inputs:
  bodies:
    leg: {between: [alpha, beta_m], section: {b: 10 mm, h: 10 mm}, elements: 2}
"""


@pytest.mark.parametrize(
    ("setting", "needle"),
    [
        ("inputs.bodies.leg.between=[s, beta_m]", "not neighbouring joints"),
        ("inputs.bodies.leg.between=[alpa, beta_m]", "did you mean 'alpha'"),
        ("inputs.bodies.leg.section={b: 10 mm}", "inputs.bodies.leg.section: expected a section"),
        ("inputs.bodies.leg.stiffness=lumpd", "did you mean 'lumped'"),
        ("inputs.bodies.leg.elements=0", "inputs.bodies.leg.elements"),
        ("inputs.bodies.leg.elemnts=3", "did you mean 'elements'"),
        ("inputs.hinge_axes=kinematic", "hinge_axes: all"),
    ],
)
def test_bad_bodies(tmp_path, setting, needle):
    f = tmp_path / "p.yaml"
    f.write_text(FLEX)
    out = subprocess.run(
        [sys.executable, "-m", "cpm_nlp", "solve", str(f), "--set", setting], capture_output=True, text=True
    )
    assert out.returncode == 2 and needle in out.stderr and "Traceback" not in out.stderr, out.stderr


def test_a_mechanism_file_declares_flexible_bodies(tmp_path):
    """stiffness.bodies of a mechanism file: the defaults of the compliance kinds; a problem removes
    one with null; natural_frequencies (rigid links) refuses them with the key path."""
    text = (ROOT / "problems/mechanisms/prs3.yaml").read_text()
    text = text.replace(
        "  material: {name: Al 7075 (prs3-ruiz)",
        "  bodies:\n    leg: {between: [alpha, beta_m], section: {b: 10 mm, h: 10 mm}, elements: 1}\n"
        "  material: {name: Al 7075 (prs3-ruiz)",
    )
    text = text.replace("examples: [", "examples_off: [").split("examples_off:")[0]
    text = text.replace("name: prs3\n", "name: prs3_flex\n")
    mech = tmp_path / "flex.yaml"
    mech.write_text(text)
    prob = tmp_path / "p.yaml"
    prob.write_text(
        f"problem: platform_compliance\nmechanism: {{file: {mech}, parameters: {{b: 47.91 mm, L: 109.215 mm}}}}\n"
    )
    described = subprocess.run([sys.executable, "-m", "cpm_nlp", "describe", str(mech)], capture_output=True, text=True)
    assert "leg        flexible body: between: ['alpha', 'beta_m']" in described.stdout, described.stderr
    cmd = [sys.executable, "-m", "cpm_nlp", "solve", str(prob), "--json"]
    out = subprocess.run(cmd, capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    assert json.loads(out.stdout)["values"]["C_px"] == pytest.approx(4.7365e-6, rel=1e-4)
    out = subprocess.run(
        [sys.executable, "-m", "cpm_nlp", "solve", str(prob), "--json", "--set", "inputs.bodies={leg: null}"],
        capture_output=True,
        text=True,
    )
    assert out.returncode == 0, out.stderr
    assert json.loads(out.stdout)["values"]["C_px"] == pytest.approx(3.4880e-6, rel=1e-4)
    prob.write_text(
        f"problem: natural_frequencies\nmechanism: {{file: {mech}, parameters: {{b: 47.91 mm, L: 109.215 mm}}}}\n"
        "inputs: {masses: {pz: 100 g}}\n"
    )
    out = subprocess.run([sys.executable, "-m", "cpm_nlp", "solve", str(prob)], capture_output=True, text=True)
    assert out.returncode == 2 and "stiffness.bodies" in out.stderr and "Traceback" not in out.stderr, out.stderr


NOTCH = {"profile": "circular_notch", "t": "2 mm", "r": "8 mm", "w": "20 mm", "kappa": 5 / 6}


def test_a_notch_hinge_as_a_beam_of_varying_section_in_the_mechanism():
    """The 3-PRS revolute notch (t 2, r 8 mm; w 20 mm, where Lobontiu's torsion holds) as a beam
    whose thickness follows the notch profile (``at: alpha``), in place of its six-axis spring:
    the home compliance equals that of the six-axis spring with Lobontiu's compliances
    (circular_notch_compliances, the hinge's formula stiffness, shear coefficient 6/5)."""
    m = build_model("prs3", PRS3)
    hinges = {"revolute": {"k": None, "w": "20 mm"}}

    def compliance(bodies):
        hs = cm.hinge_set(m, hinges, bodies=bodies)
        sm = six_axis_model(m, hs)
        ok, z, lam, _ = sm.newton(sm.start(m.x_home, m.q_home), np.zeros(6), m.q_home, None, None)
        assert ok
        return sm.compliance(z, lam, None, None)

    ref = compliance(None)
    C = compliance({"notch": {"at": "alpha", "section": NOTCH, "elements": 4}})
    np.testing.assert_allclose(C, ref, rtol=1e-6, atol=1e-6 * np.max(np.abs(ref)))


def test_a_notch_hinge_as_a_beam_under_the_table2_strokes():
    """Geometrically nonlinear notch beam against the six-axis spring at the Table 2 strokes
    (rotations up to 2 degrees): forces and the thinnest section's nominal stress within 0.1 %, z
    within 2 um (1.2 um apart: the beam bends along its 16 mm, where the spring turns about a point)."""
    m = build_model("prs3", PRS3)
    hinges = {"revolute": {"k": None}}
    notch = {**NOTCH, "w": "10 mm"}
    notch.pop("kappa")
    cfg = SolverConfig()
    got = []
    for bodies in (None, {"notch": {"at": "alpha", "section": notch, "elements": 8}}):
        hs = cm.hinge_set(m, hinges, bodies=bodies)
        sm = six_axis_model(m, hs)
        sol = forward_kinematics(m, np.full(3, 2.865e-3), cfg)
        sp, _ = six_axis_point(sm, m, sol.x, sol.q, np.zeros(6))
        got.append(sp)
    assert got[1].F[0] == pytest.approx(got[0].F[0], rel=1e-3)
    assert got[1].stress_max == pytest.approx(got[0].stress_max, rel=1e-3)
    assert got[1].x[2] == pytest.approx(got[0].x[2], abs=2e-6)


@pytest.mark.parametrize(
    ("body", "needle"),
    [
        ({"at": "s", "section": NOTCH}, "a hinge beam sits at a passive joint"),
        ({"section": NOTCH}, "give either between"),
        ({"at": "alpha", "section": {"b": "10 mm", "h": "2 mm"}}, "needs its length"),
    ],
)
def test_bad_hinge_beams(body, needle):
    m = build_model("prs3", PRS3)
    with pytest.raises(cm.InputError, match=needle):
        six_axis_model(m, cm.hinge_set(m, None, bodies={"notch": body}))


def test_small_loads_follow_the_linearization_with_flexible_legs(prs3):
    """The loaded pose by IPOPT (minimum potential energy, the legs' beams geometrically
    nonlinear) under 1 N in x, y, z follows C f; Newton and IPOPT agree on the unloaded pose."""
    m, hs, sm = prs3
    ok, z_u, lam_u, _ = sm.newton(sm.start(m.x_home, m.q_home), np.zeros(6), m.q_home, None, None)
    assert ok
    ok_i, z_i, *_ = sm.ipopt(sm.start(m.x_home, m.q_home), np.zeros(6), m.q_home, None, None)
    assert ok_i
    np.testing.assert_allclose(z_i[:6], z_u[:6], atol=1e-12)
    C = sm.compliance(z_u, lam_u, None, None)
    f = np.array([1.0, 1.0, 1.0, 0.0, 0.0, 0.0])
    ok, z, *_ = sm.ipopt(z_u, f, m.q_home, None, None)
    assert ok
    d = z[:6] - z_u[:6]
    np.testing.assert_allclose(d, C @ f, rtol=2e-3, atol=2e-3 * np.max(np.abs(C @ f)))


def test_actuator_forces_with_six_axis_hinges_and_rigid_legs():
    """hinge_axes: all without bodies: the six-axis equilibrium at the Table 2 strokes, within
    0.5 % of the energy method on the kinematics (the hinges' extra axes add a little
    compliance); asking for the kinematic model with flexible bodies is bad input."""
    path = str(ROOT / "problems/prs3_fem_table2.yaml")

    def solve(*extra):
        cmd = [sys.executable, "-m", "cpm_nlp", "solve", path, "--json", *extra]
        out = subprocess.run(cmd, capture_output=True, text=True)
        assert out.returncode == 0, out.stderr
        return json.loads(out.stdout)["values"]

    kin, six = solve(), solve("--set", "inputs.hinge_axes=all")
    np.testing.assert_allclose(six["F1"], kin["F1"], rtol=5e-3)
    np.testing.assert_allclose(six["stress_max"], kin["stress_max"], rtol=5e-3)
    assert "beam_stress_max" not in six
    flex = str(ROOT / "problems/prs3_table2_flexible_legs.yaml")
    cmd = [sys.executable, "-m", "cpm_nlp", "solve", flex, "--set", "inputs.hinge_axes=kinematic"]
    bad = subprocess.run(cmd, capture_output=True, text=True)
    assert bad.returncode == 2 and "inputs.hinge_axes" in bad.stderr and "hinge_axes: all" in bad.stderr
