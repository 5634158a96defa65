"""A refused mechanism file leaves the registry as it was: an edited copy of a shipped file
(the same name) whose model does not build must not replace the shipped mechanism for the
rest of the process (test_file_hinges failed after test_hostile_validity: the refused
bad_prs3.yaml, named prs3_file, had taken the name)."""

from __future__ import annotations

import pytest

import cpm_nlp as cn
from cpm_nlp.mechanisms.registry import mechanism_type

from .conftest import ROOT

PROBLEMS = ROOT / "problems"


def test_a_refused_copy_of_a_shipped_file_does_not_take_its_name(tmp_path):
    shipped = mechanism_type("prs3_file")
    text = (PROBLEMS / "mechanisms" / "prs3.yaml").read_text()
    old = "axes: [[0, -1, 0], [sin(alpha0), 0, cos(alpha0)], [-cos(alpha0), 0, sin(alpha0)]]"
    assert old in text
    (tmp_path / "mechanisms").mkdir()
    bad = tmp_path / "mechanisms" / "prs3.yaml"
    dependent = "axes: [[0, -1, 0], [sin(alpha0), 0, cos(alpha0)], [sin(alpha0), 0, cos(alpha0)]]"
    bad.write_text(text.replace(old, dependent))
    problem = tmp_path / "p.yaml"
    problem.write_text((PROBLEMS / "prs3_file_forward_kinematics.yaml").read_text())
    with pytest.raises(cn.InputError, match="linearly dependent"):
        cn.load_problem(problem)
    assert mechanism_type("prs3_file") is shipped
    model = cn.build_model("prs3_file", {"b": "47.91 mm", "L": "109.215 mm", "alpha0": "45 deg"})
    assert model.closure.nq == 3
