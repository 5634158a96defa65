"""The figures of issue 14: a plot for every problem kind, the mechanism drawn
from its kinematics, regressions caught by committed baseline images, text
that is not clipped, legends without placeholders, and interactive .html
figures rendered in a real headless browser."""

from __future__ import annotations

import math
import os
import shutil
import subprocess
from dataclasses import replace

import numpy as np
import pytest

from cpm_nlp.mechanisms.registry import build_model, mechanism_names, mechanism_type
from cpm_nlp.plot import compliance_plots, figures
from cpm_nlp.plot import pose as plot_pose
from cpm_nlp.plot.draw import (
    BoundarySlice,
    Comparison,
    Panel,
    comparison_figure,
    design_map_figure,
    panels_figure,
    save,
    unit_text,
    value_text,
    workspace_figure,
)
from cpm_nlp.plot.registry import plot_type_names
from cpm_nlp.plot.style import number as draw_number
from cpm_nlp.problems.registry import kind_names, problem_kind
from tests.figure_checks import assert_figure_readable

matplotlib = pytest.importorskip("matplotlib")


#: a pose of each mechanism away from home, by its task coordinates (SI)
POSES = {
    "prs3": [0.0792, 0.03, -0.02],
    "pantograph": [0.101, 0.004, -0.003],
    "prc3": [-8e-5, -4e-5, -1e-4],
    "rpr": [0.05, -0.04, 0.042],
}
PARAMETERS = {
    "prs3": {"b": "47.91 mm", "L": "109.215 mm"},
    "pantograph": {"a": "20 mm", "b": "50 mm"},
    "prc3": {"L1": "9.5 mm", "L2": "25 mm", "L3": "9 mm", "L4": "30 mm", "L7": "73.5 mm"},
    "rpr": {"r1": "40 mm", "r2": "80 mm", "P0": "40 mm"},
}


def pose_of(name):
    """(model, x, q) at the pose of POSES, by the closed-form IK of the model."""
    model = build_model(name, PARAMETERS[name])
    x, q, reach = (np.asarray(v, dtype=float).ravel() for v in model.closure.ik(POSES[name], model.p))
    assert reach.min() > 0
    return model, x, q


# -- every kind has a plot ----------------------------------------------------------------------------


def test_every_problem_kind_has_a_plot():
    """Issue 14: 19 of 31 kinds had no plot.  Every kind lists plot types, all of them known."""
    for name in kind_names():
        plots = problem_kind(name).plots
        assert plots, f"problem kind {name} has no plot"
        assert set(plots) <= set(plot_type_names()), (name, plots)


# -- the mechanism drawn from its kinematics ---------------------------------------------------------


def test_every_shipped_mechanism_declares_a_drawing():
    """The four mechanisms of the papers; a mechanism defined in a file or a plugin may
    have none, and gets "no drawing of the mechanism" (below)."""
    assert set(PARAMETERS) <= set(mechanism_names())
    for name in PARAMETERS:
        assert mechanism_type(name).geometry is not None, name
        assert "geometry" in mechanism_type(name).capabilities()


def _dist(d, a, b):
    return float(np.linalg.norm(np.asarray(d.points[a]) - np.asarray(d.points[b])))


def test_prs3_drawing_has_legs_of_length_L_and_sliders_on_their_rails():
    """prs3-ruiz.md eq 2-6, 17-18: |C_iB_i| = L, C_i = A_i + s_i s_i0 (towards the axis).
    The drawing of the mechanism file names its points by leg and joint: leg{i}_1 is the
    slider's zero position A_i (P joint), leg{i}_2 the slider C_i (R joint), leg{i}_3 B_i (S)."""
    model, x, q = pose_of("prs3")
    d = model.mechanism.geometry(model, x, q)
    L = model.parameters["L"]
    for i in (1, 2, 3):
        assert (d.joints[f"leg{i}_1"], d.joints[f"leg{i}_2"], d.joints[f"leg{i}_3"]) == ("P", "R", "S")
        assert _dist(d, f"leg{i}_2", f"leg{i}_3") == pytest.approx(L, rel=1e-9)
        A, C = np.asarray(d.points[f"leg{i}_1"]), np.asarray(d.points[f"leg{i}_2"])
        assert np.linalg.norm(A - C) == pytest.approx(abs(q[i - 1]), abs=1e-12)
        assert np.linalg.norm(C) == pytest.approx(np.linalg.norm(A) - q[i - 1], rel=1e-12)  # towards the axis
    centre = np.mean([d.points[f"leg{i}_3"] for i in (1, 2, 3)], axis=0)
    assert centre[:2] == pytest.approx(x[:2], abs=1e-12) and centre[2] == pytest.approx(x[2], rel=1e-12)


