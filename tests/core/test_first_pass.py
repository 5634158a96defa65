"""The compiled loop over poses runs a kernel's first kernel (the closed form, or the reduced
Newton) on its own, the work on the shared numbers once per call and the joint limits built in
where a model has none, and the whole kernel only for the poses it does not settle (issue 23,
items 4-5).  These tests check that it gives the kernel's outputs -- evaluated by CasADi's
virtual machine, the reference -- on hostile poses: out of reach, at the edge of reach, next to
singularities and leg singularities, across branches, from guesses in the other assembly."""

import numpy as np
import pytest

import cpm_nlp as cn
from cpm_nlp.core.batch import evaluate
from cpm_nlp.core.compiled import compiler_available, first_pass, native_loop
from cpm_nlp.core.kernels import fk_kernel, shared_values
from cpm_nlp.core.pose_checks import code_of
from cpm_nlp.core.result import Status
from tests.conftest import PAPER_PRS3

pytestmark = pytest.mark.skipif(not compiler_available(), reason="no C compiler")
NEWTON = cn.SolverConfig("newton")


def reference_and_compiled(model, q, x0):
    """The FK kernel's outputs over the poses: CasADi's virtual machine, and the compiled loop."""
    kern = fk_kernel(model.closure, NEWTON)
    args = [q, x0, *shared_values(kern, model, NEWTON.tolerance)]
    vm = evaluate(kern.function, args, 1)
    c = evaluate(native_loop(model.closure, kern), args, 1)
    return kern, dict(zip(kern.outputs, vm)), dict(zip(kern.outputs, c))


def boundary_poses(model, q_a, q_b, x0, steps=48):
    """Poses at every status boundary on the segments q_a -> q_b: bisection on the reference's
    status (and on its path), both ends of each final bracket."""
    kern = fk_kernel(model.closure, NEWTON)
    shared = shared_values(kern, model, NEWTON.tolerance)

    def label(q):
        out = dict(zip(kern.outputs, evaluate(kern.function, [q, x0, *shared], 1)))
        path = out["path"] if "path" in out else np.zeros_like(out["status"])
        return (out["status"] * 10 + path).ravel()

    la, lb = label(q_a), label(q_b)
    keep = la != lb
    a, b, la = q_a[keep], q_b[keep], la[keep]
    for _ in range(steps):
        m = 0.5 * (a + b)
        lm = label(m)
        same = lm == la
        a = np.where(same[:, None], m, a)
        b = np.where(same[:, None], b, m)
    return np.vstack([a, b])


def assert_same_outputs(kern, vm, c):
    for name in kern.outputs:
        # as numbers (NaN where NaN); the fast path folds x + 0 into x, so a zero's sign may differ
        np.testing.assert_array_equal(c[name], vm[name], err_msg=name)


@pytest.fixture(scope="module")
def five_bar():
    return cn.build_model("five_bar")


def test_five_bar_has_a_first_pass(five_bar):
    kern = fk_kernel(five_bar.closure, NEWTON)
    fast = first_pass(kern)
    assert fast is not None
    assert native_loop(five_bar.closure, kern).call.__name__ == "five_bar_fk_batch_first"
    # the shared parts (the crank's home angle's sine and cosine, limit flags) leave the pose loop
    assert fast.per.n_instructions() < 0.75 * fk_kernel(five_bar.closure, NEWTON).first.function.n_instructions()


def test_five_bar_hostile_poses(five_bar):
    rng = np.random.default_rng(7)
    n = 3000
    home = five_bar.q_home
    q = home + rng.uniform(-np.pi, np.pi, (n, 2))  # out of reach, other branches, singular
    x0 = five_bar.x_home + rng.uniform(-0.2, 0.2, (n, 2))  # guesses on either side of the centres' line
    x0[::3] = five_bar.x_home
    edge = boundary_poses(five_bar, home + rng.uniform(-1.5, 1.5, (400, 2)), q[:400], five_bar.x_home)
    q_all = np.vstack([q, edge])
    x_all = np.vstack([x0, np.tile(five_bar.x_home, (len(edge), 1))])
    kern, vm, c = reference_and_compiled(five_bar, q_all, x_all)
    assert_same_outputs(kern, vm, c)
    codes = set(vm["status"].ravel().astype(int).tolist())
    assert {code_of(Status.SOLVED), code_of(Status.WRONG_BRANCH)} <= codes
    assert set(vm["path"].ravel().tolist()) == {0.0, 1.0, 2.0}  # closed form, reduced and full Newton
    assert len(edge) > 100


def test_prs3_hostile_poses(prs3):
    rng = np.random.default_rng(3)
    n = 1500
    q = rng.uniform(-6e-3, 6e-3, (n, 3))  # beyond the stroke: unreachable poses, Newton failing
    q[::40] = [0.3, -0.3, 0.0]
    edge = boundary_poses(prs3, rng.uniform(-2e-3, 2e-3, (150, 3)), q[:150] * 3, prs3.x_home, steps=40)
    q_all = np.vstack([q, edge])
    kern, vm, c = reference_and_compiled(prs3, q_all, prs3.x_home)
    assert first_pass(kern) is not None
    assert_same_outputs(kern, vm, c)
    assert len(set(vm["status"].ravel().tolist())) >= 2
    assert len(set(vm["path"].ravel().tolist())) >= 2  # reduced and full


