"""The pose checks every solution passes before it is reported solved -- loop-closure
residual, assembly branch, round trip through the closed-form IK, conditioning of Φ_x, joint
limits -- and **the status rule** that turns them into a [`Status`][cpm_nlp.core.result.Status].

The rule is written once (`status_rules`) and evaluated both symbolically (inside every
kernel of `cpm_nlp.core.kernels`, so exported C code reports a status) and on numpy arrays
(single solves, refinement of batch results).  Status codes are the positions in
`STATUSES`.

Conditioning: the single-pose check uses the 2-norm condition number of Φ_x
(numpy).  A kernel cannot compute singular values, so it uses the 1-norm
condition number κ₁ = ‖Φ_x‖₁‖Φ_x⁻¹‖₁, which bounds the 2-norm one within a
factor n: κ₂ ≤ n κ₁.  The kernel flags a pose singular when κ₁ ≥ 10¹⁰/n --
conservative, it never misses a pose the single check would flag -- and the
batch path recomputes κ₂ with numpy for the (rare) flagged poses, so batch
and single statuses agree exactly.  Exported code keeps the conservative flag.
A closure solved through normal equations (``LoopClosure.loops``: an
overconstrained linkage, Φ = Aᵀ e with e every closure equation) would square
the condition number in Φ_x (≈ e_xᵀ e_x up to scaling where e = 0): its
conditioning is measured on e_x instead (``LoopClosure.cond_matrix``), the
2-norm deciding on κ₂(e_x) = σ_max/σ_min and the kernels reporting as
``cond1`` the upper bound of κ₂(e_x) of
`cond2_left_inverse_bound` (a block left inverse at the pose;
first derivatives only), flagged at 10¹⁰/2 (the bound is of κ₂ itself; 2 covers rounding:
`screen_factor`).
"""

from __future__ import annotations

import functools
from collections.abc import Callable, Mapping, Sequence
from typing import Any

import casadi as ca
import numpy as np

from .conditioning import (
    all_finite,
    closure_blocks,
    cond1_block_bound,
    cond1_bound,
    cond2_left_inverse_bound,
    robust_max_abs,
)
from .model import Coordinate, LoopClosure, Model
from .result import Status
from .solver import solvers_of

#: FK/IK round trips must agree to this multiple of the residual tolerance.
ROUND_TRIP_FACTOR = 100.0
#: Φ_x (or Φ_y) with a larger condition number is reported singular.
SINGULAR_CONDITION = 1e10
#: status code = position in this tuple (exported code reports codes)
STATUSES: tuple[Status, ...] = tuple(Status)
#: check outputs of every kernel (besides the pose itself and the status)
CHECKS = ("residual", "branch_margin", "round_trip_error", "cond1", "limit_margin")


def code_of(status: Status) -> int:
    return STATUSES.index(status)


def status_of(code: Any) -> Status:
    """The [`Status`][cpm_nlp.core.result.Status] of a code output by a kernel, an exported function or a batch."""
    value = code.full() if isinstance(code, ca.DM) else code
    return STATUSES[int(np.asarray(value, dtype=float).reshape(-1)[0])]


# -- the status rule, symbolic or numeric ----------------------------------------------------


class _Ops:
    """The two operations the status rules are written with, for one kind of value (a plain
    class: a dataclass costs every process 0.5 ms to create; issue 23, start-up)."""

    __slots__ = ("where", "not_")

    def __init__(self, where: Callable, not_: Callable) -> None:
        self.where = where
        self.not_ = not_


NUMPY = _Ops(np.where, np.logical_not)
CASADI = _Ops(ca.if_else, ca.logic_not)
SCALAR = _Ops(lambda c, a, b: a if c else b, lambda v: not v)


def status_rules(checks: Mapping[str, Any], tolerance: Any, singular: Any, ops: _Ops) -> list[tuple[Any, Status]]:
    """The checks of a candidate pose, in order; the first that fails gives the status.

    ``checks`` holds ``finite`` (pose and joints are finite numbers) and the
    values named in `CHECKS`; ``singular`` is the conditioning verdict.
    Written with ``not (value within bound)`` so that NaN always fails.
    """
    return [
        (ops.not_(checks["finite"]), Status.NOT_CONVERGED),
        (ops.not_(checks["residual"] <= tolerance), Status.RESIDUAL_TOO_LARGE),
        (ops.not_(checks["branch_margin"] > 0), Status.WRONG_BRANCH),
        (ops.not_(checks["round_trip_error"] <= ROUND_TRIP_FACTOR * tolerance), Status.WRONG_BRANCH),
        (singular, Status.SINGULAR),
        (ops.not_(checks["limit_margin"] >= 0), Status.OUTSIDE_JOINT_LIMITS),
    ]


