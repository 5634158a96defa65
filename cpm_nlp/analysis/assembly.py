"""All assembly modes: every distinct real solution of the forward kinematics
that a seeded multi-start Newton search finds, for any mechanism.

For given actuators q the loop closures Φ(x, q; p) = 0 usually have several
real solutions x (the assembly modes: up to 40 for a 6-UPS Stewart-Gough
platform, two for a planar five-bar, several for a 3-PRS whose legs can flip).
The model designates one of them (its branch indicators, its closed-form IK);
the FK of a problem file reports only that one.  :func:`assembly_modes` finds
the others, so that a designer sees how far the working mode is from them.

Method
------
1. ``starts`` initial poses are drawn (seeded, uniform) in the search region,
   the box ``[model.x_lower, model.x_upper]`` that IPOPT also uses (an
   unbounded side is replaced by the home pose ± the largest finite span of
   the coordinates of its kind, or ± 1 SI unit); the home pose is the first.
2. Newton's method runs from every start at once (the FK kernel of
   :mod:`cpm_nlp.core.batch`, CasADi ``fast_newton``, mapped over threads).
3. Angle coordinates of the converged poses are wrapped into the ±π interval
   about the middle of the region (a closure periodic in an angle gives the
   same pose; one that is not keeps its unwrapped value, see step 5); poses
   outside the region are dropped and counted.
4. The remaining poses are merged when they agree within ``merge_tolerance``
   (lengths divided by the region's largest length span, angles in radians).
5. Each distinct pose is checked like any FK solution (:func:`~cpm_nlp.core.kinematics.assess`:
   residual, branch indicators, IK round trip, conditioning, joint limits)
   and reported with its branch indicators and whether it lies on the
   designated branch.

The working mode is the solution of the ordinary FK (the configured solver
from the home pose, or the given guess).  Its distance to the nearest other
mode is reported in the lengths (m) and angles (rad) of the pose.

The search is **not a proof of completeness**: a mode whose basin of
attraction holds none of the starts, or that lies outside the search region,
is missed.  The result says so, with the number of starts that reached each
mode (a mode reached by few starts suggests others may hide in small basins).
"""

from __future__ import annotations

import logging
import math
import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..core import progress
from ..core.batch import batch_forward_kinematics
from ..core.errors import InputError
from ..core.kernels import ROUND_TRIP_FACTOR, STATUSES
from ..core.kinematics import PoseSolution, assess, forward_kinematics, passive_joints
from ..core.model import Model
from ..core.result import Status
from ..core.solver import SolverConfig

log = logging.getLogger(__name__)

#: two converged poses within this (scaled) distance are the same mode
MERGE_TOLERANCE = 1e-6
#: starts per mapped Newton call of the search (about 0.1 s: a Ctrl-C stops the search that soon)
SEARCH_CHUNK = 256
#: rows of a block of the merge, and most distances computed at once
MERGE_BLOCK, MERGE_CELLS = 8192, 1 << 22
#: a converged pose may lie this far (scaled) outside the search region and still count
REGION_SLACK = 1e-9
#: statuses of converged real solutions (the others: Newton did not reach a solution)
REAL = (Status.SOLVED, Status.WRONG_BRANCH, Status.OUTSIDE_JOINT_LIMITS, Status.SINGULAR)

COMPLETENESS_NOTE = (
    "a multi-start search, not a proof of completeness: modes whose basins hold none of the starts, "
    "or that lie outside the search region, are not found"
)


@dataclass
class AssemblyMode:
    """One assembly mode: the pose, its check and its branch indicators.

    status: as an FK solution would report it (``wrong_branch`` off the
    designated branch); designated: on the branch the model designates
    (branch indicators > 0 and the closed-form IK round trip agrees);
    branch: the branch indicator values (empty without indicators);
    basin: the number of starts that converged to it.
    """

    x: np.ndarray
    q: np.ndarray
    passive: dict[str, float]
    status: Status
    message: str
    residual: float
    branch: np.ndarray
    designated: bool
    basin: int


@dataclass
class AssemblyModes:
    """The distinct assembly modes found for one actuator vector.

    modes: found, the working mode (if any) first, then by basin size;
    working: index of the working mode in ``modes`` (None if the ordinary FK
    failed); nearest: index of the mode nearest to the working one;
    distance_length (m), distance_angle (rad): Euclidean distances of the
    length and angle coordinates of the pose between them;
    starts, converged, outside_region: how many starts ran, converged to a real
    solution, and converged outside the search region (dropped);
    region: the search region (x_lower, x_upper).
    """

    q: np.ndarray
    modes: list[AssemblyMode]
    working: int | None
    working_solution: PoseSolution
    nearest: int | None
    distance_length: float | None
    distance_angle: float | None
    starts: int
    converged: int
    outside_region: int
    region: tuple[np.ndarray, np.ndarray]
    seconds: float
    note: str = COMPLETENESS_NOTE
    details: dict = field(default_factory=dict)

    @property
    def count(self) -> int:
        return len(self.modes)


