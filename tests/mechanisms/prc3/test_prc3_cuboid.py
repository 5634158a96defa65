"""The 3-PRC's maximal inscribed cuboid through the generic inscribed_cuboid kind:
a mechanism given only by its loop closures and joint limits (issue 4)."""

import numpy as np
import pytest

import cpm_nlp as cn
from cpm_nlp.analysis import workspace as W
from cpm_nlp.core.result import Status
from tests.conftest import PROBLEMS

QMAX = 15e-6  # eq 27
A2 = 25 * 30 / (9.5 * 9)  # eq 1 with Table 1


@pytest.fixture(scope="module")
def cuboid():
    problem = cn.load_problem(PROBLEMS / "prc3_cuboid.yaml")
    result = cn.solve(problem)
    assert result.status is Status.SOLVED, result.message
    return problem.model, result.values


def test_cuboid_is_inside_the_reachable_workspace(cuboid):
    model, v = cuboid
    lower = np.array([v["x_min"], v["y_min"], v["z_min"]])
    upper = np.array([v["x_max"], v["y_max"], v["z_max"]])
    assert v["check_outside"] == 0
    # an independent, denser check than the kind's own: 25 points per edge
    check, _, _ = W.check_box(model, lower, upper, per_edge=25)
    assert check.outside == 0
    # every face touches the boundary: a box 0.5 % larger about its centre leaves the workspace
    c, h = (lower + upper) / 2, (upper - lower) / 2
    grown, _, _ = W.check_box(model, c - 1.005 * h, c + 1.005 * h, per_edge=9)
    assert grown.outside > 0


def test_cuboid_close_to_the_linear_cube(cuboid):
    """eq 26 (p = -A2 q) would give the cube of edge A2 q_max; the exact q_i = 0 faces
    are slightly curved (eq 9), so the largest box is a little smaller."""
    _, v = cuboid
    linear = (A2 * QMAX) ** 3
    assert 0.98 * linear < v["volume"] < linear
    for axis in "xyz":
        assert v[f"{axis}_max"] < 0 and v[f"{axis}_min"] == pytest.approx(-A2 * QMAX, rel=2e-3)
    assert v["starts_agreed"] == v["starts"]
