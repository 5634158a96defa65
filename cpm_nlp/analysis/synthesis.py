"""Generic dimensional synthesis: geometry parameters as decision variables of
the cuboid NLP, for any mechanism (no paper formulation needed).

The NLP is the discretised cuboid problem of `cpm_nlp.analysis.workspace`
(the box [c + D∘u, c + D∘(u + w)] in the task coordinates, sample points s_j on
its surface, pose unknowns y_j with Φ(t_j, y_j; p) = 0 and every limited
quantity -- actuators, pose coordinates, passive joints, branch indicators --
within its limits at every sample), with the chosen parameters p_k as further
unknowns, p_k = lo_k + (hi_k - lo_k) z_k, 0 <= z_k <= 1 (the parameter
bounds).  The objective is the box volume per unit of a footprint,

    maximise  Π w_i D_i / F(p),      F(p) = Π_k p_k^e_k

(a product of parameter powers, e.g. ``{b: 2}`` for the area of a base of
radius b; no footprint: the volume itself), solved as the minimum of
-Σ log w_i + Σ e_k log p_k.  Joint and hinge limits are those of the model
(fixed); the parameters not chosen keep their values.

Multi-start: the first start is the model's own design (clipped into the
bounds), the others seeded uniform draws in the parameter box; each start
begins at the largest cuboid of its own design
([`inscribed_cuboid`][cpm_nlp.analysis.workspace.cuboid.inscribed_cuboid], the poses of its
samples from the IK), so every start is feasible.  The best optimum is
**re-checked**: the model is rebuilt with the optimal parameters and the box is
tested against [`check_box`][cpm_nlp.analysis.workspace.cuboid.check_box] on a dense grid of
its faces, edges and interior.  A box that fails is shrunk about its centre
until it passes, and the result says by how much; a design with no box that
passes is reported infeasible, never as a number.
"""

from __future__ import annotations

import logging
import math
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field

import casadi as ca
import numpy as np

from ..core.errors import InputError, suggest
from ..core.model import LoopClosure, Model
from ..core.multistart import AGREEMENT, best_and_agreement, uniform_starts
from ..core.progress import track
from ..core.solver import SolverConfig, run_nlp, solvers_of
from .workspace import (
    CUBOID_IPOPT,
    DEFAULT_CHECK_POINTS,
    DEFAULT_NLP_SAMPLES,
    NLP_MARGIN,
    CuboidCheck,
    default_per_edge,
    inscribed_cuboid,
    limit_bounds,
    limited_function,
    poses,
    surface_grid,
)
from .workspace.cuboid import shrink_to_pass

log = logging.getLogger(__name__)

#: bisection steps of the shrink that makes a failed box pass its check
SHRINK_STEPS = 30


@dataclass
class SynthesisResult:
    """The best design found and its re-checked box.

    Attributes
    ----------
    parameters
        every parameter (SI) of the optimal design;
    lower, upper
        the box (task coordinates); volume, footprint, objective = volume / footprint;
    check
        the membership check of the box at the optimal parameters;
    shrink
        factor applied about its centre to pass it (1 = none); starts,
    converged, agreed
        the multi-start's counts;
    start_objectives
        of the converged starts.  None/empty unless ``found``.
    """

    found: bool
    message: str
    parameters: dict[str, float] = field(default_factory=dict)
    lower: np.ndarray | None = None
    upper: np.ndarray | None = None
    volume: float | None = None
    footprint: float | None = None
    objective: float | None = None
    check: CuboidCheck | None = None
    shrink: float = 1.0
    starts: int = 0
    converged: int = 0
    agreed: int = 0
    iterations: int = 0
    seconds: float = 0.0
    start_objectives: list[float] = field(default_factory=list)
    infeasible: bool = False


