"""The largest axis-aligned box in the task coordinates inside the workspace (see
`cpm_nlp.analysis.workspace`)."""

from __future__ import annotations

import functools
import itertools
import logging
import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Any

import casadi as ca
import numpy as np

from ...core.errors import InputError, suggest
from ...core.model import LoopClosure, Model
from ...core.multistart import AGREEMENT, best_and_agreement
from ...core.options import Option
from ...core.progress import track
from ...core.solver import SolverConfig, run_nlp, solvers_of
from ..cuboid_ik import ClosedFormCuboid
from .membership import Membership, limit_bounds, limited_function, membership, poses
from .sampling import probe_region

log = logging.getLogger(__name__)

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

# -- sample points of a box ----------------------------------------------------------------------


@functools.lru_cache(maxsize=32)
def _grid(d: int, n: int, interior: int | None) -> np.ndarray:
    """`surface_grid` (interior None) or `check_grid`, computed once (read-only)."""
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


#: the most points a default grid gives: the cuboid NLP's samples, the membership check's
#: surface, the membership check's interior (per edge counts fall with the dimension: a 6-axis
#: platform's 5 samples per edge would be 14896 samples, each with its own pose unknowns)
DEFAULT_NLP_SAMPLES = 100
DEFAULT_CHECK_POINTS = 2000
#: explicit per-edge counts may give at most this many points
MAX_NLP_SAMPLES = 2000
MAX_CHECK_POINTS = 200_000


def surface_count(d: int, n: int) -> int:
    """Points of `surface_grid` (d, n): n^d - (n - 2)^d."""
    return n**d - max(n - 2, 0) ** d


def default_per_edge(d: int, largest: int, budget: int) -> int:
    """The most points per edge, up to ``largest`` (at least 2), whose surface grid in d
    dimensions has at most ``budget`` points (3 task coordinates: ``largest`` itself for the
    defaults used here)."""
    n = largest
    while n > 2 and surface_count(d, n) > budget:
        n -= 1
    return n


def check_interior(d: int) -> int:
    """Interior points per edge of the membership check: 5, fewer where 5^d would pass
    `DEFAULT_CHECK_POINTS`."""
    n = 5
    while n > 1 and n**d > DEFAULT_CHECK_POINTS:
        n -= 1
    return n


def check_per_edge_of(d: int, per_edge: int | None) -> int:
    """The membership check's points per edge: as given, else 17 (fewer in more than 3 dimensions)."""
    return per_edge if per_edge is not None else default_per_edge(d, 17, DEFAULT_CHECK_POINTS)


def check_per_edge_option(default_3d: int) -> Option:
    return Option(
        "check_per_edge",
        "int",
        f"points per box edge of the membership check afterwards (default: {default_3d} for up to 3 task "
        f"coordinates, fewer above, at most {DEFAULT_CHECK_POINTS} surface points)",
        default=None,
        lower=2,
        upper=65,
    )


#: the input that sets the density of the membership check of a box
CHECK_OPTION = check_per_edge_option(17)


def check_grid(d: int, per_edge: int, interior: int | None = None) -> np.ndarray:
    """Dense check sample of the unit box: its surface on a grid of ``per_edge``
    points per edge, plus the interior points of a grid of ``interior + 2``
    (default: `check_interior`)."""
    return _grid(d, per_edge, check_interior(d) if interior is None else interior).copy()


def check_grid_sizes(d: int, samples_per_edge: int | None, check_per_edge: int | None, path: tuple) -> None:
    """Refuse explicit per-edge counts whose grids are too large in d task coordinates."""
    for key, n, most in (
        ("samples_per_edge", samples_per_edge, MAX_NLP_SAMPLES),
        ("check_per_edge", check_per_edge, MAX_CHECK_POINTS),
    ):
        if n is not None and surface_count(d, n) > most:
            raise InputError(
                f"{n} points per edge in {d} task coordinates give {surface_count(d, n)} points on the box's "
                f"surface; expected at most {most} (leave it out for a default that suits {d} coordinates)",
                path=path + (key,),
            )


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
    return solvers_of(model.closure).get(key, config, lambda: CuboidNLP(model.closure, n_samples, active, config))


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
    model: Model, lower, upper, per_edge: int | None = None, solver: SolverConfig | None = None
) -> tuple[CuboidCheck, np.ndarray, Membership]:
    """Check a box against [`membership`][cpm_nlp.analysis.workspace.membership.membership] on `check_grid`; also
    returns
    the unit-box positions checked and the membership report."""
    lower, upper = np.asarray(lower, dtype=float), np.asarray(upper, dtype=float)
    S = check_grid(lower.size, check_per_edge_of(lower.size, per_edge))
    mem = membership(model, lower + S * (upper - lower), solver)
    margin, binding = mem.worst()
    return CuboidCheck(len(S), mem.count_outside, margin, binding), S, mem


