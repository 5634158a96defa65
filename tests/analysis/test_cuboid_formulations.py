"""The two formulations of the cuboid NLP (pose unknowns at every sample, or the
limited quantities through the closed-form IK on working sets of rows) solve the
same NLP; the vectorised membership test and probe give what the point-by-point
ones gave."""

import math

import numpy as np
import pytest

import cpm_nlp as cn
from cpm_nlp.analysis import workspace as W
from cpm_nlp.core.errors import InputError
from tests.conftest import PROBLEMS


@pytest.mark.parametrize("name", ["pantograph_cuboid", "prc3_cuboid"])
def test_both_formulations_give_the_same_cuboid(name):
    problem = cn.load_problem(PROBLEMS / f"{name}.yaml")
    model, starts = problem.model, problem.inputs["starts"]
    poses = W.inscribed_cuboid(model, problem.solver, starts=starts, formulation="poses")
    closed = W.inscribed_cuboid(model, problem.solver, starts=starts, formulation="closed_form")
    for res in (poses, closed):
        assert res.found and res.check.passed and res.agreed == res.starts == starts
    # the same optimum to IPOPT's tolerance (tol 1e-10), in volume and in every face
    assert closed.volume == pytest.approx(poses.volume, rel=1e-8)
    scale = poses.upper - poses.lower
    np.testing.assert_allclose((closed.lower - poses.lower) / scale, 0, atol=1e-8)
    np.testing.assert_allclose((closed.upper - poses.upper) / scale, 0, atol=1e-8)
    # the default for a mechanism with a closed-form IK is the closed form
    auto = W.inscribed_cuboid(model, problem.solver, starts=starts)
    np.testing.assert_array_equal(auto.lower, closed.lower)


def test_corners_only_closed_form_finds_the_larger_local_optimum():
    """With only the corners as samples the discretised NLP has a second, larger local
    optimum: a box around the inner ellipsoid (eq 24), its corners in the workspace and
    its centre in the hole.  The closed form reaches it from these starts; no shrink
    about that centre passes the check, and the result says so instead of a number."""
    m = cn.build_model("pantograph", {"a": 0.02, "b": 0.05}, {"psi_min": 1.49, "psi_max": 1.65, "phi_max": 0.0795})
    res = W.inscribed_cuboid(m, starts=2, samples_per_edge=2, refinements=0, formulation="closed_form")
    poses = W.inscribed_cuboid(m, starts=2, samples_per_edge=2, refinements=0, formulation="poses")
    assert min(res.start_volumes) > 2 * max(poses.start_volumes)
    assert not res.found and res.volume is None and res.lower is None
    assert "no box passes the membership check" in res.message
    assert poses.found and poses.shrink < 1.0


def test_formulation_is_checked(prs3):
    with pytest.raises(InputError, match="unknown cuboid formulation 'pose'.*did you mean 'poses'"):
        W.inscribed_cuboid(prs3, formulation="pose")
    from cpm_nlp.core.model import LoopClosure, Model
    from tests.reference import prs3_closures as P3

    no_ik = LoopClosure(
        "prs3_no_ik",
        x=P3.X,
        q=P3.Q,
        parameters=("b", "L", "alpha0"),
        phi=P3.loop_closure(),
        task=P3.TASK,
        home=P3.home,
        bounds=P3.bounds,
    )
    other = Model(no_ik, dict(prs3.parameters), {"s": (-2e-3, 2e-3)}, dict(prs3.derived))
    with pytest.raises(InputError, match="needs a closed-form IK; prs3_no_ik has none"):
        W.inscribed_cuboid(other, formulation="closed_form")


def _home_engine():
    m = cn.build_model("pantograph", {"a": 0.02, "b": 0.05}, {"psi_min": 1.49, "psi_max": 1.65, "phi_max": 0.0795})
    config = cn.SolverConfig()
    lo, hi = W.probe_region(m, config)
    centre, size = 0.5 * (lo + hi), hi - lo
    T = lo + (hi - lo) * np.random.default_rng(0).random((2000, 3))
    engine = W._closed_form_cuboid(m, config, W.surface_grid(3, 5), centre, size, W.membership(m, T, config))
    box = W._start_box(m, m.x_home[:3], engine.S, centre, size, config)
    return m, engine, box


