"""Mechanisms described in files (cpm_nlp/mechanisms/described, problems/mechanisms/).

The papers' mechanisms re-described as files must be the hand-derived modules:
FK, IK, the Jacobians and the passive joint angles to 1e-12 on random poses of
the working range.  The reference is the hand-written module of each paper
(tests/reference/prs3_closures.py, prc3_closures.py, rpr_closures.py and
pantograph_closures.py -- the 3-PRS, the 3-PRC, the RPR and the pantograph are the files
themselves now, issue 21), whose
formulas are pinned to the papers in their own tests; the file's closure is
generated from the legs and shares no code with them.
"""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import cpm_nlp as cn
from cpm_nlp.analysis import flexure
from cpm_nlp.core.result import Status
from cpm_nlp.mechanisms import described

ROOT = Path(__file__).resolve().parents[3]
MECH = ROOT / "problems" / "mechanisms"

CASES = {
    # file mechanism, hand-written type, parameters, actuator half-range around home
    "prs3": ("prs3", "prs3_reference", {"b": "47.91 mm", "L": "109.215 mm", "alpha0": "45 deg"}, 2e-3),
    "prc3": (
        "prc3",
        "prc3_reference",
        {"L1": "9.5 mm", "L2": "25 mm", "L3": "9 mm", "L4": "30 mm", "L7": "73.5 mm"},
        15e-6,
    ),
    "rpr": ("rpr", "rpr_reference", {"r1": "40 mm", "r2": "80 mm", "P0": "40 mm"}, 50e-6),
    "pantograph": ("pantograph", "pantograph_reference", {"a": "20 mm", "b": "50 mm"}, 0.3e-3),
}
NEWTON = cn.SolverConfig("newton")


def _models(case):
    file_name, hand_name, params, _ = CASES[case]
    if hand_name == "prs3_reference":  # the hand-written 3-PRS left the package: tests/reference
        from tests.reference import prs3_closures

        return cn.build_model(file_name, params), prs3_closures.reference_model(params)
    if hand_name == "prc3_reference":  # the hand-written 3-PRC too (issue 21, item 5)
        from tests.reference import prc3_closures

        return cn.build_model(file_name, params), prc3_closures.reference_model(params)
    if hand_name == "rpr_reference":  # and the hand-written RPR (issue 21, item 5)
        from tests.reference import rpr_closures

        return cn.build_model(file_name, params), rpr_closures.reference_model(params)
    if hand_name == "pantograph_reference":  # and the hand-written pantograph (issue 21, item 5)
        from tests.reference import pantograph_closures

        return cn.build_model(file_name, params), pantograph_closures.reference_model(params)
    return cn.build_model(file_name, params), cn.build_model(hand_name, params)


def _close(a, b, tol=1e-12):
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    scale = max(1.0, float(np.max(np.abs(b))))
    np.testing.assert_allclose(a, b, rtol=0, atol=tol * scale)


@pytest.mark.parametrize("case", list(CASES))
def test_file_mechanism_equals_the_hand_derived_module(case):
    """By name: a file of bodies and joints (the pantograph) has more pose coordinates than the
    module (every tree joint's value); the module's are among them, or among its passive joints."""
    fm, hm = _models(case)
    idx = _rows(fm, hm)
    assert fm.closure.q_names == hm.closure.q_names
    if not fm.closure.loops and len(fm.closure.x_names) == len(hm.closure.x_names):
        assert fm.closure.x_names == hm.closure.x_names and fm.closure.passive_names == hm.closure.passive_names
    np.testing.assert_allclose(fm.x_home[idx], hm.x_home, atol=1e-15)
    np.testing.assert_allclose(fm.q_home, hm.q_home, atol=1e-15)
    rng = np.random.default_rng(11)
    half = CASES[case][3]
    solved = 0
    for _ in range(15):
        q = hm.q_home + rng.uniform(-half, half, hm.closure.nq)
        a, b = cn.forward_kinematics(hm, q, NEWTON), cn.forward_kinematics(fm, q, NEWTON)
        assert a.status == b.status == Status.SOLVED, (a.message, b.message)
        solved += 1
        _close(b.x[idx], a.x)
        pa, pb = cn.passive_joints(hm, a.x, q), cn.passive_joints(fm, b.x, q)
        xb = dict(zip(fm.closure.x_names, b.x))
        _close([pb[n] if n in pb else xb[n] for n in pa], list(pa.values()))
        _close(fm.closure.jacobian(b.x, q, fm.p)[idx, :], hm.closure.jacobian(a.x, q, hm.p))
        _close(fm.closure.inverse_jacobian(b.x, q, fm.p), hm.closure.inverse_jacobian(a.x, q, hm.p))
        t = hm.task_of(a.x)
        ia, ib = cn.inverse_kinematics(hm, t, NEWTON), cn.inverse_kinematics(fm, t, NEWTON)
        assert ib.status == Status.SOLVED, ib.message
        _close(ib.q, ia.q)
        _close(np.asarray(ib.x)[idx], ia.x)
        if fm.closure.ik is not None:  # the file's closed form against the hand-written closed form
            xf, qf, _ = fm.closure.ik(t, fm.p)
            xh, qh, _ = hm.closure.ik(t, hm.p)
            _close(np.asarray(qf).ravel(), np.asarray(qh).ravel())
            _close(np.asarray(xf).ravel()[idx], np.asarray(xh).ravel())
    assert solved == 15