@dataclass
class CuboidResult:
    """The largest box found, with how it was found and checked.

    Attributes
    ----------
    lower, upper
        corners in the task coordinates (SI); None unless ``found``.
    starts
        number of starts;
    converged
        how many converged;
    agreed
        how many converged to the best volume (within AGREEMENT);
    refinements
        exchange rounds used;
    shrink
        factor applied about the centre after them (1 = none);
    check
        the dense membership check of the reported box.
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
    see `CuboidNLP`), with EXTRA_SLOTS sample slots for the exchange rounds."""

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
    """The working-set NLP through the closed-form IK (`cpm_nlp.analysis.cuboid_ik`); its first
    rows at the corners and, where every cloud point assembles, the face centres (where the
    IK's reach margin bounds the workspace, the corners alone, as IPOPT converges there less
    reliably)."""
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
    face_centres = "no assembly" not in binding
    return ClosedFormCuboid(
        model, config, fn, rows, lower, upper, NLP_MARGIN, base, centre, size, options, initial, face_centres
    )


#: the initial box of a start: a cube of this width (unit box) about its seed, unless the cloud
#: shows more room (`_start_widths`)
START_WIDTH = 1e-3
#: the fraction of the room the cloud shows about a seed that its initial box takes
START_FRACTION = 0.5


def _start_box(model: Model, t_c: np.ndarray, S: np.ndarray, centre, size, config: SolverConfig):
    """The initial box of a start about the task point t_c: (u0, w0, X, Q) with the
    poses of its samples, shrunk until every sample assembles; None if none does."""
    d = model.closure.nq
    w0 = np.full(d, START_WIDTH)
    for _ in range(4):
        u0 = (t_c - centre) / size - 0.5 * w0
        X, Q, ok = poses(model, centre + size * (u0 + S * w0), config)
        if np.all(ok):
            return u0, w0, X, Q
        w0 = w0 * 0.1
    return None


def _start_widths(seeds: list, cloud_T: np.ndarray, cloud: Membership, centre, size) -> np.ndarray:
    """The initial width (unit box, the same along every axis) of each seed's box.  The first
    seed's is `START_WIDTH`, as it always was; each later one's is the cube about the seed
    that holds no cloud point outside the workspace, times `START_FRACTION`, at least
    `START_WIDTH` (the cloud is already judged: no new evaluation).  A larger initial box
    takes IPOPT fewer iterations to the optimum (the later starts are solved together, where
    the iterations cost most), but it can also reach another local optimum of a coarse
    discretised NLP (the five-bar with 2 samples per edge): the first start keeps the box
    it had."""
    out = (cloud_T[~cloud.inside] - centre) / size
    widths = np.full(len(seeds), START_WIDTH)
    if not len(out):
        return widths
    for k in range(1, len(seeds)):
        free = 2.0 * float(np.min(np.max(np.abs(out - (seeds[k] - centre) / size), axis=1)))
        widths[k] = max(START_FRACTION * free, START_WIDTH)
    return widths


def _start_boxes(
    model: Model, seeds: list, S: np.ndarray, centre, size, config: SolverConfig, widths: np.ndarray | None = None
) -> list:
    """`_start_box` of every seed; with a closed-form IK the poses of all seeds'
    samples in one call per shrink step, each seed's box from its width in ``widths``
    (default `START_WIDTH`), shrunk by 10 until every sample assembles."""
    if model.closure.ik is None:
        return [_start_box(model, t_c, S, centre, size, config) for t_c in seeds]
    d = model.closure.nq
    boxes: list = [None] * len(seeds)
    todo = list(range(len(seeds)))
    w0 = np.full(len(seeds), START_WIDTH) if widths is None else np.asarray(widths, dtype=float).copy()
    for _ in range(4):
        if not todo:
            break
        u0 = [(seeds[k] - centre) / size - 0.5 * w0[k] for k in todo]
        X, Q, ok = poses(model, np.vstack([centre + size * (u + S * w0[k]) for u, k in zip(u0, todo)]), config)
        n = len(S)
        left = []
        for i, k in enumerate(todo):
            part = slice(i * n, (i + 1) * n)
            if np.all(ok[part]):
                boxes[k] = (u0[i], np.full(d, w0[k]), X[part], Q[part])
            else:
                left.append(k)
        todo = left
        w0 = w0 * 0.1
    return boxes


