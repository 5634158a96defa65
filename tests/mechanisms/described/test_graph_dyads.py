"""Prismatic dyads in closed form (issue 23, item 5; cpm_nlp.mechanisms.described.graph_dyads): the
slider-crank with its rod a distance joint (one body: a slide and a rod, RRP), with its rod a body
pinned at both ends (a pair of bodies, RRP), and the inverted slider-crank (the crank's block
sliding on a rocker: RPR), each against its textbook closed form derived here in numpy, against
Newton on the same poses, and its AD Jacobian against central differences."""

from __future__ import annotations

import casadi as ca
import numpy as np
import pytest

import cpm_nlp as cn
from cpm_nlp.core.batch import _finish, evaluate
from cpm_nlp.core.kernels import _newton_fk_kernel, closed_fk_kernel, shared_values
from cpm_nlp.core.pose_checks import code_of
from cpm_nlp.core.result import Status
from cpm_nlp.mechanisms.described import from_dict
from tests.conftest import central_difference

NEWTON = cn.SolverConfig("newton")
A, E, L, B = 0.020, 0.010, 0.060, 0.040  # crank, slider offset, rod; the rocker's pivot below the crank's

SLIDER_ROD = {  # the slider-crank of docs/site/guide/mechanism-files.md, drawn exactly
    "name": "slider_rod",
    "parameters": {"l": {"dimension": "length", "default": "60 mm", "bounds": ["30 mm", "100 mm"]}},
    "points": {"O": ["0 mm", "0 mm"], "A": ["20 mm", "0 mm"], "S": ["20 mm + sqrt(l^2 - (10 mm)^2)", "10 mm"]},
    "bodies": {"ground": ["O"], "crank": ["O", "A"], "slider": ["S"]},
    "joints": [
        {"type": "R", "between": ["ground", "crank"], "at": "O", "actuated": "theta"},
        {
            "type": "P",
            "between": ["ground", "slider"],
            "at": "S",
            "axis": [1, 0],
            "coordinates": ["s"],
            "home": ["20 mm + sqrt(l^2 - (10 mm)^2)"],
        },
        {"type": "distance", "between": ["crank", "slider"], "at": "A", "to": "S"},
    ],
    "platform": {"planar": True, "task": ["s"]},
}

SLIDER_LINK = {  # the same, its rod a body pinned to the crank and to the slider (listed slider first)
    **SLIDER_ROD,
    "name": "slider_link",
    "bodies": {"ground": ["O"], "crank": ["O", "A"], "rod": ["A", "S"], "slider": ["S"]},
    "joints": [
        *SLIDER_ROD["joints"][:2],
        {"type": "R", "between": ["crank", "rod"], "at": "A"},
        {"type": "R", "between": ["slider", "rod"], "at": "S"},
    ],
}

INVERTED = {  # the inverted slider-crank: a block pinned to the crank pin slides on a rocker pivoted at B
    "name": "inverted_slider_crank",
    "points": {"O": ["0 mm", "0 mm"], "A": ["20 mm", "0 mm"], "B": ["0 mm", "-40 mm"]},
    "bodies": {"ground": ["O", "B"], "crank": ["O", "A"], "block": ["A"], "rocker": ["B", "A"]},
    "joints": [
        {"type": "R", "between": ["ground", "crank"], "at": "O", "actuated": "theta"},
        {"type": "R", "between": ["crank", "block"], "at": "A"},
        {"type": "R", "between": ["ground", "rocker"], "at": "B", "coordinates": ["psi"]},
        {"type": "P", "between": ["block", "rocker"], "at": "A", "axis": [1, 2]},
    ],
    "platform": {"planar": True, "task": ["psi"]},
}

THETA = np.deg2rad(np.arange(-170.0, 181.0, 10.0))[:, None]


def _model(data):
    mech = from_dict(data)
    return mech.model(mech.closure(), {}, {}, ())


def _kernel(kern, model, q, x0):
    return dict(zip(kern.outputs, evaluate(kern.function, [q, x0, *shared_values(kern, model, NEWTON.tolerance)])))


