"""Reachable workspace of any mechanism given by its loop closures and joint limits.

A point t of the task coordinates belongs to the workspace when the mechanism
assembles there on the branch the model designates and every actuator, pose
coordinate and passive joint with declared limits lies within them:

* :func:`membership` -- that test for many points at once (the closed-form
  IK of the model when it has one, with the limited quantities, residuals
  and Φ_x of all points in one mapped CasADi call; else the IK solved point
  by point);
* :func:`probe_region` and :func:`sample_workspace` -- a box around the home
  pose found by probing along the task axes, and a seeded point cloud;
* :func:`inscribed_cuboid` -- the largest axis-aligned box in the task
  coordinates inside the workspace, by IPOPT, seeded multi-start, verified
  afterwards on a dense sample of its faces, edges and interior.

Nothing here knows a particular mechanism.  The cuboid NLP is a discretised
semi-infinite program: the box [c + D∘u, c + D∘(u + w)] (normalised by the
region's centre c and size D) carries N sample points s_j on its surface
(a grid of n per edge, so corners, edge and face centres are among them);
each sample has its own pose unknowns y_j = (dependent pose coordinates,
actuators) with Φ(t_j, y_j) = 0 and the limits as bounds on the limited
quantities; the objective is -Σ log w_i (the log of the volume).  With a
closed-form IK the same NLP is solved without pose unknowns, the limited
quantities being functions of the sample points through the IK, on working
sets of its rows (:mod:`cpm_nlp.analysis.cuboid_ik`; ``formulation`` chooses).  The dense
check afterwards finds any point of the box that is outside (between the
samples, or a hole inside); its worst points become extra samples and the
NLP is solved again (an exchange method), a few rounds at most.  If points
are still outside after that, the box is shrunk about its centre until the
check passes, and the result says by how much.

The image of the actuator-stroke box under the forward kinematics (the
"hexahedron" of prc3-li-2018.md, eq 27, Fig. 5) is a second view of the same
set when the strokes are the binding limits:

* :func:`reachable_workspace` -- FK on a grid over the box (faces included),
  the vertices, the axis-aligned bounding box, the volume, and how far the
  kinematics strays from its linearization at home over the workspace;
* :func:`joint_box` -- the actuator strokes of a model.
"""

from __future__ import annotations

import functools
import itertools
import logging
import time
from collections.abc import Sequence
from dataclasses import dataclass, field

import casadi as ca
import numpy as np

from ..core.batch import evaluate_points
from ..core.errors import InputError, suggest
from ..core.kernels import SINGULAR_CONDITION  # cond(Φ_x) above it: singular, outside the workspace
from ..core.kinematics import PoseSolution, forward_kinematics
from ..core.model import LoopClosure, Model
from ..core.multistart import AGREEMENT, best_and_agreement
from ..core.options import Option
from ..core.progress import track
from ..core.result import Status, worst_status
from ..core.solver import SolverConfig, run_nlp
from .cuboid_ik import ClosedFormCuboid
from .requirements import full_factorial

log = logging.getLogger(__name__)

#: a limited quantity may exceed its bound by this much (SI) and still count as inside
CHECK_TOLERANCE = 1e-9
#: the NLP keeps its limits this much (SI) inside the declared ones, so that IPOPT's
#: relaxed bounds still pass the check
NLP_MARGIN = 5e-9
#: defaults for the cuboid NLP under the user's solver options
CUBOID_IPOPT = {
    "ipopt.tol": 1e-10,
    "ipopt.max_iter": 1000,
    "ipopt.acceptable_tol": 1e-8,
    "ipopt.bound_relax_factor": 1e-10,
}
#: and under those for the closed-form (working-set) NLP: with its few unknowns and rows
#: the adaptive barrier update with LOQO's rule (no extra linear solves per iteration)
#: takes ~20 % fewer iterations than the monotone one and ~10 % less time (same tolerances)
CLOSED_FORM_IPOPT = {"ipopt.mu_strategy": "adaptive", "ipopt.mu_oracle": "loqo"}
#: extra sample slots for the exchange rounds
EXTRA_SLOTS = 12
#: worst outside points added per exchange round
ADDED_PER_ROUND = 4


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


# -- sampling ------------------------------------------------------------------------------------


#: bisection steps of :func:`probe_region` along each direction
PROBE_BISECTIONS = 40
#: bisection levels decided per membership call when membership is one vectorised call
#: (closed-form IK): the 2^k - 1 midpoints of the next k levels are tested at once
PROBE_LEVELS = 4


