"""Generated branch indicators are mode invariants, and IK reduces angles by whole turns
into their declared ranges (issue 20, items 3 and 5).

* The shipped Delta (problems/mechanisms/delta.yaml): each arm's indicator arm{i}.S2 is its
  working mode (the elbow), w·((c - a) × (B - c)) with the sign of home: checked against an
  independent numpy IK of both elbows of each arm (a cos q + b sin q = K, both roots).
* The shipped five-bar: left.R2, right.R2 are the elbows (the orientation of the triangle
  base joint, elbow, platform point), against the law of cosines in numpy.
* :func:`cpm_nlp.core.kinematics.reduce_angle`, IK of a revolute actuator whose solution is a
  turn away from its range, and passive joint angles reduced into their ranges.
The corpus's single-loop linkages (four-bar, RSSR, crank-slider six-bar) are checked over a
full crank turn in tests/corpus/test_corpus.py.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import yaml

import cpm_nlp as cn
from cpm_nlp.core.kinematics import assess, reduce_angle
from cpm_nlp.core.result import Status
from cpm_nlp.mechanisms.described import from_dict, load_file
from cpm_nlp.problems.shipped import shipped_problems_dir

DEG = math.pi / 180
MECHANISMS = shipped_problems_dir() / "mechanisms"
CORPUS = Path(__file__).resolve().parents[2] / "corpus"


def _model(path, parameters=None):
    mech = load_file(path)
    return mech.model(mech.closure(), parameters or {}, {}, ())


def _branch(model, x, q):
    g = np.asarray(model.closure.branch(np.asarray(x, float), np.asarray(q, float), model.p)).ravel()
    return dict(zip(model.closure.branch_names, g.tolist()))


def _delta_arm_roots(P, i, rb=0.1, rp=0.04, la=0.12, lb=0.25):
    """numpy: both roots q of arm i (frame turned by 2 pi (i - 1)/3 about z; elbow at
    (rb + la cos q, 0, -la sin q), platform joint B = R_z^T P + (rp, 0, 0), |B - elbow| = lb),
    each with the sign of dg/dq (g = |B - elbow|^2: the working mode)."""
    th = 2 * math.pi * (i - 1) / 3
    c, s = math.cos(th), math.sin(th)
    B = np.array([c * P[0] + s * P[1] + rp, -s * P[0] + c * P[1], P[2]])
    u = B[0] - rb
    a, b = -2 * la * u, 2 * la * B[2]
    K = lb**2 - (u * u + B[1] ** 2 + B[2] ** 2 + la**2)
    base, half = math.atan2(b, a), math.acos(K / math.hypot(a, b))
    out = []
    for q in (base + half, base - half):
        elbow = np.array([rb + la * math.cos(q), 0.0, -la * math.sin(q)])
        rate = 2 * (B - elbow) @ np.array([la * math.sin(q), 0.0, la * math.cos(q)])  # -dg/dq
        out.append((math.remainder(q, 2 * math.pi), math.copysign(1.0, rate)))
    return out


def test_delta_indicators_single_out_one_elbow():
    """At random platform points below the base, each arm's two IK roots (numpy) have opposite
    working modes; arm{i}.S2 is positive exactly on the root with the working mode of home
    and negative on the other, whatever the other arms do (the old cosine indicator did not
    tell the elbows apart everywhere)."""
    model = _model(MECHANISMS / "delta.yaml")
    names = model.closure.branch_names
    assert names == ("arm1.S2", "arm2.S2", "arm3.S2", "aspect")
    home_modes = [r[1] for i in (1, 2, 3) for r in _delta_arm_roots(model.x_home, i) if abs(r[0]) < 1e-9]
    assert len(home_modes) == 3
    rng = np.random.default_rng(3)
    checked = 0
    for P in np.array([-0.12, -0.12, -0.33]) + rng.random((40, 3)) * np.array([0.24, 0.24, 0.2]):
        try:
            roots = [_delta_arm_roots(P, i) for i in (1, 2, 3)]
        except ValueError:  # out of reach
            continue
        for flip in range(4):  # flip: 0 = all home elbows, i = arm i on its other elbow
            q = []
            for i in (1, 2, 3):
                mode = home_modes[i - 1] if flip != i else -home_modes[i - 1]
                q.append(next(r[0] for r in roots[i - 1] if r[1] == mode))
            assert np.max(np.abs(cn.residual(model, P, q))) < 1e-12
            g = _branch(model, P, q)
            for i in (1, 2, 3):
                assert (g[f"arm{i}.S2"] > 0) == (flip != i), (P, flip, g)
            checked += 1
    assert checked >= 80


def test_delta_other_elbow_is_wrong_branch_named():
    """The pose of home with arm 2 on its other elbow: `wrong_branch`, the message naming
    the indicator, the leg and the value."""
    model = _model(MECHANISMS / "delta.yaml")
    x = np.asarray(model.x_home, float)
    q = np.asarray(model.q_home, float).copy()
    q[1] = next(r[0] for r in _delta_arm_roots(x, 2) if abs(r[0]) > 1e-6)
    status, message, _ = assess(model, x, q, 1e-9)
    assert status is Status.WRONG_BRANCH
    assert "arm2.S2 = -" in message and "leg arm2, joint 2" in message and "working mode" in message


def test_five_bar_elbows_are_the_triangles_orientation():
    """left.R2 and right.R2 of the shipped five-bar have the sign of the orientation of the
    triangle (base joint, elbow, P) relative to home, on all four working modes of a point
    (numpy law of cosines)."""
    model = _model(MECHANISMS / "five_bar.yaml")
    assert model.closure.branch_names == ("left.R2", "right.R2", "aspect")
    d, l1, l2 = (model.parameters[k] for k in ("d", "l1", "l2"))
    bases = (np.array([-d / 2, 0.0]), np.array([d / 2, 0.0]))

    def orientation(P, q):  # sign of cross(c - A, P - c) per leg
        out = []
        for A, qi in zip(bases, q):
            c = A + l1 * np.array([math.cos(qi), math.sin(qi)])
            e, f = c - A, P - c
            out.append(math.copysign(1.0, float(e[0] * f[1] - e[1] * f[0])))
        return np.array(out)

    home = orientation(np.asarray(model.x_home, float), model.q_home)
    rng = np.random.default_rng(5)
    for P in np.array([-0.06, 0.12]) + rng.random((10, 2)) * np.array([0.12, 0.08]):
        cos = [(l1**2 + (P - A) @ (P - A) - l2**2) / (2 * l1 * np.linalg.norm(P - A)) for A in bases]
        for s1 in (1, -1):
            for s2 in (1, -1):
                q = [math.atan2(*(P - A)[::-1]) + s * math.acos(cs) for A, s, cs in zip(bases, (s1, s2), cos)]
                assert np.max(np.abs(cn.residual(model, P, q))) < 1e-12
                g = _branch(model, P, q)
                want = orientation(P, q) * home
                assert math.copysign(1.0, g["left.R2"]) == want[0] and math.copysign(1.0, g["right.R2"]) == want[1]


def test_reduce_angle():
    """A turn of the angle inside the range (the value itself first, then its value in
    (-180, 180] deg, then its lowest turn there), else its value in (-180, 180] deg."""
    r = lambda v, lim: reduce_angle(v * DEG, [None if lim is None else (lim[0] * DEG, lim[1] * DEG)]) / DEG  # noqa: E731
    assert r(232.797, (-180, 180)) == pytest.approx(-127.203)
    assert r(-300, (-360, 360)) == pytest.approx(-300)
    assert r(-420, (-360, 360)) == pytest.approx(-60)
    assert r(300, (200, 400)) == pytest.approx(300)
    assert r(-90, (0, 360)) == pytest.approx(270)
    assert r(725, (300, 400)) == pytest.approx(365)
    assert r(725, (380, 460)) == pytest.approx(5)  # no turn of it in [380, 460]
    assert r(100, (-10, 10)) == pytest.approx(100)  # no turn inside: reported outside, reduced
    assert r(460, (-10, 10)) == pytest.approx(100)
    assert r(-1935, None) == pytest.approx(-135)


def test_rssr_ik_of_a_reachable_pose_within_one_turn():
    """The corpus RSSR with its input range [-180, 180] deg: IK of phi = 39.09454637 deg was
    `outside_joint_limits: theta = 4.06309 outside [-3.14159, 3.14159]`; the angle a turn
    away, -2.220 rad, is inside and is the answer (FK of it gives phi back)."""
    path = CORPUS / "rssr_linkr.yaml"
    model = _model(path)
    ik = cn.inverse_kinematics(model, [39.09454637 * DEG], method="solve")
    assert ik.status == Status.SOLVED, ik.message
    assert -math.pi <= ik.q[0] <= math.pi
    assert ik.q[0] == pytest.approx(4.06309 - 2 * math.pi, abs=1e-5)
    fk = cn.forward_kinematics(model, ik.q, cn.SolverConfig("newton"))
    assert fk.status == Status.SOLVED and fk.x[0] == pytest.approx(39.09454637 * DEG, abs=1e-9)


def test_passive_angles_reduced_into_their_range():
    """A passive joint angle declared in [0, 360] deg: the coupler angle mu of the corpus
    four-bar, negative as computed (atan2) at these crank angles, is reported a turn up and
    the pose is solved; declared in [0, 90] deg, where no turn of it lies, the pose is
    `outside_joint_limits` with the value reduced to (-180, 180] deg."""
    path = CORPUS / "fourbar_pyslvs.yaml"
    data = yaml.safe_load(path.read_text())
    plain = from_dict(data)
    model = plain.model(plain.closure(), {}, {}, ())
    newton = cn.SolverConfig("newton")
    mus = {deg: cn.forward_kinematics(model, [deg * DEG], newton).passive[0] for deg in range(0, 360, 30)}
    negative = [deg for deg, mu in mus.items() if mu < 0]
    assert negative
    for rng, solved in (([0, 360], True), ([0, 90], False)):
        data["legs"][0]["joints"][1]["range"] = [f"{rng[0]} deg", f"{rng[1]} deg"]
        mech = from_dict({**data, "name": f"fourbar_mu_{rng[1]}"})
        limited = mech.model(mech.closure(), {}, {}, ())
        for deg in negative:
            fk = cn.forward_kinematics(limited, [deg * DEG], newton)
            if solved:
                assert fk.status == Status.SOLVED, fk.message
                assert fk.passive[0] == pytest.approx(mus[deg] + 2 * math.pi, abs=1e-12)
            else:
                assert fk.status == Status.OUTSIDE_JOINT_LIMITS
                assert f"mu = {mus[deg]:.6g}" in fk.message
