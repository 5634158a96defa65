"""Hostile numbers: every number is finite, or there is a status (issue 19, "22 inputs
end in an internal error").

A derived value that is not finite (``1e999``, ``10**1000``, ``b/0``, ``0/0``,
``sqrt(-1)``, ``log(0)``, ``acos(2)``, ``exp(1000)``), a 1500-digit integer, a 400-digit
float, Poisson's ratio -1 (in ``inputs.material``, in a mechanism file's
``stiffness.material``, in a file-mechanism problem), a hinge ``k: 1e300 N*m/rad`` and
``sigma_allow: 1e-30 Pa`` are each refused with exit 2 and one line naming the key.
Each case asserts: the exit status and one message naming the file and the key; no
traceback; nothing written and no file changed; under 1 s (after a warm-up solve of the
same problem, so that the time is the refusal's, not CasADi's first code generation).

Then: a result holding a NaN or an inf is the failed status ``not_finite`` (exit 1),
never printed as a number; JSON output (``Result.to_json``, the sweep files) never fails
and never holds NaN or Infinity.
"""

from __future__ import annotations

import json
import math
import shutil
import time

import numpy as np
import pytest
import yaml
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from cpm_nlp.core.outputs import Output, outputs_of
from cpm_nlp.core.result import Result, SolverInfo, Status, finite_status
from cpm_nlp.io.results import _cell
from cpm_nlp.kinds.kinematic import ForwardKinematics
from tests.conftest import PROBLEMS, run_cli
from tests.hostile.test_hostile import HANG_S, assert_refused, dump, snapshot

#: the limit on one refusal (the issue's target), measured after a warm-up
LIMIT_S = HANG_S

BIG_INT = "1" * 1500
BIG_FLOAT = "1" * 400 + ".5"


def _refused(tmp_path, argv, names, key, *, code=2, warm=None):
    """Run ``argv`` (a warm-up first, if given); assert the refusal, the time, and that
    nothing under ``tmp_path`` was written or changed.  Returns the message line."""
    if warm is not None:
        run_cli(*warm)
    before = snapshot(tmp_path)
    t0 = time.perf_counter()
    run = run_cli(*argv)
    elapsed = time.perf_counter() - t0
    line = assert_refused(run, names, key, code=code)
    assert run.out == ""
    assert snapshot(tmp_path) == before
    assert elapsed < LIMIT_S, f"{elapsed:.2f} s: {line}"
    return line


def _mode_args(mode, tmp_path):
    return {"solve": [], "json": ["--json"], "output": ["-o", str(tmp_path / "out.json")]}[mode]


# -- derived values that are not finite ------------------------------------------------------

#: expression -> the operation the message names
DERIVED = {
    "1e999": "beyond the largest float",
    "10**1000": "the power overflows",
    "b/0": "division by zero",
    "0/0": "division by zero",
    "sqrt(-1)": "sqrt of a negative number",
    "log(0)": "log of zero",
    "acos(2)": "acos of a number outside [-1, 1]",
    "exp(1000)": "exp overflows",
}


def _file_mechanism(tmp_path, *, derived=None, material=None, problem="prs3_file_forward_kinematics.yaml"):
    """A copy of the shipped 3-PRS mechanism file (with a derived value ``evil``, or
    another material) and of a problem on it; returns the problem file."""
    mech_dir = tmp_path / "mechanisms"
    mech_dir.mkdir()
    # a changed copy of the built-in prs3's file takes a name of its own
    text = (PROBLEMS / "mechanisms" / "prs3.yaml").read_text().replace("\nname: prs3\n", "\nname: prs3_copy\n")
    if derived is not None:  # as written, quoted: YAML itself reads a bare 1e999 as inf
        assert "\nderived:\n" in text
        text = text.replace("\nderived:\n", f"\nderived:\n  evil: {json.dumps(derived)}\n")
    if material is not None:
        data = yaml.safe_load(text)
        data["stiffness"]["material"] = material
        text = dump(data)
    (mech_dir / "prs3.yaml").write_text(text)
    target = tmp_path / problem
    shutil.copy(PROBLEMS / problem, target)
    return target


