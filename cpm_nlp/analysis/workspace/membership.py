"""Membership of task points in the reachable workspace: the limited quantities, the
pose of each point and the test."""

from __future__ import annotations

import functools
import logging
from dataclasses import dataclass, field

import casadi as ca
import numpy as np

from ...core.batch import evaluate_points
from ...core.conditioning import closure_blocks, cond2_left_inverse_bound
from ...core.model import LoopClosure, Model
from ...core.pose_checks import SINGULAR_CONDITION  # cond(Φ_x) above it: singular, outside the workspace
from ...core.solver import SolverConfig, solvers_of
from .exclusion import prove_outside
from .point_ik import IPOPT_STARTS, ipopt_solve, newton, reduce_angles, start_set

log = logging.getLogger(__name__)

#: a limited quantity may exceed its bound by this much (SI) and still count as inside
CHECK_TOLERANCE = 1e-9
#: the statuses of a task point
INSIDE, OUTSIDE, UNDECIDED = "inside", "outside", "undecided"

# -- limited quantities --------------------------------------------------------------------------


@functools.cache
def limited_function(closure: LoopClosure) -> tuple[ca.Function, tuple[str, ...]]:
    """``limited(x, q, p) -> v``: actuators, pose coordinates, passive joints and
    branch indicators, the quantities that joint limits and the branch bound
    (built once per mechanism type), with their names."""
    x = ca.SX.sym("x", closure.nx)
    q = ca.SX.sym("q", closure.nq)
    p = ca.SX.sym("p", closure.np)
    rows = [q, x]
    names = list(closure.q_names) + list(closure.x_names)
    if closure.passive is not None:
        rows.append(closure.passive(x, q, p))
        names += closure.passive_names
    if closure.branch is not None:
        g = closure.branch(x, q, p)
        rows.append(g)
        names += [f"branch[{i}]" for i in range(g.size1())]
    fn = ca.Function("limited", [x, q, p], [ca.vertcat(*rows)], ["x", "q", "p"], ["v"])
    return fn, tuple(names)


def limit_bounds(model: Model) -> tuple[np.ndarray, np.ndarray]:
    """Lower and upper bounds of the limited quantities (±inf where unlimited;
    branch indicators must be >= 0)."""
    c = model.closure
    lo, hi = [], []
    for coord in list(c.q) + list(c.x) + list(c.passive_coords):
        lim = model.limit_of(coord)
        lo.append(-np.inf if lim is None else lim[0])
        hi.append(np.inf if lim is None else lim[1])
    n_branch = len(limited_function(c)[1]) - len(lo)
    return np.r_[lo, np.zeros(n_branch)], np.r_[hi, np.full(n_branch, np.inf)]


# -- membership ----------------------------------------------------------------------------------


@dataclass
class Membership:
    """Membership of N task points.

    Attributes
    ----------
    inside
        bool (N,);
    margin
        (N,) the worst signed margin (SI, of the quantity named in ``binding``; >=
        -CHECK_TOLERANCE inside; -inf where the mechanism does not assemble, is singular or the
        point is undecided); X (N, nx),
    Q
        (N, nq) the poses (NaN where none was found);
    status
        per point "inside", "outside" or "undecided" (no pose on the designated branch found;
        not inside).
    """

    inside: np.ndarray
    margin: np.ndarray
    binding: list[str]
    X: np.ndarray
    Q: np.ndarray
    status: list[str] = field(default_factory=list)

    def __post_init__(self) -> None:
        if not self.status:
            self.status = [INSIDE if v else OUTSIDE for v in np.asarray(self.inside, dtype=bool)]

    @property
    def count_outside(self) -> int:
        """Points not inside (outside or undecided)."""
        return int(np.count_nonzero(~self.inside))

    @property
    def count_undecided(self) -> int:
        return sum(1 for s in self.status if s == UNDECIDED)

    def worst(self) -> tuple[float, str]:
        k = int(np.argmin(self.margin))
        return float(self.margin[k]), self.binding[k]