def probe_region(  # noqa: C901 - one loop of probe rounds with its stop rules
    model: Model, solver: SolverConfig | None = None, centre=None, factor: float = 2.0
) -> tuple[np.ndarray, np.ndarray] | None:
    """A box around ``centre`` (default: the home pose) in the task coordinates:
    the distance to the workspace boundary along each task axis (both ways,
    by doubling and bisection), times ``factor``.  None if the centre itself
    is outside.

    With a closed-form IK the steps of the doubling are tested in one call and
    the bisection decides :data:`PROBE_LEVELS` levels per call (all midpoints
    those levels could visit); the result is the same as one level per call.
    """
    t0 = model.task_of(model.x_home) if centre is None else np.asarray(centre, dtype=float)
    d = t0.size
    if not membership(model, t0[None, :], solver).inside[0]:
        return None
    levels = PROBE_LEVELS if model.closure.ik is not None else 1
    dirs = np.vstack([np.eye(d), -np.eye(d)])
    cols = np.arange(2 * d)
    inside_step = np.zeros(2 * d)
    outside_step = np.full(2 * d, np.nan)
    steps = [1e-9]
    while steps[-1] * 2 < 1e4:
        steps.append(steps[-1] * 2)
    block = len(steps) if levels > 1 else 1
    for first in range(0, len(steps), block):  # doubling
        todo = np.flatnonzero(np.isnan(outside_step))
        if not todo.size:
            break
        s = np.array(steps[first : first + block])
        pts = t0 + s[None, :, None] * dirs[todo][:, None, :]
        inside = membership(model, pts.reshape(-1, d), solver).inside.reshape(todo.size, s.size)
        for row, k in enumerate(todo):
            out = np.flatnonzero(~inside[row])
            if out.size:
                outside_step[k] = s[out[0]]
                if out[0] > 0:
                    inside_step[k] = s[out[0] - 1]
            else:
                inside_step[k] = s[-1]
    outside_step = np.where(np.isnan(outside_step), 1e4, outside_step)
    done = 0
    while done < PROBE_BISECTIONS:  # bisection, k levels per call
        k = min(levels, PROBE_BISECTIONS - done)
        nodes = 2**k - 1  # a binary tree: node i has children 2i + 1 (outside) and 2i + 2 (inside)
        low, high, mid = (np.empty((nodes, 2 * d)) for _ in range(3))
        low[0], high[0] = inside_step, outside_step
        for i in range(nodes):
            mid[i] = 0.5 * (low[i] + high[i])
            if 2 * i + 2 < nodes:
                low[2 * i + 1], high[2 * i + 1] = low[i], mid[i]
                low[2 * i + 2], high[2 * i + 2] = mid[i], high[i]
        pts = t0 + mid[:, :, None] * dirs[None, :, :]
        inside = membership(model, pts.reshape(-1, d), solver).inside.reshape(nodes, 2 * d)
        node = np.zeros(2 * d, dtype=int)
        for _ in range(k):
            ins, m = inside[node, cols], mid[node, cols]
            inside_step = np.where(ins, m, inside_step)
            outside_step = np.where(ins, outside_step, m)
            node = np.where(ins, 2 * node + 2, 2 * node + 1)
        done += k
    plus, minus = inside_step[:d], inside_step[d:]
    span = np.maximum(plus + minus, 1e-12)
    return t0 - factor * np.maximum(minus, 0.25 * span), t0 + factor * np.maximum(plus, 0.25 * span)


def sample_workspace(
    model: Model,
    count: int,
    seed: int = 0,
    region: tuple[np.ndarray, np.ndarray] | None = None,
    solver: SolverConfig | None = None,
) -> tuple[np.ndarray, tuple[np.ndarray, np.ndarray] | None, float]:
    """A seeded point cloud of the workspace: ``count`` points drawn uniformly
    in ``region`` (default: :func:`probe_region`), those inside kept.  Returns
    (points inside (M, nq), the region, the Monte-Carlo volume estimate)."""
    if region is None:
        region = probe_region(model, solver)
        if region is None:
            return np.zeros((0, model.closure.nq)), None, 0.0
    lo, hi = (np.asarray(v, dtype=float) for v in region)
    rng = np.random.default_rng(seed)
    T = lo + (hi - lo) * rng.random((count, lo.size))
    inside = membership(model, T, solver).inside
    volume = float(np.prod(hi - lo)) * np.count_nonzero(inside) / max(count, 1)
    return T[inside], (lo, hi), volume


# -- sample points of a box ----------------------------------------------------------------------