class SynthesisNLP:
    """IPOPT on the cuboid NLP with design parameters as unknowns, for one
    mechanism type, sample count, pattern of bounded quantities, design set and
    footprint; built once and reused for every start."""

    def __init__(
        self,
        closure: LoopClosure,
        n_samples: int,
        active: tuple[bool, ...],
        design: tuple[int, ...],
        exponents: tuple[float, ...],
        config: SolverConfig,
    ):
        c = closure
        d, nd, k = c.nq, len(c.dep_index), len(design)
        self.d, self.ny, self.N, self.k = d, nd + c.nq, n_samples, k
        self.rows = np.flatnonzero(active)
        fn, _names = limited_function(c)
        y, t, p = ca.SX.sym("y", self.ny), ca.SX.sym("t", d), ca.SX.sym("p", c.np)
        x = c.assemble_x(t, y[:nd])
        q = y[nd:]
        v = fn(x, q, p)
        per = ca.Function(
            "synthesis_sample",
            [y, t, p],
            [ca.vertcat(c.phi(x, q, p), v[list(self.rows)] if self.rows.size else ca.SX(0, 1))],
            ["y", "t", "p"],
            ["g"],
        )
        self.ng = c.nx + self.rows.size
        U, W, Z = ca.MX.sym("u", d), ca.MX.sym("w", d), ca.MX.sym("z", k)
        Y = ca.MX.sym("Y", self.ny, n_samples)
        p_fixed = ca.MX.sym("p_fixed", c.np)
        lo, span = ca.MX.sym("lo", k), ca.MX.sym("span", k)
        S = ca.MX.sym("S", d, n_samples)
        centre, size = ca.MX.sym("c", d), ca.MX.sym("D", d)
        design_values = lo + span * Z
        P = ca.vertcat(*[design_values[design.index(i)] if i in design else p_fixed[i] for i in range(c.np)])
        N = n_samples
        T = ca.repmat(centre, 1, N) + ca.repmat(size, 1, N) * (ca.repmat(U, 1, N) + S * ca.repmat(W, 1, N))
        G = per.map(N)(Y, T, ca.repmat(P, 1, N))
        f = -ca.sum1(ca.log(W))
        for j, e in enumerate(exponents):
            if e:
                f += e * ca.log(design_values[j])
        nlp = {
            "x": ca.vertcat(U, W, Z, ca.vec(Y)),
            "p": ca.vertcat(p_fixed, lo, span, ca.vec(S), centre, size),
            "f": f,
            "g": ca.vec(G),
        }
        opts = {**config.casadi_options(), **CUBOID_IPOPT, **dict(config.options), "expand": True}
        self._solver = ca.nlpsol(f"{c.name}_synthesis_{N}_{k}", "ipopt", nlp, opts)

    def solve(self, z0, params, lbx, ubx, lbg, ubg) -> tuple[np.ndarray, bool, str, int]:
        return run_nlp(self._solver, "synthesis NLP", x0=z0, p=params, lbx=lbx, ubx=ubx, lbg=lbg, ubg=ubg)


def _check_names(names: Sequence[str], closure: LoopClosure, path: tuple) -> None:
    for n in names:
        if n not in closure.parameters:
            raise InputError(
                f"unknown parameter {n!r}; the mechanism {closure.name} has: {', '.join(closure.parameters)}",
                path=path + (n,),
                suggestions=suggest(str(n), closure.parameters),
            )


def footprint_of(parameters: Mapping[str, float], footprint: Mapping[str, float]) -> float:
    """F(p) = Π p_k^e_k (1 without a footprint)."""
    return float(math.prod(parameters[n] ** e for n, e in footprint.items()))


def _design_bounds(
    model: Model, design: Mapping[str, tuple[float, float]], footprint: Mapping[str, float]
) -> tuple[list[str], np.ndarray, np.ndarray]:
    """The parameters that vary (in the closure's order) and their bounds; bad input: an
    unknown name, no parameter, bounds not finite with low < high, a footprint's log of a
    bound not positive."""
    c = model.closure
    _check_names(list(design), c, ("design",))
    _check_names(list(footprint), c, ("footprint",))
    if not design:
        raise InputError("expected at least one parameter to vary", path=("design",))
    names = [n for n in c.parameters if n in design]
    lo = np.array([float(design[n][0]) for n in names])
    hi = np.array([float(design[n][1]) for n in names])
    if not (np.all(np.isfinite(lo)) and np.all(np.isfinite(hi)) and np.all(lo < hi)):
        raise InputError(f"expected finite bounds low < high, got {dict(design)}", path=("design",))
    for n, e in footprint.items():
        low = float(design[n][0]) if n in design else float(model.parameters[n])
        if e != 0 and not low > 0:
            raise InputError(
                f"the footprint takes the log of {n}; its lower bound must be positive, got {low:g}",
                path=("design", n),
            )
    return names, lo, hi


