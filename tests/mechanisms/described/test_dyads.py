"""The closed-form FK of a planar RRR dyad (issue 23, item 5; cpm_nlp.mechanisms.described.dyads):
the five-bar file's two circles intersected in closed form, its branch the file's assembly mode,
settled by the pose checks, anything else left to Newton (same statuses as before)."""

from __future__ import annotations

import numpy as np
import pytest

import cpm_nlp as cn
from cpm_nlp.core.batch import _finish, evaluate
from cpm_nlp.core.kernels import PATHS, _newton_fk_kernel, closed_fk_kernel, fk_kernel, shared_values
from cpm_nlp.core.pose_checks import code_of
from cpm_nlp.core.result import Status
from tests.conftest import central_difference

NEWTON = cn.SolverConfig("newton")


@pytest.fixture(scope="module")
def five_bar():
    return cn.build_model("five_bar")


def _poses(model, n=400, spread=0.25, seed=0):
    return model.q_home + np.random.default_rng(seed).uniform(-spread, spread, (n, model.closure.nq))


def _newton_only(model, q):
    """The FK as it was before the closed form: the Newton kernel (reduced, then full) from home."""
    kern = _newton_fk_kernel(model.closure, NEWTON, "five_bar_fk_newton_reference")
    args = [q, model.x_home, *shared_values(kern, model, NEWTON.tolerance)]
    out = dict(zip(kern.outputs, evaluate(kern.function, args)))
    return _finish("forward_kinematics", model, out, q, NEWTON.tolerance, "map", 1, 0.0, "fast_newton")


def _numpy_dyad(d, l1, l2, q1, q2):
    """The five-bar's pose from the two circles, derived here in numpy (not the code's
    expressions): elbows C1 = (-d/2 + l1 cos q1, l1 sin q1), C2 = (d/2 + l1 cos q2, l1 sin q2);
    P is the circles' (radius l2) intersection above the line C1C2 (elbows out, P up)."""
    c1 = np.array([-d / 2 + l1 * np.cos(q1), l1 * np.sin(q1)])
    c2 = np.array([d / 2 + l1 * np.cos(q2), l1 * np.sin(q2)])
    mid, half = (c1 + c2) / 2, np.linalg.norm(c2 - c1) / 2
    n = np.array([-(c2 - c1)[1], (c2 - c1)[0]]) / (2 * half)
    return mid + np.sqrt(l2**2 - half**2) * n


def test_five_bar_is_recognised_and_others_are_not():
    """The five-bar's loop is an RRR dyad once q is set; a four-bar-like planar platform that turns
    (rpr, rrr3) or a spatial mechanism is not, and keeps the Newton FK alone."""
    assert cn.build_model("five_bar").closure.fk_closed is not None
    for name in ("delta", "pantograph"):
        assert cn.build_model(name).closure.fk_closed is None, name
    fn = cn.build_model("five_bar").closure.fk_closed
    assert fn.name() == "fk_closed" and fn.name_in() == ["q", "x0", "p"] and fn.name_out() == ["x", "disc", "side"]


def test_closed_form_equals_newton_and_numpy(five_bar):
    """Seeded poses at +-0.25 rad about home: the closed form's pose equals Newton's (reduced or
    full) and the numpy derivation to 1e-12 m, every status solved, answered by the closed path."""
    m = five_bar
    q = _poses(m)
    got = cn.batch_forward_kinematics(m, q)
    ref = _newton_only(m, q)
    assert got.statuses == ref.statuses and got.ok.all()
    assert set(got.path(i) for i in range(len(got))) == {"closed"}
    np.testing.assert_allclose(got.x, ref.x, rtol=0, atol=1e-12)
    d, l1, l2 = 0.100, 0.100, 0.150  # the file's defaults
    expected = np.array([_numpy_dyad(d, l1, l2, *row) for row in q])
    np.testing.assert_allclose(got.x, expected, rtol=0, atol=1e-12)
    single = cn.forward_kinematics(m, q[7], NEWTON)
    assert single.status is Status.SOLVED
    np.testing.assert_allclose(single.x, got.x[7], rtol=0, atol=1e-12)


