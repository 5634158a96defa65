"""Legs as a shorthand that expands into bodies and joints (issue 21, item 1 last bullet).

For every legs file shipped (problems/mechanisms) and in tests/corpus: the expanded graph
(:func:`cpm_nlp.mechanisms.described.expand.expand_legs`, read by the graph generator) has the
legs file's mobility -- by the loops' rank at the reference configuration and by Grübler-Kutzbach
-- and its forward kinematics equals the legs generator's to 1e-10 at several poses, the passive
joint values too where a name maps (a legs coordinate that is a tree joint's value or a loop-closing
joint's reported value in the graph).  The two closures are written independently (elimination
of each leg's passive joints against a spanning tree with every joint's value an unknown), so
agreement is a check of both.  Consistency checks, no published figures.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import cpm_nlp as cn
from cpm_nlp.core.errors import InputError
from cpm_nlp.core.result import Status
from cpm_nlp.io.yamlfile import read_yaml
from cpm_nlp.mechanisms import described
from cpm_nlp.mechanisms.described import load_file, read_description
from cpm_nlp.mechanisms.described.closure import closure_parts
from cpm_nlp.mechanisms.described.expand import expand_legs, expansion_gap
from cpm_nlp.mechanisms.described.read import description_from_dict

ROOT = Path(__file__).resolve().parents[3]
LEGS_FILES = sorted(
    f
    for f in [*(ROOT / "problems" / "mechanisms").glob("*.yaml"), *(ROOT / "tests" / "corpus").glob("*.yaml")]
    if read_description(f).legs
)
NEWTON = cn.SolverConfig("newton")
#: the FK of both closures on CasADi's virtual machine: the comparison is of the closures, and
#: compiling each file's two kernels took nearly all the time (Dietmaier's 6-6: 23 of 24 s,
#: issue 23); the backends' agreement is tests/core/test_batch.py's
MAP = "map"
TOL = 1e-10


def _parameters(path: Path, d) -> dict:
    """The parameters of the file's first example (its required parameters have no default)."""
    if not d.examples:
        return {}
    example = read_yaml((path.parent / d.examples[0]).resolve())
    return dict((example.get("mechanism") or {}).get("parameters") or {})


def _models(path: Path):
    d = read_description(path)
    gap = expansion_gap(d)
    if gap is not None:
        pytest.skip(f"{path.name}: no bodies-and-joints equivalent yet: {gap}")
    mech = load_file(path)
    legs = mech.model(mech.closure(), _parameters(path, d), {}, ())
    values = dict(zip(legs.closure.parameters, np.asarray(legs.p, dtype=float)))
    e = expand_legs(d, values)
    gmech = described.mechanism(e)
    graph = gmech.model(gmech.closure(), values, {}, ())
    return d, e, legs, graph


def _close(a, b, tol=TOL):
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    np.testing.assert_allclose(a, b, rtol=0, atol=tol * max(1.0, float(np.max(np.abs(b))) if b.size else 1.0))


def _inputs(model: cn.Model, n: int = 4) -> np.ndarray:
    """Actuator values around the reference: lengths within 0.2% of the characteristic length,
    angles within 0.005 rad (seeded)."""
    rng = np.random.default_rng(21)
    scale = np.array([2e-3 * model.characteristic_length if c.kind == "length" else 5e-3 for c in model.closure.q])
    return model.q_home + rng.uniform(-1, 1, (n, len(scale))) * scale