@functools.lru_cache(maxsize=32)
def _grid(d: int, n: int, interior: int | None) -> np.ndarray:
    """:func:`surface_grid` (interior None) or :func:`check_grid`, computed once (read-only)."""
    g = np.linspace(0.0, 1.0, n)
    pts = np.array(list(itertools.product(g, repeat=d)))
    pts = pts[np.any((pts == 0.0) | (pts == 1.0), axis=1)]
    if interior is not None:
        inner = np.linspace(0.0, 1.0, interior + 2)[1:-1]
        pts = np.vstack([pts, np.array(list(itertools.product(inner, repeat=d)))])
    pts.flags.writeable = False
    return pts


def surface_grid(d: int, n: int) -> np.ndarray:
    """Points of the unit box [0, 1]^d on its boundary, from a grid of n per edge
    (corners, edges and faces; (n^d - (n-2)^d) points)."""
    return _grid(d, n, None).copy()


#: the input that sets the density of the membership check of a box
CHECK_OPTION = Option(
    "check_per_edge", "int", "points per box edge of the membership check afterwards", default=17, lower=2, upper=65
)


def check_grid(d: int, per_edge: int, interior: int = 5) -> np.ndarray:
    """Dense check sample of the unit box: its surface on a grid of ``per_edge``
    points per edge, plus the interior points of a grid of ``interior + 2``."""
    return _grid(d, per_edge, interior).copy()


# -- the cuboid NLP ------------------------------------------------------------------------------


class CuboidNLP:
    """IPOPT on the discretised cuboid problem of one mechanism type, for N
    sample points and one pattern of active (bounded) limited quantities;
    built once and reused for every model, start and exchange round."""

    def __init__(self, closure: LoopClosure, n_samples: int, active: tuple[bool, ...], config: SolverConfig):
        c = closure
        d, nd = c.nq, len(c.dep_index)
        self.d, self.ny, self.N = d, nd + c.nq, n_samples
        self.rows = np.flatnonzero(active)
        fn, _names = limited_function(c)
        y = ca.SX.sym("y", self.ny)
        t = ca.SX.sym("t", d)
        p = ca.SX.sym("p", c.np)
        x = c.assemble_x(t, y[:nd])
        q = y[nd:]
        v = fn(x, q, p)
        per = ca.Function(
            "cuboid_sample",
            [y, t, p],
            [ca.vertcat(c.phi(x, q, p), v[list(self.rows)] if self.rows.size else ca.SX(0, 1))],
            ["y", "t", "p"],
            ["g"],
        )
        self.ng = c.nx + self.rows.size
        U = ca.MX.sym("u", d)
        W = ca.MX.sym("w", d)
        Y = ca.MX.sym("Y", self.ny, n_samples)
        P = ca.MX.sym("p", c.np)
        S = ca.MX.sym("S", d, n_samples)
        centre = ca.MX.sym("c", d)
        size = ca.MX.sym("D", d)
        N = n_samples
        T = ca.repmat(centre, 1, N) + ca.repmat(size, 1, N) * (ca.repmat(U, 1, N) + S * ca.repmat(W, 1, N))
        G = per.map(N)(Y, T, ca.repmat(P, 1, N))
        nlp = {
            "x": ca.vertcat(U, W, ca.vec(Y)),
            "p": ca.vertcat(P, ca.vec(S), centre, size),
            "f": -ca.sum1(ca.log(W)),
            "g": ca.vec(G),
        }
        opts = {**config.casadi_options(), **CUBOID_IPOPT, **dict(config.options), "expand": True}
        self._solver = ca.nlpsol(f"{c.name}_cuboid_{N}", "ipopt", nlp, opts)

    def solve(self, z0, params, lbx, ubx, lbg, ubg) -> tuple[np.ndarray, bool, str, int]:
        return run_nlp(self._solver, "cuboid NLP", x0=z0, p=params, lbx=lbx, ubx=ubx, lbg=lbg, ubg=ubg)


def cuboid_nlp(model: Model, n_samples: int, config: SolverConfig) -> CuboidNLP:
    lo, hi = limit_bounds(model)
    active = tuple(bool(v) for v in (np.isfinite(lo) | np.isfinite(hi)))
    key = f"cuboid:{n_samples}:{''.join('1' if a else '0' for a in active)}"
    return model.closure.solvers.get(key, config, lambda: CuboidNLP(model.closure, n_samples, active, config))


@dataclass
class CuboidCheck:
    """Membership of the dense sample of a box (faces, edges, interior)."""

    points: int
    outside: int
    margin: float
    binding: str

    @property
    def passed(self) -> bool:
        return self.outside == 0