def test_branch_is_the_home_one(five_bar):
    """At home the closed form gives the file's reference pose; on every seeded pose the branch
    indicators keep their home signs (the file's assembly mode), and the other intersection of
    the same circles is a different assembly (a wrong branch, not the answer)."""
    m, c = five_bar, five_bar.closure
    x, disc, side = c.fk_closed(m.q_home, m.x_home, m.p)
    np.testing.assert_allclose(np.asarray(x).ravel(), m.x_home, rtol=0, atol=1e-15)
    assert float(disc) > 0 and float(side) > 0
    for qi in _poses(m, 50, seed=1):
        xi = np.asarray(c.fk_closed(qi, m.x_home, m.p)[0]).ravel()
        assert np.all(np.asarray(c.branch(xi, qi, m.p)) > 0)
        c1 = np.array([-0.05 + 0.1 * np.cos(qi[0]), 0.1 * np.sin(qi[0])])
        c2 = np.array([0.05 + 0.1 * np.cos(qi[1]), 0.1 * np.sin(qi[1])])
        mirror = xi + 2 * ((c1 - xi) - np.dot(c1 - xi, c2 - c1) / np.dot(c2 - c1, c2 - c1) * (c2 - c1))
        assert np.max(np.abs(np.asarray(c.phi(mirror, qi, m.p)))) < 1e-12  # also a closure...
        assert not np.all(np.asarray(c.branch(mirror, qi, m.p)) > 0)  # ...on another branch


def test_out_of_reach_pose_keeps_newtons_status(five_bar):
    """Distal links of 120 mm (d = l1 = 100 mm): with the cranks along the base line, outwards,
    the elbows are 300 mm > 2 x 120 mm apart -- the circles do not meet (disc < 0), the closed
    form settles nothing and the status is Newton's, as before it (not a number).  A far pose the
    closed form does not confirm (q_home +- 3 rad: its IK round trip is off by a turn) keeps
    Newton's status too."""
    m = cn.build_model("five_bar", {"l2": "120 mm"})
    c = m.closure
    q = np.array([[np.pi, 0.0], [np.pi - 0.1, 0.1], [3.0, 0.3]])
    assert all(float(c.fk_closed(qi, m.x_home, m.p)[1]) < 0 for qi in q)
    got, ref = cn.batch_forward_kinematics(m, q), _newton_only(m, q)
    assert got.statuses == ref.statuses == [Status.NOT_CONVERGED] * 3
    assert np.isnan(got.x).all() and all(got.path(i) == "full" for i in range(3))
    kern = closed_fk_kernel(c, NEWTON)
    out = dict(zip(kern.outputs, evaluate(kern.function, [q, m.x_home, *shared_values(kern, m, 1e-9)])))
    assert np.all(out["status"].ravel() == code_of(Status.NOT_CONVERGED))
    far = five_bar.q_home + np.array([[3.0, -3.0]])
    got, ref = cn.batch_forward_kinematics(five_bar, far), _newton_only(five_bar, far)
    assert got.statuses == ref.statuses and got.statuses[0] is not Status.SOLVED and got.path(0) == "full"


def test_fk_against_ik_and_ad_jacobian(five_bar):
    """The closed-form pose maps back to q through the file's closed-form IK (1e-12 rad); the AD
    Jacobian of fk_closed equals central differences and the closure's J = -Φ_x⁻¹ Φ_q."""
    import casadi as ca

    m, c = five_bar, five_bar.closure
    q_sym = ca.SX.sym("q", c.nq)
    dx_dq = ca.Function("dx_dq", [q_sym], [ca.jacobian(c.fk_closed(q_sym, m.x_home, m.p)[0], q_sym)], ["q"], ["J"])
    for qi in _poses(m, 20, seed=2):
        xi = np.asarray(c.fk_closed(qi, m.x_home, m.p)[0]).ravel()
        q_back = np.asarray(c.ik(xi[list(c.task_index)], m.p)[1]).ravel()
        np.testing.assert_allclose(q_back, qi, rtol=0, atol=1e-12)
        jac = np.asarray(dx_dq(qi))
        fd = central_difference(lambda v: np.asarray(c.fk_closed(v, m.x_home, m.p)[0]).ravel(), qi, 1e-6)
        np.testing.assert_allclose(jac, fd, rtol=0, atol=1e-8)
        np.testing.assert_allclose(jac, np.asarray(c.jacobian(xi, qi, m.p)), rtol=0, atol=1e-12)


def test_kernel_outputs_and_path_names(five_bar):
    """The FK kernel keeps its signature (the Newton FK's inputs and outputs) and reports the
    closed path by name."""
    kern = fk_kernel(five_bar.closure, NEWTON)
    assert kern.name == "five_bar_fk"
    assert kern.outputs[-2:] == ("path", "status") and PATHS[2] == "closed"
    assert list(kern.function.name_in()) == ["q", "x0", *kern.shared_inputs]


