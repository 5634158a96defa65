"""Planar mechanisms are first-class (issue 20, item 4): every kind and every plot on the
five-bar (problems/mechanisms/five_bar.yaml: x, y) and the 3-RRR (rrr3.yaml: x, y, phi).

* sizes follow the dimension: an area for x, y, an area times an angle for x, y, phi,
  printed with its unit and prefix;
* the figures are 2-D where the mechanism is: the drawing in its plane, the workspace of
  x, y in its plane with its boundary (checked against the five-bar's geometry, numpy);
* a 3-RRR with six real assembly modes (geometry constructed here), all six found without
  bounds, checked against an independent numpy elimination.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import cpm_nlp as cn
from cpm_nlp.cli.render import render_result
from cpm_nlp.core.units import format_quantity, size_dimension
from cpm_nlp.plot import figures
from cpm_nlp.plot import pose as plot_pose
from cpm_nlp.plot.draw import save
from cpm_nlp.problems.registry import problem_kind
from tests.conftest import PROBLEMS
from tests.figure_checks import assert_figure_readable, assert_png_drawn

pytest.importorskip("matplotlib")

#: every planar problem file and the plot its result makes (None: the kind has no plot)
FILES = {
    "five_bar_forward_kinematics": "mechanism",
    "five_bar_inverse_kinematics": "mechanism",
    "five_bar_jacobian": "jacobian",
    "five_bar_joint_requirements": "requirements",
    "five_bar_actuator_workspace": "workspace",
    "five_bar_workspace": "workspace",
    "five_bar_inscribed_cuboid": "workspace",
    "five_bar_synthesis": "design",
    "five_bar_platform_compliance": "ellipsoid",
    "rrr3_forward_kinematics": "mechanism",
    "rrr3_inverse_kinematics": "mechanism",
    "rrr3_jacobian": "jacobian",
    "rrr3_joint_requirements": "requirements",
    "rrr3_actuator_workspace": "workspace",
    "rrr3_workspace": "workspace",
    "rrr3_inscribed_cuboid": "workspace",
    "rrr3_synthesis": "design",
    "rrr3_platform_compliance": "ellipsoid",
    "rrr3_assembly_modes": None,
}


@pytest.fixture(scope="module")
def solved():
    """Each planar problem solved once: (problem, result)."""
    out = {}
    for name in FILES:
        problem = cn.load_problem(PROBLEMS / f"{name}.yaml")
        out[name] = (problem, cn.solve(problem))
    return out


def _figure(problem, result):
    data = figures.from_result(result)
    data.live = problem.model
    return figures.figure(data)


def test_the_mechanism_files_list_every_planar_problem_as_an_example():
    for mech in ("five_bar", "rrr3"):
        text = (PROBLEMS / "mechanisms" / f"{mech}.yaml").read_text()
        for name in FILES:
            if name.startswith(mech + "_"):
                assert f"../{name}.yaml" in text, (mech, name)


@pytest.mark.parametrize("name", sorted(FILES))
def test_every_kind_solves_on_the_planar_mechanisms(solved, name):
    _problem, result = solved[name]
    assert result.status == cn.Status.SOLVED, (name, result.message)


@pytest.mark.parametrize("mech", ["five_bar", "rrr3"])
def test_a_kind_that_does_not_apply_says_why(mech):
    model = cn.load_problem(PROBLEMS / f"{mech}_forward_kinematics.yaml").model
    assert problem_kind("dynamics").supports(model) == "it has no dynamic model (no energies)"
    for kind in ("workspace", "inscribed_cuboid", "actuator_workspace", "jacobian", "synthesis"):
        assert problem_kind(kind).supports(model) is None


# -- sizes follow the dimension ------------------------------------------------------------------


def test_size_dimension_counts_the_translational_coordinates():
    assert size_dimension(["length"]) == ("length", "m")
    assert size_dimension(["length", "length"]) == ("area", "m^2")
    assert size_dimension(["length"] * 3) == ("volume", "m^3")
    assert size_dimension(["length", "length", "angle"]) == ("area_angle", "m^2*rad")
    assert size_dimension(["angle", "angle"])[0] == "task volume"


def test_sizes_are_printed_with_their_unit_and_prefix():
    assert format_quantity(2.68133e-7, "area") == "0.268133 mm^2"  # issue 20: the five-bar's 0.268 mm^2
    assert format_quantity(2.7e-14, "volume") == "27000 µm^3"  # a 30 µm cube: µm, not 2.7e-05 mm^3
    assert format_quantity(1.78e-6, "volume") == "1780 mm^3"
    assert format_quantity(5.0, "volume") == "5 m^3"
    assert format_quantity(math.radians(1.0) * 1e-6, "area_angle") == "1 mm^2*deg"


def test_the_five_bar_rectangle_is_an_area(solved):
    _p, r = solved["five_bar_inscribed_cuboid"]
    v = r.values
    assert r.dimensions["volume"] == "area" and r.units["volume"] == "m^2"
    assert v["volume"] == pytest.approx((v["x_max"] - v["x_min"]) * (v["y_max"] - v["y_min"]), rel=1e-9)
    line = next(s for s in render_result(r).splitlines() if s.startswith("volume "))
    assert "m^2" in line and "mm^2" in line and "m^3" not in line


def test_the_3rrr_box_is_an_area_times_an_angle(solved):
    for name in ("rrr3_inscribed_cuboid", "rrr3_synthesis", "rrr3_actuator_workspace"):
        _p, r = solved[name]
        assert r.dimensions["volume"] == "area_angle" and r.units["volume"] == "m^2*rad", name
        line = next(s for s in render_result(r).splitlines() if s.startswith("volume "))
        assert "mm^2*deg" in line, line
    _p, r = solved["rrr3_workspace"]
    assert r.dimensions["volume_estimate"] == "area_angle"


def _five_bar_fk(q1, q2, d=0.1, l1=0.1, l2=0.15):
    """The five-bar's end effector, elbows out (numpy: the two circles about the elbows)."""
    e1 = np.array([-d / 2 + l1 * math.cos(q1), l1 * math.sin(q1)])
    e2 = np.array([d / 2 + l1 * math.cos(q2), l1 * math.sin(q2)])
    half = np.linalg.norm(e2 - e1) / 2
    u = (e2 - e1) / (2 * half)
    return (e1 + e2) / 2 + math.sqrt(l2**2 - half**2) * np.array([-u[1], u[0]])


