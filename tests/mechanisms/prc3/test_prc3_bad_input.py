"""Bad 3-PRC input: one message naming the file, the key path and what was expected;
exit status 2, no traceback, no output file (the checks of test_bad_input.expect_input_error)."""

import pytest

from tests.cli.test_bad_input import expect_input_error

FK = """\
problem: forward_kinematics
mechanism:
  type: prc3
  parameters: {L1: 9.5 mm, L2: 25 mm, L3: 9 mm, L4: 30 mm, L7: 73.5 mm}
  limits: {q: [0 um, 15 um]}
inputs: {q1: 15 um, q2: 5 um, q3: 10 um}
"""

HINGES = "L7: 73.5 mm, L5: 26 mm, L6: 33 mm, L8: 59.5 mm, r: 3 mm, t: 0.5 mm, b: 6.5 mm}"
MASSES = "m0: 30 g, m1: 1 g, m2: 3 g, m3: 3 g, m4: 3.5 g, m5: 4 g, m6: 1 g, m7: 9 g"
DYN = (
    FK.replace("problem: forward_kinematics", "problem: dynamics")
    .replace("L7: 73.5 mm}", HINGES)
    .replace("inputs: {q1: 15 um, q2: 5 um, q3: 10 um}", "inputs: {material: Al 7075-T6, " + MASSES + "}")
)
WS = FK.replace("problem: forward_kinematics", "problem: actuator_workspace").replace(
    "inputs: {q1: 15 um, q2: 5 um, q3: 10 um}", "inputs: {samples: 3}"
)
STROKE = "expected a value within the stroke [0 mm, 0.015 mm] declared at mechanism.limits.q"


def test_good_files_solve(cli, tmp_path):
    for k, text in enumerate((FK, DYN, WS)):
        path = tmp_path / f"good{k}.yaml"
        path.write_text(text)
        run = cli("solve", str(path))
        assert run.code == 0, run.err


@pytest.mark.parametrize(
    "old, new, message",
    [
        ("q1: 15 um", "q1: 16 um", f"inputs.q1: actuator displacement 0.016 mm is out of reach: {STROKE}"),
        ("q3: 10 um", "q3: -1 um", f"inputs.q3: actuator displacement -0.001 mm is out of reach: {STROKE}"),
        (
            "L7: 73.5 mm}",
            "L7: 73.5 mm, r: -3 mm, t: 0.5 mm}",
            "mechanism.parameters.r: expected a length such as '47.91 mm' in (0 mm, 1000 mm), got '-3 mm'",
        ),
        (
            "L7: 73.5 mm}",
            "L7: 73.5 mm, r: 0 mm, t: 0.5 mm}",
            "mechanism.parameters.r: expected a length such as '47.91 mm' in (0 mm, 1000 mm), got '0 mm'",
        ),
        (
            "L7: 73.5 mm}",
            "L7: 73.5 mm, r: 3 mm, t: 4 mm}",
            "mechanism.parameters.t: expected the notch thickness t (4 mm) to be at most the notch radius r (3 mm): "
            "the circular-notch formula k = 2 E b t^2.5 / (9 pi r^0.5) holds for t << r",
        ),
        (
            "L1: 9.5 mm",
            "L1: 0 mm",
            "mechanism.parameters.L1: expected a length such as '47.91 mm' in (0 mm, 1000 mm), got '0 mm'",
        ),
        ("[0 um, 15 um]", "[15 um, 0 um]", "mechanism.limits.q: expected low < high, got [0.015 mm, 0 mm]"),
    ],
)
def test_bad_kinematics_input(cli, tmp_path, old, new, message):
    assert old in FK
    expect_input_error(cli, tmp_path, FK.replace(old, new), message)


def test_amplifier_input_outside_the_stroke(cli, tmp_path):
    text = FK.replace("problem: forward_kinematics", "problem: amplifier").replace(
        "inputs: {q1: 15 um, q2: 5 um, q3: 10 um}", "inputs: {q2: 20 um}"
    )
    expect_input_error(cli, tmp_path, text, f"inputs.q2: actuator displacement 0.02 mm is out of reach: {STROKE}")


