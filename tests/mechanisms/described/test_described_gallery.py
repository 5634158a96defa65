"""The gallery of classic parallel mechanisms described as files (problems/mechanisms/):
five-bar, Delta, 3-RPS, 6-UPS, planar 3-RRR.  Each is checked against an independent
reference written here in numpy from the textbook geometry (not from the file or the
generator): FK of random actuators is solved on the file mechanism, and the closed-form
inverse kinematics below (derived in each test's docstring) must return the actuators.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import cpm_nlp as cn
from cpm_nlp.core.result import Status

NEWTON = cn.SolverConfig("newton")
#: the actuators from the reference IK of a solved FK pose: the pose carries the solver's
#: tolerance (|Φ| <= 1e-10 m), amplified by the inverse Jacobian (up to ~1e2 for these links)
TOL = 1e-10


def _poses(name: str, half: float, n: int = 12, seed: int = 5):
    model = cn.build_model(name)
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(n):
        q = model.q_home + rng.uniform(-half, half, model.closure.nq)
        sol = cn.forward_kinematics(model, q, NEWTON)
        assert sol.status == Status.SOLVED, sol.message
        out.append((sol.x, q))
    return model, out


def _rz(a):
    return np.array([[math.cos(a), -math.sin(a), 0], [math.sin(a), math.cos(a), 0], [0, 0, 1]])


def _ry(a):
    return np.array([[math.cos(a), 0, math.sin(a)], [0, 1, 0], [-math.sin(a), 0, math.cos(a)]])


def _rx(a):
    return np.array([[1, 0, 0], [0, math.cos(a), -math.sin(a)], [0, math.sin(a), math.cos(a)]])


def test_five_bar_against_the_two_circle_ik():
    """Crank angle of arm i: atan2(P - A_i) + s_i acos((l1^2 + rho^2 - l2^2) / (2 l1 rho)),
    s = +1 for the left arm and -1 for the right one (elbows out)."""
    model, poses = _poses("five_bar", math.radians(5))
    d, l1, l2 = (model.parameters[k] for k in ("d", "l1", "l2"))
    for x, q in poses:
        for A, s, qi in (((-d / 2, 0.0), 1.0, q[0]), ((d / 2, 0.0), -1.0, q[1])):
            w = np.array(x) - np.array(A)
            rho = np.hypot(*w)
            want = math.atan2(w[1], w[0]) + s * math.acos((l1**2 + rho**2 - l2**2) / (2 * l1 * rho))
            assert qi == pytest.approx(want, abs=TOL)


def test_delta_against_the_arm_angle_ik():
    """Arm i (radial e_i, tangent axis): |B_i - A_i - la (e_i cos q - z sin q)| = lb, i.e.
    E cos q + F sin q = G with E = w.e_i, F = -w_z, G = (|w|^2 + la^2 - lb^2) / (2 la);
    the root nearer the horizontal arm."""
    model, poses = _poses("delta", math.radians(8))
    rb, rp, la, lb = (model.parameters[k] for k in ("rb", "rp", "la", "lb"))
    for x, q in poses:
        for i in range(3):
            g = 2 * math.pi * i / 3
            e = np.array([math.cos(g), math.sin(g), 0.0])
            w = np.array(x) + rp * e - rb * e
            E, F, G = w @ e, -w[2], (w @ w + la**2 - lb**2) / (2 * la)
            base, half = math.atan2(F, E), math.acos(G / math.hypot(E, F))
            roots = [base + half, base - half]
            want = min(roots, key=abs)
            assert q[i] == pytest.approx(want, abs=TOL)


def _rps_ik(model, x):
    rb, rp = model.parameters["rb"], model.parameters["rp"]
    P = np.array(x[:3])
    R = _ry(x[4]) @ _rx(x[3]) @ _rz(x[5])
    out = []
    for i in range(3):
        e = _rz(2 * math.pi * i / 3)
        A, b = e @ [rb, 0, 0], e @ [rp, 0, 0]
        B = P + R @ b
        out.append((np.linalg.norm(B - A), (B - A) @ (e @ [0, 1, 0])))
    return out


def test_rps3_leg_lengths_and_revolute_planes():
    """l_i = |B_i - A_i| with B_i = P + Ry(theta) Rx(psi) Rz(phi) b_i, and the revolute at
    A_i keeps the leg in the plane normal to its (tangent) axis: (B_i - A_i).t_i = 0."""
    model, poses = _poses("rps3", 3e-3)
    for x, q in poses:
        for qi, (length, off_plane) in zip(q, _rps_ik(model, x)):
            assert qi == pytest.approx(length, abs=1e-12)
            assert abs(off_plane) < 1e-12


def test_ups6_leg_lengths():
    """l = |P + Rz(phi) Ry(theta) Rx(psi) b - a| for the six legs (base pairs about 0, 120,
    240 deg at +-bb/2; platform pairs about 60, 180, 300 deg at -+pb/2)."""
    model, poses = _poses("ups6", 3e-3)
    rb, rp, bb, pb = (model.parameters[k] for k in ("rb", "rp", "bb", "pb"))
    for x, q in poses:
        P = np.array(x[:3])
        R = _rz(x[5]) @ _ry(x[4]) @ _rx(x[3])
        lengths = []
        for sign in (-1, 1):  # legs a1..a3, then b1..b3
            for i in range(3):
                g = 2 * math.pi * i / 3
                A = rb * np.array([math.cos(g + sign * bb / 2), math.sin(g + sign * bb / 2), 0.0])
                gp = g + sign * (math.pi / 3 - pb / 2)
                b = rp * np.array([math.cos(gp), math.sin(gp), 0.0])
                lengths.append(np.linalg.norm(P + R @ b - A))
        np.testing.assert_allclose(q, lengths, rtol=0, atol=1e-12)


def test_rrr3_against_the_two_circle_ik():
    """Crank i: atan2(B_i - A_i) - acos((l1^2 + rho^2 - l2^2) / (2 l1 rho)) (the elbow of the
    reference pose), with B_i = (x, y) + Rz(phi) rp e_i; angles compared modulo 2 pi."""
    model, poses = _poses("rrr3", math.radians(4))
    rb, rp, l1, l2 = (model.parameters[k] for k in ("rb", "rp", "l1", "l2"))
    for x, q in poses:
        for i in range(3):
            g = 2 * math.pi * i / 3
            e = np.array([math.cos(g), math.sin(g)])
            c, s = math.cos(x[2]), math.sin(x[2])
            B = np.array(x[:2]) + rp * np.array([c * e[0] - s * e[1], s * e[0] + c * e[1]])
            w = B - rb * e
            rho = np.hypot(*w)
            want = math.atan2(w[1], w[0]) - math.acos((l1**2 + rho**2 - l2**2) / (2 * l1 * rho))
            assert math.remainder(q[i] - want, 2 * math.pi) == pytest.approx(0.0, abs=TOL)


def test_five_bar_other_working_modes_are_wrong_branch():
    """The mirrored elbow of one arm solves the same closure: reported as wrong_branch."""
    model = cn.build_model("five_bar")
    d, l1, l2 = (model.parameters[k] for k in ("d", "l1", "l2"))
    x = np.array([0.0, model.x_home[1]])
    # the left arm with its elbow in: the other root of the two-circle IK
    w = x - np.array([-d / 2, 0.0])
    rho = np.hypot(*w)
    q1 = math.atan2(w[1], w[0]) - math.acos((l1**2 + rho**2 - l2**2) / (2 * l1 * rho))
    q = np.array([q1, model.q_home[1]])
    status, message, _ = cn.assess(model, x, q, 1e-9)
    assert np.max(np.abs(cn.residual(model, x, q))) < 1e-12  # it closes the loops
    assert status == Status.WRONG_BRANCH, message


def test_prs3_as_built_with_design_values_is_the_paper_model():
    """With the design guide angles (120, 240 deg) and no height errors the as-built file is
    the 3-PRS of the paper: FK and passive angles equal the hand-written module's."""
    design = {"g2": "120 deg", "g3": "240 deg", "dh1": 0, "dh2": 0, "dh3": 0}
    fm = cn.build_model("prs3_as_built", design)
    hm = cn.build_model("prs3", {"b": "47.91 mm", "L": "109.215 mm", "alpha0": "45 deg"})
    rng = np.random.default_rng(3)
    for _ in range(10):
        q = rng.uniform(-2e-3, 2e-3, 3)
        a, b = cn.forward_kinematics(hm, q, NEWTON), cn.forward_kinematics(fm, q, NEWTON)
        assert a.status == b.status == Status.SOLVED
        np.testing.assert_allclose(b.x, a.x, rtol=0, atol=1e-12)
        pa, pb = cn.passive_joints(hm, a.x, q), cn.passive_joints(fm, b.x, q)
        np.testing.assert_allclose([pb[n] for n in pa], list(pa.values()), rtol=0, atol=1e-12)