def _recorded(engine) -> list:
    solves = []
    solve = engine._solve
    engine._solve = lambda z0, work: solves.append(len(work)) or solve(z0, work)
    return solves


def test_working_set_rows_added_until_none_is_violated():
    """Begun from the corner rows only, the rows its solution violates are added until
    none is, and the final box satisfies every row of every sample (the same NLP as with
    all rows)."""
    _m, engine, box = _home_engine()
    assert {r for _, r in engine.initial} == {0, 1}  # phi and psi bind in the region; the branch does not
    corners = {int(j) for j in np.flatnonzero(np.all((engine.S == 0) | (engine.S == 1), axis=1))}
    engine.initial = {(j, r) for j, r in engine.initial if j in corners}
    assert len(engine.initial) == 16  # their rows at the 8 corners
    solves = _recorded(engine)
    ok, z, _status, _iters = engine.start(*box)
    assert ok and len(solves) >= 2 and solves[0] == 16 and solves == sorted(solves)
    V = engine.values(z)  # within IPOPT's relaxed bounds (bound_relax_factor 1e-10), inside the margin
    assert np.all((V >= engine.lo - 1e-9) & (V <= engine.hi + 1e-9))
    assert 0 < len(engine.memory) < 40  # the active rows carried to the next starts


def test_first_rows_are_the_corners_and_face_centres():
    """The first start's rows: the binding quantities at the 8 corners and the 6 face centres
    of the 5-per-edge grid; from them the home start settles in one solve, at the box the
    corners' rows reach in several (the same optimum of the NLP with all rows)."""
    _m, engine, box = _home_engine()
    S = engine.S
    faces = {int(j) for j in np.flatnonzero(np.sum(S == 0.5, axis=1) == 2)}
    corners = {int(j) for j in np.flatnonzero(np.all((S == 0) | (S == 1), axis=1))}
    assert len(faces) == 6 and {j for j, _ in engine.initial} == faces | corners
    assert len(engine.initial) == 28
    solves = _recorded(engine)
    ok, z, _status, _iters = engine.start(*box)
    assert ok and solves == [28]
    _m, other, box = _home_engine()
    other.initial = {(j, r) for j, r in other.initial if j in corners}
    ok2, z2, _status, _iters = other.start(*box)
    assert ok2
    np.testing.assert_allclose(z, z2, atol=1e-8)


def test_condition_numbers_screen_is_exact_where_it_matters():
    rng = np.random.default_rng(1)
    A = rng.normal(size=(200, 6, 6))
    A[:50, :, 0] = A[:50, :, 1] * (1 + 1e-13)  # nearly singular
    A[50:60, :, 0] = A[50:60, :, 1]  # singular
    A[60:70] = np.nan
    got = W.condition_numbers(A)
    assert np.all(np.isinf(got[60:70]))  # NaN entries: singular
    A, got = np.delete(A, np.s_[60:70], axis=0), np.delete(got, np.s_[60:70])
    cond = np.linalg.cond(A)
    high = ~(cond < W.SINGULAR_CONDITION)
    np.testing.assert_array_equal(~(got < W.SINGULAR_CONDITION), high)
    np.testing.assert_array_equal(got[high & np.isfinite(cond)], cond[high & np.isfinite(cond)])
    assert np.all(got[~high] >= cond[~high] * (1 - 1e-12))  # an upper bound elsewhere


@pytest.mark.parametrize("name", ["pantograph_cuboid", "prc3_cuboid"])
def test_probe_with_several_levels_per_call_equals_one_level(name, monkeypatch):
    model = cn.load_problem(PROBLEMS / f"{name}.yaml").model
    fast = W.probe_region(model)
    monkeypatch.setattr(W, "PROBE_LEVELS", 1)
    one = W.probe_region(model)
    np.testing.assert_array_equal(fast[0], one[0])
    np.testing.assert_array_equal(fast[1], one[1])