def _rows(fm, hm) -> list[int]:
    """The file model's pose coordinates that are the module's, in the module's order."""
    return [list(fm.closure.x_names).index(n) for n in hm.closure.x_names]


@pytest.mark.parametrize("case", list(CASES))
def test_ipopt_fk_agrees(case):
    fm, hm = _models(case)
    q = hm.q_home + CASES[case][3] * np.array([0.5, -0.3, 0.2])
    a = cn.forward_kinematics(hm, q, cn.SolverConfig("ipopt"))
    b = cn.forward_kinematics(fm, q, cn.SolverConfig("ipopt"))
    assert a.status == b.status == Status.SOLVED
    _close(np.asarray(b.x)[_rows(fm, hm)], a.x, 1e-10)


def test_prs3_joint_requirements_equal_the_hand_module():
    """The joint requirements of the paper's Fig. 6-7 (problems/prs3_joint_requirements.yaml),
    on the file (the problem as shipped) and on the hand-written reference closures."""
    problem = cn.load_problem(ROOT / "problems" / "prs3_joint_requirements.yaml")
    res_f = cn.solve(problem)
    _, hm = _models("prs3")
    res_h = problem.kind.run(hm, problem.kind.parse_inputs(problem.data["inputs"], hm, ("inputs",)), problem.solver)
    assert res_h.status == res_f.status == Status.SOLVED
    common = [k for k in res_h.values if k in res_f.values and isinstance(res_h.values[k], float)]
    assert {"s_min", "s_max", "beta_m_min", "beta_m_max", "beta_n_max", "beta_l_max"} <= set(common)
    for k in common:
        assert res_f.values[k] == pytest.approx(res_h.values[k], abs=1e-12), k


def test_prc3_cuboid_equals_the_hand_module():
    fm, hm = _models("prc3")
    lims = {"q": ("0 um", "15 um")}
    from tests.reference import prc3_closures

    fm = cn.build_model("prc3", CASES["prc3"][2], lims)
    hm = prc3_closures.reference_model(CASES["prc3"][2], lims)
    a = cn.inscribed_cuboid(hm, solver=cn.SolverConfig("ipopt"))
    b = cn.inscribed_cuboid(fm, solver=cn.SolverConfig("ipopt"))
    assert a.found and b.found, (a.message, b.message)
    np.testing.assert_allclose(b.lower, a.lower, rtol=1e-6, atol=1e-12)
    np.testing.assert_allclose(b.upper, a.upper, rtol=1e-6, atol=1e-12)


def test_problem_file_override_of_a_file_mechanism(tmp_path):
    p = cn.load_problem(ROOT / "problems" / "prs3_file_forward_kinematics.yaml", ["mechanism.parameters.L=110 mm"])
    assert p.model.parameters["L"] == pytest.approx(0.110)
    assert cn.solve(p).status == Status.SOLVED


def test_inline_description_in_a_problem_file(tmp_path):
    data = described.read_yaml(MECH / "prc3.yaml")
    data["name"] = "prc3_inline"
    data.pop("examples")
    problem = {
        "problem": "forward_kinematics",
        "mechanism": {"description": data, "parameters": CASES["prc3"][2]},
        "inputs": {"q1": "1 um", "q2": "2 um", "q3": "3 um"},
        "solver": "newton",
    }
    res = cn.solve(cn.problem_from_dict(problem))
    assert res.status == Status.SOLVED


def test_the_description_is_cached_per_content():
    a = described.load_file(MECH / "prs3.yaml")
    b = described.load_file(MECH / "prs3.yaml")
    assert a is b and a.closure() is b.closure()


# -- errors -------------------------------------------------------------------------------------