def test_the_five_bar_actuator_workspace_area_against_numpy(solved):
    """The area (Gauss-Legendre of |det dt/dq|, 4 x 4 points) against the shoelace area
    of the image of the stroke square's edges (numpy FK, 2001 points an edge): 5e-8 apart."""
    _p, r = solved["five_bar_actuator_workspace"]
    assert r.dimensions["volume"] == "area" and r.units["volume"] == "m^2"
    line = next(s for s in render_result(r).splitlines() if s.startswith("volume "))
    assert "mm^2" in line
    lo, hi = np.radians([100.0, 40.0]), np.radians([140.0, 80.0])  # the file's strokes
    s = np.linspace(0.0, 1.0, 2001)
    walk = np.vstack(
        [
            np.c_[np.full_like(s, lo[0]), lo[1] + s * (hi[1] - lo[1])],
            np.c_[lo[0] + s * (hi[0] - lo[0]), np.full_like(s, hi[1])],
            np.c_[np.full_like(s, hi[0]), hi[1] - s * (hi[1] - lo[1])],
            np.c_[hi[0] - s * (hi[0] - lo[0]), np.full_like(s, lo[1])],
        ]
    )
    P = np.array([_five_bar_fk(*w) for w in walk])
    area = 0.5 * abs(np.dot(P[:, 0], np.roll(P[:, 1], 1)) - np.dot(P[:, 1], np.roll(P[:, 0], 1)))
    assert r.values["volume"] == pytest.approx(area, rel=1e-6)


# -- figures ------------------------------------------------------------------------------------


def _three_d(fig):
    return [ax for ax in fig.axes if hasattr(ax, "zaxis")]


