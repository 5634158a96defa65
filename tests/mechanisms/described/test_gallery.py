"""The gallery of classic parallel mechanisms: the numpy references
(tests/gallery_reference.py, each citing its source) pass their own checks,
and the hand-written LoopClosures (tests/gallery_closures.py) agree with them:
IK and FK on random poses, AD Jacobians against central differences of the
reference, branch indicators against the reference's other roots, and the
generic machinery (batch FK, all assembly modes) on each."""

import math

import numpy as np
import pytest

import cpm_nlp as cn
from cpm_nlp.analysis.assembly import assembly_modes
from cpm_nlp.core.result import Status
from tests import gallery_closures as gc
from tests import gallery_reference as ref
from tests.conftest import PAPER_PRS3, central_difference

NEWTON = cn.SolverConfig("newton")


@pytest.mark.parametrize("name", ["five_bar", "delta", "rps3", "rrr3", "stewart", "prs3_as_built"])
def test_reference_selftest(name):
    getattr(ref, f"selftest_{name}")()


def _fk_ik_round_trip(model, ts, ref_ik, ref_fk, ik_tol=1e-12, fk_tol=1e-11):
    """IK of the closure equals the reference IK; FK (IPOPT and batch Newton) of
    those actuators returns the pose; FK of the reference's actuators likewise."""
    for t in ts:
        ik = cn.inverse_kinematics(model, t)
        assert ik.ok, ik.message
        x_ref, q_ref = ref_ik(t)
        np.testing.assert_allclose(ik.q, q_ref, atol=ik_tol)
        np.testing.assert_allclose(ik.x, x_ref, atol=ik_tol)
        fk = cn.forward_kinematics(model, q_ref)
        assert fk.ok, fk.message
        np.testing.assert_allclose(fk.x, ref_fk(q_ref, x_ref), atol=fk_tol)
        np.testing.assert_allclose(fk.x, x_ref, atol=fk_tol)
    qs = np.array([ref_ik(t)[1] for t in ts])
    batch = cn.batch_forward_kinematics(model, qs, NEWTON)
    assert batch.ok.all()
    np.testing.assert_allclose(batch.x, np.array([ref_ik(t)[0] for t in ts]), atol=fk_tol)


def _jacobian_vs_reference(model, t, ref_ik, h=1e-7, atol=1e-6):
    """The AD inverse Jacobian dq/dt equals central differences of the reference IK."""
    ik = cn.inverse_kinematics(model, t)
    rep = cn.jacobians(model, ik.x, ik.q)
    num = central_difference(lambda tt: ref_ik(tt)[1], t, h)
    np.testing.assert_allclose(rep.J_inv, num, atol=atol, rtol=1e-6)
    np.testing.assert_allclose(rep.J_task @ rep.J_inv, np.eye(len(t)), atol=1e-9)


def test_five_bar_against_closed_form():
    m = gc.five_bar_model()
    r = ref.FiveBar()
    rng = np.random.default_rng(11)
    ts = [np.array([0.0, 0.33]) + rng.uniform(-0.04, 0.04, 2) for _ in range(10)]
    _fk_ik_round_trip(m, ts, lambda t: (t, r.ik(t)), lambda q, x: r.fk(q)[0])
    _jacobian_vs_reference(m, ts[0], lambda t: (t, r.ik(t)))
    ik = cn.inverse_kinematics(m, ts[0])
    rep = cn.jacobians(m, ik.x, ik.q)
    np.testing.assert_allclose(rep.J, r.jacobian(ik.x, ik.q), atol=1e-12)  # Merlet's A dP = B dθ
    # the other elbow of leg 1 is off the designated working mode
    other = r.ik(ts[0], (-1.0, -1.0))
    assert cn.assess(m, ts[0], other, 1e-10)[0] is Status.WRONG_BRANCH


def test_delta_against_clavel():
    m = gc.delta_model()
    r = ref.Delta()
    home = r.fk(np.zeros(3))
    np.testing.assert_allclose(m.x_home, home, atol=1e-15)
    rng = np.random.default_rng(12)
    ts = [home + rng.uniform(-0.04, 0.04, 3) for _ in range(10)]
    _fk_ik_round_trip(m, ts, lambda t: (t, r.ik(t)), lambda q, x: r.fk(q))
    _jacobian_vs_reference(m, ts[1], lambda t: (t, r.ik(t)))
    # the other root of Clavel's quadratic (knee in) is off the designated branch
    t = ts[2]
    xl, yl, z = ref.rot_z(0.0) @ t
    X = xl + r.rp - r.rb
    E, F = -2 * r.la * X, 2 * r.la * z
    G = X * X + yl * yl + z * z + r.la**2 - r.lb**2
    knee_in = 2 * math.atan((-F + math.sqrt(E * E + F * F - G * G)) / (G - E))
    q = r.ik(t)
    q[0] = knee_in
    status, _msg, details = cn.assess(m, t, q, 1e-10)
    assert status is Status.WRONG_BRANCH and details["residual"] < 1e-14


