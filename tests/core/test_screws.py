"""Twists and wrenches (cpm_nlp.core.screws): reciprocal product, transport,
velocity at a point, screw axes and compliance transforms, numeric and symbolic."""

import casadi as ca
import numpy as np
import pytest

from cpm_nlp.core import screws

RNG = np.random.default_rng(7)


def test_reciprocal_product_of_a_force_and_a_rotation_is_the_moment_arm():
    # force along z through (a, 0, 0), rotation about y through the origin: power = -a
    # (the rotation moves the point (a, 0, 0) with velocity y x (a, 0, 0) = (0, 0, -a))
    a = 0.04
    f = screws.force([0, 0, 1], [a, 0, 0])
    w = screws.rotation([0, 1, 0], [0, 0, 0])
    assert screws.reciprocal(f, w) == pytest.approx(-a)
    assert screws.reciprocal(w, f) == pytest.approx(-a)  # symmetric
    # intersecting or parallel lines are reciprocal
    assert screws.reciprocal(f, screws.rotation([1, 0, 0], [a, 0, 0.3])) == pytest.approx(0.0)
    assert screws.reciprocal(f, screws.rotation([0, 0, 1], [0.1, 0.2, 0])) == pytest.approx(0.0)
    # the Δ form of eq 9
    assert f @ screws.DELTA @ w == pytest.approx(screws.reciprocal(f, w))


def test_reciprocal_product_does_not_depend_on_the_reference_point():
    for _ in range(5):
        a, b = RNG.normal(size=6), RNG.normal(size=6)
        c0, c1 = RNG.normal(size=3), RNG.normal(size=3)
        a1, b1 = screws.transport(a, c0, c1), screws.transport(b, c0, c1)
        assert screws.reciprocal(a1, b1) == pytest.approx(screws.reciprocal(a, b), rel=1e-12)


def test_velocity_at_a_point_is_the_rigid_body_velocity():
    omega, v_ref = RNG.normal(size=3), RNG.normal(size=3)
    c, p = RNG.normal(size=3), RNG.normal(size=3)
    twist = np.r_[omega, v_ref]
    assert np.allclose(screws.velocity_at(twist, c, p), v_ref + np.cross(omega, p - c))
    # a rotation about a line leaves the points of that line at rest
    a, s = RNG.normal(size=3), RNG.normal(size=3)
    rot = screws.rotation(s, a, c)
    assert np.allclose(screws.velocity_at(rot, c, a + 0.7 * s), 0.0, atol=1e-14)


def test_pitch_axis_and_distance_of_a_screw():
    s = np.array([0.0, 0.6, 0.8])
    a = np.array([1.0, 2.0, -1.0])
    h = 0.25
    screw = screws.rotation(s, a) + np.r_[np.zeros(3), h * s]  # rotation plus h times translation
    assert screws.pitch(screw) == pytest.approx(h)
    foot = screws.axis_point(screw)
    assert np.linalg.norm(np.cross(foot - a, s)) == pytest.approx(0.0, abs=1e-14)  # on the axis
    assert foot @ s == pytest.approx(0.0, abs=1e-14)  # nearest to the reference point
    p = a + 0.3 * s + np.array([2.0, 0.0, 0.0])  # 2 away from the axis, perpendicular (s_x = 0)
    assert screws.distance_to_axis(screw, p) == pytest.approx(2.0)
    assert screws.distance_to_axis(2.5 * screw, p) == pytest.approx(2.0)  # scale-free


def test_null_screw_is_reciprocal_to_five_screws_and_matches_the_svd_basis():
    H = RNG.normal(size=(6, 5))
    x = screws.null_screw(H)
    assert np.allclose(H.T @ screws.DELTA @ x, 0.0, atol=1e-12 * np.abs(x).max())
    basis = screws.reciprocal_basis(H)
    assert basis.shape == (6, 1)
    assert abs(abs(basis[:, 0] @ x) / np.linalg.norm(x)) == pytest.approx(1.0)
    # symbolic evaluation gives the same numbers
    Hs = ca.SX.sym("H", 6, 5)
    f = ca.Function("null_screw", [Hs], [screws.null_screw(Hs)])
    assert np.allclose(np.asarray(f(H)).ravel(), x, rtol=1e-10)


