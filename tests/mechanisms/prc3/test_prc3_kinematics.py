"""3-PRC kinematics (prc3-li-2018.md): loop closures, IK (eq 8-10), FK, the
Jacobian of eq 21 against AD and central differences, and the workspace
(eq 27).  Every FK solution is checked against IK."""

import json
import math

import numpy as np
import pytest

import cpm_nlp as cn
from cpm_nlp.analysis import workspace as W
from cpm_nlp.core.result import Status
from tests.conftest import PROBLEMS, central_difference
from tests.reference import prc3_closures as P

#: Table 1 (kinematic part) and eq 27: l = L7 = 73.5 mm, 0 <= q_i <= 15 um
TABLE1 = {"L1": "9.5 mm", "L2": "25 mm", "L3": "9 mm", "L4": "30 mm", "L7": "73.5 mm"}
L, A2 = 73.5e-3, 25 * 30 / (9.5 * 9)
QMAX = 15e-6

NEWTON = cn.SolverConfig("newton")
IPOPT = cn.SolverConfig("ipopt")
# tight settings: Newton's default step tolerance (abstolStep 1e-12 m) stops it about 1e-12 m
# short on this micrometre-sized workspace; without it (and abstol 1e-16) Newton polishes to round-off
NEWTON_TIGHT = cn.SolverConfig("newton", {"abstolStep": 0.0, "abstol": 1e-16})
IPOPT_TIGHT = cn.SolverConfig("ipopt", {"ipopt.tol": 1e-14})


@pytest.fixture(scope="module")
def prc3():
    return cn.build_model("prc3", TABLE1, {"q": ["0 um", "15 um"]})


def random_q(rng, n):
    return rng.uniform(0.0, QMAX, size=(n, 3))


def eq9(p):
    """eq 9 typed in from the paper: d_i = -p_i - l + sqrt(l^2 - (other two)^2)."""
    x, y, z = p
    return np.array(
        [
            -x - L + math.sqrt(L**2 - y**2 - z**2),
            -y - L + math.sqrt(L**2 - x**2 - z**2),
            -z - L + math.sqrt(L**2 - x**2 - y**2),
        ]
    )


def test_home_pose(prc3):
    assert np.all(prc3.x_home == 0) and np.all(prc3.q_home == 0)
    assert np.max(np.abs(cn.residual(prc3, prc3.x_home, prc3.q_home))) == 0.0
    # at home J = -A2 I (eq 26 holds exactly there)
    rep = cn.jacobians(prc3, prc3.x_home, prc3.q_home)
    np.testing.assert_allclose(rep.J, -A2 * np.eye(3), rtol=1e-15, atol=0)


def test_closed_form_ik_is_eq_9_and_10(prc3):
    rng = np.random.default_rng(3)
    for p in rng.uniform(-130e-6, 0.0, size=(50, 3)):
        sol = cn.inverse_kinematics(prc3, p, method="closed_form")
        d = eq9(p)
        q = d / A2  # eq 10
        if np.all((q >= 0) & (q <= prc3.limits["q"][1])):
            assert sol.status is Status.SOLVED, sol.message
        else:
            assert sol.status is Status.OUTSIDE_JOINT_LIMITS
            continue
        np.testing.assert_allclose(sol.q, q, rtol=0, atol=1e-18)
        passive = cn.passive_joints(prc3, sol.x, sol.q)
        np.testing.assert_allclose([passive[f"d{i}"] for i in (1, 2, 3)], d, rtol=0, atol=1e-18)  # eq 2


def test_fk_of_random_inputs_matches_ik(prc3):
    """FK(q) for 100 random inputs of the stroke box, both solvers; IK(FK(q)) = q."""
    rng = np.random.default_rng(2018)
    # Newton polishes to round-off (1e-17 m); IPOPT stops at its tolerance (residual ~1e-14 m)
    for q in random_q(rng, 100):
        exact = None
        for cfg, tol in ((NEWTON_TIGHT, 1e-16), (IPOPT_TIGHT, 1e-14)):
            fk = cn.forward_kinematics(prc3, q, cfg)
            assert fk.status is Status.SOLVED, fk.message
            assert fk.residual < tol
            ik = cn.inverse_kinematics(prc3, fk.x)
            np.testing.assert_allclose(ik.q, q, rtol=0, atol=tol / A2)
            np.testing.assert_allclose(A2 * q, eq9(fk.x), rtol=0, atol=tol + 2e-16)  # eq 2 and 9
            exact = fk.x if exact is None else exact
            np.testing.assert_allclose(fk.x, exact, rtol=0, atol=tol)


