"""The faster paths of the cuboid and the membership test (issue 23, item 6) compute what
the direct ones computed: the working-set NLP's derivatives through the task points equal
CasADi's AD of the same NLP (and central differences), the singularity screen by the
certified bound gives numpy's verdicts, the verdict-only membership and the IK-only poses
equal the full ones, and mapped evaluation with less padding gives the same numbers."""

import importlib

import casadi as ca
import numpy as np
import pytest

import cpm_nlp as cn
from cpm_nlp.analysis import cuboid_ik
from cpm_nlp.analysis import workspace as W
from cpm_nlp.core.batch import evaluate_points

membership_module = importlib.import_module("cpm_nlp.analysis.workspace.membership")
cuboid_module = importlib.import_module("cpm_nlp.analysis.workspace.cuboid")


@pytest.fixture(scope="module")
def pantograph():
    """The pantograph of problems/pantograph_cuboid.yaml, its probed region and a 2000-point cloud."""
    m = cn.build_model("pantograph", {"a": 0.02, "b": 0.05}, {"psi_min": 1.49, "psi_max": 1.65, "phi_max": 0.0795})
    lo, hi = W.probe_region(m, cn.SolverConfig())
    T = lo + (hi - lo) * np.random.default_rng(0).random((2000, 3))
    return m, (lo, hi), T


@pytest.mark.parametrize("blocks", [1, 2])
def test_working_set_derivatives_equal_casadi_ad(pantograph, blocks):
    """hess_lag and jac_g of `SlotNLP` (through the task points, each slot's own quantity)
    against CasADi's Hessian and Jacobian of the NLP's own f and g over all 2d unknowns, and
    the Jacobian against central differences of g (numpy), at boxes about the optimum with
    random slots and multipliers."""
    m, (lo, hi), T = pantograph
    config = cn.SolverConfig()
    centre, size = 0.5 * (lo + hi), hi - lo
    engine = W._closed_form_cuboid(m, config, W.surface_grid(3, 5), centre, size, W.membership(m, T, config))
    layout = ((0, 6), (1, 6), (2, 4))  # phi, psi, a branch indicator: 16 slots in groups
    K = sum(Kr for _, Kr in layout)
    nlp = engine._nlp(layout, blocks)._solver
    hess, jac = nlp.get_function("nlp_hess_l"), nlp.get_function("nlp_jac_g")
    f_fn, g_fn = nlp.get_function("nlp_f"), nlp.get_function("nlp_g")
    X, P = ca.SX.sym("x", nlp.nnz_in(0)), ca.SX.sym("p", nlp.nnz_in(1))
    lam_f, lam_g = ca.SX.sym("lam_f"), ca.SX.sym("lam_g", g_fn.nnz_out(0))
    L = lam_f * f_fn(X, P) + ca.dot(lam_g, g_fn(X, P))
    ref_h = ca.Function("ref_h", [X, P, lam_f, lam_g], [ca.triu(ca.hessian(L, X)[0])])
    ref_j = ca.Function("ref_j", [X, P], [ca.jacobian(g_fn(X, P), X)])
    rng = np.random.default_rng(3)
    d = 3
    for _ in range(3):
        z = np.tile(np.r_[-0.24, -0.2, -0.24, 0.32, 0.4, 0.48], blocks) + 0.01 * rng.standard_normal(2 * d * blocks)
        S = rng.random((K * blocks, d))
        p = np.r_[m.p, S.ravel(), centre, size]
        lam = rng.standard_normal(K * blocks)
        H = np.array(ca.densify(hess(z, p, 0.7, lam)))
        H_ref = np.array(ca.densify(ref_h(z, p, 0.7, lam)))
        np.testing.assert_allclose(H, H_ref, rtol=1e-12, atol=1e-12 * np.abs(H_ref).max())
        g, Jg = (np.array(ca.densify(v)) for v in jac(z, p))
        np.testing.assert_allclose(g.ravel(), np.array(g_fn(z, p)).ravel(), rtol=1e-14, atol=1e-15)
        J_ref = np.array(ca.densify(ref_j(z, p)))
        np.testing.assert_allclose(Jg, J_ref, rtol=1e-12, atol=1e-12 * np.abs(J_ref).max())
        h = 1e-6
        fd = np.column_stack(
            [
                (np.array(g_fn(z + h * e, p)).ravel() - np.array(g_fn(z - h * e, p)).ravel()) / (2 * h)
                for e in np.eye(z.size)
            ]
        )
        np.testing.assert_allclose(Jg, fd, atol=1e-6 * max(1.0, np.abs(fd).max()))


