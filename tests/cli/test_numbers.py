"""Readable numbers in what the CLI prints (issue 24): an engineering prefix chosen per value,
rounding noise below the solve's tolerance printed as 0 (never -0), iterations and times
reported as what they are (the path that answered, the build apart from the solve), and the
JSON keeping every digit."""

from __future__ import annotations

import json
import math
import re

import pytest

from cpm_nlp.cli.numbers import Noise, engineering
from tests.conftest import PROBLEMS

# -- engineering prefixes ---------------------------------------------------------------------------


@pytest.mark.parametrize(
    "value, dimension, text",
    [
        (0.00348767e-3, "length", "3.488 µm"),  # issue 24: "0.00348767 mm"
        (-6.91265229e-07, "length", "-691.3 nm"),
        (0.07761798713, "length", "77.62 mm"),
        (1.0, "length", "1 m"),
        (999.96e-6, "length", "1 mm"),  # rounds up into the next prefix, not "1000 µm"
        (0.02, "force", "20 mN"),
        (20.18001309, "force", "20.18 N"),
        (1500.0, "force", "1.5 kN"),
        (177583719.3, "stress", "177.6 MPa"),
        (72e9, "stress", "72 GPa"),
        (0.0125, "mass", "12.5 g"),
        (0.02847040059, "energy", "28.47 mJ"),
        (93.83, "frequency", "93.83 Hz"),
        (0.009736590125, "angle", "0.5579 deg"),  # an angle from 1 mrad up: degrees, the papers' unit
        (math.radians(92.1157), "angle", "92.12 deg"),
        (-6.012625722e-05, "angle", "-60.13 µrad"),  # below 1 mrad: µrad
        (3e-9, "angle", "3 nrad"),
        (0.0, "length", "0 m"),
        (-0.0, "angle", "0 deg"),  # never -0
        (-1e-30, "dimensionless", "-1e-30"),
    ],
)
def test_an_engineering_prefix_is_chosen_per_value(value, dimension, text):
    assert engineering(value, dimension) == text


def test_compound_units_keep_their_display_unit_and_never_show_minus_zero():
    assert engineering(2.0e6, "stiffness") == "2 N/um"
    assert engineering(-0.0, "stiffness") == "0 N/um"
    assert not engineering(-1e-300, "compliance").startswith("-0 ")


# -- noise below the solve's tolerance ----------------------------------------------------------------


def test_noise_is_derived_from_the_tolerance_and_the_scale_of_the_quantity():
    values = {"pz": 0.0776, "px": -6.9e-7, "psi": math.radians(1.71766e-15), "alpha1": 0.798, "F1": 20.0}
    dims = {"pz": "length", "px": "length", "psi": "angle", "alpha1": "angle", "F1": "force"}
    L = 0.109215  # the mechanism's largest length parameter (the 3-PRS leg)
    noise = Noise(1e-10, values, dims, L)
    # a length is known to the tolerance itself (max |Phi| <= tol, Phi a length)
    assert noise.threshold("length") == 1e-10
    # another dimension to the same fraction of its scale: tol / L times its largest value
    assert noise.threshold("angle") == pytest.approx(1e-10 / L * 0.798)
    assert noise.threshold("force") == pytest.approx(1e-10 / L * 20.0)
    assert noise.clean(values["psi"], "angle") == 0.0  # issue 24: "psi 1.71766e-15 deg"
    assert noise.clean(values["px"], "length") == values["px"]  # a 0.69 um parasitic motion is real
    assert noise.clean(5e-11, "length") == 0.0 and noise.clean(2e-10, "length") == 2e-10
    assert math.copysign(1.0, noise.clean(-0.0, "length")) == 1.0  # -0 is 0
    assert Noise(None, values, dims).clean(1e-300, "length") == 1e-300  # no tolerance, no noise


def test_a_mechanism_without_lengths_keeps_its_angles():
    """A linkage whose pose is angles only (its residual a tiny length): the scale is 1 m,
    never the residual, so 0.512 rad is not taken for noise."""
    values = {"phi": 0.512024908, "theta": 1e-17, "residual": 1e-17}
    noise = Noise(1e-10, values, {"phi": "angle", "theta": "angle", "residual": "length"})
    assert noise.clean(0.512024908, "angle") == 0.512024908 and noise.clean(1e-17, "angle") == 0.0


