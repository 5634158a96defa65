"""Kinematics algorithms: free functions over a [`Model`][cpm_nlp.core.model.Model].

* [`forward_kinematics`][cpm_nlp.core.kinematics.forward_kinematics] -- x from q, by IPOPT (default) or Newton;
* [`inverse_kinematics`][cpm_nlp.core.kinematics.inverse_kinematics] -- q (and the dependent pose coordinates) from
  the task coordinates, in closed form where the paper gives one, else solved;
* [`jacobians`][cpm_nlp.core.kinematics.jacobians] -- Φ_x, Φ_q, forward and inverse Jacobians and singularity
  measures, all from algorithmic differentiation of Φ;
* [`passive_joints`][cpm_nlp.core.kinematics.passive_joints] -- passive joint angles of a pose;
* [`assess`][cpm_nlp.core.kinematics.assess] -- the checks every pose passes before it is reported solved.

Sizes: nx = pose coordinates, nq = actuated joints (= task coordinates).
"""

from __future__ import annotations

import logging
import math
import time
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from .errors import InputError
from .fast_calls import BoundCall, fast
from .kernels import PATHS, batch_newton_supported, fk_kernel, shared_values
from .model import Model
from .pose_checks import ROUND_TRIP_FACTOR as ROUND_TRIP_FACTOR  # noqa: F401 - re-exported (defined in pose_checks)
from .pose_checks import (
    SCALAR,
    STATUSES,
    checks_function,
    code_of,
    condition_number,
    is_singular,
    limit_vectors,
    status_code,
    status_rules,
)
from .pose_checks import SINGULAR_CONDITION as SINGULAR_CONDITION  # noqa: F401
from .result import Status
from .solver import SolverConfig

TYPE_CHECKING = False
if TYPE_CHECKING:
    from .compiled import BoundNative

log = logging.getLogger(__name__)


@dataclass
class PoseSolution:
    """Outcome of one FK or IK solve.

    Attributes
    ----------
    x
        pose, size nx;
    q
        actuated joints, size nq;
    passive
        passive joint angles (model.closure.passive_names).  All three are None unless
        ``status`` is ``solved``.  ``residual`` is max |Φ| at the last iterate.
    """

    status: Status
    x: np.ndarray | None = None
    q: np.ndarray | None = None
    passive: np.ndarray | None = None
    residual: float = float("nan")
    iterations: int = 0
    seconds: float = 0.0
    solver: str = ""
    message: str = ""
    details: dict = field(default_factory=dict)
    #: Newton FK of a mechanism with a closed-form IK: "reduced" (Newton on the
    #: task coordinates through the IK answered) or "full" (Newton on Φ); else ""
    path: str = ""

    @property
    def ok(self) -> bool:
        return self.status.ok


def _vector(values, n: int, name: str) -> np.ndarray:
    arr = np.asarray(values, dtype=float).ravel()
    if arr.size != n:
        raise InputError(f"expected {n} values, got {arr.size}", path=(name,))
    if not all(map(math.isfinite, arr.tolist())):
        raise InputError(f"expected finite numbers, got {arr.tolist()}", path=(name,))
    return arr


