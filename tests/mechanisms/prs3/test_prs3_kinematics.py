"""3-PRS kinematics (prs3-ruiz.md): loop closures, IK, FK, passive joints.

Every FK solution is checked against IK, every AD Jacobian against central
differences.
"""

import math

import numpy as np
import pytest

import cpm_nlp as cn
from cpm_nlp.core.result import Status
from tests.conftest import central_difference
from tests.reference import prs3_closures as P

NEWTON = cn.SolverConfig(method="newton")
IPOPT = cn.SolverConfig(method="ipopt")


TILT = math.radians(0.2)


def random_task(rng, n, dz=2e-3, tilt=TILT):
    """Poses in the paper's working range: z +-2 mm, psi and theta +-0.2 deg (section 4)."""
    return np.column_stack([rng.uniform(-dz, dz, n), rng.uniform(-tilt, tilt, n), rng.uniform(-tilt, tilt, n)])


def test_home_pose_geometry(prs3):
    # a follows from alpha0 (see problems/mechanisms/prs3.yaml): a = b + L cos(alpha0), pz0 = L sin(alpha0)
    b, L = 47.91e-3, 109.215e-3
    assert prs3.derived["a"] == pytest.approx(b + L * math.cos(math.pi / 4), rel=1e-15)
    assert prs3.derived["a"] == pytest.approx(0.1251366671, rel=1e-9)
    assert prs3.derived["pz0"] == pytest.approx(L / math.sqrt(2), rel=1e-15)
    assert np.max(np.abs(cn.residual(prs3, prs3.x_home, prs3.q_home))) < 1e-16
    joints = cn.passive_joints(prs3, prs3.x_home, prs3.q_home)
    for i in (1, 2, 3):
        assert joints[f"alpha{i}"] == pytest.approx(math.pi / 4, abs=1e-14)  # eq 22 at home
        for fam in ("beta_m", "beta_n", "beta_l"):
            assert joints[f"{fam}{i}"] == pytest.approx(0.0, abs=1e-14)  # frames F_i, F_i0 overlap


def test_ik_zero_at_home(prs3):
    # eq 20, minus root: s = 0 at the home pose (the branch the model designates)
    sol = cn.inverse_kinematics(prs3, [prs3.derived["pz0"], 0.0, 0.0])
    assert sol.status is Status.SOLVED
    np.testing.assert_allclose(sol.q, 0.0, atol=1e-15)


def test_parasitic_motions_satisfy_leg_planes(prs3):
    # eq 13-15 are derived from eq 7-9: at IK poses the leg-plane residuals vanish
    rng = np.random.default_rng(1)
    pz0 = prs3.derived["pz0"]
    for dz, psi, theta in random_task(rng, 50, tilt=math.radians(5)):
        sol = cn.inverse_kinematics(prs3, [pz0 + dz, psi, theta])
        assert sol.ok
        res = cn.residual(prs3, sol.x, sol.q)
        assert np.max(np.abs(res)) < 1e-15


def test_fk_of_ik_round_trip_100_random_poses(prs3):
    """FK(IK(pose)) = pose for 100 random poses of the working range, both solvers."""
    rng = np.random.default_rng(2024)
    pz0 = prs3.derived["pz0"]
    for dz, psi, theta in random_task(rng, 100):
        ik = cn.inverse_kinematics(prs3, [pz0 + dz, psi, theta])
        assert ik.ok, ik.message
        # IPOPT stops at its tolerance (ipopt.tol = 1e-12 on the scaled NLP); Newton polishes to round-off
        for cfg, atol in ((IPOPT, 1e-10), (NEWTON, 1e-13)):
            fk = cn.forward_kinematics(prs3, ik.q, cfg)
            assert fk.status is Status.SOLVED, fk.message
            np.testing.assert_allclose(fk.x, ik.x, rtol=0, atol=atol)
            np.testing.assert_allclose(fk.passive, ik.passive, rtol=0, atol=10 * atol)