@pytest.mark.parametrize("path", LEGS_FILES, ids=lambda p: p.name)
def test_expanded_graph_has_the_legs_mobility_and_forward_kinematics(path):
    d, e, legs, graph = _models(path)
    gen, _fns = closure_parts(e)
    nq = len(legs.closure.q_names)
    # mobility: the legs' (nx + nq - rank [Φ_x Φ_q] at the reference) and the graph's by rank
    c = legs.closure
    J = np.hstack(
        [np.asarray(c.phi_x(legs.x_home, legs.q_home, legs.p)), np.asarray(c.phi_q(legs.x_home, legs.q_home, legs.p))]
    )
    assert c.nx + c.nq - np.linalg.matrix_rank(J) == nq
    assert gen.info.mobility == nq
    assert gen.info.gruebler == nq  # no leg file is overconstrained: the two counts agree
    assert list(graph.closure.q_names) == list(c.q_names)
    names = list(graph.closure.x_names)
    idx = [names.index(n) for n in c.x_names if n in names]
    assert [names[k] for k in idx[: len(d.platform.coordinates)]] == [
        n for n in d.platform.coordinates if n not in d.platform.fixed
    ]
    _close(np.asarray(graph.x_home)[idx], np.asarray(legs.x_home)[: len(idx)], 1e-15)
    _close(graph.q_home, legs.q_home, 1e-15)
    for q in _inputs(legs):
        a, b = cn.forward_kinematics(legs, q, NEWTON, backend=MAP), cn.forward_kinematics(graph, q, NEWTON, backend=MAP)
        assert a.status == b.status == Status.SOLVED, (a.message, b.message)
        xa, xb = np.asarray(a.x), np.asarray(b.x)
        _close(xb[idx], xa[: len(idx)])
        # the task Jacobian dx/dq (AD on each closure) of the coordinates both have
        Ja = np.asarray(legs.closure.jacobian(xa, q, legs.p))
        Jb = np.asarray(graph.closure.jacobian(xb, q, graph.p))
        _close(Jb[idx], Ja[: len(idx)], 1e-8)
        # passive joint values where a name maps: the graph's unknowns and its reported values
        pa = cn.passive_joints(legs, xa, q)
        pb = dict(zip(names, xb)) | cn.passive_joints(graph, xb, q)
        shared = [n for n in pa if n in pb]
        _close([pb[n] for n in shared], [pa[n] for n in shared])


def test_every_legs_file_maps_its_platform_and_some_passive_values():
    """The comparison above is not empty: the platform coordinates always map, and the shipped
    files' named joint values do (prs3: alpha_i, beta_*i; rpr: none named, its passive are expressions)."""
    path = ROOT / "problems" / "mechanisms" / "prs3.yaml"
    _d, _e, legs, graph = _models(path)
    q = _inputs(legs, 1)[0]
    a, b = cn.forward_kinematics(legs, q, NEWTON, backend=MAP), cn.forward_kinematics(graph, q, NEWTON, backend=MAP)
    pa = cn.passive_joints(legs, np.asarray(a.x), q)
    pb = dict(zip(graph.closure.x_names, np.asarray(b.x))) | cn.passive_joints(graph, np.asarray(b.x), q)
    wanted = {f"{f}{i}" for f in ("alpha", "beta_m", "beta_n", "beta_l") for i in (1, 2, 3)}
    assert wanted <= set(pa) & set(pb)
    assert max(abs(pa[n]) for n in wanted if n.startswith("beta")) > 1e-4  # the poses move the joints
    # the graph's AD Jacobian dx/dq against central differences of its FK
    h = 1e-7
    J = np.asarray(graph.closure.jacobian(b.x, q, graph.p))
    for k in range(len(q)):
        step = np.zeros(len(q))
        step[k] = h
        up, down = (cn.forward_kinematics(graph, q + s, NEWTON, guess=b.x, backend=MAP) for s in (step, -step))
        _close((np.asarray(up.x) - np.asarray(down.x)) / (2 * h), J[:, k], 1e-6)


def test_expanded_bodies_and_joints():
    """prs3: the ground, three links per leg (slider, leg) and the platform; each leg's P, R, S in
    order, the P actuated; the platform placed by its six coordinates."""
    e = expand_legs(read_description(ROOT / "problems" / "mechanisms" / "prs3.yaml"), {"b": 0.04791, "L": 0.109215})
    assert [b.name for b in e.bodies] == [
        "ground",
        "leg1_link1",
        "leg1_link2",
        "leg2_link1",
        "leg2_link2",
        "leg3_link1",
        "leg3_link2",
        "platform",
    ]
    assert [(j.name, j.type, j.between, j.actuated) for j in e.joints[:3]] == [
        ("leg1_j1", "P", ("ground", "leg1_link1"), "s1"),
        ("leg1_j2", "R", ("leg1_link1", "leg1_link2"), None),
        ("leg1_j3", "S", ("leg1_link2", "platform"), None),
    ]
    assert e.joints[1].coordinates == ("alpha1",) and e.joints[2].coordinates == ("beta_m1", "beta_n1", "beta_l1")
    gen, _fns = closure_parts(e)
    assert [(n, t, a, b) for n, t, a, b, *_ in gen.info.joints][0] == ("platform_pose", "pose", "ground", "platform")
    assert [loop[1] for loop in gen.info.loops] == ["leg1_j3", "leg2_j3", "leg3_j3"]


