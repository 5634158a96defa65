"""Batch kinematics: the same statuses, numbers and messages as single solves,
on the map and the compiled backends, from any number of threads."""

import json
import math
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest

import cpm_nlp as cn
from cpm_nlp.core.result import Status
from tests.conftest import PAPER_PRS3, PROBLEMS
from tests.mechanisms.prs3.test_prs3_kinematics import central_difference, random_task

NEWTON = cn.SolverConfig(method="newton")
LIMITED = {"s": ["-2 mm", "2 mm"], "beta_m": ["-1.5 deg", "1.5 deg"]}


@pytest.fixture(scope="module")
def limited():
    return cn.build_model("prs3", PAPER_PRS3, LIMITED)


def mixed_actuators(rng, n):
    """Actuator vectors inside and outside the limits, plus some no stage can reach."""
    q = rng.uniform(-2.2e-3, 2.2e-3, (n, 3))
    q[::50] = [0.3, -0.3, 0.0]  # far out of reach
    return q


def assert_same_as_single(model, res, single, k):
    s = single
    assert res.statuses[k] is s.status, (k, s.message, res.message(k))
    if s.status is not Status.NOT_CONVERGED:  # (else each solver says why in its own words)
        assert res.message(k) == s.message
    if s.ok:
        np.testing.assert_allclose(res.x[k], s.x, rtol=0, atol=1e-13)
        np.testing.assert_allclose(res.q[k], s.q, rtol=0, atol=1e-13)
        np.testing.assert_allclose(res.passive[k], s.passive, rtol=0, atol=1e-12)
    else:
        assert np.all(np.isnan(res.x[k])) and np.all(np.isnan(res.q[k]))


def test_batch_fk_matches_single_solves(limited):
    """Every status (solved, outside limits, not converged) and every number
    of the batch equals the single Newton solve of the same point."""
    rng = np.random.default_rng(11)
    q = mixed_actuators(rng, 1000)
    res = cn.batch_forward_kinematics(limited, q)
    counts = res.counts()
    assert counts["solved"] > 100 and counts["outside_joint_limits"] > 100 and counts["not_converged"] >= 20
    for k in range(0, 1000, 10):
        assert_same_as_single(limited, res, cn.forward_kinematics(limited, q[k], NEWTON), k)
    assert res.overall is res.statuses[int(np.flatnonzero(~res.ok)[0])]


def test_batch_ik_matches_single_solves(limited):
    rng = np.random.default_rng(12)
    t = random_task(rng, 600, dz=3e-3, tilt=math.radians(0.5))
    t[:, 0] += limited.derived["pz0"]
    t[::60, 0] = 0.2  # 200 mm high: unreachable
    res = cn.batch_inverse_kinematics(limited, t)
    assert {"solved", "outside_joint_limits", "unreachable"} <= set(res.counts())
    assert res.message(0).startswith("the closed-form IK has no real solution (reach margin -")
    for k in range(0, 600, 6):
        assert_same_as_single(limited, res, cn.inverse_kinematics(limited, t[k]), k)


def test_fk_of_ik_round_trip_in_batch(prs3):
    rng = np.random.default_rng(13)
    t = random_task(rng, 2000)
    t[:, 0] += prs3.derived["pz0"]
    ik = cn.batch_inverse_kinematics(prs3, t)
    assert ik.ok.all()
    fk = cn.batch_forward_kinematics(prs3, ik.q)
    assert fk.ok.all()
    np.testing.assert_allclose(fk.x, ik.x, rtol=0, atol=1e-13)
    np.testing.assert_allclose(fk.passive, ik.passive, rtol=0, atol=1e-12)
    assert np.all(fk.checks["residual"] <= 1e-14)


def test_wrong_branch_in_batch(prs3):
    guess = prs3.x_home.copy()
    guess[2] = -guess[2]  # below the actuator plane: Newton finds the mirrored assembly
    q = [[0.5e-3, 0.2e-3, 0.1e-3], [0.0, 0.0, 0.0]]
    res = cn.batch_forward_kinematics(prs3, q, NEWTON, guess=guess)
    assert res.statuses == [Status.WRONG_BRANCH] * 2
    far = cn.batch_forward_kinematics(prs3, [[0.3, -0.3, 0.0]])
    assert far.statuses == [Status.NOT_CONVERGED]
    assert far.message(0).startswith("Newton stopped at max |Φ| = ")
    single = cn.forward_kinematics(prs3, q[0], NEWTON, guess=guess, continuation=False)
    assert res.message(0) == single.message
    assert np.all(np.isnan(res.x))


@pytest.mark.parametrize(("alpha0", "expected"), [("1e-6 deg", Status.SOLVED), ("1e-7 deg", Status.SINGULAR)])
def test_singular_screen_is_refined_to_the_single_verdict(alpha0, expected):
    """Nearly flat legs (type II singularity): the kernels' 1-norm screen flags
    both models (cond1 >= 1e10/6); the 2-norm condition number decides, as in
    a single solve (2.4e9 < 1e10 solved, 2.4e10 singular)."""
    model = cn.build_model("prs3", {"b": "47.91 mm", "L": "109.215 mm", "alpha0": alpha0})
    res = cn.batch_forward_kinematics(model, [[0.0, 0.0, 0.0]])
    assert res.checks["cond1"][0] >= 1e10 / 6
    single = cn.forward_kinematics(model, [0.0, 0.0, 0.0], NEWTON)
    assert single.status is expected and res.statuses == [expected]
    assert res.checks["cond_phi_x"][0] == pytest.approx(single.details["cond_phi_x"], rel=1e-6)
    assert res.message(0) == single.message