def _newton(model, q, x0):
    kern = _newton_fk_kernel(model.closure, NEWTON, f"{model.closure.name}_fk_newton_reference")
    out = _kernel(kern, model, q, x0)
    return _finish("forward_kinematics", model, out, q, NEWTON.tolerance, "map", 1, 0.0, "fast_newton")


def _slider_s(theta):
    """s = a cos θ + √(l² − (e − a sin θ)²): the slider's pin on y = e, |AS| = l (derived here)."""
    return A * np.cos(theta) + np.sqrt(L**2 - (E - A * np.sin(theta)) ** 2)


def _rocker_psi(theta):
    """The rocker's turn from the drawing: the direction of A(θ) - B against A(0) - B."""
    d = np.stack([A * np.cos(theta), A * np.sin(theta) + B], axis=-1)
    return np.arctan2(d[..., 1], d[..., 0]) - np.arctan2(B, A)


@pytest.mark.parametrize(
    "data, expected",
    [(SLIDER_ROD, _slider_s), (SLIDER_LINK, _slider_s), (INVERTED, _rocker_psi)],
    ids=["rrp_rod", "rrp_pair", "rpr"],
)
def test_prismatic_dyad_in_closed_form(data, expected):
    """A full turn of the crank: every pose settled by the closed form (its kernel alone), the task
    coordinate equal to the numpy closed form (1e-12), the pose equal to Newton's from a guess near
    it (1e-10), the AD Jacobian equal to central differences and to -Φ_x⁻¹ Φ_q."""
    m = _model(data)
    c = m.closure
    assert c.fk_closed is not None
    closed = _kernel(closed_fk_kernel(c, NEWTON), m, THETA, m.x_home)
    assert np.all(closed["status"].ravel() == code_of(Status.SOLVED))
    got = cn.batch_forward_kinematics(m, THETA)
    assert got.ok.all()
    t = got.x[:, list(c.task_index)].ravel()
    want = expected(THETA.ravel())
    if data is INVERTED:
        want = (want + np.pi) % (2 * np.pi) - np.pi
    np.testing.assert_allclose(t, want, rtol=0, atol=1e-12)
    guess = got.x + np.random.default_rng(1).uniform(-1e-3, 1e-3, got.x.shape)
    ref = _newton(m, THETA, guess)
    assert ref.ok.all()
    np.testing.assert_allclose(got.x, ref.x, rtol=0, atol=1e-10)
    q_sym = ca.SX.sym("q", c.nq)
    x0 = ca.SX.sym("x0", c.nx)  # the guess picks the turn of an angle: the pose itself, away from a wrap
    dx_dq = ca.Function("dx_dq", [q_sym, x0], [ca.jacobian(c.fk_closed(q_sym, x0, m.p)[0], q_sym)])
    for qi in THETA[::5]:
        xi = np.asarray(c.fk_closed(qi, m.x_home, m.p)[0]).ravel()
        jac = np.asarray(dx_dq(qi, xi))
        fd = central_difference(lambda v, x0=xi: np.asarray(c.fk_closed(v, x0, m.p)[0]).ravel(), qi, 1e-6)
        np.testing.assert_allclose(jac, fd, rtol=0, atol=1e-7)
        np.testing.assert_allclose(jac, np.asarray(c.jacobian(xi, qi, m.p)), rtol=0, atol=1e-10)


def test_slider_crank_out_of_reach_and_other_assembly():
    """A 12 mm rod (it reaches the slider's line at home): at θ = -90 deg the line is 30 mm from the
    crank pin, out of reach, and the pose is left to Newton, whose status stands; a guess with the
    slider on the crank pin's other side (the other assembly) is left to Newton too."""
    m = _model({**SLIDER_ROD, "name": "slider_short", "parameters": {"l": {"dimension": "length", "default": "12 mm"}}})
    c = m.closure
    far = np.array([[-np.pi / 2]])  # e - a sin θ = 30 mm > l
    assert float(c.fk_closed(far[0], m.x_home, m.p)[1]) < 0
    got, ref = cn.batch_forward_kinematics(m, far), _newton(m, far, m.x_home[None, :])
    assert got.statuses == ref.statuses and got.statuses[0] is not Status.SOLVED
    m = _model(SLIDER_ROD)
    q = np.ascontiguousarray(THETA[::6])
    other = np.tile(m.x_home, (len(q), 1))
    other[:, list(m.closure.x_names).index("s")] = -0.06  # the slider left of the crank pin
    closed = _kernel(closed_fk_kernel(m.closure, NEWTON), m, q, other)
    assert not np.any(closed["status"].ravel() == code_of(Status.SOLVED))
    got, ref = cn.batch_forward_kinematics(m, q, guess=other), _newton(m, q, other)
    assert got.statuses == ref.statuses