def test_solve_prints_noise_as_zero_and_keeps_every_digit_in_the_json(cli):
    """Equal strokes: the 3-PRS rises without tilting; psi, px and the beta_n are zero up to
    rounding, which the text shows as 0 and the JSON keeps."""
    f = str(PROBLEMS / "prs3_table2_forces.yaml")
    text = cli("solve", f).out
    doc = json.loads(cli("solve", f, "--json").out)
    rows = {line.split()[0]: line for line in text.splitlines() if line and not line.startswith(" ")}
    for name in ("px", "py", "psi", "theta", "beta_n1", "residual"):
        raw = doc["values"][name]
        assert abs(raw) < 1e-10  # noise, in the JSON as computed
        assert rows[name].split()[1] == "0", rows[name]
    assert doc["values"]["psi"] != 0.0 or doc["values"]["px"] != 0.0  # the JSON has the digits
    assert not re.search(r"(?<![\w.])-0(?![.\d])", text)  # never -0
    assert not re.search(r"\de-1[0-9]", text)  # no rounding noise printed anywhere
    assert "177.6 MPa" in rows["stress_max"] and "20.18 N" in rows["F1"]
    assert "923.8 µm" in rows["dz"]


# -- iterations and times, truthfully ------------------------------------------------------------------


def test_a_newton_kernel_names_its_path_and_times_the_build_apart(cli):
    """Issue 24: "newton, 0 iterations, 879.95 ms" for a pose away from home.  The compiled
    kernel answers by its reduced path and does not count its steps: the text says so, the
    JSON has iterations null, and the build (symbolic construction, compilation) is apart."""
    f = str(PROBLEMS / "prs3_forward_kinematics.yaml")
    args = (f, "--set", "solver=newton", "--set", "inputs.s1=0.5 mm")
    doc = json.loads(cli("solve", *args, "--json").out)
    s = doc["solver"]
    assert s["name"] == "newton" and s["path"] == "reduced" and s["iterations"] is None
    assert s["seconds"] >= 0 and s["build_seconds"] >= 0
    text = cli("solve", *args).out
    solver = next(line for line in text.splitlines() if line.startswith("solver"))
    assert "reduced path" in solver and "not counted" in solver and "0 iterations" not in solver
    time = next(line for line in text.splitlines() if line.startswith("time"))
    assert time.startswith("time    : solve ")


def test_ipopt_counts_its_iterations(cli):
    text = cli("solve", str(PROBLEMS / "prs3_forward_kinematics.yaml")).out
    assert re.search(r"^solver  : ipopt, \d+ iterations$", text, re.M)
    assert re.search(r"^time    : solve [\d.]+ m?s", text, re.M)


def test_the_build_time_is_measured_apart_from_the_solve():
    """The kernel is built and bound once per model: the first solve reports the build, the
    second none (its solve time alone)."""
    import cpm_nlp as cn
    from cpm_nlp.core.solver import SolverConfig

    model = cn.build_model("prs3", {"b": "47.91 mm", "L": "109.215 mm", "alpha0": "33 deg"})
    config = SolverConfig("newton")
    first = cn.forward_kinematics(model, [5e-4, 5e-4, -3e-4], config)
    second = cn.forward_kinematics(model, [4e-4, 5e-4, -3e-4], config)
    assert first.ok and second.ok
    assert first.details["build_seconds"] > 0 and second.details["build_seconds"] < first.details["build_seconds"]
    assert first.details["iterations_counted"] is (first.path == "closed")


def test_the_model_line_shows_declared_parameters_with_their_units(cli):
    """prs3_forward_kinematics.yaml: b = 47.91 mm, L = 109.215 mm, alpha0 = 45 deg (as typed, six
    digits); a and pz0 are derived by the Python add-on, without a declared unit: SI."""
    text = cli("solve", str(PROBLEMS / "prs3_forward_kinematics.yaml")).out
    model = next(line for line in text.splitlines() if line.startswith("model"))
    assert model.startswith("model   : prs3: b = 47.91 mm, L = 109.215 mm, alpha0 = 45 deg; a = ")
    assert model.endswith("(SI)")


def test_many_derived_values_are_counted_not_listed(cli):
    """jansen.yaml derives 22 values (the reference configuration's points): the model line
    gives its 13 declared lengths and the count of the derived ones, which the JSON holds."""
    import json

    text = cli("solve", str(PROBLEMS / "jansen_forward_kinematics.yaml")).out
    model = next(line for line in text.splitlines() if line.startswith("model"))
    assert model.startswith("model   : jansen: a = 38 mm, b = 41.5 mm,") and "m = 15 mm;" in model
    data = json.loads(cli("solve", str(PROBLEMS / "jansen_forward_kinematics.yaml"), "--json").out)
    derived = [k for k in data["model"] if k != "type" and k not in set("abcdefghijklm")]
    assert model.endswith(f"; {len(derived)} derived values (in the JSON result, --json)") and len(derived) > 4
