"""Kinds declare their outputs (name, dimension, role) and their Result is built from the
declaration (issue 22, item 2): units and dimensions in one place, in the declared order."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from cpm_nlp.core.outputs import Output, declared_result
from cpm_nlp.core.result import Status
from cpm_nlp.problems.file import load_problem, solve

PROBLEMS = Path(__file__).resolve().parents[2] / "problems"


def test_a_declared_result_takes_units_and_dimensions_from_its_outputs():
    outputs = [
        Output("x", "length"),
        Output("dx", "length", "reference", "x"),
        Output("phi", "angle"),
        Output("J", "matrix", "matrix", unit="rows x [m] per columns q [m]"),
        Output("note", "text", "text"),
    ]
    res = declared_result("k", Status.SOLVED, outputs, {"x": 0.1, "dx": 0.0, "phi": 0.2, "J": [[1.0]], "note": "n"})
    assert list(res.units.items()) == [
        ("x", "m"),
        ("dx", "m"),
        ("phi", "rad"),
        ("J", "rows x [m] per columns q [m]"),
        ("note", "text"),  # a value without SI unit: what it is, as results have always written it
    ]
    assert res.dimensions == {"x": "length", "dx": "length", "phi": "angle", "J": "matrix", "note": "text"}


def test_a_bad_declaration_is_refused():
    with pytest.raises(ValueError, match="role must be one of"):
        Output("x", "length", "vector")
    with pytest.raises(ValueError, match="refers_to"):
        Output("dx", "length", "reference")
    with pytest.raises(ValueError, match="declared twice"):
        declared_result("k", Status.SOLVED, [Output("x", "length"), Output("x", "angle")], {})


@pytest.mark.parametrize("name", ["five_bar_jacobian.yaml", "prs3_jacobian.yaml"])
def test_the_jacobian_kind_returns_what_it_declares(name):
    problem = load_problem(PROBLEMS / name)
    res = solve(problem)
    assert res.ok, res.message
    declared = problem.kind.output_names(problem.model)
    assert list(res.units) == declared and list(res.dimensions) == declared
    assert set(res.values) == set(declared)
    assert res.units["characteristic_length"] == "m" and res.dimensions["J"] == "matrix"
    assert res.units["J"].startswith("rows ") and " per columns " in res.units["J"]


# -- a Result holds its declared outputs and their values (one source for values, units, dimensions)


def _declared() -> list[Output]:
    return [Output("x", "length"), Output("phi", "angle"), Output("note", "text", "text", unit="")]


def test_values_units_and_dimensions_are_read_only_views_of_one_declaration():
    res = declared_result("k", Status.SOLVED, _declared(), {"phi": 0.5, "x": 0.1})
    for view in (res.values, res.units, res.dimensions):
        with pytest.raises(TypeError):
            view["x"] = 1.0  # type: ignore[index]
    with pytest.raises(AttributeError):
        res.values = {}  # type: ignore[misc]
    # each value with its declaration: the unit and dimension a value has are those declared
    assert {n: (e.output.si, e.output.dimension, e.value) for n, e in res.entries.items()} == {
        "phi": ("rad", "angle", 0.5),
        "x": ("m", "length", 0.1),
    }


def test_a_value_of_no_declared_output_is_refused():
    with pytest.raises(ValueError, match="no declared output: y"):
        declared_result("k", Status.SOLVED, _declared(), {"x": 0.1, "y": 2.0})
    res = declared_result("k", Status.SOLVED, _declared(), {"x": 0.1})
    with pytest.raises(ValueError, match="no declared output: z"):
        res.set({"z": 1.0})
    assert dict(res.values) == {"x": 0.1}  # nothing set by the refused call


def test_the_json_keeps_the_declared_order_for_units_and_the_computed_order_for_values():
    """The JSON a result writes (read back by ``cpm-nlp plot`` and io/results.py): units in
    the declared order, for every declared output (one without a value too), values in the
    order computed; ``keep`` (a problem's ``outputs``) drops values, not units."""
    res = declared_result("k", Status.SOLVED, _declared(), {"phi": 0.5, "x": 0.1})
    doc = json.loads(res.to_json())
    assert list(doc["values"]) == ["phi", "x"]
    assert list(doc["units"].items()) == [("x", "m"), ("phi", "rad"), ("note", "")]
    res.keep(["x"])
    doc = json.loads(res.to_json())
    assert doc["values"] == {"x": 0.1} and list(doc["units"]) == ["x", "phi", "note"]
    assert res.to_json() == json.dumps(json.loads(res.to_json()), indent=2)  # the same text, key for key


def test_a_result_extended_by_a_kind_declares_what_it_adds():
    res = declared_result("k", Status.SOLVED, _declared(), {"x": 0.1})
    res.declare([Output("J", "matrix", "matrix", unit="rows x per columns q")]).set({"J": [[1.0]]})
    assert res.units["J"] == "rows x per columns q" and res.dimensions["J"] == "matrix"
    with pytest.raises(ValueError, match="declared twice"):
        res.declare([Output("x", "angle")])


@pytest.mark.parametrize(
    "name",
    [
        "prs3_forward_kinematics.yaml",
        "five_bar_joint_requirements.yaml",
        "five_bar_platform_compliance.yaml",
        "rrr3_workspace.yaml",
        "prc3_amplifier.yaml",
        "prc3_dynamics.yaml",
        "five_bar_synthesis.yaml",
        "pantograph_synthesis.yaml",
    ],
)
def test_a_kind_writes_the_units_it_declares(name):
    """What ``cpm-nlp describe`` lists (the kind's declared outputs) is what a solved result
    writes: each unit and dimension of the result is its declared output's."""
    problem = load_problem(PROBLEMS / name)
    res = solve(problem)
    assert res.ok, res.message
    families = [o for o in problem.kind.outputs(problem.model) if o.family]
    declared = {o.name: o for o in problem.kind.outputs(problem.model) if not o.family}
    # a hinge group the problem gives (not the mechanism) is a member of a declared family
    undeclared = [o for o in res.outputs if o.name not in declared]
    assert all(any(f.covers(o) for f in families) for o in undeclared), undeclared
    assert len(set(res.units) & set(declared)) >= 4
    for n in set(res.units) & set(declared):
        assert (res.units[n], res.dimensions[n]) == (declared[n].si, declared[n].dimension), n


def test_the_unit_of_a_physical_dimension_is_core_units_own():
    """Units derive in one place: an output of a dimension of core.units writes its SI unit,
    across every declared output of the generic kinds on a shipped mechanism."""
    from cpm_nlp.core.units import DIMENSIONS
    from cpm_nlp.problems.describe import reference_model
    from cpm_nlp.problems.registry import kind_names, problem_kind

    model, _ = reference_model("prs3")
    checked = 0
    for kind_name in kind_names():
        kind = problem_kind(kind_name)
        if kind.supports(model):
            continue
        try:
            outputs = kind.outputs(model)
        except NotImplementedError:
            continue
        for o in outputs:
            if o.dimension in DIMENSIONS and o.unit is None:
                assert o.si == DIMENSIONS[o.dimension].si, (kind_name, o)
                checked += 1
    assert checked > 50


def test_a_result_built_the_old_way_says_how_to_build_it():
    """A plugin that still passes the values (a mapping) where the outputs go is told how to
    build a result, not left with an AttributeError."""
    from cpm_nlp.core.result import Result

    with pytest.raises(TypeError, match="declared_result"):
        Result("k", Status.SOLVED, {"x": 0.1}, {"x": "m"})  # type: ignore[arg-type]
