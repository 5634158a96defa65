"""Spherical dyads in closed form (issue 23, item 5; cpm_nlp.mechanisms.described.graph_spherical):
the spherical four-bar (problems/mechanisms/spherical_four_bar.yaml) over a whole crank turn in
both assemblies, against its input-output relation derived here by spherical trigonometry in
numpy, against Newton on the same poses, the AD Jacobian against central differences, FK against
IK; the branch kept over the turn; a pose out of reach and axes that no longer meet left to Newton
with its status; a spatial 4R whose axes do not meet (Bennett's) gets no closed form."""

from __future__ import annotations

from pathlib import Path

import casadi as ca
import numpy as np
import pytest
import yaml

import cpm_nlp as cn
from cpm_nlp.core.batch import _finish, evaluate
from cpm_nlp.core.kernels import _newton_fk_kernel, closed_fk_kernel, shared_values
from cpm_nlp.core.pose_checks import code_of
from cpm_nlp.core.result import Status
from cpm_nlp.mechanisms.described import from_dict
from tests.conftest import central_difference

NEWTON = cn.SolverConfig("newton")
ROOT = Path(__file__).resolve().parents[3]
FILE = ROOT / "problems" / "mechanisms" / "spherical_four_bar.yaml"
TURN = np.deg2rad(np.arange(0.5, 360.0, 1.0))[:, None]  # a crank turn, 1 deg apart


def _data(**changes) -> dict:
    d = yaml.safe_load(FILE.read_text(encoding="utf-8"))
    d.pop("examples")
    d.update(changes)
    return d


def _mirrored() -> dict:
    """The same linkage drawn in its other assembly (b1 on the other side of the arc a1-b0)."""
    d = _data(name="spherical_four_bar_other")
    d["derived"]["b1"]["value"] = "xb*a1 + yb*b0 - zb*cross(a1, b0)"
    return d


def _model(data: dict):
    mech = from_dict(data)
    return mech.model(mech.closure(), {}, {}, ())


@pytest.fixture(scope="module")
def four_bar():
    return cn.build_model("spherical_four_bar")


@pytest.fixture(scope="module")
def other():
    return _model(_mirrored())


def _kernel(kern, model, q, x0):
    out = evaluate(kern.function, [q, x0, *shared_values(kern, model, NEWTON.tolerance)])
    return dict(zip(kern.outputs, out))


def _newton(model, q, x0):
    """The FK as it is without the closed form: Newton on Φ from x0."""
    kern = _newton_fk_kernel(model.closure, NEWTON, f"{model.closure.name}_fk_newton_reference")
    return _finish("forward_kinematics", model, _kernel(kern, model, q, x0), q, NEWTON.tolerance, "map", 1, 0.0, "f")


def _psi_numpy(P: dict, theta: np.ndarray, sigma: float) -> np.ndarray:
    """The follower's angle about b0 (right-handed), from the arc b0-a0 to the arc b0-b1, for the
    crank at theta about a0 = z (from the arc a0-b0), by the spherical law of cosines (derived here):
    the diagonal d = arc a1-b0 of triangle a0 a1 b0 (sides alpha, gamma, angle theta at a0); at b0
    the angle delta from b0-a0 to b0-a1 (law of cosines for its cosine, law of sines for its sine;
    right-handed about b0 it turns towards -y) and the angle kappa from b0-a1 to b0-b1 of triangle
    a1 b0 b1 (sides d, beta, eta); the assembly sigma = +-1."""
    al, et, be, ga = P["alpha"], P["eta"], P["beta"], P["gamma"]
    cd = np.cos(al) * np.cos(ga) + np.sin(al) * np.sin(ga) * np.cos(theta)
    sd = np.sqrt(1 - cd**2)
    delta = np.arctan2(-np.sin(al) * np.sin(theta) / sd, (np.cos(al) - np.cos(ga) * cd) / (np.sin(ga) * sd))
    kappa = np.arccos((np.cos(et) - np.cos(be) * cd) / (np.sin(be) * sd))
    return delta + sigma * kappa


def _wrapped(a: np.ndarray) -> np.ndarray:
    return (a + np.pi) % (2 * np.pi) - np.pi


def test_the_four_bar_is_one_spherical_dyad(four_bar):
    """The coupler and the follower are placed by one spherical dyad, detected from the graph: the
    closed form exists, gives the reference configuration back, and ``describe`` says so."""
    from cpm_nlp.mechanisms.described.read import description_from_dict
    from cpm_nlp.mechanisms.described.summary import summary_text

    m, c = four_bar, four_bar.closure
    assert c.fk_closed is not None and c.fk_seed is None
    x, disc, side = (np.asarray(v).ravel() for v in c.fk_closed(m.q_home, m.x_home, m.p))
    np.testing.assert_allclose(x, m.x_home, rtol=0, atol=1e-14)
    assert disc[0] > 0 and side[0] > 0
    text = summary_text(description_from_dict(yaml.safe_load(FILE.read_text())), None, "spherical_four_bar.yaml")
    assert "forward kinematics in closed form: 1 spherical dyad(s), RRR (coupler, follower)" in text


