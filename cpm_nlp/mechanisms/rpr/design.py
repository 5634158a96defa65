"""Motion/force transmission and dimensional synthesis of the 2-RPU-UPR
(rpr-2rpu-upr-zhang-2022.md, section 2.3, eq 1 and 14-26).

* `transmission_screws` -- the locked-leg twist systems (eq 14-15), the
  constraint wrenches H1..H5 (eq 16), the output twist S_O (eq 17) and the
  transmission wrench S_T of leg A1B1 (eq 18) at the initial pose, referred to
  the fixed origin o as in the paper;
* `eta_expression` -- the output transmission index η (eq 19), symbolic in
  (r1, r2, P) so that IPOPT can optimise it;
* design space: D and the normalized l1, l2, l3 (eq 20-21), the constraints of
  eq 22 (`design_space_violation`), the (s, t) plane (eq 23);
* `transmission_map` -- η over a grid of the (s, t) triangle (Fig. 4),
  ``nan`` outside eq 22;
* `synthesis` -- maximise η under eq 22 by IPOPT from several starts.

Readings (documented, not tuned):

* |S_T ∘ S_O|max "is equal to the distance from B1 to S_O" (section 2.3.1,
  after Wang, Wu, Liu 2010): ``eta_max = "distance"`` uses the distance from B1
  to the axis of the unit output twist.  S_O has a pitch (it is a screw, not a
  rotation: leg 1 alone both tilts and lifts the platform); Wang et al. bound
  the power by the speed of the point B1, sqrt(d² + h²): ``eta_max =
  "velocity"`` offers that reading.
* η tends to 1 as P -> 0 (l3 -> 0) everywhere on the edge l3 = 0 of eq 22,
  which eq 22 excludes (0 < l3); a synthesis therefore needs a smallest
  admissible normalized parameter ``l_min``.
* With r1 on the x axis (eq 3, 5; confirmed by eq 45), η(r1, r2, P) =
  [1 + (P r2 / (2 r1 sqrt(r1² + r2²)))²]^(-1/2): it grows with r1 and falls with
  r2, so the paper's choice l = (0.75, 1.5, 0.75) (eq 25) has η = 0.913 while
  its two "comparison" designs of eq 47 and 49, (1, 1, 1) and (1.5, 0.75, 0.75),
  have 0.943 and 0.994.  The paper's ranking is what η gives with r1 and r2
  exchanged, i.e. with the naming of its section 2 text (r1 = |o'B2|,
  r2 = |oA1|); the model keeps the equations' geometry and reports the
  disagreement (problems/rpr_synthesis.yaml).
"""

from __future__ import annotations

import functools
import logging
import math
import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import casadi as ca
import numpy as np

from ...core import screws
from ...core.errors import InputError
from ...core.model import Model
from ...core.result import Status
from ...core.solver import SolverConfig, solvers_of, translate_casadi_error

log = logging.getLogger(__name__)

ETA_MAX_MODES = ("distance", "velocity")
SQRT3 = math.sqrt(3.0)
#: the paper's chosen point (eq 24)
PAPER_POINT = (1.5, 0.0)


# -- transmission index, eq 14-19 ------------------------------------------------------------------


def _points(r1, r2, P):
    A = [ca.vertcat(r1, 0, 0), ca.vertcat(0, r2, 0), ca.vertcat(-r1, 0, 0)]
    B = [a + ca.vertcat(0, 0, P) for a in A]
    return A, B


def locked_twists(r1, r2, P):
    """The twist systems of legs 3 and 2 with their actuators locked (eq 14, 15),
    referred to o, at the initial pose."""
    A, B = _points(r1, r2, P)
    x, y = ca.DM([1, 0, 0]), ca.DM([0, 1, 0])
    leg3 = [screws.rotation(y, A[2]), screws.rotation(y, B[2]), screws.rotation(x, B[2])]  # eq 14
    leg2 = [screws.rotation(y, A[1]), screws.rotation(x, A[1]), screws.rotation(x, B[1])]  # eq 15
    return ca.horzcat(*leg3), ca.horzcat(*leg2)