def test_pantograph_drawing_has_the_paper_link_lengths():
    """pantograph-3d-elgammal-2016.md section 3: AC = BC = DF = a, CD = BF = FE = b; E is the end-effector.
    The file's drawing (problems/mechanisms/pantograph.yaml) names the points of the sliders A' (dy)
    and A'' (dz, where L1 turns), B' (dx, where L3 turns); A and B are the ground's."""
    model, x, q = pose_of("pantograph")
    d = model.mechanism.geometry(model, x, q)
    a, b = model.parameters["a"], model.parameters["b"]
    A, B = "A''", "B'"
    for (p, r), length in {(A, "C"): a, (B, "C"): a, ("D", "F"): a, ("C", "D"): b, (B, "F"): b}.items():
        assert _dist(d, p, r) == pytest.approx(length, rel=1e-9), (p, r)
    assert _dist(d, "F", "E") == pytest.approx(b, rel=1e-9)
    assert np.asarray(d.points["E"]) == pytest.approx(x[:3], abs=1e-12)
    assert np.asarray(d.points[A]) == pytest.approx([0, q[1], q[2]]) and d.points[B][0] == pytest.approx(q[0])
    assert np.asarray(d.points["A"]) == pytest.approx([0, 0, 0]) and d.points["B"][1:] == pytest.approx([0, 0])


def test_prc3_drawing_has_legs_of_length_l():
    """prc3-li-2018.md eq 5-9: each leg C_iB_i is l = L7 long; the sliders move by d_i = A2 q_i along -e_i.
    The drawing is the mechanism file's: limb{i}_1 is the rail's origin A_i, limb{i}_2 the slider
    C_i, limb{i}_3 the platform joint B_i = P + l e_i."""
    model, x, q = pose_of("prc3")
    d = model.mechanism.geometry(model, x, q)
    l = model.parameters["L7"]
    for i in (1, 2, 3):
        e = np.eye(3)[i - 1]
        assert _dist(d, f"limb{i}_2", f"limb{i}_3") == pytest.approx(l, rel=1e-9)
        assert _dist(d, f"limb{i}_1", f"limb{i}_2") == pytest.approx(model.derived["A2"] * q[i - 1], rel=1e-9)
        slide = np.asarray(d.points[f"limb{i}_2"]) - np.asarray(d.points[f"limb{i}_1"])
        assert slide == pytest.approx(-model.derived["A2"] * q[i - 1] * e, abs=1e-15)  # along -e_i
        assert np.asarray(d.points[f"limb{i}_3"]) == pytest.approx(x + l * e, abs=1e-15)


def test_rpr_drawing_has_legs_of_the_actuated_lengths():
    """rpr-2rpu-upr-zhang-2022.md eq 2-6: |A_iB_i| = l_i; |oo'| = P.  The drawing is its file's
    (problems/mechanisms/rpr.yaml): A_i is leg{i}_1, B_i leg{i}_3, o' the platform centre P."""
    model, x, q = pose_of("rpr")
    d = model.mechanism.geometry(model, x, q)
    for i in (1, 2, 3):
        assert _dist(d, f"leg{i}_1", f"leg{i}_3") == pytest.approx(q[i - 1], rel=1e-9)
    assert np.linalg.norm(np.asarray(d.points["P"])) == pytest.approx(x[2], rel=1e-12)
    r1, r2 = model.parameters["r1"], model.parameters["r2"]
    for i, A in ((1, [r1, 0, 0]), (2, [0, r2, 0]), (3, [-r1, 0, 0])):  # eq 5
        assert np.asarray(d.points[f"leg{i}_1"]) == pytest.approx(A, abs=1e-15)