def test_solved_ik_matches_closed_form(prs3):
    rng = np.random.default_rng(7)
    pz0 = prs3.derived["pz0"]
    for dz, psi, theta in random_task(rng, 20):
        t = [pz0 + dz, psi, theta]
        closed = cn.inverse_kinematics(prs3, t, method="closed_form")
        for cfg in (IPOPT, NEWTON):
            solved = cn.inverse_kinematics(prs3, t, cfg, method="solve")
            assert solved.ok, solved.message
            np.testing.assert_allclose(solved.q, closed.q, atol=1e-13)
            np.testing.assert_allclose(solved.x, closed.x, atol=1e-13)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_ad_jacobians_against_central_differences(prs3, seed):
    rng = np.random.default_rng(seed)
    pz0 = prs3.derived["pz0"]
    dz, psi, theta = random_task(rng, 1)[0]
    sol = cn.inverse_kinematics(prs3, [pz0 + dz, psi, theta])
    x, q = sol.x, sol.q
    rep = cn.jacobians(prs3, x, q)
    # Phi_x and Phi_q against central differences of Phi
    cd_x = central_difference(lambda xx: cn.residual(prs3, xx, q), x, 1e-7)
    cd_q = central_difference(lambda qq: cn.residual(prs3, x, qq), q, 1e-7)
    np.testing.assert_allclose(rep.phi_x, cd_x, atol=1e-8)
    np.testing.assert_allclose(rep.phi_q, cd_q, atol=1e-8)
    # forward Jacobian dx/dq against central differences of FK (Newton, tight)
    fk = lambda qq: cn.forward_kinematics(prs3, qq, NEWTON, guess=x).x  # noqa: E731
    np.testing.assert_allclose(rep.J, central_difference(fk, q, 1e-7), atol=1e-6 * np.max(np.abs(rep.J)))
    # inverse Jacobian dq/dt against central differences of the closed-form IK
    ik = lambda tt: cn.inverse_kinematics(prs3, tt).q  # noqa: E731
    t = prs3.task_of(x)
    np.testing.assert_allclose(rep.J_inv, central_difference(ik, t, 1e-8), rtol=1e-6, atol=1e-8)
    # and the two are inverse to each other
    np.testing.assert_allclose(rep.J_inv @ rep.J_task, np.eye(3), atol=1e-12)


def test_passive_joint_reconstruction(prs3):
    """beta_m, beta_n, beta_l of eq 33 rebuild R_iSjoint of eq 24 through eq 32."""
    import casadi as ca

    sol = cn.inverse_kinematics(prs3, [prs3.derived["pz0"] + 1.5e-3, math.radians(0.2), math.radians(-0.15)])
    x, q = sol.x, sol.q
    p = prs3.p
    j = cn.passive_joints(prs3, x, q)
    R = np.array(ca.evalf(P.rotation(x[3], x[4], x[5])))  # eq 4
    for i in range(3):
        l0 = np.array(ca.evalf(P.OB(i, ca.DM(x[:3]), ca.DM(R), p[0]) - P.OC(i, q[i], prs3.derived["a"])))
        l0 = l0.ravel() / p[1]  # eq 21
        m0 = np.array(P.m0(i)).ravel()  # eq 25
        RR = np.column_stack([m0, np.cross(l0, m0), l0])  # eq 26-27
        g = P.GAMMA[i]
        a0 = p[2]
        Rim = np.column_stack(
            [
                m0,
                [math.sin(a0) * math.cos(g), math.sin(a0) * math.sin(g), math.cos(a0)],
                [-math.cos(a0) * math.cos(g), -math.cos(a0) * math.sin(g), math.sin(a0)],
            ]
        )
        RS = RR.T @ R @ Rim  # eq 24
        bm, bn, bl = j[f"beta_m{i + 1}"], j[f"beta_n{i + 1}"], j[f"beta_l{i + 1}"]
        Rm = np.array([[1, 0, 0], [0, math.cos(bm), -math.sin(bm)], [0, math.sin(bm), math.cos(bm)]])
        Rn = np.array([[math.cos(bn), 0, math.sin(bn)], [0, 1, 0], [-math.sin(bn), 0, math.cos(bn)]])
        Rl = np.array([[math.cos(bl), -math.sin(bl), 0], [math.sin(bl), math.cos(bl), 0], [0, 0, 1]])
        np.testing.assert_allclose(Rm @ Rn @ Rl, RS, atol=1e-14)  # eq 32
        # eq 22: the revolute angle is the angle between leg and slider direction
        assert j[f"alpha{i + 1}"] == pytest.approx(math.acos(l0 @ (-np.array([math.cos(g), math.sin(g), 0]))))


def test_pure_vertical_translation_bends_only_about_m(prs3):
    # Fig. 3: for a pure z motion the spherical joints bend about m by alpha_i - alpha0
    sol = cn.inverse_kinematics(prs3, [prs3.derived["pz0"] + 1e-3, 0.0, 0.0])
    j = sol.passive
    names = prs3.closure.passive_names
    for i in (1, 2, 3):
        d_alpha = j[names.index(f"alpha{i}")] - math.pi / 4
        assert j[names.index(f"beta_m{i}")] == pytest.approx(d_alpha, rel=1e-12)
        assert abs(j[names.index(f"beta_n{i}")]) < 1e-14
        assert abs(j[names.index(f"beta_l{i}")]) < 1e-14


