"""The drawing of every shipped mechanism file (the generated ``geometry`` capability):
it exists at home, its platform points are where the closure puts them, and the legs'
rigid links keep their lengths at another solved pose (the drawing follows the kinematics)."""

from __future__ import annotations

import numpy as np
import pytest

import cpm_nlp as cn
from cpm_nlp.core.result import Status
from cpm_nlp.mechanisms import described
from cpm_nlp.mechanisms.described.drawing import fixed_links

NEWTON = cn.SolverConfig("newton")
#: parameters of the files that declare no defaults
PARAMS = {
    "prs3": {"b": "47.91 mm", "L": "109.215 mm", "alpha0": "45 deg"},
    "prc3": {"L1": "9.5 mm", "L2": "25 mm", "L3": "9 mm", "L4": "30 mm", "L7": "73.5 mm"},
    "rpr": {"r1": "40 mm", "r2": "80 mm", "P0": "40 mm"},
    "pantograph": {"a": "20 mm", "b": "50 mm"},
}
FILES = {described.read_description(f).name: f for f in described.shipped_files()}


def _model(name):
    return cn.build_model(name, PARAMS.get(name, {}))


@pytest.mark.parametrize("name", sorted(FILES))
def test_drawing_at_home_and_at_another_pose(name):
    model = _model(name)
    mech = model.mechanism
    d = described.read_description(FILES[name])
    if not d.legs and not d.is_graph:
        assert mech.geometry is None  # closures written as expressions: no legs to draw
        return
    home = mech.geometry(model, model.x_home, model.q_home)
    assert home.joints and home.segments
    assert (
        any(part == "platform" for part, _ in home.faces)
        or any(s[2] == "platform" for s in home.segments)
        or (
            model.closure.nq <= 2  # a planar end effector: the legs meet at one point
        )
    )
    span = float(np.ptp(np.array(list(home.points.values())), axis=0).max())
    q = model.q_home + np.where([c.kind == "angle" for c in model.closure.q], 0.02, 0.02 * span) * np.linspace(
        1.0, -0.5, model.closure.nq
    )
    sol = cn.forward_kinematics(model, q, NEWTON)
    assert sol.status == Status.SOLVED, sol.message
    pose = mech.geometry(model, sol.x, q)
    moved = max(np.linalg.norm(np.asarray(pose.points[k]) - np.asarray(home.points[k])) for k in home.points)
    assert moved > 1e-6 * span
    for drawing in (home, pose):
        for a, b, _part in drawing.segments:
            assert np.all(np.isfinite(drawing.points[a])) and np.all(np.isfinite(drawing.points[b]))
    if d.is_graph:  # each body is drawn as a segment or a face through its points: rigid
        edges = [(a, b) for a, b, _part in home.segments]
        edges += [(r[k], r[(k + 1) % len(r)]) for _part, r in home.faces for k in range(len(r))]
        assert edges
        for a, b in edges:
            dh = np.linalg.norm(np.asarray(home.points[a]) - np.asarray(home.points[b]))
            dp = np.linalg.norm(np.asarray(pose.points[a]) - np.asarray(pose.points[b]))
            assert dp == pytest.approx(dh, abs=1e-9 * span), (a, b)
        return
    layout = _layout(model)
    # the platform is one rigid body: its joint points and its centre P keep their distances
    platform = [f"{leg}_{len(joints)}" for leg, joints in layout] + ["P"]
    for i, a in enumerate(platform):
        for b in platform[i + 1 :]:
            dh = np.linalg.norm(np.asarray(home.points[a]) - np.asarray(home.points[b]))
            dp = np.linalg.norm(np.asarray(pose.points[a]) - np.asarray(pose.points[b]))
            assert dp == pytest.approx(dh, abs=1e-9 * span), (a, b)
    links = fixed_links(layout)
    assert links or name in ("prc3",)
    for a, b in links:
        lh = np.linalg.norm(np.asarray(home.points[a]) - np.asarray(home.points[b]))
        lp = np.linalg.norm(np.asarray(pose.points[a]) - np.asarray(pose.points[b]))
        assert lp == pytest.approx(lh, abs=1e-9 * span), (a, b)


def _layout(model):
    from cpm_nlp.mechanisms.described.closure import closure_parts

    _gen, fns = closure_parts(described.read_description(FILES[model.name]))
    return fns["drawing_legs"]


def test_prs3_file_platform_points_equal_the_reference_drawing():
    """The drawing of prs3 (the file) against the hand-written reference's A_i, C_i, B_i, P."""
    from tests.reference import prs3_closures

    params = PARAMS["prs3"]
    fm, hm = cn.build_model("prs3", params), prs3_closures.reference_model(params)
    rng = np.random.default_rng(3)
    for q in (hm.q_home, hm.q_home + rng.uniform(-2e-3, 2e-3, 3)):
        x = cn.forward_kinematics(hm, q, NEWTON).x
        df, dh = fm.mechanism.geometry(fm, x, q), hm.mechanism.geometry(hm, x, q)
        for i in (1, 2, 3):
            np.testing.assert_allclose(df.points[f"leg{i}_3"], dh.points[f"B{i}"], rtol=0, atol=1e-9)
            np.testing.assert_allclose(df.points[f"leg{i}_2"], dh.points[f"C{i}"], rtol=0, atol=1e-9)
            np.testing.assert_allclose(df.points[f"leg{i}_1"], dh.points[f"A{i}"], rtol=0, atol=1e-9)
        np.testing.assert_allclose(df.points["P"], dh.points["P"], rtol=0, atol=1e-9)
        assert [f for f, _ in df.faces] == ["base", "platform"]


def test_five_bar_points_follow_the_links():
    model = _model("five_bar")
    d, l1, l2 = (model.parameters[k] for k in ("d", "l1", "l2"))
    q = model.q_home + np.array([0.05, -0.03])
    x = cn.forward_kinematics(model, q, NEWTON).x
    dr = model.mechanism.geometry(model, x, q)
    np.testing.assert_allclose(dr.points["left_1"], [-d / 2, 0, 0], atol=1e-12)
    np.testing.assert_allclose(dr.points["left_2"], [-d / 2 + l1 * np.cos(q[0]), l1 * np.sin(q[0]), 0], atol=1e-12)
    np.testing.assert_allclose(dr.points["left_3"], [x[0], x[1], 0], atol=1e-10)
    assert np.linalg.norm(dr.points["left_3"] - dr.points["left_2"]) == pytest.approx(l2, abs=1e-10)
    assert dr.joints["left_1"] == "R" and ("left_1", "left_2", "actuator") in dr.segments