def test_a_mechanism_without_geometry_says_so():
    model = build_model("prs3", PARAMETERS["prs3"])

    class Bare:
        name = "bare"
        mechanism = replace(mechanism_type("prs3"), geometry=None)

    with pytest.raises(figures.NotApplicable, match="no drawing of the mechanism: bare declares no geometry"):
        plot_pose.geometry_of(Bare())
    assert plot_pose.geometry_of(model) is not None


def test_small_motions_are_drawn_exaggerated_and_said_so():
    """A compliant mechanism moves micrometres: the drawing scales the displacements from home by a
    round factor and the title says it."""
    model, x, q = pose_of("prc3")
    pose, home, k = plot_pose.drawings(model, x, q)
    true = model.mechanism.geometry(model, x, q)
    H = np.array([np.asarray(v) for v in home.points.values()])
    span = np.ptp(H, axis=0).max()
    move = max(np.linalg.norm(np.asarray(true.points[n]) - np.asarray(home.points[n])) for n in true.points)
    assert move < 0.02 * span and k == 10.0  # 0.15 mm of a mechanism 73.5 mm wide, shown 1.5 mm
    assert 0.01 * span <= k * move <= 0.1 * span
    for n in true.points:
        moved = np.asarray(true.points[n]) - np.asarray(home.points[n])
        assert np.asarray(pose.points[n]) == pytest.approx(np.asarray(home.points[n]) + k * moved)
    assert "displacements from home drawn ×10)" in plot_pose.pose_title(model, x, k)


# -- labels and values --------------------------------------------------------------------------------


def test_units_and_values_as_a_reader_reads_them():
    assert unit_text("mm^3") == r"$\mathrm{mm}^{3}$" and unit_text("mm") == "mm"
    assert value_text(0.99999999991) == "0.99999999991" and value_text(0.5) == "0.5"
    assert value_text(1.0) == "1" and value_text(0.123456) == "0.12346"


# -- baseline images ----------------------------------------------------------------------------------


def synthetic_workspace():
    """An ellipsoid workspace (semi-axes 3, 2, 1 mm), the largest box in it (semi-axes
    / sqrt 3), a box too tall for it (a 'printed' formulation), the boundary in the
    three planes through the centre."""
    rng = np.random.default_rng(0)
    semi = np.array([3e-3, 2e-3, 1e-3])
    u = rng.normal(size=(800, 3))
    u *= (rng.uniform(size=(800, 1)) ** (1 / 3)) / np.linalg.norm(u, axis=1, keepdims=True)
    half = semi / math.sqrt(3)
    slices = []
    for i, j in ((0, 1), (0, 2), (1, 2)):
        gx, gy = np.linspace(-1.3 * semi[i], 1.3 * semi[i], 41), np.linspace(-1.3 * semi[j], 1.3 * semi[j], 41)
        X, Y = np.meshgrid(gx, gy)
        margin = 1 - np.sqrt((X / semi[i]) ** 2 + (Y / semi[j]) ** 2)
        slices.append(BoundarySlice((i, j), gx, gy, margin, 0.0))
    tall = half * [0.8, 0.8, 1.6]
    return workspace_figure(
        u * semi,
        cuboid=(-half, half),
        names=("px", "py", "pz"),
        title="synthetic ellipsoid workspace",
        boxes=[(-tall, tall, "printed formulation")],
        slices=slices,
    )


def synthetic_map():
    """eta over a grid, its maximum 0.99999999991 (not 1), volume in mm³."""
    s, t = np.meshgrid(np.linspace(0, 2, 21), np.linspace(-1, 1, 17))
    eta = 0.99999999991 * np.exp(-((s - 1.2) ** 2) - t**2)
    return design_map_figure(
        s.ravel(), t.ravel(), eta.ravel(), names=("s", "t", "eta"), best="max", title="synthetic map"
    ), design_map_figure(
        s.ravel(),
        t.ravel(),
        1e-9 * (1 + s.ravel() + t.ravel() ** 2),
        names=("a", "b", "volume"),
        dimensions=(None, None, "volume"),
        title="volume",
    )


