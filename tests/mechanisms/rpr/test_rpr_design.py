"""Motion/force transmission and synthesis of the RPR (rpr-2rpu-upr-zhang-2022.md,
eq 14-26): the wrench system of eq 16, the output transmission index eq 19, the
design space eq 20-23, the chosen point eq 24-26 and the IPOPT synthesis."""

import math

import casadi as ca
import numpy as np
import pytest

import cpm_nlp as cn
from cpm_nlp.core import screws
from cpm_nlp.core.errors import InputError
from cpm_nlp.mechanisms.rpr import design as rd

PAPER_RPR = {"r1": "40 mm", "r2": "80 mm", "P0": "40 mm"}


@pytest.fixture(scope="module")
def model():
    return cn.build_model("rpr", PAPER_RPR)


def closed_form_eta(r1, r2, P):
    """Eq 19 worked by hand at the initial pose: S_O ~ (r1, r2, 0; 0, P r1, -r1 r2),
    |S_T o S_O| = 2 r1 r2 / n, distance B1 to the axis sqrt((2 r1 r2 / n)^2 + (P r2^2 / n^2)^2)."""
    n = math.hypot(r1, r2)
    return 1.0 / math.sqrt(1.0 + (P * r2 / (2.0 * r1 * n)) ** 2)


def test_eq_16_wrenches_are_reciprocal_to_the_locked_legs_of_eq_14_15():
    r1, r2, P = 0.04, 0.08, 0.04
    leg3, leg2 = (np.asarray(m) for m in rd.locked_twists(r1, r2, P))
    sc = rd.transmission_screws(r1, r2, P)
    H = np.asarray(sc["H"])
    # H1..H3 are reciprocal to leg 3's twists, H1, H4, H5 to leg 2's
    for k in (0, 1, 2):
        assert np.allclose(H[:, k] @ screws.DELTA @ leg3, 0.0, atol=1e-15)
    for k in (0, 3, 4):
        assert np.allclose(H[:, k] @ screws.DELTA @ leg2, 0.0, atol=1e-15)
    # S_O (eq 17): unit |s|, reciprocal to all five, in both locked legs' twist spaces
    S_O = np.asarray(sc["S_O"]).ravel()
    assert np.linalg.norm(S_O[:3]) == pytest.approx(1.0)
    assert np.allclose(H.T @ screws.DELTA @ S_O, 0.0, atol=1e-14)
    for twists in (leg3, leg2):
        coef, *_ = np.linalg.lstsq(twists, S_O, rcond=None)
        assert np.allclose(twists @ coef, S_O, atol=1e-12)
    n = math.hypot(r1, r2)
    expected = np.array([r1, r2, 0, 0, P * r1, -r1 * r2]) / n
    assert np.allclose(np.abs(S_O), np.abs(expected))


@pytest.mark.parametrize("l", [(0.75, 1.5, 0.75), (1.0, 1.0, 1.0), (1.5, 0.75, 0.75), (0.4, 0.5, 2.1)])
def test_eta_matches_its_closed_form(l):
    assert rd.eta(*l) == pytest.approx(closed_form_eta(*l), rel=1e-12)
    assert rd.eta(*(40e-3 * np.array(l))) == pytest.approx(rd.eta(*l), rel=1e-12)  # scale-free
    assert 0 < rd.eta(*l, eta_max="velocity") < rd.eta(*l)  # the speed of B1 bounds the distance


def test_eta_at_the_paper_point_and_the_comparison_designs():
    # eq 25 (the choice) and the designs of eq 47 and 49 read off their twist matrices
    assert rd.eta(0.75, 1.5, 0.75) == pytest.approx(0.912871, abs=1e-6)
    assert rd.eta(1.0, 1.0, 1.0) == pytest.approx(0.942809, abs=1e-6)
    assert rd.eta(1.5, 0.75, 0.75) == pytest.approx(0.993808, abs=1e-6)