def test_membership_of_many_and_few_points_agree():
    """Small batches (one mapped call, padded) and large ones (threaded chunks) give
    the same answers point by point."""
    m = cn.build_model("pantograph", {"a": 0.02, "b": 0.05}, {"psi_min": 1.2, "psi_max": 2.2, "phi_max": 0.3})
    lo, hi = W.probe_region(m, factor=3.0)
    T = lo + (hi - lo) * np.random.default_rng(3).random((20000, 3))
    big = W.membership(m, T)
    for k in (0, 1, 7, 300, 19999):
        one = W.membership(m, T[k : k + 1])
        assert one.inside[0] == big.inside[k] and one.binding[0] == big.binding[k]
        assert one.margin[0] == big.margin[k] or (math.isinf(one.margin[0]) and math.isinf(big.margin[k]))
    few = W.membership(m, T[:1000])
    np.testing.assert_array_equal(few.inside, big.inside[:1000])
    np.testing.assert_array_equal(few.margin, big.margin[:1000])


def test_auto_keeps_pose_unknowns_where_the_ik_reach_bounds_the_workspace():
    """Without joint limits the pantograph's workspace ends where the links stretch out
    (the IK's reach margin 2a - |AB| reaches 0, its derivatives unbounded): "auto" then
    solves with pose unknowns; "closed_form" can be asked for and finds the same box to
    the tolerance of its ill-conditioned boundary."""
    m = cn.build_model("pantograph", {"a": 0.02, "b": 0.05}, {})
    auto = W.inscribed_cuboid(m, starts=4)
    poses = W.inscribed_cuboid(m, starts=4, formulation="poses")
    np.testing.assert_array_equal(auto.lower, poses.lower)
    closed = W.inscribed_cuboid(m, starts=4, formulation="closed_form")
    # at least 3 of the 4 starts: on the pantograph file (12 pose coordinates, issue 21) one start
    # stops on the ill-conditioned boundary (the module's 6 let all 4 converge); the box is the same
    assert closed.found and closed.converged >= 3 and closed.volume == pytest.approx(poses.volume, rel=1e-5)


@pytest.mark.parametrize("name", ["pantograph_cuboid", "prc3_cuboid"])
def test_starts_together_give_the_starts_one_by_one(name, monkeypatch):
    """The starts after the first, solved as one block-separable NLP, reach the optima
    the same starts reach one by one (each start's volume, to IPOPT's tolerance: a row
    outside a working set counts as violated beyond IPOPT's bound relaxation,
    1e-10 absolute, 1e-6 of the 3-PRC's 0.1 mm strokes, so two solve sequences of one start
    may stop 1e-8 apart in volume)."""
    from cpm_nlp.analysis import cuboid_ik

    problem = cn.load_problem(PROBLEMS / f"{name}.yaml")
    model, starts = problem.model, problem.inputs["starts"]
    together = W.inscribed_cuboid(model, problem.solver, starts=starts, formulation="closed_form")
    monkeypatch.setattr(cuboid_ik.ClosedFormCuboid, "start_all", lambda self, boxes: (None, 0))
    alone = W.inscribed_cuboid(model, problem.solver, starts=starts, formulation="closed_form")
    assert together.found and alone.found and together.agreed == alone.agreed == starts
    np.testing.assert_allclose(together.start_volumes, alone.start_volumes, rtol=1e-7)
    assert together.iterations < alone.iterations  # IPOPT iterations: one run for the seven starts
    scale = alone.upper - alone.lower
    np.testing.assert_allclose((together.lower - alone.lower) / scale, 0, atol=1e-8)


def test_a_failed_joint_start_falls_back_to_one_by_one(monkeypatch):
    """If the joint solve of the later starts does not converge, they run one by one:
    the same optima as without the joint solve, its iterations still counted."""
    from cpm_nlp.analysis import cuboid_ik

    problem = cn.load_problem(PROBLEMS / "prc3_cuboid.yaml")
    model, starts = problem.model, problem.inputs["starts"]
    monkeypatch.setattr(cuboid_ik.ClosedFormCuboid, "start_all", lambda self, boxes: (None, 0))
    alone = W.inscribed_cuboid(model, problem.solver, starts=starts, formulation="closed_form")
    monkeypatch.undo()
    monkeypatch.setattr(
        cuboid_ik.ClosedFormCuboid, "settle_blocks", lambda self, z0s, works: ([], False, "forced failure", 7, [])
    )
    fallback = W.inscribed_cuboid(model, problem.solver, starts=starts, formulation="closed_form")
    assert fallback.found and fallback.agreed == starts
    np.testing.assert_array_equal(fallback.start_volumes, alone.start_volumes)
    assert fallback.iterations == alone.iterations + 7