def synthetic_lines():
    """One narrow panel under a long title (issue 14: lines titles clipped on both sides)."""
    x = np.linspace(30, 60, 4) * math.pi / 180
    return panels_figure(
        x,
        [Panel("s_max", "length", {"s_max": [1e-3, 1.2e-3, 1.5e-3, 1.9e-3]})],
        xname="mechanism.parameters.alpha0",
        xdimension="angle",
        title="joint_requirements: sweep of mechanism.parameters.alpha0",
    )


def synthetic_comparison():
    rows = [Comparison("f", 107.3, 96.5, "frequency"), Comparison("M_e", 5.514, 5.523, "mass")]
    return comparison_figure([("printed in the paper", rows)], {"starts": 8, "starts_converged": 8}, title="synthetic")


def _solved_figure(name):
    import cpm_nlp as cn
    from tests.conftest import PROBLEMS

    problem = cn.load_problem(PROBLEMS / f"{name}.yaml")
    data = figures.from_result(cn.solve(problem))
    data.live = problem.model
    return figures.figure(data)[0]


def test_lines_figure_matches_its_baseline_image(tmp_path):
    """Regressions show: one narrow panel under a long title against its committed baseline, in
    the fixed style of every baseline (the mechanism drawings, the modes and the maps are pinned
    by tests/plot/test_plot_drawings.py, the journal figures by test_plot_journal.py)."""
    from tests.figure_checks import assert_matches_baseline

    fig = assert_matches_baseline(
        synthetic_lines,
        "lines_one_panel",
        tmp_path,
        tol=2.0,
        reason="renders identically run to run in the fixed style (RMS 0.0); a lost curve, marker or "
        "title line moves it far more",
    )
    assert_figure_readable(fig)


def test_map_marks_the_max_as_it_is_and_keeps_its_colorbar_attached():
    fig = synthetic_map()[0]
    legend = [t.get_text() for t in fig.legends[0].get_texts()]
    assert "max 0.99999999991" in legend  # not "max 1"
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    FigureCanvasAgg(fig).draw()
    ax, bar = fig.axes
    gap = bar.get_position().x0 - ax.get_position().x1
    assert 0 <= gap < 0.03  # attached: no white gap between the map and its colour bar
    volume = synthetic_map()[1]
    assert volume.axes[1].get_ylabel() == r"volume ($\mathrm{mm}^{3}$)"


def test_workspace_legend_and_boundary_layers():
    fig = synthetic_workspace()
    legend = [t.get_text() for t in fig.legends[0].get_texts()]
    assert legend == [
        "reachable points: 800 points",
        "workspace boundary (slices through the box centre)",
        "maximal inscribed cuboid (3.46 × 2.31 × 1.15 mm)",
        "printed formulation (2.77 × 1.85 × 1.85 mm)",
        "reachable region of each section (membership on a 41 × 41 grid)",
    ]
    for ax in fig.axes[1:]:  # the sections: the two boxes over the shaded region, no projected points
        assert len(ax.patches) == 3 and ax.get_title().startswith("section at ") and not ax.collections
        assert sum(len(ln.get_xdata()) > 10 for ln in ax.lines) == 1  # one closed boundary (an ellipse)
    # the 3-D view keeps at most four ticks per axis (long labels of a short range overlapped)
    assert all(len(a.get_major_locator()()) <= 5 for a in (fig.axes[0].xaxis, fig.axes[0].yaxis, fig.axes[0].zaxis))


# -- interactive figures in a real browser -----------------------------------------------------------


def _chromium():
    exe = shutil.which("chromium") or shutil.which("chromium-browser")
    if exe is None:
        if os.environ.get("CPM_NLP_REQUIRE_BROWSER"):
            pytest.fail("chromium is not installed; CI (.ci/run) installs it: apt-get install -y chromium")
        pytest.skip("chromium is not installed (apt-get install -y chromium); .ci/run installs it")
    return exe


