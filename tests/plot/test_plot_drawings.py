"""The figures of issue 24 (item 4, part B): mechanism drawings (labels apart, every leg and
actuator seen, readable titles, the pantograph file drawn), mode shapes (one frame, the arrow
scale stated), the pantograph workspace (boundary and colour bar), the maps (round contour
levels; the RPR map's swatch and the bound of its optimum region). Each figure: what it draws
checked against an independent computation where there is one, texts not clipped and apart,
legends that match the drawn artists, and a baseline image in the fixed style
(tests/figure_checks.py)."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from cpm_nlp.mechanisms.registry import build_model
from cpm_nlp.plot import compliance_plots, figures
from cpm_nlp.plot import pose as plot_pose
from cpm_nlp.plot.draw import design_map_figure, mechanism_figure
from cpm_nlp.plot.draw_map import contour_levels, level_format
from cpm_nlp.plot.draw_mechanism import readable_names
from tests.figure_checks import (
    assert_figure_readable,
    assert_labels_apart,
    assert_legend_matches_artists,
    assert_matches_baseline,
)

matplotlib = pytest.importorskip("matplotlib")

#: RMS (0-255) a baseline may differ by: drawn in the fixed style (DejaVu fonts, no hinting,
#: fixed dpi, tests/figure_checks.BASELINE_STYLE) it is 0.0 run to run here; another platform
#: differs in anti-aliased edges and sub-pixel text placement only. The smallest lost layer
#: measured (load 7, this run): the contour labels of map_log_levels 1.86, the point labels of
#: mechanism_prs3 3.95, the optimum outline of map_rpr_transmission 7.17, the arrows of one
#: panel of modes_prs3 19.7: a tolerance under the smallest
TOLERANCE = 1.5
REASON = "fixed fonts without hinting: only anti-aliasing differs; the smallest lost layer moves it by 1.86 (measured)"

#: a pose of the 3-PRS away from home (SI) and its parameters (prs3-ruiz.md, Table 1)
PRS3_POSE = [0.0792, 0.03, -0.02]
PRS3 = {"b": "47.91 mm", "L": "109.215 mm"}


def checked(fig):
    """The checks every fixed figure passes: texts inside the figure and apart, legends that
    name what is drawn."""
    assert_figure_readable(fig)
    assert_labels_apart(fig)
    assert_legend_matches_artists(fig)
    return fig


def _pose(name, parameters, task):
    model = build_model(name, parameters)
    x, q, reach = (np.asarray(v, dtype=float).ravel() for v in model.closure.ik(task, model.p))
    assert reach.min() > 0
    return model, x, q


def _point_labels(fig):
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    FigureCanvasAgg(fig).draw()
    return [
        t.get_text()
        for ax in fig.axes
        for a in ax.get_children()
        if type(a).__name__ == "PointLabels"
        for t in a.get_children()
    ]


def test_the_label_check_fails_on_overlapping_labels():
    """assert_labels_apart catches what issue 24 saw: two point labels a few pixels apart
    ("leg3_1" over "leg3_2"), in 2-D and 3-D axes; labels apart pass."""
    from cpm_nlp.plot.style import figure_class

    fig = figure_class()(figsize=(4, 3))
    ax = fig.add_subplot(1, 2, 1)
    ax.text(0.5, 0.5, "leg3_1")
    ax.text(0.51, 0.51, "leg3_2")
    with pytest.raises(AssertionError, match="'leg3_1' and 'leg3_2' overlap"):
        assert_labels_apart(fig)
    ax.texts[1].set_position((0.5, 0.1))
    assert_labels_apart(fig)
    ax3 = fig.add_subplot(1, 2, 2, projection="3d")
    ax3.text(0, 0, 0, "B3 = C2")
    ax3.text(0, 0, 0.01, "B3")
    with pytest.raises(AssertionError, match="overlap"):
        assert_labels_apart(fig)


# -- mechanism drawings ---------------------------------------------------------------------------------


def prs3_drawing():
    model, x, q = _pose("prs3", PRS3, PRS3_POSE)
    pose, home, k = plot_pose.drawings(model, x, q)
    return mechanism_figure(
        pose, home=home, title=plot_pose.pose_title(model, x, k, plot_pose.span_of(home), "inverse_kinematics")
    )


def test_joint_labels_read_as_letter_and_leg():
    """leg3_2 is the revolute joint of leg 3: R_3; a leg with two joints of one letter numbers them."""
    joints = {"leg3_1": "P", "leg3_2": "R", "leg3_3": "S", "leg1_1": "R", "leg1_2": "R", "leg1_3": "R"}
    names = readable_names([*joints, "P", "A''"], joints)
    assert names["leg3_1"] == "$P_{3}$" and names["leg3_2"] == "$R_{3}$" and names["leg3_3"] == "$S_{3}$"
    assert names["leg1_2"] == "$R_{1,2}$" and names["P"] == "P" and names["A''"] == "A''"
    # legs named by a word and a number each (the 6-UPS: a1 ... b3): by the name, not the number alone
    six = {"a1_1": "U", "b1_1": "U", "a1_3": "S"}
    assert readable_names(list(six), six) == {"a1_1": "$U_{a1}$", "b1_1": "$U_{b1}$", "a1_3": "$S_{a1}$"}


def test_prs3_drawing_labels_apart_legs_seen_actuators_marked(tmp_path):
    """issue 24: labels overlapped ("leg3_1/leg3_2"), leg 2 hid behind the platform, the orange
    actuator of the legend could not be seen, the title named internal names."""
    fig = assert_matches_baseline(prs3_drawing, "mechanism_prs3", tmp_path, tol=TOLERANCE, reason=REASON)
    checked(fig)
    labels = _point_labels(fig)
    # the slider A_i (P) and the revolute C_i (R) lie |q_i| apart (a few pixels): one label each leg
    for i in (1, 2, 3):
        assert f"$P_{{{i}}}$, $R_{{{i}}}$" in labels or f"$P_{{{i}}}$ = $R_{{{i}}}$" in labels, labels
    assert not any("leg" in t for t in labels)
    ax = fig.axes[0]
    assert ax.computed_zorder is False  # the layers in a fixed order: legs over the translucent platform
    legs = [ln for ln in ax.get_lines() if ln.get_label() == "leg" or ln.get_color() == "tab:blue"]
    faces = [c for c in ax.collections if type(c).__name__ == "Poly3DCollection"]
    assert legs and faces and min(ln.get_zorder() for ln in legs) > max(c.get_zorder() for c in faces)
    entries = [t.get_text() for t in fig.legends[0].get_texts()]
    assert "actuated prismatic joint (P)" in entries  # seen: the legend check renders it
    title = fig._suptitle.get_text()
    assert title.startswith("3-PRS compliant stage (Ruiz et al.)\ninverse kinematics: $pz$ = ")
    assert "(inverse_kinematics)" not in title and "prs3" not in title


def test_the_plot_of_a_file_mechanism_is_titled_by_the_mechanism(solved_file):
    data = solved_file("prs3_file_forward_kinematics")
    fig, kind = figures.figure(data)
    title = fig._suptitle.get_text()
    assert kind == "mechanism" and title.startswith("3-PRS compliant stage (Ruiz et al.)\nforward kinematics: ")
    assert "prs3_file" not in title and "(forward_kinematics)" not in title
    checked(fig)


def pantograph_drawing():
    model, x, q = _pose("pantograph", {"a": "20 mm", "b": "50 mm"}, [0.101, 0.004, -0.003])
    pose, home, k = plot_pose.drawings(model, x, q)
    return mechanism_figure(pose, home=home, title=plot_pose.pose_title(model, x, k, plot_pose.span_of(home)))


def test_pantograph_file_drawing(tmp_path):
    """pantograph-3d-elgammal-2016.md section 3 (problems/mechanisms/pantograph.yaml): the sliders
    A' (dy), A'' (dz, where L1 turns) and B' (dx) are the actuated joints, each drawn; the joints
    are marked where they are drawn (not at the ground's A and B); a stroke from home is an
    actuator segment as long as the slider moved (eq 9-10: the closed-form IK, computed here)."""
    model, x, q = _pose("pantograph", {"a": "20 mm", "b": "50 mm"}, [0.101, 0.004, -0.003])
    d = model.mechanism.geometry(model, x, q)
    assert set(d.actuated) == {"A'", "A''", "B'"} and all(d.joints[n] == "P" for n in d.actuated)
    assert "A" not in d.joints and "B" not in d.joints  # the ground's points: no joint there
    a, b = 0.02, 0.05
    qx, qy, qz = x[0] / (1 + b / a), -x[1] * a / b, -x[2] * a / b  # eq 9-10
    strokes = {
        (s, t): np.linalg.norm(np.subtract(d.points[t], d.points[s])) for s, t, part in d.segments if part == "actuator"
    }
    home_x = 2 * a * math.cos(math.pi / 4)
    assert strokes[("B", "B'")] == pytest.approx(abs(qx - home_x), rel=1e-9)
    assert strokes[("A", "A'")] == pytest.approx(abs(qy), rel=1e-9) and strokes[("A'", "A''")] == pytest.approx(
        abs(qz), rel=1e-9
    )
    fig = assert_matches_baseline(
        pantograph_drawing, "mechanism_pantograph_file", tmp_path, tol=TOLERANCE, reason=REASON
    )
    checked(fig)
    labels = _point_labels(fig)
    assert "E = P" in labels and "A, A', A''" in labels  # coincident: one label; 1.6 mm apart on the page: one label
    assert fig._suptitle.get_text().startswith("3D compliant pantograph, decoupled XYZ (Elgammal et al.)\n")


def test_pantograph_file_problem_plots_its_drawing(solved_file):
    data = solved_file("pantograph_file_forward_kinematics")
    fig, kind = figures.figure(data)
    assert kind == "mechanism"
    checked(fig)


def five_bar_drawing():
    import cpm_nlp as cn

    model = build_model("five_bar")
    q = model.q_home + np.array([0.15, -0.1])
    x = cn.forward_kinematics(model, q, cn.SolverConfig("newton")).x
    pose, home, k = plot_pose.drawings(model, x, q)
    return mechanism_figure(pose, home=home, title=plot_pose.pose_title(model, x, k), note=pose.note)


def test_planar_file_drawing(tmp_path):
    fig = assert_matches_baseline(five_bar_drawing, "mechanism_five_bar_file", tmp_path, tol=TOLERANCE, reason=REASON)
    checked(fig)


def test_a_drawing_at_home_draws_no_hidden_home_pose():
    model, x, q = _pose("prs3", PRS3, [0.0792, 0.0, 0.0])
    pose, home, _ = plot_pose.drawings(model, model.x_home, model.q_home)
    fig = mechanism_figure(pose, home=home)
    assert "home pose" not in [t.get_text() for t in fig.legends[0].get_texts()]
    checked(fig)


# -- modes ------------------------------------------------------------------------------------------------


def modes_figure(solved_file):
    return figures.figure(solved_file("prs3_natural_frequencies"))[0]


def test_modes_share_their_ranges_and_state_the_arrow_scale(solved_file, tmp_path):
    """issue 24: the axis ranges differed from panel to panel, and the arrow scale was not stated."""
    data = solved_file("prs3_natural_frequencies")
    fig = assert_matches_baseline(
        lambda: modes_figure(solved_file), "modes_prs3", tmp_path, tol=TOLERANCE, reason=REASON
    )
    checked(fig)
    limits = {(ax.get_xlim(), ax.get_ylim(), ax.get_zlim()) for ax in fig.axes}
    assert len(fig.axes) == 3 and len(limits) == 1
    # the scale: each mode's largest point displacement drawn MODE_ARROW of the drawing's size
    model, geometry, x, q = compliance_plots.drawn_pose(data)
    span = plot_pose.span_of(geometry(model, x, q))
    for mx, mq in zip(data.values["modes_x"], data.values["modes_q"]):
        arrows = compliance_plots.mode_arrows(model, geometry, x, q, mx, mq)
        longest = max(np.linalg.norm(a.vector) for a in arrows)
        assert longest == pytest.approx(compliance_plots.MODE_ARROW * span, rel=1e-9)
    entry = next(t.get_text() for t in fig.legends[0].get_texts() if t.get_text().startswith("point displacement"))
    assert (
        f"the largest drawn {compliance_plots.MODE_ARROW * span * 1e3:.3g} mm long (25% of the mechanism's size"
        in entry
    )
    assert fig._suptitle.get_text().startswith("Mode shapes: 3-PRS compliant stage (Ruiz et al.)")


# -- maps -----------------------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("lo", "hi", "log", "levels"),
    [
        (40.3, 1040.0, True, [50, 100, 200, 500, 1000]),  # issue 24: 40.3, 119, 351, 1.04e+03
        (15.0, 6.2e4, True, [100, 1000, 10000]),  # 1-2-5 would be 11 levels: the decades
        (1e-9, 1e-3, True, [1e-8, 1e-7, 1e-6, 1e-5, 1e-4]),
        (0.012, 0.999, False, [0.2, 0.4, 0.6, 0.8]),
        (-3.0, 5.0, False, [-2, -1, 0, 1, 2, 3, 4]),
    ],
)
def test_contour_levels_are_round(lo, hi, log, levels):
    assert contour_levels(lo, hi, log=log) == pytest.approx(levels, rel=1e-12, abs=1e-15)


def test_contour_levels_are_written_as_read():
    assert [level_format([50, 100, 2000, 1e5])(v) for v in (50, 100, 2000, 1e5)] == ["50", "100", "2000", "100000"]
    assert [level_format([2.302, 2.304])(v) for v in (2.302, 2.304)] == ["2.302", "2.304"]  # apart, not "2.3", "2.3"
    assert level_format([1e-5, 1e-4])(1e-5) == "1e-05"


def log_map():
    """A value over four decades on a grid (a cuboid volume in mm³ over two parameters)."""
    s, t = np.meshgrid(np.linspace(0, 1, 21), np.linspace(0, 1, 17))
    volume = 1e-9 * 30 * 10 ** (3.2 * s * (1 - 0.4 * t))
    return design_map_figure(
        s.ravel(), t.ravel(), volume.ravel(), names=("a", "b", "volume"), dimensions=(None, None, "volume")
    )


def test_a_map_over_decades_has_round_levels(tmp_path):
    fig = assert_matches_baseline(log_map, "map_log_levels", tmp_path, tol=TOLERANCE, reason=REASON)
    checked(fig)
    ax = fig.axes[0]
    texts = [t.get_text() for t in ax.texts]
    assert texts and set(texts) <= {"50", "100", "200", "500", "1000", "2000", "5000", "10000", "20000", "50000"}


@pytest.mark.parametrize(("name", "which"), [("map_best_max", 0), ("map_volume_unit", 1)])
def test_synthetic_maps(name, which, tmp_path):
    """The maps of tests/plot/test_plot_figures.synthetic_map (the max marked as it is; mm³),
    now with round levels."""
    from tests.plot.test_plot_figures import synthetic_map

    fig = assert_matches_baseline(lambda: synthetic_map()[which], name, tmp_path, tol=TOLERANCE, reason=REASON)
    checked(fig)
    levels = np.unique([float(t.get_text()) for t in fig.axes[0].texts if t.get_text().replace(".", "").isdigit()])
    step = float(np.diff(levels).min())  # linear levels: multiples of a 1-2-2.5-5 step
    assert len(levels) >= 3 and round(step / 10 ** math.floor(math.log10(step)), 9) in (1, 2, 2.5, 5)
    assert np.allclose(levels / step, np.round(levels / step), atol=1e-9)


def test_rpr_map_swatch_and_region_bound(solved_file, tmp_path):
    """issue 24: a grey legend swatch stood for a white region, and the optimum region's bound was
    not stated. The bound comes from the result (eta_region, the kind's input), not the plot."""
    data = solved_file("rpr_transmission_map")
    fig = assert_matches_baseline(
        lambda: figures.figure(data)[0], "map_rpr_transmission", tmp_path, tol=TOLERANCE, reason=REASON
    )
    checked(fig)  # the swatch's colour is the cells' (assert_legend_matches_artists)
    entries = [t.get_text() for t in fig.legends[0].get_texts()]
    assert "optimum region: $\\eta$ ≥ 0.99" in entries
    outside = [c for c in fig.axes[0].collections if c.get_label().startswith("outside the design space")]
    n_out = sum(v is None for row in data.values["eta"] for v in row)
    assert len(outside) == 1 and outside[0].get_label() == f"outside the design space ({n_out} grid points)"
    # the cells and the region: eta >= eta_region exactly where in_region (an independent count)
    eta = np.array([[np.nan if v is None else v for v in row] for row in data.values["eta"]])
    region = np.array([[bool(v) for v in row] for row in data.values["in_region"]])
    assert np.array_equal(region, eta >= data.values["eta_region"])


def test_rpr_map_states_the_bound_it_was_solved_with(cli, tmp_path):
    from tests.conftest import PROBLEMS

    out = tmp_path / "r.json"
    run = cli(
        "solve", str(PROBLEMS / "rpr_transmission_map.yaml"), "-q", "--set", "inputs.eta_region=0.95", "-o", str(out)
    )
    assert run.code == 0, run.err
    fig, _ = figures.figure(figures.load(out))
    assert "optimum region: $\\eta$ ≥ 0.95" in [t.get_text() for t in fig.legends[0].get_texts()]


# -- the pantograph workspace ---------------------------------------------------------------------------------


def _workspace_json(cli, tmp_path):
    from tests.conftest import PROBLEMS

    out = tmp_path / "w.json"
    run = cli("solve", str(PROBLEMS / "pantograph_workspace.yaml"), "-q", "-o", str(out))
    assert run.code == 0, run.err
    return out


def test_pantograph_workspace_from_its_result_file(cli, tmp_path):
    """issue 24: plotted from its result file, a bare scatter with no boundary and no colour bar."""
    path = _workspace_json(cli, tmp_path)
    fig = assert_matches_baseline(
        lambda: figures.figure(figures.load(path))[0], "workspace_pantograph", tmp_path, tol=TOLERANCE, reason=REASON
    )
    checked(fig)
    (bar,) = fig.axes[0].child_axes  # the colour bar of the 3-D view
    assert bar.get_ylabel() == "colour: $pz$ (mm)"
    cloud = next(c for c in fig.axes[0].collections if c.get_label().startswith("reachable points"))
    pz = np.asarray(json.loads(path.read_text())["values"]["cloud_pz"], dtype=float) * 1e3
    assert np.asarray(cloud.get_array(), dtype=float).tolist() == pytest.approx(pz.tolist())  # the colour: pz
    entries = [t.get_text() for t in fig.legends[0].get_texts()]
    assert any(e.startswith("workspace boundary") and "(of the model rebuilt from the result)" in e for e in entries)
    # on the axis py = pz = 0 the boundary is where psi reaches its limits (eq 9-10, 17, derived
    # here): q = px a / (a + b) = 2 a cos(h), psi = pi - 2 h, so px = 2 (a + b) cos((pi - psi) / 2):
    # psi_max = 135 deg gives the outer 129.35 mm, psi_min = 45 deg the inner 53.58 mm
    slice_xy = next(ax for ax in fig.axes if ax.get_title().startswith("section at $pz$"))
    pts = np.vstack([ln.get_xydata() for ln in slice_xy.get_lines() if len(ln.get_xdata()) > 10])
    on_axis = pts[np.abs(pts[:, 1]) < 0.5, 0]
    a, b = 20.0, 50.0
    outer, inner = (2 * (a + b) * math.cos((math.pi - math.radians(p)) / 2) for p in (135.0, 45.0))
    assert on_axis.max() == pytest.approx(outer, abs=0.05) and on_axis.min() == pytest.approx(inner, abs=0.05)


def test_a_result_whose_cloud_the_rebuilt_model_does_not_hold_gets_no_boundary(cli, tmp_path):
    path = _workspace_json(cli, tmp_path)
    result = json.loads(path.read_text())
    result["values"]["cloud_px"][0] = 0.5  # half a metre: outside any pantograph of a = 20, b = 50 mm
    path.write_text(json.dumps(result))
    fig, _ = figures.figure(figures.load(path))
    assert not any(t.get_text().startswith("workspace boundary") for t in fig.legends[0].get_texts())


# -- every shipped mechanism's drawing ------------------------------------------------------------------------

FK_FILES = (
    "delta_forward_kinematics",
    "five_bar_forward_kinematics",
    "pantograph_forward_kinematics",
    "prc3_forward_kinematics",
    "prs3_as_built_forward_kinematics",
    "rpr_file_forward_kinematics",
    "rps3_forward_kinematics",
    "rrr3_forward_kinematics",
    "ups6_forward_kinematics",
)


@pytest.mark.parametrize("name", FK_FILES)
def test_every_shipped_mechanism_drawing_is_readable(solved_file, name):
    """Labels apart, legends naming what shows (an actuator, each joint type, the home pose),
    titled by the mechanism's own title."""
    data = solved_file(name)
    fig, kind = figures.figure(data)
    assert kind == "mechanism"
    checked(fig)
    title = fig._suptitle.get_text()
    assert title.split("\n")[1].startswith("forward kinematics: ") and "_" not in title.split("\n")[0]
