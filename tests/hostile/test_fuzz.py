"""Property-based fuzzing: mutate the shipped problem files at random; the CLI
must answer with exit status 0, 1 or 2 and never a traceback."""

from __future__ import annotations

import copy
import math

import yaml
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from tests.conftest import PROBLEMS

SHIPPED = sorted(PROBLEMS.glob("*.yaml"))
BASES = [yaml.safe_load(p.read_text()) for p in SHIPPED]

scalars = st.one_of(
    st.none(),
    st.booleans(),
    st.integers(min_value=-(10**6), max_value=10**6),
    st.floats(allow_nan=True, allow_infinity=True),
    st.sampled_from(
        [
            "",
            "mm",
            "1 mm",
            "-3 mm",
            "2 deg",
            "45",
            "1e-3",
            "nan",
            "inf mm",
            "0.2 rad",
            "1,5 mm",
            "47.91 kg",
            "prs3",
            "ipopt",
            "newton",
            "solve",
            "closed_form",
            "forward_kinematics",
            "joint_requirements",
            "[1 mm, 2 mm]",
            "{from: 0 mm, to: 1 mm, count: 3}",
            "yes",
            "1 GPa",
            "3 N*m/rad",
            "µm",
            "°",
        ]
    ),
    st.text(max_size=12),
)
values = st.recursive(
    scalars,
    lambda inner: st.one_of(st.lists(inner, max_size=4), st.dictionaries(st.text(max_size=8), inner, max_size=3)),
    max_leaves=6,
)


def paths(node, prefix=()):
    """Every key path of a nested YAML document."""
    yield prefix
    if isinstance(node, dict):
        for k, v in node.items():
            yield from paths(v, prefix + (k,))
    elif isinstance(node, list):
        for i, v in enumerate(node):
            yield from paths(v, prefix + (i,))


def get(node, path):
    for p in path:
        node = node[p]
    return node


@st.composite
def mutated(draw):
    base = copy.deepcopy(draw(st.sampled_from(BASES)))
    for _ in range(draw(st.integers(1, 3))):
        all_paths = [p for p in paths(base) if p]
        if not all_paths:
            break
        path = draw(st.sampled_from(all_paths))
        parent = get(base, path[:-1])
        key = path[-1]
        action = draw(st.sampled_from(["replace", "delete", "rename", "add", "scale"]))
        if action == "replace":
            parent[key] = draw(values)
        elif action == "delete":
            del parent[key]
        elif action == "rename" and isinstance(parent, dict):
            parent[str(key) + draw(st.sampled_from(["x", "_", "s", ""]))[:-1] or "z"] = parent.pop(key)
        elif action == "add" and isinstance(parent, dict):
            parent[draw(st.text(min_size=1, max_size=8))] = draw(values)
        elif action == "scale":
            v = parent[key]
            if isinstance(v, str) and v.split() and v.split()[0].lstrip("-").replace(".", "", 1).isdigit():
                num, *unit = v.split()
                factor = draw(st.sampled_from([0, -1, 1000, 1e-6, 1e6]))
                parent[key] = " ".join([repr(float(num) * factor)] + unit)
    return base


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(doc=mutated())
def test_mutated_problem_files_never_crash(doc, tmp_path_factory, cli):
    path = tmp_path_factory.mktemp("fuzz") / "problem.yaml"
    try:
        text = yaml.safe_dump(doc, allow_unicode=True)
    except yaml.YAMLError:  # pragma: no cover - unrepresentable mutations are skipped
        return
    path.write_text(text)
    out = path.with_suffix(".json")
    run = cli("solve", str(path), "-o", str(out))
    assert run.code in (0, 1, 2), run.err
    assert "Traceback" not in run.err and "internal error" not in run.err, run.err
    if run.code == 2:
        assert run.out == "" and not out.exists()
        assert run.err.startswith("error: ") and run.err.count("\n") == 1
    else:
        assert out.exists()


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(
    key=st.sampled_from(
        [
            "inputs.s1",
            "inputs.dz",
            "mechanism.parameters.L",
            "mechanism.parameters.alpha0",
            "solver.options.ipopt.tol",
            "solver",
            "inputs.psi",
            "mechanism.limits.s",
            "problem",
        ]
    ),
    value=st.one_of(st.floats(), st.text(max_size=10), st.integers()),
)
def test_random_overrides_never_crash(key, value, cli):
    text = repr(value) if isinstance(value, float) and not math.isfinite(value) else str(value)
    run = cli("solve", str(SHIPPED[0]), "-q", "--set", f"{key}={text}")
    assert run.code in (0, 1, 2), run.err
    assert "Traceback" not in run.err and "internal error" not in run.err, run.err