#: cache keys of the membership functions
POSE_VALUES_KEY = ("workspace", "pose_values")
POSE_BOUND_KEY = ("workspace", "pose_bound")
TASK_POINT_KEY = ("workspace", "task_point")
TASK_POSE_KEY = ("workspace", "task_pose")
TASK_POINT_BOUND_KEY = ("workspace", "task_point_bound")


def _pose_values(c: LoopClosure, x, q, p) -> list:
    """Symbolic values the membership test needs at a pose: the limited
    quantities, the loop-closure residuals and the matrix whose condition number
    decides a singularity, `LoopClosure.cond_matrix` (dense, column-major;
    Φ_x, or for normal equations the Jacobian of every closure equation, whose
    rows then join the residuals), common subexpressions shared."""
    fn, _names = limited_function(c)
    res = c.phi(x, q, p) if c.loops is None else ca.vertcat(c.phi(x, q, p), c.loops(x, q, p))
    return ca.cse([fn(x, q, p), res, ca.vec(ca.densify(c.cond_matrix(x, q, p)))])


def pose_check_function(closure: LoopClosure) -> ca.Function:
    """``<name>_pose_values: (x, q, p) -> (v, phi, phi_x)`` (built once per mechanism type; see
    `_pose_values`: for normal equations ``phi`` also holds every closure equation and
    ``phi_x`` is their Jacobian)."""

    def build() -> ca.Function:
        c = closure
        x, q, p = ca.SX.sym("x", c.nx), ca.SX.sym("q", c.nq), ca.SX.sym("p", c.np)
        return ca.Function(
            f"{c.name}_pose_values", [x, q, p], _pose_values(c, x, q, p), ["x", "q", "p"], ["v", "phi", "phi_x"]
        )

    return solvers_of(closure).memo(POSE_VALUES_KEY, build)


def pose_bound_function(closure: LoopClosure) -> ca.Function:
    """``<name>_pose_bound: (x, q, p) -> cond_bound``: a certified upper bound of the 2-norm
    condition number of `LoopClosure.cond_matrix` at the pose, from a block left inverse
    (`cpm_nlp.core.conditioning.cond2_left_inverse_bound`: no inverse of the whole matrix,
    no SVD; +inf where it certifies nothing), built once per mechanism type."""

    def build() -> ca.Function:
        c = closure
        x, q, p = ca.SX.sym("x", c.nx), ca.SX.sym("q", c.nq), ca.SX.sym("p", c.np)
        bound = cond2_left_inverse_bound(c.cond_matrix(x, q, p), closure_blocks(c))
        return ca.Function(f"{c.name}_pose_bound", [x, q, p], [ca.cse(bound)], ["x", "q", "p"], ["cond_bound"])

    return solvers_of(closure).memo(POSE_BOUND_KEY, build)


def task_point_function(closure: LoopClosure) -> ca.Function:
    """``<name>_task_point: (t, p) -> (x, q, reach, v, phi)``: the closed-form IK at a task
    point and the limited quantities and residuals of `pose_check_function` there (one flat
    SX graph, built once per mechanism type; Φ_x and its conditioning are evaluated
    afterwards, only at the poses that need them, see `judge`)."""

    def build() -> ca.Function:
        c = closure
        t, p = ca.SX.sym("t", c.nq), ca.SX.sym("p", c.np)
        x, q, reach = c.ik(t, p)
        v, res, _phi_x = _pose_values(c, x, q, p)
        return ca.Function(
            f"{c.name}_task_point",
            [t, p],
            ca.cse([x, q, reach, v, res]),
            ["t", "p"],
            ["x", "q", "reach", "v", "phi"],
        )

    return solvers_of(closure).memo(TASK_POINT_KEY, build)


def task_point_bound_function(closure: LoopClosure) -> ca.Function:
    """``<name>_task_point_bound: (t, p) -> (x, q, reach, v, phi, cond_bound)``: `task_point_function`
    and `pose_bound_function` at its pose in one flat SX graph, their common subexpressions
    shared (for points that are all screened: about 8 % fewer instructions than the two)."""

    def build() -> ca.Function:
        c = closure
        t, p = ca.SX.sym("t", c.nq), ca.SX.sym("p", c.np)
        x, q, reach = c.ik(t, p)
        v, res, _phi_x = _pose_values(c, x, q, p)
        bound = cond2_left_inverse_bound(c.cond_matrix(x, q, p), closure_blocks(c))
        return ca.Function(
            f"{c.name}_task_point_bound",
            [t, p],
            ca.cse([x, q, reach, v, res, bound]),
            ["t", "p"],
            ["x", "q", "reach", "v", "phi", "cond_bound"],
        )

    return solvers_of(closure).memo(TASK_POINT_BOUND_KEY, build)