@pytest.mark.parametrize("which, sigma", [("file", -1.0), ("mirrored", 1.0)])
def test_turn_in_closed_form_against_spherical_trigonometry_and_newton(four_bar, other, which, sigma):
    """A whole crank turn in each assembly: every pose settled by the closed form (its kernel alone,
    every check), the follower's angle equal to the spherical law of cosines' of the same assembly
    (1e-12 rad; the assembly the drawing shows, kept over the whole turn: the branch sign is
    stable), the coupler-follower axis at its arcs eta and beta from the crank's and the follower's
    axes, and the pose equal to Newton's from a guess near it (1e-10)."""
    m = four_bar if which == "file" else other
    c, P = m.closure, m.parameters
    closed = _kernel(closed_fk_kernel(c, NEWTON), m, TURN, m.x_home)
    assert np.all(closed["status"].ravel() == code_of(Status.SOLVED))
    got = cn.batch_forward_kinematics(m, TURN)
    assert got.ok.all()
    np.testing.assert_array_equal(got.x, np.asarray(closed["x"]).reshape(got.x.shape))  # the closed form's
    psi = got.x[:, list(c.x_names).index("psi")]
    th = TURN.ravel()
    want = _psi_numpy(P, th, sigma) - _psi_numpy(P, np.array([P["th0"]]), sigma)
    np.testing.assert_allclose(_wrapped(psi - want), 0, atol=1e-12)
    other_branch = _psi_numpy(P, th, -sigma) - _psi_numpy(P, np.array([P["th0"]]), sigma)
    assert np.abs(_wrapped(psi - other_branch)).min() > 1e-3  # never the other assembly's
    names = list(c.passive_names)
    B1 = got.passive[:, [names.index(f"B1_{k}") for k in "xyz"]] / P["r"]
    sa, ca_ = np.sin(P["alpha"]), np.cos(P["alpha"])
    a1 = np.stack([sa * np.cos(th), sa * np.sin(th), np.full_like(th, ca_)], 1)  # the crank's axis
    b0 = np.array([np.sin(P["gamma"]), 0.0, np.cos(P["gamma"])])
    np.testing.assert_allclose(np.einsum("ij,ij->i", B1, a1), np.cos(P["eta"]), atol=1e-13)
    np.testing.assert_allclose(B1 @ b0, np.cos(P["beta"]), atol=1e-13)
    guess = got.x + np.random.default_rng(0).uniform(-0.01, 0.01, got.x.shape)
    ref = _newton(m, TURN, guess)
    assert ref.ok.all()
    np.testing.assert_allclose(got.x, ref.x, rtol=0, atol=1e-10)


def test_fk_against_ik_and_ad_jacobian(four_bar):
    """The IK (Newton for the crank angle from the follower's) returns the closed form's crank angle
    and pose; the AD Jacobian of fk_closed equals central differences and the closure's
    J = -Φ_x⁻¹ Φ_q, over +-45 deg about the drawing (the follower at mid-stroke: the IK from home stays
    on the crank angle the closed form started from there)."""
    m, c = four_bar, four_bar.closure
    q_sym = ca.SX.sym("q", c.nq)
    dx_dq = ca.Function("dx_dq", [q_sym], [ca.jacobian(c.fk_closed(q_sym, m.x_home, m.p)[0], q_sym)], ["q"], ["J"])
    for qi in m.q_home + np.deg2rad(np.arange(-45.0, 46.0, 15.0))[:, None]:
        xi = np.asarray(c.fk_closed(qi, m.x_home, m.p)[0]).ravel()
        ik = cn.inverse_kinematics(m, xi[list(c.task_index)], NEWTON)
        assert ik.status is Status.SOLVED
        np.testing.assert_allclose(ik.q, qi, rtol=0, atol=1e-10)
        np.testing.assert_allclose(ik.x, xi, rtol=0, atol=1e-9)
        jac = np.asarray(dx_dq(qi))
        fd = central_difference(lambda v: np.asarray(c.fk_closed(v, m.x_home, m.p)[0]).ravel(), qi, 1e-6)
        np.testing.assert_allclose(jac, fd, rtol=0, atol=1e-7)
        np.testing.assert_allclose(jac, np.asarray(c.jacobian(xi, qi, m.p)), rtol=0, atol=1e-10)


