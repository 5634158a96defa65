"""``cpm-nlp describe KIND --mechanism NAME`` and the generated reference page
(cpm_nlp/problems/describe.py): both come from the kinds' declared options."""

from __future__ import annotations

import pytest

from cpm_nlp.core.units import DIMENSIONS
from cpm_nlp.mechanisms.described import shipped_files
from cpm_nlp.mechanisms.registry import mechanism_names, mechanism_type
from cpm_nlp.problems.describe import describe_kind, kind_text, reference_markdown, reference_model
from cpm_nlp.problems.registry import kind_names, problem_kind


def _shipped_names() -> list[str]:
    """The built-in, plugin and shipped-file mechanisms, not the ones other tests described
    (from files or inline) and registered in this process: that made this module depend on
    the order of the tests (test_described's inline prc3 without defaults)."""
    shipped = {f"file {f.resolve()}" for f in shipped_files()}

    def kept(origin) -> bool:
        return origin.kind in ("built-in", "plugin") or str(origin) in shipped

    return [n for n in mechanism_names() if kept(mechanism_type(n).origin)]


@pytest.fixture(scope="module")
def models():
    return {name: reference_model(name) for name in _shipped_names()}


def test_every_input_of_every_kind_is_described_from_its_declared_option(models):
    applied = 0
    for kind_name in kind_names():
        kind = problem_kind(kind_name)
        for mech, (model, source) in models.items():
            desc = describe_kind(kind_name, mech, model, source)
            if kind.supports(model):
                assert desc.unsupported == kind.supports(model) and not desc.inputs
                continue
            applied += 1
            options = kind.input_options(model)
            assert [r.name for r in desc.inputs] == [o.name for o in options]
            for row, option in zip(desc.inputs, options):
                assert option.description.rstrip(".") in row.meaning
                if option.kind in DIMENSIONS and option.kind != "dimensionless":
                    assert row.unit == DIMENSIONS[option.kind].display
                assert row.default == ("required" if option.required else row.default)
            assert list(desc.values) == kind.output_names(model)
    assert applied >= 4 * 8  # the generic kinematic and workspace kinds on all four mechanisms, at least


def test_the_model_comes_from_the_first_shipped_problem_file(models):
    model, source = models["prs3"]
    assert source == "problems/prs3_forward_kinematics.yaml"
    assert model.p[0] == pytest.approx(47.91e-3)  # b of the paper (prs3-ruiz, section 4)


def test_defaults_are_shown_in_display_units():
    desc = describe_kind("rpr_twists", "rpr")
    row = {r.name: r for r in desc.inputs}
    assert row["d"].default == "0.01 mm" and row["d"].unit == "mm"  # 10 µm, section 5.1
    assert "one of 'o_prime', 'o', 'point'" in row["reference"].meaning


def test_cli_prints_the_same_text(cli):
    run = cli("describe", "jacobian", "--mechanism", "pantograph")
    assert run.code == 0, run.err
    assert run.out == kind_text(describe_kind("jacobian", "pantograph"))
    assert "inputs:" in run.out and "values:" in run.out and "manipulability" in run.out


def test_cli_kind_without_mechanism_lists_every_mechanism_it_applies_to(cli):
    run = cli("describe", "amplifier")
    assert run.code == 0 and "mechanism: prc3" in run.out
    not_applied = run.out.split("does not apply to: ")[1].split(")")[0].split(", ")
    assert {"pantograph", "prs3", "rpr"} <= set(not_applied) and "prc3" not in not_applied


def test_cli_bad_names_are_input_errors(cli):
    run = cli("describe", "jacobain", "--mechanism", "prs3")
    assert run.code == 2 and "did you mean 'jacobian'" in run.err
    run = cli("describe", "jacobian", "--mechanism", "prs4")
    assert run.code == 2 and "--mechanism" in run.err and "did you mean 'prs3'" in run.err


def test_reference_page_has_every_kind():
    page = reference_markdown()
    for name in kind_names():
        assert f"## `{name}`" in page
    assert "| `s1` | mm | optional |" in page  # prs3 forward kinematics


def test_a_kind_without_declared_inputs_or_with_a_broken_one(monkeypatch):
    import cpm_nlp.problems.describe as describe
    from cpm_nlp.core.kind import ProblemKind
    from cpm_nlp.mechanisms.registry import PluginError

    class Undeclared(ProblemKind):
        name = "undeclared"

    class Broken(ProblemKind):
        name = "broken"

        def input_options(self, model):
            raise KeyError(model.name)

    kinds = {"undeclared": Undeclared, "broken": Broken}
    monkeypatch.setattr(describe, "problem_kind", lambda name, path=(): kinds[name]())
    monkeypatch.setattr(describe, "kind_origin", lambda name: "plugin")
    desc = describe.describe_kind("undeclared", "prs3")
    assert desc.unsupported and "declares no inputs" in desc.unsupported
    with pytest.raises(PluginError, match="problem kind 'broken' \\(plugin\\): describing its inputs failed"):
        describe.describe_kind("broken", "prs3")


def test_no_nested_input_is_described_as_a_string(models):
    """Issue 22: every nested input (hinges, load, material, stress_limit ...) is declared by
    its schema, so describe prints its keys, not [str]."""
    nested = set()
    for kind_name in kind_names():
        for mech, (model, source) in models.items():
            desc = describe_kind(kind_name, mech, model, source)
            for top in desc.inputs:
                assert top.unit != "str", (kind_name, mech, top.name)
                if top.children:
                    nested.add(top.name)
    assert {"hinges", "material", "load", "stress_limit", "masses", "k_actuator", "guess", "design"} <= nested


def test_describe_prints_the_nested_schema_indented():
    text = kind_text(describe_kind("platform_compliance", "prc3"))
    lines = text.splitlines()
    hinge = lines.index(next(line for line in lines if line.startswith("  hinges ")))
    assert lines[hinge + 2].startswith("    <hinge>")  # a mapping's value, one level in
    joints = next(line for line in lines[hinge:] if line.strip().startswith("joints"))
    assert joints.startswith("      joints") and "[one of] optional" in joints
    assert any(line.startswith("      t ") and "[mm] optional" in line for line in lines)
    assert (
        "one of 'circular_notch', 'circular_notch_paros_weisbord', 'circular_rod', 'filleted_rod', 'leaf_spring'"
        in text
    )
    assert "    x            [N] 0 N" in text  # load on x: a force, default 0


def test_reference_page_defines_each_shared_nested_schema_once():
    page = reference_markdown()
    assert page.count("### `hinges` { #nested-hinges }") == 1
    assert "its keys: [hinges](#nested-hinges)" in page
    assert "| `hinges.<hinge>.t` | mm | optional |" in page
    assert page.count("| `hinges.<hinge>.t` |") == 1