def residual(model: Model, x: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Φ(x, q; p), size nx, in the model's residual unit."""
    return np.asarray(model.closure.phi(x, q, model.p)).ravel()


def passive_joints(model: Model, x: np.ndarray, q: np.ndarray) -> dict[str, float]:
    """Passive joint angles of a pose (empty if the model declares none)."""
    c = model.closure
    if c.passive is None:
        return {}
    vals = np.asarray(c.passive(x, q, model.p)).ravel()
    return dict(zip(c.passive_names, vals.tolist()))


def _limit_violations(model: Model, x: np.ndarray, q: np.ndarray, passive: np.ndarray | None) -> list[str]:
    """Actuators, pose coordinates (e.g. joint angles that are unknowns of the
    loops) and passive joints outside their declared limits."""
    out = []
    c = model.closure
    coords = list(c.q) + list(c.x) + (list(c.passive_coords) if passive is not None else [])
    values = list(q) + list(x) + (list(passive) if passive is not None else [])
    for coord, v in zip(coords, values):
        lim = model.limit_of(coord)
        if lim is not None and not (lim[0] <= v <= lim[1]):
            out.append(f"{coord.name} = {v:.6g} outside [{lim[0]:.6g}, {lim[1]:.6g}]")
    return out


def pose_checks(model: Model, x: np.ndarray, q: np.ndarray, tolerance: float) -> dict[str, np.ndarray]:
    """The kernel checks of one pose (see `cpm_nlp.core.pose_checks`), one fast call."""
    c = model.closure
    fn = fast(c, ("pose_checks",), lambda: checks_function(c))
    lower, upper = limit_vectors(model)
    return fn.named(x, q, model.p, lower, upper, [tolerance])


def failure_message(model: Model, status: Status, details: dict, x, q, passive, tolerance: float) -> str:
    """Why a pose with these check values has this status ("" when solved)."""
    unit = model.closure.residual_unit
    if status is Status.NOT_CONVERGED:
        res = details.get("residual", float("nan"))
        if np.isfinite(res):  # Newton ran out of iterations
            return f"Newton stopped at max |Φ| = {res:.3g} {unit} > tolerance {tolerance:.3g} {unit}"
        return "the solver returned non-finite values"
    if status is Status.UNREACHABLE:
        return f"the closed-form IK has no real solution (reach margin {details['reach']:.3g} < 0)"
    if status is Status.RESIDUAL_TOO_LARGE:
        res = details["residual"]
        return f"max |Φ| = {res:.3g} {unit} > tolerance {tolerance:.3g} {unit}"
    if status is Status.WRONG_BRANCH:
        margin = details.get("branch_margin", np.inf)
        if not margin > 0:
            return branch_failure(model, x, q, margin)
        err = details.get("round_trip_error", np.inf)
        if not np.isfinite(err):
            return "the closed-form IK has no real solution at this pose's task coordinates"
        return f"closed-form IK of this pose gives other joints (max difference {err:.3g})"
    if status is Status.SINGULAR:
        return _singular_message(model, details["cond_phi_x"])
    if status is Status.OUTSIDE_JOINT_LIMITS:
        return "; ".join(_limit_violations(model, x, q, passive))
    return ""


def _singular_message(model: Model, cond: float) -> str:
    if model.closure.loops is not None:  # normal equations: measured on every closure equation
        return f"cond(∂e/∂x) = {cond:.3g} (e: every closure equation; Φ holds their normal equations)"
    return f"cond(Φ_x) = {cond:.3g}"


def branch_failure(model: Model, x, q, margin: float) -> str:
    """Which branch indicator failed, named (its leg and joint) with its value."""
    c = model.closure
    if c.branch is None or x is None or q is None:
        return f"branch indicator {margin:.3g} <= 0"
    g = np.asarray(c.branch(np.asarray(x, dtype=float), np.asarray(q, dtype=float), model.p), dtype=float).ravel()
    bad = [k for k in range(g.size) if not g[k] > 0]
    if not bad:
        return f"branch indicator {margin:.3g} <= 0"
    k = min(bad, key=lambda i: (g[i], i))  # the most negative
    what = c.branch_descriptions[k]
    text = f"branch indicator {c.branch_names[k]} = {g[k]:.3g} <= 0" + (f" ({what})" if what else "")
    others = [c.branch_names[i] for i in bad if i != k]
    if others:
        text += f"; also <= 0: {', '.join(others)}"
    return text


def _assess(
    model: Model, x: np.ndarray, q: np.ndarray, tolerance: float
) -> tuple[Status, str, dict, np.ndarray | None]:
    c = model.closure
    x = np.asarray(x, dtype=float)
    q = np.asarray(q, dtype=float)
    if not (np.all(np.isfinite(x)) and np.all(np.isfinite(q))):
        return Status.NOT_CONVERGED, "the solver returned non-finite values", {}, None
    chk = pose_checks(model, x, q, tolerance)
    cond = condition_number(chk["cond_matrix"], c.nx)
    values = {k: float(chk[k][0]) for k in ("residual", "branch_margin", "round_trip_error", "limit_margin")}
    values["finite"] = True
    code = status_code(status_rules(values, tolerance, is_singular(cond, SCALAR), SCALAR), SCALAR)
    status = STATUSES[int(code)]
    details = {"residual": values["residual"]}
    if c.branch is not None:
        details["branch_margin"] = values["branch_margin"]
    if c.ik is not None:
        details["round_trip_error"] = values["round_trip_error"]
    details["cond_phi_x"] = cond
    passive = chk["passive"] if c.passive is not None else None
    return status, failure_message(model, status, details, x, q, passive, tolerance), details, passive


def assess(model: Model, x: np.ndarray, q: np.ndarray, tolerance: float) -> tuple[Status, str, dict]:
    """Check a candidate pose: residual, assembly branch, IK round trip,
    singularity, joint limits (in this order; the first failure gives the
    status, see `cpm_nlp.core.pose_checks.status_rules`).  Returns (status,
    message, details)."""
    status, message, details, _ = _assess(model, x, q, tolerance)
    return status, message, details


def _checked(model: Model, x, q, tolerance: float, iterations: int, seconds: float, solver: str) -> PoseSolution:
    status, message, details, passive = _assess(model, x, q, tolerance)
    residual = details.get("residual", float("nan"))
    if status is Status.SOLVED:
        return PoseSolution(status, x, q, passive, residual, iterations, seconds, solver, message, details)
    return PoseSolution(status, None, None, None, residual, iterations, seconds, solver, message, details)


_CHECK_NAMES = ("residual", "branch_margin", "round_trip_error", "cond1", "limit_margin")


def _bound_fk(model: Model, config: SolverConfig, backend: str) -> tuple[BoundCall | BoundNative, tuple[int, ...]]:
    """The FK kernel bound to this model (built once per model, configuration
    and backend) and the positions of its outputs."""
    key = ("fk", config.key(), float(config.tolerance), backend)
    cache = model.__dict__.setdefault("_bound_kernels", {})
    hit = cache.get(key)
    if hit is None:
        from .compiled import BoundNative, backend_function, native_loop  # the Newton path only (issue 23, start-up)

        kern = fk_kernel(model.closure, config)
        fn, used = backend_function(model.closure, kern, backend)
        shared = shared_values(kern, model, config.tolerance)
        defaults = [None, model.x_home]  # x0: the home pose unless a guess is given
        if used == "compiled":  # straight into the library's loop, through ctypes
            bound: BoundCall | BoundNative = BoundNative(native_loop(model.closure, kern), shared, defaults)
        else:
            bound = BoundCall(fn, shared, defaults)
        hit = cache[key] = (bound, _fk_index(kern.outputs))
    return hit


#: outputs of the FK kernel that make a PoseSolution, in this order (path: absent for mechanisms without an IK)
_FK_FIELDS = (
    "x",
    "passive",
    "residual",
    "branch_margin",
    "round_trip_error",
    "limit_margin",
    "cond1",
    "path",
    "status",
)


def _fk_index(outputs: Sequence[str]) -> tuple[int, ...]:
    return tuple(outputs.index(n) if n in outputs else -1 for n in _FK_FIELDS)


def pose_from_kernel(
    model: Model,
    outs: Sequence[np.ndarray],
    index: tuple[int, ...],
    q: np.ndarray,
    tolerance: float,
    seconds: float,
    solver: str,
) -> PoseSolution:
    """A [`PoseSolution`][cpm_nlp.core.kinematics.PoseSolution] from the outputs of the FK kernel for one pose
    (``index``: positions of `_FK_FIELDS` among them), exactly as
    [`cpm_nlp.core.batch.BatchResult`][cpm_nlp.core.batch.BatchResult] turns a batch row into one (the
    1-norm singularity screen refined by the 2-norm condition number)."""
    c = model.closure
    i_x, i_passive, i_res, i_branch, i_trip, i_limit, i_cond, i_path, i_status = index
    code = int(outs[i_status][0])
    residual = float(outs[i_res][0])
    details = {
        "residual": residual,
        "branch_margin": float(outs[i_branch][0]),
        "round_trip_error": float(outs[i_trip][0]),
        "limit_margin": float(outs[i_limit][0]),
        "cond1_phi_x": float(outs[i_cond][0]),
    }
    path = PATHS[int(outs[i_path][0])] if i_path >= 0 else ""
    x = outs[i_x].copy()
    passive = outs[i_passive].copy()
    if code == code_of(Status.SINGULAR):
        cond = condition_number(fast(c, ("cond_matrix",), lambda: c.cond_matrix)(x, q, model.p)[0], c.nx)
        rows = {k: details[k] for k in ("residual", "branch_margin", "round_trip_error", "limit_margin")}
        rows["finite"] = True
        code = int(status_code(status_rules(rows, tolerance, is_singular(cond, SCALAR), SCALAR), SCALAR))
        details["cond_phi_x"] = cond
    if code == 0:
        passive_out = passive if c.passive is not None else None
        return PoseSolution(Status.SOLVED, x, q, passive_out, residual, 0, seconds, solver, "", details, path)
    status = STATUSES[code]
    message = failure_message(model, status, details, x, q, passive, tolerance)
    return PoseSolution(
        status, residual=residual, seconds=seconds, solver=solver, message=message, details=details, path=path
    )


def _kernel_forward(
    model: Model, q: np.ndarray, x0: np.ndarray | None, config: SolverConfig, backend: str
) -> PoseSolution:
    t0 = time.perf_counter()
    call, index = _bound_fk(model, config, backend)  # built (and compiled) once per model
    t1 = time.perf_counter()
    outs = call(q, x0)
    seconds = time.perf_counter() - t1
    sol = pose_from_kernel(model, outs, index, q, config.tolerance, seconds, config.name)
    sol.details["build_seconds"] = t1 - t0
    sol.details["iterations_counted"] = sol.path == "closed"  # the kernel does not count Newton's steps
    return sol


def forward_kinematics(
    model: Model,
    q: Sequence[float],
    solver: SolverConfig | None = None,
    guess: Sequence[float] | None = None,
    *,
    backend: str = "auto",
    continuation: bool = True,
) -> PoseSolution:
    """Solve Φ(x, q; p) = 0 for the pose x on the designated branch.

    Newton (``SolverConfig("newton")``, with the options the kernels take:
    abstol, abstolStep, max_iter): the kernel of the batch,
    `cpm_nlp.core.kernels.fk_kernel`, so a single solve and a batch
    give the same statuses and values.  For a mechanism with a closed-form IK
    it solves for the nq task coordinates through the IK from the first-order
    guess and falls back to Newton on Φ from ``guess`` where that does not
    settle the pose (``PoseSolution.path``).  backend: "auto" (compiled C when
    a compiler is available, built once per machine), "compiled" or "map"
    (CasADi's virtual machine).

    continuation: when the solve from the guess fails (no convergence, or a
    pose off the designated branch, as from a pose far from home), FK follows
    the designated branch from home to q (`continued_forward_kinematics`)
    before reporting the failure.  Angles of a solved pose are reduced
    (`reduce_angles`).

    Parameters
    ----------
    q
        actuated joints, size nq (SI).
    guess
        initial pose, size nx (default: the home pose).  The answer is checked
        ([`assess`][cpm_nlp.core.kinematics.assess]) before it is reported solved.
    """
    config = solver or SolverConfig()
    c = model.closure
    qv = _vector(q, c.nq, "q")
    x0 = None if guess is None else _vector(guess, c.nx, "guess")
    sol = _forward_once(model, qv, x0, config, backend)
    # IPOPT stopped by a limit of its own options (max_iter, max_cpu_time: the user's) is the configured
    # solver's verdict; a pose off the branch, no pose inside IPOPT's bounds, or Newton from far away is
    # where continuing from home helps
    limited = config.method != "newton" and "Maximum" in sol.message
    if not sol.ok and continuation and sol.status in CONTINUED and not limited:
        alt = continued_forward_kinematics(model, qv, config, backend=backend)
        if alt.ok:
            alt.details["first_attempt"] = f"{sol.status.value}: {sol.message}" if sol.message else sol.status.value
            sol = alt
    if sol.ok:
        sol.x, _ = reduce_angles(model, sol.x, sol.q, config.tolerance)
    return sol


#: statuses after which FK tries the continuation from home (a real pose may exist on the branch)
CONTINUED = (Status.NOT_CONVERGED, Status.WRONG_BRANCH, Status.RESIDUAL_TOO_LARGE, Status.SINGULAR)
#: numbers of steps the continuation from home tries, in turn
CONTINUATION_STEPS = (4, 16, 64)
#: statuses an intermediate step of the continuation may have (a real pose on the branch)
_ON_PATH = (Status.SOLVED, Status.OUTSIDE_JOINT_LIMITS)


def _forward_once(model: Model, qv: np.ndarray, x0: np.ndarray | None, config: SolverConfig, backend: str):
    if config.method == "newton" and batch_newton_supported(config):
        return _kernel_forward(model, qv, x0, config, backend)
    c = model.closure
    x0 = model.x_home if x0 is None else x0
    built = c.fk_solver(config)
    x, ok, iters, msg, sec = built.solve(x0, np.concatenate([qv, model.p]), model.x_lower, model.x_upper)
    if not ok:
        return PoseSolution(
            Status.NOT_CONVERGED,
            iterations=iters,
            seconds=sec,
            solver=config.name,
            message=f"{config.name}: {msg or f'no convergence in {iters} iterations'}",
        )
    return _checked(model, x, qv, config.tolerance, iters, sec, config.name)


def _newton_step(model: Model, q: np.ndarray, x0: np.ndarray, config: SolverConfig, backend: str):
    """One Newton solve on Φ from x0 (the kernel's, no IK path): (x, status)."""
    call, index = _bound_fk(model, config, backend)
    outs = call(q, x0)
    code = int(outs[index[-1]][0])
    return outs[index[0]].copy(), STATUSES[code]


def continued_forward_kinematics(
    model: Model, q: Sequence[float], solver: SolverConfig | None = None, *, backend: str = "auto"
) -> PoseSolution:
    """FK by continuation in the inputs from home: q_k = q_home + (k/n)(q - q_home),
    each step's Newton solve warm-started from the previous pose, which stays on
    the designated branch while the path meets no singularity.  Tries n = 4, 16,
    64 steps in turn; the last pose is checked like any FK solution."""
    config = solver or SolverConfig()
    c = model.closure
    qv = _vector(q, c.nq, "q")
    newton = config if config.method == "newton" else SolverConfig("newton", tolerance=config.tolerance)
    if not batch_newton_supported(newton):
        newton = SolverConfig("newton", tolerance=config.tolerance)
    t0 = time.perf_counter()
    last = PoseSolution(Status.NOT_CONVERGED, message="the continuation from home did not reach q")
    for n in CONTINUATION_STEPS:
        x = model.x_home.copy()
        reached = True
        for k in range(1, n + 1):
            qk = model.q_home + (k / n) * (qv - model.q_home)
            xk, status = _newton_step(model, qk, x, newton, backend)
            if k < n and status not in _ON_PATH:
                reached = False
                break
            x = xk
        if not reached:
            continue
        sec = time.perf_counter() - t0
        sol = _checked(model, x, qv, config.tolerance, n, sec, f"{newton.name} (continuation from home, {n} steps)")
        sol.details["continuation_steps"] = n
        if sol.ok:
            return sol
        last = sol
    last.seconds = time.perf_counter() - t0
    return last


def reduce_angle(v: float, ranges: Sequence[tuple[float, float] | None]) -> float:
    """The angle v shifted by whole turns into the first finite range of ``ranges`` that
    holds one of its turns (v itself if it lies there, else its value in (-pi, pi] if that
    does, else its lowest turn there), else into (-pi, pi]."""
    r = math.pi - (math.pi - v) % (2 * math.pi)  # in (-pi, pi]
    for lim in ranges:
        if lim is None or not (math.isfinite(lim[0]) and math.isfinite(lim[1])):
            continue
        if lim[0] <= v <= lim[1]:
            return v
        if lim[0] <= r <= lim[1]:
            return r
        turns = math.ceil((lim[0] - r) / (2 * math.pi))
        if lim[0] <= r + 2 * math.pi * turns <= lim[1]:
            return r + 2 * math.pi * turns
    return r


def _angle_ranges(model: Model) -> list[tuple[bool, int, tuple, float, float]]:
    """The angle coordinates `reduce_angles` reduces, with their ranges, in its order (the
    actuators first): (in x, index, ranges, low, high), [low, high] the first finite range (a value
    there is kept: `reduce_angle`; (inf, -inf) when none is); built once per model (a single
    FK calls it each time)."""
    cached = model.__dict__.get("_angle_ranges")
    if cached is None:
        c = model.closure
        # an actuator without a declared range keeps its value (the solvers start from its home value)
        items = [
            (False, k, (model.limit_of(co),)) for k, co in enumerate(c.q) if co.kind == "angle" and model.limit_of(co)
        ]
        items += [
            (True, k, (model.limit_of(co), (model.x_lower[k], model.x_upper[k])))
            for k, co in enumerate(c.x)
            if co.kind == "angle"
        ]
        cached = []
        for in_x, k, ranges in items:
            finite = [lim for lim in ranges if lim is not None and math.isfinite(lim[0]) and math.isfinite(lim[1])]
            low, high = (float(finite[0][0]), float(finite[0][1])) if finite else (math.inf, -math.inf)
            cached.append((in_x, k, ranges, low, high))
        model.__dict__["_angle_ranges"] = cached
    return cached


def reduce_angles(model: Model, x: np.ndarray, q: np.ndarray, tolerance: float) -> tuple[np.ndarray, np.ndarray]:
    """The pose and the actuators with each angle coordinate reduced by whole turns
    (`reduce_angle`) to its declared range (its joint limits, else, for a pose
    coordinate, the bounds of the pose coordinates) if a turn of it lies there, else to
    (-pi, pi]; an actuator without a declared range, and a coordinate the closures are not
    periodic in (the residual grows, e.g. an actuator geared to its joint), keep their
    values.  Returns (x, q)."""
    out_x, out_q = np.array(x, dtype=float), np.array(q, dtype=float)
    limit = max(tolerance, 1e-12)
    values = (out_q.tolist(), out_x.tolist())  # each coordinate is read once, before it may change
    for in_x, k, ranges, low, high in _angle_ranges(model):
        v = values[in_x][k]
        if low <= v <= high:  # in its first finite range: kept (reduce_angle would return v)
            continue
        vec = out_x if in_x else out_q
        r = reduce_angle(v, ranges)
        if r == v:
            continue
        vec[k] = r
        if not np.max(np.abs(residual(model, out_x, out_q)), initial=0.0) <= limit:
            vec[k] = v
    return out_x, out_q


def inverse_kinematics(
    model: Model,
    t: Sequence[float],
    solver: SolverConfig | None = None,
    method: str = "auto",
) -> PoseSolution:
    """Actuated joints (and dependent pose coordinates) for task coordinates t.

    Parameters
    ----------
    t
        the model's task coordinates (closure.task), size nq.
    method
        "closed_form" (the paper's IK), "solve" (Φ = 0 for the dependent coordinates and q, by
        the configured solver), or "auto" (closed form when the model has one).
    """
    config = solver or SolverConfig()
    c = model.closure
    tv = _vector(t, c.nq, "t")
    if method not in ("auto", "closed_form", "solve"):
        raise InputError(f"unknown IK method {method!r}; expected auto, closed_form or solve", path=("method",))
    use_closed = c.ik is not None and method in ("auto", "closed_form")
    if method == "closed_form" and c.ik is None:
        raise InputError(
            f"mechanism {c.name} has no closed-form inverse kinematics; use method 'solve'", path=("method",)
        )
    if use_closed:
        t0 = time.perf_counter()
        x, q, reach = fast(c, ("ik",), lambda: c.ik)(tv, model.p)
        sec = time.perf_counter() - t0
        if not reach[0] >= 0:
            details = {"reach": float(reach[0])}
            message = failure_message(model, Status.UNREACHABLE, details, None, None, None, config.tolerance)
            return PoseSolution(Status.UNREACHABLE, seconds=sec, solver="closed_form", message=message, details=details)
        x, q = reduce_angles(model, np.asarray(x).ravel(), np.asarray(q).ravel(), config.tolerance)
        return _checked(model, x, q, config.tolerance, 0, sec, "closed_form")
    built = c.ik_solver(config)
    nd = len(c.dep_index)
    y0 = np.r_[model.x_home[c.dep_index], model.q_home]
    lower = np.r_[model.x_lower[c.dep_index], np.full(c.nq, -np.inf)]
    upper = np.r_[model.x_upper[c.dep_index], np.full(c.nq, np.inf)]
    y, ok, iters, msg, sec = built.solve(y0, np.r_[tv, model.p], lower, upper)
    if not ok:
        return PoseSolution(
            Status.NOT_CONVERGED,
            iterations=iters,
            seconds=sec,
            solver=config.name,
            message=f"{config.name}: {msg or f'no convergence in {iters} iterations'}",
        )
    # angles reduced by whole turns into their declared ranges before the limit check (issue 20)
    x, q = reduce_angles(model, c.assemble_x(tv, y[:nd]), y[nd:], config.tolerance)
    return _checked(model, x, q, config.tolerance, iters, sec, config.name)


@dataclass
class JacobianReport:
    """Differential kinematics at one pose (all from AD of Φ).

    phi_x (nx x nx), phi_q (nx x nq);
    J = -Φ_x⁻¹ Φ_q (nx x nq): pose rates from actuator rates;

    Attributes
    ----------
    J_task
        (nq x nq) the task rows of J;
    J_inv
        (nq x nq) actuator rates from task rates, from Φ with the dependent coordinates and q as
        unknowns (equals J_task⁻¹);
    det_phi_x
        zero at forward (type II) singularities;
    det_phi_y
        zero at inverse (type I) singularities;
    cond, manipulability
        condition number and Yoshikawa's sqrt(det(J Jᵀ)) of J_task with angle rows multiplied by
        ``characteristic_length`` so that every row is a length rate (the measures are then
        dimensionless).
    """

    phi_x: np.ndarray
    phi_q: np.ndarray
    J: np.ndarray
    J_task: np.ndarray
    J_inv: np.ndarray
    det_phi_x: float
    det_phi_y: float
    cond: float
    manipulability: float
    characteristic_length: float


def jacobians(
    model: Model, x: Sequence[float], q: Sequence[float], characteristic_length: float | None = None
) -> JacobianReport:
    """Jacobians and singularity measures at the pose (x, q).

    characteristic_length: length that turns angle rates into length rates for
    ``cond`` and ``manipulability`` (default: the model's, e.g. b for the 3-PRS).
    """
    c = model.closure
    xv = _vector(x, c.nx, "x")
    qv = _vector(q, c.nq, "q")
    p = model.p
    phi_x = np.asarray(c.phi_x(xv, qv, p))
    phi_q = np.asarray(c.phi_q(xv, qv, p))
    J = np.asarray(c.jacobian(xv, qv, p))
    J_inv = np.asarray(c.inverse_jacobian(xv, qv, p))
    J_task = J[c.task_index, :]
    lc = model.characteristic_length if characteristic_length is None else float(characteristic_length)
    weights = np.array([lc if c.x[i].kind == "angle" else 1.0 for i in c.task_index])
    Jh = weights[:, None] * J_task
    sv = np.linalg.svd(Jh, compute_uv=False)
    cond = float(sv[0] / sv[-1]) if sv[-1] > 0 else float("inf")
    manip = float(np.sqrt(max(np.linalg.det(Jh @ Jh.T), 0.0)))
    return JacobianReport(
        phi_x=phi_x,
        phi_q=phi_q,
        J=J,
        J_task=J_task,
        J_inv=J_inv,
        det_phi_x=float(np.linalg.det(phi_x)),
        det_phi_y=float(np.linalg.det(np.asarray(c.phi_y(xv, qv, p)))),
        cond=cond,
        manipulability=manip,
        characteristic_length=float(lc),
    )