@pytest.mark.parametrize("name", sorted(n for n, plot in FILES.items() if plot))
def test_every_plot_of_the_planar_problems_is_drawn(solved, name, tmp_path):
    problem, result = solved[name]
    fig, kind = _figure(problem, result)
    assert kind == FILES[name]
    assert_figure_readable(fig)
    out = tmp_path / f"{name}.png"
    save(fig, out)
    assert_png_drawn(out, min_ink=0.02)  # line panels (requirements) hold less ink than a cloud
    three_d = _three_d(fig)
    if name.startswith("rrr3") and kind == "workspace":  # (x, y, phi): one 3-D view and three planes
        assert len(three_d) == 1 and len(fig.axes) == 4
        assert three_d[0].get_zlabel() == r"$\phi$ (deg)", three_d[0].get_zlabel()  # not "z (mm)"
    else:  # the drawing in its plane, the five-bar's workspace in its plane
        assert not three_d, f"{name}: a planar figure drawn in 3-D"


def test_the_3rrr_workspace_draws_the_constant_orientation_boundary(solved):
    problem, result = solved["rrr3_workspace"]
    fig, _ = _figure(problem, result)
    xy = fig.axes[1]
    assert "phi" in xy.get_title() and "= 0 deg" in xy.get_title()  # the plane phi = 0 through home
    assert any(len(line.get_xdata()) > 20 for line in xy.get_lines())


def _boundary_lines(fig):
    ax = fig.axes[0]
    return [np.c_[line.get_xdata(), line.get_ydata()] for line in ax.get_lines() if line.get_color() == "k"]


def test_the_five_bar_boundary_lies_on_the_reach_circles(solved):
    """The upper outer boundary of the five-bar's workspace is where the farther leg is
    stretched: max_i |P - A_i| = l1 + l2 = 250 mm (numpy, from the geometry).  The
    drawn boundary (vertices bisected onto it) lies there to 1 µm.  (Below the base,
    y < 0, the elbows-out branch ends before the legs stretch.)"""
    problem, result = solved["five_bar_workspace"]
    fig, _ = _figure(problem, result)
    lines = _boundary_lines(fig)
    assert lines
    P = np.vstack(lines) * 1e-3  # drawn in mm
    A = np.array([[-0.05, 0.0], [0.05, 0.0]])
    far = np.max(np.linalg.norm(P[:, None, :] - A[None], axis=2), axis=1)
    outer = (np.linalg.norm(P, axis=1) > 0.2) & (P[:, 1] > 0.1)
    assert outer.sum() > 50
    assert np.max(np.abs(far[outer] - 0.25)) < 1e-6


def test_the_five_bar_rectangle_sits_inside_its_drawn_boundary(solved):
    problem, result = solved["five_bar_inscribed_cuboid"]
    fig, _ = _figure(problem, result)
    ax = fig.axes[0]
    assert ax.get_aspect() == 1.0  # equal scales: x and y are both lengths
    assert "mm" in ax.get_xlabel() and "mm" in ax.get_ylabel()
    labels = [t.get_text() for t in fig.legends[0].get_texts()]
    v = result.values
    w, h = (v["x_max"] - v["x_min"]) * 1e3, (v["y_max"] - v["y_min"]) * 1e3
    assert any(t.startswith(f"maximal inscribed rectangle ({w:.0f} × {h:.0f} mm)") for t in labels), labels
    assert "workspace boundary" in labels
    assert "not a hull" in fig.legends[0].get_title().get_text().replace("\n", " ")


def test_the_pose_title_has_no_rounding_noise():
    model = cn.load_problem(PROBLEMS / "five_bar_forward_kinematics.yaml").model
    x = np.array(model.x_home, dtype=float)
    x[0] = -7.939e-15  # what Newton leaves of x = 0
    pose, home, k = plot_pose.drawings(model, x, model.q_home)
    assert k == 1.0  # at home: nothing to exaggerate
    title = plot_pose.pose_title(model, x, k, plot_pose.span_of(home))
    assert title.startswith("planar five-bar linkage (2-RRR), elbows out\npose: $x$ = 0 mm, $y$ = 198.4 mm"), title
    pose_line = title.split("\n")[1]  # the mechanism's title over it ("five-bar" has its own "e-")
    assert "e-" not in pose_line and "nm" not in pose_line