def test_batch_jacobians_match_single_and_central_differences(prs3):
    rng = np.random.default_rng(14)
    t = random_task(rng, 50)
    t[:, 0] += prs3.derived["pz0"]
    ik = cn.batch_inverse_kinematics(prs3, t)
    jac = cn.batch_jacobians(prs3, ik.x, ik.q)
    assert jac.J.shape == (50, 6, 3) and jac.J_inv.shape == (50, 3, 3) and jac.Phi_x.shape == (50, 6, 6)
    for k in range(0, 50, 10):
        rep = cn.jacobians(prs3, ik.x[k], ik.q[k])
        np.testing.assert_allclose(jac.J[k], rep.J, rtol=1e-14, atol=1e-16)
        np.testing.assert_allclose(jac.J_inv[k], rep.J_inv, rtol=1e-14, atol=1e-16)
        np.testing.assert_allclose(jac.Phi_x[k], rep.phi_x, rtol=1e-14, atol=1e-16)
        np.testing.assert_allclose(jac.Phi_q[k], rep.phi_q, rtol=1e-14, atol=1e-16)
    # AD against central differences of the batch FK itself (dx/dq)
    q = ik.q[0]
    fd = central_difference(lambda qq: cn.batch_forward_kinematics(prs3, qq, guess=ik.x[0]).x[0], q, 1e-7)
    np.testing.assert_allclose(jac.J[0], fd, atol=1e-6 * np.max(np.abs(jac.J[0])))


def test_threads_and_chunks_do_not_change_results(prs3):
    rng = np.random.default_rng(15)
    q = rng.uniform(-2e-3, 2e-3, (5000, 3))
    one = cn.batch_forward_kinematics(prs3, q, threads=1)
    two = cn.batch_forward_kinematics(prs3, q, threads=2)
    np.testing.assert_array_equal(one.x, two.x)
    np.testing.assert_array_equal(one.status, two.status)


def test_batch_from_several_threads_at_once(prs3):
    """The library keeps no global state: concurrent batches and single solves
    give what they give alone."""
    rng = np.random.default_rng(16)
    blocks = [rng.uniform(-2e-3, 2e-3, (300, 3)) for _ in range(6)]
    alone = [cn.batch_forward_kinematics(prs3, b, threads=1).x for b in blocks]
    singles = [cn.forward_kinematics(prs3, b[0], NEWTON).x for b in blocks]

    def work(k):
        return cn.batch_forward_kinematics(prs3, blocks[k], threads=2).x, cn.forward_kinematics(
            prs3, blocks[k][0], NEWTON
        ).x

    with ThreadPoolExecutor(max_workers=4) as pool:
        together = list(pool.map(work, range(6)))
    for k, (xb, xs) in enumerate(together):
        np.testing.assert_array_equal(xb, alone[k])
        np.testing.assert_array_equal(xs, singles[k])


def test_batch_solutions_are_pose_solutions(limited):
    res = cn.batch_forward_kinematics(limited, [[1e-3, 0.5e-3, -0.3e-3], [2.5e-3, 2.5e-3, 2.5e-3]])
    ok, bad = res.solutions()
    assert ok.status is Status.SOLVED and ok.x is not None and ok.solver == "fast_newton"
    assert bad.status is Status.OUTSIDE_JOINT_LIMITS and bad.x is None and "s1 = 0.0025" in bad.message


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (lambda m: cn.batch_forward_kinematics(m, np.zeros((4, 2))), "q: expected an array of shape (N, 3)"),
        (lambda m: cn.batch_forward_kinematics(m, [[0.0, np.nan, 0.0]]), "q: expected finite numbers"),
        (lambda m: cn.batch_forward_kinematics(m, [[0.0, 0.0, 0.0]], cn.SolverConfig()), "solves by Newton"),
        (lambda m: cn.batch_forward_kinematics(m, [[0.0] * 3], backend="compild"), "did you mean 'compiled'"),
        (
            lambda m: cn.batch_forward_kinematics(m, [[0.0] * 3], cn.SolverConfig("newton", {"line_search": False})),
            "takes only abstol, abstolStep, max_iter; got 'line_search'",
        ),
        (lambda m: cn.batch_forward_kinematics(m, np.zeros((4, 3)), guess=np.zeros((3, 6))), "expected 1 or 4 rows"),
    ],
)
def test_batch_bad_input(prs3, call, message):
    with pytest.raises(cn.InputError) as err:
        call(prs3)
    assert message in str(err.value)


def test_problem_file_batches_use_the_batch_path(cli):
    """FK lists with the newton solver and IK lists in closed form go through
    the batch kernels; the result reads as before."""
    run = cli(
        "solve",
        str(PROBLEMS / "prs3_forward_kinematics.yaml"),
        "--set",
        "inputs.s1=[0 mm, 1 mm, 2.9 mm]",
        "--set",
        "solver=newton",
        "--set",
        "mechanism.limits.beta_m=[-1 deg, 1 deg]",
        "--json",
    )
    out = json.loads(run.out)
    assert run.code == 1 and out["statuses"] == ["solved", "outside_joint_limits", "outside_joint_limits"]
    assert out["solver"]["name"] == "fast_newton"
    assert out["values"]["pz"][1] is None
    assert "beta_m1 = 0.0251847 outside [-0.0174533, 0.0174533]" in out["message"]
    single = cn.forward_kinematics(prs3_limited(), [0.0, 0.5e-3, -0.3e-3], NEWTON)
    assert out["values"]["pz"][0] == pytest.approx(single.x[2], rel=0, abs=1e-15)


def prs3_limited():
    return cn.build_model("prs3", PAPER_PRS3, {"s": ["-3 mm", "3 mm"], "beta_m": ["-1 deg", "1 deg"]})
