"""All assembly modes (cpm_nlp.analysis.assembly, ``assembly_modes: all`` of the
forward_kinematics kind), checked against independent references
(tests/gallery_reference.py): the five-bar's two modes in closed form (circle
intersections), the 6-UPS modes against the leg lengths (its IK), the 3-PRS
modes against the paper's loop closures written in numpy."""

import math

import numpy as np
import pytest

import cpm_nlp as cn
from cpm_nlp.analysis.assembly import assembly_modes
from cpm_nlp.core.errors import InputError
from cpm_nlp.core.result import Status
from cpm_nlp.problems.file import problem_from_dict, solve
from tests import gallery_closures as gc
from tests import gallery_reference as ref
from tests.conftest import PAPER_PRS3


def _match(found: np.ndarray, expected: np.ndarray, atol: float) -> None:
    """Every expected pose is found once, and nothing else."""
    assert len(found) == len(expected)
    for e in expected:
        d = np.max(np.abs(found - e), axis=1)
        assert np.count_nonzero(d < atol) == 1, (e, found)


@pytest.mark.parametrize("signs", [(1.0, -1.0), (1.0, 1.0), (-1.0, -1.0), (-1.0, 1.0)])
def test_five_bar_two_assembly_modes_in_every_working_mode(signs):
    """Five-bar (Merlet 2006 §4.2): for given θ the end point is one of the two
    intersections of the distal links' circles (up and down); both are found,
    the designated one ("up") is the working mode; every one of the four
    working modes (elbow signs σ1, σ2) is reached by branch choice (IK)."""
    r5 = ref.FiveBar()
    p = np.array([0.03, 0.34])
    th = r5.ik(p, signs)
    up, down = r5.fk(th)  # up: to the left of B1 -> B2
    kappa = 1.0 if np.allclose(up, p, atol=1e-12) else -1.0
    m = gc.five_bar_model(sigma1=signs[0], sigma2=signs[1], kappa=kappa)
    ik = cn.inverse_kinematics(m, p)
    assert ik.ok and np.allclose(ik.q, th, atol=1e-13)  # the working mode chosen by σ
    found = assembly_modes(m, th, starts=300, seed=1)
    _match(np.array([md.x for md in found.modes]), np.array([up, down]), 1e-10)
    work = found.modes[found.working]
    assert found.working == 0 and np.allclose(work.x, p, atol=1e-12) and work.designated
    assert work.status is Status.SOLVED
    other = found.modes[1]
    assert other.status is Status.WRONG_BRANCH and not other.designated and other.branch[2] < 0
    assert found.nearest == 1 and found.distance_length == pytest.approx(np.linalg.norm(up - down), abs=1e-12)
    assert found.distance_angle == 0.0  # no angle coordinates in the pose
    assert sum(md.basin for md in found.modes) == found.converged  # every converged start reached a mode
    assert "not a proof" in found.note and found.completeness.complete


def test_stewart_modes_are_distinct_solutions_of_the_leg_lengths():
    """6-UPS (Merlet 2006 §5.1): every mode found has the given leg lengths
    (reference IK, numpy), the modes are distinct, the working mode is the
    pose the actuators came from."""
    m = gc.stewart_model()
    rs = ref.Stewart()
    x0 = np.array([0.01, -0.005, 0.24, 0.06, -0.04, 0.1])
    lengths = rs.ik(x0)
    found = assembly_modes(m, lengths, starts=3000, seed=2)
    assert found.count >= 2 and found.working == 0
    assert np.allclose(found.modes[0].x, x0, atol=1e-10)
    for md in found.modes:
        assert np.max(np.abs(rs.ik(md.x) - lengths)) < 1e-9
        assert md.designated == bool(md.x[2] > 0 and math.cos(md.x[3]) * math.cos(md.x[4]) > 0)
    X = np.array([md.x for md in found.modes])
    for i in range(len(X)):
        for j in range(i):
            d = X[i] - X[j]
            d[3:] = (d[3:] + math.pi) % (2 * math.pi) - math.pi
            assert np.max(np.abs(d)) > 1e-6
    assert np.all(np.abs(X[:, 3:]) <= math.pi)  # angles reduced to (-pi, pi]


def test_prs3_modes_satisfy_the_paper_closures(prs3):
    """3-PRS: several modes for the same actuators (a leg folds down towards its
    slider, alpha_i ~ 10 deg, and the platform tilts ~45 deg; with the full turn of
    the angles also poses below the sliders); each satisfies the paper's equations
    (eq 35 and the leg planes, numpy reference).  The tilted ones keep the legs'
    signs but not the aspect (det Φ_x per twist), so only the working mode is on
    the designated branch (tests/analysis/test_mode_search.py)."""
    s = np.array([1e-3, 0.5e-3, -0.3e-3])
    found = assembly_modes(prs3, s, starts=2000)
    nominal = ref.AsBuiltPRS3()
    assert found.count >= 2
    for md in found.modes:
        assert np.max(np.abs(nominal.equations(md.x, s))) < 1e-12
        assert md.designated == bool(np.all(md.branch > 0))
    assert np.allclose(found.modes[0].x, cn.forward_kinematics(prs3, s).x, atol=1e-12)
    above = [md for md in found.modes[1:] if md.x[2] > 0]
    alphas = np.array([[md.passive[f"alpha{i}"] for i in (1, 2, 3)] for md in above])
    assert np.all(np.min(alphas, axis=1) < math.radians(20))  # one folded leg per other mode above
    limited = cn.build_model("prs3", PAPER_PRS3, {"alpha": ["30 deg", "60 deg"]})
    again = assembly_modes(limited, s, starts=2000)
    assert again.modes[0].status is Status.SOLVED
    assert all(md.status is not Status.SOLVED for md in again.modes[1:])


def test_forward_kinematics_kind_all_modes():
    data = {
        "problem": "forward_kinematics",
        "mechanism": {"type": "prs3", "parameters": PAPER_PRS3},
        "inputs": {"s1": "1 mm", "s2": "0.5 mm", "s3": "-0.3 mm", "assembly_modes": "all", "mode_starts": 500},
    }
    res = solve(problem_from_dict(data))
    assert res.ok and res.values["modes"] >= 2 and len(res.values["modes_px"]) == res.values["modes"]
    assert res.values["px"] == pytest.approx(res.values["modes_px"][0], abs=1e-15)
    assert "not a proof" in res.message and res.dimensions["distance_length"] == "length"
    data["inputs"]["s1"] = ["1 mm", "2 mm"]
    data["inputs"]["s2"] = ["1 mm", "2 mm"]
    with pytest.raises(InputError, match="one actuator vector"):
        problem_from_dict(data)