def status_code(rules: Sequence[tuple[Any, Status]], ops: _Ops, otherwise: Any = 0) -> Any:
    """Code of the first failed rule, else ``otherwise`` (default: solved)."""
    code = otherwise
    for failed, status in reversed(rules):
        code = ops.where(failed, code_of(status), code)
    return code


def is_singular(cond: Any, ops: _Ops, factor: float = 1.0) -> Any:
    """cond >= SINGULAR_CONDITION / factor, true for NaN."""
    return ops.not_(cond < SINGULAR_CONDITION / factor)


def condition_number(cond_x: np.ndarray, nx: int) -> float:
    """κ₂ = σ_max/σ_min of a closure's `cond_matrix` at a
    pose (flat, column-major, as a Function returns it; Φ_x, or the m x nx Jacobian of every
    closure equation of normal equations): the 2-norm that decides a flagged pose; inf where
    σ_min = 0."""
    sv = np.linalg.svd(np.asarray(cond_x, dtype=float).reshape(nx, -1), compute_uv=False)  # its transpose
    return float(sv[0] / sv[-1]) if sv[-1] > 0 else float("inf")


#: the screen's margin where ``cond1`` bounds κ₂ itself (normal equations): rounding in the bound
#: and in the SVD that decides, both of relative size ~κ u (1e-6 at the threshold)
KAPPA2_SCREEN_MARGIN = 2.0


def screen_factor(closure: LoopClosure) -> float:
    """The kernels flag a pose singular where ``cond1 >= SINGULAR_CONDITION / factor``: n for κ₁ of
    Φ_x (κ₂ <= n κ₁), `KAPPA2_SCREEN_MARGIN` for a closure solved through normal equations
    (cond1 an upper bound of κ₂ of every closure equation's Jacobian)."""
    return float(closure.nx) if closure.loops is None else KAPPA2_SCREEN_MARGIN


# -- symbolic checks ----------------------------------------------------------------------------


