"""The nested input declarations of cpm_nlp/core/schema.py: records, mappings, lists,
alternatives, named tables and quantities; units read in SI, choices and unknown keys
with a "did you mean", required and optional keys, bad types named by their key path,
and the check/convert hooks."""

from __future__ import annotations

import math

import numpy as np
import pytest

from cpm_nlp.analysis import compliance as cm
from cpm_nlp.analysis import flexure
from cpm_nlp.core.errors import InputError
from cpm_nlp.core.options import REQUIRED, Option, validate_mapping
from cpm_nlp.core.schema import Either, ListOf, MappingOf, Quantity, Record, walk

LEAF = Record(
    "leaf",
    "a leaf hinge",
    (
        Option("length", "length", "leaf length", lower=0.0, strict=True),
        Option("thickness", "length", "leaf thickness", default=0.1e-3, lower=0.0, strict=True),
        Option("shape", "choice", "profile", default="flat", choices=("flat", "notched")),
    ),
    what="leaf key",
)
STAGE = Record(
    "stage",
    "a stage",
    (
        Option("travel", "length", "travel"),
        LEAF,
        MappingOf("hinges", "hinge name -> leaf", LEAF, key_what="hinge", default=None, nullable=True),
        ListOf("points", "points", Record("point", "a point", (Option("x", "length", "x"),)), default=None),
    ),
    what="stage key",
)


def _error(node, value, path=("inputs", "stage")) -> InputError:
    with pytest.raises(InputError) as info:
        node.parse(value, path)
    return info.value


def test_nested_records_read_units_in_si_and_fill_defaults():
    got = STAGE.parse(
        {
            "travel": "1.2 mm",
            "leaf": {"length": "5 mm", "shape": "notched"},
            "hinges": {"a": {"length": "2 um", "thickness": "50 um"}, "b": None},
            "points": [{"x": "3 mm"}, {"x": 0.004}],
        },
        ("inputs", "stage"),
    )
    # independent: 1.2 mm = 1.2e-3 m, 2 um = 2e-6 m; a bare number is SI
    assert got["travel"] == pytest.approx(1.2e-3, rel=1e-15)
    assert got["leaf"] == {"length": pytest.approx(5e-3), "thickness": 0.1e-3, "shape": "notched"}
    assert got["hinges"]["a"]["length"] == pytest.approx(2e-6) and got["hinges"]["a"]["shape"] == "flat"
    assert got["hinges"]["b"] is None  # nullable: "remove this one"
    assert [p["x"] for p in got["points"]] == [pytest.approx(3e-3), 0.004]


def test_unknown_keys_name_their_path_with_a_did_you_mean():
    e = _error(STAGE, {"travel": "1 mm", "leaf": {"length": "1 mm", "thicknes": "1 um"}})
    assert e.path == ("inputs", "stage", "leaf")
    assert str(e) == (
        "inputs.stage.leaf: unknown leaf key 'thicknes'; expected one of: length, shape, thickness; "
        "did you mean 'thickness'?"
    )
    e = _error(STAGE, {"travle": "1 mm", "leaf": {"length": "1 mm"}})
    assert e.path == ("inputs", "stage") and e.suggestions == ("travel",)


def test_choices_refuse_with_a_did_you_mean():
    e = _error(STAGE, {"travel": "1 mm", "leaf": {"length": "1 mm", "shape": "notch"}})
    assert e.path == ("inputs", "stage", "leaf", "shape")
    assert "expected one of 'flat', 'notched', got 'notch'" in str(e) and e.suggestions == ("notched",)


def test_required_and_optional_keys():
    e = _error(STAGE, {"leaf": {"length": "1 mm"}})
    assert e.message.startswith("missing required stage key 'travel' (travel; expected a length")
    e = _error(STAGE, {"travel": "1 mm", "leaf": {}})
    assert e.path == ("inputs", "stage", "leaf") and "missing required leaf key 'length'" in e.message
    got = STAGE.parse({"travel": "1 mm", "leaf": {"length": "1 mm"}}, ())
    assert got["hinges"] is None and got["points"] is None  # optional nodes: their default


def test_bad_types_and_values_are_named_by_their_key_path():
    e = _error(STAGE, {"travel": "1 mm", "leaf": {"length": "1 mm"}, "points": [{"x": "1 mm"}, {"x": "2 deg"}]})
    assert e.path == ("inputs", "stage", "points", 1, "x") and "not a length" in e.message
    e = _error(STAGE, {"travel": "1 mm", "leaf": {"length": "1 mm"}, "hinges": {"a": 5}})
    assert e.path == ("inputs", "stage", "hinges", "a")
    e = _error(STAGE, {"travel": "1 mm", "leaf": {"length": "1 mm"}, "points": "x"})
    assert e.path == ("inputs", "stage", "points") and "expected a non-empty list of a mapping {x}" in e.message
    e = _error(STAGE, {"travel": "1 mm", "leaf": {"length": "-1 mm"}})
    assert e.path == ("inputs", "stage", "leaf", "length") and "> 0 mm" in e.message
    e = _error(STAGE, ["travel"])
    assert e.path == ("inputs", "stage") and "expected a mapping of stage keys" in e.message


def test_either_reads_each_form_by_its_shape():
    limit = Either(
        "stress_limit",
        "true or {sigma}",
        (Option("on", "bool", "on"), Record("spec", "spec", (Option("sigma", "stress", "allowable"),))),
        default=None,
        mismatch="expected stress_limit: true or a mapping {sigma}",
    )
    assert limit.parse(True, ()) is True
    assert limit.parse({"sigma": "400 MPa"}, ())["sigma"] == pytest.approx(400e6)
    assert str(_error(limit, "yes", ("s",))) == "s: expected stress_limit: true or a mapping {sigma}, got 'yes'"
    stiffness = Either(
        "k",
        "'rigid' or a stiffness",
        (Option("k", "choice", "held", choices=("rigid",)), Option("k", "stiffness", "k", lower=0.0)),
    )
    assert stiffness.parse("rigid", ()) == "rigid"
    assert stiffness.parse("2 N/um", ()) == pytest.approx(2e6)  # a string that is no choice: the quantity
    assert _error(stiffness, "rigd").suggestions == ("rigid",)  # the reading with a "did you mean"


