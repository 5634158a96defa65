"""The RPR problem files and problem kinds end to end: every file solves, its
reproduce rows come out as expected, JSON values are plot-ready, and bad input
gives one clear message (exit 2)."""

import json

import numpy as np
import pytest

import cpm_nlp as cn
from tests.cli.test_bad_input import expect_input_error
from tests.conftest import PROBLEMS

RPR_FILES = sorted(PROBLEMS.glob("rpr_*.yaml"))

SYNTHESIS = """\
problem: synthesis
mechanism:
  type: rpr
  parameters: {r1: 40 mm, r2: 80 mm, P0: 40 mm}
inputs: {l_min: 0.1, starts: 2}
"""

TWISTS = """\
problem: rpr_twists
mechanism:
  type: rpr
  parameters: {r1: 40 mm, r2: 80 mm, P0: 40 mm}
inputs: {d: 10 um}
"""

COMPLIANCE = """\
problem: rpr_compliance
mechanism:
  type: rpr
  parameters: {r1: 40 mm, r2: 80 mm, P0: 40 mm}
inputs:
  amplifier: {l1: 16 mm, l2: 1.6 mm, leaf: {length: 1 mm, thickness: 0.4 mm, width: 12 mm}}
  joints: {R: {r: 4 mm, t: 0.4 mm, b: 12 mm}, U: {r: 1 mm, t: 0.4 mm, h: 12 mm}}
"""


def test_there_is_a_file_per_question():
    kinds = {cn.load_problem(f).kind.name for f in RPR_FILES}
    assert kinds >= {
        "forward_kinematics",
        "rpr_screw_jacobian",
        "rpr_twists",
        "rpr_transmission_map",
        "synthesis",
        "rpr_joint_design",
        "rpr_compliance",
    }


@pytest.mark.parametrize("path", RPR_FILES, ids=lambda p: p.name)
def test_every_rpr_file_solves(path, cli, tmp_path):
    out = tmp_path / "r.json"
    run = cli("solve", str(path), "-o", str(out))
    assert run.code == 0, run.err + run.out
    data = json.loads(out.read_text())
    assert data["status"] == "solved"


def test_every_reproduce_row_is_as_expected():
    rows = cn.reproduce([p for p in RPR_FILES])
    assert len(rows) > 60
    bad = [(r.file, r.quantity, r.verdict) for r in rows if not r.expected]
    assert not bad


def test_screw_jacobian_file_agrees_with_ad():
    res = cn.solve(cn.load_problem(PROBLEMS / "rpr_screw_jacobian.yaml"))
    assert res.values["dJ"] < 1e-13 and res.values["dG_p"] < 1e-11


def test_twists_file_linearisation_and_reference_point(tmp_path):
    res = cn.solve(cn.load_problem(PROBLEMS / "rpr_twists.yaml"))
    assert res.values["dT_fk"] < 1e-8  # exact FK against the linear G d for 10 um
    at_o = cn.solve(cn.load_problem(PROBLEMS / "rpr_twists_velocity.yaml", ["inputs.reference=o"]))
    # velocity of the body point at o: (0, P dalpha, dP)
    T = at_o.values["T"]
    assert T[3][0] == pytest.approx(0.0, abs=1e-20)
    assert T[4][0] == pytest.approx(0.04 * -6.25e-5)
    point = cn.solve(
        cn.load_problem(
            PROBLEMS / "rpr_twists_velocity.yaml", ["inputs.reference=point", "inputs.point=[0 mm, 0 mm, 0 mm]"]
        )
    )
    assert np.allclose(point.values["T"], T, rtol=1e-12, atol=1e-20)


def test_transmission_map_is_plot_ready(tmp_path, cli):
    out = tmp_path / "map.json"
    assert cli("solve", str(PROBLEMS / "rpr_transmission_map.yaml"), "-q", "-o", str(out)).code == 0
    v = json.loads(out.read_text())["values"]
    assert len(v["eta"]) == len(v["t"]) and all(len(row) == len(v["s"]) for row in v["eta"])
    flat = [e for row in v["eta"] for e in row]
    assert None in flat and all(e is None or 0 < e <= 1 for e in flat)
    assert v["eta_design"] == pytest.approx(0.9128709, abs=1e-7)


def test_rpr_kinds_need_the_rpr_mechanism(cli, tmp_path):
    expect_input_error(
        cli,
        tmp_path,
        SYNTHESIS.replace("type: rpr", "type: prs3").replace(
            "{r1: 40 mm, r2: 80 mm, P0: 40 mm}", "{b: 47.91 mm, L: 109.215 mm}"
        ),
        # prs3 has no synthesis of its own: the generic one asks for its inputs
        # (tests/analysis/test_synthesis_generic.py)
        "inputs: missing required input 'design' (the parameters to vary: a list of names, which vary within "
        "their declared bounds, or a mapping name -> [low, high]; e.g. design: {L: [90 mm, 130 mm]}); "
        "parameters of prs3: b, L, alpha0",
    )