def test_distance_joint_becomes_a_rod_and_ss_link_a_u():
    """A distance joint is a rod (U at `at` across the rod, S at `to`); the RPR's S-P-S legs get a U
    at the base: the spin the legs generator never writes stays out of the mobility."""
    delta = expand_legs(read_description(ROOT / "problems" / "mechanisms" / "delta.yaml"))
    assert [(j.name, j.type, j.between) for j in delta.joints[:3]] == [
        ("arm1_j1", "R", ("ground", "arm1_link1")),
        ("arm1_j2", "U", ("arm1_link1", "arm1_rod")),
        ("arm1_j2_end", "S", ("arm1_rod", "platform")),
    ]
    rpr_file = read_description(ROOT / "problems" / "mechanisms" / "rpr.yaml")
    rpr = expand_legs(rpr_file, {"r1": 0.04, "r2": 0.08, "P0": 0.04})
    assert [j.type for j in rpr.joints[:3]] == ["U", "P", "S"]


def test_a_legs_feature_without_a_graph_equivalent_is_named():
    """closures and actuators written as expressions have no bodies-and-joints equivalent yet: one
    message that says which."""
    text = {
        "name": "slider",
        "parameters": {"l": {"default": "10 mm"}},
        "platform": {"coordinates": {"x": "length"}, "position": ["x", 0, 0], "rotation": [], "task": ["x"]},
        "legs": [
            {
                "name": "a",
                "joints": [
                    {"type": "P", "at": [0, 0, 0], "axis": [1, 0, 0], "actuated": "q1"},
                    {"type": "S", "at": [0, 0, 0]},
                ],
            }
        ],
        "actuators": {"d": "length"},
        "closures": ["x - d"],
    }
    d = description_from_dict(text)
    with pytest.raises(InputError, match="no bodies-and-joints equivalent yet: its closures are written as expr"):
        expand_legs(d)
    del text["closures"]
    assert "declares actuators without joints" in expansion_gap(description_from_dict(text))


# -- a rough drawing (issue 21, item 3): a rod's given length, the reference assembled ----------


def _delta(z_drawn: str, length: str | None = "lb") -> dict:
    """problems/mechanisms/delta.yaml with its platform drawn at ``z_drawn`` (not the closed form
    z0 = -sqrt(lb^2 - (rb + la - rp)^2)) and its forearms of the given length."""
    data = read_yaml(ROOT / "problems" / "mechanisms" / "delta.yaml")
    data.pop("examples")
    data["name"] = "delta_drawn"
    data["derived"] = {}
    data["platform"]["home"] = {"z": z_drawn}
    rod = {"type": "distance", "at": ["rb + la", 0, 0], "to": ["rp", 0, z_drawn]}
    if length is not None:
        rod["length"] = length
    data["legs"][0]["joints"][1] = rod
    return data


def _z0(lb: float, rb: float = 0.1, la: float = 0.12, rp: float = 0.04) -> float:
    """The Delta's platform height with the arms horizontal (Pythagoras in the leg's plane)."""
    return -np.sqrt(lb**2 - (rb + la - rp) ** 2)


def test_a_rough_drawing_is_assembled_for_any_parameter_value():
    mech = described.from_dict(_delta("-200 mm"), file="delta_drawn.yaml")
    for lb in (0.25, 0.30, 0.40):
        model = mech.model(mech.closure(), {"lb": lb}, {}, ())
        _close(model.x_home, [0.0, 0.0, _z0(lb)], 1e-12)
        _close(model.q_home, [0.0, 0.0, 0.0], 0)
    # the assembled model is the exact file's: FK at other actuator values agrees to 1e-12
    exact = load_file(ROOT / "problems" / "mechanisms" / "delta.yaml")
    a = exact.model(exact.closure(), {}, {}, ())
    b = mech.model(mech.closure(), {}, {}, ())
    for q in _inputs(a):
        sa, sb = cn.forward_kinematics(a, q, NEWTON, backend=MAP), cn.forward_kinematics(b, q, NEWTON, backend=MAP)
        assert sa.status == sb.status == Status.SOLVED
        _close(sb.x, sa.x, 1e-12)


