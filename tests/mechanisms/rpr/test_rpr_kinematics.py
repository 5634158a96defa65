"""RPR (2-RPU-UPR) kinematics (rpr-2rpu-upr-zhang-2022.md, eq 2-13, 45):
FK/IK round trips, AD Jacobians against central differences, the screw-theory
route of eq 7-13 against AD to round-off, and the displacement twists of eq 45."""

import casadi as ca
import numpy as np
import pytest

import cpm_nlp as cn
from cpm_nlp.core import screws
from cpm_nlp.mechanisms.rpr import compliance as rc
from cpm_nlp.mechanisms.rpr import screws as rpr

#: eq 26: r1 = 40 mm, r2 = 80 mm, P = 40 mm
PAPER_RPR = {"r1": "40 mm", "r2": "80 mm", "P0": "40 mm"}
POSES = [
    np.array([0.0, 0.0, 0.04]),
    np.array([0.02, -0.01, 0.0402]),
    np.array([-0.3, 0.25, 0.05]),
    np.array([0.5, -0.3, 0.03]),
]


@pytest.fixture(scope="module")
def model():
    return cn.build_model("rpr", PAPER_RPR)


def dj_dx(model, x):
    """d(passive angles)/dx of the file's passive joints (eq 13), by AD (they depend on x only)."""
    q = np.asarray(model.closure.ik(x, model.p)[1]).ravel()
    dx, dq = rc.passive_jacobian(model.closure)(x, q, model.p)
    assert np.all(np.asarray(dq) == 0)
    return np.asarray(dx)


def test_initial_pose(model):
    assert np.allclose(model.x_home, [0, 0, 0.04])
    assert np.allclose(model.q_home, [0.04, 0.04, 0.04])
    assert model.derived["D"] == pytest.approx(0.16 / 3)
    assert np.allclose(cn.residual(model, model.x_home, model.q_home), 0.0)
    assert np.allclose(list(cn.passive_joints(model, model.x_home, model.q_home).values()), 0.0)


def test_rotation_and_joint_points_follow_eq_2_to_5(model):
    theta, alpha, P = 0.3, -0.2, 0.05
    R = np.asarray(rpr.rotation(theta, alpha))
    Ry = np.array([[np.cos(theta), 0, np.sin(theta)], [0, 1, 0], [-np.sin(theta), 0, np.cos(theta)]])
    Rx = np.array([[1, 0, 0], [0, np.cos(alpha), -np.sin(alpha)], [0, np.sin(alpha), np.cos(alpha)]])
    assert np.allclose(R, Ry @ Rx)
    A, B = rpr.joint_points(ca.DM([theta, alpha, P]), model.p)
    o_ = np.array([P * np.sin(theta), 0, P * np.cos(theta)])
    assert np.allclose(np.asarray(B[1]).ravel(), R @ [0, 0.08, 0] + o_)  # eq 4 with B2' of eq 3
    assert np.allclose(np.asarray(A[2]).ravel(), [-0.04, 0, 0])  # eq 5


@pytest.mark.parametrize("x", POSES)
def test_ik_fk_round_trip(model, x):
    ik = cn.inverse_kinematics(model, x)
    assert ik.ok, ik.message
    fk = cn.forward_kinematics(model, ik.q)
    assert fk.ok, fk.message
    assert np.allclose(fk.x, x, atol=1e-10)
    fk_n = cn.forward_kinematics(model, ik.q, cn.SolverConfig("newton"), guess=x + 1e-3)
    assert fk_n.ok and np.allclose(fk_n.x, x, atol=1e-10)
    solved = cn.inverse_kinematics(model, x, method="solve")
    assert solved.ok and np.allclose(solved.q, ik.q, atol=1e-10)


def test_a_pose_with_a_platform_joint_below_the_base_is_the_wrong_branch(model):
    # B2 = o' + R (0, r2, 0) has z = c_theta (r2 s_alpha + P) < 0 for alpha = -0.4, P = 30 mm
    sol = cn.inverse_kinematics(model, [0.5, -0.4, 0.03])
    assert sol.status is cn.Status.WRONG_BRANCH and sol.q is None


def test_fk_reports_an_unreachable_pose(model):
    sol = cn.forward_kinematics(model, [0.04, 0.2, 0.04])  # leg 2 far too long for legs 1, 3
    assert not sol.ok and sol.x is None


def central_jacobian(f, x, h=1e-7):
    cols = []
    for k in range(len(x)):
        dx = np.zeros(len(x))
        dx[k] = h
        cols.append((f(x + dx) - f(x - dx)) / (2 * h))
    return np.column_stack(cols)


@pytest.mark.parametrize("x", POSES)
def test_ad_jacobians_match_central_differences(model, x):
    ik = cn.inverse_kinematics(model, x)
    rep = cn.jacobians(model, ik.x, ik.q)

    def legs(xx):
        return np.asarray(model.closure.ik(xx, model.p)[1]).ravel()

    assert np.allclose(rep.J_inv, central_jacobian(legs, x), rtol=1e-6, atol=1e-9)
    assert np.allclose(rep.J, np.linalg.inv(rep.J_inv))

    def passive(xx):
        return np.asarray(model.closure.passive(xx, legs(xx), model.p)).ravel()

    dj = dj_dx(model, x)
    assert np.allclose(dj, central_jacobian(passive, x), rtol=1e-6, atol=1e-8)