def test_bad_r1(cli, tmp_path):
    expect_input_error(
        cli,
        tmp_path,
        SYNTHESIS.replace("r1: 40 mm", "r1: -40 mm"),
        "mechanism.parameters.r1: expected a length such as '47.91 mm' in (0 mm, 10000 mm), got '-40 mm'",
    )
    expect_input_error(
        cli,
        tmp_path,
        SYNTHESIS.replace("r1: 40 mm", "r1: 0 mm"),
        "mechanism.parameters.r1: expected a length such as '47.91 mm' in (0 mm, 10000 mm), got '0 mm'",
    )


def test_normalized_parameters_outside_eq_22(cli, tmp_path):
    expect_input_error(
        cli,
        tmp_path,
        SYNTHESIS.replace("l_min: 0.1", "l1: 0.5, l2: 1.5"),
        "inputs.l2: normalized parameters outside the design space of eq 22 (l2 = 1.5 is not within [l1/2, 2 l1] = "
        "[0.25, 1]); expected 0 < l1, l2, l3 < 3, l1 + l2 + l3 = 3 and l1/2 <= l2 <= 2 l1",
    )
    expect_input_error(
        cli,
        tmp_path,
        SYNTHESIS.replace("l_min: 0.1", "l1: 1.0, l2: 1.0, l3: 1.5"),
        "inputs: normalized parameters outside the design space of eq 22 (l1 + l2 + l3 = 3.5, not 3); expected "
        "0 < l1, l2, l3 < 3, l1 + l2 + l3 = 3 and l1/2 <= l2 <= 2 l1",
    )
    expect_input_error(
        cli,
        tmp_path,
        SYNTHESIS.replace("l_min: 0.1", "l3: 3.2"),
        "inputs.l3: expected a number in (0, 3), got 3.2",
    )


def test_synthesis_needs_ipopt(cli, tmp_path):
    expect_input_error(
        cli,
        tmp_path,
        SYNTHESIS + "solver: newton\n",
        "solver.method: problem kind 'synthesis' solves an optimisation problem and needs method ipopt, got 'newton'",
    )


def test_infeasible_synthesis_reports_its_status(cli, tmp_path):
    path = tmp_path / "p.yaml"
    path.write_text(SYNTHESIS.replace("l_min: 0.1", "l2: 2.5"))
    run = cli("solve", str(path), "--json")
    assert run.code == 1
    data = json.loads(run.out)
    assert data["status"] == "infeasible" and data["values"] == {}


def test_twists_reference_point_input(cli, tmp_path):
    expect_input_error(
        cli,
        tmp_path,
        TWISTS.replace("d: 10 um", "reference: point"),
        "inputs.point: reference 'point' needs 'point' with three coordinates [x, y, z]",
    )
    expect_input_error(
        cli,
        tmp_path,
        TWISTS.replace("d: 10 um", "point: [0 mm, 0 mm, 1 mm]"),
        "inputs.point: 'point' is used only with reference: point (reference is 'o_prime')",
    )
    expect_input_error(
        cli,
        tmp_path,
        TWISTS.replace("d: 10 um", "convention: paper"),
        "inputs.convention: expected one of 'velocity', 'eq45', got 'paper'",
    )


def test_compliance_inputs(cli, tmp_path):
    expect_input_error(
        cli,
        tmp_path,
        COMPLIANCE.replace(
            "leaf: {length: 1 mm, thickness: 0.4 mm, width: 12 mm}",
            "leaf: {length: 1 mm, thickness: 0.4 mm, width: 12 mm}, k_r: 4 N*m/rad",
        ),
        "inputs.amplifier: give either leaf or k_r and k_t, not both",
    )
    expect_input_error(
        cli,
        tmp_path,
        COMPLIANCE.replace("U: {r: 1 mm, t: 0.4 mm, h: 12 mm}", "V: {r: 1 mm}"),
        "inputs.joints: unknown joint 'V'; expected R or U",
    )
    expect_input_error(
        cli,
        tmp_path,
        COMPLIANCE.replace(", U: {r: 1 mm, t: 0.4 mm, h: 12 mm}", ""),
        "inputs: give either joints.U (its dimensions) or k_U (its stiffness)",
    )
    expect_input_error(
        cli,
        tmp_path,
        COMPLIANCE.replace("b: 12 mm", "b: -12 mm"),
        "inputs.joints.R.b: expected a length such as '47.91 mm' in (0 mm, 1000 mm), got '-12 mm'",
    )