# -- six real assembly modes ----------------------------------------------------------------------

#: the constructed 3-RRR (problems/rrr3_assembly_modes.yaml): rb, rp, l1, l2 (m), cranks (deg)
RRR3_SIX = (0.2, 0.115, 0.135, 0.16, (115.0, 25.0, 95.0))


def _rrr3_modes_numpy(rb, rp, l1, l2, q, n=200_001):
    """Every real FK solution (x, y, phi) of the 3-RRR, independently of cpm_nlp: with the
    cranks given the elbows B_i are fixed, and |P + R(phi) p_i - B_i| = l2 for i = 1..3.
    The differences of these equations are linear in P: P(phi) by Cramer's rule, and
    equation 1 times det^2 is a scalar f(phi); its sign changes on a fine grid, bisected."""
    from scipy.optimize import brentq

    al = 2 * np.pi * np.arange(3) / 3
    B = rb * np.c_[np.cos(al), np.sin(al)] + l1 * np.c_[np.cos(q), np.sin(q)]

    def parts(phi):
        d = rp * np.c_[np.cos(phi + al), np.sin(phi + al)] - B  # C_i - B_i = P + d_i
        M = 2 * np.array([d[1] - d[0], d[2] - d[0]])
        r = -np.array([d[1] @ d[1] - d[0] @ d[0], d[2] @ d[2] - d[0] @ d[0]])
        return M, r, d

    def f(phi):
        M, r, d = parts(phi)
        det = M[0, 0] * M[1, 1] - M[0, 1] * M[1, 0]
        Pd = np.array([M[1, 1] * r[0] - M[0, 1] * r[1], M[0, 0] * r[1] - M[1, 0] * r[0]])  # P * det
        return Pd @ Pd + 2 * det * (Pd @ d[0]) + det**2 * (d[0] @ d[0] - l2**2)

    grid = np.linspace(-np.pi, np.pi, n)
    fv = np.array([f(p) for p in grid])
    out = []
    for k in np.flatnonzero(np.sign(fv[:-1]) != np.sign(fv[1:])):
        phi = brentq(f, grid[k], grid[k + 1], xtol=1e-15)
        M, r, d = parts(phi)
        P = np.linalg.solve(M, r)
        assert max(abs(np.linalg.norm(P + d[i]) - l2) for i in range(3)) < 1e-12
        out.append((P[0], P[1], phi))
    return np.array(out)


def test_the_constructed_3rrr_has_six_real_modes_and_the_search_finds_all(solved):
    rb, rp, l1, l2, qdeg = RRR3_SIX
    ref = _rrr3_modes_numpy(rb, rp, l1, l2, np.radians(qdeg))
    assert len(ref) == 6  # the most a 3-RRR has
    _p, r = solved["rrr3_assembly_modes"]
    v = r.values
    assert v["modes"] == 6 and r.status == cn.Status.SOLVED
    assert "x in [" in v["mode_search"] and "full turn" in v["mode_search"]  # no bounds were given
    found = np.c_[v["modes_x"], v["modes_y"], v["modes_phi"]]
    for pose in ref:
        dphi = np.angle(np.exp(1j * (found[:, 2] - pose[2])))
        dist = np.hypot(found[:, 0] - pose[0], found[:, 1] - pose[1]) + 0.1 * np.abs(dphi)
        assert dist.min() < 1e-9, (pose, found)
    assert max(v["modes_residual"]) < 1e-10


def test_the_six_modes_are_found_from_several_seeds():
    """Not one lucky seed: the default search (2000 starts) finds 6 of 6 for seeds 0..4."""
    from cpm_nlp.analysis.assembly import assembly_modes

    rb, rp, l1, l2, qdeg = RRR3_SIX
    problem = cn.load_problem(PROBLEMS / "rrr3_assembly_modes.yaml")
    for seed in range(5):
        assert assembly_modes(problem.model, np.radians(qdeg), seed=seed).count == 6, seed
