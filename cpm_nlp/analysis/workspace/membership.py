"""Membership of task points in the reachable workspace: the limited quantities, the
pose of each point and the test."""

from __future__ import annotations

import functools
import logging
from dataclasses import dataclass

import casadi as ca
import numpy as np

from ...core.batch import evaluate_points
from ...core.kernels import SINGULAR_CONDITION  # cond(Φ_x) above it: singular, outside the workspace
from ...core.model import LoopClosure, Model
from ...core.solver import SolverConfig

log = logging.getLogger(__name__)

#: a limited quantity may exceed its bound by this much (SI) and still count as inside
CHECK_TOLERANCE = 1e-9

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

    inside: bool (N,); margin: (N,) the worst signed margin (SI, of the
    quantity named in ``binding``; >= -CHECK_TOLERANCE inside); X (N, nx),
    Q (N, nq): the poses (NaN where the mechanism does not assemble).
    """

    inside: np.ndarray
    margin: np.ndarray
    binding: list[str]
    X: np.ndarray
    Q: np.ndarray

    @property
    def count_outside(self) -> int:
        return int(np.count_nonzero(~self.inside))

    def worst(self) -> tuple[float, str]:
        k = int(np.argmin(self.margin))
        return float(self.margin[k]), self.binding[k]


#: cache keys of the membership functions
POSE_VALUES_KEY = ("workspace", "pose_values")
TASK_POINT_KEY = ("workspace", "task_point")


def _pose_values(c: LoopClosure, x, q, p) -> list:
    """Symbolic values the membership test needs at a pose: the limited
    quantities, the loop-closure residuals and Φ_x (dense, column-major),
    common subexpressions shared."""
    fn, _names = limited_function(c)
    return ca.cse([fn(x, q, p), c.phi(x, q, p), ca.vec(ca.densify(c.phi_x(x, q, p)))])


def pose_check_function(closure: LoopClosure) -> ca.Function:
    """``<name>_pose_values: (x, q, p) -> (v, phi, phi_x)`` (built once per mechanism type)."""

    def build() -> ca.Function:
        c = closure
        x, q, p = ca.SX.sym("x", c.nx), ca.SX.sym("q", c.nq), ca.SX.sym("p", c.np)
        return ca.Function(
            f"{c.name}_pose_values", [x, q, p], _pose_values(c, x, q, p), ["x", "q", "p"], ["v", "phi", "phi_x"]
        )

    return closure.solvers.memo(POSE_VALUES_KEY, build)


def task_point_function(closure: LoopClosure) -> ca.Function:
    """``<name>_task_point: (t, p) -> (x, q, reach, v, phi, phi_x)``: the closed-form
    IK at a task point and the values of :func:`pose_check_function` there (one
    flat SX graph, built once per mechanism type)."""

    def build() -> ca.Function:
        c = closure
        t, p = ca.SX.sym("t", c.nq), ca.SX.sym("p", c.np)
        x, q, reach = c.ik(t, p)
        return ca.Function(
            f"{c.name}_task_point",
            [t, p],
            ca.cse([x, q, reach, *_pose_values(c, x, q, p)]),
            ["t", "p"],
            ["x", "q", "reach", "v", "phi", "phi_x"],
        )

    return closure.solvers.memo(TASK_POINT_KEY, build)


@dataclass
class _PoseValues:
    """Poses of N task points and the membership values there (NaN where not assembled)."""

    X: np.ndarray
    Q: np.ndarray
    ok: np.ndarray
    V: np.ndarray | None = None  # (N, n limited)
    PX: np.ndarray | None = None  # (N, nx, nx), transposed Φ_x (same singular values)


def _pose_values_at(model: Model, T: np.ndarray, solver: SolverConfig | None) -> _PoseValues:
    c = model.closure
    config = solver or SolverConfig()
    T = np.atleast_2d(np.asarray(T, dtype=float))
    N = T.shape[0]
    nv = len(limited_function(c)[1])
    if N == 0:
        return _PoseValues(np.zeros((0, c.nx)), np.zeros((0, c.nq)), np.zeros(0, dtype=bool))
    if c.ik is not None:
        X, Q, reach, V, R, PX = evaluate_points(c, TASK_POINT_KEY, task_point_function(c), [T], model.p)
        ok = reach.ravel() >= 0
    else:
        X, Q, ok = _solve_poses(model, T, config)
        V, R, PX = (np.full((N, k), np.nan) for k in (nv, c.nx, c.nx * c.nx))
        good = ok & np.all(np.isfinite(X), axis=1) & np.all(np.isfinite(Q), axis=1)
        if np.any(good):
            V[good], R[good], PX[good] = evaluate_points(
                c, POSE_VALUES_KEY, pose_check_function(c), [X[good], Q[good]], model.p
            )
    good = ok & np.all(np.isfinite(X), axis=1) & np.all(np.isfinite(Q), axis=1)
    with np.errstate(invalid="ignore"):
        resid = np.where(good, np.max(np.abs(R), axis=1), np.inf)
    ok = good & (resid <= config.tolerance)
    return _PoseValues(X, Q, ok, V, PX.reshape(N, c.nx, c.nx))


def _solve_poses(model: Model, T: np.ndarray, config: SolverConfig) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The IK solved point by point (no closed form), each from the previous
    point's solution (or home), with the configured solver and its bounds."""
    c = model.closure
    N = T.shape[0]
    built = c.ik_solver(config)
    nd = len(c.dep_index)
    lower = np.r_[model.x_lower[c.dep_index], np.full(c.nq, -np.inf)]
    upper = np.r_[model.x_upper[c.dep_index], np.full(c.nq, np.inf)]
    home = np.r_[model.x_home[c.dep_index], model.q_home]
    X, Q = np.full((N, c.nx), np.nan), np.full((N, c.nq), np.nan)
    ok = np.zeros(N, dtype=bool)
    y0 = home
    for k in range(N):
        y, conv, *_ = built.solve(y0, np.r_[T[k], model.p], lower, upper)
        if not conv:
            y, conv, *_ = built.solve(home, np.r_[T[k], model.p], lower, upper)
        if conv:
            X[k], Q[k], ok[k] = c.assemble_x(T[k], y[:nd]), y[nd:], True
            y0 = y
    return X, Q, ok


