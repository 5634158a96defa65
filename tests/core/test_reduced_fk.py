"""FK by Newton on the task coordinates through the closed-form IK (issue 15).

The reduced formulation (nq unknowns, :func:`cpm_nlp.core.kernels.reduced_fk_kernel`)
answers a pose only when it settles it as solved; every other pose goes to
the full Newton on Φ (:func:`cpm_nlp.core.kernels.full_fk_kernel`).  Checked
here: agreement with the full path on random poses of all four mechanisms,
identical statuses on poses that are wrong-branch, out of reach, singular or
outside the joint limits, the conditioning certificate against numpy, the
first-order guess against central differences, and batch = single solves
(issue 13).
"""

import math
from pathlib import Path

import casadi as ca
import numpy as np
import pytest

import cpm_nlp as cn
from cpm_nlp.core.batch import _finish, evaluate, thread_pool
from cpm_nlp.core.compiled import compiler_available
from cpm_nlp.core.conditioning import (
    CERTIFY_DELTA,
    LeftInverseBlocks,
    closure_blocks,
    cond1_block_bound,
    cond2_left_inverse_bound,
)
from cpm_nlp.core.kernels import PATHS, full_fk_kernel, linearization, reduced_fk_kernel, shared_values
from cpm_nlp.core.pose_checks import SCALAR, is_singular
from cpm_nlp.core.result import Status
from cpm_nlp.mechanisms.described import load_file
from tests.conftest import PAPER_PRS3, central_difference
from tests.reference import pantograph_closures

NEWTON = cn.SolverConfig("newton")
LIMITED = {"s": ["-2 mm", "2 mm"], "beta_m": ["-1.5 deg", "1.5 deg"]}
#: prc3-li-2018.md Table 1 (kinematic part), as in test_prc3_kinematics.py
TABLE1 = {"L1": "9.5 mm", "L2": "25 mm", "L3": "9 mm", "L4": "30 mm", "L7": "73.5 mm"}


def build(name, limited=True):
    """The papers' models (with the papers' joint limits unless ``limited`` is false)."""
    if name == "prs3":
        return cn.build_model("prs3", PAPER_PRS3, LIMITED if limited else {})
    if name == "prc3":
        return cn.build_model("prc3", TABLE1, {"q": ["0 um", "15 um"]} if limited else {})
    if name == "rpr":
        return cn.build_model("rpr", {"r1": "40 mm", "r2": "80 mm", "P0": "40 mm"})
    if name == "pantograph_file":  # bodies and joints, solved through normal equations (no limits declared)
        return overconstrained_pantograph()
    limits = {"psi_min": "1.49 rad", "psi_max": "1.65 rad", "phi_max": "0.0795 rad"}
    return cn.build_model("pantograph", {"a": "20 mm", "b": "50 mm"}, limits if limited else {})


def overconstrained_pantograph(params=None):
    """The pantograph with the paper's R hinges at C and F (tests/corpus/pantograph_joints.yaml):
    Gruebler-Kutzbach -1, solved through normal equations.  (The shipped file closes its loops
    with S joints at C and F since the pantograph became its file: not overconstrained.)"""
    mech = load_file(Path(__file__).resolve().parents[1] / "corpus" / "pantograph_joints.yaml")
    return mech.model(mech.closure(), params or {"a": "20 mm", "b": "50 mm"}, {}, ())


#: half-widths of random task coordinates about home (SI), per mechanism: the papers' working ranges and beyond
SPREAD = {
    "prs3": [3e-3, math.radians(1.0), math.radians(1.0)],
    "prc3": [4e-6, 4e-6, 4e-6],
    "rpr": [0.2, 0.2, 8e-3],
    "pantograph": [6e-3, 6e-3, 6e-3],
    "pantograph_file": [6e-3, 6e-3, 6e-3],
}


def full_only(model, q, x0=None):
    """The batch as it was before the reduced path: Newton on Φ from x0 for every pose."""
    c = model.closure
    kern = full_fk_kernel(c, NEWTON)
    x0 = model.x_home if x0 is None else x0
    out = dict(zip(kern.outputs, evaluate(kern.function, [q, x0, *shared_values(kern, model, NEWTON.tolerance)])))
    return _finish("forward_kinematics", model, out, q, NEWTON.tolerance, "map", 1, 0.0, "fast_newton")


