"""The reduction of an angle into its joint range inside the pose checks, built as one scalar
CasADi Function replayed on SX (issue 23, start-up): the same values as the expression built
operation by operation, and the same pose-checks Function, instruction for instruction."""

from __future__ import annotations

import math

import casadi as ca
import numpy as np
import pytest

import cpm_nlp as cn
from cpm_nlp.core import pose_checks as pc
from tests.conftest import PAPER_PRS3, PROBLEMS


def _reference(v: float, low: float, high: float) -> float:
    """What ``_into_range`` says it does, in plain Python: v in its range; else its value in
    (-pi, pi] if that is in the range; else its lowest turn in the range; else that value."""
    if not (math.isfinite(low) and math.isfinite(high)):
        return v
    if low <= v <= high:
        return v
    r = v - 2 * math.pi * math.ceil((v - math.pi) / (2 * math.pi))
    if low <= r <= high:
        return r
    lowest = v - 2 * math.pi * math.floor((v - low) / (2 * math.pi))
    return lowest if low <= lowest <= high else r


CASES = [
    (0.3, -1.0, 1.0),  # inside
    (0.3 + 2 * math.pi, -1.0, 1.0),  # a turn away
    (-0.3 - 6 * math.pi, -1.0, 1.0),  # three turns away
    (3.0, 2.5, 3.5 + 2 * math.pi),  # a range wider than a turn, off (-pi, pi]
    (1.9, 2.5, 3.0),  # outside, every turn
    (7.5, -math.inf, math.inf),  # no range
    (7.5, -1.0, math.inf),  # half a range
]


@pytest.mark.parametrize(("v", "low", "high"), CASES)
def test_the_replayed_function_reduces_as_the_expression(v, low, high):
    s = [ca.SX.sym(n) for n in ("v", "low", "high")]
    replayed = ca.Function("a", s, [pc._into_range(*s)])
    built = ca.Function("b", s, [pc._into_range_expression(*s)])
    assert float(replayed(v, low, high)) == float(built(v, low, high))  # to the bit
    assert float(replayed(v, low, high)) == pytest.approx(_reference(v, low, high), abs=1e-12)


#: a forward kinematics file of each shipped mechanism with angles to reduce
FK_FILES = [
    "five_bar_forward_kinematics.yaml",
    "delta_forward_kinematics.yaml",
    "rrr3_forward_kinematics.yaml",
    "pantograph_forward_kinematics.yaml",
    "prc3_forward_kinematics.yaml",
    "rpr_forward_kinematics.yaml",
    "ups6_forward_kinematics.yaml",
]


@pytest.mark.parametrize("file", [None, *FK_FILES])
def test_the_pose_checks_are_the_same_function(file):
    """A mechanism's pose checks built with the replayed reduction and with the expression:
    the same number of instructions and the same outputs, to the bit, at random poses and
    limits (seeded)."""
    model = cn.build_model("prs3", PAPER_PRS3) if file is None else cn.load_problem(PROBLEMS / file).model
    c = model.closure

    def checks() -> ca.Function:
        x, q, p = ca.SX.sym("x", c.nx), ca.SX.sym("q", c.nq), ca.SX.sym("p", c.np)
        nl = pc.n_joints(c)
        lower, upper = ca.SX.sym("lower", nl), ca.SX.sym("upper", nl)
        chk = pc.check_expressions(c, x, q, p, lower, upper)
        return ca.Function("checks", [x, q, p, lower, upper], [ca.densify(v) for v in chk.values()])

    replayed = checks()
    original = pc._into_range
    try:
        pc._into_range = pc._into_range_expression
        built = checks()
    finally:
        pc._into_range = original
    assert replayed.n_instructions() == built.n_instructions()
    rng = np.random.default_rng(7)
    for _ in range(20):
        args = [rng.normal(scale=3.0, size=s.numel()) for s in replayed.sx_in()]
        args[3], args[4] = -np.abs(args[3]) - 0.2, np.abs(args[4]) + 0.2
        for a, b in zip(replayed(*args), built(*args)):
            assert np.array_equal(np.array(a), np.array(b), equal_nan=True)