def _error(tmp_path, text: str, *extra: str) -> str:
    f = tmp_path / "m.yaml"
    f.write_text(text)
    with pytest.raises(cn.InputError) as info:
        described.load_file(f)
    msg = str(info.value)
    assert str(f) in msg
    for e in extra:
        assert e in msg, msg
    return msg


BASE = (MECH / "prc3.yaml").read_text().replace("name: prc3\n", "name: prc3_bad\n").split("examples:")[0]
DEFAULTS = BASE
for _n, _v in (("L1", "9.5 mm"), ("L2", "25 mm"), ("L3", "9 mm"), ("L4", "30 mm"), ("L7", "73.5 mm")):
    DEFAULTS = DEFAULTS.replace(f"  {_n}: {{dimension: length,", f"  {_n}: {{dimension: length, default: {_v},")


def test_defaults_variant_loads():
    assert described.from_dict(described.load_yaml_text(DEFAULTS)).name == "prc3_bad"


def test_unknown_joint_type(tmp_path):
    _error(tmp_path, DEFAULTS.replace("type: distance", "type: distanse", 1), "legs[0].joints[1].type", "'distance'")


def test_expression_syntax_error_points_at_the_column(tmp_path):
    _error(tmp_path, DEFAULTS.replace("value: L2/L1,", "value: L2/(L1,"), "derived.A1", "column")


def test_unknown_symbol(tmp_path):
    _error(
        tmp_path, DEFAULTS.replace("to: [L7, 0, 0]", "to: [L8, 0, 0]"), "legs[0].joints[1].to", "unknown symbol 'L8'"
    )


def test_dimension_mismatch(tmp_path):
    text = DEFAULTS.replace("to: [L7, 0, 0]", "to: [A2, 0, 0]")
    _error(tmp_path, text, "legs[0].joints[1].to", "expected a length")
    text = DEFAULTS.replace("to: [L7, 0, 0]", "to: [L7, 0, L7*sin(L1)]")
    _error(tmp_path, text, "sin() takes an angle")


def test_reference_configuration_that_does_not_assemble(tmp_path):
    """Legs given at the reference configuration assemble there by construction; an escape-hatch
    closure that does not vanish at home, or a P joint off its leg's line, does not."""
    # (without the limit descriptions: the truncated file has no passive joints d, beta, gamma)
    no_limits = DEFAULTS.split("limits:")[0] + "derived:" + DEFAULTS.split("derived:", 1)[1]
    text = no_limits.split("  - name: limb3")[0] + "closures: [z + q3 - 1 mm]\nactuators: {q3: length}\n"
    _error(tmp_path, text, "does not assemble", "residual -1.000e-03", "closures[0]")
    rpr = (
        (MECH / "rpr.yaml")
        .read_text()
        .replace("name: rpr\n", "name: rpr_bad\n")
        .replace("P0: {dimension: length,", "P0: {dimension: length, default: 40 mm,")
    )
    rpr = rpr.replace("r1: {dimension: length,", "r1: {dimension: length, default: 40 mm,").replace(
        "r2: {dimension: length,", "r2: {dimension: length, default: 80 mm,"
    )
    rpr = rpr.replace("{type: P, at: [r1, 0, 0], axis: [0, 0, 1]", "{type: P, at: [r1, 0, 0], axis: [0, 0.1, 1]")
    _error(tmp_path, rpr.split("examples:")[0], "legs[0].joints[1]", "axis is not along the leg")


def test_wrong_mobility(tmp_path):
    text = DEFAULTS.replace("  - name: limb3\n", "  - name: limb3\n", 1)
    text = text.split("  - name: limb3")[0] + "passive: {}\n"
    _error(tmp_path, text, "wrong mobility", "under-constrained")


def test_leg_that_does_not_reach_the_platform(tmp_path):
    text = DEFAULTS.replace("      - {type: distance, at: [0, 0, 0], to: [L7, 0, 0]}\n", "")
    _error(tmp_path, text, "limb1", "must reach the platform")


def test_cli_exit_code_2_without_traceback(tmp_path):
    mfile = tmp_path / "m.yaml"
    mfile.write_text(DEFAULTS.replace("to: [L7, 0, 0]", "to: [L8, 0, 0]"))
    pfile = tmp_path / "p.yaml"
    pfile.write_text("problem: forward_kinematics\nmechanism: {file: m.yaml}\ninputs: {q1: 1 um, q2: 1 um, q3: 1 um}\n")
    run = subprocess.run([sys.executable, "-m", "cpm_nlp", "solve", str(pfile)], capture_output=True, text=True)
    assert run.returncode == 2, run.stderr
    assert "Traceback" not in run.stderr and "unknown symbol 'L8'" in run.stderr and "m.yaml" in run.stderr