@dataclass
class _Starts:
    """What every start of the synthesis shares: the design's parameters and bounds, the
    NLP with its constraint bounds, the sample grid, and how to build a design's model."""

    model: Model
    names: list[str]
    lo: np.ndarray
    hi: np.ndarray
    build: Callable[[dict[str, float]], Model]
    nlp: SynthesisNLP
    lbg: np.ndarray
    ubg: np.ndarray
    S: np.ndarray
    config: SolverConfig
    seed: int
    samples_per_edge: int
    start_check: int

    def run(self, z0: np.ndarray) -> tuple[bool, np.ndarray | None, str, int, tuple | None]:
        """One start: the start design's own largest cuboid, then the synthesis NLP from it."""
        model, c, names, lo, hi = self.model, self.model.closure, self.names, self.lo, self.hi
        d, N = c.nq, len(self.S)
        params = dict(model.parameters)
        params.update({n: float(v) for n, v in zip(names, lo + (hi - lo) * z0)})
        try:
            m0 = self.build(params)
        except (InputError, ValueError) as exc:
            return False, None, f"design not buildable: {exc}", 0, None
        box = inscribed_cuboid(  # the start box on the synthesis's own grid (in 6-D 5 per edge: 14896 samples)
            m0,
            self.config,
            starts=1,
            seed=self.seed,
            samples_per_edge=self.samples_per_edge,
            check_per_edge=self.start_check,
            refinements=0,
        )
        if not box.found:
            return False, None, f"no cuboid at the start design ({box.message})", 0, None
        centre = 0.5 * (box.region[0] + box.region[1])
        size = np.maximum(box.region[1] - box.region[0], 1e-12)
        u0, w0 = (box.lower - centre) / size, (box.upper - box.lower) / size
        X, Q, ok = poses(m0, box.lower + self.S * (box.upper - box.lower), self.config)
        if not np.all(ok):
            return False, None, "a sample of the start box does not assemble", 0, None
        y0 = np.hstack([X[:, c.dep_index], Q]).ravel()
        ylo = np.r_[m0.x_lower[c.dep_index], np.full(c.nq, -np.inf)]
        yhi = np.r_[m0.x_upper[c.dep_index], np.full(c.nq, np.inf)]
        lbx = np.r_[np.full(d, -np.inf), np.full(d, 1e-10), np.zeros(len(names)), np.tile(ylo, N)]
        ubx = np.r_[np.full(d, np.inf), np.full(d, np.inf), np.ones(len(names)), np.tile(yhi, N)]
        par = np.r_[model.p, lo, hi - lo, self.S.T.ravel(order="F"), centre, size]
        z, conv, status, iters = self.nlp.solve(np.r_[u0, w0, z0, y0], par, lbx, ubx, self.lbg, self.ubg)
        return conv, z if conv else None, status, iters, (centre, size)

    def design(self, z: np.ndarray) -> dict[str, float]:
        """The varied parameters of the NLP's solution ``z``."""
        d, lo, hi = self.model.closure.nq, self.lo, self.hi
        return dict(zip(self.names, lo + (hi - lo) * z[2 * d : 2 * d + len(self.names)]))


def _objective(starts: _Starts, footprint: Mapping[str, float], run: tuple) -> float | None:
    """Volume per footprint of a converged start's design; None for a failed one."""
    if not run[0]:
        return None
    d = starts.model.closure.nq
    z, (_centre, size) = run[1], run[4]
    vol = float(np.prod(size * z[d : 2 * d]))
    return vol / footprint_of({**starts.model.parameters, **starts.design(z)}, footprint)