def test_prs3_with_limits_and_per_pose_guesses():
    """Limits (the generic loop) and a guess per pose: still the kernel's outputs."""
    model = cn.build_model("prs3", PAPER_PRS3, {"s": ["-2 mm", "2 mm"], "beta_m": ["-1.5 deg", "1.5 deg"]})
    rng = np.random.default_rng(4)
    q = rng.uniform(-3e-3, 3e-3, (400, 3))
    x0 = model.x_home + rng.uniform(-1e-3, 1e-3, (400, model.closure.nx))
    kern, vm, c = reference_and_compiled(model, q, x0)
    assert_same_outputs(kern, vm, c)
    assert code_of(Status.OUTSIDE_JOINT_LIMITS) in set(vm["status"].ravel().astype(int).tolist())


def test_jansen_turn_and_guesses():
    model = cn.build_model("jansen")
    rng = np.random.default_rng(5)
    q = rng.uniform(-4 * np.pi, 4 * np.pi, (2000, 1))
    x0 = np.tile(model.x_home, (2000, 1))
    x0[::2] += rng.uniform(-0.05, 0.05, (1000, model.closure.nx))
    kern, vm, c = reference_and_compiled(model, q, x0)  # a guess per pose: the whole kernel
    assert_same_outputs(kern, vm, c)
    fast = first_pass(kern)
    assert fast is not None and 1 in fast.shared  # the guess is hoisted: one guess, the first pass
    kern, vm, c = reference_and_compiled(model, q, model.x_home)
    assert_same_outputs(kern, vm, c)
    assert set(vm["status"].ravel().tolist()) == {code_of(Status.SOLVED)}


def test_single_solve_takes_the_same_path(five_bar):
    """A single compiled solve runs the same loop for one pose: the batch's answer."""
    q = five_bar.q_home + np.array([0.1, -0.2])
    one = cn.forward_kinematics(five_bar, q, NEWTON, backend="compiled")
    batch = cn.batch_forward_kinematics(five_bar, q[None, :], backend="compiled")
    assert one.ok and batch.ok[0] and one.path == batch.path(0) == "closed"
    np.testing.assert_array_equal(one.x, batch.x[0])


def test_the_round_trip_is_not_redundant_on_the_closed_path(five_bar):
    """The IK round trip stays in the closed form's checks: next to a leg singularity (crank and
    distal link in line) the closed form's pose passes the residual and the branch indicators,
    but the file's IK (acos near +-1) does not give the actuators back within 100 tol -- or finds
    the pose out of reach -- so the pose is left to Newton (dropping the check would call these
    poses solved by the closed form)."""
    c = five_bar.closure
    kern = fk_kernel(c, NEWTON).first
    shared = shared_values(kern, five_bar, NEWTON.tolerance)
    tol = NEWTON.tolerance

    def outputs(q):
        return dict(zip(kern.outputs, evaluate(kern.function, [q, five_bar.x_home, *shared], 1)))

    def label(q):
        o = outputs(q)
        ok = [o["residual"] <= tol, o["branch_margin"] > 0, o["round_trip_error"] <= 100 * tol]
        return sum(k * v.ravel() for k, v in zip((1, 2, 4), ok))

    rng = np.random.default_rng(2)
    a = five_bar.q_home + rng.uniform(-0.3, 0.3, (1000, 2))
    b = five_bar.q_home + rng.uniform(-2.5, 2.5, (1000, 2))
    la = label(a)
    keep = la != label(b)
    a, b, la = a[keep], b[keep], la[keep]
    for _ in range(60):
        m = 0.5 * (a + b)
        same = label(m) == la
        a, b = np.where(same[:, None], m, a), np.where(same[:, None], b, m)
    o = outputs(np.vstack([a, b]))
    passes = (o["residual"] <= tol) & (o["branch_margin"] > 0)
    fails = passes & ~(o["round_trip_error"] <= 100 * tol)
    assert fails.sum() > 10
    assert np.all(o["status"][fails] == code_of(Status.WRONG_BRANCH))
    assert np.all(o["branch_margin"][fails] < 1e-6)  # at a leg singularity


@pytest.mark.parametrize("name", ["five_bar", "prs3", "jansen"])
def test_unlimited_checks_are_the_checks_at_infinite_limits(name, prs3):
    """check_expressions(unlimited=True) gives the numbers of the checks with every limit
    infinite, also where a joint is NaN or infinite (the limit margin, the passive joints)."""
    import casadi as ca

    from cpm_nlp.core.pose_checks import check_expressions, n_joints

    model = prs3 if name == "prs3" else cn.build_model(name)
    c = model.closure
    x, q, p = ca.SX.sym("x", c.nx), ca.SX.sym("q", c.nq), ca.SX.sym("p", c.np)
    nl = n_joints(c)
    inf = ca.DM.ones(nl) * ca.inf
    names = ["passive", "limit_margin", "residual", "branch_margin", "round_trip_error"]

    def outputs(**kw):
        chk = check_expressions(c, x, q, p, -inf, inf, **kw)
        return ca.Function("f", [x, q, p], [ca.densify(chk[n]) for n in names])

    limited, unlimited = outputs(), outputs(unlimited=True)
    assert unlimited.n_instructions() < limited.n_instructions()
    rng = np.random.default_rng(8)
    for k in range(300):
        xv = model.x_home + rng.normal(0, 0.02, c.nx)
        qv = model.q_home + rng.normal(0, 0.05, c.nq)
        if k % 3 == 1:
            xv[rng.integers(c.nx)] = [np.nan, np.inf, -np.inf][k % 9 // 3]
        if k % 3 == 2:
            qv[rng.integers(c.nq)] = [np.nan, np.inf, -np.inf][k % 9 // 3]
        for a, b, n in zip(limited(xv, qv, model.p), unlimited(xv, qv, model.p), names):
            np.testing.assert_array_equal(np.asarray(b), np.asarray(a), err_msg=f"{n} at {xv}, {qv}")