@pytest.mark.parametrize("name", ["prs3", "prc3", "rpr", "pantograph", "pantograph_file"])
def test_reduced_agrees_with_full_on_random_poses(name):
    """Random poses (from the closed-form IK of random task coordinates, and
    random actuator vectors about home): the reduced path answers the poses it
    settles with the pose of the full Newton (1e-12) and of the IK, and every
    status equals the full path's."""
    model = build(name, limited=False)
    c = model.closure
    rng = np.random.default_rng(150)
    t = model.x_home[c.task_index] + rng.uniform(-1, 1, (300, c.nq)) * np.array(SPREAD[name])
    ik = cn.batch_inverse_kinematics(model, t)
    assert ik.ok.sum() >= 100, ik.counts()
    q_home = model.q_home + rng.uniform(-1, 1, (200, c.nq)) * np.abs(ik.q[ik.ok] - model.q_home).max(axis=0)
    q = np.vstack([ik.q[ik.ok], q_home])
    res = cn.batch_forward_kinematics(model, q)
    ref = full_only(model, q)
    np.testing.assert_array_equal(res.status, ref.status)
    paths = np.array([res.path(i) for i in range(len(res))])
    assert set(paths) <= set(PATHS)
    reduced = paths == "reduced"
    assert reduced.mean() > 0.8, res.counts()
    assert res.ok[reduced].all()  # the reduced path answers only what it settles as solved
    both = res.ok & ref.ok
    np.testing.assert_allclose(res.x[both], ref.x[both], rtol=0, atol=1e-12)
    if c.passive is not None:
        np.testing.assert_allclose(res.passive[both], ref.passive[both], rtol=0, atol=1e-12)
    # FK against IK: the poses the IK made come back
    n_ik = int(ik.ok.sum())
    np.testing.assert_allclose(res.x[:n_ik][res.ok[:n_ik]], ik.x[ik.ok][res.ok[:n_ik]], rtol=0, atol=1e-12)


def hard_cases(model, rng):
    """(q rows, x0 rows) of the edge cases: out of the joint limits, out of
    reach (no assembly: not_converged for an FK), a guess on the mirrored
    assembly (wrong_branch), large strokes where Newton from home wanders off."""
    inside = rng.uniform(-2.2e-3, 2.2e-3, (150, 3))  # in reach; some outside the +-2 mm stroke limits
    far = np.array([[0.3, -0.3, 0.0], [0.0, 0.0, 0.2], [-0.1, 0.05, 0.08]])
    large = rng.uniform(-0.05, 0.05, (100, 3))
    q = np.vstack([inside, far, large])
    x0 = np.tile(model.x_home, (q.shape[0], 1))
    mirrored = model.x_home.copy()
    mirrored[2] = -mirrored[2]  # below the actuator plane
    x0[::7] = mirrored
    return q, x0


def test_edge_cases_have_the_statuses_of_the_full_path():
    """wrong_branch, out of reach (not_converged), singular and
    outside_joint_limits poses get exactly the status the full path gives
    them, and the full path is the one that answers them."""
    model = build("prs3")
    rng = np.random.default_rng(151)
    q, x0 = hard_cases(model, rng)
    res = cn.batch_forward_kinematics(model, q, guess=x0)
    ref = full_only(model, q, x0)
    np.testing.assert_array_equal(res.status, ref.status)
    statuses = set(res.statuses)
    assert {Status.SOLVED, Status.WRONG_BRANCH, Status.NOT_CONVERGED, Status.OUTSIDE_JOINT_LIMITS} <= statuses
    for i in np.flatnonzero(~res.ok):
        assert res.path(i) == "full" and res.message(i) == ref.message(i)
    # singular: nearly flat legs (type II); the second model is refined to solved by the 2-norm condition number
    for alpha0, expected in (("1e-7 deg", Status.SINGULAR), ("1e-6 deg", Status.SOLVED)):
        flat = cn.build_model("prs3", {"b": "47.91 mm", "L": "109.215 mm", "alpha0": alpha0})
        qs = np.vstack([np.zeros(3), rng.uniform(-1e-6, 1e-6, (20, 3))])
        res = cn.batch_forward_kinematics(flat, qs)
        ref = full_only(flat, qs)
        np.testing.assert_array_equal(res.status, ref.status)
        assert res.statuses[0] is expected and res.path(0) == "full"
        assert res.message(0) == ref.message(0)