def cuboid_synthesis(
    model: Model,
    design: Mapping[str, tuple[float, float]],
    footprint: Mapping[str, float] | None = None,
    solver: SolverConfig | None = None,
    *,
    starts: int = 4,
    seed: int = 0,
    samples_per_edge: int | None = None,
    check_per_edge: int | None = None,
    rebuild: Callable[[dict[str, float]], Model] | None = None,
) -> SynthesisResult:
    """The design that maximises the inscribed cuboid per unit of footprint (see
    the module docstring).

    Parameters
    ----------
    design
        parameter name -> (low, high) bounds (SI) of the parameters that vary;
    footprint
        parameter name -> exponent (F = Π p^e; None: volume);
    rebuild
        ``parameters -> Model`` for a design (default: the model's closure and limits with the
        new parameters).
    """
    t_start = time.perf_counter()
    config = solver or SolverConfig()
    c = model.closure
    footprint = dict(footprint or {})
    names, lo, hi = _design_bounds(model, design, footprint)
    lc = model.characteristic_length
    mech = model.mechanism
    build = rebuild or (lambda params: Model(c, params, model.limits, characteristic_length=lc, mechanism=mech))
    design_idx = tuple(c.parameters.index(n) for n in names)
    exps = tuple(float(footprint.get(n, 0.0)) for n in names)
    d = c.nq
    if samples_per_edge is None:  # 3 per edge, fewer in more than 3 task coordinates
        samples_per_edge = default_per_edge(d, 3, DEFAULT_NLP_SAMPLES)
    if check_per_edge is None:
        check_per_edge = default_per_edge(d, 9, DEFAULT_CHECK_POINTS)
    S = surface_grid(d, samples_per_edge)
    N = len(S)
    lo_b, hi_b = limit_bounds(model)
    active = tuple(bool(v) for v in (np.isfinite(lo_b) | np.isfinite(hi_b)))
    key = f"synthesis:{N}:{''.join('1' if a else '0' for a in active)}:{design_idx}:{exps}"
    nlp = solvers_of(c).get(key, config, lambda: SynthesisNLP(c, N, active, design_idx, exps, config))
    rows = nlp.rows
    lo_a, hi_a = lo_b[rows], hi_b[rows]
    lo_a = np.where(np.isfinite(lo_a), lo_a + NLP_MARGIN, lo_a)
    hi_a = np.where(np.isfinite(hi_a), hi_a - NLP_MARGIN, hi_a)
    lbg, ubg = np.tile(np.r_[np.zeros(c.nx), lo_a], N), np.tile(np.r_[np.zeros(c.nx), hi_a], N)
    start_check = default_per_edge(d, 5, DEFAULT_CHECK_POINTS)
    shared = _Starts(model, names, lo, hi, build, nlp, lbg, ubg, S, config, seed, samples_per_edge, start_check)
    first = np.array([model.parameters[n] for n in names])
    z_starts = uniform_starts(np.zeros(len(names)), np.ones(len(names)), starts, seed, (first - lo) / (hi - lo))
    # progress; Ctrl-C between starts and inside IPOPT
    runs = [shared.run(z0) for z0 in track(z_starts, "synthesis starts")]
    iterations = sum(r[3] for r in runs)
    objs = [_objective(shared, footprint, r) for r in runs]
    best, agreed = best_and_agreement([-v if v is not None else None for v in objs])
    converged = [v for v in objs if v is not None]
    if best is None:
        reasons = sorted({r[2] for r in runs})
        return SynthesisResult(
            False,
            f"no start converged ({'; '.join(reasons)})",
            starts=len(runs),
            iterations=iterations,
            seconds=time.perf_counter() - t_start,
            infeasible=all("Infeasible" in r[2] or "no cuboid" in r[2] for r in runs),
        )
    z, (centre, size) = runs[best][1], runs[best][4]
    params = dict(model.parameters)
    params.update({n: float(v) for n, v in shared.design(z).items()})
    params.update({n: float(np.clip(params[n], lo[k], hi[k])) for k, n in enumerate(names)})
    lower = centre + size * z[:d]
    m_opt = build(params)
    upper = lower + size * z[d : 2 * d]
    lower, upper, shrink, check = shrink_to_pass(m_opt, lower, upper, check_per_edge, config, steps=SHRINK_STEPS)
    volume = float(np.prod(upper - lower))
    fp = footprint_of(params, footprint)
    msg = f"best of {len(runs)} starts ({len(converged)} converged, {agreed} agree within {AGREEMENT:g})"
    if shrink < 1.0:
        msg += f"; shrunk by a factor {shrink:.10g} about its centre to pass the membership check"
    if not check.passed or shrink == 0.0:
        return SynthesisResult(
            False,
            f"the optimal design's box does not pass the membership check ({check.binding})",
            starts=len(runs),
            converged=len(converged),
            iterations=iterations,
            seconds=time.perf_counter() - t_start,
        )
    return SynthesisResult(
        True,
        msg,
        parameters=params,
        lower=lower,
        upper=upper,
        volume=volume,
        footprint=fp,
        objective=volume / fp,
        check=check,
        shrink=shrink,
        starts=len(runs),
        converged=len(converged),
        agreed=agreed,
        iterations=iterations,
        seconds=time.perf_counter() - t_start,
        start_objectives=converged,
    )