def task_pose_function(closure: LoopClosure) -> ca.Function:
    """``<name>_task_pose: (t, p) -> (x, q, reach)``: the closed-form IK alone (built once per
    mechanism type)."""

    def build() -> ca.Function:
        c = closure
        t, p = ca.SX.sym("t", c.nq), ca.SX.sym("p", c.np)
        return ca.Function(f"{c.name}_task_pose", [t, p], ca.cse(list(c.ik(t, p))), ["t", "p"], ["x", "q", "reach"])

    return solvers_of(closure).memo(TASK_POSE_KEY, build)


@dataclass
class _Judged:
    """Membership values of M poses: converged (Φ within the solver tolerance), on the
    designated branch, the worst margin and its quantity, singular."""

    converged: np.ndarray
    on_branch: np.ndarray
    margin: np.ndarray
    binding: np.ndarray
    X: np.ndarray
    Q: np.ndarray

    @property
    def witness(self) -> np.ndarray:
        return self.converged & self.on_branch & (self.margin >= -self.tolerance)

    @property
    def evidence(self) -> np.ndarray:
        """A pose on the designated branch that violates a limit or is singular."""
        return self.converged & self.on_branch & ~(self.margin >= -self.tolerance)

    tolerance: float = CHECK_TOLERANCE


def judge(
    model: Model,
    X: np.ndarray,
    Q: np.ndarray,
    config: SolverConfig,
    tolerance: float = CHECK_TOLERANCE,
    values=None,
    detail: bool = True,
) -> _Judged:
    """Judge M poses (X, Q): residual, branch, limits (to ``tolerance``) and Φ_x.
    ``values``: (V, R) already evaluated at them, or (V, R, B) with the bounds of
    `pose_bound_function` too (the screen is then `singular`); else one mapped call of
    `pose_check_function`, whose Φ_x `condition_numbers` judges.

    The singularity screen runs on every converged pose, or with ``detail``
    False only on those within every limit (the others are outside either way: the
    verdicts are the same, but such a pose reports its worst limit, never "singular")."""
    c = model.closure
    M = X.shape[0]
    _fn, names = limited_function(c)
    lo, hi = limit_bounds(model)
    finite = np.all(np.isfinite(X), axis=1) & np.all(np.isfinite(Q), axis=1)
    B = PX = None
    if values is not None:
        V, R, *rest = (np.asarray(v, dtype=float) for v in values)
        B = rest[0].reshape(-1) if rest else None
    else:  # Φ_x comes with the values here: it is judged directly (`condition_numbers`)
        fn = pose_check_function(c)
        V = np.full((M, len(names)), np.nan)
        R = np.full((M, fn.nnz_out(1)), np.nan)
        PX = np.full((M, fn.nnz_out(2)), np.nan)
        if np.any(finite):
            V[finite], R[finite], PX[finite] = evaluate_points(c, POSE_VALUES_KEY, fn, [X[finite], Q[finite]], model.p)
    with np.errstate(invalid="ignore"):
        resid = np.where(finite, np.max(np.abs(R), axis=1), np.inf)
        converged = finite & (resid <= config.tolerance)  # NaN: False
        m = np.minimum(V - lo, hi - V)
    m = np.where(np.isnan(m), np.inf, m)
    branch_rows = _branch_rows(names)
    with np.errstate(invalid="ignore"):
        on_branch = np.all(m[:, branch_rows] >= -tolerance, axis=1) if branch_rows.size else np.ones(M, dtype=bool)
        xd = X[:, c.dep_index]
        on_branch &= np.all(xd >= model.x_lower[c.dep_index] - tolerance, axis=1)
        on_branch &= np.all(xd <= model.x_upper[c.dep_index] + tolerance, axis=1)
    worst = np.argmin(m, axis=1) if M else np.zeros(0, dtype=int)
    w = m[np.arange(M), worst]
    margin = np.where(converged, np.where(np.isfinite(w), w, np.inf), -np.inf)
    # the binding quantity's position in `names`; -1 "no assembly", -2 none (w not finite), -3 "singular"
    code = np.where(converged, np.where(np.isfinite(w), worst, -2), -1)
    idx = np.flatnonzero(converged if detail else converged & (margin >= -tolerance))
    if idx.size:  # forward singularities: Φ_x rank deficient
        if PX is not None:
            sing = ~(condition_numbers(PX[idx].reshape(idx.size, c.nx, -1)) < SINGULAR_CONDITION)  # transposed
        else:
            sing = singular(model, X[idx], Q[idx], None if B is None else B[idx])
        margin[idx[sing]], code[idx[sing]] = -np.inf, -3
    binding = np.asarray(list(names) + ["singular", "", "no assembly"], dtype=object)[code]
    return _Judged(converged, on_branch, margin, binding, X, Q, tolerance)