def test_an_exact_drawing_with_lengths_gives_todays_model():
    """The rods' lengths given and the drawing exact: the assembly takes no step and the model is
    the one of the file without lengths (reference to 1e-12, FK to 1e-12)."""
    z0 = f"{_z0(0.25)} m"
    plain = described.from_dict(_delta(z0, None), file="plain.yaml")
    given = described.from_dict(_delta(z0), file="given.yaml")
    a, b = (m.model(m.closure(), {}, {}, ()) for m in (plain, given))
    _close(b.x_home, a.x_home, 1e-12)
    for q in _inputs(a):
        xb, xa = (cn.forward_kinematics(m, q, NEWTON, backend=MAP).x for m in (b, a))
        _close(xb, xa, 1e-12)


def test_links_that_cannot_close_are_refused_with_the_loops_residual():
    mech = described.from_dict(_delta("-200 mm"), file="delta_drawn.yaml")
    with pytest.raises(InputError, match=r"does not assemble from the drawing: .* residual .* in loop \d") as exc:
        mech.model(mech.closure(), {"lb": 0.1}, {}, ())  # shorter than rb + la - rp = 0.18 m
    assert "mechanism" in exc.value.render() or "legs" in exc.value.render()


def test_only_a_distance_joint_has_a_length(tmp_path):
    data = _delta("-200 mm")
    data["legs"][0]["joints"][0]["length"] = "lb"
    with pytest.raises(InputError, match="only a distance joint has 'length'") as exc:
        described.from_dict(data, file="bad.yaml")
    assert exc.value.path == ("legs", 0, "joints", 0, "length")


def test_cli_set_reassembles_and_describe_reports_the_assembly(tmp_path, cli):
    import yaml

    (tmp_path / "delta_drawn.yaml").write_text(yaml.safe_dump(_delta("-200 mm")))
    (tmp_path / "fk.yaml").write_text(
        "problem: forward_kinematics\nmechanism: {file: delta_drawn.yaml}\n"
        "inputs: {q1: 0 deg, q2: 0 deg, q3: 0 deg}\nsolver: newton\n"
    )
    run = cli("solve", str(tmp_path / "fk.yaml"), "--json", "--set", "mechanism.parameters.lb=300mm")
    assert run.code == 0, run.err
    import json

    x = json.loads(run.out)["values"]
    assert x["z"] == pytest.approx(_z0(0.3), abs=1e-12)
    run = cli("describe", str(tmp_path / "delta_drawn.yaml"))
    assert run.code == 0, run.err
    assert "reference configuration: assembled from the drawing in " in run.out
    assert "in 0 Gauss-Newton" not in run.out  # the drawing is rough: steps were taken
    run = cli("solve", str(tmp_path / "fk.yaml"), "--set", "mechanism.parameters.lb=100mm")
    assert run.code == 2 and "Traceback" not in run.err
    assert "does not assemble from the drawing" in run.err and "delta_drawn.yaml" in run.err


# -- mixing (issue 21, item 1): legs and extra bodies and joints in one file --------------------

MIXED = """
name: stage_lever
title: 3-PRC-like stage, limb 1 driven through a lever amplifier (legs and bodies in one file)
parameters:
  l: {default: 73.5 mm, description: leg length}
  a: {default: 5 mm, description: the lever's input arm (pivot O to I)}
  b: {default: 25 mm, description: the lever's output arm (pivot O to T)}
  c: {default: 40 mm, description: the pivot's distance from the slider's axis}
  f: {default: 10 mm, description: the input link J-I}
  e: {default: 10 mm, description: the output link T-K}
platform:
  coordinates: {x: length, y: length, z: length}
  position: [x, y, z]
  rotation: []
  task: [x, y, z]
legs:
  - name: limb1          # its slider is not actuated: the lever drives it
    joints:
      - {type: P, at: [0, 0, 0], axis: [-1, 0, 0], coordinates: [d1], body: slider1}
      - {type: distance, at: [0, 0, 0], to: [l, 0, 0]}
  - name: limb2
    joints:
      - {type: P, at: [0, 0, 0], axis: [0, -1, 0], actuated: q2}
      - {type: distance, at: [0, 0, 0], to: [0, l, 0]}
  - name: limb3
    joints:
      - {type: P, at: [0, 0, 0], axis: [0, 0, -1], actuated: q3}
      - {type: distance, at: [0, 0, 0], to: [0, 0, l]}
points:
  O: [0 m, -c, 0 m]
  T: [0 m, b - c, 0 m]
  K: [-e, b - c, 0 m]
  I: [0 m, -c - a, 0 m]
  J: [-f, -c - a, 0 m]
bodies:
  piezo: [J]
  lever: [O, T, I]
  slider1: [K]           # a bracket on limb 1's slider (a body of the legs)
joints:
  - {type: P, between: [ground, piezo], at: J, axis: [1, 0, 0], actuated: q1}
  - {type: R, between: [ground, lever], at: O, axis: [0, 0, 1], coordinates: [theta]}
  - {type: distance, between: [piezo, lever], at: J, to: I}
  - {type: distance, between: [lever, slider1], at: T, to: K}
"""
#: the stage alone, limb 1's slider actuated: the platform for given slider displacements
STAGE = (
    MIXED.split("points:")[0]
    .replace("name: stage_lever", "name: stage_alone")
    .replace("coordinates: [d1], body: slider1}", "actuated: d1}")
)
A, B, C, F, E = 5e-3, 25e-3, 40e-3, 10e-3, 10e-3


