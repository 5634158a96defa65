"""Plots from real results (3-PRS solves and a sweep results file) and from
synthetic arrays (a cuboid in a cloud, a map over the RPR (s, t) triangle):
each file is a valid PNG/SVG, drawn (not blank), axes labelled with units."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

import cpm_nlp as cn
from cpm_nlp.io.results import open_store, read_results
from cpm_nlp.plot.draw import design_map_figure, display_unit, pretty, save, workspace_figure
from cpm_nlp.plot.figures import PlotOptions, figure, from_result, from_table, load
from cpm_nlp.sweep.run import columns, job_of, metadata, solve_points
from tests.conftest import PROBLEMS
from tests.figure_checks import assert_figure_readable, assert_png_drawn, assert_svg_drawn

matplotlib = pytest.importorskip("matplotlib")


@pytest.fixture(scope="module")
def requirements():
    return cn.solve(cn.load_problem(PROBLEMS / "prs3_joint_requirements.yaml"))


@pytest.fixture(scope="module")
def fk_sample():
    """A batch FK of 150 random actuator displacements within +-2 mm (seeded)."""
    s = np.random.default_rng(3).uniform(-2e-3, 2e-3, size=(150, 3))
    sets = [f"inputs.s{i + 1}={json.dumps(s[:, i].tolist())}" for i in range(3)]
    return cn.solve(cn.load_problem(PROBLEMS / "prs3_forward_kinematics.yaml", sets))


@pytest.fixture(scope="module")
def map_file(tmp_path_factory):
    """A sweep results file: the 3-PRS s_max over (b, L), solved in this process."""
    d = tmp_path_factory.mktemp("map")
    path = d / "s.yaml"
    path.write_text(
        (PROBLEMS / "prs3_joint_requirements.yaml").read_text().split("reproduce:")[0]
        + "outputs: {values: [s_max, dalpha_max]}\n"
        "sweep:\n  parameters:\n    mechanism.parameters.b: {from: 30 mm, to: 60 mm, count: 4}\n"
        "    mechanism.parameters.L: {from: 90 mm, to: 130 mm, count: 3}\n"
    )
    problem = cn.load_problem(path)
    job = job_of(problem)
    out = d / "map.csv"
    store = open_store(out, metadata(problem, job), columns(job))
    solved = solve_points(job, range(job.spec.size))
    store.append(solved["records"], solved["units"], solved["dimensions"])
    store.close()
    return out


def test_requirements_plot_like_fig_6_7(requirements, tmp_path):
    fig, kind = figure(from_result(requirements))
    assert kind == "requirements" and len(fig.axes) == 8
    assert [ax.get_ylabel() for ax in fig.axes] == [
        "$d_{z}$ (mm)",
        r"$\psi$ (deg)",
        r"$\theta$ (deg)",
        "$s$ (mm)",
        r"$\Delta \alpha$ (deg)",
        r"$\beta_{m}$ (deg)",
        r"$\beta_{n}$ (deg)",
        r"$\beta_{l}$ (deg)",
    ]
    assert all(len(ax.lines) == n for ax, n in zip(fig.axes, [1, 1, 1, 3, 3, 3, 3, 3]))
    v = requirements.values
    # the ranges written in the panels are the result's (prs3-ruiz.md, Fig. 6: -2.15 ... 2.30 mm)
    assert fig.axes[3].get_title() == f"range {v['s_min'] * 1e3:.3g} … {v['s_max'] * 1e3:.3g} mm"
    dalpha = f"{math.degrees(v['dalpha_min']):.3g} … {math.degrees(v['dalpha_max']):.3g} deg"
    assert fig.axes[4].get_title() == f"range {dalpha}"
    assert np.allclose(fig.axes[3].lines[0].get_ydata(), np.array(v["s1"]) * 1e3)
    save(fig, tmp_path / "r.png")
    assert_png_drawn(tmp_path / "r.png")


def test_io_plot_outputs_against_the_varied_input(tmp_path, cli):
    result = tmp_path / "fk.json"
    run = cli(
        "solve",
        str(PROBLEMS / "prs3_forward_kinematics.yaml"),
        "--set",
        "inputs.s1={from: -2 mm, to: 2 mm, count: 11}",
        "-o",
        str(result),
        "--plot",
        str(tmp_path / "io.svg"),
    )
    assert run.code == 0, run.err
    assert f"plot    : {tmp_path / 'io.svg'} (io)" in run.out
    assert_svg_drawn(tmp_path / "io.svg", 100)
    fig, kind = figure(load(result))
    assert kind == "io" and len(fig.axes) == 6
    assert {ax.get_xlabel() for ax in fig.axes} == {"$s_{1}$ (mm)"}
    ylabels = [ax.get_ylabel() for ax in fig.axes]
    assert ylabels[2] == "$d_{z}$ (µm)" and ylabels[3] == r"$\psi$ (deg)"  # about 0.65 mm: shown in µm
    dz = json.loads(result.read_text())["values"]["dz"]
    assert np.allclose(fig.axes[2].lines[0].get_ydata(), np.array(dz) * 1e6)


def test_workspace_cloud_from_a_batch_fk_sample(fk_sample):
    assert fk_sample.ok
    fig, kind = figure(from_result(fk_sample), "workspace")
    assert kind == "workspace" and len(fig.axes) == 4
    cloud = fig.axes[0].collections[0]
    assert len(cloud.get_offsets()) == 150
    assert fig.axes[0].get_xlabel() == "$d_{z}$ (mm)" and fig.axes[0].get_zlabel() == r"$\theta$ (deg)"
    dz = np.array(fk_sample.values["dz"]) * 1e3
    assert np.allclose(np.sort(cloud.get_offsets()[:, 0]), np.sort(dz))  # the solved poses, in mm


def test_workspace_with_its_inscribed_cuboid(tmp_path):
    """Synthetic: points inside an ellipsoid (semi-axes 3, 2, 1 mm) and the
    largest box inside it, (2/sqrt 3) x the semi-axes."""
    rng = np.random.default_rng(0)
    u = rng.normal(size=(600, 3))
    u *= (rng.uniform(size=(600, 1)) ** (1 / 3)) / np.linalg.norm(u, axis=1, keepdims=True)
    semi = np.array([3e-3, 2e-3, 1e-3])
    pts = u * semi
    half = semi / math.sqrt(3)
    fig = workspace_figure(pts, cuboid=(-half, half), names=("px", "py", "pz"), title="synthetic")
    ax3 = fig.axes[0]
    assert len(ax3.collections) == 2  # the cloud and the cuboid's faces
    assert [len(ax.patches) for ax in fig.axes[1:]] == [1, 1, 1]  # the cuboid in each projection
    rect = fig.axes[1].patches[0]
    assert rect.get_width() == pytest.approx(2 * half[0] * 1e3) and rect.get_height() == pytest.approx(
        2 * half[1] * 1e3
    )
    assert fig.legends[0].get_texts()[1].get_text() == "maximal inscribed cuboid (3.46 × 2.31 × 1.15 mm)"
    assert_figure_readable(fig)
    save(fig, tmp_path / "c.png")
    assert len(ax3.collections[1].get_paths()) == 6  # six faces, projected when drawn
    rgb = assert_png_drawn(tmp_path / "c.png")
    red = (rgb[..., 0] > 0.7) & (rgb[..., 1] < 0.4) & (rgb[..., 2] < 0.4)
    assert red.mean() > 0.001  # the cuboid is drawn in red


def test_map_of_s_max_over_b_and_L_from_a_sweep_file(map_file, tmp_path, cli):
    data = load(map_file)
    fig, kind = figure(data, options=PlotOptions(value="s_max", best="max"))
    assert kind == "map"
    ax = fig.axes[0]
    mesh = ax.collections[0]
    cells = mesh.get_array()
    rows = read_results(map_file).rows
    assert cells.shape == (3, 4)  # L (3) by b (4)
    assert sorted(np.asarray(cells).ravel()) == pytest.approx(sorted(r["s_max"] * 1e3 for r in rows))
    assert ax.get_xlabel() == "$b$ (mm)" and ax.get_ylabel() == "$L$ (mm)"
    assert fig.axes[1].get_ylabel() == "$s_{max}$ (mm)"  # the colour bar
    legend = [t.get_text() for t in fig.legends[0].get_texts()]
    assert legend[0] == "base design (the file)" and legend[1].startswith("max ")
    run = cli("plot", str(map_file), "-o", str(tmp_path / "m.png"), "--value", "dalpha_max")
    assert run.code == 0, run.err
    assert run.out == f"{tmp_path / 'm.png'}: map plot of {map_file}\n"
    assert_png_drawn(tmp_path / "m.png", min_ink=0.3)


def test_lines_of_a_one_parameter_sweep(tmp_path):
    path = tmp_path / "s.yaml"
    path.write_text(
        (PROBLEMS / "sweep_prs3_requirements.yaml").read_text().split("sweep:")[0]
        + "sweep:\n  parameters:\n    mechanism.parameters.alpha0: {from: 30 deg, to: 60 deg, count: 4}\n"
    )
    problem = cn.load_problem(path)
    job = job_of(problem)
    out = tmp_path / "r.parquet"
    store = open_store(out, metadata(problem, job), columns(job))
    solved = solve_points(job, range(4))
    store.append(solved["records"], solved["units"], solved["dimensions"])
    store.close()
    fig, kind = figure(load(out))
    assert kind == "lines" and len(fig.axes) == 10
    assert fig.axes[1].get_xlabel() == r"$\alpha_{0}$ (deg)" and fig.axes[1].get_ylabel() == "$s_{max}$ (mm)"
    assert list(fig.axes[1].lines[0].get_xdata()) == pytest.approx([30, 40, 50, 60])
    # s_max grows with alpha0: a slider moves tan(alpha0) per unit of rise (prs3-ruiz.md, eq 20)
    assert np.all(np.diff(fig.axes[1].lines[0].get_ydata()) > 0)


def rpr_triangle_map(n=400, seed=1):
    """Synthetic values on the RPR design triangle (rpr-2rpu-upr-zhang-2022.md,
    eq 21-23): l1 + l2 + l3 = 3, l_i > 0, s = l2, t = (l3 - l1)/sqrt 3."""
    rng = np.random.default_rng(seed)
    ls = rng.dirichlet([1, 1, 1], size=n) * 3
    s = ls[:, 1]
    t = (ls[:, 2] - ls[:, 0]) / math.sqrt(3)
    eta = np.exp(-((s - 1.5) ** 2) - t**2)  # a smooth bump at the paper's choice (1.5, 0), eq 24
    domain = [(0.0, -math.sqrt(3)), (3.0, 0.0), (0.0, math.sqrt(3))]
    return s, t, eta, domain


def test_design_map_over_a_triangular_domain(tmp_path):
    s, t, eta, domain = rpr_triangle_map()
    fig = design_map_figure(
        s, t, eta, names=("s", "t", "eta"), domain=domain, best="max", title="synthetic, RPR triangle"
    )
    ax = fig.axes[0]
    assert ax.get_xlabel() == "$s$" and ax.get_ylabel() == "$t$" and fig.axes[1].get_ylabel() == r"$\eta$"
    best = [ln for ln in ax.lines if ln.get_marker() == "*"][0]
    assert best.get_xdata()[0] == pytest.approx(1.5, abs=0.25) and best.get_ydata()[0] == pytest.approx(0, abs=0.25)
    path = tmp_path / "tri.png"
    save(fig, path)
    rgb = assert_png_drawn(path)
    # colour inside the triangle, none outside it (the axes' corner beyond the hypotenuse)
    fig.canvas.draw()
    height = rgb.shape[0]

    def pixel(x, y):
        px, py = ax.transData.transform((x, y)) * (150 / fig.dpi)
        return rgb[int(height - py), int(px)]

    assert not np.allclose(pixel(1.0, 0.0), 1.0, atol=0.05)  # inside: coloured
    assert np.allclose(pixel(2.8, 1.5), 1.0, atol=0.02)  # outside: white


def test_failed_points_leave_holes_and_are_marked(tmp_path):
    x, y = np.meshgrid(np.linspace(0, 1, 6), np.linspace(0, 2, 5))
    z = (x + y).ravel().astype(object)
    z[[3, 17]] = None
    fig = design_map_figure(x.ravel(), y.ravel(), z, names=("a", "b", "c"), dimensions=("length", "angle", None))
    ax = fig.axes[0]
    assert np.ma.count_masked(ax.collections[0].get_array()) == 2
    crosses = [ln for ln in ax.lines if ln.get_marker() == "x"]
    assert len(crosses[0].get_xdata()) == 2 and crosses[0].get_label() == "not solved (2)"
    assert ax.get_xlabel() == "$a$ (m)" and ax.get_ylabel() == "$b$ (deg)"  # lengths of 1 m in m


def test_nothing_solved_is_said_not_drawn(cli, tmp_path):
    out = tmp_path / "r.json"
    fig = tmp_path / "f.png"
    run = cli(
        "solve",
        str(PROBLEMS / "prs3_inverse_kinematics.yaml"),
        "--set",
        "inputs.dz=[150 mm, 160 mm]",
        "-o",
        str(out),
        "--plot",
        str(fig),
    )
    assert run.code == 1
    assert run.err == ("error: --plot: no plot written: no point of the result is solved; there is nothing to plot\n")
    assert out.exists() and not fig.exists()


def test_plot_bad_input(cli, tmp_path):
    fk = str(PROBLEMS / "prs3_forward_kinematics.yaml")
    out = tmp_path / "fk.json"
    assert cli("solve", fk, "-o", str(out), "-q").code == 0
    run = cli("plot", str(out), "-o", str(tmp_path / "x.png"), "--type", "map")
    assert run.code == 2
    assert run.err == f"error: {out}: a map of a single result needs --x, --y and --value naming three of its lists\n"
    run = cli("plot", str(out), "-o", str(tmp_path / "x.png"), "--type", "heatmap")
    assert run.err.startswith(
        "error: --type: unknown plot type 'heatmap'; expected one of: amplifier, assembly_modes, comparison, design"
    )
    assert run.err.endswith("did you mean 'map'?\n")
    run = cli("plot", str(out), "-o", str(tmp_path / "x.jpg"))
    assert run.err == (
        f"error: -o: expected a figure file ending in .png, .svg, .pdf, .html, got '{tmp_path / 'x.jpg'}'\n"
    )
    run = cli("plot", str(out), "-o", str(tmp_path / "x.png"), "--x", "px")  # an FK result draws no map
    assert run.code == 2 and run.err.startswith(
        f"error: --x: --x chooses the axes of a map plot; {out} was drawn as a "
    ), run.err
    assert run.err.endswith("leave it out, or ask for the map with --type map\n")
    run = cli("plot", fk, "-o", str(tmp_path / "x.png"))
    assert run.code == 2 and run.err == (
        f"error: {fk}: expected a JSON result written by 'cpm-nlp solve -o' or a sweep results file (.parquet, .csv)\n"
    )
    run = cli("solve", fk, "-q", "--plot", str(tmp_path / "y.gif"))
    assert run.err == (
        f"error: --plot: expected a figure file ending in .png, .svg, .pdf, .html, got '{tmp_path / 'y.gif'}'\n"
    )
    assert sorted(p.name for p in tmp_path.iterdir()) == ["fk.json"]  # bad input wrote nothing


def test_solve_plot_never_discards_the_result(cli, tmp_path):
    """A plot that does not fit the result: the result is printed and written first,
    then a clear message, exit 1 (issue 14)."""
    fk = str(PROBLEMS / "prs3_forward_kinematics.yaml")
    out = tmp_path / "fk.json"
    run = cli("solve", fk, "-o", str(out), "--plot", str(tmp_path / "y.png"), "--type", "requirements")
    assert run.code == 1
    assert "platform" in run.out.lower() or "px" in run.out  # the table is printed
    assert json.loads(out.read_text())["status"] == "solved"  # and written
    assert run.err.startswith("error: --plot: no plot written: the requirements plot needs per-point lists")
    assert not (tmp_path / "y.png").exists()


def test_display_units_and_symbols():
    assert display_unit("length", [0.0, 2e-3]) == (1e3, "mm")
    assert display_unit("length", [5e-5, -3e-5]) == (pytest.approx(1e6), "µm")
    assert display_unit("length", [0.5e-9]) == (1e9, "nm")
    assert display_unit("length", [1.2]) == (1.0, "m")
    f, unit = display_unit("angle", [0.01])
    assert unit == "deg" and f == pytest.approx(180 / math.pi)
    assert display_unit("dimensionless", [3]) == (1.0, "")
    assert pretty("beta_m1") == r"$\beta_{m1}$" and pretty("dalpha_max") == r"$\Delta \alpha_{max}$"
    assert pretty("alpha0") == r"$\alpha_{0}$" and pretty("s2") == "$s_{2}$" and pretty("dz") == "$d_{z}$"
    assert pretty("mechanism.parameters.L") == "$L$" and pretty("manipulability") == "manipulability"


def test_sweep_table_and_result_views(map_file, requirements):
    data = from_table(read_results(map_file))
    assert data.sweep and data.kind == "sweep" and data.problem == "joint_requirements"
    assert data.dimensions["mechanism.parameters.b"] == "length" and data.dimensions["s_max"] == "length"
    assert list(data.ok) == [True] * 12
    view = from_result(requirements.to_dict())
    assert view.kind == "joint_requirements" and view.dimensions["psi"] == "angle"


# -- the kinds of the pantograph and the RPR ----------------------------------------------------


def test_pantograph_printed_eq34c_box_beside_ours_in_the_workspace(tmp_path):
    """pantograph-3d-elgammal-2016.md, Fig. 13 and eq 32-34: the maximal cuboid in the
    workspace, its boundary drawn around it, and the box of eq 34c as printed beside it:
    that box leaves the workspace (544 of 1663 check points, problems/pantograph_cuboid_eq34_printed.yaml)
    at its near face px = k, where the phi planes (eq 18) bind."""
    from matplotlib.path import Path as MplPath

    problem = cn.load_problem(PROBLEMS / "pantograph_cuboid_eq34_printed.yaml")
    result = cn.solve(problem)
    v = result.values
    data = from_result(result)
    data.live = problem.model  # as solve --plot has it
    fig, kind = figure(data)
    assert kind == "workspace"
    legend = [t.get_text() for t in fig.legends[0].get_texts()]
    assert any(t.startswith("paper's eq 32-34 box, 544 of 1663 check points outside") for t in legend), legend
    assert any(t.startswith("workspace boundary") for t in legend)
    xz = fig.axes[2]  # px-pz projection, the boundary slice at py = 0, in mm
    from matplotlib.patches import Rectangle

    ours, paper = [p for p in xz.patches if isinstance(p, Rectangle)]  # beside the section's shading
    assert ours.get_width() == pytest.approx((v["px_max"] - v["px_min"]) * 1e3)
    assert paper.get_x() == pytest.approx(v["paper_k"] * 1e3) and paper.get_linestyle() == "--"
    assert paper.get_height() == pytest.approx(2 * v["paper_z_hat"] * 1e3)
    boundary = [MplPath(ln.get_xydata()) for ln in xz.lines if len(ln.get_xdata()) > 10]
    assert boundary

    def inside(px, pz):
        return any(b.contains_point((px * 1e3, pz * 1e3)) for b in boundary)

    # our box's near-face corner is inside (just), the printed box's is not
    k, z = v["px_min"], v["pz_max"]
    assert inside(k + 0.02 * (v["px_max"] - k), 0.98 * z)
    assert not inside(v["paper_k"] + 0.02 * (v["paper_x_hat"] - v["paper_k"]), v["paper_z_hat"])
    assert_figure_readable(fig)
    save(fig, tmp_path / "c.png")
    assert_png_drawn(tmp_path / "c.png")
    alone, _ = figure(from_result(result.to_dict()))  # from the JSON alone: the boxes, and how to see the workspace
    assert len(alone.axes[1].patches) == 2 and not alone.axes[0].collections[1:]
    assert "`cpm-nlp solve FILE --plot` draws the workspace around it" in alone._suptitle.get_text()


def assert_cloud_covers_cuboid(fig, values, task, shown):
    """The sampled workspace reaches every face of the cuboid inscribed in it (``shown``: SI -> drawn)."""
    cloud = np.array(fig.axes[0].collections[0]._offsets3d).T
    lo = np.array([values[f"{t}_min"] for t in task]) * shown
    hi = np.array([values[f"{t}_max"] for t in task]) * shown
    slack = 0.05 * (hi - lo)
    assert np.all(cloud.min(axis=0) <= lo + slack) and np.all(cloud.max(axis=0) >= hi - slack)


def test_prc3_cuboid_in_its_workspace():
    """3-PRC (prc3-li-2018.md): the probe from home stops short of the cuboid; the cloud must not."""
    problem = cn.load_problem(PROBLEMS / "prc3_cuboid.yaml")
    result = cn.solve(problem)
    data = from_result(result)
    data.live = problem.model
    fig, kind = figure(data)
    assert kind == "workspace" and fig.axes[1].get_xlabel() == "$x$ (µm)"
    assert_cloud_covers_cuboid(fig, result.values, ("x", "y", "z"), 1e6)


def test_actuator_workspace_points():
    result = cn.solve(cn.load_problem(PROBLEMS / "prc3_workspace.yaml", ["inputs.points=true"]))
    fig, kind = figure(from_result(result))
    assert kind == "workspace" and len(fig.axes[0].collections[0].get_offsets()) == result.values["n_points"]


def test_workspace_kind_cloud(tmp_path):
    result = cn.solve(cn.load_problem(PROBLEMS / "pantograph_workspace.yaml"))
    fig, kind = figure(from_result(result))
    assert kind == "workspace"
    assert len(fig.axes[0].collections[0].get_offsets()) == result.values["cloud_count"]
    save(fig, tmp_path / "w.svg")
    assert_svg_drawn(tmp_path / "w.svg", 300)


def test_rpr_transmission_map_like_fig_4(tmp_path):
    """rpr-2rpu-upr-zhang-2022.md, Fig. 4: eta over the (s, t) triangle, the optimum region marked."""
    result = cn.solve(cn.load_problem(PROBLEMS / "rpr_transmission_map.yaml"))
    fig, kind = figure(from_result(result))
    assert kind == "map"
    ax = fig.axes[0]
    cells = ax.collections[0].get_array()
    eta = result.values["eta"]
    assert cells.shape == (len(result.values["t"]), len(result.values["s"]))
    assert np.ma.count_masked(cells) == sum(v is None for row in eta for v in row)  # blank outside eq 22
    assert np.nanmax(cells.filled(np.nan)) == pytest.approx(result.values["eta_best"])
    red = [ln for ln in ax.lines if ln.get_color() == "tab:red" and len(ln.get_xdata()) > 10]
    assert red  # the optimum region eta >= 0.99 is outlined
    marks = {ln.get_label(): (ln.get_xdata()[0], ln.get_ydata()[0]) for ln in ax.lines if len(ln.get_xdata()) == 1}
    assert marks["design (the file)"] == pytest.approx((1.5, 0.0))  # eq 24
    assert marks[r"best $\eta$ (the result)"] == pytest.approx((result.values["s_best"], result.values["t_best"]))
    save(fig, tmp_path / "eta.png")
    assert_png_drawn(tmp_path / "eta.png", min_ink=0.2)


def test_pantograph_outputs_against_dx_like_fig_20(tmp_path):
    """pantograph-3d-elgammal-2016.md, Fig. 20: px, py, pz against d_x (28.234 ... 28.334 mm, section 7);
    the rigid model gives px/d_x = Mx = 1 + b/a = 3.5 (eq 9) and no parasitic motion."""
    path = tmp_path / "fk.yaml"
    path.write_text(
        "problem: forward_kinematics\nmechanism: {type: pantograph, parameters: {a: 20 mm, b: 50 mm}}\n"
        "inputs: {dx: {from: 28.234 mm, to: 28.334 mm, count: 11}, dy: 0 mm, dz: 0 mm}\n"
    )
    fig, kind = figure(from_result(cn.solve(cn.load_problem(path))))
    assert kind == "io" and fig.axes[0].get_xlabel() == "$d_{x}$ (mm)"
    px = fig.axes[0].lines[0]
    slope = np.polyfit(px.get_xdata(), px.get_ydata(), 1)[0]
    assert slope == pytest.approx(3.5, rel=1e-6)
    # no parasitic motion: py, pz and phi are exact zeros (and the file's yA, zA, phiB: the sliders of
    # dy, dz and the second U's turn), said in the title, not drawn as flat panels
    title = fig._suptitle.get_text().replace("\n", " ")
    assert "constant over the batch: py = 0 mm, pz = 0 mm, yA = 0 mm, zA = 0 mm, phi = 0 deg, phiB = 0 deg" in title
    # the paper's px, theta1, theta2, and the file's own joints that move: the slider xB (= dx), the
    # parallelogram's angles psiD, psiB (= psi, eq 17)
    labels = [ax.get_ylabel() for ax in fig.axes]
    assert labels == ["$px$ (mm)", "$xB$ (mm)", r"$\theta_{1}$ (deg)", r"$\theta_{2}$ (deg)"] + [
        "psiD (deg)",
        "psiB (deg)",
    ]
    assert_figure_readable(fig)