def singular(model: Model, X: np.ndarray, Q: np.ndarray, bound: np.ndarray | None = None) -> np.ndarray:
    """Whether each pose (X, Q) is singular: cond(Φ_x) (`LoopClosure.cond_matrix`) at or above
    `SINGULAR_CONDITION`.  The certified bound of `pose_bound_function` (``bound``: already
    evaluated at the poses) decides where it is below half the threshold (κ₂ is then below
    it); `condition_numbers` of Φ_x decides the rest (the same verdicts as
    `condition_numbers` everywhere)."""
    c = model.closure
    if bound is None:
        (B,) = evaluate_points(c, POSE_BOUND_KEY, pose_bound_function(c), [X, Q], model.p)
    else:
        B = np.asarray(bound, dtype=float)
    out = np.zeros(X.shape[0], dtype=bool)
    rest = np.flatnonzero(~(B.reshape(-1) < 0.5 * SINGULAR_CONDITION))
    if rest.size:
        PX = evaluate_points(c, POSE_VALUES_KEY, pose_check_function(c), [X[rest], Q[rest]], model.p)[2]
        out[rest] = ~(condition_numbers(PX.reshape(rest.size, c.nx, -1)) < SINGULAR_CONDITION)  # transposed
    return out


@functools.cache
def _branch_rows(names: tuple[str, ...]) -> np.ndarray:
    """Positions of the branch indicators among the limited quantities ``names``."""
    return np.flatnonzero([n.startswith("branch[") for n in names])


@dataclass
class _Points:
    """Verdicts of N task points."""

    status: np.ndarray  # INSIDE, OUTSIDE, UNDECIDED
    margin: np.ndarray
    binding: np.ndarray
    X: np.ndarray
    Q: np.ndarray


def _closed_form_points(
    model: Model, T: np.ndarray, config: SolverConfig, tolerance: float, detail: bool = True
) -> _Points:
    """Every point at once through the closed-form IK: decided inside or outside (a
    negative reach margin proves that the mechanism does not assemble there)."""
    c = model.closure
    if detail:  # every pose that assembles is screened: the bound with the rest, in one graph
        X, Q, reach, V, R, B = evaluate_points(c, TASK_POINT_BOUND_KEY, task_point_bound_function(c), [T], model.p)
        extra = [B]
    else:
        X, Q, reach, V, R = evaluate_points(c, TASK_POINT_KEY, task_point_function(c), [T], model.p)
        extra = []
    ok = reach.ravel() >= 0
    V, R = np.where(ok[:, None], V, np.nan), np.where(ok[:, None], R, np.nan)
    X, Q = np.where(ok[:, None], X, np.nan), np.where(ok[:, None], Q, np.nan)
    j = judge(model, X, Q, config, tolerance, (V, R, *extra), detail)
    # on the closed form's branch by construction; the branch rows still count as limits
    status = np.where(j.converged & (j.margin >= -tolerance), INSIDE, OUTSIDE).astype(object)
    return _Points(status, j.margin, j.binding, X, Q)