TRIAD = {  # an RRR dyad (coupler and rocker) placed by the crank, then a triad (a class III group)
    "name": "dyad_then_triad",
    "points": {
        "G0": ["0 mm", "0 mm"],
        "X": ["10 mm", "0 mm"],
        "G1": ["40 mm", "0 mm"],
        "M": ["30 mm", "25 mm"],
        "A": ["20 mm", "50 mm"],
        "B": ["45 mm", "55 mm"],
        "C": ["35 mm", "70 mm"],
        "G2": ["70 mm", "40 mm"],
        "G3": ["0 mm", "75 mm"],
    },
    "bodies": {
        "ground": ["G0", "G1", "G2", "G3"],
        "crank": ["G0", "X"],
        "coupler": ["X", "M"],
        "rocker": ["G1", "M"],
        "l1": ["M", "A"],
        "tri": ["A", "B", "C"],
        "l2": ["G2", "B"],
        "l3": ["G3", "C"],
    },
    "joints": [
        {"type": "R", "between": ["ground", "crank"], "at": "G0", "actuated": "theta"},
        {"type": "R", "between": ["crank", "coupler"], "at": "X"},
        {"type": "R", "between": ["ground", "rocker"], "at": "G1", "coordinates": ["psi"]},
        {"type": "R", "between": ["coupler", "rocker"], "at": "M"},
        {"type": "R", "between": ["rocker", "l1"], "at": "M"},
        {"type": "R", "between": ["l1", "tri"], "at": "A"},
        {"type": "R", "between": ["ground", "l2"], "at": "G2"},
        {"type": "R", "between": ["l2", "tri"], "at": "B"},
        {"type": "R", "between": ["ground", "l3"], "at": "G3"},
        {"type": "R", "between": ["l3", "tri"], "at": "C"},
    ],
    "platform": {"planar": True, "task": ["psi"]},
}


def test_a_triad_after_a_dyad_is_left_to_newton():
    """A triad (a ternary body held by three links: no dyad places it) after an RRR dyad: no closed
    form of the whole, but a seed -- the dyad's coordinates in closed form (equal to Newton's
    solution to 1e-12), the triad's from the guess, its links keeping their turn -- from which
    Newton solves every pose of +-20 deg, equal to Newton from home (1e-10)."""
    from cpm_nlp.mechanisms.described.read import description_from_dict
    from cpm_nlp.mechanisms.described.summary import summary_text

    m = _model(TRIAD)
    c = m.closure
    assert c.fk_closed is None and c.fk_seed is not None
    text = summary_text(description_from_dict(TRIAD), None, "triad")
    assert "partly in closed form: 1 dyad(s), RRR (coupler, rocker); Newton places l1, tri, l2, l3" in text
    q = np.deg2rad(np.arange(-20.0, 21.0, 5.0))[:, None]
    ref = _newton(m, q, np.tile(m.x_home, (len(q), 1)))
    got = cn.batch_forward_kinematics(m, q)
    assert ref.ok.all() and got.ok.all()
    np.testing.assert_allclose(got.x, ref.x, rtol=0, atol=1e-10)
    placed = [list(c.x_names).index(n) for n in ("J1", "J2", "psi")]  # crank, coupler, rocker
    for qi, xi in zip(q, ref.x):
        seed = np.asarray(c.fk_seed(qi, m.x_home, m.p)).ravel()
        np.testing.assert_allclose(seed[placed], xi[placed], rtol=0, atol=1e-12)