def test_reduced_kernel_never_settles_a_pose_the_full_path_rejects():
    """The reduced kernel on its own: on every edge case it reports solved only where the full path does."""
    model = build("prs3")
    q, x0 = hard_cases(model, np.random.default_rng(152))
    kern = reduced_fk_kernel(model.closure, NEWTON)
    out = dict(zip(kern.outputs, evaluate(kern.function, [q, x0, *shared_values(kern, model, NEWTON.tolerance)])))
    settled = out["status"].ravel() == 0
    ref = full_only(model, q, x0)
    assert settled.sum() >= 10 and ref.ok.sum() == settled.sum()  # all the solved poses settle here
    assert ref.ok[settled].all()
    np.testing.assert_allclose(out["x"][settled], ref.x[settled], rtol=0, atol=1e-12)


def test_conditioning_certificate_bounds_the_condition_number():
    """cond1 of the reduced path is an upper bound of κ₁(Φ_x) (induced 1-norm,
    numpy), from Φ_x⁻¹ at home and no inverse at the pose; +inf where the
    preconditioned residual exceeds CERTIFY_DELTA."""
    model = cn.build_model("prs3", PAPER_PRS3)
    c = model.closure
    rng = np.random.default_rng(153)
    q = np.vstack([rng.uniform(-2.3e-3, 2.3e-3, (100, 3)), rng.uniform(-0.03, 0.03, (100, 3))])
    kern = reduced_fk_kernel(c, NEWTON)
    out = dict(zip(kern.outputs, evaluate(kern.function, [q, model.x_home, *shared_values(kern, model, 1e-10)])))
    b = linearization(model)["Phi_x_home_inv"].reshape(c.nx, c.nx, order="F")
    np.testing.assert_allclose(b @ np.asarray(c.phi_x(model.x_home, model.q_home, model.p)), np.eye(c.nx), atol=1e-12)
    finite = 0
    for i in range(q.shape[0]):
        x = out["x"][i]
        if not np.all(np.isfinite(x)):
            continue
        a = np.asarray(c.phi_x(x, q[i], model.p))
        delta = np.abs(np.eye(c.nx) - a @ b).sum(axis=0).max()
        bound = out["cond1"][i, 0]
        if delta <= CERTIFY_DELTA * (1 - 1e-9):
            exact = np.linalg.cond(a, 1)
            assert exact <= bound * (1 + 1e-12)
            assert bound <= exact * np.linalg.cond(b, 1) / (1 - delta) * 1.01  # not vacuous either
            finite += 1
        elif delta > CERTIFY_DELTA * (1 + 1e-9):
            assert bound == np.inf
    assert finite >= 100


def test_first_order_guess_is_the_ad_jacobian_at_home():
    """J_home (dt/dq at home, AD) equals central differences of the FK's task
    coordinates, and the first-order guess is second-order accurate."""
    model = cn.build_model("prs3", PAPER_PRS3)
    c = model.closure
    jac = linearization(model)["J_home"].reshape(c.nq, c.nq, order="F")

    def task_of_q(q):
        return cn.forward_kinematics(model, q, NEWTON).x[c.task_index]

    np.testing.assert_allclose(jac, central_difference(task_of_q, model.q_home, 1e-7), rtol=1e-6, atol=1e-9)
    direction = np.array([1.0, -0.4, 0.7])
    errors = []
    for h in (1e-3, 0.5e-3):
        q = model.q_home + h * direction
        t0 = model.x_home[c.task_index] + jac @ (q - model.q_home)
        errors.append(np.max(np.abs(t0 - task_of_q(q))))
    assert errors[0] / errors[1] == pytest.approx(4.0, rel=0.05)  # error O(|q - q_home|²)


def hard_batch(model, rng, n=240):
    """>= 200 random actuator vectors, incl. hard ones: outside the limits, out
    of reach, large strokes (wrong branch or no convergence from home)."""
    q = rng.uniform(-2.2e-3, 2.2e-3, (n, 3))
    q[::8] = rng.uniform(-0.05, 0.05, (q[::8].shape[0], 3))
    q[::25] = [0.3, -0.3, 0.0]
    return q