def _assemble(model: Model, T: np.ndarray, Y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    c = model.closure
    nd = len(c.dep_index)
    X = np.empty((T.shape[0], c.nx))
    X[:, c.task_index] = T
    X[:, c.dep_index] = Y[:, :nd]
    return X, Y[:, nd:]


def _take(points: _Points, model, T, k: np.ndarray, Y: np.ndarray, j: _Judged, index: np.ndarray) -> None:
    """Record the verdict of points ``k`` from judged poses ``index`` of ``j``."""
    X, Q = _assemble(model, T[k], Y[index])
    points.X[k], points.Q[k] = X, Q
    points.margin[k], points.binding[k] = j.margin[index], j.binding[index]


def _decide(points: _Points, model, T, todo: np.ndarray, Y: np.ndarray, j: _Judged, per: int) -> None:
    """Verdicts from ``per`` judged starts of each point of ``todo`` (rows point-major):
    the first witness in start order makes a point inside; else the first pose on the
    designated branch outside a limit makes it outside (the branch designates one pose)."""
    wit = j.witness.reshape(todo.size, per)
    evi = j.evidence.reshape(todo.size, per)
    base = np.arange(todo.size) * per
    has_w = wit.any(axis=1)
    if has_w.any():
        rows = base[has_w] + np.argmax(wit[has_w], axis=1)
        points.status[todo[has_w]] = INSIDE
        _take(points, model, T, todo[has_w], Y, j, rows)
    has_e = ~has_w & evi.any(axis=1)
    if has_e.any():
        rows = base[has_e] + np.argmax(evi[has_e], axis=1)
        points.status[todo[has_e]] = OUTSIDE
        _take(points, model, T, todo[has_e], Y, j, rows)


def _solved_points(model: Model, T: np.ndarray, config: SolverConfig, tolerance: float, detail: bool = True) -> _Points:
    """Every point from its own start set (`point_ik`), never from another point."""
    c = model.closure
    N = T.shape[0]
    starts = start_set(model, T)
    points = _Points(
        np.full(N, UNDECIDED, dtype=object),
        np.full(N, -np.inf),
        np.full(N, "undecided", dtype=object),
        np.full((N, c.nx), np.nan),
        np.full((N, c.nq), np.nan),
    )
    for first, last in ((0, 2), (2, starts.shape[1])):  # Newton rounds
        todo = np.flatnonzero(points.status == UNDECIDED)
        if todo.size and first > 0:  # before more starts: a proof that no pose passes
            fn, _names = limited_function(c)
            lo, hi = limit_bounds(model)
            proven = todo[prove_outside(model, T[todo], tolerance, fn, lo, hi)]
            points.status[proven] = OUTSIDE
            points.binding[proven] = "no pose within the limits (interval proof)"
            todo = np.flatnonzero(points.status == UNDECIDED)
        if not todo.size:
            break
        per = last - first
        Y0 = starts[todo, first:last].reshape(-1, starts.shape[2])
        Tr = np.repeat(T[todo], per, axis=0)
        Y, _norm = newton(model, Y0, Tr, config.tolerance)
        Y = reduce_angles(model, Y)
        X, Q = _assemble(model, Tr, Y)
        _decide(points, model, T, todo, Y, judge(model, X, Q, config, tolerance, detail=detail), per)
    for s in range(min(IPOPT_STARTS, starts.shape[1])):  # IPOPT with the strokes as bounds
        todo = np.flatnonzero(points.status == UNDECIDED)
        if not todo.size:
            break
        Y = np.full((todo.size, starts.shape[2]), np.nan)
        for i, k in enumerate(todo):
            y, conv = ipopt_solve(model, T[k], starts[k, s], config)
            if conv:
                Y[i] = y
        Y = reduce_angles(model, Y)
        X, Q = _assemble(model, T[todo], Y)
        _decide(points, model, T, todo, Y, judge(model, X, Q, config, tolerance, detail=detail), 1)
    und = points.status == UNDECIDED
    points.binding[und] = f"undecided: no pose on the designated branch from {starts.shape[1]} starts"
    return points


def _points(model: Model, T, solver: SolverConfig | None, tolerance: float, detail: bool = True) -> _Points:
    c = model.closure
    config = solver or SolverConfig()
    T = np.atleast_2d(np.asarray(T, dtype=float))
    if T.shape[0] == 0:
        e = np.zeros(0, dtype=object)
        return _Points(e, np.zeros(0), e.copy(), np.zeros((0, c.nx)), np.zeros((0, c.nq)))
    if c.ik is not None:
        return _closed_form_points(model, T, config, tolerance, detail)
    return _solved_points(model, T, config, tolerance, detail)


def poses(model: Model, T: np.ndarray, solver: SolverConfig | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Poses (X, Q) for task points T (N, nq) and whether each assembles on the
    designated branch (inside or outside the limits).

    With a closed-form IK all points are evaluated at once (one mapped CasADi call of the
    IK alone: a point assembles where its reach margin is not negative); otherwise each
    point's IK is solved from its own start set (`point_ik`; the binding quantities of the
    membership test are not needed, see `judge`'s ``detail``).
    """
    c = model.closure
    T = np.atleast_2d(np.asarray(T, dtype=float))
    if c.ik is not None and T.shape[0]:
        X, Q, reach = evaluate_points(c, TASK_POSE_KEY, task_pose_function(c), [T], model.p)
        ok = reach.ravel() >= 0
        X, Q = np.where(ok[:, None], X, np.nan), np.where(ok[:, None], Q, np.nan)
    else:
        got = _points(model, T, solver, CHECK_TOLERANCE, detail=False)
        X, Q = got.X, got.Q
    return X, Q, np.all(np.isfinite(X), axis=1) & np.all(np.isfinite(Q), axis=1)


def condition_numbers(PX: np.ndarray) -> np.ndarray:
    """2-norm condition numbers of N square matrices (N, n, n), computed by SVD only
    where they may reach `SINGULAR_CONDITION`; elsewhere the returned value is the
    upper bound κ₂ ≤ ‖A‖_F ‖A⁻¹‖_F (σ_max ≤ ‖A‖_F and 1/σ_min = ‖A⁻¹‖₂ ≤ ‖A⁻¹‖_F; at
    most n κ₂) from one batched inverse (about 40 % of the cost of the SVD), below half
    the threshold, so the verdict is the same (there the computed inverse is accurate to
    κ₂ ε < 1e-6, far inside the factor 2 kept).  A batch with an exactly singular LU
    factor (no inverse) goes to the SVD whole.  inf for a matrix with a NaN or infinite
    entry.  Rectangular matrices (the transposed Jacobian of every closure equation of
    normal equations): by SVD."""
    finite = np.all(np.isfinite(PX), axis=(1, 2))
    out = np.full(PX.shape[0], np.inf)
    if PX.shape[-1] == PX.shape[-2] and np.any(finite):
        A = PX[finite]
        try:
            with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
                inv = np.linalg.inv(A)
                out[finite] = np.sqrt(np.sum(A * A, axis=(1, 2))) * np.sqrt(np.sum(inv * inv, axis=(1, 2)))
        except np.linalg.LinAlgError:  # an exactly singular factor: every matrix by SVD below
            pass
    rest = ~(out < 0.5 * SINGULAR_CONDITION) & finite  # NaN included
    if np.any(rest):
        out[rest] = np.linalg.cond(PX[rest])
    return out


def membership(
    model: Model, T, solver: SolverConfig | None = None, tolerance: float = CHECK_TOLERANCE, *, detail: bool = True
) -> Membership:
    """Which task points T (N, nq) lie in the reachable workspace: the pose
    assembles on the designated branch, is not singular, and every limited
    quantity is within its limits (to ``tolerance``).

    Each point is decided on its own (never from another point's solution): inside
    (a pose that passes), outside (the closed form's reach margin is negative, or
    the pose on the designated branch violates a limit or is singular) or undecided
    (no pose on the designated branch from any start; ``inside`` is False there).

    ``detail`` False: only the verdicts are needed; a point outside a limit is not screened
    for a singularity (the same verdicts; its margin and binding are then its worst limit's,
    never "singular")."""
    got = _points(model, T, solver, tolerance, detail)
    inside = got.status == INSIDE
    return Membership(inside, got.margin, got.binding.tolist(), got.X, got.Q, got.status.tolist())