def test_out_of_reach_keeps_newtons_status():
    """A longer crank (alpha = 45 deg: shortest + longest arcs exceed the other two, so the crank does
    not turn fully): where the cones do not meet, disc < 0, the closed form settles nothing and the
    status is Newton's, never a number; the poses in reach are still settled by the closed form."""
    m = cn.build_model("spherical_four_bar", {"alpha": "45 deg"})
    c = m.closure
    disc = np.array([float(c.fk_closed(qi, m.x_home, m.p)[1]) for qi in TURN])
    far, near = TURN[disc < 0], TURN[disc > 1e-3]
    assert len(far) > 10 and len(near) > 10
    got, ref = cn.batch_forward_kinematics(m, far), _newton(m, far, np.tile(m.x_home, (len(far), 1)))
    assert got.statuses == ref.statuses and Status.SOLVED not in got.statuses
    closed = _kernel(closed_fk_kernel(c, NEWTON), m, far, m.x_home)
    assert np.all(closed["status"].ravel() == code_of(Status.NOT_CONVERGED))
    one = cn.forward_kinematics(m, far[0], NEWTON)
    assert one.status is not Status.SOLVED and one.status is got.statuses[0]
    closed = _kernel(closed_fk_kernel(c, NEWTON), m, near, m.x_home)
    inside = closed["status"].ravel() == code_of(Status.SOLVED)
    assert inside.mean() > 0.9  # the rest: guesses on the other side of a fold (Newton answers)


def test_axes_that_no_longer_meet_are_left_to_newton():
    """The concurrency is checked on the parameters in use, not assumed from the defaults: with the
    crank-coupler joint moved off its axis by a parameter e (0 by default: the axes meet, the closed
    form is generated), e = 1 µm makes disc negative (the pose is Newton's); a spatial 4R whose axes
    do not meet (Bennett's, tests/corpus/bennett.yaml) has no closed form at all."""
    d = _data(name="spherical_four_bar_offset")
    d["parameters"]["e"] = {"dimension": "length", "default": "0 mm"}
    d["points"]["A1"] = "r*a1 + e*[0, 0, 1]"
    m = _model(d)
    c = m.closure
    assert c.fk_closed is not None
    assert float(c.fk_closed(m.q_home, m.x_home, m.p)[1]) > 0
    p = m.p.copy()
    p[list(c.parameters).index("e")] = 1e-6
    assert float(c.fk_closed(m.q_home, m.x_home, p)[1]) < 0
    bennett = _model(yaml.safe_load((ROOT / "tests" / "corpus" / "bennett.yaml").read_text()))
    assert bennett.closure.fk_closed is None and bennett.closure.fk_seed is None


def _tip_numpy(P: dict, q: np.ndarray) -> np.ndarray:
    """The five-bar's tip direction for crank angles q (N x 2), derived here: the crank axes a1, b1
    turned about a0, b0 as the file draws them, and the unit c with c·a1 = c·b1 = cos(beta) (both
    links' arcs equal) on the tip-up assembly: c = k (a1 + b1) + h (b1 × a1), by symmetry."""
    g, al, be = P["gamma"], P["alpha"], P["beta"]
    a0, b0 = np.array([-np.sin(g / 2), 0, np.cos(g / 2)]), np.array([np.sin(g / 2), 0, np.cos(g / 2)])
    e, f, y = np.array([np.cos(g / 2), 0, np.sin(g / 2)]), np.array([np.cos(g / 2), 0, -np.sin(g / 2)]), np.eye(3)[1]
    t1, t2 = q[:, :1], q[:, 1:]
    a1 = np.cos(al) * a0 + np.sin(al) * (np.cos(t1) * e + np.sin(t1) * y)
    b1 = np.cos(al) * b0 + np.sin(al) * (np.cos(t2) * f + np.sin(t2) * y)
    s = a1 + b1
    k = np.cos(be) / np.einsum("ij,ij->i", s, a1)[:, None]  # c·a1 = k (1 + a1·b1) = cos(beta)
    n = np.cross(b1, a1)
    h = np.sqrt((1 - k[:, 0] ** 2 * np.einsum("ij,ij->i", s, s)) / np.einsum("ij,ij->i", n, n))[:, None]
    return k * s + h * n


