"""Kinematics algorithms: free functions over a :class:`~cpm_nlp.model.Model`.

* :func:`forward_kinematics` -- x from q, by IPOPT (default) or Newton;
* :func:`inverse_kinematics` -- q (and the dependent pose coordinates) from
  the task coordinates, in closed form where the paper gives one, else solved;
* :func:`jacobians` -- Φ_x, Φ_q, forward and inverse Jacobians and singularity
  measures, all from algorithmic differentiation of Φ;
* :func:`passive_joints` -- passive joint angles of a pose;
* :func:`assess` -- the checks every pose passes before it is reported solved.

Sizes: nx = pose coordinates, nq = actuated joints (= task coordinates).
"""

from __future__ import annotations

import logging
import time
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from .errors import InputError
from .model import Model
from .result import Status
from .solver import SolverConfig

log = logging.getLogger(__name__)

#: FK/IK round trips must agree to this multiple of the residual tolerance.
ROUND_TRIP_FACTOR = 100.0
#: Φ_x (or Φ_y) with a larger condition number is reported singular.
SINGULAR_CONDITION = 1e10


@dataclass
class PoseSolution:
    """Outcome of one FK or IK solve.

    x: pose, size nx; q: actuated joints, size nq; passive: passive joint
    angles (model.closure.passive_names).  All three are None unless
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

    @property
    def ok(self) -> bool:
        return self.status.ok


def _vector(values, n: int, name: str) -> np.ndarray:
    arr = np.asarray(values, dtype=float).ravel()
    if arr.size != n:
        raise InputError(f"expected {n} values, got {arr.size}", path=(name,))
    if not np.all(np.isfinite(arr)):
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


def assess(model: Model, x: np.ndarray, q: np.ndarray, tolerance: float) -> tuple[Status, str, dict]:
    """Check a candidate pose: residual, assembly branch, IK round trip,
    singularity, joint limits.  Returns (status, message, details)."""
    c = model.closure
    details: dict = {}
    if not (np.all(np.isfinite(x)) and np.all(np.isfinite(q))):
        return Status.NOT_CONVERGED, "the solver returned non-finite values", details
    res = float(np.max(np.abs(residual(model, x, q))))
    details["residual"] = res
    if res > tolerance:
        return (
            Status.RESIDUAL_TOO_LARGE,
            f"max |Φ| = {res:.3g} {c.residual_unit} > tolerance {tolerance:.3g} {c.residual_unit}",
            details,
        )
    if c.branch is not None:
        g = np.asarray(c.branch(x, q, model.p)).ravel()
        details["branch_margin"] = float(g.min())
        if g.min() <= 0:
            return Status.WRONG_BRANCH, f"branch indicator {g.min():.3g} <= 0", details
    if c.ik is not None:
        x_ik, q_ik, reach = (np.asarray(v).ravel() for v in c.ik(model.task_of(x), model.p))
        err = max(float(np.max(np.abs(q_ik - q))), float(np.max(np.abs(x_ik - x))))
        details["round_trip_error"] = err
        if not (reach[0] >= 0 and err <= ROUND_TRIP_FACTOR * tolerance):
            return (
                Status.WRONG_BRANCH,
                f"closed-form IK of this pose gives other joints (max difference {err:.3g})",
                details,
            )
    cond = float(np.linalg.cond(np.asarray(c.phi_x(x, q, model.p))))
    details["cond_phi_x"] = cond
    if not cond < SINGULAR_CONDITION:
        return Status.SINGULAR, f"cond(Φ_x) = {cond:.3g}", details
    passive = np.asarray(c.passive(x, q, model.p)).ravel() if c.passive is not None else None
    bad = _limit_violations(model, x, q, passive)
    if bad:
        return Status.OUTSIDE_JOINT_LIMITS, "; ".join(bad), details
    return Status.SOLVED, "", details


def _finish(
    model: Model, status: Status, x, q, message: str, details: dict, iterations: int, seconds: float, solver: str
) -> PoseSolution:
    if status is Status.SOLVED:
        passive = np.asarray(model.closure.passive(x, q, model.p)).ravel() if model.closure.passive else None
        return PoseSolution(
            status, x, q, passive, details.get("residual", float("nan")), iterations, seconds, solver, message, details
        )
    return PoseSolution(
        status, None, None, None, details.get("residual", float("nan")), iterations, seconds, solver, message, details
    )


def forward_kinematics(
    model: Model,
    q: Sequence[float],
    solver: SolverConfig | None = None,
    guess: Sequence[float] | None = None,
) -> PoseSolution:
    """Solve Φ(x, q; p) = 0 for the pose x.

    q: actuated joints, size nq (SI).  guess: initial pose, size nx (default:
    the home pose).  The answer is checked (:func:`assess`) before it is
    reported solved.
    """
    config = solver or SolverConfig()
    c = model.closure
    qv = _vector(q, c.nq, "q")
    x0 = model.x_home if guess is None else _vector(guess, c.nx, "guess")
    built = c.fk_solver(config)
    x, ok, iters, msg, sec = built.solve(x0, np.r_[qv, model.p], model.x_lower, model.x_upper)
    if not ok:
        return PoseSolution(
            Status.NOT_CONVERGED, iterations=iters, seconds=sec, solver=config.name, message=f"{config.name}: {msg}"
        )
    status, message, details = assess(model, x, qv, config.tolerance)
    return _finish(model, status, x, qv, message, details, iters, sec, config.name)


def inverse_kinematics(
    model: Model,
    t: Sequence[float],
    solver: SolverConfig | None = None,
    method: str = "auto",
) -> PoseSolution:
    """Actuated joints (and dependent pose coordinates) for task coordinates t.

    t: the model's task coordinates (closure.task), size nq.
    method: "closed_form" (the paper's IK), "solve" (Φ = 0 for the
    dependent coordinates and q, by the configured solver), or "auto"
    (closed form when the model has one).
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
        x, q, reach = (np.asarray(v).ravel() for v in c.ik(tv, model.p))
        sec = time.perf_counter() - t0
        if not reach[0] >= 0:
            return PoseSolution(
                Status.UNREACHABLE,
                seconds=sec,
                solver="closed_form",
                message=f"the closed-form IK has no real solution (reach margin {reach[0]:.3g} < 0)",
                details={"reach": float(reach[0])},
            )
        status, message, details = assess(model, x, q, config.tolerance)
        return _finish(model, status, x, q, message, details, 0, sec, "closed_form")
    built = c.ik_solver(config)
    nd = len(c.dep_index)
    y0 = np.r_[model.x_home[c.dep_index], model.q_home]
    lower = np.r_[model.x_lower[c.dep_index], np.full(c.nq, -np.inf)]
    upper = np.r_[model.x_upper[c.dep_index], np.full(c.nq, np.inf)]
    y, ok, iters, msg, sec = built.solve(y0, np.r_[tv, model.p], lower, upper)
    if not ok:
        return PoseSolution(
            Status.NOT_CONVERGED, iterations=iters, seconds=sec, solver=config.name, message=f"{config.name}: {msg}"
        )
    x = c.assemble_x(tv, y[:nd])
    q = y[nd:]
    status, message, details = assess(model, x, q, config.tolerance)
    return _finish(model, status, x, q, message, details, iters, sec, config.name)


@dataclass
class JacobianReport:
    """Differential kinematics at one pose (all from AD of Φ).

    phi_x (nx x nx), phi_q (nx x nq);
    J = -Φ_x⁻¹ Φ_q (nx x nq): pose rates from actuator rates;
    J_task (nq x nq): the task rows of J;
    J_inv (nq x nq): actuator rates from task rates, from Φ with the
    dependent coordinates and q as unknowns (equals J_task⁻¹);
    det_phi_x: zero at forward (type II) singularities;
    det_phi_y: zero at inverse (type I) singularities;
    cond, manipulability: condition number and Yoshikawa's sqrt(det(J Jᵀ)) of
    J_task with angle rows multiplied by ``characteristic_length`` so that
    every row is a length rate (the measures are then dimensionless).
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