def _screenshot(exe, html, tmp_path):
    shot = tmp_path / f"{html.stem}.png"
    profile = tmp_path / f"profile-{html.stem}"
    cmd = [
        exe,
        "--headless",
        "--no-sandbox",
        "--disable-gpu",
        "--disable-background-networking",
        "--disable-component-update",
        "--disable-sync",
        "--no-first-run",
        f"--user-data-dir={profile}",
        f"--screenshot={shot}",
        "--window-size=800,600",
        "--virtual-time-budget=10000",
        html.resolve().as_uri(),
    ]
    subprocess.run(cmd, capture_output=True, timeout=180, check=False)
    assert shot.exists(), f"chromium wrote no screenshot of {html}"
    from matplotlib.image import imread

    return imread(shot)[..., :3]


def test_interactive_html_renders_in_a_headless_browser(tmp_path, cli):
    """--plot FILE.html: a self-contained Plotly page (plotly.js embedded, no network) that
    chromium renders to a drawn picture: a mechanism drawing and a workspace with its box."""
    pytest.importorskip("plotly")
    exe = _chromium()
    from tests.conftest import PROBLEMS

    html = tmp_path / "fk.html"
    run = cli("solve", str(PROBLEMS / "prs3_forward_kinematics.yaml"), "-q", "--plot", str(html))
    assert run.code == 0, run.err
    text = html.read_text()
    assert '<script src="http' not in text and len(text) > 1_000_000  # plotly.js inside the file
    rgb = _screenshot(exe, html, tmp_path)
    ink = (rgb < 0.9).any(axis=-1).mean()
    assert rgb.std() > 0.03 and ink > 0.01, (rgb.std(), ink)
    coloured = (np.ptp(rgb, axis=-1) > 0.25).mean()  # the legs, actuators and platform in colour
    assert coloured > 0.001, coloured
    # a workspace figure too (its boxes drawn as coloured lines)
    fig = synthetic_workspace_html()
    assert {t.name.split(" (")[0] for t in fig.data} >= {"maximal inscribed cuboid", "printed formulation"}
    page = tmp_path / "ws.html"
    save(fig, page)
    rgb = _screenshot(exe, page, tmp_path)
    assert rgb.std() > 0.03 and (np.ptp(rgb, axis=-1) > 0.25).mean() > 0.001
    page_text = page.read_text()  # the page names both boxes and needs no network
    assert "maximal inscribed cuboid" in page_text and "printed formulation" in page_text
    assert '<script src="http' not in page_text


def synthetic_workspace_html():
    from cpm_nlp.plot.interactive import workspace_html

    semi = np.array([3e-3, 2e-3, 1e-3])
    rng = np.random.default_rng(0)
    pts = rng.uniform(-1, 1, size=(500, 3)) * semi
    half = semi / math.sqrt(3)
    return workspace_html(
        pts, cuboid=(-half, half), boxes=[(-1.2 * half, 1.2 * half, "printed formulation")], title="synthetic"
    )


def test_html_of_a_flat_plot_is_refused_clearly():
    import cpm_nlp as cn
    from tests.conftest import PROBLEMS

    data = figures.from_result(cn.solve(cn.load_problem(PROBLEMS / "prs3_joint_requirements.yaml")))
    with pytest.raises(figures.NotApplicable, match=r"an interactive \(.html\) figure is drawn for the 3-D plots"):
        figures.figure(data, "requirements", interactive=True)
    fig, kind = figures.figure(data, interactive=True)  # the default falls through to the 3-D one
    assert kind == "workspace" and type(fig).__module__.startswith("plotly")


def test_without_plotly_an_html_plot_says_what_to_install(tmp_path):
    import subprocess
    import sys

    from tests.conftest import PROBLEMS

    fk, html = str(PROBLEMS / "prs3_forward_kinematics.yaml"), str(tmp_path / "f.html")
    code = f"""
import sys
sys.modules["plotly"] = None  # ImportError on import, as when not installed
from cpm_nlp.cli.main import main
print("exit", main(["solve", {fk!r}, "-q", "--plot", {html!r}]))
"""
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert proc.stdout.splitlines()[-1] == "exit 2", proc.stderr
    assert proc.stderr.splitlines()[-1] == (
        "error: interactive (.html) plots needs the Python package 'plotly', which is not installed "
        "(pip install 'cpm_nlp[plot]')"
    )
    assert list(tmp_path.iterdir()) == []


