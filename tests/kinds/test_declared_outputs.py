"""Every kind declares its outputs up front (issue 22, item 2): name, dimension, role and unit,
on every mechanism it applies to -- the generic kinds, the mechanisms' own kinds and
synthesis formulations, on the built-in mechanisms and on the plugin example of
tests/plugin_pkg -- and ``cpm-nlp describe`` prints each with its unit and dimension.
Solving a shipped problem gives exactly what its kind declares: each value of the result
is a declared output (or a member of a declared family), with the declared unit and dimension."""

from __future__ import annotations

import importlib.util
import re
from pathlib import Path

import pytest

import cpm_nlp as cn
from cpm_nlp.core.outputs import Output
from cpm_nlp.core.units import DIMENSIONS, result_unit
from cpm_nlp.problems.describe import describe_kind, kind_text, reference_model
from cpm_nlp.problems.registry import kind_names, problem_kind

ROOT = Path(__file__).resolve().parents[2]
PROBLEMS = ROOT / "problems"
PLUGIN = ROOT / "tests" / "plugin_pkg" / "cpm_nlp_demo_plugin" / "__init__.py"

#: dimensions with no unit of their own: a number, a text, a flag (their unit text may be empty)
NO_UNIT = ("dimensionless", "text", "bool")


@pytest.fixture(scope="module")
def plugin_mechanism():
    """The demo plugin's biglide, registered in code for the module (not installed)."""
    spec = importlib.util.spec_from_file_location("cpm_nlp_demo_plugin_h22", PLUGIN)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    cn.register_mechanism(module.MECHANISM)
    yield module.MECHANISM.name
    cn.unregister_mechanism(module.MECHANISM.name)


def _kinds_on(mechanism: str):
    model, source = reference_model(mechanism)
    for name in kind_names():
        kind = problem_kind(name)
        if kind.supports(model) is None:
            yield kind, model, source


def _check_declared(mechanism: str) -> int:
    """Every kind on ``mechanism`` declares its outputs, and describe prints each with its unit
    and dimension; returns how many kinds were checked."""
    checked = 0
    for kind, model, source in _kinds_on(mechanism):
        declared = kind.outputs(model)  # raises NotImplementedError for a kind that declares none
        assert declared, (kind.name, mechanism)
        desc = describe_kind(kind.name, mechanism, model, source)
        assert [r.name for r in desc.outputs] == [o.name for o in declared], (kind.name, mechanism)
        text = kind_text(desc)
        values = text.split("\nvalues:\n", 1)[1]
        for row, out in zip(desc.outputs, declared, strict=True):
            where = (kind.name, mechanism, out.name)
            assert row.dimension == out.dimension and row.dimension, where
            assert row.unit == out.si, where
            # a physical dimension writes its SI unit; every other value says what it holds
            if out.dimension in DIMENSIONS and out.unit is None:
                assert row.unit == result_unit(out.dimension), where
            assert row.unit or out.dimension in NO_UNIT or out.role == "text", where
            line = f"  {row.name:<14} [{row.unit}] {row.dimension}"
            assert line in values, (where, line)
            if out.family:  # a family says what its members are one per
                assert f"one per {out.per}" in values, where
        checked += 1
    return checked


@pytest.mark.parametrize("mechanism", cn.mechanism_names())
def test_every_kind_declares_its_outputs_on_every_builtin_mechanism(mechanism):
    assert _check_declared(mechanism) >= 8


def test_every_kind_declares_its_outputs_on_the_plugin_example(plugin_mechanism):
    assert _check_declared(plugin_mechanism) >= 8


def test_the_kinds_own_to_a_mechanism_are_among_those_checked():
    """The RPR's kinds, its synthesis formulation and the pantograph's cuboid values are
    declared (each was names only before)."""
    model, _ = reference_model("rpr")
    for name in ("rpr_compliance", "rpr_joint_design", "rpr_screw_jacobian", "rpr_twists", "rpr_transmission_map"):
        assert problem_kind(name).outputs(model)
    assert {o.name for o in problem_kind("synthesis").outputs(model)} >= {"l1", "eta", "r1", "optima"}
    pantograph, _ = reference_model("pantograph")
    cuboid = {o.name: o for o in problem_kind("inscribed_cuboid").outputs(pantograph)}
    assert cuboid["x_hat"].dimension == "length" and cuboid["paper_volume"].dimension == "volume"
    assert cuboid["paper_check_margin"].si == "SI unit of the binding quantity"


def test_names_from_a_part_are_the_parts():
    """The hinge groups of the mechanism's JointStiffness (prs3: revolute, spherical) give the
    stress and formula-stiffness outputs; a problem's own groups are members of the families."""
    model, _ = reference_model("prs3")
    declared = problem_kind("actuator_forces").outputs(model)
    names = [o.name for o in declared]
    assert {"stress_revolute", "stress_spherical", "k_formula_revolute_bend"} <= set(names)
    family = next(o for o in declared if o.name == "stress_{group}")
    assert family.covers(Output("stress_leaf", "stress")) and not family.covers(Output("stress_leaf", "length"))
    assert "stress_{group}" not in problem_kind("actuator_forces").output_names(model)
    compliance = [o.name for o in problem_kind("platform_compliance").outputs(model)]
    assert {"stress_revolute_loaded", "stress_{group}_loaded"} <= set(compliance)


def _shipped() -> list[str]:
    return sorted(p.name for p in PROBLEMS.glob("*.yaml"))


@pytest.mark.parametrize("name", _shipped())
def test_a_shipped_problem_gives_exactly_the_declared_outputs(name, shipped_solve):
    problem, res = shipped_solve(Path(name).stem)  # the file as it is, its outputs selection kept
    assert res.ok, (name, res.status, res.message)
    declared = problem.kind.outputs(problem.model)
    for out in res.outputs:
        assert any(d.covers(out) for d in declared), (name, out)
    assert set(res.values) <= {o.name for o in res.outputs}
    # the default names are each declared once, and a family's name is no value's
    plain = [o.name for o in declared if not o.family]
    assert len(plain) == len(set(plain)), name
    assert not any(re.search(r"\{\w+\}", v) for v in res.values), name


def test_the_reference_page_lists_every_value_with_its_unit():
    """The generated docs reference (problems/describe.reference_markdown) has a table of values
    with unit and dimension for every kind on every mechanism, never a bare list of names."""
    from cpm_nlp.problems.describe import reference_markdown

    page = reference_markdown()
    assert "\nValues: " not in page
    assert "| `c_r` | rad/(N*m) | rotational_compliance |" in page
    assert "| `stress_{group}` | Pa | stress | one per hinge group with a flexure type |" in page
    assert "| `x_hat` | m | length |" in page  # the pantograph's cuboid values, from its part
    assert "| `modes` |  | dimensionless | with assembly_modes: all |" in page