def check_box(
    model: Model, lower, upper, per_edge: int = 17, solver: SolverConfig | None = None
) -> tuple[CuboidCheck, np.ndarray, Membership]:
    """Check a box against :func:`membership` on :func:`check_grid`; also returns
    the unit-box positions checked and the membership report."""
    lower, upper = np.asarray(lower, dtype=float), np.asarray(upper, dtype=float)
    S = check_grid(lower.size, per_edge)
    mem = membership(model, lower + S * (upper - lower), solver)
    margin, binding = mem.worst()
    return CuboidCheck(len(S), mem.count_outside, margin, binding), S, mem


@dataclass
class CuboidResult:
    """The largest box found, with how it was found and checked.

    lower, upper: corners in the task coordinates (SI); None unless ``found``.
    starts: number of starts; converged: how many converged; agreed: how
    many converged to the best volume (within AGREEMENT); refinements:
    exchange rounds used; shrink: factor applied about the centre after
    them (1 = none); check: the dense membership check of the reported box.
    """

    found: bool
    message: str
    lower: np.ndarray | None = None
    upper: np.ndarray | None = None
    volume: float | None = None
    starts: int = 0
    converged: int = 0
    agreed: int = 0
    refinements: int = 0
    shrink: float = 1.0
    check: CuboidCheck | None = None
    iterations: int = 0
    seconds: float = 0.0
    region: tuple[np.ndarray, np.ndarray] | None = None
    infeasible: bool = False
    start_volumes: list[float] = field(default_factory=list)


def _nlp_bounds(model: Model, rows) -> tuple[np.ndarray, np.ndarray]:
    """Bounds of the limited quantities ``rows`` as the cuboid NLPs keep them
    (NLP_MARGIN inside the declared ones)."""
    lo, hi = limit_bounds(model)
    lo_a, hi_a = lo[rows], hi[rows]
    return (
        np.where(np.isfinite(lo_a), lo_a + NLP_MARGIN, lo_a),
        np.where(np.isfinite(hi_a), hi_a - NLP_MARGIN, hi_a),
    )


def _layout(nlp: CuboidNLP, model: Model, S: np.ndarray, centre, size):
    c = model.closure
    d, N = nlp.d, nlp.N
    lo_a, hi_a = _nlp_bounds(model, nlp.rows)
    per_lbg = np.r_[np.zeros(c.nx), lo_a]
    per_ubg = np.r_[np.zeros(c.nx), hi_a]
    lbg, ubg = np.tile(per_lbg, N), np.tile(per_ubg, N)
    ylo = np.r_[model.x_lower[c.dep_index], np.full(c.nq, -np.inf)]
    yhi = np.r_[model.x_upper[c.dep_index], np.full(c.nq, np.inf)]
    lbx = np.r_[np.full(d, -np.inf), np.full(d, 1e-10), np.tile(ylo, N)]
    ubx = np.r_[np.full(d, np.inf), np.full(d, np.inf), np.tile(yhi, N)]
    params = np.r_[model.p, S.T.ravel(order="F"), centre, size]
    return params, lbx, ubx, lbg, ubg


class _PoseCuboid:
    """The general cuboid NLP (pose unknowns y_j with Φ(t_j, y_j) = 0 at every sample,
    see :class:`CuboidNLP`), with EXTRA_SLOTS sample slots for the exchange rounds."""

    def __init__(self, model: Model, config: SolverConfig, base: np.ndarray, centre, size):
        d = model.closure.nq
        self.model, self.config, self.centre, self.size = model, config, centre, size
        self.S = np.vstack([base, np.full((EXTRA_SLOTS, d), 0.5)])
        self.slot = len(base)
        self.nlp = cuboid_nlp(model, len(self.S), config)
        self.layout = _layout(self.nlp, model, self.S, centre, size)

    def room(self) -> int:
        return len(self.S) - self.slot

    def start(self, u0, w0, X, Q) -> tuple[bool, np.ndarray | None, str, int]:
        c = self.model.closure
        y0 = np.hstack([X[:, c.dep_index], Q])
        z, ok, status, iters = self.nlp.solve(np.r_[u0, w0, y0.ravel()], *self.layout)
        return ok, z, status, iters

    def exchange(self, z: np.ndarray, points: np.ndarray) -> tuple[np.ndarray, bool, str, int]:
        d = self.model.closure.nq
        Y = z[2 * d :].reshape(len(self.S), -1).copy()
        for point in points:  # a new sample starts from the pose of its nearest sample
            nearest = int(np.argmin(np.sum((self.S[: self.slot] - point) ** 2, axis=1)))
            self.S[self.slot] = point
            Y[self.slot] = Y[nearest]
            self.slot += 1
        self.layout = _layout(self.nlp, self.model, self.S, self.centre, self.size)
        return self.nlp.solve(np.r_[z[: 2 * d], Y.ravel()], *self.layout)


