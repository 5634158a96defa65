"""The pose of each task point of a mechanism without a closed-form IK, independent of
the other points.

The pose unknowns at a task point t are y = (dependent pose coordinates, actuators)
with Φ(t, y) = 0.  Every point has its own **start set**, a function of t and the
model alone (never of another point or of the order of the points):

1. the linearisation at home, y_home + (dy/dt)(home) (t - t_home);
2. home, y_home;
3. `HALTON_STARTS` points of the unlimited Halton sequence (bases 2, 3, 5, ...,
   unscrambled) in the box of the unknowns (`unknown_box`: the actuator strokes,
   the declared pose limits and the closure's bounds; home ± a span where nothing bounds a
   coordinate).

The points are solved in rounds, every start of a round of every point in one
vectorised damped Newton iteration (the residual and Φ_y of all (point, start) pairs in
one mapped CasADi call per step; each pair is its own iteration, so the pairs never
interact): round 1 the first two starts, round 2 the Halton starts for the points not
decided by round 1.  Points still undecided are then solved by IPOPT with the box of
the unknowns as bounds (the actuator strokes among them), from each start in turn.

Each converged pose is reduced (angles by whole turns, to the turn nearest the middle
of the box, kept only if Φ still vanishes there) and judged by
`cpm_nlp.analysis.workspace.membership.judge`; the caller takes a point's first
witness in the order of its start set.
"""

from __future__ import annotations

import numpy as np

from ...core.batch import evaluate_points
from ...core.model import LoopClosure, Model
from ...core.solver import SolverConfig, solvers_of

#: Halton starts per point after the linearisation and home
HALTON_STARTS = 16
#: IPOPT starts per point (with the box as bounds) for points the Newton rounds left undecided
IPOPT_STARTS = 4
#: damped Newton: iterations, step halvings per iteration
NEWTON_ITERATIONS = 40
NEWTON_HALVINGS = 10
#: cache key of the residual and Φ_y function
NEWTON_KEY = ("workspace", "ik_newton")

_PRIMES = (2, 3, 5, 7, 11, 13, 17, 19, 23, 29, 31, 37, 41, 43, 47, 53, 59, 61, 67, 71, 73, 79, 83, 89, 97)


def halton(n: int, d: int) -> np.ndarray:
    """The first n points (from index 1) of the unscrambled Halton sequence in [0, 1)^d."""
    if d > len(_PRIMES):
        raise ValueError(f"halton: at most {len(_PRIMES)} dimensions")
    out = np.zeros((n, d))
    for j in range(d):
        b = _PRIMES[j]
        for i in range(n):
            k, f, v = i + 1, 1.0, 0.0
            while k > 0:
                f /= b
                v += f * (k % b)
                k //= b
            out[i, j] = v
    return out


def unknown_kinds(closure: LoopClosure) -> list[str]:
    """Dimension of each unknown y = (x_dep, q)."""
    return [closure.x[i].kind for i in closure.dep_index] + [q.kind for q in closure.q]


def unknown_box(model: Model) -> tuple[np.ndarray, np.ndarray]:
    """Bounds of the pose unknowns y = (x_dep, q): the closure's bounds of the dependent
    pose coordinates and their declared limits, the actuator strokes (±inf where none)."""
    c = model.closure
    lo, hi = [], []
    for i in c.dep_index:
        lim = model.limit_of(c.x[i])
        lo.append(max(model.x_lower[i], lim[0]) if lim else model.x_lower[i])
        hi.append(min(model.x_upper[i], lim[1]) if lim else model.x_upper[i])
    for coord in c.q:
        lim = model.limit_of(coord)
        lo.append(lim[0] if lim else -np.inf)
        hi.append(lim[1] if lim else np.inf)
    return np.asarray(lo, dtype=float), np.asarray(hi, dtype=float)


def _home_y(model: Model) -> np.ndarray:
    c = model.closure
    return np.r_[model.x_home[c.dep_index], model.q_home]


def _spans(model: Model) -> np.ndarray:
    """Half-width of the start box of a coordinate nothing bounds."""
    length = max(model.characteristic_length, 1e-3)
    return np.array([np.pi if k == "angle" else 0.5 * length for k in unknown_kinds(model.closure)])


def start_set(model: Model, T: np.ndarray) -> np.ndarray:
    """The starts of every task point, shape (N, 2 + HALTON_STARTS, ny): the linearisation
    at home, home, then the Halton points of the unknowns' box (see the module docstring)."""
    c = model.closure
    T = np.atleast_2d(T)
    N = T.shape[0]
    y_home = _home_y(model)
    lo, hi = unknown_box(model)
    span = _spans(model)
    blo = np.where(np.isfinite(lo), lo, y_home - span)
    bhi = np.where(np.isfinite(hi), hi, y_home + span)
    # dy/dt at home: -Φ_y⁻¹ Φ_t
    phi_x = np.asarray(c.phi_x(model.x_home, model.q_home, model.p))
    phi_y = np.asarray(c.phi_y(model.x_home, model.q_home, model.p))
    try:
        dydt = -np.linalg.solve(phi_y, phi_x[:, c.task_index])
    except np.linalg.LinAlgError:
        dydt = np.zeros((y_home.size, c.nq))
    t_home = model.task_of(model.x_home)
    lin = y_home + (T - t_home) @ dydt.T
    inner = 1e-6 * (bhi - blo)
    lin = np.clip(lin, blo + inner, bhi - inner)
    fixed = blo + (bhi - blo) * halton(HALTON_STARTS, y_home.size)
    starts = np.empty((N, 2 + HALTON_STARTS, y_home.size))
    starts[:, 0] = lin
    starts[:, 1] = y_home
    starts[:, 2:] = fixed[None, :, :]
    return starts