def test_five_bar_in_closed_form():
    """The spherical five-bar (problems/mechanisms/spherical_five_bar.yaml: one spherical dyad placed
    by the two cranks, the tip's coordinates by their linear rows): over +-25 deg of each crank
    every pose is settled by the closed form, the tip on the direction derived in numpy (1e-12 m),
    equal to Newton's from a guess near it (1e-10); the IK (Newton from the tip's x, y) gives the
    cranks back; the AD Jacobian equals central differences and -Φ_x⁻¹ Φ_q."""
    m = cn.build_model("spherical_five_bar")
    c, P = m.closure, m.parameters
    assert c.fk_closed is not None
    q = m.q_home + np.random.default_rng(0).uniform(-np.deg2rad(25), np.deg2rad(25), (200, 2))
    closed = _kernel(closed_fk_kernel(c, NEWTON), m, q, m.x_home)
    assert np.all(closed["status"].ravel() == code_of(Status.SOLVED))
    got = cn.batch_forward_kinematics(m, q)
    assert got.ok.all()
    names = list(c.x_names)
    tip = got.x[:, [names.index(n) for n in "xyz"]]
    np.testing.assert_allclose(tip, P["r"] * _tip_numpy(P, q), rtol=0, atol=1e-12)
    scale = np.array([1e-3] * 3 + [1.0] * 4)  # 10 µm on the tip, 0.01 rad on the joints
    ref = _newton(m, q, got.x + np.random.default_rng(1).uniform(-0.01, 0.01, got.x.shape) * scale)
    assert ref.ok.all()
    np.testing.assert_allclose(got.x, ref.x, rtol=0, atol=1e-10)
    q_sym = ca.SX.sym("q", c.nq)
    dx_dq = ca.Function("dx_dq", [q_sym], [ca.jacobian(c.fk_closed(q_sym, m.x_home, m.p)[0], q_sym)], ["q"], ["J"])
    for qi in q[:8]:
        xi = np.asarray(c.fk_closed(qi, m.x_home, m.p)[0]).ravel()
        ik = cn.inverse_kinematics(m, xi[list(c.task_index)], NEWTON)
        assert ik.status is Status.SOLVED
        np.testing.assert_allclose(ik.q, qi, rtol=0, atol=1e-9)
        jac = np.asarray(dx_dq(qi))
        fd = central_difference(lambda v: np.asarray(c.fk_closed(v, m.x_home, m.p)[0]).ravel(), qi, 1e-6)
        np.testing.assert_allclose(jac, fd, rtol=0, atol=1e-7)
        np.testing.assert_allclose(jac, np.asarray(c.jacobian(xi, qi, m.p)), rtol=0, atol=1e-10)


def test_a_slider_after_the_dyad_is_left_to_newton():
    """The four-bar's follower drives a slider on the ground (a P joint along x) through a rod (a
    distance joint from B1): no closed form of the whole, but a seed -- the spherical dyad's
    coordinates in closed form, the slider's from the guess -- from which Newton solves the whole
    turn: the follower's angle the four-bar's closed form's (1e-10 rad), the slider on the line-
    sphere intersection derived here, s = B1_x + √(L² - B1_y² - B1_z²) (1e-12 m); Newton from home
    without the seed fails on part of the turn."""
    d = _data(name="spherical_four_bar_slider")
    d["points"]["S"] = ["100 mm", "0 mm", "0 mm"]
    d["bodies"]["slider"] = ["S"]
    d["joints"] += [
        {"type": "P", "between": ["ground", "slider"], "at": "S", "axis": [1, 0, 0], "coordinates": ["s"]},
        {"type": "distance", "between": ["follower", "slider"], "at": "B1", "to": "S"},
    ]
    m = _model(d)
    c = m.closure
    assert c.fk_closed is None and c.fk_seed is not None
    got = cn.batch_forward_kinematics(m, TURN)
    assert got.ok.all()
    four = cn.batch_forward_kinematics(cn.build_model("spherical_four_bar"), TURN)
    names = list(c.x_names)
    np.testing.assert_allclose(_wrapped(got.x[:, names.index("psi")] - four.x[:, 2]), 0, atol=1e-10)
    B1 = four.passive  # B1_x, B1_y, B1_z of the four-bar at the same crank angles
    L = float(np.linalg.norm(_b1_home(m) - [0.1, 0, 0]))  # the rod: its length in the drawing
    want = B1[:, 0] + np.sqrt(L**2 - B1[:, 1] ** 2 - B1[:, 2] ** 2) - 0.1  # s: the slide from the drawing
    np.testing.assert_allclose(got.x[:, names.index("s")], want, rtol=0, atol=1e-12)
    home = _newton(m, TURN, np.tile(m.x_home, (len(TURN), 1)))
    assert 0 < np.mean(home.ok) < 1


def _b1_home(m) -> np.ndarray:
    names = list(m.closure.passive_names)
    pas = np.asarray(m.closure.passive(m.x_home, m.q_home, m.p)).ravel()
    return pas[[names.index(f"B1_{k}") for k in "xyz"]]