def test_singular_screen_gives_numpys_verdicts(pantograph, monkeypatch):
    """`singular`: the certified bound where it clears half the threshold, Φ_x's condition
    number elsewhere -- the verdicts of numpy's 2-norm condition numbers at every pose, with
    the threshold moved to the middle of the poses' condition numbers so that both paths run
    (the bound is an upper bound of κ₂ everywhere)."""
    m, _region, T = pantograph
    c = m.closure
    X, Q, ok = W.poses(m, T)
    X, Q = X[ok], Q[ok]
    values = evaluate_points(c, membership_module.POSE_VALUES_KEY, W.pose_check_function(c), [X, Q], m.p)
    PX = values[2].reshape(-1, c.nx, c.nx)
    kappa = np.linalg.cond(PX)
    (B,) = evaluate_points(c, membership_module.POSE_BOUND_KEY, membership_module.pose_bound_function(c), [X, Q], m.p)
    assert np.all(B.ravel() >= kappa * (1 - 1e-12))
    for threshold in (W.SINGULAR_CONDITION, float(np.median(kappa)), float(np.median(B))):
        monkeypatch.setattr(membership_module, "SINGULAR_CONDITION", threshold)
        np.testing.assert_array_equal(membership_module.singular(m, X, Q), ~(kappa < threshold))


def test_verdicts_without_detail_are_the_same(pantograph):
    """membership(..., detail=False) screens only the poses within every limit: the same
    status of every point, and the same margin and binding wherever none is singular (none
    is here)."""
    m, _region, T = pantograph
    full = W.membership(m, T)
    fast = W.membership(m, T, detail=False)
    assert "singular" not in full.binding
    np.testing.assert_array_equal(fast.inside, full.inside)
    assert fast.status == full.status and fast.binding == full.binding
    np.testing.assert_array_equal(fast.margin, full.margin)


def test_poses_through_the_ik_alone_are_the_same(pantograph):
    """`poses` with a closed-form IK evaluates the IK only: the poses and flags the full
    membership evaluation gave (NaN where the reach margin is negative)."""
    m, (lo, hi), _T = pantograph
    T = lo + (hi - lo) * np.random.default_rng(5).uniform(-0.5, 1.5, (500, 3))  # some do not assemble
    X, Q, ok = W.poses(m, T)
    got = membership_module._points(m, T, None, W.CHECK_TOLERANCE)
    np.testing.assert_array_equal(X, got.X)
    np.testing.assert_array_equal(Q, got.Q)
    np.testing.assert_array_equal(ok, np.all(np.isfinite(got.X), axis=1))
    assert 0 < np.count_nonzero(ok) < len(T)


def test_rows_left_out_count_beyond_ipopts_bound_relaxation():
    """IPOPT relaxes a bound b by bound_relax_factor * max(1, |b|), at most constr_viol_tol
    (an infinite bound: no slack, and no NaN from 0 * inf)."""
    b = np.array([0.0, 1.65, -2.0, 1e7, np.inf])
    got = cuboid_ik.relaxation(b, {"ipopt.bound_relax_factor": 1e-10})
    np.testing.assert_allclose(got, [1e-10, 1.65e-10, 2e-10, 1e-4, 0.0])  # 1e-3 capped
    got = cuboid_ik.relaxation(b[:3], {})  # IPOPT's defaults: 1e-8, 1e-4
    np.testing.assert_allclose(got, [1e-8, 1.65e-8, 2e-8])
    assert np.all(cuboid_ik.relaxation(b, {"ipopt.bound_relax_factor": 0.0}) == 0.0)


def test_start_widths_hold_no_outside_cloud_point(pantograph):
    """The first seed's box keeps START_WIDTH; each later seed's cube, divided by
    START_FRACTION, holds no cloud point outside the workspace and touches one."""
    m, (lo, hi), T = pantograph
    mem = W.membership(m, T)
    centre, size = 0.5 * (lo + hi), hi - lo
    seeds = [m.task_of(m.x_home)] + list(T[mem.inside][:5])
    widths = cuboid_module._start_widths(seeds, T, mem, centre, size)
    assert widths[0] == cuboid_module.START_WIDTH
    out = (T[~mem.inside] - centre) / size
    for t, w in zip(seeds[1:], widths[1:]):
        half = 0.5 * w / cuboid_module.START_FRACTION
        cheb = np.max(np.abs(out - (t - centre) / size), axis=1)
        assert np.all(cheb >= half * (1 - 1e-12)) and np.min(cheb) == pytest.approx(half, rel=1e-12)


@pytest.mark.parametrize("n", [1, 9, 90, 264, 300])
def test_mapped_evaluation_padding_gives_the_same_numbers(pantograph, n):
    """evaluate_points pads to a multiple of an eighth of the next power of two: the values of
    a direct call of the function at every point, bit for bit."""
    m, _region, T = pantograph
    c = m.closure
    fn = W.task_point_function(c)
    got = evaluate_points(c, membership_module.TASK_POINT_KEY, fn, [T[:n]], m.p)
    for k in (0, n // 2, n - 1):
        direct = fn(T[k], m.p)
        for g, v in zip(got, direct):
            np.testing.assert_array_equal(g[k], np.array(v).ravel())


def test_no_bound_relaxation_still_settles(pantograph):
    """With IPOPT's bound relaxation off (bound_relax_factor 0), the rows left out count as
    violated beyond no slack, and the working sets still settle: the same box."""
    m, region, _T = pantograph
    strict = cn.SolverConfig(options={"ipopt.bound_relax_factor": 0.0})
    got = W.inscribed_cuboid(m, strict, starts=3, region=region)
    ref = W.inscribed_cuboid(m, cn.SolverConfig(), starts=3, region=region)
    assert got.found and ref.found and got.agreed == 3
    assert got.volume == pytest.approx(ref.volume, rel=1e-7)