def test_two_joints_on_the_same_body(tmp_path):
    text = DEFAULTS.replace(
        "      - {type: P, at: [0, 0, 0], axis: [-1, 0, 0], actuated: q1, gain: A2}",
        "      - {type: P, at: [0, 0, 0], axis: [-1, 0, 0], actuated: q1, gain: A2, body: slider}\n"
        "      - {type: R, at: [0, 0, 0], axis: [0, 0, 1], body: slider}",
    )
    _error(tmp_path, text, "legs[0].joints[1].body", "two joints on the body 'slider' with no loop")


def test_body_chain_that_stops_short_of_the_platform(tmp_path):
    text = DEFAULTS.replace(
        "{type: distance, at: [0, 0, 0], to: [L7, 0, 0]}", "{type: distance, at: [0, 0, 0], to: [L7, 0, 0], body: rod}"
    )
    _error(tmp_path, text, "legs[0].joints[1].body", "does not reach the platform")


def test_vector_of_the_wrong_size_and_mixed_dimensions(tmp_path):
    _error(tmp_path, DEFAULTS.replace("to: [L7, 0, 0]", "to: [L7, 0]"), "expected a vector of 3 elements")
    _error(
        tmp_path,
        DEFAULTS.replace("rotation: []", "rotation: [[z, L7]]"),
        "platform.rotation[0][1]",
        "expected an angle",
    )


def test_builder_api_builds_the_same_mechanism_as_the_file():
    """The 3-PRC stage built in code from the dataclasses gives the file's FK."""
    legs = [
        cn.Leg(
            f"limb{i + 1}",
            [
                cn.Joint("P", at=[0, 0, 0], axis=[-(k == i) * 1.0 for k in range(3)], actuated=f"q{i + 1}", gain="A2"),
                cn.Joint("distance", at=[0, 0, 0], to=["L7" if k == i else 0 for k in range(3)]),
            ],
        )
        for i in range(3)
    ]
    desc = cn.Description(
        name="prc3_code",
        title="3-PRC built in code",
        parameters=[
            cn.Parameter(n, "length", default=v)
            for n, v in (("L1", 9.5e-3), ("L2", 25e-3), ("L3", 9e-3), ("L4", 30e-3), ("L7", 73.5e-3))
        ],
        platform=cn.Platform({"x": "length", "y": "length", "z": "length"}, ["x", "y", "z"], [], ("x", "y", "z")),
        legs=legs,
        derived=[cn.Quantity("A2", "L2*L4/(L1*L3)", "dimensionless")],
    )
    mech = cn.describe_mechanism(desc)
    try:
        code = cn.build_model("prc3_code")
        from tests.reference import prc3_closures  # the hand-written closures (issue 21, item 5)

        ref = prc3_closures.reference_model(CASES["prc3"][2])
        q = np.array([5e-6, 1e-6, 8e-6])
        a, b = cn.forward_kinematics(ref, q, NEWTON), cn.forward_kinematics(code, q, NEWTON)
        assert a.status == b.status == Status.SOLVED
        _close(b.x, a.x)
        assert mech.origin.kind == "inline" and str(mech.origin) == "described in code"
    finally:
        cn.unregister_mechanism("prc3_code")


def test_rank_deficient_mobility_names_the_free_coordinates(tmp_path):
    """Three legs but two along x: as many equations as coordinates, Φ_x of rank 2; z is free."""
    text = DEFAULTS.replace("axis: [0, 0, -1], actuated: q3", "axis: [-1, 0, 0], actuated: q3").replace(
        "to: [0, 0, L7]", "to: [L7, 0, 0]"
    )
    msg = _error(tmp_path, text, "wrong mobility", "rank")
    assert "free: z" in msg or "free: y" in msg, msg


def test_flexure_hinge_sets_the_joint_limits(tmp_path):
    """A circular-notch hinge on the S joints: the limits of beta_m, beta_n, beta_l are the
    stress-limited rotation of cpm_nlp.analysis.flexure (the built-in formula, eq 38 of the
    pantograph paper), +- about the reference configuration."""
    text = (MECH / "prs3.yaml").read_text().replace("\nname: prs3\n", "\nname: prs3_flex\n")
    text = text.replace(
        '        coordinates: ["beta_m{i}", "beta_n{i}", "beta_l{i}"]',
        '        coordinates: ["beta_m{i}", "beta_n{i}", "beta_l{i}"]\n'
        "        flexure: {hinge: circular_notch, t: 0.5 mm, r: 2 mm, material: Al 7075-T6}",
    )
    f = tmp_path / "flex.yaml"
    f.write_text(text.split("examples:")[0])
    mech = described.load_file(f)
    m = flexure.MATERIALS["Al 7075-T6"]
    rot = flexure.circular_notch_max_rotation(m.E, 0.5e-3, 2e-3, flexure.allowable_stress(m))
    limits = {o.name: o.default for o in mech.limits}
    assert limits["beta_m"] == pytest.approx((-rot, rot), rel=1e-12)
    assert limits["alpha"] is None