@pytest.mark.parametrize("backend", ["map", "compiled"])
def test_batch_equals_single_solves_on_hard_poses(backend):
    """Issue 13: the same statuses, messages, paths and values in a batch as in
    single Newton solves, over 240 random poses incl. hard ones (same kernel,
    same initial-guess rule, same checks)."""
    if backend == "compiled" and not compiler_available():
        pytest.skip("no C compiler")
    model = cn.build_model("prs3", PAPER_PRS3, {"s": ["-2 mm", "2 mm"]})
    q = hard_batch(model, np.random.default_rng(154))
    res = cn.batch_forward_kinematics(model, q, backend=backend)
    counts = res.counts()
    assert counts["solved"] >= 50 and counts["outside_joint_limits"] >= 20, counts
    assert counts.get("not_converged", 0) + counts.get("wrong_branch", 0) >= 10, counts
    for k in range(len(q)):
        single = cn.forward_kinematics(model, q[k], NEWTON, backend=backend)
        assert res.statuses[k] is single.status, (k, single.message, res.message(k))
        assert res.message(k) == single.message
        assert res.path(k) == single.path
        if single.ok:
            np.testing.assert_allclose(res.x[k], single.x, rtol=0, atol=1e-12)
            np.testing.assert_allclose(res.passive[k], single.passive, rtol=0, atol=1e-12)


def test_single_solve_says_which_path_answered():
    model = build("prs3")
    sol = cn.forward_kinematics(model, [1e-3, 0.5e-3, -0.3e-3], NEWTON)
    assert sol.ok and sol.path == "reduced" and sol.solver == "newton"
    np.testing.assert_allclose(sol.x, cn.inverse_kinematics(model, sol.x[model.closure.task_index]).x, atol=1e-13)
    far = cn.forward_kinematics(model, [0.3, -0.3, 0.0], NEWTON)
    assert far.status is Status.NOT_CONVERGED and far.path == "full"
    assert far.message.startswith("Newton stopped at max |Φ| = ")
    # IPOPT keeps its own path
    assert cn.forward_kinematics(model, [1e-3, 0.5e-3, -0.3e-3]).path == ""


def test_exported_code_has_the_reduced_path(tmp_path):
    model = build("prs3")
    data = cn.export_kinematics(model, tmp_path / "c", what="fk", fmt="c")
    source = (tmp_path / "c" / "prs3_kinematics.c").read_text()
    assert "prs3_fk_reduced" in source and "prs3_fk_full" in source
    assert "task coordinates through the closed-form IK" in data["newton"]["method"]


def test_the_thread_pool_is_kept_between_batches():
    model = build("prs3")
    q = np.random.default_rng(155).uniform(-2e-3, 2e-3, (1000, 3))
    cn.batch_forward_kinematics(model, q, threads=2)
    pool = thread_pool(2)
    one = cn.batch_forward_kinematics(model, q, threads=1)
    two = cn.batch_forward_kinematics(model, q, threads=2)
    assert thread_pool(2) is pool
    np.testing.assert_array_equal(one.x, two.x)


def test_auto_backend_falls_back_to_the_virtual_machine_when_compiling_fails(tmp_path, monkeypatch, caplog):
    """A single Newton solve never fails for want of a working C compiler."""
    monkeypatch.setenv("CPM_NLP_CACHE", str(tmp_path / "cache"))
    monkeypatch.setenv("CC", "false")  # a "compiler" that always fails
    model = build("prs3")
    with caplog.at_level("WARNING", logger="cpm_nlp"):
        sol = cn.forward_kinematics(model, [1e-3, 0.5e-3, -0.3e-3], NEWTON)
    assert sol.ok and sol.path == "reduced"
    assert "backend 'auto' uses 'map'" in caplog.text
    ref = cn.forward_kinematics(model, [1e-3, 0.5e-3, -0.3e-3], NEWTON, backend="map")
    np.testing.assert_array_equal(sol.x, ref.x)


# -- a linkage solved through normal equations (the pantograph file): certified at the pose --------


