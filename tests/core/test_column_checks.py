"""Column-wise checks and conversions of a large batch (a 100 000-row data file, issue 23):
the numpy paths give what the value-by-value paths give, and the same errors.

* :func:`cpm_nlp.core.finite.nonfinite_paths`: the first non-finite entry of each value,
  against a reference walk written here value by value (the definition);
* :meth:`cpm_nlp.core.options.Option.parse` of a long list: the same SI values, and the same
  error (message, key path with the index) as the check of the failing value alone;
* :meth:`cpm_nlp.core.batch.BatchResult.solutions`: every field, and the order of each
  pose's details, as :meth:`~cpm_nlp.core.batch.BatchResult.solution` gives them one by one;
* a kinematic result of a batch with failed points: None exactly at them, the solved poses'
  numbers the batch's (to 1e-12: the problem file's parameters pass through unit parsing).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import cpm_nlp as cn
from cpm_nlp.core.errors import InputError
from cpm_nlp.core.finite import nonfinite_paths
from cpm_nlp.core.options import FAST_LIST, Option
from cpm_nlp.core.result import Status

PAPER_PRS3 = {"L": 0.109215, "b": 0.04791, "alpha0": math.radians(45.0)}
LIMITED = {"s": (-2e-3, 2e-3)}


def reference_paths(values: dict) -> list[str]:
    """The first non-finite number of each value, visiting containers in order (the definition)."""

    def walk(v, name):
        if isinstance(v, dict):
            for k, w in v.items():
                yield from walk(w, f"{name}.{k}")
        elif isinstance(v, (list, tuple, np.ndarray)):
            for i, w in enumerate(v):
                yield from walk(w, f"{name}[{i}]")
        elif isinstance(v, (float, complex, np.floating, np.complexfloating)) and not np.isfinite(v):
            yield name

    out = []
    for key, v in values.items():
        first = next(walk(v, str(key)), None)
        if first is not None:
            out.append(first)
    return out


def _long(n: int, bad: dict) -> list:
    v = np.linspace(-1.0, 1.0, n).tolist()
    for i, x in bad.items():
        v[i] = x
    return v


CASES = {
    "finite floats": _long(1000, {}),
    "nan late": _long(1000, {700: math.nan}),
    "inf and nan": _long(1000, {900: math.nan, 40: -math.inf}),
    "None among floats": _long(500, {3: None, 499: math.inf}),
    "strings and a nan": ["nan", "inf", 1.0, math.nan],
    "bool before a nan": [True, False, math.nan],
    "ints": list(range(300)),
    "huge int": [1.0, 10**400, math.inf],
    "nested": [[1.0, 2.0], [3.0, math.nan], [math.inf, 0.0]],
    "ragged": [[1.0], [2.0, math.nan]],
    "dicts": [{"a": 1.0}, {"a": math.nan}],
    "tuple of complex": (1 + 1j, complex(math.nan, 0.0)),
    "matrix batch": [[[1.0, 2.0], [3.0, 4.0]], [[5.0, 6.0], [7.0, math.inf]]],
    "float array with object rows": np.array([[1.0, None], [math.nan, 2.0]], dtype=object),
    "int array": np.arange(10),
    "float array": np.array([[0.0, 1.0], [np.nan, 2.0]]),
    "empty": [],
    "one nan": [math.nan],
    "scalar": math.inf,
    "text": "nan",
}


@pytest.mark.parametrize("name", list(CASES))
def test_nonfinite_paths_are_the_value_by_value_walk(name):
    values = {"v": CASES[name], "w": {"inner": CASES[name]}}
    assert nonfinite_paths(values) == reference_paths(values)


def test_nonfinite_paths_of_every_case_at_once():
    assert nonfinite_paths(CASES) == reference_paths(CASES)
    assert "nan late[700]" in nonfinite_paths(CASES) and "nested[1][1]" in nonfinite_paths(CASES)


_numbers = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True),
    st.integers(),
    st.booleans(),
    st.none(),
    st.text(max_size=3),
    st.complex_numbers(allow_nan=True, allow_infinity=True),
    st.floats(allow_nan=True, allow_infinity=True).map(np.float64),
)
_nested = st.recursive(
    _numbers,
    lambda inner: st.one_of(
        st.lists(inner, max_size=5),
        st.lists(inner, max_size=5).map(tuple),
        st.dictionaries(st.text(max_size=3), inner, max_size=3),
        st.lists(st.lists(st.floats(allow_nan=True, allow_infinity=True), min_size=2, max_size=2), max_size=4),
    ),
    max_leaves=25,
)


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(values=st.dictionaries(st.text(max_size=4), _nested, max_size=4))
def test_nonfinite_paths_of_any_value_are_the_walks(values):
    assert nonfinite_paths(values) == reference_paths(values)


LENGTH = Option("s", "length", "a stroke", shape="list", lower=-0.01, upper=0.01)
STRICT = Option("k", "stiffness", "a stiffness", shape="list", lower=0.0, strict=True)
FREE = Option("d", "length", "a length", shape="list")


@pytest.mark.parametrize(
    ("option", "bad"),
    [
        (LENGTH, 0.02),  # above the upper bound
        (LENGTH, -0.0100001),  # below the lower bound
        (STRICT, 0.0),  # on a strict bound
        (STRICT, -1.0),
        (FREE, 1e-70),  # a nonzero length below TINY
        (FREE, 1e300),  # beyond the sanity limit of a length
        (FREE, math.nan),
        (FREE, math.inf),
        (FREE, True),  # no float: the per-value path refuses it
        (FREE, "1 mm"),  # a string among floats: parsed per value, and accepted
    ],
)
def test_a_long_list_is_checked_as_each_value_alone(option, bad):
    n = 4 * FAST_LIST
    values = np.linspace(1e-3, 2e-3, n).tolist()
    values[n - 7] = bad
    path = ("inputs", option.name)
    try:
        alone = option._scalar(bad, path + (n - 7,))
    except InputError as exc:
        with pytest.raises(InputError) as got:
            option.parse(values, path)
        assert str(got.value) == str(exc)
        assert got.value.path == path + (n - 7,)
    else:  # accepted alone: accepted in the list, at its own SI value
        out = option.parse(values, path)
        assert out[n - 7] == alone and out[:3] == values[:3]


def test_a_long_list_of_floats_is_returned_unchanged():
    values = np.random.default_rng(0).uniform(-0.01, 0.01, 3 * FAST_LIST).tolist()
    values[5] = -0.0
    out = LENGTH.parse(values, ("inputs", "s"))
    assert out == values and all(type(v) is float for v in out)
    assert math.copysign(1.0, out[5]) == -1.0
    short = values[: FAST_LIST - 1]
    assert LENGTH.parse(short, ("inputs", "s")) == short  # the per-value path


@pytest.fixture(scope="module")
def limited():
    return cn.build_model("prs3", PAPER_PRS3, LIMITED)


def _mixed(n: int) -> np.ndarray:
    q = np.random.default_rng(5).uniform(-2.2e-3, 2.2e-3, (n, 3))  # some outside the limits
    q[::37] = [0.3, -0.3, 0.0]  # out of reach
    return q


def test_batch_solutions_are_each_pose_solution(limited):
    res = cn.batch_forward_kinematics(limited, _mixed(400))
    assert 0 < int(np.count_nonzero(res.ok)) < len(res)
    got = res.solutions()
    assert len(got) == len(res)
    for i, s in enumerate(got):
        one = res.solution(i)
        assert s.status is one.status and s.message == one.message and s.path == one.path
        assert s.residual == one.residual or (math.isnan(s.residual) and math.isnan(one.residual))
        assert s.seconds == one.seconds and s.solver == one.solver and s.iterations == one.iterations
        assert list(s.details) == list(one.details)  # the same keys in the same order
        for key, v in one.details.items():
            assert s.details[key] == v or (math.isnan(v) and math.isnan(s.details[key]))
        for a, b in ((s.x, one.x), (s.q, one.q), (s.passive, one.passive)):
            assert (a is None) == (b is None)
            if a is not None:
                np.testing.assert_array_equal(a, b)


def test_a_batch_result_has_none_exactly_at_its_failed_points():
    model = cn.build_model("prs3", PAPER_PRS3)  # a problem file refuses inputs outside the limits
    q = _mixed(300)
    res = cn.batch_forward_kinematics(model, q)
    problem = cn.problem_from_dict(
        {
            "problem": "forward_kinematics",
            "mechanism": {"type": "prs3", "parameters": {"L": "109.215 mm", "b": "47.91 mm", "alpha0": "45 deg"}},
            "inputs": {"s1": q[:, 0].tolist(), "s2": q[:, 1].tolist(), "s3": q[:, 2].tolist()},
            "solver": "newton",
        }
    )  # fmt: skip
    out = cn.solve(problem)
    assert out.status is not Status.SOLVED
    c = model.closure
    failed = np.flatnonzero(~res.ok)
    solved = np.flatnonzero(res.ok)
    for i, name in enumerate(c.x_names):
        column = out.values[name]
        assert [column[k] for k in failed] == [None] * failed.size
        np.testing.assert_allclose([column[k] for k in solved], res.x[solved, i], rtol=1e-12, atol=1e-15)
    for j, name in enumerate(c.q_names):
        np.testing.assert_allclose([out.values[name][k] for k in solved], res.q[solved, j], rtol=1e-12, atol=1e-15)
    assert [out.values["residual"][k] for k in failed] == [None] * failed.size


# -- the CSV reader of data files (cpm_nlp.io.datafile): all values at once, else row by row --


def _csv_table(lines: list[str]) -> tuple[list[str], np.ndarray]:
    from cpm_nlp.io.datafile import _csv

    return _csv(("s1, s2, s3\n" + "\n".join(lines) + "\n").encode(), ("inputs", "data"))


def _rows(n: int) -> list[str]:
    return [f"{k * 1e-6:.17g},{-k * 2e-6:.17g},{k * 3.5e-7:.17g}" for k in range(n)]


def test_a_csv_is_read_at_once_as_row_by_row():
    lines = _rows(2000)
    lines[7] = " 1.5e-3 ,\t-2e-3, 0"  # spaces around numbers, as float() reads them
    lines[9] = "1_0,-0.,1E-3"  # what float() accepts, numpy's own parser may not
    headers, table = _csv_table(lines)
    assert headers == ["s1", "s2", "s3"] and table.shape == (2000, 3)
    want = np.array([[float(c) for c in line.split(",")] for line in lines])
    np.testing.assert_array_equal(table, want)
    assert math.copysign(1.0, table[9, 1]) == -1.0


@pytest.mark.parametrize(
    ("bad", "message"),
    [
        ({500: "1,2,x"}, "row 501, column 's3': expected a number"),
        ({500: "1,2"}, "row 501 has 2 value(s); the header names 3 column(s)"),
        # the first error in row order, whichever its kind
        ({300: "1,y,3", 900: "1,2"}, "row 301, column 's2': expected a number"),
        ({300: "1,2,3,4", 900: "1,2,z"}, "row 301 has 4 value(s)"),
    ],
)
def test_a_bad_csv_row_is_named_as_row_by_row(bad, message):
    lines = _rows(1000)
    for k, text in bad.items():
        lines[k] = text
    with pytest.raises(InputError) as got:
        _csv_table(lines)
    assert message in str(got.value) and got.value.path == ("inputs", "data")
