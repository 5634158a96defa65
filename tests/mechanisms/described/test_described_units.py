"""Issue 21, items 4 and 7: units wherever a number is written in a mechanism file, one rule
for dimensions (docs/site/guide/mechanism-files.md, "Units and dimensions"), derived vectors
reported as vectors, and ``cpm-nlp describe`` on a mechanism file.

The unit factors are checked against numbers written here (1 deg = pi/180 rad, 1 inch =
25.4 mm exactly), not against the code's own tables; a file written with units must give the
same closure as the same file written in bare SI numbers (and as the shipped five-bar)."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
import yaml

import cpm_nlp as cn
from cpm_nlp.core.result import Status
from cpm_nlp.mechanisms import described
from cpm_nlp.mechanisms.described import expr as ex
from tests.conftest import ROOT

MECH = ROOT / "problems" / "mechanisms"

STAGE = """
name: {name}
parameters:
  l: {{dimension: length, default: 73.5 mm, bounds: [0 m, 1 m], description: leg length}}
derived: {{}}
platform:
  coordinates: {{x: length, y: length, z: length}}
  position: [x, y, z]
  rotation: []
  task: [x, y, z]
legs:
  - name: limb1
    joints:
      - {{type: P, at: [0, 0, 0], axis: [-1, 0, 0], actuated: q1, range: [0 um, 100 um]}}
      - {{type: distance, at: [0, 0, 0], to: [l, 0, 0]}}
  - name: limb2
    joints:
      - {{type: P, at: [0, 0, 0], axis: [0, -1, 0], actuated: q2}}
      - {{type: distance, at: [0, 0, 0], to: [0, l, 0]}}
  - name: limb3
    joints:
      - {{type: P, at: [0, 0, 0], axis: [0, 0, -1], actuated: q3}}
      - {{type: distance, at: [0, 0, 0], to: [0, 0, l]}}