def test_pose_outside_the_stroke_is_a_status_not_bad_input(cli, tmp_path):
    # IK of a pose that needs q1 < 0: a well-formed question with the answer "outside the joint limits" (exit 1)
    path = tmp_path / "ik.yaml"
    path.write_text(
        FK.replace("problem: forward_kinematics", "problem: inverse_kinematics").replace(
            "inputs: {q1: 15 um, q2: 5 um, q3: 10 um}", "inputs: {x: 10 um, y: -5 um, z: -5 um}"
        )
    )
    run = cli("solve", str(path), "--json")
    assert run.code == 1
    assert '"status": "outside_joint_limits"' in run.out and '"q1": null' in run.out


@pytest.mark.parametrize(
    "old, new, message",
    [
        (
            "material: Al 7075-T6",
            "material: Flexible-T",
            "inputs.material: material 'Flexible-T' has no Young's modulus E (the hinge stiffness needs it): "
            "no source gives it; give the material inline, e.g. {name: Flexible-T, E: ...}",
        ),
        (
            "material: Al 7075-T6",
            "material: Al 7075",
            "inputs.material: unknown material 'Al 7075'; expected one of: Al 7075-T6, Ti-6Al-4V, polypropylene, "
            "Flexible-T or an inline mapping {E, nu, density, yield_strength}; did you mean 'Al 7075-T6'?",
        ),
        (
            "material: Al 7075-T6, m0: 30 g",
            "material: polypropylene, m0: {length: 40 mm, width: 40 mm, height: 6.5 mm}",
            "inputs.m0: a block mass needs the density of the material, and material 'polypropylene' gives none; "
            "give the mass ('12 g') or the density (material: {E: ..., density: ...})",
        ),
        (
            "m0: 30 g",
            "m0: {length: 40 mm, widht: 40 mm, height: 6.5 mm}",
            "inputs.m0: unknown block dimension 'widht'; expected one of: height, length, width; did you mean 'width'?",
        ),
        (
            "m3: 3 g, ",
            "",
            "inputs: missing required input 'm3' (coupler, length L5, moving with A1 q and turning with the first "
            "lever (I_G3 = m3 L5^2/12); a mass or a block {length, width, height})",
        ),
        (
            "m3: 3 g",
            "m3: -3 g",
            "inputs.m3: expected a positive mass such as '12 g' or a block {length, width, height}, got '-3 g'",
        ),
        ("m3: 3 g", "m3: 3 mm", "inputs.m3: '3 mm' is not a mass; expected a unit like 'kg', 'g', 'mg'"),
        (
            "m0: 30 g",
            "m9: 30 g",
            "inputs: unknown input 'm9'; expected one of: g, m0, m1, m2, m3, m4, m5, m6, m7, material",
        ),
        (
            "L5: 26 mm, ",
            "",
            "mechanism.parameters: missing parameter(s) L5, needed by the dynamics (see cpm-nlp describe prc3)",
        ),
    ],
)
def test_bad_dynamics_input(cli, tmp_path, old, new, message):
    assert old in DYN
    expect_input_error(cli, tmp_path, DYN.replace(old, new), message)


def test_workspace_needs_the_strokes(cli, tmp_path):
    expect_input_error(
        cli,
        tmp_path,
        WS.replace("  limits: {q: [0 um, 15 um]}\n", ""),
        "mechanism.limits: the workspace is the image of the actuator strokes; no stroke is declared for "
        "q1, q2, q3 (expected mechanism.limits.q: [low, high])",
    )
    expect_input_error(
        cli, tmp_path, WS.replace("samples: 3", "samples: 1"), "inputs.samples: expected an integer in [2, 101], got 1"
    )


def test_kinds_that_do_not_apply_to_the_3prs(cli, tmp_path):
    prs3 = """\
problem: {kind}
mechanism:
  type: prs3
  parameters: {{b: 47.91 mm, L: 109.215 mm, alpha0: 45 deg}}
"""
    expect_input_error(
        cli,
        tmp_path,
        prs3.format(kind="amplifier"),
        "problem: problem kind 'amplifier' does not apply to mechanism 'prs3': it has no lever amplifier (no ratio A2)",
    )
    expect_input_error(
        cli,
        tmp_path,
        prs3.format(kind="dynamics"),
        "problem: problem kind 'dynamics' does not apply to mechanism 'prs3': it has no dynamic model (no energies)",
    )