def _closed_form_cuboid(
    model: Model, config: SolverConfig, base: np.ndarray, centre, size, cloud: Membership
) -> ClosedFormCuboid:
    """The working-set NLP through the closed-form IK (:mod:`cpm_nlp.analysis.cuboid_ik`)."""
    fn, names = limited_function(model.closure)
    lo, hi = limit_bounds(model)
    rows = tuple(int(r) for r in np.flatnonzero(np.isfinite(lo) | np.isfinite(hi)))
    lower, upper = _nlp_bounds(model, list(rows))
    # the quantities that bind somewhere in the search region start the first solve
    binding = {cloud.binding[k] for k in np.flatnonzero(~cloud.inside)}
    initial = [k for k, r in enumerate(rows) if names[r] in binding]
    if "no assembly" in binding:
        initial.append(len(rows))  # the reach margin
    options = {**config.casadi_options(), **CUBOID_IPOPT, **CLOSED_FORM_IPOPT, **dict(config.options)}
    return ClosedFormCuboid(model, config, fn, rows, lower, upper, NLP_MARGIN, base, centre, size, options, initial)


def _start_box(model: Model, t_c: np.ndarray, S: np.ndarray, centre, size, config: SolverConfig):
    """The initial box of a start about the task point t_c: (u0, w0, X, Q) with the
    poses of its samples, shrunk until every sample assembles; None if none does."""
    d = model.closure.nq
    w0 = np.full(d, 1e-3)
    for _ in range(4):
        u0 = (t_c - centre) / size - 0.5 * w0
        X, Q, ok = poses(model, centre + size * (u0 + S * w0), config)
        if np.all(ok):
            return u0, w0, X, Q
        w0 = w0 * 0.1
    return None


def _start_boxes(model: Model, seeds: list, S: np.ndarray, centre, size, config: SolverConfig) -> list:
    """:func:`_start_box` of every seed; with a closed-form IK the poses of all seeds'
    samples in one call per shrink step (the same boxes)."""
    if model.closure.ik is None:
        return [_start_box(model, t_c, S, centre, size, config) for t_c in seeds]
    d = model.closure.nq
    boxes: list = [None] * len(seeds)
    todo = list(range(len(seeds)))
    w0 = np.full(d, 1e-3)
    for _ in range(4):
        if not todo:
            break
        u0 = [(seeds[k] - centre) / size - 0.5 * w0 for k in todo]
        X, Q, ok = poses(model, np.vstack([centre + size * (u + S * w0) for u in u0]), config)
        n = len(S)
        left = []
        for i, k in enumerate(todo):
            part = slice(i * n, (i + 1) * n)
            if np.all(ok[part]):
                boxes[k] = (u0[i], w0.copy(), X[part], Q[part])
            else:
                left.append(k)
        todo = left
        w0 = w0 * 0.1
    return boxes


#: formulations of the cuboid NLP: "closed_form" needs the mechanism's closed-form IK
FORMULATIONS = ("auto", "closed_form", "poses")