@dataclass(frozen=True)
class CuboidFormulation:
    """How the cuboid NLP is written (both ways solve the same NLP): ``poses``, pose unknowns
    at every sample (any mechanism); ``closed_form``, the limited quantities through the
    mechanism's closed-form IK (`cpm_nlp.analysis.cuboid_ik`); ``auto``, the closed form
    where the mechanism has one and every point of the cloud drawn for the starts assembles
    (where the IK's reach margin bounds the workspace its derivatives grow without bound, and
    IPOPT converges there less reliably than with pose unknowns).

    through_ik: True, through the closed-form IK (the mechanism must have one); False, pose
        unknowns; None, the IK where it is safe (``auto``).
    """

    name: str
    through_ik: bool | None

    def check(self, model: Model) -> None:
        """Raise [`InputError`][cpm_nlp.core.errors.InputError] if the formulation cannot be used for ``model``."""
        if self.through_ik and model.closure.ik is None:
            raise InputError(
                f"the {self.name} cuboid formulation needs a closed-form IK; {model.name} has none (use 'poses')",
                path=("formulation",),
            )

    def closed_form(self, model: Model, assembles: bool) -> bool:
        """Whether to solve through the closed-form IK, given whether every point of the
        cloud drawn for the starts assembles."""
        if self.through_ik is None:
            return model.closure.ik is not None and assembles
        return self.through_ik


#: formulations of the cuboid NLP by name (the ``formulation`` argument)
FORMULATIONS: Mapping[str, CuboidFormulation] = MappingProxyType(
    {
        "auto": CuboidFormulation("auto", None),
        "closed_form": CuboidFormulation("closed_form", True),
        "poses": CuboidFormulation("poses", False),
    }
)


def cuboid_formulation(formulation: str | CuboidFormulation) -> CuboidFormulation:
    """A formulation by its name in `FORMULATIONS` (or as given), with "did you mean"."""
    if isinstance(formulation, CuboidFormulation):
        return formulation
    if formulation not in FORMULATIONS:
        raise InputError(
            f"unknown cuboid formulation {formulation!r}; expected one of: {', '.join(FORMULATIONS)}",
            path=("formulation",),
            suggestions=suggest(str(formulation), FORMULATIONS),
        )
    return FORMULATIONS[formulation]


def _seeds(
    model: Model, config: SolverConfig, region: tuple, starts: int, seed: int, cloud: int
) -> tuple[list, Membership, np.ndarray]:
    """The start points (home where it is inside, then points of a seeded cloud of the
    region that are inside), the cloud's membership and its points."""
    lo_r, hi_r = region
    rng = np.random.default_rng(seed)
    home_t = model.task_of(model.x_home)
    T = lo_r + (hi_r - lo_r) * rng.random((cloud, lo_r.size))
    cloud_mem = membership(model, T, config, detail=False)  # verdicts and the limits that bind
    members = T[cloud_mem.inside]
    seeds = []
    if membership(model, home_t[None, :], config, detail=False).inside[0]:
        seeds.append(home_t)
    seeds += list(members[rng.permutation(len(members))[: max(starts - len(seeds), 0)]])
    return seeds[:starts], cloud_mem, T


def _run_starts(engine: Any, boxes: list) -> tuple[list, int]:
    """Each start's NLP solve (converged, z, status, iterations), and the iterations summed:
    the first start alone, the others together where the engine can (one block-separable
    NLP, see cuboid_ik.SlotNLP), else, or if that fails, one by one."""
    runs: list = [(False, None, "no pose at the start", 0) if box is None else None for box in boxes]
    pending = [k for k, box in enumerate(boxes) if box is not None]
    iterations = 0
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
        return runs, iterations
    for k in track(pending, "cuboid starts"):
        runs[k] = engine.start(*boxes[k])
        iterations += runs[k][3]
    return runs, iterations


def _exchange_rounds(
    model: Model,
    engine: Any,
    z: np.ndarray,
    frame: tuple,
    check_per_edge: int | None,
    config: SolverConfig,
    rounds: int,
) -> tuple[np.ndarray, CuboidCheck, int, int]:
    """The exchange method: while the box fails its dense check, its worst outside points
    join the NLP's samples and it is solved again (at most ``rounds`` rounds and
    `EXTRA_SLOTS` points); the last solution, its check, the rounds and iterations."""
    centre, size = frame
    d = model.closure.nq

    def checked(z: np.ndarray) -> tuple:
        lower = centre + size * z[:d]
        return check_box(model, lower, lower + size * z[d : 2 * d], check_per_edge, config)

    check, S_check, mem = checked(z)
    done = iterations = 0
    room = EXTRA_SLOTS
    while not check.passed and done < rounds and room > 0:
        out = np.flatnonzero(~mem.inside)
        worst = out[np.argsort(mem.margin[out])][: min(ADDED_PER_ROUND, room)]
        room -= len(worst)
        z_new, ok, status, iters = engine.exchange(z, S_check[worst])
        iterations += iters
        done += 1
        if not ok:
            log.info("exchange round %d did not converge (%s)", done, status)
            break
        z = z_new
        check, S_check, mem = checked(z)
    return z, check, done, iterations