# -- a plot of every kind, from real solves ------------------------------------------------------------


@pytest.fixture(scope="module")
def solved():
    """Results of the shipped problem files, solved once for this module."""
    import cpm_nlp as cn
    from tests.conftest import PROBLEMS

    cache = {}

    def get(name):
        if name not in cache:
            problem = cn.load_problem(PROBLEMS / f"{name}.yaml")
            data = figures.from_result(cn.solve(problem))
            data.live = problem.model
            cache[name] = data
        return cache[name]

    return get


def test_dynamics_plot_frequencies_are_the_eigenvalues_of_K_and_M(solved):
    """prc3-li-2018.md eq 28-41: the bars are sqrt(eig(K, M)) / 2 pi of the result's matrices,
    which the kind reports as f1..f3; the printed values are compared beside them."""
    data = solved("prc3_dynamics")
    fig, kind = figures.figure(data)
    assert kind == "dynamics"
    bars = [p.get_height() for p in fig.axes[0].patches]
    assert bars == pytest.approx([data.values[f"f{i}"] for i in (1, 2, 3)], rel=1e-9)
    assert any("printed formulas (evaluated here)" in ax.get_xlabel() for ax in fig.axes)
    assert_figure_readable(fig)


def test_amplifier_plot_slope_is_A2(solved):
    data = solved("prc3_amplifier")
    fig, kind = figures.figure(data)
    line = fig.axes[0].lines[0]
    slope = np.polyfit(line.get_xdata(), line.get_ydata(), 1)[0]
    assert kind == "amplifier" and slope == pytest.approx(data.values["A2"], rel=1e-9)  # eq 2: d = A2 q, both in µm
    assert_figure_readable(fig)


def test_twists_as_arrows_on_the_mechanism(solved):
    """rpr-2rpu-upr-zhang-2022.md eq 45: one rotation and one translation arrow per actuator that moves them."""
    data = solved("rpr_twists")
    fig, kind = figures.figure(data)
    T = np.asarray(data.values["T"])
    n = sum(np.linalg.norm(T[:3, j]) > 0 for j in range(3)) + sum(np.linalg.norm(T[3:, j]) > 0 for j in range(3))
    labels = [t.get_text() for t in fig.legends[0].get_texts()]
    assert kind == "twists" and sum(lab.startswith(("ω of", "v of")) for lab in labels) == n
    assert_figure_readable(fig)
    html, _ = figures.figure(data, interactive=True)
    assert sum(t.name.startswith(("ω of", "v of")) for t in html.data) == n


def test_compliance_matrices_with_their_entries(solved):
    data = solved("rpr_compliance")
    fig, kind = figures.figure(data)
    titles = [ax.get_title() for ax in fig.axes]
    assert kind == "matrices" and "$C$" in titles and "$C_{in}$" in titles
    C = fig.axes[titles.index("$C$")]
    entries = [float(t.get_text()) for t in C.texts]
    assert entries == pytest.approx(
        [v if abs(v) > 1e-12 * np.abs(data.values["C"]).max() else 0 for v in np.ravel(data.values["C"])], rel=5e-3
    )
    assert_figure_readable(fig)


def test_joint_design_and_synthesis_against_their_references(solved):
    data = solved("rpr_joint_design")
    fig, kind = figures.figure(data)
    assert kind == "comparison"
    names = [t.get_text() for t in fig.axes[0].get_yticklabels()]
    assert names == ["$f_{R}$", r"$\theta_{max,R}$", "$f_{U}$", r"$\theta_{max,U}$"]
    bar = fig.axes[0].patches[0]  # f_R: the compared design's over ours, from 1
    assert 1 + bar.get_width() == pytest.approx(data.values["f_R_compare"] / data.values["f_R"])
    assert_figure_readable(fig)
    syn = solved("pantograph_synthesis")
    fig, kind = figures.figure(syn)
    assert kind == "comparison" and "multi-start: starts 6" in fig.axes[-1].get_title()
    assert_figure_readable(fig)
    fig, kind = figures.figure(syn, "design")  # the designed pantograph drawn at home
    assert kind == "design" and f"a = {syn.values['a'] * 1e3:.4g} mm" in fig._suptitle.get_text()
    assert_figure_readable(fig)