def inscribed_cuboid(  # noqa: C901 - the driver: starts, exchange rounds, check
    model: Model,
    solver: SolverConfig | None = None,
    *,
    starts: int = 8,
    seed: int = 0,
    samples_per_edge: int = 5,
    check_per_edge: int = 17,
    refinements: int = 3,
    region: tuple[np.ndarray, np.ndarray] | None = None,
    cloud: int = 2000,
    formulation: str = "auto",
) -> CuboidResult:
    """The largest axis-aligned box in the task coordinates inside the reachable
    workspace (see the module docstring for the method).

    starts: IPOPT starts (the first at the home pose, the others at points of
    a seeded point cloud of ``region``); samples_per_edge: the NLP's surface
    grid; check_per_edge: the dense check's surface grid; refinements: the
    largest number of exchange rounds; region: the box the starts are drawn
    from (default: probed around home); formulation: "poses" (pose unknowns at
    every sample, any mechanism), "closed_form" (the limited quantities through
    the closed-form IK, :mod:`cpm_nlp.analysis.cuboid_ik`) or "auto" (closed_form when
    the mechanism has a closed-form IK and every point of the cloud drawn for
    the starts assembles: where the IK's reach margin bounds the workspace its
    derivatives grow without bound, and IPOPT converges there less reliably
    than with pose unknowns).  Both formulations solve the same NLP.
    """
    if formulation not in FORMULATIONS:
        raise InputError(
            f"unknown cuboid formulation {formulation!r}; expected one of: {', '.join(FORMULATIONS)}",
            path=("formulation",),
            suggestions=suggest(str(formulation), FORMULATIONS),
        )
    if formulation == "closed_form" and model.closure.ik is None:
        raise InputError(
            f"the closed_form cuboid formulation needs a closed-form IK; {model.name} has none (use 'poses')",
            path=("formulation",),
        )
    t_start = time.perf_counter()
    config = solver or SolverConfig()
    c = model.closure
    d = c.nq
    if region is None:
        region = probe_region(model, config)
        if region is None:
            return CuboidResult(
                False,
                "the home configuration is outside the workspace; give a search region (<task>_range inputs)",
                infeasible=True,
                seconds=time.perf_counter() - t_start,
            )
    lo_r, hi_r = (np.asarray(v, dtype=float) for v in region)
    centre, size = 0.5 * (lo_r + hi_r), np.maximum(hi_r - lo_r, 1e-12)
    rng = np.random.default_rng(seed)
    home_t = model.task_of(model.x_home)
    T = lo_r + (hi_r - lo_r) * rng.random((cloud, d))
    cloud_mem = membership(model, T, config)
    members = T[cloud_mem.inside]
    seeds = []
    if membership(model, home_t[None, :], config).inside[0]:
        seeds.append(home_t)
    seeds += list(members[rng.permutation(len(members))[: max(starts - len(seeds), 0)]])
    seeds = seeds[:starts]
    if not seeds:
        return CuboidResult(
            False,
            f"no reachable point found in the search region ({cloud} samples)",
            infeasible=True,
            region=(lo_r, hi_r),
            seconds=time.perf_counter() - t_start,
        )
    base = surface_grid(d, samples_per_edge)
    # auto: the closed form unless the IK's own reach limit shapes the workspace in the
    # region (a cloud point that does not assemble): its derivatives are unbounded there
    assembles = "no assembly" not in {cloud_mem.binding[k] for k in np.flatnonzero(~cloud_mem.inside)}
    closed_form = formulation == "closed_form" or (formulation == "auto" and c.ik is not None and assembles)
    if closed_form:
        engine = _closed_form_cuboid(model, config, base, centre, size, cloud_mem)
    else:
        engine = _PoseCuboid(model, config, base, centre, size)
    runs: list = [None] * len(seeds)
    iterations = 0
    boxes = _start_boxes(model, seeds, engine.S, centre, size, config)
    pending = []
    for k, box in enumerate(boxes):
        if box is None:
            runs[k] = (False, None, "no pose at the start", 0)
        else:
            pending.append(k)
    # the first start alone; the others together where the engine can (one block-separable
    # NLP, see cuboid_ik.SlotNLP), else, or if that fails, one by one
    joint = None
    if len(pending) > 2 and hasattr(engine, "start_all"):
        k0 = pending.pop(0)
        runs[k0] = engine.start(*boxes[k0])
        iterations += runs[k0][3]
        joint, iters = engine.start_all([boxes[k][:2] for k in pending])
        iterations += iters
    if joint is not None:
        for k, run in zip(pending, joint):
            runs[k] = run
    else:
        for k in track(pending, "cuboid starts"):
            runs[k] = engine.start(*boxes[k])
            iterations += runs[k][3]
    volumes = [float(np.prod(size * r[1][d : 2 * d])) if r[0] else None for r in runs]
    ok_vols = [v for v in volumes if v is not None]
    best, agreed = best_and_agreement([-v if v is not None else None for v in volumes])
    if not ok_vols:
        statuses = sorted({r[2] for r in runs})
        return CuboidResult(
            False,
            f"no start converged ({', '.join(statuses)})",
            starts=len(runs),
            iterations=iterations,
            region=(lo_r, hi_r),
            seconds=time.perf_counter() - t_start,
            infeasible=all("Infeasible" in r[2] for r in runs),
        )
    z = runs[best][1]
    lower = centre + size * z[:d]
    upper = lower + size * z[d : 2 * d]
    check, S_check, mem = check_box(model, lower, upper, check_per_edge, config)
    rounds = 0
    room = EXTRA_SLOTS
    while not check.passed and rounds < refinements and room > 0:
        out = np.flatnonzero(~mem.inside)
        worst = out[np.argsort(mem.margin[out])][: min(ADDED_PER_ROUND, room)]
        room -= len(worst)
        z_new, ok, status, iters = engine.exchange(z, S_check[worst])
        iterations += iters
        rounds += 1
        if not ok:
            log.info("exchange round %d did not converge (%s)", rounds, status)
            break
        z = z_new
        lower = centre + size * z[:d]
        upper = lower + size * z[d : 2 * d]
        check, S_check, mem = check_box(model, lower, upper, check_per_edge, config)
    shrink = 1.0
    if not check.passed:  # largest homothetic shrink about the centre that passes the check
        mid, half = 0.5 * (lower + upper), 0.5 * (upper - lower)
        good, bad = 0.0, 1.0
        for _ in range(30):
            f = 0.5 * (good + bad)
            if check_box(model, mid - f * half, mid + f * half, check_per_edge, config)[0].passed:
                good = f
            else:
                bad = f
        shrink = good
        lower, upper = mid - shrink * half, mid + shrink * half
        check = check_box(model, lower, upper, check_per_edge, config)[0]
    volume = float(np.prod(upper - lower))
    msg = f"best of {len(runs)} starts ({agreed} agree within {AGREEMENT:g})"
    if rounds:
        msg += f"; {rounds} exchange round(s) added outside points of the check as samples"
    if shrink < 1.0:
        msg += f"; shrunk by a factor {shrink:.10g} about its centre to pass the membership check"
    return CuboidResult(
        check.passed,
        msg if check.passed else f"no box passes the membership check ({check.binding})",
        lower if check.passed else None,
        upper if check.passed else None,
        volume if check.passed else None,
        starts=len(runs),
        converged=len(ok_vols),
        agreed=agreed,
        refinements=rounds,
        shrink=shrink,
        check=check,
        iterations=iterations,
        seconds=time.perf_counter() - t_start,
        region=(lo_r, hi_r),
        start_volumes=[v for v in volumes if v is not None],
    )