def _pantographs():
    panto = {"a": "20 mm", "b": "50 mm"}
    return overconstrained_pantograph(panto), pantograph_closures.reference_model(panto)


def test_pantograph_file_answers_on_the_reduced_path_as_the_module():
    """The shipped pantograph file (bodies and joints: 12 pose coordinates, normal equations of
    10 loop rows) on 500 random actuator vectors within +-2 mm of home: every pose solved on the
    reduced path (before cond1_block_bound, 498 of 500 fell back to the full Newton: Φ_x⁻¹ at home
    no longer certified), and each equals the hand-written module (eq 1-8) to 1e-12; a single
    solve answers on the same path with the same pose."""
    file, module = _pantographs()
    c = file.closure
    assert c.loops is not None  # the normal-equation form
    q = module.q_home + np.random.default_rng(160).uniform(-2e-3, 2e-3, (500, 3))
    res, ref = cn.batch_forward_kinematics(file, q), cn.batch_forward_kinematics(module, q)
    assert res.ok.all() and ref.ok.all()
    assert all(res.path(i) == "reduced" for i in range(len(res)))
    idx = [c.x_names.index(n) for n in module.closure.x_names]  # px, py, pz, theta1, theta2, phi
    np.testing.assert_allclose(res.x[:, idx], ref.x, rtol=0, atol=1e-12)
    for k in range(0, 500, 50):
        single = cn.forward_kinematics(file, q[k], NEWTON)
        assert single.ok and single.path == "reduced"
        np.testing.assert_allclose(single.x, res.x[k], rtol=0, atol=1e-13)
        assert np.max(np.abs(np.asarray(c.loops(single.x, q[k], file.p)))) < 1e-12  # every loop row holds


def test_pantograph_file_edge_cases_have_the_statuses_of_the_full_path():
    """Out of reach and large strokes (+-50 mm on 20 mm links), from home: a pose that is not
    solved has the full path's status and message and was answered by it; a pose the full path
    solves is solved with its pose (angles up to whole turns: Newton from home may wind them); a
    pose solved where Newton on the normal equations from home is not (it wanders at large
    strokes) is on the reduced path and checked here independently: every loop row holds, and
    the hand-written module's IK (eq 9-10, 18) of its task coordinates gives back its q."""
    file, module = _pantographs()
    c = file.closure
    rng = np.random.default_rng(161)
    q = np.vstack(
        [
            file.q_home + rng.uniform(-2e-3, 2e-3, (40, 3)),
            [[0.3, -0.3, 0.0], [0.0, 0.0, 0.2], [-0.1, 0.05, 0.08]],
            file.q_home + rng.uniform(-0.05, 0.05, (60, 3)),
        ]
    )
    res = cn.batch_forward_kinematics(file, q)
    ref = full_only(file, q)
    assert {Status.SOLVED, Status.NOT_CONVERGED} <= set(res.statuses), res.counts()
    for i in np.flatnonzero(~res.ok):
        assert res.status[i] == ref.status[i] and res.path(i) == "full" and res.message(i) == ref.message(i)
    assert res.ok[ref.ok].all()
    both = ref.ok
    np.testing.assert_allclose(_wrap_angles(c, res.x[both] - ref.x[both]), 0, atol=1e-12)
    extra = np.flatnonzero(res.ok & ~ref.ok)
    assert extra.size >= 1
    for i in extra:
        assert res.path(i) == "reduced"
        assert np.max(np.abs(np.asarray(c.loops(res.x[i], q[i], file.p)))) < 1e-12
        ik = cn.inverse_kinematics(module, res.x[i][c.task_index])
        np.testing.assert_allclose(ik.q, q[i], rtol=0, atol=1e-12)


def _wrap_angles(c, d):
    """Differences of poses with the angle coordinates' whole turns taken off."""
    d = np.array(d, dtype=float)
    for k, coord in enumerate(c.x):
        if coord.kind == "angle":
            d[:, k] = (d[:, k] + math.pi) % (2 * math.pi) - math.pi
    return d


def _module(params):
    """The hand-written pantograph (eq 1-8), kept as the test reference."""
    return pantograph_closures.reference_model(params)


