"""Bad input: one clear message naming the file, the key path and what was
expected; exit status 2; no traceback; no output file."""

import pytest

from cpm_nlp.mechanisms.registry import mechanism_names
from cpm_nlp.problems.registry import kind_names
from tests.conftest import PROBLEMS

FK = str(PROBLEMS / "prs3_forward_kinematics.yaml")

GOOD = """\
problem: forward_kinematics
mechanism:
  type: prs3
  parameters: {b: 47.91 mm, L: 109.215 mm, alpha0: 45 deg}
  limits: {s: [-3 mm, 3 mm]}
inputs: {s1: 1 mm, s2: 0.5 mm, s3: -0.3 mm}
"""


def expect_input_error(cli, tmp_path, text, message, *extra):
    path = tmp_path / "problem.yaml"
    path.write_text(text)
    out = tmp_path / "result.json"
    run = cli("solve", str(path), "-o", str(out), *extra)
    assert run.code == 2, (run.out, run.err)
    assert run.out == ""
    assert "Traceback" not in run.err
    assert run.err.count("\n") == 1, run.err  # one message, one line
    assert run.err == f"error: {path}: {message}\n"
    assert not out.exists()
    return run


def test_good_file_solves(cli, tmp_path):
    path = tmp_path / "problem.yaml"
    path.write_text(GOOD)
    assert cli("solve", str(path)).code == 0


def test_malformed_yaml(cli, tmp_path):
    expect_input_error(
        cli,
        tmp_path,
        GOOD + "inputs: [1, 2\n",
        "malformed YAML: line 8, column 1: expected ',' or ']', but got '<stream end>'",
    )


def test_not_a_mapping(cli, tmp_path):
    expect_input_error(
        cli,
        tmp_path,
        "- 1\n- 2\n",
        "expected a mapping with keys problem, description, mechanism, inputs, solver, outputs, "
        "reproduce, sweep; got list [1, 2]",
    )


def test_empty_file(cli, tmp_path):
    expect_input_error(
        cli,
        tmp_path,
        "",
        "expected a mapping with keys problem, description, mechanism, inputs, "
        "solver, outputs, reproduce, sweep; got an empty file",
    )


def test_unknown_top_level_key(cli, tmp_path):
    expect_input_error(
        cli,
        tmp_path,
        GOOD + "inputz: {}\n",
        "unknown top-level key 'inputz'; expected one of: description, inputs, mechanism, outputs, "
        "problem, reproduce, solver, sweep; did you mean 'inputs'?",
    )


def test_unknown_problem_kind(cli, tmp_path):
    expect_input_error(
        cli,
        tmp_path,
        GOOD.replace("forward_kinematics", "forward_kinematic"),
        "problem: unknown problem kind 'forward_kinematic'; expected one of: "
        + ", ".join(kind_names())  # every registered kind, e.g. forward_kinematics, inverse_kinematics ...
        + "; did you mean 'forward_kinematics' or 'inverse_kinematics'?",
    )


def test_unknown_mechanism_type(cli, tmp_path):
    expect_input_error(
        cli,
        tmp_path,
        GOOD.replace("type: prs3", "type: 3prs"),
        "mechanism.type: unknown mechanism type '3prs'; expected one of: "
        + ", ".join(mechanism_names())  # every registered mechanism: prc3, prs3 ...
        + "; did you mean 'prs3'?",
    )


def test_missing_parameter(cli, tmp_path):
    expect_input_error(
        cli,
        tmp_path,
        GOOD.replace("b: 47.91 mm, ", ""),
        "mechanism.parameters: missing required parameter 'b' (radius of the spherical-joint "
        "circle on the platform (eq 3); expected a length such as '47.91 mm' in (0 mm, 1000 mm))",
    )