def search_region(model: Model) -> tuple[np.ndarray, np.ndarray]:
    """The box the starts are drawn from: the IPOPT bounds, unbounded sides
    replaced by home ± the largest finite span of that kind (or ± 1)."""
    c = model.closure
    lo, hi = model.x_lower.astype(float).copy(), model.x_upper.astype(float).copy()
    kinds = np.array([x.kind for x in c.x])
    for kind in set(kinds.tolist()):
        idx = np.flatnonzero(kinds == kind)
        spans = (hi - lo)[idx]
        finite = spans[np.isfinite(spans)]
        span = float(finite.max()) if finite.size else 1.0
        for i in idx:
            if not np.isfinite(lo[i]):
                lo[i] = model.x_home[i] - span
            if not np.isfinite(hi[i]):
                hi[i] = model.x_home[i] + span
    return lo, hi


def _scales(model: Model, region: tuple[np.ndarray, np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """Per-coordinate divisors for distances (lengths by the largest length span,
    angles 1) and the mask of angle coordinates."""
    c = model.closure
    angle = np.array([x.kind == "angle" for x in c.x])
    span = region[1] - region[0]
    scale = np.ones(c.nx)
    for kind in {x.kind for x in c.x} - {"angle"}:
        idx = [i for i, x in enumerate(c.x) if x.kind == kind]
        scale[idx] = max(float(np.max(span[idx])), 1e-300)
    return scale, angle


def _wrap(X: np.ndarray, angle: np.ndarray, centre: np.ndarray) -> np.ndarray:
    out = X.copy()
    a = np.flatnonzero(angle)
    out[:, a] = centre[a] + (X[:, a] - centre[a] + math.pi) % (2 * math.pi) - math.pi
    return out


def _merge(X: np.ndarray, scale: np.ndarray, angle: np.ndarray, tol: float) -> tuple[list[int], np.ndarray]:
    """Greedy clustering of the rows of X: (index of each cluster's first row, cluster of each row).

    Row k joins the nearest cluster (the first of equally near ones) whose
    first row is within ``tol``, among the clusters started before it, or
    starts one.  The rows are taken in blocks (vectorized: a million converged
    starts merge in seconds), with the result of a row-by-row loop."""
    reps: list[int] = []
    label = np.empty(len(X), dtype=int)
    Y = X / scale

    def dist(a: np.ndarray, b: np.ndarray) -> np.ndarray:
        diff = a[:, None, :] - b[None, :, :]
        diff[:, :, angle] = (diff[:, :, angle] + math.pi) % (2 * math.pi) - math.pi
        return np.max(np.abs(diff), axis=2)

    with progress.task("merging the converged starts", len(Y)) as report:
        k = 0
        while k < len(Y):
            k = _merge_block(Y, k, reps, label, dist, tol)
            report.update(k)
    return reps, label


def _merge_block(Y: np.ndarray, k: int, reps: list[int], label: np.ndarray, dist: Any, tol: float) -> int:
    """Merge the block of rows from ``k`` (see :func:`_merge`); the first row after it."""
    size = max(1, min(MERGE_BLOCK, MERGE_CELLS // max(1, len(reps) * Y.shape[1])))
    block = Y[k : k + size]
    if reps:
        d = dist(block, Y[reps])
        near, best = np.argmin(d, axis=1), np.min(d, axis=1)
    else:
        near, best = np.full(len(block), -1), np.full(len(block), np.inf)
    i = 0
    while i < len(block):
        far = np.flatnonzero(best[i:] > tol)
        stop = i + int(far[0]) if far.size else len(block)
        label[k + i : k + stop] = near[i:stop]
        if stop == len(block):
            break
        label[k + stop] = len(reps)  # a new cluster: the rows after it compare with it too
        reps.append(k + stop)
        rest = slice(stop + 1, len(block))
        dn = dist(block[rest], block[stop : stop + 1])[:, 0]
        closer = dn < best[rest]
        best[rest] = np.where(closer, dn, best[rest])
        near[rest] = np.where(closer, len(reps) - 1, near[rest])
        i = stop + 1
    return k + len(block)


def _distances(model: Model, a: np.ndarray, b: np.ndarray) -> tuple[float, float]:
    c = model.closure
    angle = np.array([x.kind == "angle" for x in c.x])
    d = b - a
    d[angle] = (d[angle] + math.pi) % (2 * math.pi) - math.pi
    return float(np.linalg.norm(d[~angle])), float(np.linalg.norm(d[angle]))


def _mode(model: Model, x: np.ndarray, q: np.ndarray, tolerance: float, basin: int) -> AssemblyMode:
    c = model.closure
    status, message, details = assess(model, x, q, tolerance)
    branch = np.asarray(c.branch(x, q, model.p)).ravel() if c.branch is not None else np.zeros(0)
    on_branch = bool(np.all(branch > 0)) and details.get("round_trip_error", 0.0) <= ROUND_TRIP_FACTOR * tolerance
    return AssemblyMode(
        x=np.asarray(x, dtype=float),
        q=np.asarray(q, dtype=float),
        passive=passive_joints(model, x, q),
        status=status,
        message=message,
        residual=float(details.get("residual", np.nan)),
        branch=branch,
        designated=on_branch,
        basin=basin,
    )


def assembly_modes(  # noqa: C901 - one pipeline: starts, Newton, wrap, merge, check, working mode
    model: Model,
    q,
    solver: SolverConfig | None = None,
    *,
    starts: int = 2000,
    seed: int = 0,
    guess=None,
    merge_tolerance: float = MERGE_TOLERANCE,
    backend: str = "map",
    threads: int | None = None,
) -> AssemblyModes:
    """Every distinct real FK solution found for the actuators q (see the module docstring).

    solver: its tolerance accepts a pose, and (IPOPT or Newton) it solves the
    ordinary FK that gives the working mode; the search itself is Newton's
    method (the kernels' ``fast_newton``, with the solver's Newton options
    when it is a Newton configuration).
    """
    config = solver or SolverConfig()
    c = model.closure
    qv = np.asarray(q, dtype=float).ravel()
    if qv.size != c.nq or not np.all(np.isfinite(qv)):
        raise InputError(f"expected {c.nq} finite actuator values, got {np.asarray(q).tolist()}", path=("q",))
    if int(starts) < 1:
        raise InputError(f"expected at least 1 start, got {starts}", path=("starts",))
    t0 = time.perf_counter()
    region = search_region(model)
    lo, hi = region
    rng = np.random.default_rng(seed)
    X0 = lo + (hi - lo) * rng.random((int(starts), c.nx))
    X0[0] = model.x_home if guess is None else np.asarray(guess, dtype=float)
    newton = config if config.method == "newton" else SolverConfig("newton", tolerance=config.tolerance)
    res = batch_forward_kinematics(
        model,
        np.broadcast_to(qv, (len(X0), c.nq)),
        newton,
        X0,
        backend=backend,
        threads=threads,
        chunk=SEARCH_CHUNK,
        what="assembly-mode search",
    )
    statuses = [STATUSES[int(k)] for k in res.status]
    real = np.array([s in REAL for s in statuses])
    X = res.x.copy() if res.raw_joints is None else res.raw_joints[:, : c.nx].copy()
    X = X[real]
    scale, angle = _scales(model, region)
    centre = 0.5 * (lo + hi)
    Xw = _wrap(X, angle, centre) if angle.any() else X
    slack = REGION_SLACK * scale
    inside = np.all((Xw >= lo - slack) & (Xw <= hi + slack), axis=1)
    # a closure that is not periodic in an angle: keep the unwrapped pose where it lies inside
    inside_raw = np.all((X >= lo - slack) & (X <= hi + slack), axis=1)
    Xw[~inside & inside_raw] = X[~inside & inside_raw]
    keep = inside | inside_raw
    outside = int(np.count_nonzero(~keep))
    Xk, Xr = Xw[keep], X[keep]
    reps, label = _merge(Xk, scale, angle, merge_tolerance)
    modes = []
    for j, k in enumerate(reps):
        basin = int(np.count_nonzero(label == j))
        mode = _mode(model, Xk[k], qv, config.tolerance, basin)
        if mode.status is Status.RESIDUAL_TOO_LARGE:  # the wrapped angle broke the closure: not periodic
            mode = _mode(model, Xr[k], qv, config.tolerance, basin)
        if mode.status in REAL:
            modes.append(mode)
    work = forward_kinematics(model, qv, config, guess)
    working = None
    if work.ok:
        xw = _wrap(work.x[None, :], angle, centre)[0] if angle.any() else work.x
        dist = [np.max(np.abs(_wrapped_diff(m.x - xw, angle) / scale)) for m in modes]
        j = int(np.argmin(dist)) if dist else -1
        if j >= 0 and dist[j] <= max(merge_tolerance, 1e3 * config.tolerance / float(np.min(scale))):
            working = j
        else:  # the ordinary FK found a mode the search missed
            log.info("the working mode was not among the modes of the search; added")
            modes.append(_mode(model, work.x, qv, config.tolerance, 0))
            working = len(modes) - 1
    order = sorted(range(len(modes)), key=lambda i: (i != working, -modes[i].basin))
    modes = [modes[i] for i in order]
    working = 0 if working is not None else None
    nearest = dl = da = None
    if working is not None and len(modes) > 1:
        scaled = [np.linalg.norm(_wrapped_diff(m.x - modes[0].x, angle) / scale) for m in modes[1:]]
        nearest = 1 + int(np.argmin(scaled))
        dl, da = _distances(model, modes[0].x, modes[nearest].x)
    return AssemblyModes(
        q=qv,
        modes=modes,
        working=working,
        working_solution=work,
        nearest=nearest,
        distance_length=dl,
        distance_angle=da,
        starts=int(starts),
        converged=int(np.count_nonzero(real)),
        outside_region=outside,
        region=region,
        seconds=time.perf_counter() - t0,
        details={"merge_tolerance": merge_tolerance, "backend": res.backend, "newton_seconds": res.seconds},
    )


def _wrapped_diff(d: np.ndarray, angle: np.ndarray) -> np.ndarray:
    out = np.array(d, dtype=float)
    out[angle] = (out[angle] + math.pi) % (2 * math.pi) - math.pi
    return out