@pytest.mark.parametrize("mode", ["solve", "json", "output"])
@pytest.mark.parametrize("expression", list(DERIVED))
def test_a_derived_value_that_is_not_finite_is_refused(tmp_path, expression, mode):
    problem = _file_mechanism(tmp_path, derived=expression)
    line = _refused(tmp_path, ["solve", str(problem), *_mode_args(mode, tmp_path)], problem.name, "derived.evil")
    assert "mechanisms/prs3.yaml" in line and repr(expression) in line, line
    assert DERIVED[expression] in line, line
    assert not (tmp_path / "out.json").exists()


@pytest.mark.parametrize("literal", ["1e999", "-1e999", ".inf", ".nan", BIG_FLOAT])
def test_a_derived_number_yaml_reads_as_not_finite_is_refused(tmp_path, literal):
    problem = _file_mechanism(tmp_path, derived="PLACEHOLDER")
    mech = tmp_path / "mechanisms" / "prs3.yaml"
    mech.write_text(mech.read_text().replace('"PLACEHOLDER"', literal))
    line = _refused(tmp_path, ["solve", str(problem), "--json"], problem.name, "derived.evil")
    assert "expected a finite number" in line


def test_a_derived_value_not_finite_for_the_given_parameters_names_them(tmp_path):
    """sqrt(b*b - L*L) is an expression of the parameters: NaN only once b < L is given."""
    problem = _file_mechanism(tmp_path, derived={"value": "sqrt(b*b - L*L)", "dimension": "length"})
    line = _refused(tmp_path, ["solve", str(problem), "--json"], problem.name, "mechanism.parameters")
    assert "derived.evil" in line and "sqrt of a negative number" in line and "b = 47.91 mm" in line, line
    assert "b*b - L*L = " in line and " m^2" in line, line  # the square root's argument, with its value


# -- numbers no float holds ------------------------------------------------------------------


@pytest.mark.parametrize("literal", [BIG_INT, BIG_FLOAT], ids=["1500-digit integer", "400-digit float"])
@pytest.mark.parametrize(
    "where,key",
    [("    b: 47.91 mm", "mechanism.parameters.b"), ("  s1: 1.0 mm", "inputs.s1")],
    ids=["parameter", "input"],
)
def test_a_number_no_float_holds_is_refused(tmp_path, literal, where, key):
    problem = tmp_path / "fk.yaml"
    text = (PROBLEMS / "prs3_forward_kinematics.yaml").read_text()
    assert where in text
    problem.write_text(text.replace(where, where.split(":")[0] + ": " + literal))
    line = _refused(tmp_path, ["solve", str(problem), "-o", str(tmp_path / "out.json")], problem, key)
    assert ("too large" if literal == BIG_INT else "finite") in line, line


def test_a_1500_digit_integer_anywhere_is_refused(tmp_path):
    """Even where no option reads it as a number (a sweep's seed, a solver option)."""
    problem = tmp_path / "sweep.yaml"
    data = yaml.safe_load((PROBLEMS / "sweep_rpr_transmission.yaml").read_text())
    data["sweep"]["seed"] = "HUGE"
    problem.write_text(dump(data).replace("HUGE", BIG_INT))
    line = _refused(tmp_path, ["check", str(problem)], problem, "sweep.seed")
    assert "1500 digits" in line


def test_a_1500_digit_integer_in_an_expression_is_refused(tmp_path):
    problem = _file_mechanism(tmp_path, derived="PLACEHOLDER")
    mech = tmp_path / "mechanisms" / "prs3.yaml"
    mech.write_text(mech.read_text().replace("PLACEHOLDER", BIG_INT + "*b"))
    assert BIG_INT in mech.read_text()
    line = _refused(tmp_path, ["solve", str(problem)], problem.name, "derived.evil")
    assert "too large" in line


@pytest.mark.parametrize("published", ["0e400 N", "0e99999999 N"])
def test_a_published_figure_whose_last_digit_no_float_holds_is_refused(tmp_path, published):
    """The tolerance of a reproduced row is half a unit of its last printed digit: 10^400."""
    problem = tmp_path / "t2.yaml"
    problem.write_text(
        (PROBLEMS / "prs3_table2_forces.yaml").read_text().replace("published: 20 N", f"published: {published}", 1)
    )
    _refused(tmp_path, ["check", str(problem)], problem, "reproduce.rows[0].published")