def transmission_screws(r1, r2, P) -> dict:
    """H (6 x 5, eq 16), S_O (eq 17, |s| = 1), S_T (eq 18) and B1, referred to o."""
    A, B = _points(r1, r2, P)
    x, y, z = ca.DM([1, 0, 0]), ca.DM([0, 1, 0]), ca.DM([0, 0, 1])
    H = ca.horzcat(
        screws.couple(z),  # H1
        screws.force(y, B[2]),  # H2
        screws.force(z, B[2]),  # H3
        screws.force(x, A[1]),  # H4
        screws.force(z, A[1]),  # H5
    )
    S_O = screws.normalize(screws.null_screw(H))  # eq 17
    S_T = screws.force(z, A[0])  # eq 18
    return {"H": H, "S_O": S_O, "S_T": S_T, "B1": B[0]}


def eta_expression(r1, r2, P, eta_max: str = "distance"):
    """η of leg A1B1 (eq 19) as a CasADi expression of (r1, r2, P)."""
    if eta_max not in ETA_MAX_MODES:
        raise ValueError(f"unknown eta_max {eta_max!r}")
    sc = transmission_screws(r1, r2, P)
    num = ca.fabs(screws.reciprocal(sc["S_T"], sc["S_O"]))
    if eta_max == "distance":
        den = screws.distance_to_axis(sc["S_O"], sc["B1"])
    else:
        den = ca.norm_2(screws.velocity_at(sc["S_O"], ca.DM.zeros(3), sc["B1"]))
    return num / den


@functools.lru_cache(maxsize=4)
def eta_function(eta_max: str = "distance") -> ca.Function:
    """``("eta", [r1, r2, P], [eta])``, built once per mode (code, not data)."""
    r1, r2, P = ca.SX.sym("r1"), ca.SX.sym("r2"), ca.SX.sym("P")
    return ca.Function("eta", [r1, r2, P], [eta_expression(r1, r2, P, eta_max)], ["r1", "r2", "P"], ["eta"])


def eta(r1: float, r2: float, P: float, eta_max: str = "distance") -> float:
    """η (eq 19) of the design (r1, r2, P) at its initial pose."""
    return float(eta_function(eta_max)(r1, r2, P))


# -- design space, eq 20-23 -------------------------------------------------------------------------


def normalize(r1: float, r2: float, P: float) -> tuple[float, float, float, float]:
    """(D, l1, l2, l3) of eq 20-21."""
    D = (r1 + r2 + P) / 3.0
    return D, r1 / D, r2 / D, P / D


def to_plane(l1: float, l2: float, l3: float) -> tuple[float, float]:
    """(s, t) = (l2, (l3 - l1)/sqrt(3)) (eq 23)."""
    return l2, (l3 - l1) / SQRT3


def from_plane(s: float, t: float) -> tuple[float, float, float]:
    """(l1, l2, l3) of the point (s, t) of eq 23 with l1 + l2 + l3 = 3."""
    l1 = (3.0 - s - SQRT3 * t) / 2.0
    l3 = (3.0 - s + SQRT3 * t) / 2.0
    return l1, s, l3


def design_space_violation(l1: float, l2: float, l3: float, tol: float = 1e-9) -> str | None:
    """None if (l1, l2, l3) satisfies eq 22, else which condition it breaks.
    The strict bounds 0 < l_i < 3 keep a margin ``tol`` (a grid point on the
    excluded edge l3 = 0 is not admitted by round-off); the others allow it."""
    ls = (l1, l2, l3)
    for k, v in enumerate(ls, start=1):
        if not (tol < v < 3.0 - tol):
            return f"l{k} = {v:.6g} is not in (0, 3)"
    if abs(sum(ls) - 3.0) > tol:
        return f"l1 + l2 + l3 = {sum(ls):.6g}, not 3"
    if not (0.5 * l1 - tol <= l2 <= 2.0 * l1 + tol):
        return f"l2 = {l2:.6g} is not within [l1/2, 2 l1] = [{0.5 * l1:.6g}, {2 * l1:.6g}]"
    return None


