"""Workspace grids by the number of task coordinates, and a cuboid that is only a point (issue 20).

The cuboid NLP gives every sample point its own pose unknowns: 5 points per edge are 98 samples
in 3 task coordinates but 14896 in 6 (a 6-UPS's generic synthesis built that NLP for over 10 min
on main 2632ab7, measured here).  The defaults now shrink with the dimension; an explicit grid
that large is refused, naming its key.
"""

from __future__ import annotations

import pytest

import cpm_nlp as cn
from cpm_nlp.analysis import workspace as W
from cpm_nlp.analysis.workspace.cuboid import check_interior
from cpm_nlp.problems.shipped import shipped_problems_dir


@pytest.mark.parametrize(
    ("d", "samples", "check", "interior"), [(1, 5, 17, 5), (2, 5, 17, 5), (3, 5, 17, 5), (4, 3, 7, 5), (6, 2, 3, 3)]
)
def test_default_grids_by_dimension(d, samples, check, interior):
    """Up to 3 task coordinates the defaults are those of before (5, 17, 5): the same results."""
    assert W.default_per_edge(d, 5, W.DEFAULT_NLP_SAMPLES) == samples
    assert W.check_per_edge_of(d, None) == check
    assert check_interior(d) == interior
    assert W.surface_count(d, samples) <= max(W.DEFAULT_NLP_SAMPLES, 2**d)
    assert W.surface_count(3, 5) == len(W.surface_grid(3, 5)) == 98
    assert W.surface_count(6, 5) == 14896


def _ups6(kind: str, inputs: dict) -> cn.Problem:
    return cn.problem_from_dict(
        {"problem": kind, "mechanism": {"file": "mechanisms/ups6.yaml"}, "inputs": inputs},
        base_dir=shipped_problems_dir(),
    )


@pytest.mark.parametrize("kind", ["inscribed_cuboid", "synthesis"])
def test_too_large_grid_is_refused(kind):
    extra = {"design": {"rb": ["140 mm", "160 mm"]}} if kind == "synthesis" else {}
    with pytest.raises(cn.InputError, match=r"14896 points .* expected at most 2000") as err:
        _ups6(kind, {**extra, "samples_per_edge": 5})
    assert err.value.path[-1] == "samples_per_edge"
    assert _ups6(kind, {**extra, "samples_per_edge": 2}).inputs["samples_per_edge"] == 2


def test_cuboid_shrunk_to_a_point_is_not_found():
    """The five-bar with 2 samples per edge: the best box's corners assemble, its inside does
    not; no shrink about its centre passes but the point itself.  On main that was `solved`
    with a box of 2.8e-17 x 1.2e-9 m."""
    problem = cn.load_problem(shipped_problems_dir() / "five_bar_forward_kinematics.yaml")
    res = W.inscribed_cuboid(problem.model, cn.SolverConfig(), starts=2, samples_per_edge=2, check_per_edge=3)
    assert not res.found and res.lower is None and res.volume is None
    assert "shrunk to its centre" in res.message and res.shrink == 0.0
    ok = W.inscribed_cuboid(problem.model, cn.SolverConfig(), starts=2, samples_per_edge=5, check_per_edge=9)
    assert ok.found and ok.volume > 1e-3