def check_expressions(
    closure: LoopClosure,
    x: ca.SX,
    q: ca.SX,
    p: ca.SX,
    lower: ca.SX,
    upper: ca.SX,
    phi_x_home_inv: ca.SX | None = None,
    block_bound: bool = False,
    unlimited: bool = False,
) -> dict[str, ca.SX]:
    """Symbolic checks of the pose (x, q): see `CHECKS`.

    A closure solved through normal equations (``closure.loops``): ``cond1`` is instead the upper
    bound of `cond2_left_inverse_bound` on κ₂ of e_x, the Jacobian of every closure
    equation (``cond_matrix``), whatever the flags: the conditioning a square closure's Φ_x
    measures, not the square of it that Φ_x of the normal equations carries.  Since it bounds
    κ₂ itself, the screen's margin is `KAPPA2_SCREEN_MARGIN` there (`screen_factor`).
    ``cond_matrix``: the matrix the 2-norm check decides on (Φ_x or e_x).

    Parameters
    ----------
    lower, upper
        limits of `limited_coordinates` (q, x, passive joints), ±inf where none is declared.
    phi_x_home_inv
        if given (a numeric nx x nx input, Φ_x⁻¹ at the home pose), ``cond1`` is the certified
        upper bound of `cond1_bound` instead of the exact 1-norm condition number (which needs a
        symbolic inverse of Φ_x).
    block_bound
        ``cond1`` is the upper bound of `cond1_block_bound` (inverses of Φ_x's diagonal blocks
        at the pose; takes precedence over phi_x_home_inv).
    unlimited
        the checks where every limit is infinite (lower and upper unused): the same numbers as
        with lower = -inf and upper = +inf, in fewer operations -- no angle is reduced (the
        reduction is the identity without a finite range), and a joint is within (-inf, inf)
        unless it is NaN (±inf is inside: its margin is inf - inf = NaN on one side, and
        fmin takes the other, +inf), so ``limit_margin`` is +inf, or -inf where a joint is NaN.
    """
    c = closure
    out: dict[str, ca.SX] = {"finite": all_finite(ca.vertcat(x, q))}
    res = c.phi(x, q, p)
    if c.loops is not None:  # phi combines the closure equations (normal equations): check each of them
        res = ca.vertcat(res, c.loops(x, q, p))
    out["residual"] = robust_max_abs(res)
    if c.branch is not None:
        g = c.branch(x, q, p)
        out["branch_margin"] = ca.if_else(all_finite(g), ca.mmin(g), -ca.inf)
    else:
        out["branch_margin"] = ca.SX(ca.inf)
    if c.ik is not None:
        x_ik, q_ik, reach = c.ik(x[list(c.task_index)], p)
        # an angle and its value a whole turn away are one joint position (IK reduces angles)
        kinds = [k.kind for k in c.x] + [k.kind for k in c.q]
        diff = ca.vertcat(x_ik - x, q_ik - q)
        err = robust_max_abs(
            ca.vertcat(*[_turns_off(diff[k]) if kind == "angle" else diff[k] for k, kind in enumerate(kinds)])
        )
        out["round_trip_error"] = ca.if_else(reach >= 0, err, ca.inf)
    else:
        out["round_trip_error"] = ca.SX(0)
    if c.loops is not None:  # normal equations: κ₂(e_x) bounded at the pose (no Φ_x: no second derivatives)
        out["cond_matrix"] = c.cond_matrix(x, q, p)  # every closure equation's Jacobian e_x
        out["cond1"] = cond2_left_inverse_bound(out["cond_matrix"], closure_blocks(c))
    else:
        phi_x = out["cond_matrix"] = c.phi_x(x, q, p)
        out["cond1"] = _cond1(phi_x, phi_x_home_inv, block_bound)
    passive = c.passive(x, q, p) if c.passive is not None else ca.SX(0, 1)
    n0 = c.nq + c.nx
    if unlimited:
        out["passive"] = passive
        joints = ca.vertcat(q, x, passive)
        # j <= inf: false for NaN alone (CasADi would fold j == j into 1)
        number = [joints[k] <= ca.inf for k in range(joints.numel())]
        out["limit_margin"] = ca.if_else(_all(number), ca.inf, -ca.inf)
        return out
    passive = (
        ca.vertcat(
            *[
                _into_range(passive[k], lower[n0 + k], upper[n0 + k]) if coord.kind == "angle" else passive[k]
                for k, coord in enumerate(c.passive_coords)
            ]
        )
        if passive.numel()
        else passive
    )
    out["passive"] = passive
    # an actuator or pose angle a whole turn from its range is the same joint position: its limit
    # is checked on its value reduced into the range, as the passive joints' (the value is kept)
    nq = c.nq
    turned = [
        _into_range(v[k], lower[off + k], upper[off + k]) if coord.kind == "angle" else v[k]
        for v, coords, off in ((q, c.q, 0), (x, c.x, nq))
        for k, coord in enumerate(coords)
    ]
    joints = ca.vertcat(*turned, passive)  # the order of limited_coordinates
    if joints.numel():
        inside = ca.logic_and(joints >= lower, joints <= upper)
        margins = ca.if_else(inside, ca.fmin(joints - lower, upper - joints), -ca.inf)
        out["limit_margin"] = ca.mmin(margins)
    else:  # pragma: no cover - every mechanism has actuators
        out["limit_margin"] = ca.SX(ca.inf)
    return out


def _all(flags: list[ca.SX]) -> ca.SX:
    """Every flag true (a balanced tree of and)."""
    while len(flags) > 1:
        pairs = range(0, len(flags), 2)
        flags = [ca.logic_and(flags[k], flags[k + 1]) if k + 1 < len(flags) else flags[k] for k in pairs]
    return flags[0]


def _cond1(phi_x: ca.SX, phi_x_home_inv: ca.SX | None, block_bound: bool) -> ca.SX:
    """κ₁(Φ_x) of a square closure, or the upper bound `check_expressions` asks for."""
    if block_bound:
        return cond1_block_bound(phi_x)
    if phi_x_home_inv is not None:
        return cond1_bound(ca.densify(phi_x), phi_x_home_inv)
    if ca.sprank(phi_x.sparsity()) < phi_x.size1():  # structurally singular: no inverse to take
        return ca.SX(ca.inf)
    return ca.norm_1(phi_x) * ca.norm_1(ca.inv(phi_x))


def _turns_off(d: ca.SX) -> ca.SX:
    """An angle difference less its whole turns, in [-pi, pi)."""
    return d - 2 * ca.pi * ca.floor(d / (2 * ca.pi) + 0.5)


