"""A refused mechanism file leaves the registry as it was: an edited copy of a shipped file
(the same name) whose model does not build must not replace the shipped mechanism for the
rest of the process (test_file_hinges failed after test_hostile_validity: the refused
bad_prs3.yaml, named prs3_file, had taken the name).  A shipped file that is a built-in
mechanism (prs3, issue 21) is not replaced at all: a changed copy under its name is refused."""

from __future__ import annotations

import pytest

import cpm_nlp as cn
from cpm_nlp.mechanisms.registry import mechanism_type

from .conftest import ROOT

PROBLEMS = ROOT / "problems"


def test_a_refused_copy_of_a_shipped_file_does_not_take_its_name(tmp_path):
    shipped = mechanism_type("prs3_as_built")
    text = (PROBLEMS / "mechanisms" / "prs3_as_built.yaml").read_text()
    old = 'axes: ["cross(n, l)", n, l]'
    assert old in text
    (tmp_path / "mechanisms").mkdir()
    bad = tmp_path / "mechanisms" / "prs3_as_built.yaml"
    bad.write_text(text.replace(old, "axes: [n, n, l]"))
    problem = tmp_path / "p.yaml"
    problem.write_text((PROBLEMS / "prs3_as_built_forward_kinematics.yaml").read_text())
    with pytest.raises(cn.InputError, match="linearly dependent"):
        cn.load_problem(problem)
    assert mechanism_type("prs3_as_built") is shipped
    model = cn.build_model("prs3_as_built")
    assert model.closure.nq == 3


def test_a_changed_copy_of_a_built_in_file_is_refused_by_name(tmp_path):
    shipped = mechanism_type("prs3")
    text = (PROBLEMS / "mechanisms" / "prs3.yaml").read_text()
    (tmp_path / "mechanisms").mkdir()
    changed = text.replace("bounds: [0 m, 1 m], strict: true", "bounds: [0 m, 2 m], strict: true")
    assert changed != text
    (tmp_path / "mechanisms" / "prs3.yaml").write_text(changed)
    problem = tmp_path / "p.yaml"
    problem.write_text((PROBLEMS / "prs3_file_forward_kinematics.yaml").read_text())
    with pytest.raises(cn.InputError, match="'prs3' is the built-in mechanism of .*prs3.yaml.*rename it") as info:
        cn.load_problem(problem)
    assert "prs3_edited" in info.value.render()
    assert mechanism_type("prs3") is shipped and mechanism_type("prs3_file") is shipped
    # an unchanged copy elsewhere (cpm-nlp init's problems/) is the built-in; so is the
    # shipped file itself, named by a problem file
    (tmp_path / "mechanisms" / "prs3.yaml").write_text(text)
    assert cn.load_problem(problem).model.closure.mechanism is shipped
    assert cn.load_problem(PROBLEMS / "prs3_file_forward_kinematics.yaml").model.closure.mechanism is shipped
    assert mechanism_type("prs3") is shipped