def _e_x_central(c, x, q, p, h=1e-7):
    """Jacobian of every closure equation (``loops``) by central differences (numpy)."""
    f = lambda v: np.asarray(c.loops(v, q, p), dtype=float).ravel()  # noqa: E731
    return np.column_stack([(f(x + h * e) - f(x - h * e)) / (2 * h) for e in np.eye(len(x))])


def test_conditioning_bound_of_the_pantograph_file_bounds_kappa2_of_every_equation():
    """cond1 of the reduced path on the pantograph file (normal equations) is an upper bound of
    κ₂ of e_x, the Jacobian of every closure equation (16 x 12: 10 loop rows, 3 actuation, 3
    platform rows; numpy SVD, e_x checked against central differences), and within 10x of it (not
    vacuous), from poses near home to poses where Φ_x⁻¹ at home certifies nothing."""
    file, _ = _pantographs()
    c = file.closure
    rng = np.random.default_rng(162)
    q = file.q_home + np.vstack([rng.uniform(-2e-3, 2e-3, (60, 3)), rng.uniform(-6e-3, 6e-3, (60, 3))])
    kern = reduced_fk_kernel(c, NEWTON)
    out = dict(zip(kern.outputs, evaluate(kern.function, [q, file.x_home, *shared_values(kern, file, 1e-10)])))
    b = linearization(file)["Phi_x_home_inv"].reshape(c.nx, c.nx, order="F")
    solved = np.flatnonzero(out["status"].ravel() == 0)
    assert solved.size == len(q)
    uncertified = 0
    for i in solved:
        e_x = np.asarray(c.cond_matrix(out["x"][i], q[i], file.p))
        assert e_x.shape == (16, 12)
        np.testing.assert_allclose(e_x, _e_x_central(c, out["x"][i], q[i], file.p), rtol=0, atol=1e-7)
        exact = np.linalg.cond(e_x)
        assert exact * (1 - 1e-12) <= out["cond1"][i, 0] <= 10 * exact
        a = np.asarray(c.phi_x(out["x"][i], q[i], file.p))
        uncertified += np.abs(np.eye(c.nx) - a @ b).sum(axis=0).max() > CERTIFY_DELTA
    assert uncertified >= 60  # the home inverse would have sent these to the full path


def test_left_inverse_bound_on_random_matrices_of_the_pantograph_pattern():
    """cond2_left_inverse_bound on e_x's pattern of the pantograph file (block upper triangular:
    three 1 x 1 platform blocks, the 10 x 6 loop block, three 1 x 1 actuation blocks) with random
    numbers: never below κ₂ (numpy SVD, 100 matrices), +inf for a rank deficient loop block or a
    NaN entry; and on a dense tall matrix (one block) exact up to ‖·‖_F over ‖·‖₂."""
    file, _ = _pantographs()
    c = file.closure
    blocks = closure_blocks(c)
    assert [len(r) for r in blocks.rows] == [1, 1, 1, 10, 1, 1, 1]
    assert [len(k) for k in blocks.cols] == [1, 1, 1, 6, 1, 1, 1]
    sp = c.cond_matrix.sparsity_out(0)
    sym = ca.SX.sym("e", sp)
    fn = ca.Function("bound", [sym], [cond2_left_inverse_bound(sym, blocks)])
    rng = np.random.default_rng(164)
    for _ in range(100):
        v = rng.normal(size=sp.nnz())
        exact = np.linalg.cond(np.array(ca.DM(sp, v)))
        assert exact * (1 - 1e-12) <= float(fn(ca.DM(sp, v))) < np.inf
    dense = np.array(ca.DM(sp, rng.normal(size=sp.nnz())))
    rows, cols = list(blocks.rows[3]), list(blocks.cols[3])
    dense[np.ix_(rows, [cols[0]])] = 0.0  # a column of the loop block vanishes (its pattern kept)
    assert np.linalg.matrix_rank(dense) < c.nx
    assert float(fn(ca.project(ca.DM(dense), sp))) == np.inf
    nan = rng.normal(size=sp.nnz())
    nan[5] = np.nan
    assert float(fn(ca.DM(sp, nan))) == np.inf
    one = ca.SX.sym("a", 7, 4)
    g = ca.Function(
        "g", [one], [cond2_left_inverse_bound(one, LeftInverseBlocks((tuple(range(7)),), (tuple(range(4)),)))]
    )
    m = rng.normal(size=(7, 4))
    sv = np.linalg.svd(m, compute_uv=False)
    assert np.linalg.cond(m) * (1 - 1e-12) <= float(g(m)) <= np.linalg.norm(m) * np.linalg.norm(1 / sv) * (1 + 1e-12)
    m[:, 3] = m[:, 0] - 2 * m[:, 1]  # dependent columns: flagged (inf, or beyond the threshold by rounding)
    assert is_singular(float(g(m)), SCALAR, factor=2)