def test_a_length_whose_products_underflow_is_refused(tmp_path):
    """1e-320 mm: the 3-PRC lever ratio L2 L4 / (L1 L3) divided by zero."""
    problem = tmp_path / "fk.yaml"
    shutil.copy(PROBLEMS / "prc3_forward_kinematics.yaml", problem)
    argv = ["solve", str(problem), "--set", "mechanism.parameters.L1=1e-320 mm"]
    line = _refused(tmp_path, argv, problem, "mechanism.parameters.L1")
    assert "sanity limit" in line


# -- material and hinge values ---------------------------------------------------------------

MATERIAL_NU = {"E": "72 GPa", "nu": -1, "density": "2.81 g/cm^3", "yield_strength": "503 MPa", "allowable": "400 MPa"}


def _table2(tmp_path, *, file_mechanism=False, inputs=None):
    """Table 2 of the 3-PRS (actuator forces), on the built-in or the file mechanism,
    with ``inputs`` added."""
    if file_mechanism:
        problem = _file_mechanism(tmp_path, problem="prs3_file_table2_forces.yaml")
    else:
        problem = tmp_path / "prs3_table2_forces.yaml"
        shutil.copy(PROBLEMS / problem.name, problem)
    data = yaml.safe_load(problem.read_text())
    data.pop("reproduce", None)
    data["inputs"].update(inputs or {})
    problem.write_text(dump(data))
    return problem


@pytest.fixture(scope="module")
def warm_table2(tmp_path_factory):
    """The argv of a solve of Table 2 (the built-in 3-PRS and the file one), for warm-ups."""
    folder = tmp_path_factory.mktemp("warm")
    built_in = _table2(folder)
    run_cli("solve", str(built_in))
    return ["solve", str(built_in)]


def test_poisson_ratio_minus_one_in_inputs_material(tmp_path, warm_table2):
    problem = _table2(tmp_path, inputs={"material": MATERIAL_NU})
    line = _refused(tmp_path, ["solve", str(problem), "--json"], problem, "inputs.material.nu")
    assert "(-1, 0.5)" in line


def test_poisson_ratio_minus_one_in_a_mechanism_files_stiffness(tmp_path):
    problem = _file_mechanism(tmp_path, material=MATERIAL_NU, problem="prs3_file_table2_forces.yaml")
    line = _refused(tmp_path, ["solve", str(problem), "--json"], problem.name, "stiffness.material.nu")
    assert "mechanisms/prs3.yaml" in line and "(-1, 0.5)" in line


def test_poisson_ratio_minus_one_in_a_file_mechanism_problem(tmp_path):
    problem = _table2(tmp_path, file_mechanism=True, inputs={"material": MATERIAL_NU})
    _refused(tmp_path, ["solve", str(problem), "-o", str(tmp_path / "o.json")], problem, "inputs.material.nu")


@pytest.mark.parametrize("nu", [-1, 0.5, -1.5, 0.7])
def test_poisson_ratio_outside_its_physical_range(tmp_path, nu):
    problem = _table2(tmp_path, inputs={"material": {**MATERIAL_NU, "nu": nu}})
    _refused(tmp_path, ["check", str(problem)], problem, "inputs.material.nu")


@pytest.mark.parametrize(
    "prop,value", [("E", "0 GPa"), ("density", "-1 kg/m^3"), ("yield_strength", "0 MPa"), ("allowable", "-5 MPa")]
)
def test_material_properties_are_positive(tmp_path, prop, value):
    problem = _table2(tmp_path, inputs={"material": {**MATERIAL_NU, "nu": 0.33, prop: value}})
    _refused(tmp_path, ["check", str(problem)], problem, f"inputs.material.{prop}")


def test_a_hinge_stiffness_of_1e300_is_refused(tmp_path, warm_table2):
    problem = _table2(tmp_path, inputs={"hinges": {"revolute": {"k": "1e300 N*m/rad"}}})
    line = _refused(tmp_path, ["solve", str(problem), "--json"], problem, "inputs.hinges.revolute.k")
    assert "sanity limit" in line


def test_an_allowable_stress_of_1e_30_pa_is_refused(tmp_path, warm_table2):
    """Below the stress the model resolves at the start of the motion: no root to bracket."""
    problem = _table2(tmp_path, inputs={"sigma_allow": "1e-30 Pa"})
    line = _refused(
        tmp_path,
        ["solve", str(problem), "-o", str(tmp_path / "o.json")],
        problem,
        "inputs.sigma_allow",
        warm=warm_table2,
    )
    assert "give a larger sigma_allow" in line