def _lever(q1: float) -> tuple[float, float]:
    """theta and d1 for the piezo at q1, derived here in numpy (plane z = 0): the input link keeps
    |J(q1) - I(theta)| = f with J = (-f + q1, -c - a), I = O + Rz(theta) (0, -a); the output link
    |K(d1) - T(theta)| = e with T = O + Rz(theta) (0, b), K = (-e - d1, b - c)."""
    theta = 0.0
    for _ in range(60):  # Newton on g(theta) = |J - I|^2 - f^2
        ix, iy = A * np.sin(theta), -C - A * np.cos(theta)
        g = (-F + q1 - ix) ** 2 + (-C - A - iy) ** 2 - F**2
        dg = -2 * (-F + q1 - ix) * A * np.cos(theta) + 2 * (-C - A - iy) * (-A * np.sin(theta))
        theta -= g / dg
    tx, ty = -B * np.sin(theta), -C + B * np.cos(theta)
    # -e - d1 - tx = -sqrt(e^2 - (b - c - ty)^2): the root with d1 = 0 at theta = 0
    return theta, -E - tx + np.sqrt(E**2 - (B - C - ty) ** 2)


def test_a_file_with_legs_and_bodies_is_one_graph(tmp_path):
    f = tmp_path / "stage_lever.yaml"
    f.write_text(MIXED)
    mech = load_file(f)
    model = mech.model(mech.closure(), {}, {}, ())
    gen, _fns = closure_parts(read_description(f))
    assert gen.info.mobility == gen.info.gruebler == 3
    bodies = set(gen.info.bodies)
    assert {"ground", "slider1", "limb1_rod", "piezo", "lever", "platform"} <= bodies
    qn = list(model.closure.q_names)
    assert qn == ["q2", "q3", "q1"]  # the legs' actuators, then the file's joints
    (tmp_path / "stage_alone.yaml").write_text(STAGE)
    alone = load_file(tmp_path / "stage_alone.yaml")
    ref = alone.model(alone.closure(), {}, {}, ())
    names = list(model.closure.x_names)
    # first order at the reference: d1 = (b/a) q1, and the platform follows the slider (x = -d1)
    J = np.asarray(model.closure.jacobian(model.x_home, model.q_home, model.p))
    assert J[names.index("x"), qn.index("q1")] == pytest.approx(-B / A, rel=1e-9)
    for q1, q2, q3 in ([2e-4, 0.0, 0.0], [-1e-4, 1e-4, -2e-4], [3e-4, -1e-4, 1e-4]):
        given = {"q1": q1, "q2": q2, "q3": q3}
        sol = cn.forward_kinematics(model, [given[n] for n in qn], NEWTON, backend=MAP)
        assert sol.status == Status.SOLVED, sol.message
        x = np.asarray(sol.x)
        theta, d1 = _lever(q1)
        _close([x[names.index("theta")], x[names.index("d1")]], [theta, d1], TOL)
        stage = cn.forward_kinematics(ref, [d1, q2, q3], NEWTON, backend=MAP)
        assert stage.status == Status.SOLVED
        _close(x[:3], stage.x, TOL)