@pytest.mark.parametrize("lower", [False, True])
def test_block_bound_on_block_triangular_matrices(lower):
    """cond1_block_bound on a block triangular pattern (1 x 1 blocks around a 4 x 4 block, either
    pattern or its transpose, permuted), numbers from numpy: never below κ₁ (100 random
    matrices), exact for a single block, +inf for a singular block or a NaN entry."""
    rng = np.random.default_rng(163 + lower)
    n = 7
    pattern = np.triu(rng.uniform(size=(n, n)) < 0.5, 1) | np.eye(n, dtype=bool)
    pattern[2:6, 2:6] = True  # one 4 x 4 block
    pattern = pattern.T if lower else pattern
    perm_r, perm_c = rng.permutation(n), rng.permutation(n)
    pattern = pattern[np.ix_(perm_r, perm_c)]  # row i of the pattern is row perm_r[i] before
    sp = ca.sparsify(ca.DM(pattern.astype(float))).sparsity()
    assert sp.nnz() == pattern.sum() and sp.btf()[0] == 4  # 1 x 1, 1 x 1, 4 x 4, 1 x 1
    sym = ca.SX.sym("a", sp)
    fn = ca.Function("bound", [sym], [cond1_block_bound(sym)])

    def bound(values):
        return float(fn(ca.DM(sp, values)))

    for _ in range(100):
        v = rng.normal(size=sp.nnz())
        exact = np.linalg.cond(np.array(ca.DM(sp, v)), 1)
        assert exact * (1 - 1e-12) <= bound(v) < np.inf
    dense = np.array(ca.DM(sp, rng.normal(size=sp.nnz())))
    # two equal rows in the 4 x 4 block (rows and columns 2-5 before the permutations): singular
    block_rows = [int(np.flatnonzero(perm_r == k)[0]) for k in range(2, 6)]
    block_cols = [int(np.flatnonzero(perm_c == k)[0]) for k in range(2, 6)]
    dense[block_rows[1], block_cols] = dense[block_rows[0], block_cols]
    assert np.linalg.matrix_rank(dense) < n
    assert is_singular(float(fn(ca.project(ca.DM(dense), sp))), SCALAR, factor=2 * n)
    nan = rng.normal(size=sp.nnz())
    nan[3] = np.nan
    assert bound(nan) == np.inf
    one = ca.SX.sym("a", 3, 3)
    g = ca.Function("g", [one], [cond1_block_bound(one)])
    m = rng.normal(size=(3, 3))
    assert float(g(m)) == pytest.approx(np.linalg.cond(m, 1), rel=1e-12)