def poses(model: Model, T: np.ndarray, solver: SolverConfig | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Poses (X, Q) for task points T (N, nq) and whether each assembles.

    With a closed-form IK all points are evaluated at once (one mapped CasADi
    call); otherwise the IK is solved point by point, each from the previous
    point's solution (or home), with the configured solver and its bounds.
    """
    got = _pose_values_at(model, T, solver)
    return got.X, got.Q, got.ok


def condition_numbers(PX: np.ndarray) -> np.ndarray:
    """2-norm condition numbers of N square matrices (N, n, n), computed by SVD only
    where they may reach :data:`SINGULAR_CONDITION`: κ₂ ≤ ‖A‖_F^n / |det A| (since
    σ_max ≤ ‖A‖_F and σ_min ≥ |det A| / σ_max^(n-1)); elsewhere the returned value
    is that bound (below the threshold, so the verdict is the same); inf for a
    matrix with a NaN or infinite entry."""
    n = PX.shape[-1]
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        bound = np.sqrt(np.sum(PX * PX, axis=(1, 2))) ** n / np.abs(np.linalg.det(PX))
    flagged = ~(bound < 0.5 * SINGULAR_CONDITION)  # NaN and inf included
    finite = np.all(np.isfinite(PX), axis=(1, 2))
    bound[flagged & ~finite] = np.inf
    if np.any(flagged & finite):
        bound[flagged & finite] = np.linalg.cond(PX[flagged & finite])
    return bound


def membership(model: Model, T, solver: SolverConfig | None = None, tolerance: float = CHECK_TOLERANCE) -> Membership:
    """Which task points T (N, nq) lie in the reachable workspace: the pose
    assembles on the designated branch, is not singular, and every limited
    quantity is within its limits (to ``tolerance``)."""
    c = model.closure
    T = np.atleast_2d(np.asarray(T, dtype=float))
    N = T.shape[0]
    got = _pose_values_at(model, T, solver)
    margin = np.full(N, -np.inf)
    binding = np.full(N, "no assembly", dtype=object)
    _fn, names = limited_function(c)
    lo, hi = limit_bounds(model)
    idx = np.flatnonzero(got.ok)
    if idx.size:
        V = got.V[idx].T
        with np.errstate(invalid="ignore"):
            m = np.minimum(V - lo[:, None], hi[:, None] - V)
        m = np.where(np.isnan(m), np.inf, m)
        worst = np.argmin(m, axis=0)
        w = m[worst, np.arange(idx.size)]
        binding[idx] = np.where(np.isfinite(w), np.asarray(names, dtype=object)[worst], "")
        margin[idx] = np.where(np.isfinite(w), w, np.inf)
        # forward singularities: Φ_x rank deficient
        sing = ~(condition_numbers(got.PX[idx]) < SINGULAR_CONDITION)
        margin[idx[sing]], binding[idx[sing]] = -np.inf, "singular"
    inside = margin >= -tolerance
    return Membership(inside, margin, binding.tolist(), got.X, got.Q)
