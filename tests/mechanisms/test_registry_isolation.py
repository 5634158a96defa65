"""A refused mechanism file leaves the registry as it was: an edited copy of a shipped file
(the same name) whose model does not build must not replace the shipped mechanism for the
rest of the process (test_file_hinges failed after test_hostile_validity: the refused
bad_prs3.yaml, named prs3_file, had taken the name).  A shipped file that is a built-in
mechanism (prs3, issue 21) is not replaced at all: a changed copy under its name is refused."""

from __future__ import annotations

import pytest

import cpm_nlp as cn
from cpm_nlp.mechanisms.registry import mechanism_type
from tests.conftest import ROOT

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
    for model in (
        cn.load_problem(problem).model,
        cn.load_problem(PROBLEMS / "prs3_file_forward_kinematics.yaml").model,
    ):
        assert model.mechanism is shipped and model.closure is shipped.closure()
    assert mechanism_type("prs3") is shipped


def _my_five_bar(tmp_path, sub: str, crank: str):
    """A user's copy of the five-bar file under its own name ``my_five_bar``, crank length ``crank``."""
    text = (PROBLEMS / "mechanisms" / "five_bar.yaml").read_text()
    old = "l1: {dimension: length, default: 100 mm"
    assert old in text and "name: five_bar\n" in text
    folder = tmp_path / sub
    folder.mkdir()
    mine = text.replace("name: five_bar\n", "name: my_five_bar\n")
    (folder / "mine.yaml").write_text(mine.replace(old, f"l1: {{dimension: length, default: {crank}"))
    problem = folder / "p.yaml"
    fk = (PROBLEMS / "five_bar_forward_kinematics.yaml").read_text()
    problem.write_text(fk.replace("mechanisms/five_bar.yaml", "mine.yaml"))
    return problem


def test_loading_and_solving_a_problem_registers_nothing(tmp_path):
    """Issue 22, item 3: a problem's own mechanism file gives its model; the registry of
    mechanism types is the same before and after loading and solving it."""
    from cpm_nlp.mechanisms.registry import mechanism_names

    before = mechanism_names()
    problem = cn.load_problem(_my_five_bar(tmp_path, "a", "100 mm"))
    result = cn.solve(problem)
    assert result.ok
    assert problem.model.name == "my_five_bar" and problem.model.mechanism.name == "my_five_bar"
    assert mechanism_names() == before and "my_five_bar" not in before
    with pytest.raises(cn.InputError, match="unknown mechanism type 'my_five_bar'"):
        mechanism_type("my_five_bar")
    # solve --plot draws the model solved (its mechanism read from the result's live model)
    pytest.importorskip("matplotlib")
    from cpm_nlp.plot import figures

    data = figures.from_result(result)
    data.live = problem.model
    _fig, kind = figures.figure(data, "mechanism")
    assert kind == "mechanism"
    assert mechanism_names() == before


def test_two_files_of_one_name_load_side_by_side(tmp_path):
    """Two problems whose files share ``name:`` but differ (crank 100 mm and 120 mm) each get
    their own mechanism, in either order, in one process; the end effector of the FK of each
    agrees with an independent two-circle intersection (numpy) of its own crank length."""
    import numpy as np

    a = cn.load_problem(_my_five_bar(tmp_path, "a", "100 mm"))
    b = cn.load_problem(_my_five_bar(tmp_path, "b", "120 mm"))
    again = cn.load_problem(_my_five_bar(tmp_path, "c", "100 mm"))
    assert a.model.mechanism is not b.model.mechanism
    assert a.model.parameters["l1"] == pytest.approx(0.100) and b.model.parameters["l1"] == pytest.approx(0.120)
    assert again.model.parameters["l1"] == pytest.approx(0.100)
    for problem in (a, b, again):
        result = cn.solve(problem)
        assert result.ok
        prm = problem.model.parameters
        d, l1, l2 = prm["d"], prm["l1"], prm["l2"]
        q1, q2 = np.radians(118.0), np.radians(63.0)  # the inputs of five_bar_forward_kinematics.yaml
        e1 = np.array([-d / 2 + l1 * np.cos(q1), l1 * np.sin(q1)])
        e2 = np.array([d / 2 + l1 * np.cos(q2), l1 * np.sin(q2)])
        mid, span = (e1 + e2) / 2, np.linalg.norm(e2 - e1)  # two circles of radius l2 about e1, e2
        normal = np.array([-(e2 - e1)[1], (e2 - e1)[0]]) / span
        p_up = mid + np.sqrt(l2**2 - (span / 2) ** 2) * normal * np.sign(normal[1])  # elbows out: P above
        assert [result.values["x"], result.values["y"]] == pytest.approx(p_up, abs=1e-9)