def test_symbolic_and_numeric_screws_agree():
    s, a, c = RNG.normal(size=3), RNG.normal(size=3), RNG.normal(size=3)
    S, A, Cs = ca.SX.sym("s", 3), ca.SX.sym("a", 3), ca.SX.sym("c", 3)
    f = ca.Function(
        "f",
        [S, A, Cs],
        [screws.line(S, A, Cs), screws.distance_to_axis(screws.line(S, A), Cs), screws.pitch(screws.line(S, A))],
    )
    line, dist, h = f(s, a, c)
    assert np.allclose(np.asarray(line).ravel(), screws.line(s, a, c))
    assert float(dist) == pytest.approx(screws.distance_to_axis(screws.line(s, a), c))
    assert float(h) == pytest.approx(0.0, abs=1e-14)


def test_compliance_transport_gives_the_cantilever_tip_compliance():
    # a uniform beam of length L referred to its centre: translation L^3/(12 EI), rotation
    # L/(EI), no coupling; at its tip (L/2 further along x): L^3/(3 EI) and coupling L^2/(2 EI)
    L, EI = 0.05, 2.0
    C = np.diag([1e-9, L**3 / (12 * EI), 1e-9, 1e-3, 1e-3, L / EI])
    tip = screws.transport_compliance(C, [0, 0, 0], [L / 2, 0, 0])
    assert tip[1, 1] == pytest.approx(L**3 / (3 * EI))
    assert abs(tip[1, 5]) == pytest.approx(L**2 / (2 * EI))
    assert np.allclose(tip, tip.T)
    # work is frame independent: a wrench at the tip does the same work either way
    w_tip = RNG.normal(size=6)
    w_centre = screws.wrench_transform([L / 2, 0, 0]) @ w_tip
    assert w_tip @ tip @ w_tip == pytest.approx(w_centre @ C @ w_centre)


def test_rotating_a_compliance_matrix():
    C = np.diag([1.0, 2.0, 3.0, 4.0, 5.0, 6.0])
    R = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])  # frame x along the reference y
    Cr = screws.rotate_compliance(C, R)
    assert np.allclose(np.diag(Cr), [2.0, 1.0, 3.0, 5.0, 4.0, 6.0])


@pytest.mark.parametrize(
    ("axis", "angle"),
    [((1.0, 0.0, 0.0), 0.3), ((0.0, 0.0, 1.0), -2.0), ((1.0, 2.0, -2.0), 1.1), ((0.3, -0.4, 0.5), 3.0)],
)
def test_axis_rotation_is_scipy_rotvec_in_numpy_and_casadi(axis, angle):
    """Issue 22, item 5: the one Rodrigues rotation of the package agrees with scipy's
    Rotation.from_rotvec (an independent implementation, quaternion-based), numerically and
    symbolically (SX angle, SX axis)."""
    from scipy.spatial.transform import Rotation

    from cpm_nlp.core.screws import axis_rotation

    k = np.asarray(axis) / np.linalg.norm(axis)
    expected = Rotation.from_rotvec(angle * k).as_matrix()
    assert axis_rotation(k, angle) == pytest.approx(expected, abs=1e-14)
    th = ca.SX.sym("th")
    w = ca.SX.sym("w", 3)
    symbolic = ca.Function("R", [th, w], [axis_rotation(w, th)], ["th", "w"], ["R"])
    assert isinstance(axis_rotation(w, th), ca.SX)
    assert np.asarray(symbolic(angle, k)) == pytest.approx(expected, abs=1e-14)
    assert isinstance(axis_rotation(ca.DM(k), th), ca.SX)
