"""Bad pantograph files: one message naming the file, the key path and what was
expected; exit status 2; no traceback; no output file (see test_bad_input.py)."""

import pytest

from tests.cli.test_bad_input import expect_input_error
from tests.conftest import PROBLEMS

CUBOID = """\
problem: inscribed_cuboid
mechanism:
  type: pantograph
  parameters: {a: 20 mm, b: 50 mm}
  limits: {psi_min: 1.49 rad, psi_max: 1.65 rad, phi_max: 0.0795 rad}
inputs: {starts: 2}
"""

HINGE = "limits: {hinge: cantilever_notch, l: 5 mm, t: 0.1 mm, material: polypropylene}"
DIRECT = "limits: {psi_min: 1.49 rad, psi_max: 1.65 rad, phi_max: 0.0795 rad}"

CASES = [
    (
        CUBOID.replace("b: 50 mm", "b: -5 mm"),
        "mechanism.parameters.b: expected a length such as '47.91 mm' in (0 mm, 10000 mm), got '-5 mm'",
    ),
    (
        CUBOID.replace("b: 50 mm", "b: 0 mm"),
        "mechanism.parameters.b: expected a length such as '47.91 mm' in (0 mm, 10000 mm), got '0 mm'",
    ),
    (
        CUBOID.replace("psi_min: 1.49 rad", "psi_min: 1.7 rad"),
        "mechanism.limits.psi_min: expected psi_min < psi_max, got psi_min = 1.7 rad, psi_max = 1.65 rad",
    ),
    (
        CUBOID.replace("psi_min: 1.49 rad", "psi_min: 1.65 rad"),
        "mechanism.limits.psi_min: expected psi_min < psi_max, got psi_min = 1.65 rad, psi_max = 1.65 rad",
    ),
    (
        CUBOID.replace("phi_max: 0.0795 rad}", "phi_max: 0.0795 rad, hinge: cantilever_notch}"),
        "mechanism.limits: give either the joint-angle limits (psi_min, psi_max, phi_max) or the hinge that "
        "sets them by eq 31 (hinge), not both",
    ),
    (
        CUBOID.replace(DIRECT, HINGE.replace(", t: 0.1 mm", "")),
        "mechanism.limits: hinge cantilever_notch needs t (its dimensions: l, t)",
    ),
    (
        CUBOID.replace(DIRECT, HINGE.replace("polypropylene", "polypropylen")),
        "mechanism.limits.material: unknown material 'polypropylen'; expected one of: Al 7075-T6, Ti-6Al-4V, "
        "polypropylene, Flexible-T or an inline mapping {E, nu, density, yield_strength}; "
        "did you mean 'polypropylene'?",
    ),
    (
        CUBOID.replace(DIRECT, "limits: {l: 5 mm, t: 0.1 mm}"),
        "mechanism.limits: l, t describe a flexure hinge; also give hinge (one of: cantilever_notch, "
        "circular_notch, leaf_spring)",
    ),
    (
        CUBOID.replace(DIRECT, HINGE.replace(", material: polypropylene", "")),
        "mechanism.limits: hinge cantilever_notch needs a material (or E and sigma_all)",
    ),
    (
        CUBOID.replace(DIRECT, "limits: {hinge: circular_notch, t: 1 mm, r: 1 mm, l: 2 mm, material: Ti-6Al-4V}"),
        "mechanism.limits: hinge circular_notch has no dimension l (it takes t, r)",
    ),
    (
        CUBOID + "solver: newton\n",
        "solver.method: problem kind 'inscribed_cuboid' solves an optimisation problem and needs method "
        "ipopt, got 'newton'",
    ),
    (
        CUBOID.replace("{starts: 2}", "{starts: 2, px_range: [90 mm, 100 mm]}"),
        "inputs: give a search range for every task coordinate; missing py_range, pz_range",
    ),
    (
        CUBOID.replace("{starts: 2}", "{starts: 0}"),
        "inputs.starts: expected an integer in [1, 200], got 0",
    ),
    (
        CUBOID.replace("{starts: 2}", "{starts: 2, paper_reading: printd}"),
        "inputs.paper_reading: expected one of 'near_face', 'printed', got 'printd'; did you mean 'printed'?",
    ),
]


@pytest.mark.parametrize("text, message", CASES)
def test_bad_cuboid_file(cli, tmp_path, text, message):
    expect_input_error(cli, tmp_path, text, message)


SYNTHESIS = (PROBLEMS / "pantograph_synthesis.yaml").read_text()

SYNTHESIS_CASES = [
    (
        SYNTHESIS.replace("weights: [0.25, 0.25, 0.25, 0.25]", "weights: [0.3, 0.3, 0.3, 0.3]"),
        "inputs.weights: expected weights summing to 1 (eq 35), got a sum of 1.2",
    ),
    (
        SYNTHESIS.replace("    b: 50 mm\n", "    b: 50 mm\n  limits: {phi_max: 0.1 rad}\n"),
        "mechanism.limits: the synthesis sets the joint limits from the hinge of each design (eq 31); "
        "remove mechanism.limits",
    ),
    (
        SYNTHESIS.replace("cuboid: [1 mm, 1 mm, 1 mm]", "cuboid: [1 mm, 1 mm]"),
        "inputs.cuboid: expected 3 values, got 2",
    ),
    (
        SYNTHESIS.replace("  a_bounds: [10 mm, 100 mm]\n", ""),
        "inputs: missing required input 'a_bounds' ([low, high] of a; expected a length such as '47.91 mm')",
    ),
    (
        SYNTHESIS.replace("b_bounds: [10 mm, 100 mm]", "b_bounds: [100 mm, 10 mm]"),
        "inputs.b_bounds: expected low < high, got [100 mm, 10 mm]",
    ),
    (
        SYNTHESIS.replace("    x_hat: 95.1768 mm\n", "    x_hat: 95.1768 mm\n    c: 1 mm\n"),
        "inputs.reference: unknown design value 'c'; expected one of: a, b, l, t, x_hat, y_hat, z_hat",
    ),
    (
        SYNTHESIS.replace("material: polypropylene ", "material: steel          "),
        "inputs.material: unknown material 'steel'; expected one of: Al 7075-T6, Ti-6Al-4V, polypropylene, "
        "Flexible-T or an inline mapping {E, nu, density, yield_strength}",
    ),
]


@pytest.mark.parametrize("text, message", SYNTHESIS_CASES)
def test_bad_synthesis_file(cli, tmp_path, text, message):
    assert text != SYNTHESIS
    expect_input_error(cli, tmp_path, text, message)
