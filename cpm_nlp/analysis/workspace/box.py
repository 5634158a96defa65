"""The image of the actuator-stroke box under the forward kinematics."""

from __future__ import annotations

import itertools
import logging
import time
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from ...core.errors import InputError
from ...core.kinematics import PoseSolution, forward_kinematics
from ...core.model import Model
from ...core.result import Status, worst_status
from ...core.solver import SolverConfig
from ..requirements import full_factorial

log = logging.getLogger(__name__)

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