def box_volume(lower: Sequence[float], upper: Sequence[float]) -> float:
    return float(np.prod(np.asarray(upper, dtype=float) - np.asarray(lower, dtype=float)))


# -- the image of the actuator-stroke box (FK) ----------------------------------------------------


def joint_box(model: Model) -> tuple[np.ndarray, np.ndarray]:
    """(low, high) of every actuator from the model's limits; an
    :class:`InputError` naming the missing ``mechanism.limits`` key if one has none."""
    c = model.closure
    missing = [q for q in c.q if model.limit_of(q) is None]
    if missing:
        keys = sorted({q.group for q in missing})
        raise InputError(
            "the workspace is the image of the actuator strokes; no stroke is declared for "
            + ", ".join(q.name for q in missing)
            + " (expected "
            + ", ".join(f"mechanism.limits.{k}: [low, high]" for k in keys)
            + ")",
            path=("mechanism", "limits"),
        )
    lims = np.array([model.limit_of(q) for q in c.q], dtype=float)
    return lims[:, 0], lims[:, 1]


def box_grid(low: Sequence[float], high: Sequence[float], count: int) -> np.ndarray:
    """``count`` equally spaced values per axis, ends included: shape (count^n, n)."""
    return full_factorial([np.linspace(lo, hi, count) for lo, hi in zip(low, high)])


def box_corners(low: Sequence[float], high: Sequence[float]) -> np.ndarray:
    """The 2^n corners of a box, in the order of :func:`box_grid` with count 2."""
    return box_grid(low, high, 2)


def gauss_box(low: Sequence[float], high: Sequence[float], order: int) -> tuple[np.ndarray, np.ndarray]:
    """Tensor Gauss-Legendre nodes and weights of ``order`` points per axis
    over a box (exact for polynomials of degree 2 order - 1 in each variable)."""
    xi, wi = np.polynomial.legendre.leggauss(order)
    low, high = np.asarray(low, dtype=float), np.asarray(high, dtype=float)
    mid, half = (high + low) / 2, (high - low) / 2
    nodes = np.array(list(itertools.product(xi, repeat=low.size)))
    weights = np.prod(np.array(list(itertools.product(wi, repeat=low.size))), axis=1) * np.prod(half)
    return mid + nodes * half, weights