@pytest.mark.parametrize("x", POSES)
def test_screw_theory_jacobian_equals_ad_to_round_off(model, x):
    ik = cn.inverse_kinematics(model, x)
    rep = cn.jacobians(model, ik.x, ik.q)
    st = rpr.screw_jacobian(model, x)
    scale = np.abs(rep.J_inv).max()
    assert np.abs(st.J - rep.J_inv).max() <= 1e-13 * scale  # eq 10: q' = J V
    assert np.abs(st.G - rep.J).max() <= 1e-12 * np.abs(rep.J).max()  # eq 11: V = G q'
    G_p_ad = dj_dx(model, x) @ rep.J
    assert np.abs(st.G_p - G_p_ad).max() <= 1e-12 * np.abs(G_p_ad).max()  # eq 13
    for rates in st.branch_rates:  # eq 12: the constrained twists of every leg carry no motion
        assert np.abs(rates[4:]).max() <= 1e-12 * np.abs(rates).max()


def test_appendix_screws_are_reciprocal_where_eq_9_needs_it(model):
    x = POSES[2]
    out = [np.asarray(v) for v in rpr.screw_function()(x, model.p)]
    for i in range(3):
        ta, tc, wa, wc = out[1 + 4 * i : 5 + 4 * i]
        act = rpr.ACTUATED[i]
        w = wa[:, act]
        for k in range(4):
            if k != act:  # the actuated wrench does no work on the leg's passive joints
                assert screws.reciprocal(w, ta[:, k]) == pytest.approx(0.0, abs=1e-14)
        assert abs(screws.reciprocal(w, ta[:, act])) > 0.01
        for k in range(2):  # constraint wrenches do no work on any permitted twist
            for j in range(4):
                assert screws.reciprocal(wc[:, k], ta[:, j]) == pytest.approx(0.0, abs=1e-14)


def test_printed_motion_screw_system_differs_from_eq_2(model):
    """Eq 7 prints S_t with (P s_theta, 0, -P c_theta) and -x'; eq 2 gives (P c_theta, 0,
    -P s_theta) and +x' (documented in cpm_nlp/mechanisms/rpr/screws.py)."""
    theta, P = 0.3, 0.05
    S = np.asarray(rpr.motion_screws(ca.DM([theta, 0.1, P]), model.p))
    assert np.allclose(S[:, 0], [0, 1, 0, P * np.cos(theta), 0, -P * np.sin(theta)])
    assert np.allclose(S[:, 1], [np.cos(theta), 0, -np.sin(theta), 0, 0, 0])
    assert np.allclose(S[:, 2], [0, 0, 0, np.sin(theta), 0, np.cos(theta)])
    # the velocity of o' along the pose path equals the linear rows (finite differences)
    x = np.array([theta, 0.1, P])
    for k in range(3):
        dx = np.zeros(3)
        dx[k] = 1e-7
        o_plus = np.asarray(rpr.origin((x + dx)[0], (x + dx)[2])).ravel()
        o_minus = np.asarray(rpr.origin((x - dx)[0], (x - dx)[2])).ravel()
        assert np.allclose((o_plus - o_minus) / 2e-7, S[3:, k], atol=1e-8)


#: eq 45, design of eq 26, 10 um on each actuator in turn
T45 = np.array(
    [
        [-6.25e-5, 12.5e-5, -6.25e-5],
        [-12.5e-5, 0, 12.5e-5],
        [0, 0, 0],
        [5.0e-6, 0, -5.0e-6],
        [0, 0, 0],
        [5.0e-6, 0, 5.0e-6],
    ]
)


def test_eq_45_in_the_papers_convention(model):
    x = model.x_home
    G = rpr.screw_jacobian(model, x).G
    c = rpr.reference_point(model, x, "o_prime", None)
    T = rpr.twist_basis(model, x, c, "eq45") @ G * 10e-6
    assert np.allclose(T, T45, rtol=1e-12, atol=1e-18)


def test_eq_45_as_velocities_of_o_prime(model):
    x = model.x_home
    G = rpr.screw_jacobian(model, x).G
    c = rpr.reference_point(model, x, "o_prime", None)
    T = rpr.twist_basis(model, x, c, "velocity") @ G * 10e-6
    expected = T45.copy()
    expected[3] *= -1  # v_x = P dtheta: o' = (P s_theta, 0, P c_theta)
    assert np.allclose(T, expected, rtol=1e-12, atol=1e-18)


def test_twists_at_other_reference_points(model):
    x = POSES[1]
    G = rpr.screw_jacobian(model, x).G
    S_o_prime = rpr.twist_basis(model, x, rpr.reference_point(model, x, "o_prime", None), "velocity")
    for point in ([0.0, 0.0, 0.0], [0.01, -0.02, 0.05]):
        S_c = rpr.twist_basis(model, x, np.array(point), "velocity")
        o_ = rpr.reference_point(model, x, "o_prime", None)
        for k in range(3):
            assert np.allclose(S_c[:, k], screws.transport(S_o_prime[:, k], o_, point))
    # the eq45 convention differs from velocities only in the rotations' moments
    S45 = rpr.twist_basis(model, x, np.zeros(3), "eq45")
    S_v = rpr.twist_basis(model, x, np.zeros(3), "velocity")
    assert np.allclose(S45[:3], S_v[:3]) and np.allclose(S45[3:, 2], S_v[3:, 2])
    assert np.allclose((S45 @ G)[3:], (2 * S_v[:, 2:3] @ G[2:3] - S_v @ G)[3:])