def test_rps3_against_lee_shah():
    m = gc.rps3_model()
    r = ref.RPS3()
    rng = np.random.default_rng(13)
    ts = [np.array([0.12, 0.0, 0.0]) + rng.uniform([-0.02, -0.15, -0.15], [0.02, 0.15, 0.15]) for _ in range(10)]
    _fk_ik_round_trip(m, ts, lambda t: (r.pose(t), r.ik(t)), lambda q, x: r.fk(q, r.pose([0.12, 0, 0])))
    _jacobian_vs_reference(m, ts[3], lambda t: (r.pose(t), r.ik(t)))
    ik = cn.inverse_kinematics(m, ts[4])
    for i, (A, B) in enumerate(zip(r.base(), r.joints(ik.x))):
        u = A / np.linalg.norm(A)
        assert ik.passive[i] == pytest.approx(math.atan2(B[2] - A[2], (B - A) @ u), abs=1e-14)


@pytest.mark.parametrize("signs", [(1.0, 1.0, 1.0), (-1.0, 1.0, -1.0)])
def test_rrr3_against_dyads(signs):
    m = gc.rrr3_model(sigma1=signs[0], sigma2=signs[1], sigma3=signs[2])
    r = ref.RRR3()
    rng = np.random.default_rng(14)
    ts = [rng.uniform([-0.03, -0.03, -0.2], [0.03, 0.03, 0.2]) for _ in range(10)]
    _fk_ik_round_trip(m, ts, lambda t: (t, r.ik(t, signs)), lambda q, x: r.fk(q, x + 1e-3))
    _jacobian_vs_reference(m, ts[5], lambda t: (t, r.ik(t, signs)))
    q = r.ik(ts[6], signs)
    found = assembly_modes(m, q, starts=1000)
    assert 1 <= found.count <= 6  # Gosselin and Angeles: at most six assembly modes
    for md in found.modes:
        assert np.max(np.abs(r.equations(md.x, q))) < 1e-12


def test_stewart_against_leg_lengths():
    m = gc.stewart_model()
    r = ref.Stewart()
    rng = np.random.default_rng(15)
    home = np.array([0, 0, 0.25, 0, 0, 0.0])
    ts = [home + rng.uniform(-1, 1, 6) * np.array([0.02, 0.02, 0.02, 0.1, 0.1, 0.1]) for _ in range(10)]
    _fk_ik_round_trip(m, ts, lambda t: (t, r.ik(t)), lambda q, x: r.fk(q, home))
    _jacobian_vs_reference(m, ts[7], lambda t: (t, r.ik(t)))


def test_prs3_as_built_against_table3(prs3):
    r = ref.table3()
    m = gc.prs3_as_built_model(r)
    rng = np.random.default_rng(16)
    ts = [np.array([0.0775, 0.0, 0.0]) + rng.uniform([-1e-3, -0.02, -0.02], [1e-3, 0.02, 0.02]) for _ in range(6)]
    _fk_ik_round_trip(m, ts, lambda t: r.ik(t), lambda q, x: r.fk(q, r.home()), ik_tol=1e-11)
    _jacobian_vs_reference(m, ts[0], lambda t: r.ik(t), atol=1e-6)
    # with no deviations the closure is the built-in 3-PRS (prs3-ruiz.md eq 7-9, 35)
    nominal = gc.prs3_as_built_model(ref.AsBuiltPRS3())
    for s in ([1e-3, 0.5e-3, -0.3e-3], [-2e-3, 1e-3, 0.0]):
        a, b = cn.forward_kinematics(nominal, s), cn.forward_kinematics(prs3, s)
        assert a.ok and b.ok
        np.testing.assert_allclose(a.x, b.x, atol=1e-12)
    # the as-built stage at s = 0: the platform sits off the nominal home by a fraction of a mm
    x0 = cn.forward_kinematics(m, np.zeros(3)).x
    assert 1e-5 < np.max(np.abs(x0[:3] - nominal.x_home[:3])) < 1e-3
    assert cn.build_model("prs3", PAPER_PRS3).p.size == 3  # the built-in model is untouched
