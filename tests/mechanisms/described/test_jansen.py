"""Jansen's leg in closed form (issue 23, item 5; problems/mechanisms/jansen.yaml, graph_dyads):
three RRR dyads placed from the crank and the frame, the full crank cycle in closed form, checked
against Newton on the same poses, against the IK, by central differences, and against pylinkage's
own simulation of the same leg (an independent program)."""

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
from tests.conftest import central_difference

NEWTON = cn.SolverConfig("newton")
JANSEN_FILE = Path(__file__).resolve().parents[3] / "problems" / "mechanisms" / "jansen.yaml"
CYCLE = np.deg2rad(np.arange(1, 361, dtype=float))[:, None]  # pylinkage's steps: 1 deg .. 360 deg


@pytest.fixture(scope="module")
def jansen():
    return cn.build_model("jansen")


def _kernel(kern, model, q, x0):
    out = evaluate(kern.function, [q, x0, *shared_values(kern, model, NEWTON.tolerance)])
    return dict(zip(kern.outputs, out))


def _newton(model, q, x0):
    """The FK as it is without the closed form: Newton on Φ from x0."""
    kern = _newton_fk_kernel(model.closure, NEWTON, "jansen_fk_newton_reference")
    out = _kernel(kern, model, q, x0)
    return _finish("forward_kinematics", model, out, q, NEWTON.tolerance, "map", 1, 0.0, "fast_newton")


def _foot(model, res):
    names = list(model.closure.passive_names)
    return res.passive[:, [names.index("foot_x"), names.index("foot_y")]]


def test_jansen_decomposes_into_three_rrr_dyads(jansen):
    """The leg's graph is placed by three RRR dyads (Y with the upper triangle, W, E with the foot):
    the closed form exists, reproduces the file's reference configuration, and ``describe`` names
    the dyads."""
    c = jansen.closure
    assert c.fk_closed is not None and c.fk_closed.name_in() == ["q", "x0", "p"]
    x, disc, side = (np.asarray(v).ravel() for v in c.fk_closed(jansen.q_home, jansen.x_home, jansen.p))
    np.testing.assert_allclose(x, jansen.x_home, rtol=0, atol=1e-14)
    assert disc[0] > 0 and side[0] > 0
    from cpm_nlp.mechanisms.described.read import description_from_dict
    from cpm_nlp.mechanisms.described.summary import summary_text

    text = summary_text(description_from_dict(yaml.safe_load(JANSEN_FILE.read_text())), None, "jansen.yaml")
    dyads = "RRR (j_bar, upper), RRR (k_bar, c_bar), RRR (f_bar, foot)"
    assert f"forward kinematics in closed form: 3 dyad(s), {dyads}" in text


def test_cycle_closed_form_equals_newton(jansen):
    """360 crank angles: every pose settled by the closed form (its kernel alone: status solved,
    every check), equal to Newton on Φ from a guess near it (1e-10 rad) and, where Newton from the
    home guess solves, to that too (angles modulo a turn, the foot exactly)."""
    m = jansen
    closed = _kernel(closed_fk_kernel(m.closure, NEWTON), m, CYCLE, m.x_home)
    assert np.all(closed["status"].ravel() == code_of(Status.SOLVED))
    got = cn.batch_forward_kinematics(m, CYCLE)
    assert got.ok.all()
    np.testing.assert_array_equal(got.x, np.asarray(closed["x"]).reshape(got.x.shape))
    guess = got.x + np.random.default_rng(0).uniform(-0.01, 0.01, got.x.shape)
    ref = _newton(m, CYCLE, guess)
    assert ref.ok.all()
    np.testing.assert_allclose(got.x, ref.x, rtol=0, atol=1e-10)
    np.testing.assert_allclose(_foot(m, got), _foot(m, ref), rtol=0, atol=1e-12)
    home = _newton(m, CYCLE, np.tile(m.x_home, (len(CYCLE), 1)))
    ok = home.ok
    assert ok.sum() >= 100  # Newton from home settles a good part of the cycle, not all of it
    turn = (got.x[ok] - home.x[ok] + np.pi) % (2 * np.pi) - np.pi
    np.testing.assert_allclose(turn, 0, atol=1e-10)
    np.testing.assert_allclose(_foot(m, got)[ok], _foot(m, home)[ok], rtol=0, atol=1e-12)


def test_foot_path_against_pylinkage(jansen):
    """pylinkage's own simulation of the same leg (a Crank and five RRRDyads, each intersection
    taken nearest the previous step's, one degree per step) gives the same foot path over the
    whole turn (1e-12 m), though it is written apart from this code and follows the assembly by
    continuity where the closed form takes the reference's sign."""
    pl = pytest.importorskip("pylinkage")
    m = jansen
    P = m.parameters
    a, b, c, d, e, f, g, h, i, j, k, l, crank = (P[n] for n in "abcdefghijklm")
    x0 = dict(zip(m.closure.passive_names, m.closure.passive(m.x_home, m.q_home, m.p).full().ravel()))
    got = cn.batch_forward_kinematics(m, CYCLE)
    foot = _foot(m, got)
    # hints: the reference configuration's points, from the file's derived values (numpy, below)
    pts = _numpy_reference(P)
    O, Z = pl.Ground(0.0, 0.0, name="O"), pl.Ground(-a, -l, name="Z")
    cr = pl.Crank(O, crank, angular_velocity=np.pi / 180, initial_angle=0.0, name="crank")
    Y = pl.RRRDyad(cr.output, Z, j, b, x=pts["Y"][0], y=pts["Y"][1], name="Y")
    D = pl.RRRDyad(Z, Y, d, e, x=pts["D"][0], y=pts["D"][1], name="D")
    W = pl.RRRDyad(cr.output, Z, k, c, x=pts["W"][0], y=pts["W"][1], name="W")
    E = pl.RRRDyad(D, W, f, g, x=pts["E"][0], y=pts["E"][1], name="E")
    F = pl.RRRDyad(W, E, i, h, x=pts["F"][0], y=pts["F"][1], name="F")
    steps = np.array([s[-1] for s in pl.Linkage([O, Z, cr, Y, D, W, E, F]).step(iterations=360, dt=1)])
    assert steps.shape == (360, 2)
    np.testing.assert_allclose(foot, steps, rtol=0, atol=1e-12)
    np.testing.assert_allclose([x0["foot_x"], x0["foot_y"]], pts["F"], rtol=0, atol=1e-15)
    # the path itself: about 68 mm long and 22 mm high, with the flat bottom the numbers were
    # chosen for (derived here: 43 % of the turn within 1 mm of the lowest point, over 57 mm; with
    # the frame pivot above the axle instead, 12 % over 7 mm) and a lifted return
    assert 0.060 < np.ptp(foot[:, 0]) < 0.075 and 0.018 < np.ptp(foot[:, 1]) < 0.026
    flat = foot[:, 1] < foot[:, 1].min() + 1e-3
    assert flat.mean() > 0.4 and np.ptp(foot[flat, 0]) > 0.055