def test_jacobian_plot_mechanism_and_conditioning_slice(solved):
    data = solved("prs3_jacobian")
    fig, kind = figures.figure(data)
    assert kind == "jacobian"
    cond_ax = next(ax for ax in fig.axes if ax.get_title().startswith("cond at"))
    assert cond_ax.get_legend().get_title().get_text() == f"cond = {data.values['cond']:.4g}"
    star = next(ln for ln in cond_ax.lines if ln.get_marker() == "*")
    assert star.get_xdata()[0] == pytest.approx(data.values["pz"] * 1e3)  # the pose, in mm
    mesh = cond_ax.collections[0].get_array()
    assert np.nanmin(mesh) >= 1.0  # condition numbers
    assert_figure_readable(fig)
    fig, kind = figures.figure(data, "matrices")
    assert kind == "matrices" and "$J_{task}$" in [ax.get_title() for ax in fig.axes]


def test_mechanism_plot_of_a_pose_and_its_html(solved, tmp_path):
    data = solved("pantograph_forward_kinematics")
    fig, kind = figures.figure(data)
    assert kind == "mechanism" and "forward kinematics: $px$ = 101 mm" in fig._suptitle.get_text()
    assert_figure_readable(fig)
    html, kind = figures.figure(data, interactive=True)
    assert kind == "mechanism" and {"link", "revolute joint (R)"} <= {t.name for t in html.data}
    save(html, tmp_path / "m.html")
    assert (tmp_path / "m.html").stat().st_size > 1_000_000


def test_mode_shapes_as_arrows_on_the_mechanism(solved):
    """One panel per mode (up to three) titled with its frequency; the arrow at the platform
    centre P points along the mode's platform translation (modes_x)."""
    data = solved("prs3_natural_frequencies")
    fig, kind = figures.figure(data)
    assert kind == "modes"
    titles = [ax.get_title() for ax in fig.axes]
    assert titles == [f"mode {k + 1}: {draw_number(data.values[f'f{k + 1}'])} Hz" for k in range(3)]
    model, geometry, x, q = compliance_plots.drawn_pose(data)
    c = model.closure
    idx = [c.x_names.index(n) for n in ("px", "py", "pz")]
    for mx, mq in zip(data.values["modes_x"], data.values["modes_q"]):
        arrows = compliance_plots.mode_arrows(model, geometry, x, q, mx, mq)
        at_p = [a for a in arrows if np.allclose(a.origin, geometry(model, x, q).points["P"])]
        t = np.array(mx)[idx]
        if np.linalg.norm(t) > 1e-6 * np.abs(mx).max():
            (a,) = at_p
            cos = np.dot(a.vector, t) / (np.linalg.norm(a.vector) * np.linalg.norm(t))
            assert abs(cos) == pytest.approx(1.0, abs=1e-6)
    assert_figure_readable(fig)


def test_compliance_ellipsoid_on_the_mechanism(solved):
    data = solved("prs3_cutting_force")
    fig, kind = figures.figure(data)
    assert kind == "ellipsoid" and len(fig.axes) == 2
    assert fig.axes[0].get_title() == "at the platform centre: the deflections under a force of 10 kN in any direction"
    assert "compliance ellipsoid (scaled)" in [t.get_text() for t in fig.legends[0].get_texts()]
    assert_figure_readable(fig)


def test_file_mechanism_forward_kinematics_plot_draws_it(cli, tmp_path):
    """``solve --plot`` of a mechanism described in a file draws the mechanism."""
    from tests.conftest import PROBLEMS
    from tests.figure_checks import assert_png_drawn

    out = tmp_path / "five_bar.png"
    run = cli("solve", str(PROBLEMS / "five_bar_forward_kinematics.yaml"), "--plot", str(out))
    assert run.code == 0, run.err
    assert "(mechanism)" in run.out
    assert_png_drawn(out)