def test_a_guess_in_the_other_assembly_is_left_to_newton(five_bar):
    """From a guess across the centres' line (the mirror assembly, as the assembly-mode search
    starts), the FK is Newton's from that guess -- same status and pose as before the closed
    form -- not the file's assembly, so the other mode is still found."""
    m, c = five_bar, five_bar.closure
    q = _poses(m, 30, seed=3)
    mirrors = []
    for qi in q:
        xi = np.asarray(c.fk_closed(qi, m.x_home, m.p)[0]).ravel()
        c1 = np.array([-0.05 + 0.1 * np.cos(qi[0]), 0.1 * np.sin(qi[0])])
        c2 = np.array([0.05 + 0.1 * np.cos(qi[1]), 0.1 * np.sin(qi[1])])
        e = (c2 - c1) / np.linalg.norm(c2 - c1)
        mirrors.append(2 * (c1 + np.dot(xi - c1, e) * e) - xi)
    x0 = np.array(mirrors) + 1e-4  # near the other assembly, not on it
    got = cn.batch_forward_kinematics(m, q, guess=x0)
    kern = _newton_fk_kernel(c, NEWTON, "five_bar_fk_newton_reference")
    out = dict(zip(kern.outputs, evaluate(kern.function, [q, x0, *shared_values(kern, m, NEWTON.tolerance)])))
    ref = _finish("forward_kinematics", m, out, q, NEWTON.tolerance, "map", 1, 0.0, "fast_newton")
    assert got.statuses == ref.statuses and Status.SOLVED not in got.statuses
    assert all(got.path(i) != "closed" for i in range(len(got)))
    np.testing.assert_allclose(got.raw_joints[:, :2], ref.raw_joints[:, :2], rtol=0, atol=1e-12)
    np.testing.assert_allclose(got.raw_joints[:, :2], np.array(mirrors), rtol=0, atol=1e-12)


RPR2 = {  # a planar 2-RPR point platform: each leg a passive R at the base, an actuated P, an R at P
    "name": "rpr2_point",
    "parameters": {"d": {"dimension": "length", "default": "100 mm"}, "h": {"dimension": "length", "default": "80 mm"}},
    "platform": {
        "planar": True,
        "coordinates": {"x": "length", "y": "length"},
        "position": ["x", "y"],
        "rotation": [],
        "task": ["x", "y"],
        "home": {"y": "h"},
    },
    "legs": [
        {
            "name": name,
            "joints": [
                {"type": "planar_R", "at": [f"{sign}d/2", 0]},
                {
                    "type": "planar_P",
                    "at": [f"{sign}d/2", 0],
                    "axis": [axis, "h"],
                    "actuated": s,
                },
                {"type": "planar_R", "at": [0, "h"]},
            ],
        }
        for name, sign, axis, s in (("left", "-", "d/2", "s1"), ("right", "", "-d/2", "s2"))
    ],
}


def test_rpr_legs_are_circles_of_the_actuated_length():
    """An R-P-R leg (an actuated P between two point joints) is a circle of radius r + s about its
    base joint: the 2-RPR point platform's FK is the two circles' intersection in closed form (its
    kernel alone solves every pose), equal to the numpy derivation and to Newton near it."""
    from cpm_nlp.mechanisms.described import from_dict

    mech = from_dict(RPR2)
    m = mech.model(mech.closure(), {}, {}, ())
    c = m.closure
    assert c.fk_closed is not None
    q = m.q_home + np.random.default_rng(4).uniform(-0.01, 0.01, (60, 2))
    kern = closed_fk_kernel(c, NEWTON)
    out = dict(zip(kern.outputs, evaluate(kern.function, [q, m.x_home, *shared_values(kern, m, 1e-9)])))
    assert np.all(out["status"].ravel() == code_of(Status.SOLVED))
    got = cn.batch_forward_kinematics(m, q)
    assert got.ok.all()
    r0 = np.hypot(0.05, 0.08)  # the legs' length at home
    r1, r2 = r0 + q[:, 0], r0 + q[:, 1]
    x = (r1**2 - r2**2) / (2 * 0.1)  # circles about (-d/2, 0) and (d/2, 0), P above the base
    np.testing.assert_allclose(got.x, np.stack([x, np.sqrt(r1**2 - (x + 0.05) ** 2)], axis=1), rtol=0, atol=1e-12)
    kn = _newton_fk_kernel(c, NEWTON, "rpr2_fk_newton_reference")
    guess = got.x + 1e-4
    ref = dict(zip(kn.outputs, evaluate(kn.function, [q, guess, *shared_values(kn, m, NEWTON.tolerance)])))
    np.testing.assert_allclose(got.x, np.asarray(ref["x"]).reshape(got.x.shape), rtol=0, atol=1e-12)
