"""All assembly modes: every distinct real solution of the forward kinematics
that a seeded multi-start Newton search finds, for any mechanism.

For given actuators q the loop closures Φ(x, q; p) = 0 usually have several
real solutions x (the assembly modes: up to 40 for a 6-UPS Stewart-Gough
platform, two for a planar five-bar, several for a 3-PRS whose legs can flip).
The model designates one of them (its branch indicators, its closed-form IK);
the FK of a problem file reports only that one.  [`assembly_modes`][cpm_nlp.analysis.assembly.assembly_modes] finds
the others, so that a designer sees how far the working mode is from them.

Method
------
1. The search region (`search_region`) needs no bounds from the user:
   every angle coordinate takes a full turn (-pi, pi] (the closures are
   periodic in it), every length coordinate the home value ± the reach (the
   largest of the declared half-span, the characteristic length, the
   distances of the home pose and the lengths among the actuators).
   ``starts`` initial poses are drawn there (seeded, uniform); the home pose
   is the first.
2. From every start at once, `DAMPED_STEPS` Newton steps, each shortened
   to `STEP_LIMIT` (one radian in an angle, one reach in a length;
   `damped_newton`), then Newton's method (the FK kernel of
   `cpm_nlp.core.batch`, CasADi ``fast_newton``, mapped over threads).
3. Angle coordinates of the converged poses are reduced to (-pi, pi] (one
   the closures are not periodic in keeps its value).  Every converged real
   solution is a mode, wherever it lies: a solution outside the start box is
   kept and counted.
4. Poses are merged on SE(3), not on angles: by the platform's rotation
   matrix and position (the closure's ``frame``) and the other coordinates
   (angles by their sine and cosine), within ``merge_tolerance`` (lengths
   divided by the reach).  Without a ``frame`` the coordinates are compared
   with angles wrapped (two angle triples of one rotation then stay two
   modes).
5. Each distinct pose is checked like any FK solution ([`assess`][cpm_nlp.core.kinematics.assess]:
   residual, branch indicators, IK round trip, conditioning, joint limits)
   and reported with its residual, status, branch indicators, whether it lies
   on the designated branch, and how many starts reached it.
6. The counts give a completeness estimate (`completeness`): Chao1's
   estimate of the modes no start reached, from the modes reached once and
   twice, Good-Turing's probability that one more start finds a new mode, and
   the starts a 99 % chance of reaching the smallest basin seen would take.

The working mode is the solution of the ordinary FK (the configured solver
from the home pose or the given guess, with the continuation from home).  A
failure of that FK is its own status, not the search's: the search that ran
is ``solved`` with the modes it found.

The search is **not a proof of completeness**: a mode whose basin holds none
of the starts is missed.  The result says how likely that is from the counts.
"""

from __future__ import annotations

import logging
import math
import time
from dataclasses import dataclass, field
from typing import Any

import casadi as ca
import numpy as np

from ..core import progress
from ..core.batch import batch_forward_kinematics, evaluate
from ..core.errors import InputError
from ..core.kinematics import PoseSolution, assess, forward_kinematics, passive_joints
from ..core.model import Model
from ..core.multistart import DEFAULT_STARTS as DEFAULT_STARTS  # the default starts of a search (defined there)
from ..core.pose_checks import ROUND_TRIP_FACTOR, STATUSES
from ..core.result import Status
from ..core.solver import SolverConfig, solvers_of

log = logging.getLogger(__name__)

#: two converged poses within this (scaled) distance are the same mode
MERGE_TOLERANCE = 1e-6
#: starts per mapped Newton call of the search (about 0.1 s: a Ctrl-C stops the search that soon)
SEARCH_CHUNK = 256
#: rows of a block of the merge, and most distances computed at once
MERGE_BLOCK, MERGE_CELLS = 8192, 1 << 22
#: statuses of converged real solutions (the others: Newton did not reach a solution)
REAL = (Status.SOLVED, Status.WRONG_BRANCH, Status.OUTSIDE_JOINT_LIMITS, Status.SINGULAR)
#: a mode reached by fewer starts than this is "rarely hit" (its basin is small: others may hide)
FEW = 3
#: the probability of reaching a basin the search aims at
CONFIDENCE = 0.99

