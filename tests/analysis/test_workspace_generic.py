"""The workspace algorithms know no mechanism: the inscribed cuboid of the 3-PRS
(mixed units: pz in m, psi and theta in rad) from its loop closures and joint limits."""

import numpy as np
import pytest

import cpm_nlp as cn
from cpm_nlp.analysis import workspace as W
from cpm_nlp.core.multistart import best_and_agreement, uniform_starts
from cpm_nlp.core.result import Status
from tests.conftest import PAPER_PRS3


def test_surface_and_check_grids():
    assert len(W.surface_grid(3, 5)) == 5**3 - 3**3
    assert len(W.surface_grid(2, 4)) == 4**2 - 2**2
    S = W.check_grid(3, 17)
    assert len(S) == 17**3 - 15**3 + 5**3
    assert S.min() == 0.0 and S.max() == 1.0
    # corners, edge and face centres are samples of an odd grid
    for p in ([0, 0, 0], [1, 1, 1], [0.5, 0, 0], [0.5, 0.5, 1]):
        assert np.any(np.all(W.surface_grid(3, 5) == p, axis=1))


def test_multistart_helpers():
    pts = uniform_starts([0, 0], [1, 2], 5, seed=3, first=[5, -1])
    np.testing.assert_array_equal(pts[0], [1, 0])  # clipped into the box
    np.testing.assert_array_equal(pts, uniform_starts([0, 0], [1, 2], 5, seed=3, first=[5, -1]))
    assert best_and_agreement([None, 2.0, 1.0, 1.00001, None]) == (2, 2)
    assert best_and_agreement([None, None]) == (None, 0)


def test_prs3_inscribed_cuboid_from_its_limits(tmp_path):
    problem = cn.problem_from_dict(
        {
            "problem": "inscribed_cuboid",
            "mechanism": {
                "type": "prs3",
                "parameters": PAPER_PRS3,
                "limits": {"s": ["-2 mm", "2 mm"], "beta_m": ["-1.5 deg", "1.5 deg"]},
            },
            "inputs": {"starts": 2},
        }
    )
    result = cn.solve(problem)
    assert result.status is Status.SOLVED, result.message
    v = result.values
    assert v["check_outside"] == 0 and v["starts_agreed"] == 2
    assert result.units["volume"] == "m*rad^2"  # a length times two angles (size_dimension)
    model = problem.model
    # every corner assembles by the closed-form IK within the limits (kinematics.assess)
    lower = np.array([v["pz_min"], v["psi_min"], v["theta_min"]])
    upper = np.array([v["pz_max"], v["psi_max"], v["theta_max"]])
    for corner in W.surface_grid(3, 2):
        ik = cn.inverse_kinematics(model, lower + corner * (upper - lower))
        assert ik.status is Status.SOLVED, ik.message
    # slightly larger in any direction, the box leaves the workspace (the optimum touches the boundary)
    for i in range(3):
        for side in (lower, upper):
            grown_lo, grown_hi = lower.copy(), upper.copy()
            (grown_lo if side is lower else grown_hi)[i] += (-1 if side is lower else 1) * 1e-3 * (upper[i] - lower[i])
            check = W.check_box(model, grown_lo, grown_hi, per_edge=9)[0]
            assert check.outside > 0, (i, check)
    assert v["volume"] == pytest.approx(np.prod(upper - lower), rel=1e-12)


def test_membership_without_closed_form_ik(prs3):
    """A mechanism without a closed-form IK: membership solves the IK point by point
    and agrees with the closed form."""
    from cpm_nlp.core.model import LoopClosure, Model
    from tests.reference import prs3_closures as P3

    solved = LoopClosure(
        "prs3_solved_ik",
        x=P3.X,
        q=P3.Q,
        parameters=("b", "L", "alpha0"),
        phi=P3.loop_closure(),
        task=P3.TASK,
        passive=P3.passive_joints(),
        passive_coords=P3.PASSIVE,
        branch=P3.branch_indicator(),
        home=P3.home,
        bounds=P3.bounds,
    )
    limits = {"s": (-2e-3, 2e-3), "beta_m": (-0.02, 0.02)}
    closed = Model(prs3.closure, dict(prs3.parameters), limits, dict(prs3.derived))
    other = Model(solved, dict(prs3.parameters), limits, dict(prs3.derived))
    rng = np.random.default_rng(2)
    T = np.column_stack(
        [prs3.x_home[2] + rng.uniform(-1e-3, 1e-3, 40), rng.uniform(-0.01, 0.01, 40), rng.uniform(-0.015, 0.015, 40)]
    )
    a, b = W.membership(closed, T), W.membership(other, T)
    assert 5 < np.count_nonzero(a.inside) < 35
    np.testing.assert_array_equal(a.inside, b.inside)
    np.testing.assert_allclose(b.Q[b.inside], a.Q[a.inside], atol=1e-10)