"""


def _stage(name: str) -> dict:
    return yaml.safe_load(STAGE.format(name=name))


def _write(tmp_path, data: dict, file: str = "m.yaml"):
    f = tmp_path / file
    f.write_text(yaml.safe_dump(data, sort_keys=False))
    return f


def _load(tmp_path, data: dict, file: str = "m.yaml"):
    return described.load_file(_write(tmp_path, data, file))


def _error(tmp_path, data: dict, *parts: str) -> str:
    f = _write(tmp_path, data)
    with pytest.raises(cn.InputError) as info:
        described.load_file(f)
    msg = str(info.value)
    assert str(f) in msg, msg
    for part in parts:
        assert part in msg, msg
    return msg


def _model(mech):
    return mech.model(mech.closure(), {}, {}, ())


# -- units inside expressions ----------------------------------------------------------------


@pytest.mark.parametrize(
    ("text", "si", "dim"),
    [
        ("l + 3 mm", 0.1 + 0.003, ex.LENGTH),
        ("th0 + 1 deg", 0.5 + math.pi / 180, ex.ANGLE),
        ("-22.22 mm", -0.02222, ex.LENGTH),
        ("1.5e3 um", 1.5e-3, ex.LENGTH),
        ("1e-3m", 1e-3, ex.LENGTH),
        ("2 inch", 2 * 0.0254, ex.LENGTH),  # through pint: 1 inch = 25.4 mm exactly
        ("30 arcmin", 0.5 * math.pi / 180, ex.ANGLE),
        ("(3 mm)^2", 9e-6, (2.0, 0.0)),
        ("l/(2 mm)", 0.1 / 0.002, ex.NUMBER),
        ("th0 + pi/2", 0.5 + math.pi / 2, ex.ANGLE),  # an angle plus a plain number: radians
        ("pi - th0", math.pi - 0.5, ex.ANGLE),
        ("l + 0", 0.1, ex.LENGTH),  # 0 needs no unit
        ("2*l", 0.2, ex.LENGTH),
    ],
)
def test_numbers_with_units_are_si_values_of_their_dimension(text, si, dim):
    env = {"l": ex.Value(ex.ca.SX(0.1), ex.LENGTH), "th0": ex.Value(ex.ca.SX(0.5), ex.ANGLE)}
    v = ex.parse(text, env)
    assert float(ex.ca.DM(v.sx)) == pytest.approx(si, rel=1e-15)
    assert v.dim == dim


@pytest.mark.parametrize(
    ("text", "column", "words"),
    [
        ("l + 1 deg", 1, ["cannot add a length and an angle"]),
        ("l + cos(th0)", 1, ["cannot add a length and a plain number"]),
        ("3 mn", 1, ["'mn' after the number 3 is not a unit of length or angle", "did you mean '3 m"]),
        ("2 pi", 1, ["a product is written 2*pi"]),
        ("2 sin(th0)", 1, ["a product is written 2*sin(...)"]),
        ("3 mm^2", 1, ["ambiguous", "(3 mm)^2"]),
        ("1 GPa", 1, ["'1 GPa' is a stress", "takes lengths", "and angles"]),
        ("1e999 mm", 1, ["beyond the largest float"]),
    ],
)
def test_bad_units_name_the_column(text, column, words):
    env = {"l": ex.Value(ex.ca.SX.sym("l"), ex.LENGTH), "th0": ex.Value(ex.ca.SX.sym("t"), ex.ANGLE)}
    with pytest.raises(ex.ExpressionError) as info:
        ex.parse(text, env)
    assert info.value.column == column, info.value
    for w in words:
        assert w in info.value.message


def test_names_in_skips_numbers_with_units():
    assert ex.names_in("l1 + 3 mm*cos(th0 + 1 deg)") == {"l1", "th0"}


# -- units in a mechanism file (the issue's three cases) ---------------------------------------


def test_units_where_the_issue_found_syntax_errors(tmp_path):
    """bounds: [-1.2 m, 1.2 m], home: [-22.22 mm] and '1 deg' in derived all load, in SI."""
    data = _stage("units_issue")
    data["platform"]["bounds"] = {"x": ["-1.2 m", "1.2 m"], "y": ["-12 mm", "12 mm"]}
    data["derived"] = {"tilt": "1 deg", "h": {"value": "l + 3 mm", "dimension": "length"}}
    data["legs"][0]["joints"][0]["home"] = ["-22.22 mm"]
    model = _model(_load(tmp_path, data))
    c = model.closure
    assert model.x_lower[c.x_names.index("x")] == -1.2 and model.x_upper[c.x_names.index("x")] == 1.2
    assert model.x_lower[c.x_names.index("y")] == pytest.approx(-0.012, rel=1e-15)
    assert model.q_home[0] == pytest.approx(-0.02222, rel=1e-15)
    assert model.derived["tilt"] == pytest.approx(math.pi / 180, rel=1e-15)
    assert model.derived["h"] == pytest.approx(0.0765, rel=1e-15)
    assert model.dimensions["tilt"] == "angle" and model.dimensions["h"] == "length"


def test_a_file_with_units_is_the_file_in_si(tmp_path):
    """The same stage written in bare SI numbers and with units: the same closure (to 1e-15)."""
    si = _stage("stage_si")
    si["legs"][0]["joints"][1].update({"at": [0.001, 0, 0], "to": [0.0745, 0, 0]})
    units = _stage("stage_units")
    units["legs"][0]["joints"][1].update({"at": ["1 mm", 0, 0], "to": ["l + 1 mm", 0, 0]})
    a, b = _model(_load(tmp_path, si, "si.yaml")), _model(_load(tmp_path, units, "units.yaml"))
    rng = np.random.default_rng(21)
    for _ in range(20):
        x, q = rng.normal(scale=1e-3, size=3), rng.normal(scale=1e-4, size=3)
        pa = np.asarray(a.closure.phi(x, q, a.p), dtype=float)
        pb = np.asarray(b.closure.phi(x, q, b.p), dtype=float)
        np.testing.assert_allclose(pb, pa, rtol=0, atol=1e-15)


def test_shipped_five_bar_with_degrees_equals_the_shipped_file(tmp_path):
    """five_bar.yaml with its crank home written '180 deg - th0' instead of 'pi - th0': the same
    reference configuration and FK as the shipped file (1e-12)."""
    text = (MECH / "five_bar.yaml").read_text().replace("name: five_bar", "name: five_bar_deg")
    text = text.replace("home: [pi - th0]", "home: [180 deg - th0]").split("examples:")[0]
    f = tmp_path / "five_bar_deg.yaml"
    f.write_text(text)
    ours, shipped = _model(described.load_file(f)), _model(described.load_file(MECH / "five_bar.yaml"))
    assert ours.q_home[0] == pytest.approx(math.pi - math.radians(60), rel=1e-15)
    np.testing.assert_allclose(ours.q_home, shipped.q_home, rtol=0, atol=1e-15)
    newton = cn.SolverConfig("newton")
    for dq in ([0.01, -0.02], [-0.05, 0.03]):
        q = shipped.q_home + np.array(dq)
        a, b = cn.forward_kinematics(ours, q, newton), cn.forward_kinematics(shipped, q, newton)
        assert a.status == b.status == Status.SOLVED
        np.testing.assert_allclose(a.x, b.x, rtol=0, atol=1e-12)


# -- one rule for dimensions --------------------------------------------------------------------


def test_a_declared_dimension_is_the_values_dimension(tmp_path):
    """A derived vector of bare numbers declared a length adds to lengths; a derived 0.01
    declared an angle does not (the issue's two disagreeing checks)."""
    data = _stage("declared_length")
    data["derived"] = {"P": {"value": [0.02, 0, 0], "dimension": "length"}}
    data["legs"][0]["joints"][1]["to"] = "P + [l - 20 mm, 0, 0]"
    model = _model(_load(tmp_path, data))
    assert model.derived["P"] == [0.02, 0.0, 0.0]
    data = _stage("declared_numbers")  # numbers only, dimensionless on their face: SI where declared
    data["derived"] = {"P": {"value": "unit([1, 0, 0])*0.0735", "dimension": "length"}}
    data["legs"][0]["joints"][1]["to"] = "P + [l - l, 0, 0]"
    assert _model(_load(tmp_path, data)).derived["P"] == [0.0735, 0.0, 0.0]
    data = _stage("declared_angle")
    data["derived"] = {"s": {"value": 0.01, "dimension": "angle"}}
    data["legs"][0]["joints"][1]["to"] = "[l + s, 0, 0]"
    _error(tmp_path, data, "legs[0].joints[1].to", "cannot add a length and an angle")


def test_a_bare_number_in_a_sum_is_si_of_what_it_is_added_to(tmp_path):
    """A bare number is SI wherever it stands (as in a problem file, and as files written
    before units were allowed in expressions): l + 0.001 is l + 1 mm, th0 + 0.1 is th0 + 0.1 rad,
    a derived 0.01 without a dimension added to a length is 10 mm; a vector of bare numbers
    added to a vector of lengths is in metres (Dietmaier's B + [0, 0, h])."""
    env = {"l": ex.Value(ex.ca.SX(0.1), ex.LENGTH), "th0": ex.Value(ex.ca.SX(0.5), ex.ANGLE)}
    for text, si, dim in [
        ("l + 0.001", 0.101, ex.LENGTH),
        ("th0 + 0.1", 0.6, ex.ANGLE),
        ("min(l, 0.01)", 0.01, ex.LENGTH),
        ("([l, 0, 0] + [0.01, 0, 0])[0]", 0.11, ex.LENGTH),
    ]:
        v = ex.parse(text, env)
        assert float(ex.ca.DM(v.sx)) == pytest.approx(si, rel=1e-15) and v.dim == dim, text
    data = _stage("bare_sum")
    data["legs"][0]["joints"][1]["to"] = ["l + 0.001", 0, 0]
    with_bare = _model(_load(tmp_path, data))
    data = _stage("unit_sum")
    data["legs"][0]["joints"][1]["to"] = ["l + 1 mm", 0, 0]
    with_unit = _model(_load(tmp_path, data))
    rng = np.random.default_rng(22)
    for _ in range(5):
        x, q = rng.normal(scale=1e-3, size=3), rng.normal(scale=1e-4, size=3)
        pa = np.asarray(with_bare.closure.phi(x, q, with_bare.p), dtype=float)
        pb = np.asarray(with_unit.closure.phi(x, q, with_unit.p), dtype=float)
        np.testing.assert_allclose(pa, pb, rtol=0, atol=1e-15)
    data = _stage("bare_undeclared")  # a derived number without a dimension is a bare number
    data["derived"] = {"s": 0.01}
    data["legs"][0]["joints"][1]["to"] = "[l + s, 0, 0]"
    assert _model(_load(tmp_path, data)).derived["s"] == 0.01


def test_a_bare_number_standing_alone_is_si(tmp_path):
    """As in a problem file: home 0.01 of a length coordinate is 10 mm; a vector element 0.02 m."""
    data = _stage("bare_alone")
    data["platform"]["bounds"] = {"x": [-0.5, 0.5]}
    data["legs"][0]["joints"][0]["home"] = [0.01]
    model = _model(_load(tmp_path, data))
    assert model.q_home[0] == 0.01 and model.x_upper[0] == 0.5


@pytest.mark.parametrize(
    ("section", "value", "words"),
    [
        ("platform", {"bounds": {"x": ["-1 deg", "1 deg"]}}, ["platform.bounds.x[0]", "expected a length"]),
        ("derived", {"h": {"value": "1 deg", "dimension": "length"}}, ["derived.h", "expected a length"]),
        ("derived", {"h": "l + 3 mn"}, ["derived.h", "column 5", "did you mean '3 m"]),
        ("derived", {"h": "2 N"}, ["derived.h", "'2 N' is a force"]),
        ("parameters", {"w": {"dimension": "length", "default": "2 deg"}}, ["parameters.w.default", "not a length"]),
    ],
)
def test_wrong_units_in_a_file(tmp_path, section, value, words):
    data = _stage("wrong_units")
    data[section].update(value)
    _error(tmp_path, data, *words)


def test_a_gain_is_a_plain_number(tmp_path):
    data = _stage("gain_unit")
    data["legs"][0]["joints"][0]["gain"] = "2 mm"
    _error(tmp_path, data, "legs[0].joints[0].gain", "expected a plain number, got a length")


def test_every_shipped_file_loads_unchanged():
    for f in described.shipped_files():
        assert described.load_file(f).name


def test_cli_bad_unit_is_exit_2_with_one_line(tmp_path, cli):
    data = _stage("cli_bad_unit")
    data["legs"][0]["joints"][1]["to"] = ["l + 1 deg", 0, 0]
    f = _write(tmp_path, data)
    run = cli("describe", str(f))
    assert run.code == 2 and run.out == ""
    assert "Traceback" not in run.err and run.err.strip().count("\n") <= 1, run.err
    assert str(f) in run.err and "legs[0].joints[1].to" in run.err and "cannot add a length and an angle" in run.err


# -- derived vectors are reported as vectors ---------------------------------------------------------


def _vector_stage(tmp_path):
    data = _stage("derived_vectors")
    data["derived"] = {
        "P1": {"value": "[l, 11.52 mm, 0]", "dimension": "length"},
        "P2": {"value": [0.01, 0.02, 0.03], "dimension": "length"},
        "s": {"value": "1 deg", "dimension": "angle"},
    }
    f = _write(tmp_path, data, "vectors.yaml")
    p = tmp_path / "fk.yaml"
    p.write_text(
        "problem: forward_kinematics\nmechanism: {file: vectors.yaml}\n"
        "inputs: {q1: 10 um, q2: 5 um, q3: 0 um}\nsolver: newton\n"
    )
    return f, p


def test_derived_vectors_keep_their_names_in_the_model(tmp_path):
    f, _p = _vector_stage(tmp_path)
    model = _model(described.load_file(f))
    assert model.derived["P1"] == pytest.approx([0.0735, 0.01152, 0.0], rel=1e-15)
    assert model.derived["P2"] == [0.01, 0.02, 0.03]
    assert model.derived["s"] == pytest.approx(math.pi / 180, rel=1e-15)  # not P1's y, as before


def test_derived_vectors_in_solve_output_and_json(tmp_path, cli):
    _f, p = _vector_stage(tmp_path)
    run = cli("solve", str(p))
    assert run.code == 0, run.err
    assert "P1 = [0.0735, 0.01152, 0], P2 = [0.01, 0.02, 0.03], s = 0.0174533" in run.out
    run = cli("solve", str(p), "--json")
    model = json.loads(run.out)["model"]
    assert model["P1"] == pytest.approx([0.0735, 0.01152, 0.0]) and model["P2"] == [0.01, 0.02, 0.03]


def test_derived_vectors_in_the_export_manifest(tmp_path, cli):
    _f, p = _vector_stage(tmp_path)
    run = cli("export", str(p), "--what", "fk", "--out", str(tmp_path / "out"))
    assert run.code == 0, run.err
    manifest = json.loads((tmp_path / "out" / "manifest.json").read_text())
    derived = manifest["mechanism"]["derived"]
    assert derived["P2"] == {"value": [0.01, 0.02, 0.03], "unit": "m"}
    assert derived["s"]["unit"] == "rad"


def test_a_derived_vector_that_is_not_finite_is_named(tmp_path):
    data = _stage("vector_nan")
    data["derived"] = {"P": {"value": "[l, sqrt(l^2 - (1 m)^2), 0]", "dimension": "length"}}
    _error(tmp_path, data, "derived.P", "sqrt of a negative number", "l = 73.5 mm", "l^2 - (1 m)^2 = -0.9946 m^2")


#: the five-bar XY stage of the file-mechanism tutorial, with a coupler too short to reach
_SHORT_COUPLER = """
name: xy_short
parameters:
  d:  {dimension: length, default: 40 mm, bounds: [1 mm, 1 m]}
  l1: {dimension: length, default: 30 mm, bounds: [1 mm, 1 m]}
  l2: {dimension: length, default: 20 mm, bounds: [1 mm, 1 m]}
  th0: {dimension: angle, default: 60 deg, bounds: [10 deg, 90 deg]}
derived:
  cx: {value: d/2 + l1*cos(th0), dimension: length}
  cy: {value: l1*sin(th0), dimension: length}
  y0: {value: "cy + sqrt(l2^2 - cx^2)", dimension: length}
platform:
  planar: true
  coordinates: {x: length, y: length}
  position: [x, y]
  rotation: []
  task: [x, y]
  home: {y: y0}
legs:
  - name: left
    joints:
      - {type: planar_R, at: [-d/2, 0], actuated: q1, home: [pi - th0]}
      - {type: planar_R, at: [-cx, cy], coordinates: [e1]}
      - {type: planar_R, at: [0, y0]}
  - name: right
    joints:
      - {type: planar_R, at: [d/2, 0], actuated: q2, home: [th0]}
      - {type: planar_R, at: [cx, cy], coordinates: [e2]}
      - {type: planar_R, at: [0, y0]}
"""


def test_a_derived_parameter_that_becomes_nan_is_named_with_the_operation_and_its_value(tmp_path):
    """Issue 24: not "residual nan ... max |Phi| = nan" but which derived parameter, its expression,
    the operation (the square root in y0's expression) and the value it was given."""
    d, l1, l2, th0 = 40e-3, 30e-3, 20e-3, math.radians(60)
    cx, cy = d / 2 + l1 * math.cos(th0), l1 * math.sin(th0)  # by hand, not by the toolkit
    radicand = l2**2 - cx**2
    assert radicand < 0
    msg = _error(
        tmp_path,
        yaml.safe_load(_SHORT_COUPLER),
        "derived.y0",
        "'cy + sqrt(l2^2 - cx^2)'",
        "column 6: sqrt of a negative number",
        f"l2^2 - cx^2 = {radicand:.4g} m^2",
        f"l2 = 20 mm, cx = {cx * 1e3:g} mm, cy = {cy * 1e3:.6g} mm",
    )
    assert "residual" not in msg and "|" not in msg


# -- describe ---------------------------------------------------------------------------------


def test_describe_file_prints_derived_legs_loops_and_mobility(tmp_path, cli):
    f, _p = _vector_stage(tmp_path)
    run = cli("describe", str(f))
    assert run.code == 0, run.err
    out = run.out
    assert "P1       = [73.5 mm, 11.52 mm, 0 mm]" in out
    assert "leg limb1: ground -> limb1_link1 -> limb1_rod -> platform" in out
    # the expanded graph (issue 21): bodies, joints, loops, both mobility counts, the assembly
    assert "limb1_rod  points: limb1_j2, limb1_j2_end" in out
    assert "loop 1, closed by limb1_j2_end: limb1_rod - limb1_link1 - ground - platform  (3 equation(s))" in out
    assert "3 degree(s) of freedom; Grübler-Kutzbach: 3; actuated: 3 (q1, q2, q3)" in out
    assert "reference configuration: assembled from the drawing in 0 Gauss-Newton step(s)" in out
    assert "1. P         at [0 mm, 0 mm, 0 mm]  axis [-1, 0, 0]  actuated: q1" in out
    assert "2. distance  at [0 mm, 0 mm, 0 mm]  to [73.5 mm, 0 mm, 0 mm]" in out
    assert "leg limb1: 1 equation(s): distance" in out
    assert "rank Φ_x = 3, rank [Φ_x Φ_q] = 3: 3 degree(s) of freedom" in out


def test_describe_shipped_prs3_lists_hinges_and_its_example_values(cli):
    run = cli("describe", str(MECH / "prs3.yaml"))
    assert run.code == 0, run.err
    assert "prs3_forward_kinematics.yaml" in run.out  # the model's values come from its first example
    assert "coordinates: alpha1  hinge: revolute (circular_notch_paros_weisbord)" in run.out
    assert "coordinates: beta_m1, beta_n1, beta_l1  hinge: spherical (filleted_rod)" in run.out
    assert "leg leg1: 2 equation(s): plane of the R joint; radius about the R joint" in run.out
    assert "task pz, psi, theta; dependent px, py, phi" in run.out


def test_describe_pantograph_file_lists_bodies_joints_and_loops(cli):
    """The shipped pantograph is bodies and joints (issue 21): describe lists its loops; with the
    paper's R hinges at C and F (tests/corpus/pantograph_joints.yaml) it says that Grübler-Kutzbach
    (-1, as the paper's section 2 says: "negative") and the rank (3) disagree."""
    run = cli("describe", str(MECH / "pantograph.yaml"))
    assert run.code == 0, run.err
    assert "loop 1, closed by J8: L1 - Az - Ay - ground - Bx - L3" in run.out
    assert "3 degree(s) of freedom; Grübler-Kutzbach: 3" in run.out and "the two disagree" not in run.out
    run = cli("describe", str(ROOT / "tests" / "corpus" / "pantograph_joints.yaml"))
    assert run.code == 0, run.err
    assert "3 degree(s) of freedom; Grübler-Kutzbach: -1" in run.out and "the two disagree" in run.out


def test_describe_kind_takes_a_mechanism_file(tmp_path, cli):
    from cpm_nlp.mechanisms.registry import mechanism_names

    before = mechanism_names()
    f, _p = _vector_stage(tmp_path)
    run = cli("describe", "forward_kinematics", "--mechanism", str(f))
    assert run.code == 0, run.err
    assert "mechanism: derived_vectors" in run.out and "q1" in run.out
    assert mechanism_names() == before  # described on its own model, not registered (issue 22, item 3)


def test_describe_kind_with_a_bad_mechanism_file_is_exit_2(tmp_path, cli):
    data = _stage("bad_for_kind")
    data["derived"] = {"h": "l + 3 mn"}
    f = _write(tmp_path, data)
    run = cli("describe", "jacobian", "--mechanism", str(f))
    assert run.code == 2 and "Traceback" not in run.err
    assert str(f) in run.err and "derived.h" in run.err and "did you mean '3 m" in run.err
    run = cli("describe", "jacobian", "--mechanism", str(tmp_path / "missing.yaml"))
    assert run.code == 2 and "missing.yaml" in run.err


def test_describe_plot_draws_the_body_graph(tmp_path, cli):
    from cpm_nlp.mechanisms.described.summary import body_graph

    nodes, edges = body_graph(described.read_description(MECH / "prs3.yaml"))  # the expanded graph's
    assert nodes == ["ground", *[f"leg{k}_link{n}" for k in (1, 2, 3) for n in (1, 2)], "platform"]
    assert [e for e in edges if e[3]] == [("ground", f"leg{k}_link1", f"leg{k}_j1 P s{k}", True) for k in (1, 2, 3)]
    assert [e[2] for e in edges if e[1] == "platform"] == [f"leg{k}_j3 S" for k in (1, 2, 3)]
    out = tmp_path / "graph.png"
    run = cli("describe", str(MECH / "prs3.yaml"), "--plot", str(out))
    assert run.code == 0, run.err
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and f"body graph: {out}" in run.out


@pytest.mark.parametrize(
    ("args", "words"),
    [
        (("prs3", "--plot", "g.png"), ["--plot", "expected a mechanism file", "'prs3'"]),
        ((str(MECH / "prs3.yaml"), "--plot", "g.html"), ["--plot", "expected a .png, .svg or .pdf"]),
        ((str(MECH / "prs3.yaml"), "--plot", "g.txt"), ["--plot", "expected a figure file"]),
    ],
)
def test_describe_plot_bad_arguments_are_exit_2(tmp_path, cli, args, words):
    run = cli("describe", *[str(tmp_path / a) if a.startswith("g.") else a for a in args])
    assert run.code == 2 and run.out == "" and "Traceback" not in run.err
    for w in words:
        assert w in run.err, run.err
    assert not list(tmp_path.iterdir())


@pytest.mark.parametrize(
    "file, where, value, message",
    [
        (MECH / "five_bar.yaml", ("platform", "task", 0), [1, 2], "platform.task[0]: unknown coordinate [1, 2]"),
        (MECH / "prs3.yaml", ("platform", "offsets", "dz"), {"q": 1}, "expected a pose coordinate, got {'q': 1}"),
        (ROOT / "tests/data/graph/fourbar.yaml", ("platform", "task", 0), [[1]], "unknown coordinate [[1]]"),
        (ROOT / "tests/data/graph/fourbar.yaml", ("bodies", "crank", 1), [1], "bodies.crank[1]: unknown point [1]"),
        (MECH / "rpr.yaml", ("passive", "theta_a11", "family"), [1], "family: expected a joint-limit family"),
        (MECH / "prs3.yaml", ("ik", "let", "AB1"), [1, 2], "dot() takes two vectors of one size, got 3 and 2"),
        # a = 7 m puts the coupler's drawn point out of reach (the square root of a negative number)
        (ROOT / "tests/data/graph/fourbar.yaml", ("parameters", "a", "default"), 7, "does not assemble"),
    ],
)
def test_a_list_where_a_name_belongs_is_an_input_error(file, where, value, message):
    """A list or mapping where the file names a coordinate, a point or a limit family, a vector
    of the wrong size in dot(), a drawing with no value: one message at its key path (each was a
    traceback: a TypeError from a lookup, a CasADi assertion, numpy's SVD of NaN)."""
    data = yaml.safe_load(file.read_text())
    node = data
    for key in where[:-1]:
        node = node[key]
    node[where[-1]] = value
    with pytest.raises(cn.InputError) as info:
        described.from_dict(data, file="f.yaml")
    assert message in str(info.value), str(info.value)