def test_a_file_may_not_take_a_built_in_name(tmp_path):
    """A file named like a built-in (rpr, itself a shipped file) that differs from it."""
    (tmp_path / "m.yaml").write_text(DEFAULTS.replace("name: prc3_bad", "name: rpr"))
    problem = {"problem": "forward_kinematics", "mechanism": {"file": "m.yaml"}, "inputs": {"q1": 0, "q2": 0, "q3": 0}}
    with pytest.raises(cn.InputError, match="name 'rpr' is the built-in mechanism of .*rpr.yaml.* rename it"):
        cn.problem_from_dict(problem, base_dir=tmp_path)


def test_spatial_joint_in_a_planar_mechanism(tmp_path):
    text = (MECH / "five_bar.yaml").read_text().replace("name: five_bar", "name: five_bad")
    text = text.replace(
        "{type: planar_R, at: [-cx, cy], coordinates: [e1]}", "{type: R, at: [-cx, cy], coordinates: [e1]}"
    )
    _error(tmp_path, text.split("examples:")[0], "legs[0].joints[1].type", "'planar_R'")


def test_the_readme_example_solves(tmp_path):
    """The README's smallest complete example: the mechanism file and the problem file that uses it."""
    readme = (ROOT / "README.md").read_text().split("## Your own mechanism from a file")[1]
    blocks = re.findall(r"```yaml\n(.*?)```", readme, flags=re.S)
    (tmp_path / "stage.yaml").write_text(blocks[0])
    (tmp_path / "fk.yaml").write_text(blocks[1])
    run = subprocess.run(
        [sys.executable, "-m", "cpm_nlp", "solve", str(tmp_path / "fk.yaml"), "--set", "mechanism.parameters.l=75mm"],
        capture_output=True,
        text=True,
    )
    assert run.returncode == 0, run.stderr
    assert "status  : solved" in run.stdout


def test_two_mechanisms_of_one_name_never_share_a_closure(tmp_path):
    """The shipped 3-PRS file and an edited copy of the same ``name``: the registry's
    closure of each is its own, in any order (a closure cached by name alone once gave
    the shipped 3-PRS the spherical angles of a refused copy loaded earlier in the
    process: beta_m = -45 deg in ``reproduce``)."""
    from cpm_nlp.mechanisms.described import load_file
    from cpm_nlp.mechanisms.registry import REGISTRY
    from tests.conftest import PROBLEMS

    shipped = load_file(PROBLEMS / "mechanisms" / "prs3.yaml")
    (tmp_path / "prs3.yaml").write_text((PROBLEMS / "mechanisms" / "prs3.yaml").read_text() + "\n# an edited copy\n")
    copy = load_file(tmp_path / "prs3.yaml")
    assert copy is not shipped and copy.name == shipped.name
    for mech in (shipped, copy, shipped, copy):  # each its own closure (a described closure is the file's)
        assert REGISTRY.closure(mech) is mech.closure()
    assert shipped.closure() is not copy.closure()


def test_problems_of_one_inline_description_share_its_closure():
    """An inline ``description:`` is read once per content (described.inline): problems of the
    same description share the closure and its built solvers; another description (a changed
    length) or another base directory is a mechanism of its own, with its own numbers."""
    import copy

    import yaml

    from cpm_nlp.mechanisms.registry import section_model

    data = yaml.safe_load((MECH / "five_bar.yaml").read_text(encoding="utf-8"))
    data["name"] = "five_bar_inline_probe"
    first, again = section_model({"description": data}), section_model({"description": copy.deepcopy(data)})
    assert again.closure is first.closure and again.mechanism is first.mechanism
    assert section_model({"description": data}, ROOT).closure is not first.closure
    changed = copy.deepcopy(data)
    changed["parameters"]["l2"]["default"] = "160 mm"
    other = section_model({"description": changed})
    assert other.closure is not first.closure
    assert other.x_home[1] > first.x_home[1] + 1e-3  # a longer distal link: P higher at home
