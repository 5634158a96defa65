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

#: FK statuses of an actuator value where no pose was found: taken as not assembling
#: (see `_partial`); any other failure (a branch change, a singularity) is reported as such
NOT_ASSEMBLED = (Status.NOT_CONVERGED, Status.INFEASIBLE)

# -- the image of the actuator-stroke box (FK) ----------------------------------------------------


def joint_box(model: Model) -> tuple[np.ndarray, np.ndarray]:
    """(low, high) of every actuator from the model's limits; an
    [`InputError`][cpm_nlp.core.errors.InputError] naming the missing ``mechanism.limits`` key if one has none."""
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
    """The 2^n corners of a box, in the order of `box_grid` with count 2."""
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

    Attributes
    ----------
    q, t
        the grid over the stroke box and its images, shape (N, nq) (rows of t are NaN where FK
        failed);
    solutions
        the FK of every grid point.
    vertices
        images of the box corners, shape (2^nq, nq).
    lower, upper
        axis-aligned bounding box of the grid images.
    volume
        the integral of |det(dt/dq)| over the box (Gauss-Legendre), i.e. the volume of the
        workspace if FK is one-to-one on the box, which holds when det(dt/dq) keeps its sign
        (checked at every grid and quadrature point).
    linear_volume
        |det J_task(home)| times the volume of the stroke box: the volume of the linearized
        workspace (for the 3-PRC the cube (A2 q_max)^3 of eq 26).
    jacobian_deviation
        the largest entry of |J_inv - J_inv(home)| over the grid, each column scaled by its
        largest entry at home (dimensionless; zero for a linear mechanism).
    linear_error
        per task coordinate, the largest |t - t_lin| over the grid, t_lin = t_home +
        J_task(home) (q - q_home) the linearization at home. None (or empty) unless ``status``
        is solved.
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
    stroke box (`joint_box`), and the volume by ``quadrature``^nq
    Gauss-Legendre points (see `WorkspaceReport`)."""
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
    if bad and all(sols[k].status in NOT_ASSEMBLED for k in bad):  # no pose found (a fold or branch change: below)
        _partial(model, report, low, high, samples, config, J0, Jinv0)
        report.seconds = time.perf_counter() - t0
        return report
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


# -- strokes that partly assemble -----------------------------------------------------------------


def _grid_index(qs: np.ndarray, low: np.ndarray, high: np.ndarray, samples: int) -> dict[tuple, int]:
    """multi-index (one 0..samples-1 per actuator) -> row of the grid."""
    step = np.where(high > low, (high - low) / (samples - 1), 1.0)
    return {tuple(i): k for k, i in enumerate(np.rint((qs - low) / step).astype(int))}


def _continue_from_neighbours(model, qs, sols, index, config) -> None:
    """Retry FK at each unsolved grid point from the pose of every solved grid neighbour
    (one step along one actuator), until no retry succeeds (in place)."""
    changed = True
    while changed:
        changed = False
        for i, k in index.items():
            if sols[k].ok:
                continue
            for j in _neighbours(i, index):
                if sols[j].ok:
                    s = forward_kinematics(model, qs[k], config, guess=sols[j].x)
                    if s.ok:
                        sols[k], changed = s, True
                        break


def _neighbours(i: tuple, index: dict[tuple, int]) -> list[int]:
    out = []
    for a in range(len(i)):
        for d in (-1, 1):
            n = i[:a] + (i[a] + d,) + i[a + 1 :]
            if n in index:
                out.append(index[n])
    return out


def _partial(model, report, low, high, samples, config, J0, Jinv0) -> None:
    """The workspace of a stroke box that partly assembles (fills ``report``).

    FK at an unsolved grid point is retried from the poses of its solved neighbours; what
    is still unsolved is taken as not assembling, unless every grid neighbour of it
    assembles (a hole: an FK failure cannot be told from non-assembly there), or no grid
    point assembles: both keep a failure status.  The volume is the midpoint rule on the
    grid's cells: |det(dt/dq)| at the centre of every cell whose centre assembles, times
    the cell's volume.  A cell whose corners do not all assemble straddles the border of
    assembly; the sum over those cells of the cell volume times the largest |det| at its
    assembled corners and centre is ``details["volume_border"]``: the volume's error
    from the border is of that order (it shrinks with the cell size, as 1/samples); where it
    is not below the volume, the grid does not resolve the part that assembles: a failure."""
    c = model.closure
    qs, sols = report.q, report.solutions
    index = _grid_index(qs, low, high, samples)
    _continue_from_neighbours(model, qs, sols, index, config)
    ok = np.array([s.ok for s in sols])
    report.t = np.array([model.task_of(s.x) if s.ok else np.full(c.nq, np.nan) for s in sols])
    bad = np.flatnonzero(~ok)
    first = f"first, q = {qs[bad[0]].tolist()}: {sols[bad[0]].status.value}" if bad.size else ""
    if not ok.any():
        report.status = worst_status([s.status for s in sols])
        report.message = f"no grid point of the stroke box assembles ({len(sols)} tried; {first})"
        return
    holes = [k for i, k in index.items() if not ok[k] and all(ok[j] for j in _neighbours(i, index))]
    if holes:
        report.status = Status.NOT_CONVERGED
        report.message = (
            f"FK did not converge at q = {qs[holes[0]].tolist()}, where every grid neighbour assembles: "
            "an FK failure cannot be told from non-assembly there"
        )
        return
    step = (high - low) / (samples - 1)
    cell_volume = float(np.prod(step))
    det = lambda s: float(np.linalg.det(np.asarray(c.jacobian(s.x, s.q, model.p))[c.task_index, :]))  # noqa: E731
    dets = [det(sols[k]) for k in np.flatnonzero(ok)]
    rank = np.cumsum(ok) - 1  # grid row -> its place among the assembled rows (in dets)
    volume, border = 0.0, 0.0
    for base in itertools.product(range(samples - 1), repeat=c.nq):
        corners = [index[tuple(b + o for b, o in zip(base, off))] for off in itertools.product((0, 1), repeat=c.nq)]
        assembled = [k for k in corners if ok[k]]
        if not assembled:
            continue
        centre = low + (np.array(base) + 0.5) * step
        s = forward_kinematics(model, centre, config, guess=sols[assembled[0]].x)
        local = [abs(dets[rank[k]]) for k in assembled]
        if s.ok:
            d = det(s)
            dets.append(d)
            volume += abs(d) * cell_volume
            local.append(abs(d))
        elif s.status not in NOT_ASSEMBLED or len(assembled) == len(corners):
            report.status = s.status if s.status not in NOT_ASSEMBLED else Status.NOT_CONVERGED
            report.message = f"FK at the cell centre q = {centre.tolist()}: {s.status.value}" + (
                ""
                if s.status not in NOT_ASSEMBLED
                else ", though the cell's corners all assemble: an FK failure cannot be told from non-assembly"
            )
            return
        if len(assembled) < len(corners):
            border += max(local) * cell_volume
    dets = np.array(dets)
    if not (np.all(dets > 0) or np.all(dets < 0)):
        report.status = Status.SINGULAR
        report.message = "det(dt/dq) changes sign (or vanishes) where the stroke box assembles: the workspace folds"
        return
    if border >= volume:
        report.status = Status.NOT_CONVERGED
        report.message = (
            f"{bad.size} of {len(sols)} grid points do not assemble and the grid does not resolve the part "
            f"that does (volume {volume:.6g} against {border:.6g} in cells across its border): raise inputs.samples"
        )
        return
    ts = report.t[ok]
    report.status = Status.SOLVED
    report.volume = volume
    report.linear_volume = float(abs(np.linalg.det(J0[c.task_index, :])) * np.prod(high - low))
    corner_idx = [index[tuple(int(v) for v in o)] for o in itertools.product((0, samples - 1), repeat=c.nq)]
    report.vertices = report.t[[k for k in corner_idx if ok[k]]]
    report.lower, report.upper = ts.min(axis=0), ts.max(axis=0)
    t_lin = model.task_of(model.x_home) + (qs[ok] - model.q_home) @ J0[c.task_index, :].T
    report.linear_error = np.max(np.abs(ts - t_lin), axis=0)
    scale = np.max(np.abs(Jinv0), axis=0)
    dev = [np.max(np.abs(np.asarray(c.inverse_jacobian(s.x, s.q, model.p)) - Jinv0) / scale) for s in sols if s.ok]
    report.jacobian_deviation = float(max(dev))
    report.details = {
        "det_min": float(np.min(np.abs(dets))),
        "det_max": float(np.max(np.abs(dets))),
        "not_assembled": int(bad.size),
        "not_assembled_fraction": float(bad.size / len(sols)),
        "volume_border": border,
    }
    report.message = (
        f"{bad.size} of {len(sols)} grid points ({samples} per actuator) do not assemble ({first}); "
        f"the workspace is the image of the rest, its volume the midpoint rule on the {samples - 1}^{c.nq} cells"
    )