@pytest.mark.parametrize(
    ("change", "path", "words"),
    [
        (
            lambda t: t.replace("between: [lever, slider1]", "between: [lever, slidr1]"),
            "joints[3].between[1]",
            "slider1",
        ),
        (lambda t: t.replace("position: [x, y, z]", "position: []"), "platform.position", "places its platform"),
        (lambda t: t.replace("coordinates: [d1], body: slider1", "coordinates: [d1], body: ground"), "body", "base"),
        (
            lambda t: t.replace("type: P, between: [ground, piezo]", "type: P, length: 1 mm, between: [ground, piezo]"),
            "joints[0].length",
            "only a distance joint",
        ),
    ],
)
def test_bad_mixed_files_name_the_key(tmp_path, change, path, words):
    f = tmp_path / "stage_lever.yaml"
    f.write_text(change(MIXED))
    with pytest.raises(InputError) as exc:
        mech = load_file(f)
        mech.model(mech.closure(), {}, {}, ())
    text = exc.value.render()
    assert path in text and words in text and "stage_lever.yaml" in text, text


def test_describe_says_why_a_legs_file_has_no_graph_view():
    from cpm_nlp.mechanisms.described.summary import summary_text

    d = read_description(ROOT / "problems" / "mechanisms" / "prs3.yaml")  # b and L have no default
    text = summary_text(d, None, "the declared defaults")
    assert "(no bodies-and-joints view: the loops' rank needs a value of b, L" in text
    assert "leg leg1: ground -> leg1_link1 -> leg1_link2 -> platform" in text  # the legs are still listed


#: the lever's input as a planar link J-I (an R joint about z at each end) instead of a rod: the
#: loop ground-piezo-link-lever is a planar slider-crank written in space, so its loop rows repeat
#: each other (Grübler-Kutzbach counts it -2 too few) and the whole graph is solved through its
#: normal equations -- with the platform placed by its coordinates (a tree joint, no platform rows)
OVERCONSTRAINED = (
    MIXED.replace("name: stage_lever", "name: stage_lever_planar")
    .replace("  lever: [O, T, I]\n", "  lever: [O, T, I]\n  link: [J, I]\n")
    .replace(
        "  - {type: distance, between: [piezo, lever], at: J, to: I}\n",
        "  - {type: R, between: [piezo, link], at: J, axis: [0, 0, 1]}\n"
        "  - {type: R, between: [link, lever], at: I, axis: [0, 0, 1]}\n",
    )
)


def test_an_overconstrained_mixed_file_solves_its_platform_through_the_normal_equations(tmp_path):
    """An overconstrained file of legs and bodies (issue 23 item 4): the normal equations have a
    row for each placed platform coordinate (they are tree coordinates of the expanded graph), so
    it loads with mobility 3 and its FK equals the lever (numpy, :func:`_lever`: the planar link
    keeps |J - I| = f as the rod did) and the stage alone -- every closure equation holds."""
    f = tmp_path / "stage_lever_planar.yaml"
    f.write_text(OVERCONSTRAINED)
    mech = load_file(f)
    model = mech.model(mech.closure(), {}, {}, ())
    c = model.closure
    gen, _fns = closure_parts(read_description(f))
    assert gen.normal_form and gen.info.mobility == 3 and gen.info.gruebler < 3
    assert c.loops is not None
    normal = [n for n in _fns["row_names"] if n.startswith("loops, normal equation of")]
    assert {"loops, normal equation of x", "loops, normal equation of y", "loops, normal equation of z"} <= set(normal)
    (tmp_path / "stage_alone.yaml").write_text(STAGE)
    alone = load_file(tmp_path / "stage_alone.yaml")
    ref = alone.model(alone.closure(), {}, {}, ())
    names, qn = list(c.x_names), list(c.q_names)
    for q1, q2, q3 in ([2e-4, 0.0, 0.0], [-1e-4, 1e-4, -2e-4], [3e-4, -1e-4, 1e-4]):
        given = {"q1": q1, "q2": q2, "q3": q3}
        q = [given[n] for n in qn]
        sol = cn.forward_kinematics(model, q, NEWTON, backend=MAP)
        assert sol.status == Status.SOLVED, sol.message
        x = np.asarray(sol.x)
        assert np.max(np.abs(np.asarray(c.loops(x, q, model.p)))) < 1e-12
        theta, d1 = _lever(q1)
        _close([x[names.index("theta")], x[names.index("d1")]], [theta, d1], TOL)
        stage = cn.forward_kinematics(ref, [d1, q2, q3], NEWTON, backend=MAP)
        assert stage.status == Status.SOLVED
        _close(x[:3], stage.x, TOL)