COMPLETE_NOTE = (
    "every mode found was reached by at least {few} starts and Chao1 estimates no unseen mode; "
    "still a multi-start search, not a proof: a mode whose basin holds less than {p:.2g} of the "
    "starts is missed with probability above 1 %"
)
INCOMPLETE_NOTE = (
    "probably incomplete: {rare} mode(s) reached by fewer than {few} starts; Chao1 estimates "
    "{unseen:.3g} unseen mode(s) (about {estimate:.3g} in all); the smallest basin found holds "
    "{p:.2g} of the starts, and a 99 % chance of reaching a basin that small takes {needed} starts "
    "(more if the modes not found have smaller basins)"
)


@dataclass
class AssemblyMode:
    """One assembly mode: the pose, its check and its branch indicators.

    Attributes
    ----------
    status
        as an FK solution would report it (``wrong_branch`` off the designated branch);
    message
        why, when not solved;
    residual
        max |Φ|;
    designated
        on the branch the model designates (branch indicators > 0 and the closed-form IK round
        trip agrees);
    branch
        the branch indicator values (empty without indicators);
    basin
        the number of starts that converged to it.
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
class SearchRegion:
    """Where the starts are drawn: ``lower``, ``upper`` per pose coordinate (an
    angle's is a full turn, (-pi, pi]) and how each side was chosen."""

    lower: np.ndarray
    upper: np.ndarray
    names: list[str]
    kinds: list[str]
    source: list[str]

    def describe(self) -> str:
        parts = []
        for n, k, lo, hi, src in zip(self.names, self.kinds, self.lower, self.upper, self.source):
            if k == "angle":
                parts.append(f"{n} in (-180, 180] deg ({src})")
            else:
                parts.append(f"{n} in [{lo:.6g}, {hi:.6g}] {'m' if k == 'length' else ''} ({src})".replace("  ", " "))
        return "; ".join(parts)

    def as_dict(self) -> dict:
        return {
            n: {"lower": float(lo), "upper": float(hi), "kind": k, "source": s}
            for n, k, lo, hi, s in zip(self.names, self.kinds, self.lower, self.upper, self.source)
        }


@dataclass
class Completeness:
    """What the counts of starts per mode say about the modes not found.

    Attributes
    ----------
    hits
        starts that reached a mode (the sum of the basins); singletons,
    doubletons
        modes reached by one and by two starts;
    unseen
        Chao1's estimate of the modes no start reached (bias-corrected form when there is no
        doubleton);
    estimate
        found + unseen;
    new_mode_probability
        Good-Turing's probability that one more converged start finds a new mode (singletons /
        hits);
    smallest_basin
        the smallest fraction of the starts that reached one mode;
    starts_needed
        starts for a 99 % chance of reaching a basin that small;
    rare
        indices of the modes reached by fewer than `FEW` starts;
    complete
        no rare mode and no unseen mode estimated.
    """

    hits: int
    singletons: int
    doubletons: int
    unseen: float
    estimate: float
    new_mode_probability: float
    smallest_basin: float
    starts_needed: int
    rare: list[int]
    complete: bool
    note: str

    def as_dict(self) -> dict:
        return {
            "hits": self.hits,
            "singletons": self.singletons,
            "doubletons": self.doubletons,
            "unseen_chao1": self.unseen,
            "estimated_modes": self.estimate,
            "new_mode_probability": self.new_mode_probability,
            "smallest_basin": self.smallest_basin,
            "starts_needed": self.starts_needed,
            "rarely_hit_modes": self.rare,
            "complete": self.complete,
        }


@dataclass
class AssemblyModes:
    """The distinct assembly modes found for one actuator vector.

    Attributes
    ----------
    modes
        found, the working mode (if any) first, then by basin size;
    working
        index of the working mode in ``modes`` (None if the ordinary FK failed:
        ``working_solution`` says why);
    nearest
        index of the mode nearest to the working one; distance_length (m), distance_angle (rad):
        Euclidean distances of the length and angle coordinates of the pose between them (angles
        wrapped);
    starts, converged
        how many starts ran and converged to a real solution;
    outside_region
        modes found outside the start box (kept);
    region
        the search region;
    completeness
        the estimate from the counts.
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
    region: SearchRegion
    completeness: Completeness
    seconds: float
    details: dict = field(default_factory=dict)

    @property
    def count(self) -> int:
        return len(self.modes)

    @property
    def note(self) -> str:
        return self.completeness.note


def reach(model: Model) -> float:
    """Half-span of the start box of the length coordinates: the largest of the
    declared (finite) half-spans, the characteristic length, the length
    coordinates of the home pose and the lengths among the actuators at home."""
    c = model.closure
    vals = [model.characteristic_length]
    for i, x in enumerate(c.x):
        if x.kind == "length":
            vals.append(abs(model.x_home[i]))
            span = model.x_upper[i] - model.x_lower[i]
            if np.isfinite(span):
                vals.append(0.5 * span)
    vals += [abs(model.q_home[j]) for j, qc in enumerate(c.q) if qc.kind == "length"]
    return float(max(v for v in vals if np.isfinite(v)))


def search_region(model: Model) -> SearchRegion:
    """The box the starts are drawn from, without bounds from the user: a full
    turn for every angle, home ± `reach` for every other coordinate."""
    c = model.closure
    r = reach(model)
    lo, hi, src = [], [], []
    for i, x in enumerate(c.x):
        if x.kind == "angle":
            lo.append(-math.pi)
            hi.append(math.pi)
            src.append("full turn")
        else:
            half = r if x.kind == "length" else max(abs(model.x_home[i]), 1.0)
            lo.append(model.x_home[i] - half)
            hi.append(model.x_home[i] + half)
            src.append("home ± reach" if x.kind == "length" else "home ± 1")
    return SearchRegion(np.array(lo), np.array(hi), list(c.x_names), [x.kind for x in c.x], src)


def _reduce(X: np.ndarray, angle: np.ndarray) -> np.ndarray:
    out = X.copy()
    out[:, angle] = math.pi - (math.pi - X[:, angle]) % (2 * math.pi)
    return out


def _frame_columns(model: Model) -> np.ndarray:
    """Which pose coordinates the closure's frame (R, position) depends on."""
    fr = model.closure.frame
    dep = np.zeros(model.closure.nx, dtype=bool)
    for k in range(fr.n_out()):
        sp = fr.sparsity_jac(0, k)  # (output entries, nx)
        dep[np.unique(np.array(sp.get_col(), dtype=int))] = True
    return dep


def features(model: Model, X: np.ndarray, length: float) -> np.ndarray:
    """One row per pose, equal for equal configurations: the platform's rotation
    matrix and position (over ``length``) when the closure has a frame, the other
    coordinates as they are (lengths over ``length``, angles by sine and cosine)."""
    c = model.closure
    angle = np.array([x.kind == "angle" for x in c.x])
    scale = np.array([length if x.kind == "length" else 1.0 for x in c.x])
    cols = []
    rest = np.ones(c.nx, dtype=bool)
    if c.frame is not None and len(X):
        dep = _frame_columns(model)
        rest = ~dep
        fm = c.frame.map(len(X))
        R, pos = (np.asarray(v, dtype=float) for v in fm(X.T, model.p))
        n = len(X)
        cols += [R.reshape(3, n, 3).transpose(1, 0, 2).reshape(n, 9), pos.T / length]
    ang, lin = rest & angle, rest & ~angle
    cols += [X[:, lin] / scale[lin], np.cos(X[:, ang]), np.sin(X[:, ang])]
    return np.hstack(cols) if cols else np.zeros((len(X), 0))


def _merge(F: np.ndarray, tol: float) -> tuple[list[int], np.ndarray]:
    """Greedy clustering of the rows of F (max-norm): (first row of each cluster, cluster of each row).

    Row k joins the nearest cluster (the first of equally near ones) whose
    first row is within ``tol``, among the clusters started before it, or
    starts one.  The rows are taken in blocks (vectorized: a million converged
    starts merge in seconds), with the result of a row-by-row loop."""
    reps: list[int] = []
    label = np.empty(len(F), dtype=int)

    def dist(a: np.ndarray, b: np.ndarray) -> np.ndarray:
        return np.max(np.abs(a[:, None, :] - b[None, :, :]), axis=2, initial=0.0)

    with progress.task("merging the converged starts", len(F)) as report:
        k = 0
        while k < len(F):
            k = _merge_block(F, k, reps, label, dist, tol)
            report.update(k)
    return reps, label


def _merge_block(Y: np.ndarray, k: int, reps: list[int], label: np.ndarray, dist: Any, tol: float) -> int:
    """Merge the block of rows from ``k`` (see `_merge`); the first row after it."""
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


#: Newton iterations of the search (random starts need more than a solve from a near guess)
SEARCH_MAX_ITER = 100
#: Newton steps from every start before that Newton solve, each shortened to `STEP_LIMIT`
DAMPED_STEPS = 30
#: longest step of those (max-norm, lengths divided by the reach): one radian, or one reach.
#: Undamped Newton from a random start often jumps far (|Φ| of 1e37 on Dietmaier's platform):
#: there 114 of 2000 starts converged and 23 of its 40 modes were found; after the shortened
#: steps 91 % of the starts converge (measured with its home lifted 1 m) and every mode's basin holds at least
#: 0.06 % of them (benchmarks/bench_assembly_modes.py)
STEP_LIMIT = 1.0


def search_solver(config: SolverConfig) -> SolverConfig:
    """The Newton configuration of the search: the given one (or Newton at its
    tolerance), with at least `SEARCH_MAX_ITER` iterations."""
    opts = dict(config.options) if config.method == "newton" else {}
    opts["max_iter"] = max(int(opts.get("max_iter", 0)), SEARCH_MAX_ITER)
    return SolverConfig("newton", options=opts, tolerance=config.tolerance)


def damped_newton(model: Model) -> ca.Function:
    """``<name>_search_steps: (x0, w, scale) -> x``: `DAMPED_STEPS` Newton
    steps on Φ(x; w) = 0 (w = (q, p)), each shortened to max |dx / scale| <=
    `STEP_LIMIT`; a step that is not finite (Φ_x singular) is not taken.
    Built once per closure."""
    c = model.closure

    def build() -> ca.Function:
        x, w, scale = ca.SX.sym("x", c.nx), ca.SX.sym("w", c.nq + c.np), ca.SX.sym("scale", c.nx)
        phi = c.fk_residual(x, w)
        dx = -ca.solve(ca.jacobian(phi, x), phi)
        longest = ca.mmax(ca.fabs(dx / scale))
        nxt = x + dx * ca.fmin(1.0, STEP_LIMIT / longest)
        # not finite (NaN < inf is false): stay.  Not v * 0 == 0, which CasADi simplifies to true
        nxt = ca.if_else(ca.sum1(ca.fabs(nxt) < ca.inf) == c.nx, nxt, x)
        step = ca.Function(f"{c.name}_search_step", [x, w, scale], [nxt], ["x", "w", "scale"], ["x_next"])
        x0, wm, sm = ca.MX.sym("x0", c.nx), ca.MX.sym("w", c.nq + c.np), ca.MX.sym("scale", c.nx)
        xs = x0
        for _ in range(DAMPED_STEPS):
            xs = step(xs, wm, sm)
        return ca.Function(f"{c.name}_search_steps", [x0, wm, sm], [xs], ["x0", "w", "scale"], ["x"])

    return solvers_of(c).memo(("assembly_damped_newton", DAMPED_STEPS, STEP_LIMIT), build)


def completeness(basins: list[int], starts: int) -> Completeness:
    """The completeness estimate from the number of starts that reached each mode."""
    hits = int(sum(basins))
    f1 = sum(1 for b in basins if b == 1)
    f2 = sum(1 for b in basins if b == 2)
    if f2 > 0:
        unseen = f1 * f1 / (2.0 * f2)
    else:
        unseen = f1 * (f1 - 1) / 2.0
    rare = [k for k, b in enumerate(basins) if 0 < b < FEW]
    found = [b for b in basins if b > 0]
    smallest = min(found) / starts if found else 1.0 / max(starts, 1)
    needed = int(math.ceil(math.log(1 - CONFIDENCE) / math.log1p(-min(smallest, 0.999999))))
    complete = not rare and unseen == 0 and bool(found)
    if complete:
        note = COMPLETE_NOTE.format(few=FEW, p=-math.log(1 - CONFIDENCE) / starts)
    else:
        note = INCOMPLETE_NOTE.format(
            rare=len(rare), few=FEW, unseen=unseen, estimate=len(basins) + unseen, p=smallest, needed=needed
        )
        if not found:
            note = f"no start converged to a real solution of the {starts}; modes may exist in basins none reached"
    return Completeness(
        hits=hits,
        singletons=f1,
        doubletons=f2,
        unseen=float(unseen),
        estimate=float(len(basins) + unseen),
        new_mode_probability=f1 / hits if hits else 1.0,
        smallest_basin=float(smallest),
        starts_needed=needed,
        rare=rare,
        complete=complete,
        note=note,
    )


def _actuators(model: Model, q: Any, starts: int) -> np.ndarray:
    """The actuator values as a vector (bad input: not nq finite values, or no start)."""
    c = model.closure
    qv = np.asarray(q, dtype=float).ravel()
    if qv.size != c.nq or not np.all(np.isfinite(qv)):
        raise InputError(f"expected {c.nq} finite actuator values, got {np.asarray(q).tolist()}", path=("q",))
    if int(starts) < 1:
        raise InputError(f"expected at least 1 start, got {starts}", path=("starts",))
    return qv


def _distinct_modes(
    model: Model, X: np.ndarray, Xr: np.ndarray, label: np.ndarray, count: int, qv: np.ndarray, tol: float
) -> list[AssemblyMode]:
    """One mode per merged class of the solutions ``X`` (``Xr``: their angles reduced)."""
    c = model.closure
    angle = np.array([x.kind == "angle" for x in c.x])
    scale = _scale(model)
    modes = []
    for j in range(count):
        members = np.flatnonzero(label == j)
        # the representative: of the coordinates of one pose (two angle triples of one rotation),
        # those nearest to home, so that the working mode reads like the ordinary FK
        d = Xr[members] - model.x_home
        d[:, angle] = (d[:, angle] + math.pi) % (2 * math.pi) - math.pi
        k = int(members[np.argmin(np.max(np.abs(d / scale), axis=1))])
        mode = _mode(model, Xr[k], qv, tol, int(members.size))
        if mode.status is Status.RESIDUAL_TOO_LARGE:  # the reduced angle broke the closure: not periodic
            mode = _mode(model, X[k], qv, tol, int(members.size))
        if mode.status in REAL:
            modes.append(mode)
    return modes


def _scale(model: Model) -> np.ndarray:
    """The size of each pose coordinate: the reach for a length, 1 for an angle."""
    length = reach(model)
    return np.array([length if x.kind == "length" else 1.0 for x in model.closure.x])


def _with_working(
    model: Model, modes: list[AssemblyMode], work: PoseSolution, qv: np.ndarray, config: SolverConfig, merge: float
) -> tuple[list[AssemblyMode], int | None]:
    """The modes with the ordinary FK's pose first (the working mode: that of the search it
    matches, in the FK's own coordinates, else added), then by basin; None where the FK failed."""
    angle = np.array([x.kind == "angle" for x in model.closure.x])
    length = reach(model)
    working = None
    if work.ok:
        fw = features(model, _reduce(work.x[None, :], angle), length)[0]
        fm = features(model, np.array([m.x for m in modes]), length) if modes else np.zeros((0, fw.size))
        dist = np.max(np.abs(fm - fw), axis=1) if len(fm) else np.zeros(0)
        j = int(np.argmin(dist)) if dist.size else -1
        if j >= 0 and dist[j] <= max(merge, 1e3 * config.tolerance / length):
            working = j
            modes[j] = _mode(model, work.x, qv, config.tolerance, modes[j].basin)  # the FK's own coordinates
        else:  # the ordinary FK found a mode the search missed
            log.info("the working mode was not among the modes of the search; added")
            modes.append(_mode(model, work.x, qv, config.tolerance, 0))
            working = len(modes) - 1
    order = sorted(range(len(modes)), key=lambda i: (i != working, -modes[i].basin, modes[i].x.tolist()))
    return [modes[i] for i in order], (0 if working is not None else None)


def _nearest_mode(model: Model, modes: list[AssemblyMode], working: int | None) -> tuple[Any, Any, Any]:
    """The mode nearest the working one, and the distances to it (lengths, angles); None without."""
    if working is None or len(modes) <= 1:
        return None, None, None
    fm = features(model, np.array([m.x for m in modes]), reach(model))
    nearest = 1 + int(np.argmin(np.linalg.norm(fm[1:] - fm[0], axis=1)))
    dl, da = _distances(model, modes[0].x, modes[nearest].x)
    return nearest, dl, da


def assembly_modes(
    model: Model,
    q,
    solver: SolverConfig | None = None,
    *,
    starts: int = DEFAULT_STARTS,
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
    qv = _actuators(model, q, starts)
    t0 = time.perf_counter()
    region = search_region(model)
    lo, hi = region.lower, region.upper
    rng = np.random.default_rng(seed)
    X0 = lo + (hi - lo) * rng.random((int(starts), c.nx))
    X0[0] = model.x_home if guess is None else np.asarray(guess, dtype=float)
    length = reach(model)
    w = np.r_[qv, np.asarray(model.p, dtype=float).ravel()]
    (X0,) = evaluate(damped_newton(model), [X0, w, _scale(model)], threads, SEARCH_CHUNK, "assembly-mode search")
    newton = search_solver(config)
    res = batch_forward_kinematics(
        model,
        np.broadcast_to(qv, (len(X0), c.nq)),
        newton,
        X0,
        backend=backend,
        threads=threads,
        chunk=SEARCH_CHUNK,
        what="assembly-mode search, Newton",
    )
    statuses = [STATUSES[int(k)] for k in res.status]
    real = np.array([s in REAL for s in statuses])
    X = res.x.copy() if res.raw_joints is None else res.raw_joints[:, : c.nx].copy()
    X = X[real]
    angle = np.array([x.kind == "angle" for x in c.x])
    Xr = _reduce(X, angle) if angle.any() else X
    F = features(model, Xr, length)
    # a closure not periodic in an angle: the reduced pose breaks it; those keep their own value
    reps, label = _merge(F, merge_tolerance)
    modes = _distinct_modes(model, X, Xr, label, len(reps), qv, config.tolerance)
    work = forward_kinematics(model, qv, config, guess)
    modes, working = _with_working(model, modes, work, qv, config, merge_tolerance)
    inside = [bool(np.all((m.x >= lo - 1e-12) & (m.x <= hi + 1e-12))) for m in modes]
    nearest, dl, da = _nearest_mode(model, modes, working)
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
        outside_region=int(len(inside) - sum(inside)),
        region=region,
        completeness=completeness([m.basin for m in modes], int(starts)),
        seconds=time.perf_counter() - t0,
        details={
            "merge_tolerance": merge_tolerance,
            "backend": res.backend,
            "newton_seconds": res.seconds,
            "reach": length,
            "merged_on": "rotation matrix and position" if c.frame is not None else "coordinates (angles wrapped)",
        },
    )