def shrink_to_pass(
    model: Model,
    lower,
    upper,
    check_per_edge: int | None,
    config: SolverConfig,
    check: CuboidCheck | None = None,
    steps: int = 30,
) -> tuple[np.ndarray, np.ndarray, float, CuboidCheck]:
    """The box shrunk about its centre by the largest factor (bisection, ``steps`` steps)
    that passes the membership check, with that factor (1: it passes as it is) and its
    check (``check``: the box's own, when known)."""
    check = check if check is not None else check_box(model, lower, upper, check_per_edge, config)[0]
    if check.passed:
        return lower, upper, 1.0, check
    mid, half = 0.5 * (lower + upper), 0.5 * (upper - lower)
    good, bad = 0.0, 1.0
    for _ in range(steps):
        f = 0.5 * (good + bad)
        if check_box(model, mid - f * half, mid + f * half, check_per_edge, config)[0].passed:
            good = f
        else:
            bad = f
    lower, upper = mid - good * half, mid + good * half
    return lower, upper, good, check_box(model, lower, upper, check_per_edge, config)[0]


def inscribed_cuboid(
    model: Model,
    solver: SolverConfig | None = None,
    *,
    starts: int = 8,
    seed: int = 0,
    samples_per_edge: int | None = None,
    check_per_edge: int | None = None,
    refinements: int = 3,
    region: tuple[np.ndarray, np.ndarray] | None = None,
    cloud: int = 2000,
    formulation: str | CuboidFormulation = "auto",
) -> CuboidResult:
    """The largest axis-aligned box in the task coordinates inside the reachable
    workspace (see the module docstring for the method).

    Parameters
    ----------
    starts
        IPOPT starts (the first at the home pose, the others at points of a seeded point cloud
        of ``region``);
    samples_per_edge
        the NLP's surface grid (default 5, fewer in more than 3 task coordinates, see
        `default_per_edge`);
    check_per_edge
        the dense check's surface grid (`check_per_edge_of`);
    refinements
        the largest number of exchange rounds;
    region
        the box the starts are drawn from (default: probed around home);
    formulation
        a `CuboidFormulation` or its name in `FORMULATIONS` ("auto", "closed_form", "poses").
    """
    form = cuboid_formulation(formulation)
    form.check(model)
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
    seeds, cloud_mem, cloud_T = _seeds(model, config, (lo_r, hi_r), starts, seed, cloud)
    if not seeds:
        return CuboidResult(
            False,
            f"no reachable point found in the search region ({cloud} samples)",
            infeasible=True,
            region=(lo_r, hi_r),
            seconds=time.perf_counter() - t_start,
        )
    if samples_per_edge is None:
        samples_per_edge = default_per_edge(d, 5, DEFAULT_NLP_SAMPLES)
    base = surface_grid(d, samples_per_edge)
    # auto: the closed form unless the IK's own reach limit shapes the workspace in the
    # region (a cloud point that does not assemble): its derivatives are unbounded there
    assembles = "no assembly" not in {cloud_mem.binding[k] for k in np.flatnonzero(~cloud_mem.inside)}
    if form.closed_form(model, assembles):
        engine = _closed_form_cuboid(model, config, base, centre, size, cloud_mem)
    else:
        engine = _PoseCuboid(model, config, base, centre, size)
    # larger initial boxes where every cloud point assembles (as for the face centres' rows)
    widths = _start_widths(seeds, cloud_T, cloud_mem, centre, size) if assembles else None
    boxes = _start_boxes(model, seeds, engine.S, centre, size, config, widths)
    runs, iterations = _run_starts(engine, boxes)
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
    z, check, rounds, iters = _exchange_rounds(model, engine, z, (centre, size), check_per_edge, config, refinements)
    iterations += iters
    lower = centre + size * z[:d]
    lower, upper, shrink, check = shrink_to_pass(
        model, lower, lower + size * z[d : 2 * d], check_per_edge, config, check
    )
    if shrink == 0.0:  # a point, not a box: no shrink about the centre passes (a hole or a boundary there)
        return CuboidResult(
            False,
            "no box passes the membership check: the best start's box passes it only when shrunk to its centre "
            f"(a point); {check.points} points checked",
            starts=len(runs),
            converged=len(ok_vols),
            agreed=agreed,
            refinements=rounds,
            shrink=0.0,
            check=check,
            iterations=iterations,
            seconds=time.perf_counter() - t_start,
            region=(lo_r, hi_r),
            start_volumes=[v for v in volumes if v is not None],
        )
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