def test_hooks_check_then_convert_and_an_absent_node_converts_its_default():
    calls = []

    def check(value, path):
        calls.append(("check", path))
        if value["a"] > value["b"]:
            raise InputError("expected a <= b", path=path)

    def vector(value, path):
        calls.append(("convert", path))
        return np.zeros(2) if value is None else np.array([value["a"], value["b"]])

    node = Record(
        "ab",
        "a pair",
        (Option("a", "length", "a"), Option("b", "length", "b")),
        default=None,
        check=check,
        convert=vector,
    )
    assert np.allclose(node.parse({"a": "1 mm", "b": "2 mm"}, ("p",)), [1e-3, 2e-3])
    assert calls == [("check", ("p",)), ("convert", ("p",))]
    assert str(_error(node, {"a": "3 mm", "b": "2 mm"}, ("p",))) == "p: expected a <= b"
    assert np.array_equal(validate_mapping({}, [node], ("inputs",))["ab"], np.zeros(2))  # absent: convert(default)

    def odd(value, path):
        if value % 2 == 0:
            raise InputError(f"expected an odd number, got {value}", path=path)

    with_check = Option("n", "int", "odd", check=odd)  # an option's own validator
    assert with_check.parse(3, ()) == 3
    assert _error(with_check, 4, ("n",)).path == ("n",)


def test_named_entries_by_name_or_inline():
    mat = flexure.MATERIAL
    assert mat.parse("Ti-6Al-4V", ()) is flexure.MATERIALS["Ti-6Al-4V"]
    inline = mat.parse({"E": "70 GPa", "nu": 0.3}, ("m",))
    assert inline.E == pytest.approx(70e9) and inline.G == pytest.approx(70e9 / 2.6) and inline.source == "inline"
    assert mat.parse(inline, ()) is inline  # parsed already
    e = _error(mat, "Al 7075", ("inputs", "material"))
    assert e.suggestions == ("Al 7075-T6",) and "or an inline mapping {E, nu, density, yield_strength}" in e.message
    e = _error(mat, {"E": "70 GPa", "nuu": 0.3}, ("inputs", "material"))
    assert "unknown material property 'nuu'" in e.message and e.suggestions == ("nu",)


def test_quantity_of_several_dimensions_keeps_the_value_as_written():
    k = Quantity("k", "stiffness", kinds=("rotational_stiffness", "stiffness"), positive=True)
    assert k.parse("3 N*m/rad", ()) == "3 N*m/rad" and k.parse("2 N/um", ()) == "2 N/um"
    assert "expected a positive rotational stiffness or stiffness" in _error(k, "3 N").message
    assert "positive" in _error(k, "-3 N/m").message
    si = Quantity("f", "force", kinds=("force",), default=0.0, si=True)
    assert si.parse("2 kN", ()) == pytest.approx(2e3)
    assert "'2 m' is not a force" in _error(si, "2 m").message  # one dimension: its own message


def test_a_missing_essential_input_is_named_before_unknown_keys():
    design = Either("design", "what to vary", (ListOf("d", "names", Option("n", "str", "a name")),), essential=True)
    opts = [design, Option("starts", "int", "starts", default=1)]
    e = pytest.raises(InputError, validate_mapping, {"l_min": 1, "starts": 2}, opts, ("inputs",), what="input")
    assert e.value.message == "missing required input 'design' (what to vary)"
    e = pytest.raises(InputError, validate_mapping, {"desing": ["a"]}, opts, ("inputs",), what="input")
    assert "unknown input 'desing'" in e.value.message and e.value.suggestions == ("design",)  # a typo first


def test_hinges_schema_reads_a_problem_files_hinges():
    got = cm.HINGES.parse(
        {
            "h": {"joints": {"bend": "theta", "torsion": "theta"}, "type": "circular_notch", "t": "0.5 mm", "Kt": 1.2},
            "gone": None,
        },
        ("inputs", "hinges"),
    )
    assert got["h"]["t"] == pytest.approx(5e-4) and got["h"]["Kt"] == pytest.approx(1.2) and got["gone"] is None
    assert set(got["h"]) == {"joints", "type", "t", "Kt"}  # sparse: merged key by key over a mechanism's hinge
    e = _error(cm.HINGES, {"h": {"joints": {"bned": "x"}}}, ("inputs", "hinges"))
    assert e.path == ("inputs", "hinges", "h", "joints") and e.suggestions[0] == "bend"
    e = _error(cm.HINGES, {"h": {"type": "circular_noch"}}, ("inputs", "hinges"))
    assert e.path == ("inputs", "hinges", "h", "type") and e.suggestions[0] == "circular_notch"
    e = _error(cm.HINGES, {"h": {"k": "3 N"}}, ("inputs", "hinges"))
    assert e.path == ("inputs", "hinges", "h", "k")


def test_walk_lists_every_nested_declaration_with_its_depth():
    names = [(d, n.name) for d, n in walk([STAGE])]
    assert names[:3] == [(0, "stage"), (1, "travel"), (1, "leaf")]
    assert (2, "length") in names and (3, "x") in names
    assert STAGE.required and not LEAF.fields[1].required and LEAF.fields[0].default is REQUIRED
    assert math.isclose(LEAF.fields[1].default, 1e-4)
