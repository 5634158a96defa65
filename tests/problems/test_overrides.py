"""``--set dotted.key=VALUE`` (cpm_nlp/problems/overrides.py) and YAML reading
(cpm_nlp/problems/reader.py): every accepted form and every message, in-process."""

from __future__ import annotations

import pytest

from cpm_nlp.core.errors import InputError
from cpm_nlp.problems.overrides import apply_overrides, parse_override
from cpm_nlp.problems.reader import load_yaml_text, read_yaml

BASE = {"problem": "p", "inputs": {"s": [1, 2, 3]}, "solver": "ipopt", "mechanism": {"type": "prs3"}}


@pytest.mark.parametrize(
    ("text", "parts", "value"),
    [
        ("mechanism.parameters.b=50 mm", ["mechanism", "parameters", "b"], "50 mm"),
        ("inputs.s[1]=4", ["inputs", "s", 1], 4),
        ("inputs.s.2=1e-3", ["inputs", "s", 2], 1e-3),
        ("a[0][1]=x", ["a", 0, 1], "x"),
        ("inputs.flag=yes", ["inputs", "flag"], "yes"),  # YAML 1.2: only true/false are booleans
        ("inputs.v=", ["inputs", "v"], None),
        ("inputs.v=[1, 2", ["inputs", "v"], "[1, 2"),  # not YAML: kept as text
    ],
)
def test_parse_override(text, parts, value):
    assert parse_override(text) == (parts, value)


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("no equals sign", "expected dotted.key=VALUE, got 'no equals sign'"),
        ("=5", "expected dotted.key=VALUE with a non-empty key"),
        ("a..b=5", "expected dotted.key=VALUE with a non-empty key"),
        ("a[x]=5", "expected an integer list index in 'a[x]=5'"),
        ("a[1]b=5", "expected an integer list index in 'a[1]b=5'"),
        ("a[1=5", "expected an integer list index in 'a[1=5'"),
    ],
)
def test_bad_override_text(text, message):
    with pytest.raises(InputError, match=message.replace("[", r"\[").replace("(", r"\(")) as exc:
        parse_override(text)
    assert exc.value.path == ("--set",)


def test_overrides_apply_to_a_copy():
    out = apply_overrides(BASE, ["inputs.s[0]=9", "inputs.s[-1]=7", "new.key=1", "solver.options.ipopt.tol=1e-8"])
    assert out["inputs"]["s"] == [9, 2, 7]
    assert out["new"] == {"key": 1}
    assert out["solver"] == {"preset": "ipopt", "options": {"ipopt.tol": 1e-8}}
    assert BASE["inputs"]["s"] == [1, 2, 3] and BASE["solver"] == "ipopt"  # the input is never modified
    assert apply_overrides(BASE, []) is BASE


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("inputs.s[5]=1", "no list element 5"),
        ("inputs.s.x.y=1", "no list element 'x' at inputs.s"),
        ("problem.x=1", "problem is not a mapping"),
        ("problem.x.y=1", "problem is not a mapping"),
    ],
)
def test_overrides_that_miss(text, message):
    with pytest.raises(InputError, match=message):
        apply_overrides(BASE, [text])


def test_overrides_need_a_mapping():
    with pytest.raises(InputError, match="--set needs the problem file to be a mapping"):
        apply_overrides([1, 2], ["a=1"])


def test_yaml_12_readings():
    assert load_yaml_text("a: 1e-10\nb: yes\nc: true") == {"a": 1e-10, "b": "yes", "c": True}


@pytest.mark.parametrize(
    ("content", "message"),
    [
        (b"a: [1, 2\n", "malformed YAML: line 2, column 1"),
        (b"\xff\xfe bad", "expected UTF-8 text; byte 0 is not"),
        (b"t: 2001-13-45\n", "malformed YAML"),
    ],
)
def test_read_yaml_errors_name_the_file(tmp_path, content, message):
    path = tmp_path / "p.yaml"
    path.write_bytes(content)
    with pytest.raises(InputError, match=message.replace("(", r"\(")) as exc:
        read_yaml(path)
    assert exc.value.file == str(path)


def test_read_yaml_missing_and_directory(tmp_path):
    with pytest.raises(InputError, match="file not found"):
        read_yaml(tmp_path / "none.yaml")
    with pytest.raises(InputError, match="expected a regular file, got a directory"):
        read_yaml(tmp_path)