def test_unknown_parameter(cli, tmp_path):
    expect_input_error(
        cli,
        tmp_path,
        GOOD.replace("b: 47.91 mm", "b: 47.91 mm, l: 3 mm"),
        "mechanism.parameters: unknown parameter 'l'; expected one of: L, alpha0, b; did you mean 'L'?",
    )


def test_wrong_unit(cli, tmp_path):
    expect_input_error(
        cli,
        tmp_path,
        GOOD.replace("47.91 mm", "47.91 kg"),
        "mechanism.parameters.b: '47.91 kg' is not a length; expected a unit like 'm', 'mm', 'um', 'µm', 'nm', 'cm'",
    )


def test_unknown_unit(cli, tmp_path):
    expect_input_error(
        cli,
        tmp_path,
        GOOD.replace("45 deg", "45 dgr"),
        "mechanism.parameters.alpha0: '45 dgr' is not an angle; expected a unit like 'rad', 'deg', "
        "'mrad', 'urad', 'arcmin', 'arcsec'; did you mean 'deg'?",
    )


def test_unit_not_in_registry(cli, tmp_path):
    expect_input_error(
        cli,
        tmp_path,
        GOOD.replace("47.91 mm", "47.91 mmm"),
        "mechanism.parameters.b: unknown unit 'mmm' in '47.91 mmm'; expected a length such as "
        "'47.91 mm' or a bare SI number; did you mean 'mm'?",
    )


def test_missing_unit_caught_by_bounds(cli, tmp_path):
    expect_input_error(
        cli,
        tmp_path,
        GOOD.replace("45 deg", "45"),
        "mechanism.parameters.alpha0: expected an angle such as '0.2 deg' in (0 deg, 90 deg), "
        "got 45 (a bare number is read in SI (rad); did you mean '45 deg'?)",
    )


def test_number_missing(cli, tmp_path):
    expect_input_error(
        cli,
        tmp_path,
        GOOD.replace("109.215 mm", "mm"),
        "mechanism.parameters.L: expected a length such as '47.91 mm' or a bare SI number, "
        "got 'mm' (write a number first, then the unit)",
    )


def test_negative_length(cli, tmp_path):
    expect_input_error(
        cli,
        tmp_path,
        GOOD.replace("47.91 mm", "-47.91 mm"),
        "mechanism.parameters.b: expected a length such as '47.91 mm' in (0 mm, 1000 mm), got '-47.91 mm'",
    )


def test_nan(cli, tmp_path):
    expect_input_error(
        cli,
        tmp_path,
        GOOD.replace("s1: 1 mm", "s1: .nan"),
        "inputs.s1: expected a finite number (a length such as '47.91 mm' or a bare SI number), got nan",
    )


def test_actuator_out_of_reach(cli, tmp_path):
    expect_input_error(
        cli,
        tmp_path,
        GOOD.replace("s1: 1 mm", "s1: 4 mm"),
        "inputs.s1: actuator displacement 4 mm is out of reach: expected a value within the stroke "
        "[-3 mm, 3 mm] declared at mechanism.limits.s",
    )


def test_missing_actuator(cli, tmp_path):
    expect_input_error(
        cli,
        tmp_path,
        GOOD.replace("s2: 0.5 mm, ", ""),
        "inputs: missing actuator input(s) s2; give every one of s1, s2, s3",
    )


def test_unknown_input(cli, tmp_path):
    expect_input_error(
        cli,
        tmp_path,
        GOOD.replace("s3:", "s4: 1 mm, s3:"),
        "inputs: unknown input 's4'; expected one of: "
        # guess (a start pose) is accepted and, declared in the schema, now listed too
        "assembly_modes, guess, mode_certificate, mode_seed, mode_starts, s1, s2, s3",
    )


def test_batch_lengths_differ(cli, tmp_path):
    expect_input_error(
        cli,
        tmp_path,
        GOOD.replace("s1: 1 mm, s2: 0.5 mm", "s1: [1 mm, 2 mm], s2: [0 mm]"),
        "inputs: lists of inputs must have the same length (got s1: 2, s2: 1)",
    )