def check_design_space(l1: float, l2: float, l3: float, path: tuple) -> None:
    """Raise [`InputError`][cpm_nlp.core.errors.InputError] for normalized parameters outside eq 22."""
    why = design_space_violation(l1, l2, l3)
    if why:
        raise InputError(
            f"normalized parameters outside the design space of eq 22 ({why}); expected 0 < l1, l2, l3 < 3, "
            "l1 + l2 + l3 = 3 and l1/2 <= l2 <= 2 l1",
            path=path,
        )


def transmission_map(s: Sequence[float], t: Sequence[float], eta_max: str = "distance") -> np.ndarray:
    """η over the grid (rows: t, columns: s), ``nan`` where (s, t) is outside eq 22."""
    s = np.asarray(s, dtype=float)
    t = np.asarray(t, dtype=float)
    S, T = np.meshgrid(s, t)
    L1, L2, L3 = from_plane(S, T)
    inside = np.array(
        [design_space_violation(a, b, c) is None for a, b, c in zip(L1.ravel(), L2.ravel(), L3.ravel())]
    ).reshape(S.shape)
    out = np.full(S.shape, np.nan)
    if inside.any():
        f = eta_function(eta_max).map(int(inside.sum()))
        out[inside] = np.asarray(f(L1[inside], L2[inside], L3[inside])).ravel()
    return out


# -- synthesis -----------------------------------------------------------------------------------------


@dataclass
class SynthesisResult:
    """Best design found by the multi-start IPOPT synthesis.

    Attributes
    ----------
    l
        (l1, l2, l3);
    eta
        its η;
    starts
        number of starts;
    converged
        how many converged;
    at_best
        how many of those reached the best η (within 1e-8);
    optima
        the distinct local optima (l1, l2, l3, η), best first.
    """

    status: Status
    l: tuple[float, float, float] | None = None
    eta: float | None = None
    starts: int = 0
    converged: int = 0
    at_best: int = 0
    optima: list[tuple[float, float, float, float]] = field(default_factory=list)
    iterations: int = 0
    seconds: float = 0.0
    message: str = ""


def optimisation_options(config: SolverConfig) -> dict:
    """The configuration's CasADi options; unless the user set it, IPOPT keeps
    the solution exactly within the bounds (bound_relax_factor 0), so that a
    design on a bound of eq 22 or of the size box reports the bound itself."""
    opts = config.casadi_options()
    opts.setdefault("ipopt.bound_relax_factor", 0.0)
    return opts


class _SynthesisSolver:
    """IPOPT for max η(l) s.t. l1 + l2 + l3 = 3, l1/2 <= l2 <= 2 l1, bounds
    (eq 22); built once per (eta_max, solver configuration)."""

    def __init__(self, eta_max: str, config: SolverConfig) -> None:
        l = ca.SX.sym("l", 3)
        e = eta_expression(l[0], l[1], l[2], eta_max)
        g = ca.vertcat(l[0] + l[1] + l[2] - 3.0, l[1] - 0.5 * l[0], 2.0 * l[0] - l[1])
        try:
            self.fn = ca.nlpsol(
                f"rpr_synthesis_{eta_max}", "ipopt", {"x": l, "f": -e, "g": g}, optimisation_options(config)
            )
        except RuntimeError as exc:
            raise translate_casadi_error(exc, config.options) from exc

    def solve(self, x0, lbx, ubx):
        out = self.fn(x0=x0, lbx=lbx, ubx=ubx, lbg=[0.0, 0.0, 0.0], ubg=[0.0, ca.inf, ca.inf])
        stats = self.fn.stats()
        return np.asarray(out["x"]).ravel(), stats