def test_pantograph_file_near_full_reach_agrees_with_the_module():
    """Along qx -> 2a (the arms stretched, theta1 -> theta2; q = (2a(1 - eps), 0, 0)), issue 23:
    the file (normal equations) and the hand-written module (eq 1-8) agree on solved for eps from
    1e-3 to 1e-10 -- the file's κ₂ of every closure equation's Jacobian is within 1x-4x of the
    module's κ₂(Φ_x) (both grow as eps^-1/2; measured 3.1x) and cond1 bounds it within 10x -- the
    file solves on to eps = 1e-12 (the module's batch loses eps = 1e-11 to its IK round trip, a
    check before conditioning) and neither solves the pose at full reach.  Before (κ of the normal
    equations' Φ_x, ~ its square: 5e10 at eps = 1e-8) the file was singular from eps = 1e-8 while
    the module solved."""
    file, _ = _pantographs()
    module = _module({"a": "20 mm", "b": "50 mm"})
    c, m = file.closure, module.closure
    a = 0.020
    eps = np.array([1e-3, 1e-7, 1e-9, 1e-10, 1e-11, 1e-12])
    q = np.column_stack([2 * a * (1 - eps), 0 * eps, 0 * eps])
    res, mod = cn.batch_forward_kinematics(file, q), cn.batch_forward_kinematics(module, q)
    assert res.ok.all() and mod.ok[eps >= 1e-10].all(), (res.counts(), mod.counts())
    for i in range(len(eps)):
        k_file = np.linalg.cond(np.asarray(c.cond_matrix(res.x[i], q[i], file.p)))
        if eps[i] >= 1e-10:
            k_mod = np.linalg.cond(np.asarray(m.phi_x(mod.x[i], q[i], module.p)))
            assert 1 <= k_file / k_mod <= 4, (eps[i], k_file, k_mod)
        assert k_file * (1 - 1e-12) <= res.checks["cond1"][i] <= 10 * k_file
        single = cn.forward_kinematics(file, q[i], NEWTON)
        assert single.ok and single.details["cond1_phi_x"] == pytest.approx(res.checks["cond1"][i], rel=1e-9)
        if eps[i] <= 1e-8:  # the square the normal equations carry: singular by the old measure
            assert np.linalg.cond(np.asarray(c.phi_x(res.x[i], q[i], file.p))) >= 1e10
    full = np.array([[2 * a, 0.0, 0.0]])
    assert not cn.batch_forward_kinematics(file, full).ok[0] and not cn.batch_forward_kinematics(module, full).ok[0]


def test_pantograph_file_workspace_near_full_reach_agrees_with_the_module():
    """Workspace membership judges a normal-equation closure on every closure equation's
    Jacobian too: near full reach along x (px = (1 + b/a) 2a (1 - eps)) the file and the module
    give the same verdict, binding indicator and margin (before: the file's points at eps = 1e-8
    and 1e-10 were `outside`, `singular`)."""
    from cpm_nlp.analysis.workspace import membership

    file, _ = _pantographs()
    module = _module({"a": "20 mm", "b": "50 mm"})
    a, b = 0.020, 0.050
    T = np.array([[(1 + b / a) * 2 * a * (1 - eps), 0.0, 0.0] for eps in (1e-3, 1e-8, 1e-10)])
    got, ref = membership(file, T), membership(module, T)
    assert list(got.status) == list(ref.status) == ["inside"] * 3
    assert list(got.binding) == list(ref.binding)
    np.testing.assert_allclose(got.margin, ref.margin, rtol=1e-9)


def test_reduced_steps_adapt_so_few_five_bar_poses_fall_back():
    """Issue 23 (item 4): on the five-bar at +-0.25 rad about home (5000 seeded poses) the
    3-step reduced Newton leaves more than 5 % unsettled; with the second try where the first
    did not converge (the reduced kernel again from the pose it reached), fewer than 5 % go to the full
    Newton (a count, not a timing).  Statuses stay the full path's, the poses the full path's
    and the IK's, and a pose out of reach is still not_converged, answered by the full path."""
    model = cn.build_model("five_bar")
    c = model.closure
    q = model.q_home + np.random.default_rng(0).uniform(-0.25, 0.25, (5000, c.nq))
    kern = reduced_fk_kernel(c, NEWTON)
    three = evaluate(kern.function, [q, model.x_home, *shared_values(kern, model, NEWTON.tolerance)])
    assert np.mean(three[kern.outputs.index("status")].ravel() != 0) > 0.05  # what fell back before
    res = cn.batch_forward_kinematics(model, q)
    assert np.mean(res.path_codes == 1) < 0.05, res.counts()
    ref = full_only(model, q)
    np.testing.assert_array_equal(res.status, ref.status)
    both = res.ok & ref.ok
    np.testing.assert_allclose(res.x[both], ref.x[both], rtol=0, atol=1e-12)
    ik = cn.batch_inverse_kinematics(model, res.x[res.ok][:500][:, list(c.task_index)])
    np.testing.assert_allclose(ik.q, q[res.ok][:500], rtol=0, atol=1e-12)
    far = cn.batch_forward_kinematics(model, model.q_home + np.array([[3.0, -3.0]]))
    single = cn.forward_kinematics(model, model.q_home + np.array([3.0, -3.0]), NEWTON)
    assert far.statuses == [single.status] and single.status is not Status.SOLVED and far.path(0) == "full"