def test_inverted_limits(cli, tmp_path):
    expect_input_error(
        cli,
        tmp_path,
        GOOD.replace("[-3 mm, 3 mm]", "[3 mm, -3 mm]"),
        "mechanism.limits.s: expected low < high, got [3 mm, -3 mm]",
    )


def test_pose_and_offset_both_given(cli, tmp_path):
    text = GOOD.replace("forward_kinematics", "inverse_kinematics").replace(
        "{s1: 1 mm, s2: 0.5 mm, s3: -0.3 mm}", "{pz: 78 mm, dz: 1 mm, psi: 0, theta: 0}"
    )
    expect_input_error(cli, tmp_path, text, "inputs: give only one of 'pz', 'dz'")


def test_unknown_solver_option(cli, tmp_path):
    expect_input_error(
        cli,
        tmp_path,
        GOOD + "solver: {options: {ipopt.tolerance: 1e-8}}\n",
        "solver.options.ipopt.tolerance: IPOPT has no option 'tolerance'; did you mean 'ipopt.tol'? "
        "(see https://coin-or.github.io/Ipopt/OPTIONS.html)",
    )


def test_bad_solver_option_value(cli, tmp_path):
    expect_input_error(
        cli,
        tmp_path,
        GOOD + "solver: {options: {ipopt.tol: small}}\n",
        "solver.options.ipopt.tol: expected a dimensionless number such as '0.5' or a bare SI number, got 'small' "
        "(write a number first, then the unit)",
    )


def test_unknown_preset(cli, tmp_path):
    path = tmp_path / "problem.yaml"
    path.write_text(GOOD + "solver: newtn\n")
    result = cli("solve", str(path))
    assert result.code == 2
    assert result.err.startswith(f"error: {path}: solver.preset: unknown solver preset 'newtn'; expected one of: ")
    assert "did you mean 'newton'?" in result.err


def test_unknown_output_value(cli, tmp_path):
    run = cli("solve", FK, "--set", "outputs.values=[pzz]")
    assert run.code == 2
    assert "outputs.values[0]: unknown value 'pzz'" in run.err and "did you mean 'pz'?" in run.err


def test_bad_set_syntax(cli):
    run = cli("solve", FK, "--set", "inputs.s1")
    assert run.code == 2
    assert run.err == f"error: {FK}: --set: expected dotted.key=VALUE, got 'inputs.s1'\n"


def test_missing_file(cli, tmp_path):
    run = cli("solve", str(tmp_path / "nope.yaml"))
    assert run.code == 2 and run.err == f"error: {tmp_path / 'nope.yaml'}: file not found\n"


def test_output_directory_missing(cli, tmp_path):
    run = cli("solve", FK, "-o", str(tmp_path / "no" / "such" / "r.json"))
    assert run.code == 2 and "output directory" in run.err and "does not exist" in run.err


def test_bad_command_line(cli):
    run = cli("solve")
    assert run.code == 2


@pytest.mark.parametrize("kind", ["inverse_kinematics", "joint_requirements"])
def test_missing_task_coordinate(cli, tmp_path, kind):
    text = GOOD.replace("forward_kinematics", kind).replace("{s1: 1 mm, s2: 0.5 mm, s3: -0.3 mm}", "{dz: 1 mm, psi: 0}")
    expect_input_error(cli, tmp_path, text, "inputs: missing input 'theta' (rotation about y (eq 4))")


def test_solver_option_given_a_mapping(cli, tmp_path):
    """An unhashable option value is refused by its declared type (it was a crash, exit 70)."""
    expect_input_error(
        cli,
        tmp_path,
        GOOD + "solver: {options: {ipopt.mu_min: {a: 1}}}\n",
        "solver.options.ipopt.mu_min: expected a dimensionless number such as '0.5' or a bare SI number, "
        "got dict {'a': 1}",
    )