def start_points(count: int, l_min: float) -> np.ndarray:
    """``count`` deterministic starts spread over the eq 22 triangle (a Halton
    sequence in (s, t), the points outside the design space skipped)."""
    from scipy.stats import qmc  # here: scipy.stats takes 0.5 s to import (start-up of every rpr problem)

    sampler = qmc.Halton(d=2, scramble=False)
    out: list[tuple[float, float, float]] = []
    while len(out) < count:
        s_, t_ = sampler.random(64).T
        for a, b in zip(2.0 * s_, -2.0 / SQRT3 + (SQRT3 + 2.0 / SQRT3) * t_):
            ls = from_plane(a, b)
            if design_space_violation(*ls) is None and min(ls) >= l_min:
                out.append(ls)
                if len(out) == count:
                    break
    return np.array(out)


def synthesis(
    model: Model,
    config: SolverConfig,
    *,
    l_min: float,
    fixed: Mapping[str, float] | None = None,
    starts: int = 8,
    eta_max: str = "distance",
) -> SynthesisResult:
    """Maximise η (eq 19) over the normalized design space of eq 22 with
    l_i >= l_min, by IPOPT from ``starts`` points; ``fixed`` pins any of
    l1, l2, l3.  The built solver is cached on the model's mechanism type."""
    fixed = dict(fixed or {})
    t0 = time.perf_counter()
    built = solvers_of(model.closure).get(f"rpr_synthesis_{eta_max}", config, lambda: _SynthesisSolver(eta_max, config))
    lbx = np.full(3, l_min)
    ubx = np.full(3, 3.0 - 2.0 * l_min)
    for k, name in enumerate(("l1", "l2", "l3")):
        if name in fixed:
            lbx[k] = ubx[k] = fixed[name]
    x0s = start_points(starts, l_min)
    found: list[tuple[np.ndarray, float]] = []
    iterations = 0
    failures: list[str] = []
    for x0 in x0s:
        x0 = np.clip(x0, lbx, ubx)
        try:
            l, stats = built.solve(x0, lbx, ubx)
        except RuntimeError as exc:
            log.debug("synthesis start %s: %s", x0, exc)
            failures.append(str(exc).splitlines()[0])
            continue
        iterations += int(stats.get("iter_count", 0))
        if not stats.get("success", False):
            log.debug("synthesis start %s: %s", x0, stats.get("return_status"))
            failures.append(str(stats.get("return_status", "")))
            continue
        if design_space_violation(*l, tol=1e-7) is not None or np.any(l < lbx - 1e-7) or np.any(l > ubx + 1e-7):
            failures.append("converged to a point outside eq 22")
            continue
        found.append((l, eta(*l, eta_max=eta_max)))
    seconds = time.perf_counter() - t0
    if not found:
        infeasible = any("Infeasible" in f for f in failures)
        status = Status.INFEASIBLE if infeasible else Status.NOT_CONVERGED
        msg = f"no start converged ({failures[0] if failures else 'no start'})"
        return SynthesisResult(status, starts=len(x0s), iterations=iterations, seconds=seconds, message=msg)
    found.sort(key=lambda item: -item[1])
    best_l, best_eta = found[0]
    optima: list[tuple[float, float, float, float]] = []
    for l, e in found:
        if all(np.max(np.abs(l - np.array(o[:3]))) > 1e-6 for o in optima):
            optima.append((*map(float, l), float(e)))
    at_best = sum(1 for _, e in found if abs(e - best_eta) <= 1e-8)
    return SynthesisResult(
        Status.SOLVED,
        tuple(float(v) for v in best_l),
        float(best_eta),
        len(x0s),
        len(found),
        at_best,
        optima,
        iterations,
        seconds,
        f"{len(found)} of {len(x0s)} starts converged, {at_best} to the best design",
    )