def test_eta_gradient_matches_central_differences():
    r = ca.SX.sym("r", 3)
    e = rd.eta_expression(r[0], r[1], r[2])
    grad = ca.Function("grad", [r], [ca.gradient(e, r)])
    x0 = np.array([0.9, 1.3, 0.8])
    g = np.asarray(grad(x0)).ravel()
    h = 1e-6
    fd = [(rd.eta(*(x0 + h * np.eye(3)[k])) - rd.eta(*(x0 - h * np.eye(3)[k]))) / (2 * h) for k in range(3)]
    assert np.allclose(g, fd, rtol=1e-6, atol=1e-10)


def test_eq_20_to_26_chosen_point():
    # eq 24 -> eq 25 -> eq 26 with D = (40 + 80 + 40)/3 mm
    l = rd.from_plane(1.5, 0.0)
    assert l == pytest.approx((0.75, 1.5, 0.75))
    D = 0.16 / 3
    assert np.array(l) * D == pytest.approx([0.04, 0.08, 0.04])
    assert rd.normalize(0.04, 0.08, 0.04) == pytest.approx((D, 0.75, 1.5, 0.75))
    assert rd.to_plane(*l) == pytest.approx((1.5, 0.0))
    assert rd.design_space_violation(*l) is None  # on the edge l2 = 2 l1 of eq 22


def test_design_space_of_eq_22():
    assert rd.design_space_violation(1, 1, 1) is None
    assert "not within [l1/2, 2 l1]" in rd.design_space_violation(0.5, 1.5, 1.0)
    assert "l3 = 0 is not in (0, 3)" in rd.design_space_violation(1.5, 1.5, 0.0)
    assert "not 3" in rd.design_space_violation(1, 1, 1.2)
    with pytest.raises(InputError) as err:
        rd.check_design_space(0.5, 1.5, 1.0, ("inputs",))
    assert str(err.value) == (
        "inputs: normalized parameters outside the design space of eq 22 (l2 = 1.5 is not within [l1/2, 2 l1] = "
        "[0.25, 1]); expected 0 < l1, l2, l3 < 3, l1 + l2 + l3 = 3 and l1/2 <= l2 <= 2 l1"
    )


def test_transmission_map_is_nan_outside_eq_22():
    s = np.linspace(0, 2, 21)
    t = np.linspace(-2 / math.sqrt(3), math.sqrt(3), 31)
    E = rd.transmission_map(s, t)
    assert E.shape == (31, 21)
    for i, tt in enumerate(t):
        for j, ss in enumerate(s):
            inside = rd.design_space_violation(*rd.from_plane(ss, tt)) is None
            assert np.isfinite(E[i, j]) == inside
            if inside:
                assert E[i, j] == pytest.approx(closed_form_eta(*rd.from_plane(ss, tt)), rel=1e-12)


def test_synthesis_goes_to_the_corner_of_eq_22(model):
    res = rd.synthesis(model, cn.SolverConfig(), l_min=0.1, starts=6)
    assert res.status is cn.Status.SOLVED and res.converged == 6 and res.at_best == 6
    # eta rises with l1 / l2 and as l3 falls: l3 = l_min, l2 = l1/2
    assert res.l == pytest.approx((1.9333333333, 0.9666666667, 0.1), abs=1e-8)
    assert res.eta == pytest.approx(closed_form_eta(*res.l), rel=1e-12)


def test_synthesis_with_the_papers_platform_height_gives_the_design_of_eq_49(model):
    res = rd.synthesis(model, cn.SolverConfig(), l_min=0.1, fixed={"l3": 0.75}, starts=4)
    assert res.status is cn.Status.SOLVED
    assert res.l == pytest.approx((1.5, 0.75, 0.75), abs=1e-8)
    # every admissible (l1, l2) with l3 = 0.75 has a lower eta (a 1-D scan of the edge-to-edge range)
    for l1 in np.linspace(0.75, 1.5, 31)[:-1]:
        assert rd.eta(l1, 2.25 - l1, 0.75) < res.eta


def test_synthesis_reports_an_infeasible_problem(model):
    res = rd.synthesis(model, cn.SolverConfig(), l_min=0.1, fixed={"l2": 2.5}, starts=2)
    assert res.status is cn.Status.INFEASIBLE and res.l is None
