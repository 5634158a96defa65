"""Kinds declare their outputs (name, dimension, role) and their Result is built from the
declaration (issue 22, item 2): units and dimensions in one place, in the declared order."""

from __future__ import annotations

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