def test_wrong_branch_is_reported_not_returned(prs3):
    """Newton started below the actuator plane converges to the mirrored
    assembly; the tool says so instead of returning its numbers."""
    guess = prs3.x_home.copy()
    guess[2] = -guess[2]
    sol = cn.forward_kinematics(prs3, [0.5e-3, 0.2e-3, 0.1e-3], NEWTON, guess=guess, continuation=False)
    assert sol.status is Status.WRONG_BRANCH
    assert sol.x is None and sol.q is None
    # by default FK then follows the designated branch from home (issue 20): the working pose
    cont = cn.forward_kinematics(prs3, [0.5e-3, 0.2e-3, 0.1e-3], NEWTON, guess=guess)
    home = cn.forward_kinematics(prs3, [0.5e-3, 0.2e-3, 0.1e-3], NEWTON)
    assert cont.ok and "continuation from home" in cont.solver and cont.details["first_attempt"].startswith("wrong")
    np.testing.assert_allclose(cont.x, home.x, rtol=0, atol=1e-12)


def test_unreachable_pose(prs3):
    sol = cn.inverse_kinematics(prs3, [0.2, 0.0, 0.0])  # 200 mm high: legs are 109 mm
    assert sol.status is Status.UNREACHABLE
    assert sol.message.startswith("the closed-form IK has no real solution (reach margin -")
    assert sol.x is None and sol.q is None


def test_fk_far_out_of_reach_is_not_a_number(prs3):
    for cfg in (IPOPT, NEWTON):
        sol = cn.forward_kinematics(prs3, [0.3, -0.3, 0.0], cfg)
        assert sol.status is not Status.SOLVED
        assert sol.x is None


def test_joint_limits_reported(prs3):
    limited = cn.build_model("prs3", {"b": "47.91 mm", "L": "109.215 mm"}, {"s": ["-1 mm", "1 mm"]})
    sol = cn.inverse_kinematics(limited, [limited.derived["pz0"] + 2e-3, 0.0, 0.0])
    assert sol.status is Status.OUTSIDE_JOINT_LIMITS
    assert "s1 = " in sol.message
    limited = cn.build_model("prs3", {"b": "47.91 mm", "L": "109.215 mm"}, {"beta_m": ["-1 deg", "1 deg"]})
    sol = cn.forward_kinematics(limited, [2e-3, 2e-3, 2e-3])
    assert sol.status is Status.OUTSIDE_JOINT_LIMITS
    assert "beta_m1" in sol.message


def test_singularity_measures(prs3):
    rep = cn.jacobians(prs3, prs3.x_home, prs3.q_home)
    # At home the three legs are at 45 deg: dz/ds_i = 1/3 each (tan 45 = 1)
    np.testing.assert_allclose(rep.J_task[0], [1 / 3] * 3, rtol=1e-12)
    # Yoshikawa: sqrt(det(J J^T)) = |det J| for a square J
    assert rep.manipulability == pytest.approx(abs(np.linalg.det(np.diag([1, 47.91e-3, 47.91e-3]) @ rep.J_task)))
    sv = np.linalg.svd(np.diag([1, 47.91e-3, 47.91e-3]) @ rep.J_task, compute_uv=False)
    assert rep.cond == pytest.approx(sv[0] / sv[-1])
    assert rep.det_phi_x != 0 and rep.det_phi_y != 0
    # nearly flat legs approach a forward (type II) singularity: det(Phi_x) -> 0, J -> infinity
    flat = cn.build_model("prs3", {"b": "47.91 mm", "L": "109.215 mm", "alpha0": "0.5 deg"})
    rep_flat = cn.jacobians(flat, flat.x_home, flat.q_home)
    assert abs(rep_flat.det_phi_x) < 1e-4 * abs(rep.det_phi_x)
    assert rep_flat.manipulability > 1e4 * rep.manipulability
    # nearly vertical legs approach an inverse (type I) singularity: det(Phi_y) -> 0, J -> 0
    steep = cn.build_model("prs3", {"b": "47.91 mm", "L": "109.215 mm", "alpha0": "89.5 deg"})
    rep_steep = cn.jacobians(steep, steep.x_home, steep.q_home)
    assert abs(rep_steep.det_phi_y) < 1e-4 * abs(rep.det_phi_y)
    assert rep_steep.manipulability < 1e-4 * rep.manipulability


def test_symbolic_functions_are_named(prs3):
    c = prs3.closure
    assert c.phi.name() == "phi" and c.phi.name_in() == ["x", "q", "p"] and c.phi.name_out() == ["phi"]
    assert c.jacobian.name_out() == ["J"]
    assert c.ik.name_in() == ["t", "p"] and c.ik.name_out() == ["x", "q", "reach"]