def newton_function(closure: LoopClosure):
    """``<name>_ik_newton: (y, t, p) -> (phi, phi_y)`` (Φ_y dense, row-major per point)."""
    import casadi as ca

    def build():
        c = closure
        nd = len(c.dep_index)
        y, t, p = ca.SX.sym("y", nd + c.nq), ca.SX.sym("t", c.nq), ca.SX.sym("p", c.np)
        r = c.ik_residual(y, ca.vertcat(t, p))
        J = ca.densify(ca.jacobian(r, y))
        return ca.Function(f"{c.name}_ik_newton", [y, t, p], [r, ca.vec(J.T)], ["y", "t", "p"], ["phi", "phi_y"])

    return solvers_of(closure).memo(NEWTON_KEY, build)


def newton(model: Model, Y0: np.ndarray, T: np.ndarray, tolerance: float) -> tuple[np.ndarray, np.ndarray]:
    """Damped Newton on Φ(t_k, y) = 0 from each row of Y0 (M, ny) at T (M, nq), every
    row its own iteration (vectorised).  Returns (Y, residual max-norm)."""
    c = model.closure
    fn = newton_function(c)
    Y = np.array(Y0, dtype=float)
    M, ny = Y.shape
    if M == 0:
        return Y, np.zeros(0)

    def residual(rows: np.ndarray, Yr: np.ndarray):
        r, J = evaluate_points(c, NEWTON_KEY, fn, [Yr, T[rows]], model.p)
        return r, J.reshape(len(rows), ny, ny)

    active = np.arange(M)
    r, J = residual(active, Y)
    norm = np.max(np.abs(r), axis=1)
    norm[~np.isfinite(norm)] = np.inf
    for _ in range(NEWTON_ITERATIONS):
        todo = np.flatnonzero((norm > tolerance * 1e-3) & np.isfinite(norm))
        if not todo.size:
            break
        Jt, rt = J[todo], r[todo]
        with np.errstate(all="ignore"):
            ok = np.all(np.isfinite(Jt), axis=(1, 2)) & (np.abs(np.linalg.det(Jt)) > 0)
        step = np.full((todo.size, ny), np.nan)
        if np.any(ok):
            try:
                step[ok] = np.linalg.solve(Jt[ok], rt[ok][..., None])[..., 0]
            except np.linalg.LinAlgError:
                step[ok] = np.einsum("kij,kj->ki", np.linalg.pinv(Jt[ok]), rt[ok])
        alpha = np.ones(todo.size)
        pending = np.flatnonzero(np.all(np.isfinite(step), axis=1))
        dead = np.setdiff1d(np.arange(todo.size), pending)
        norm[todo[dead]] = np.inf  # singular Φ_y: this start stops here
        for _h in range(NEWTON_HALVINGS):
            if not pending.size:
                break
            rows = todo[pending]
            trial = Y[rows] - alpha[pending, None] * step[pending]
            r_new, J_new = residual(rows, trial)
            n_new = np.max(np.abs(r_new), axis=1)
            better = np.isfinite(n_new) & (n_new < norm[rows] * (1 - 1e-4 * alpha[pending]))
            acc = rows[better]
            Y[acc], r[acc], J[acc], norm[acc] = trial[better], r_new[better], J_new[better], n_new[better]
            pending = pending[~better]
            alpha[pending] *= 0.5
        norm[todo[pending]] = np.where(norm[todo[pending]] <= tolerance, norm[todo[pending]], np.inf)
    norm[~np.isfinite(norm)] = np.inf
    return Y, norm


def reduce_angles(model: Model, Y: np.ndarray) -> np.ndarray:
    """Angles of the unknowns shifted by whole turns to the turn nearest the middle of
    their box (home where unbounded)."""
    kinds = unknown_kinds(model.closure)
    lo, hi = unknown_box(model)
    mid = np.where(np.isfinite(lo) & np.isfinite(hi), 0.5 * (lo + hi), _home_y(model))
    out = np.array(Y, dtype=float)
    for j, k in enumerate(kinds):
        if k == "angle":
            out[:, j] = out[:, j] - 2 * np.pi * np.round((out[:, j] - mid[j]) / (2 * np.pi))
    return out


def ipopt_config(config: SolverConfig) -> SolverConfig:
    """The IPOPT configuration of the bounded solves (the user's when it is IPOPT)."""
    return config if config.method == "ipopt" else SolverConfig("ipopt", tolerance=config.tolerance)


def ipopt_solve(model: Model, t: np.ndarray, y0: np.ndarray, config: SolverConfig) -> tuple[np.ndarray, bool]:
    """IPOPT from y0 with the box of the unknowns (the actuator strokes among them) as bounds."""
    c = model.closure
    lo, hi = unknown_box(model)
    built = c.ik_solver(ipopt_config(config))
    y, conv, *_ = built.solve(y0, np.r_[t, model.p], lo, hi)
    return y, bool(conv)