# -- results that are not finite ---------------------------------------------------------------


def test_a_result_that_is_not_finite_is_a_failed_status(tmp_path, monkeypatch):
    """Whatever a kind computes, a NaN or an inf is never printed as an answer."""
    real = ForwardKinematics.run

    def run(self, model, inputs, solver):
        result = real(self, model, inputs, solver)
        return result.set({"pz": math.inf, "psi": [0.1, math.nan]})

    monkeypatch.setattr(ForwardKinematics, "run", run)
    problem = tmp_path / "fk.yaml"
    shutil.copy(PROBLEMS / "prs3_forward_kinematics.yaml", problem)
    printed = run_cli("solve", str(problem))
    assert printed.code == 1, printed.err
    assert "status  : not_finite" in printed.out
    table = printed.out.split("\n\n", 1)[1]  # the values, after the header
    assert "inf" not in table and "nan" not in table.lower(), table
    assert [line.split()[1] for line in table.splitlines() if line.startswith("pz ")] == ["—"]
    out = tmp_path / "o.json"
    run = run_cli("solve", str(problem), "--json", "-o", str(out))
    assert run.code == 1
    for text in (run.out, out.read_text()):
        doc = json.loads(text, parse_constant=_no_constant)
        assert doc["status"] == "not_finite"
        assert doc["values"]["pz"] is None and doc["values"]["psi"] == [0.1, None]
        assert "pz" in doc["message"] and "psi[1]" in doc["message"]


def test_a_failed_result_keeps_its_status_and_loses_its_infs():
    outputs = outputs_of({"a": "vector", "b": "length"})
    r = Result("x", Status.NOT_CONVERGED, outputs, {"a": np.array([1.0, np.inf]), "b": 2.0}, message="no")
    finite_status(r)
    assert r.status is Status.NOT_CONVERGED and r.values == {"a": [1.0, None], "b": 2.0}
    assert r.message.startswith("not finite") and r.message.endswith("; no")


# -- JSON never fails and never holds NaN or Infinity ---------------------------------------------


def _no_constant(name):
    raise AssertionError(f"{name} in JSON output")


_scalars = st.one_of(
    st.none(),
    st.booleans(),
    st.integers(),
    st.floats(allow_nan=True, allow_infinity=True),
    st.text(max_size=8),
    st.complex_numbers(allow_nan=True, allow_infinity=True),
    st.floats(allow_nan=True, allow_infinity=True).map(np.float64),
    st.integers(-(2**63), 2**63 - 1).map(np.int64),
    st.sampled_from(list(Status)),
)
_keys = st.one_of(st.text(max_size=5), st.integers(), st.floats(allow_nan=True), st.booleans(), st.none())
_values = st.recursive(
    _scalars,
    lambda inner: st.one_of(
        st.lists(inner, max_size=4),
        st.lists(inner, max_size=4).map(tuple),
        st.dictionaries(_keys, inner, max_size=4),
        st.lists(st.floats(allow_nan=True, allow_infinity=True), max_size=4).map(np.array),
    ),
    max_leaves=30,
)


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    # names without braces: a name with fields in braces declares a family (Output(per=...))
    values=st.dictionaries(st.text(max_size=5).filter(lambda k: "{" not in k and "}" not in k), _values, max_size=5),
    model=st.dictionaries(st.text(max_size=5), _values, max_size=3),
)
def test_result_to_json_never_fails_nor_holds_nan(values, model):
    outputs = [Output("a", "length")] + [Output(k, "text", "text") for k in values if k != "a"]
    r = Result("p", Status.SOLVED, outputs, values, solver=SolverInfo("s", 1, math.nan), message="msg", model=model)
    text = r.to_json()
    json.loads(text, parse_constant=_no_constant)
    finite_status(r)
    json.loads(r.to_json(indent=None), parse_constant=_no_constant)


@given(value=_values)
@settings(max_examples=200, deadline=None)
def test_a_sweep_cell_is_never_nan(value):
    text = _cell(value)
    if isinstance(value, str):
        return
    if text and text[:1] in "[{":
        json.loads(text, parse_constant=_no_constant)
    assert text.lower() not in ("nan", "inf", "-inf"), text