def _numpy_reference(P):
    """The reference configuration (crank at 0) by circle intersections in numpy, derived here:
    Y above the line XZ, D outwards of ZY, W below, E and F outwards (Jansen's assembly)."""

    def meet(A, r1, B, r2, s):
        e = B - A
        dd = e @ e
        a = (r1**2 - r2**2 + dd) / (2 * dd)
        return A + a * e + s * np.sqrt(r1**2 / dd - a**2) * np.array([-e[1], e[0]])

    X, Z = np.array([P["m"], 0.0]), np.array([-P["a"], -P["l"]])
    Y = meet(X, P["j"], Z, P["b"], -1)
    D = meet(Z, P["d"], Y, P["e"], 1)
    W = meet(X, P["k"], Z, P["c"], 1)
    E = meet(D, P["f"], W, P["g"], -1)
    F = meet(W, P["i"], E, P["h"], 1)
    assert Y[1] > 0 > W[1] and D[0] < Z[0] and F[1] < W[1]
    return {"Y": Y, "D": D, "W": W, "E": E, "F": F}


def test_fk_against_ik_and_ad_jacobian(jansen):
    """The IK (Newton on the loops for the crank's coordinate, from home: it stays on the file's
    assembly within about +-50 deg of it, so the check runs there) returns the closed form's pose and
    crank angle; the AD Jacobian of fk_closed equals central differences and the closure's
    J = -Φ_x⁻¹ Φ_q."""
    m, c = jansen, jansen.closure
    q_sym = ca.SX.sym("q", c.nq)
    dx_dq = ca.Function("dx_dq", [q_sym], [ca.jacobian(c.fk_closed(q_sym, m.x_home, m.p)[0], q_sym)], ["q"], ["J"])
    for qi in np.deg2rad(np.arange(-50.0, 51.0, 10.0))[:, None]:
        xi = np.asarray(c.fk_closed(qi, m.x_home, m.p)[0]).ravel()
        ik = cn.inverse_kinematics(m, xi[list(c.task_index)], NEWTON)
        assert ik.status is Status.SOLVED
        np.testing.assert_allclose(ik.q, qi, rtol=0, atol=1e-10)
        np.testing.assert_allclose(ik.x, xi, rtol=0, atol=1e-9)
        jac = np.asarray(dx_dq(qi))
        fd = central_difference(lambda v: np.asarray(c.fk_closed(v, m.x_home, m.p)[0]).ravel(), qi, 1e-6)
        np.testing.assert_allclose(jac, fd, rtol=0, atol=1e-7)
        np.testing.assert_allclose(jac, np.asarray(c.jacobian(xi, qi, m.p)), rtol=0, atol=1e-10)


def test_out_of_reach_and_other_assembly_keep_newtons_status():
    """A crank of 20 mm (the reference at 0 deg still assembles, 53 of the 360 angles do not): where
    a dyad's circles do not meet the closed form settles nothing and the status is Newton's (not a
    number); from a guess in the other assembly of the first dyad (Y mirrored), Newton answers as
    before the closed form."""
    m = cn.build_model("jansen", {"m": "20 mm"})
    c = m.closure
    disc = np.array([float(c.fk_closed(qi, m.x_home, m.p)[1]) for qi in CYCLE])
    far = CYCLE[disc < 0]
    assert len(far) > 0
    got, ref = cn.batch_forward_kinematics(m, far), _newton(m, far, np.tile(m.x_home, (len(far), 1)))
    assert got.statuses == ref.statuses and Status.SOLVED not in got.statuses
    closed = _kernel(closed_fk_kernel(c, NEWTON), m, far, m.x_home)
    assert np.all(closed["status"].ravel() == code_of(Status.NOT_CONVERGED))
    j = cn.build_model("jansen")
    names = list(j.closure.x_names)
    mirror = j.x_home.copy()
    mirror[names.index("J2")] += 2.6  # j_bar swung across the line XZ: Y on the other side
    q = np.ascontiguousarray(CYCLE[::60])
    x0 = np.tile(mirror, (len(q), 1))
    got, ref = cn.batch_forward_kinematics(j, q, guess=x0), _newton(j, q, x0)
    assert got.statuses == ref.statuses
    closed = _kernel(closed_fk_kernel(j.closure, NEWTON), j, q, x0)
    assert not np.any(closed["status"].ravel() == code_of(Status.SOLVED))