def _into_range(v: ca.SX, low: ca.SX, high: ca.SX) -> ca.SX:
    """A passive joint angle with a finite range [low, high] reduced by whole turns as
    `cpm_nlp.core.kinematics.reduce_angle` reduces the pose and the actuators: v if
    it is in the range, else its value in (-pi, pi] if that is, else its lowest turn in the
    range, else (outside) its value in (-pi, pi].  Without a finite range: unchanged.

    On SX arguments, the scalar Function of `_into_range_function` replays the same
    operations in CasADi's C++ (the same expression, instruction for instruction) instead of
    each through CasADi's Python operators: 6 of the 9 ms of the 3-PRS's pose checks, which
    every process builds (issue 23, start-up)."""
    if all(isinstance(a, ca.SX) for a in (v, low, high)):
        return _into_range_function()(v, low, high)
    return _into_range_expression(v, low, high)


@functools.cache
def _into_range_function() -> ca.Function:
    """`_into_range` of scalars as one CasADi Function (built once per process)."""
    v, low, high = ca.SX.sym("v"), ca.SX.sym("low"), ca.SX.sym("high")
    return ca.Function(
        "into_range", [v, low, high], [_into_range_expression(v, low, high)], ["v", "low", "high"], ["reduced"]
    )


def _into_range_expression(v: ca.SX, low: ca.SX, high: ca.SX) -> ca.SX:
    """The expression of `_into_range`."""
    finite = ca.logic_and(low > -ca.inf, high < ca.inf)
    base = ca.if_else(finite, low, 0)
    r = v - 2 * ca.pi * ca.ceil((v - ca.pi) / (2 * ca.pi))  # in (-pi, pi]
    lowest = v - 2 * ca.pi * ca.floor((v - base) / (2 * ca.pi))  # in [low, low + 2 pi)
    inside = lambda a: ca.logic_and(a >= low, a <= high)  # noqa: E731
    reduced = ca.if_else(inside(v), v, ca.if_else(inside(r), r, ca.if_else(inside(lowest), lowest, r)))
    return ca.if_else(finite, reduced, v)


def limited_coordinates(closure: LoopClosure) -> tuple[Coordinate, ...]:
    """Every coordinate a limit may apply to, in the kernels' order: actuators q,
    pose coordinates x (some are joint angles, e.g. the pantograph's phi) and
    passive joints."""
    return closure.q + closure.x + closure.passive_coords


def limit_vectors(model: Model) -> tuple[np.ndarray, np.ndarray]:
    """Declared limits of `limited_coordinates`, ±inf where none is declared."""
    c = model.closure
    coords = limited_coordinates(c)
    lower = np.full(len(coords), -np.inf)
    upper = np.full(len(coords), np.inf)
    if model.limits:
        for k, coord in enumerate(coords):
            lim = model.limit_of(coord)
            if lim is not None:
                lower[k], upper[k] = lim
    return lower, upper


def n_joints(closure: LoopClosure) -> int:
    return len(limited_coordinates(closure))


def checks_function(closure: LoopClosure) -> ca.Function:
    """``pose_checks: (x, q, p, lower, upper, tol) -> (passive, residual,
    branch_margin, round_trip_error, cond1, limit_margin, cond_matrix, status)``;
    status with the conservative (1-norm) singularity screen; ``cond_matrix`` is
    `LoopClosure.cond_matrix` (Φ_x; for a closure solved through normal
    equations, ``loops``, the Jacobian of every closure equation, and cond1 the
    upper bound of `cond2_left_inverse_bound` on its κ₂)."""

    def build() -> ca.Function:
        c = closure
        x, q, p = ca.SX.sym("x", c.nx), ca.SX.sym("q", c.nq), ca.SX.sym("p", c.np)
        nl = n_joints(c)
        lower, upper, tol = ca.SX.sym("lower", nl), ca.SX.sym("upper", nl), ca.SX.sym("tol")
        # normal equations: an upper bound of κ₂ of every closure equation's Jacobian (see check_expressions)
        chk = check_expressions(c, x, q, p, lower, upper)
        singular = is_singular(chk["cond1"], CASADI, factor=screen_factor(c))
        status = status_code(status_rules(chk, tol, singular, CASADI), CASADI)
        names = ["passive", *CHECKS, "cond_matrix"]
        return ca.Function(
            f"{c.name}_pose_checks",
            [x, q, p, lower, upper, tol],
            [ca.densify(chk[n]) for n in names] + [status],
            ["x", "q", "p", "lower", "upper", "tol"],
            names + ["status"],
        )

    return solvers_of(closure).memo(("pose_checks",), build)