def test_prs3_as_built_against_eq20_with_the_measured_guides():
    """Eq 20 with each leg's own guide: A_i = a (cos g_i, sin g_i, dh_i), s_i0 = -(cos g_i,
    sin g_i, 0); s_i = k - sqrt(k^2 - |A_iB_i|^2 + L^2), k = s_i0 . A_iB_i (the root of the
    reference configuration), with the guide angles and base heights of Table 3."""
    model, poses = _poses("prs3_as_built", 2e-3)
    p = model.parameters
    a = p["b"] + p["L"] * math.cos(p["alpha0"])
    guides = (0.0, p["g2"], p["g3"])
    heights = (p["dh1"], p["dh2"], p["dh3"])
    assert math.degrees(p["g2"]) == pytest.approx(120 - (5 + 24 / 60) / 60, abs=1e-12)
    for x, q in poses:
        P = np.array(x[:3])
        R = _ry(x[4]) @ _rx(x[3]) @ _rz(x[5])
        for i in range(3):
            e = np.array([math.cos(guides[i]), math.sin(guides[i]), 0.0])
            A = a * e + np.array([0, 0, heights[i]])
            B = P + R @ (p["b"] * np.array([math.cos(2 * math.pi * i / 3), math.sin(2 * math.pi * i / 3), 0]))
            AB = B - A
            k = -e @ AB
            want = k - math.sqrt(k**2 - AB @ AB + p["L"] ** 2)
            assert q[i] == pytest.approx(want, abs=TOL)