def test_default_solvers_are_sub_picometre(prc3):
    # with the shipped presets (abstolStep 1e-12 m for Newton) the pose is still good to < 1 pm
    rng = np.random.default_rng(5)
    for q in random_q(rng, 20):
        exact = cn.forward_kinematics(prc3, q, NEWTON_TIGHT).x
        for cfg in (NEWTON, IPOPT):
            fk = cn.forward_kinematics(prc3, q, cfg)
            assert fk.ok, fk.message
            np.testing.assert_allclose(fk.x, exact, rtol=0, atol=1e-12)


def test_unreachable_pose_and_other_branch(prc3):
    far = cn.inverse_kinematics(prc3, [0.0, 0.06, 0.06])  # y^2 + z^2 > l^2: the legs cannot reach
    assert far.status is Status.UNREACHABLE and far.q is None
    # the negative root of eq 7 assembles too, with the legs pointing backwards: it is another branch
    x = np.array([-20e-6, -30e-6, -10e-6])
    q_neg = np.array([-x[i] - L - math.sqrt(L**2 - np.sum(np.delete(x, i) ** 2)) for i in range(3)]) / A2
    assert np.max(np.abs(cn.residual(prc3, x, q_neg))) < 1e-15
    status, message, _ = cn.assess(prc3, x, q_neg, 1e-10)
    assert status is Status.WRONG_BRANCH and message.startswith("branch indicator")


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_ad_jacobians_against_central_differences(prc3, seed):
    q = random_q(np.random.default_rng(seed), 1)[0]
    x = cn.forward_kinematics(prc3, q, NEWTON_TIGHT).x
    rep = cn.jacobians(prc3, x, q)
    h = 1e-9  # 0.1 % of the stroke; Phi is quadratic, so central differences are exact up to round-off
    np.testing.assert_allclose(rep.phi_x, central_difference(lambda xx: cn.residual(prc3, xx, q), x, h), atol=1e-7)
    np.testing.assert_allclose(rep.phi_q, central_difference(lambda qq: cn.residual(prc3, x, qq), q, h), atol=1e-6)
    fk = lambda qq: cn.forward_kinematics(prc3, qq, NEWTON_TIGHT, guess=x).x  # noqa: E731
    np.testing.assert_allclose(rep.J, central_difference(fk, q, h), rtol=0, atol=1e-6)
    ik = lambda tt: prc3.closure.ik(tt, prc3.p)[1].full().ravel()  # noqa: E731 - no limit check at the box edge
    np.testing.assert_allclose(rep.J_inv, central_difference(ik, x, h), rtol=0, atol=1e-8)
    np.testing.assert_allclose(rep.J_inv @ rep.J_task, np.eye(3), atol=1e-13)


def test_ad_jacobian_is_eq_21(prc3):
    """A2 dq/dx (AD) equals J = J_d^-1 J_p of eq 19-21 to round-off on random poses."""
    rng = np.random.default_rng(21)
    for q in random_q(rng, 30):
        x = cn.forward_kinematics(prc3, q, NEWTON_TIGHT).x
        J_ad = A2 * cn.jacobians(prc3, x, q).J_inv
        np.testing.assert_allclose(J_ad, P.jacobian_eq21(x, A2 * q, L), rtol=0, atol=1e-14)


def test_printed_expansion_of_eq_21_has_x_plus_l_minus_d():
    """The printed expansion -[1, y/(x+l-d1), ...] is not eq 21 on eq 8's root (x + l + d1):
    the difference is real but below 1e-5 over the workspace."""
    x = np.array([-131.8e-6, -131.8e-6, -131.8e-6])
    d = np.full(3, A2 * QMAX)
    exact, printed = P.jacobian_eq21(x, d, L), P.jacobian_printed(x, d, L)
    off = ~np.eye(3, dtype=bool)
    # by hand: y (1/(x+l-d) - 1/(x+l+d)) = y 2 d / ((x + l)^2 - d^2)
    #        = 131.8e-6 * 2 * 131.579e-6 / ((73.3682e-3)^2 - (131.579e-6)^2) = 3.46842e-8 / 5.38287e-3 = 6.4434e-6
    np.testing.assert_allclose(np.abs(printed - exact)[off], 6.4434e-6, rtol=1e-4)
    np.testing.assert_allclose(np.diag(printed), np.diag(exact), rtol=0, atol=1e-15)


# -- workspace (eq 27) --------------------------------------------------------------------------------


@pytest.fixture(scope="module")
def workspace(prc3):
    return W.reachable_workspace(prc3, samples=6, quadrature=4, solver=NEWTON)