@dataclass
class WorkspaceReport:
    """The reachable workspace (task coordinates, SI).

    q, t: the grid over the stroke box and its images, shape (N, nq) (rows of
    t are NaN where FK failed); solutions: the FK of every grid point.
    vertices: images of the box corners, shape (2^nq, nq).
    lower, upper: axis-aligned bounding box of the grid images.
    volume: the integral of |det(dt/dq)| over the box (Gauss-Legendre), i.e.
    the volume of the workspace if FK is one-to-one on the box, which holds
    when det(dt/dq) keeps its sign (checked at every grid and quadrature point).
    linear_volume: |det J_task(home)| times the volume of the stroke box: the
    volume of the linearized workspace (for the 3-PRC the cube (A2 q_max)^3
    of eq 26).
    jacobian_deviation: the largest entry of |J_inv - J_inv(home)| over the
    grid, each column scaled by its largest entry at home (dimensionless;
    zero for a linear mechanism).
    linear_error: per task coordinate, the largest |t - t_lin| over the grid,
    t_lin = t_home + J_task(home) (q - q_home) the linearization at home.
    None (or empty) unless ``status`` is solved.
    """

    q: np.ndarray
    t: np.ndarray
    solutions: list[PoseSolution]
    status: Status
    message: str = ""
    vertices: np.ndarray | None = None
    lower: np.ndarray | None = None
    upper: np.ndarray | None = None
    volume: float | None = None
    linear_volume: float | None = None
    jacobian_deviation: float | None = None
    linear_error: np.ndarray | None = None
    seconds: float = 0.0
    details: dict = field(default_factory=dict)


def _fk_all(model: Model, qs: np.ndarray, solver: SolverConfig, J0: np.ndarray) -> list[PoseSolution]:
    """FK of every row of qs, each started from the linearization at home."""
    return [forward_kinematics(model, q, solver, guess=model.x_home + J0 @ (q - model.q_home)) for q in qs]


def reachable_workspace(
    model: Model, samples: int = 11, quadrature: int = 4, solver: SolverConfig | None = None
) -> WorkspaceReport:
    """Sample the reachable workspace: FK on a ``samples``^nq grid over the
    stroke box (:func:`joint_box`), and the volume by ``quadrature``^nq
    Gauss-Legendre points (see :class:`WorkspaceReport`)."""
    config = solver or SolverConfig()
    c = model.closure
    t0 = time.perf_counter()
    low, high = joint_box(model)
    J0 = np.asarray(c.jacobian(model.x_home, model.q_home, model.p))
    Jinv0 = np.asarray(c.inverse_jacobian(model.x_home, model.q_home, model.p))
    qs = box_grid(low, high, samples)
    sols = _fk_all(model, qs, config, J0)
    ts = np.array([model.task_of(s.x) if s.ok else np.full(c.nq, np.nan) for s in sols])
    report = WorkspaceReport(qs, ts, sols, worst_status([s.status for s in sols]))
    bad = [k for k, s in enumerate(sols) if not s.ok]
    if bad:
        k = bad[0]
        report.message = (
            f"{len(bad)} of {len(sols)} grid points not solved; first, q = {qs[k].tolist()}: "
            f"{sols[k].status.value}" + (f" ({sols[k].message})" if sols[k].message else "")
        )
        report.seconds = time.perf_counter() - t0
        return report
    nodes, weights = gauss_box(low, high, quadrature)
    nsols = _fk_all(model, nodes, config, J0)
    if not all(s.ok for s in nsols):
        s = next(s for s in nsols if not s.ok)
        report.status, report.message = s.status, f"a quadrature point was not solved: {s.message}"
        return report
    det = []
    for s in sols + nsols:
        det.append(float(np.linalg.det(np.asarray(c.jacobian(s.x, s.q, model.p))[c.task_index, :])))
    det = np.array(det)
    if not (np.all(det > 0) or np.all(det < 0)):
        report.status = Status.SINGULAR
        report.message = "det(dt/dq) changes sign (or vanishes) inside the stroke box: the workspace folds"
        return report
    report.volume = float(np.sum(weights * np.abs(det[len(sols) :])))
    report.linear_volume = float(abs(np.linalg.det(J0[c.task_index, :])) * np.prod(high - low))
    corner_idx = [int(np.argmin(np.sum(np.abs(qs - corner), axis=1))) for corner in box_corners(low, high)]
    report.vertices = ts[corner_idx]
    report.lower, report.upper = ts.min(axis=0), ts.max(axis=0)
    t_home = model.task_of(model.x_home)
    t_lin = t_home + (qs - model.q_home) @ J0[c.task_index, :].T
    report.linear_error = np.max(np.abs(ts - t_lin), axis=0)
    scale = np.max(np.abs(Jinv0), axis=0)
    dev = [np.max(np.abs(np.asarray(c.inverse_jacobian(s.x, s.q, model.p)) - Jinv0) / scale) for s in sols]
    report.jacobian_deviation = float(max(dev))
    report.details = {"det_min": float(np.min(np.abs(det))), "det_max": float(np.max(np.abs(det)))}
    report.message = f"{len(sols)} grid points ({samples} per actuator) and {len(nsols)} quadrature points solved by FK"
    report.seconds = time.perf_counter() - t0
    return report