def test_workspace_vertices_are_fk_of_the_stroke_corners(prc3, workspace):
    assert workspace.status is Status.SOLVED, workspace.message
    corners = W.box_corners([0, 0, 0], [QMAX] * 3)
    assert workspace.vertices.shape == (8, 3)
    for q, v in zip(corners, workspace.vertices):
        np.testing.assert_allclose(A2 * q, eq9(v), rtol=0, atol=1e-12)  # each vertex satisfies eq 9-10
    # the q = 0 corner is the origin; q = q_max on all three is the far corner on the diagonal
    np.testing.assert_allclose(workspace.vertices[0], 0.0, atol=1e-18)
    far = workspace.vertices[-1]
    assert far[0] == pytest.approx(far[1], abs=1e-16) == pytest.approx(far[2], abs=1e-16)
    # on the diagonal eq 9 reads -s - l + sqrt(l^2 - 2 s^2) = d with d = A2 q_max; squaring,
    # 3 s^2 + 2 (d + l) s + (d + l)^2 - l^2 = 0, whose root near -d is
    d = A2 * QMAX
    assert far[0] == pytest.approx((-(d + L) + math.sqrt(3 * L**2 - 2 * (d + L) ** 2)) / 3, rel=1e-12)
    np.testing.assert_allclose(workspace.lower, far, rtol=1e-12)
    np.testing.assert_allclose(workspace.upper, 0.0, atol=1e-18)


def test_workspace_volume(prc3, workspace):
    # the linear model p = -A2 q (eq 26) maps the stroke box to a cube of edge A2 q_max; the exact
    # workspace differs from it in second order (terms ~ (A2 q_max / l)^2 = 3e-6)
    cube = (A2 * QMAX) ** 3
    assert workspace.linear_volume == pytest.approx(cube, rel=1e-13)
    assert workspace.volume == pytest.approx(cube, rel=1e-4)
    assert abs(workspace.volume / cube - 1) > 1e-7  # but it is not the cube
    # the quadrature has converged: 4 and 6 points per actuator agree
    finer = W.reachable_workspace(prc3, samples=2, quadrature=6, solver=NEWTON)
    assert finer.volume == pytest.approx(workspace.volume, rel=1e-12)


def test_workspace_linearity_measures(prc3, workspace):
    # J ~ -I (eq 22): the largest |J + I| entry is y/(x + l + d) at the far corner, ~ A2 q_max / l
    jac = [A2 * cn.jacobians(prc3, s.x, s.q).J_inv + np.eye(3) for s in workspace.solutions]
    assert workspace.jacobian_deviation == pytest.approx(max(np.max(np.abs(j)) for j in jac), rel=1e-12)
    assert workspace.jacobian_deviation == pytest.approx(A2 * QMAX / L, rel=2e-3)  # 1.79e-3
    # p = -A2 q (eq 26): x = -d1 - (l - sqrt(l^2 - y^2 - z^2)), so the error is (y^2 + z^2)/(2 l) at most,
    # reached at q = (0, q_max, q_max): 2 (131.6e-6)^2 / (2 * 73.5e-3) = 0.2356 um
    np.testing.assert_allclose(workspace.linear_error, 2 * (A2 * QMAX) ** 2 / (2 * L), rtol=5e-3)


def test_membership(prc3):
    inside = W.membership(prc3, [[-50e-6, -60e-6, -70e-6], [10e-6, -60e-6, -70e-6], [-140e-6, -60e-6, -70e-6]])
    # the second needs q1 < 0, the third q1 > 15 um
    assert inside.inside.tolist() == [True, False, False]


def test_workspace_problem_file(cli):
    run = cli("solve", str(PROBLEMS / "prc3_workspace.yaml"), "--json", "--set", "inputs.samples=3")
    assert run.code == 0, run.err
    values = json.loads(run.out)["values"]
    assert values["n_points"] == 27
    assert values["x_min"] == pytest.approx(-131.815e-6, rel=1e-5)
    assert values["volume"] == pytest.approx((A2 * QMAX) ** 3, rel=1e-4)


def test_other_reading_of_the_c_joint_changes_d_by_at_most_0_118_um(workspace):
    """prc3.py documents: a C joint sliding along one transverse axis would drop that coordinate
    from under the root of eq 9, changing d_i by at most 0.118 um over the workspace."""
    t = workspace.t
    change = 0.0
    for i in range(3):
        a, b = t[:, (i + 1) % 3], t[:, (i + 2) % 3]
        both = np.sqrt(L**2 - a**2 - b**2)
        change = max(change, np.max(np.abs(both - np.sqrt(L**2 - a**2))), np.max(np.abs(both - np.sqrt(L**2 - b**2))))
    assert change == pytest.approx(0.118e-6, abs=0.5e-9)


def test_workspace_points_on_request(cli):
    run = cli(
        "solve",
        str(PROBLEMS / "prc3_workspace.yaml"),
        "--json",
        "--set",
        "inputs.samples=2",
        "--set",
        "inputs.points=true",
    )
    assert run.code == 0, run.err
    values = json.loads(run.out)["values"]
    assert len(values["points"]) == 8 and values["points"] == values["vertices"]
