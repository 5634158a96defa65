"""Kinematics kernels: CasADi Functions built generically from a
:class:`~cpm_nlp.core.model.LoopClosure`, for single solves, batches, embedding
and exported code.

* **The pose checks** every solution passes before it is reported solved --
  loop-closure residual, assembly branch, round trip through the closed-form
  IK, conditioning of Φ_x, joint limits -- and **the status rule** that turns
  them into a :class:`~cpm_nlp.core.result.Status`.  The rule is written once
  (:func:`status_rules`) and evaluated both symbolically (inside every kernel,
  so exported C code reports a status) and on numpy arrays (single solves,
  refinement of batch results).
* **FK kernel**: Newton's method from a guess, with CasADi's ``fast_newton``
  rootfinder (it generates C code; its derivatives come from the implicit
  function theorem), followed by the checks.
* **IK kernel**: the closed form where the mechanism has one (else
  ``fast_newton`` on the IK residual), followed by the checks.
* **Jacobian kernel**: J = -Φ_x⁻¹ Φ_q and the inverse Jacobian, from AD.

Kernels take the parameters p, the joint limits and the tolerance as inputs,
so one kernel -- and one compiled library -- serves every model of a
mechanism type; :func:`bake` substitutes one model's numbers (for export and
for the embedding API).  Status codes are the positions in :data:`STATUSES`.

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
``cond1`` the upper bound of κ₂(e_x) of :func:`cond2_left_inverse_bound` (a
block left inverse at the pose; first derivatives only), flagged at
10¹⁰/2 (the bound is of κ₂ itself; 2 covers rounding: :func:`screen_factor`).
"""

from __future__ import annotations

import threading
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import casadi as ca
import numpy as np

from .errors import InputError
from .model import Coordinate, LoopClosure, Model
from .result import Status
from .solver import DEFAULT_OPTIONS, SolverConfig
from .solver_options import NEWTON_BATCH, NEWTON_BATCH_IGNORED

#: FK/IK round trips must agree to this multiple of the residual tolerance.
ROUND_TRIP_FACTOR = 100.0
#: Φ_x (or Φ_y) with a larger condition number is reported singular.
SINGULAR_CONDITION = 1e10
#: status code = position in this tuple (exported code reports codes)
STATUSES: tuple[Status, ...] = tuple(Status)
#: Newton options the kernels' rootfinder (CasADi ``fast_newton``) accepts (from the one table,
#: :data:`cpm_nlp.core.solver_options.NEWTON_TABLE`)
NEWTON_OPTIONS = NEWTON_BATCH
#: options of CasADi's ``newton`` plugin that have no meaning here (fast_newton never raises or prints)
_IGNORED_NEWTON = NEWTON_BATCH_IGNORED

#: check outputs of every kernel (besides the pose itself and the status)
CHECKS = ("residual", "branch_margin", "round_trip_error", "cond1", "limit_margin")


def code_of(status: Status) -> int:
    return STATUSES.index(status)


def status_of(code: Any) -> Status:
    """The :class:`Status` of a code output by a kernel, an exported function or a batch."""
    value = code.full() if isinstance(code, ca.DM) else code
    return STATUSES[int(np.asarray(value, dtype=float).reshape(-1)[0])]


# -- the status rule, symbolic or numeric ----------------------------------------------------


@dataclass(frozen=True)
class _Ops:
    where: Callable
    not_: Callable


NUMPY = _Ops(np.where, np.logical_not)
CASADI = _Ops(ca.if_else, ca.logic_not)
SCALAR = _Ops(lambda c, a, b: a if c else b, lambda v: not v)


def status_rules(checks: Mapping[str, Any], tolerance: Any, singular: Any, ops: _Ops) -> list[tuple[Any, Status]]:
    """The checks of a candidate pose, in order; the first that fails gives the status.

    ``checks`` holds ``finite`` (pose and joints are finite numbers) and the
    values named in :data:`CHECKS`; ``singular`` is the conditioning verdict.
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
    """κ₂ = σ_max/σ_min of a closure's :attr:`~cpm_nlp.core.model.LoopClosure.cond_matrix` at a
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
    Φ_x (κ₂ <= n κ₁), :data:`KAPPA2_SCREEN_MARGIN` for a closure solved through normal equations
    (cond1 an upper bound of κ₂ of every closure equation's Jacobian)."""
    return float(closure.nx) if closure.loops is None else KAPPA2_SCREEN_MARGIN


# -- symbolic checks ----------------------------------------------------------------------------


def _all_finite(v: ca.SX) -> ca.SX:
    # |v| < inf is false for inf and NaN (not v * 0 == 0: CasADi simplifies v * 0 to 0)
    return ca.sum1(ca.fabs(ca.vec(v)) < ca.inf) == v.numel()


def _robust_max_abs(v: ca.SX) -> ca.SX:
    """max |v|, inf if any entry is NaN (C's fmax would skip NaN)."""
    return ca.if_else(_all_finite(v), ca.mmax(ca.fabs(v)), ca.inf)


def check_expressions(
    closure: LoopClosure,
    x: ca.SX,
    q: ca.SX,
    p: ca.SX,
    lower: ca.SX,
    upper: ca.SX,
    phi_x_home_inv: ca.SX | None = None,
    block_bound: bool = False,
) -> dict[str, ca.SX]:
    """Symbolic checks of the pose (x, q): see :data:`CHECKS`.

    lower, upper: limits of :func:`limited_coordinates` (q, x, passive joints),
    ±inf where none is declared.
    phi_x_home_inv: if given (a numeric nx x nx input, Φ_x⁻¹ at the home pose),
    ``cond1`` is the certified upper bound of :func:`cond1_bound` instead of
    the exact 1-norm condition number (which needs a symbolic inverse of Φ_x).
    block_bound: ``cond1`` is the upper bound of :func:`cond1_block_bound` (inverses of
    Φ_x's diagonal blocks at the pose; takes precedence over phi_x_home_inv).

    A closure solved through normal equations (``closure.loops``): ``cond1`` is instead the upper
    bound of :func:`cond2_left_inverse_bound` on κ₂ of e_x, the Jacobian of every closure
    equation (``cond_matrix``), whatever the flags: the conditioning a square closure's Φ_x
    measures, not the square of it that Φ_x of the normal equations carries.  Since it bounds
    κ₂ itself, the screen's margin is :data:`KAPPA2_SCREEN_MARGIN` there (:func:`screen_factor`).
    ``cond_matrix``: the matrix the 2-norm check decides on (Φ_x or e_x).
    """
    c = closure
    out: dict[str, ca.SX] = {"finite": _all_finite(ca.vertcat(x, q))}
    res = c.phi(x, q, p)
    if c.loops is not None:  # phi combines the closure equations (normal equations): check each of them
        res = ca.vertcat(res, c.loops(x, q, p))
    out["residual"] = _robust_max_abs(res)
    if c.branch is not None:
        g = c.branch(x, q, p)
        out["branch_margin"] = ca.if_else(_all_finite(g), ca.mmin(g), -ca.inf)
    else:
        out["branch_margin"] = ca.SX(ca.inf)
    if c.ik is not None:
        x_ik, q_ik, reach = c.ik(x[list(c.task_index)], p)
        # an angle and its value a whole turn away are one joint position (IK reduces angles)
        kinds = [k.kind for k in c.x] + [k.kind for k in c.q]
        diff = ca.vertcat(x_ik - x, q_ik - q)
        err = _robust_max_abs(
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


def _cond1(phi_x: ca.SX, phi_x_home_inv: ca.SX | None, block_bound: bool) -> ca.SX:
    """κ₁(Φ_x) of a square closure, or the upper bound :func:`check_expressions` asks for."""
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
    :func:`cpm_nlp.core.kinematics.reduce_angle` reduces the pose and the actuators: v if
    it is in the range, else its value in (-pi, pi] if that is, else its lowest turn in the
    range, else (outside) its value in (-pi, pi].  Without a finite range: unchanged."""
    finite = ca.logic_and(low > -ca.inf, high < ca.inf)
    base = ca.if_else(finite, low, 0)
    r = v - 2 * ca.pi * ca.ceil((v - ca.pi) / (2 * ca.pi))  # in (-pi, pi]
    lowest = v - 2 * ca.pi * ca.floor((v - base) / (2 * ca.pi))  # in [low, low + 2 pi)
    inside = lambda a: ca.logic_and(a >= low, a <= high)  # noqa: E731
    reduced = ca.if_else(inside(v), v, ca.if_else(inside(r), r, ca.if_else(inside(lowest), lowest, r)))
    return ca.if_else(finite, reduced, v)


#: the preconditioned residual ‖I - Φ_x B‖₁ must stay below this for :func:`cond1_bound` to certify
CERTIFY_DELTA = 0.9


def _induced_norm_1(m: ca.SX) -> ca.SX:
    """‖M‖₁ = largest column sum of |M| (the induced 1-norm)."""
    return ca.mmax(ca.sum1(ca.fabs(m)))


def _robust_norm_1(m: ca.SX) -> ca.SX:
    """‖M‖₁, inf if any entry is not finite (C's fmax would skip NaN): the column sums of |M|
    carry a NaN or inf into their total (a total that overflows also gives inf: conservative)."""
    sums = ca.sum1(ca.fabs(m))
    return ca.if_else(ca.sum2(sums) < ca.inf, ca.mmax(sums), ca.inf)


def cond1_bound(phi_x: ca.SX, b: ca.SX) -> ca.SX:
    """A certified upper bound of the 1-norm condition number of Φ_x, from an
    approximate inverse B (Φ_x⁻¹ at the home pose, numbers) and no inverse
    at the pose itself.

    With δ = ‖I - Φ_x B‖₁ < 1, Φ_x B is invertible (Neumann series) and
    ‖Φ_x⁻¹‖₁ = ‖B (Φ_x B)⁻¹‖₁ ≤ ‖B‖₁ / (1 - δ), so
    κ₁(Φ_x) ≤ ‖Φ_x‖₁ ‖B‖₁ / (1 - δ) (induced 1-norms).  Where δ >
    :data:`CERTIFY_DELTA` (far from home) or Φ_x is not finite the bound is
    +inf: nothing is certified.  Costs one nx x nx product instead of a
    symbolic inverse.
    """
    n = phi_x.size1()
    delta = _induced_norm_1(ca.DM.eye(n) - ca.mtimes(phi_x, b))
    bound = _induced_norm_1(phi_x) * _induced_norm_1(b) / (1 - delta)
    return ca.if_else(ca.logic_and(_all_finite(ca.vec(phi_x)), delta <= CERTIFY_DELTA), bound, ca.inf)


def _block_upper(u: ca.SX, rows: list[list[int]], cols: list[list[int]]) -> bool:
    """Whether u has no structural nonzero below its diagonal blocks."""
    return all(u[rows[i], cols[j]].nnz() == 0 for i in range(len(rows)) for j in range(i))


def cond1_block_bound(phi_x: ca.SX) -> ca.SX:
    """An upper bound of the 1-norm condition number of Φ_x at the pose itself, from its block
    triangular form: no approximate inverse from elsewhere, so it holds as far from home as
    Φ_x stays regular.

    The sparsity's Dulmage-Mendelsohn form (fixed when the kernel is built) permutes Φ_x to a
    block upper triangular U with square diagonal blocks D_i.  The inverse X = U⁻¹ is block
    upper triangular too: X_jj = D_j⁻¹ and X_ij = -D_i⁻¹ Σ_{i<k≤j} U_ik X_kj, so with
    α_i = ‖D_i⁻¹‖₁ (each block inverted at the pose; a 1 x 1 block is 1/d) the norms obey
    ‖X_ij‖₁ ≤ β_ij = α_i Σ_k ‖U_ik‖₁ β_kj, and ‖Φ_x⁻¹‖₁ = ‖X‖₁ ≤ max_j Σ_i β_ij (a column of
    block column j sums at most the blocks' 1-norms).  Permutations keep the 1-norm, so
    κ₁(Φ_x) ≤ ‖Φ_x‖₁ max_j Σ_i β_ij (induced 1-norms).  A structurally singular Φ_x, a
    singular block (its inverse not finite) or a Φ_x that is not finite gives +inf (NaN is
    read as singular too: :func:`is_singular`).  Costs the inverses of the diagonal blocks only
    (for a linkage's normal equations: the block of the loops' passive coordinates).
    """
    n = phi_x.size1()
    sp = phi_x.sparsity()
    if ca.sprank(sp) < n:
        return ca.SX(ca.inf)
    nb, rowperm, colperm, rowblock, colblock, *_ = sp.btf()
    rows = [list(range(rowblock[k], rowblock[k + 1])) for k in range(nb)]
    cols = [list(range(colblock[k], colblock[k + 1])) for k in range(nb)]
    u = phi_x[rowperm, colperm]
    if not _block_upper(u, rows, cols):  # the lower form (CasADi 3.6 gives it): reversing both orders makes it upper
        rowperm, colperm = rowperm[::-1], colperm[::-1]
        rows = [[n - 1 - r for r in rows[k][::-1]] for k in reversed(range(nb))]
        cols = [[n - 1 - r for r in cols[k][::-1]] for k in reversed(range(nb))]
        u = phi_x[rowperm, colperm]
        if not _block_upper(u, rows, cols):  # pragma: no cover - the Dulmage-Mendelsohn form is triangular
            return ca.SX(ca.inf)
    alpha = []
    for i in range(nb):
        d = u[rows[i], cols[i]]
        alpha.append(1 / ca.fabs(d) if d.numel() == 1 else _robust_norm_1(ca.inv(ca.densify(d))))
    beta: dict[tuple[int, int], ca.SX] = {}
    sums = []
    for j in range(nb):
        column = []
        for i in range(j, -1, -1):
            if i == j:
                b = alpha[j]
            else:
                terms = [
                    _induced_norm_1(u[rows[i], cols[k]]) * beta[k, j]
                    for k in range(i + 1, j + 1)
                    if u[rows[i], cols[k]].nnz() and (k, j) in beta
                ]
                if not terms:
                    continue
                b = alpha[i] * ca.sum1(ca.vertcat(*terms))
            beta[i, j] = b
            column.append(b)
        sums.append(ca.sum1(ca.vertcat(*column)))
    return _robust_norm_1(phi_x) * _robust_max_abs(ca.vertcat(*sums))  # inf where a sum is NaN


@dataclass(frozen=True)
class LeftInverseBlocks:
    """A block upper triangular form of e_x (m x n, m >= n: the Jacobian of every closure
    equation of a closure solved through normal equations) with tall diagonal blocks: ``rows[i]``
    (the rows of group i) and ``cols[i]`` (column block i), in order.  A row of group i has
    nonzeros in column blocks i, i+1, ... only; each diagonal block has at least as many rows as
    columns and full structural column rank.  Rows of e_x with no structural nonzero are left
    out (they add nothing to e_xᵀ e_x)."""

    rows: tuple[tuple[int, ...], ...]
    cols: tuple[tuple[int, ...], ...]


def left_inverse_blocks(e_sp: ca.Sparsity, phi_sp: ca.Sparsity) -> LeftInverseBlocks | None:
    """The column blocks of Φ_x's block triangular (Dulmage-Mendelsohn) form, in upper order, and
    each row of e_x in the group of the first column block it touches: e_x is then block upper
    triangular by construction.  Where a diagonal block would be wide or structurally singular, one
    block (the whole of e_x); None if e_x is structurally rank deficient."""
    m, n = e_sp.shape
    touched = [[] for _ in range(m)]
    for r, c in zip(*e_sp.get_triplet()):
        touched[r].append(c)
    live = [r for r in range(m) if touched[r]]
    whole = LeftInverseBlocks((tuple(live),), (tuple(range(n)),))
    if ca.sprank(e_sp) < n:
        return None
    if ca.sprank(phi_sp) < n:
        return whole
    nb, rowperm, colperm, rowblock, colblock, *_ = phi_sp.btf()
    rows = [list(range(rowblock[k], rowblock[k + 1])) for k in range(nb)]
    cols = [list(range(colblock[k], colblock[k + 1])) for k in range(nb)]
    u = ca.DM(phi_sp, 1)[rowperm, colperm]
    if not _block_upper(u, rows, cols):  # the lower form: reverse the blocks' order
        colperm = colperm[::-1]
        cols = [[n - 1 - c for c in cols[k][::-1]] for k in reversed(range(nb))]
    blocks = [tuple(colperm[c] for c in block) for block in cols]
    block_of = {c: k for k, block in enumerate(blocks) for c in block}
    groups: list[list[int]] = [[] for _ in blocks]
    for r in live:
        groups[min(block_of[c] for c in touched[r])].append(r)
    for g, b in zip(groups, blocks):
        if len(g) < len(b) or ca.sprank(ca.DM(e_sp, 1)[g, list(b)].sparsity()) < len(b):
            return whole
    return LeftInverseBlocks(tuple(tuple(g) for g in groups), tuple(blocks))


def _left_inverse_norm(d: ca.SX) -> ca.SX:
    """An upper bound of ‖D⁺‖₂ = 1/σ_min(D) for a tall block D (full column rank): 1/‖d‖₂ for a
    single column (exact), else ‖T⁻¹‖_F with D = QT its QR factorization (CasADi's modified
    Gram-Schmidt; σ_min(T) = σ_min(D), and ‖T⁻¹‖₂ <= ‖T⁻¹‖_F).  No DᵀD is formed: the bound is
    as accurate as D's smallest singular value is in floating point (κ(D) u), never κ(D)² u."""
    d = ca.densify(d)
    if d.size2() == 1:
        return 1 / ca.norm_2(d)
    _q, t = ca.qr(d)
    return ca.norm_fro(ca.solve(t, ca.SX.eye(t.size1())))


def closure_blocks(closure: LoopClosure) -> LeftInverseBlocks | None:
    """:func:`left_inverse_blocks` of a closure's e_x (built once per closure)."""
    c = closure
    return c.solvers.memo(
        ("left_inverse_blocks",),
        lambda: left_inverse_blocks(c.cond_matrix.sparsity_out(0), c.phi_x.sparsity_out(0)),
    )


def cond2_left_inverse_bound(e_x: ca.SX, blocks: LeftInverseBlocks | None) -> ca.SX:
    """An upper bound of the 2-norm condition number κ₂(e_x) = σ_max/σ_min of the (tall) Jacobian
    of every closure equation, from a block left inverse at the pose: no SVD, no e_xᵀ e_x.

    Any left inverse X (X e_x = I) bounds the smallest singular value: |v| = |X e_x v| <=
    ‖X‖₂ |e_x v|, so σ_min(e_x) >= 1/‖X‖₂.  In the form of :func:`left_inverse_blocks` (block
    upper triangular U, tall diagonal blocks D_i) one left inverse is block upper triangular:
    X_ii = D_i⁺ (the pseudo-inverse) and X_ij = -D_i⁺ Σ_{i<k<=j} U_ik X_kj, so with
    α_i >= ‖D_i⁺‖₂ (:func:`_left_inverse_norm`) the norms obey ‖X_ij‖₂ <= β_ij = α_i Σ_k ‖U_ik‖_F
    β_kj (‖·‖₂ <= ‖·‖_F), and ‖X‖₂ <= ‖(β_ij)‖₂ <= ‖(β_ij)‖_F (a block matrix's 2-norm is at most
    that of its blocks' norms).  So κ₂(e_x) <= ‖e_x‖_F ‖(β_ij)‖_F.  For a square closure e_x is Φ_x
    itself: this is the same measure the 2-norm check decides on.  +inf where e_x is structurally
    rank deficient (``blocks`` None), a block is singular or a value is not finite (NaN too).
    """
    if blocks is None:
        return ca.SX(ca.inf)
    rows, cols = blocks.rows, blocks.cols
    nb = len(rows)
    alpha = [_left_inverse_norm(e_x[list(rows[i]), list(cols[i])]) for i in range(nb)]
    beta: dict[tuple[int, int], ca.SX] = {}
    squares = []
    for j in range(nb):
        for i in range(j, -1, -1):
            if i == j:
                b = alpha[j]
            else:
                terms = [
                    ca.norm_fro(e_x[list(rows[i]), list(cols[k])]) * beta[k, j]
                    for k in range(i + 1, j + 1)
                    if (k, j) in beta and e_x[list(rows[i]), list(cols[k])].nnz()
                ]
                if not terms:
                    continue
                b = alpha[i] * ca.sum1(ca.vertcat(*terms))
            beta[i, j] = b
            squares.append(b**2)
    bound = ca.norm_fro(e_x) * ca.sqrt(ca.sum1(ca.vertcat(*squares)))
    return ca.if_else(bound < ca.inf, bound, ca.inf)  # NaN and inf: +inf


def limited_coordinates(closure: LoopClosure) -> tuple[Coordinate, ...]:
    """Every coordinate a limit may apply to, in the kernels' order: actuators q,
    pose coordinates x (some are joint angles, e.g. the pantograph's phi) and
    passive joints."""
    return closure.q + closure.x + closure.passive_coords


def limit_vectors(model: Model) -> tuple[np.ndarray, np.ndarray]:
    """Declared limits of :func:`limited_coordinates`, ±inf where none is declared."""
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
    :attr:`LoopClosure.cond_matrix` (Φ_x; for a closure solved through normal
    equations, ``loops``, the Jacobian of every closure equation, and cond1 the
    upper bound of :func:`cond2_left_inverse_bound` on its κ₂)."""

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

    return closure.solvers.memo(("pose_checks",), build)


# -- Newton options ---------------------------------------------------------------------------


def newton_options(config: SolverConfig | None) -> dict[str, Any]:
    """Options of the kernels' rootfinder (``fast_newton``) from a solver config.

    The kernels always solve by Newton's method; an IPOPT configuration only
    contributes its tolerance.  User options outside :data:`NEWTON_OPTIONS`
    are rejected (they would be silently ignored otherwise).
    """
    opts = {k: v for k, v in DEFAULT_OPTIONS["newton"].items() if k in NEWTON_OPTIONS}
    if config is not None and config.method == "newton":
        for key, value in config.options.items():
            if key in _IGNORED_NEWTON:
                continue
            if key not in NEWTON_OPTIONS:
                raise InputError(
                    f"the batch and exported Newton solver (CasADi fast_newton) takes only "
                    f"{', '.join(NEWTON_OPTIONS)}; got '{key}'",
                    path=("solver", "options", key),
                )
            opts[key] = value
    return opts


def batch_newton_supported(config: SolverConfig) -> bool:
    """Whether the kernels' Newton solver honours every option of ``config``."""
    return config.method == "newton" and all(k in NEWTON_OPTIONS + _IGNORED_NEWTON for k in config.options)


def _options_key(opts: Mapping[str, Any]) -> tuple:
    return tuple(sorted((k, repr(v)) for k, v in opts.items()))


# -- kernels ----------------------------------------------------------------------------------


@dataclass(frozen=True)
class Kernel:
    """A kernel and how to call it.

    function: the CasADi Function; its inputs are ``pose_inputs`` (one row per
        pose in a batch) followed by ``SHARED_INPUTS``.
    kind: "fk", "ik" or "jacobian".
    """

    function: ca.Function
    kind: str
    pose_inputs: tuple[str, ...]
    outputs: tuple[str, ...]
    key: tuple = ()  # identity in the closure's cache
    #: inputs shared by every pose (numbers of one model), after ``pose_inputs``
    shared_inputs: tuple[str, ...] = ()

    @property
    def name(self) -> str:
        return self.function.name()


SHARED_INPUTS = ("p", "lower", "upper", "tol")
#: shared inputs of the FK through the closed-form IK: also the model's linearization at home
REDUCED_SHARED_INPUTS = SHARED_INPUTS + ("J_home", "Phi_x_home_inv")
#: ``path`` output of the FK kernel: which formulation answered
PATHS = ("reduced", "full")
#: outputs of the FK as embedded (:func:`cpm_nlp.io.embed.functions`) and exported: without ``path``
FK_OUTPUTS = ("x", "passive", "residual", "branch_margin", "round_trip_error", "cond1", "limit_margin", "status")
_STATUS_OUTPUTS = ("residual", "branch_margin", "round_trip_error", "cond1", "limit_margin", "status")


def _shared_symbols(c: LoopClosure, sym: Any = ca.MX) -> list[Any]:
    nl = n_joints(c)
    return [sym.sym("p", c.np), sym.sym("lower", nl), sym.sym("upper", nl), sym.sym("tol")]


def _checks(c: LoopClosure, x: Any, q: Any, shared: list[Any]) -> dict[str, Any]:
    """The checks of (x, q) inside a kernel, by name (status: the checks' verdict)."""
    fn = checks_function(c)
    return dict(zip(fn.name_out(), fn(x, q, *shared)))


def _first(failed: Any, status: Status, otherwise: Any) -> Any:
    """``status`` where ``failed`` (e.g. Newton did not converge), else ``otherwise``."""
    return status_code([(failed, status)], CASADI, otherwise=otherwise)


def _converged(y: ca.MX, residual: ca.MX, tol: ca.MX) -> ca.MX:
    return ca.logic_and(_all_finite(y), residual <= tol)


def _rootfinder(name: str, residual: ca.Function, ny: int, nw: int, opts: Mapping[str, Any]) -> ca.Function:
    y, w = ca.SX.sym("y", ny), ca.SX.sym("w", nw)
    g = ca.Function(f"{name}_residual", [y, w], [residual(y, w)], ["y", "w"], ["g"])
    # a pose Newton cannot solve is reported by its status, never by an exception
    return ca.rootfinder(name, "fast_newton", g, {**opts, "error_on_fail": False})


def full_fk_kernel(closure: LoopClosure, config: SolverConfig | None = None) -> Kernel:
    """``<name>_fk_full: (q, x0, p, lower, upper, tol) -> (x, passive, residual,
    branch_margin, round_trip_error, cond1, limit_margin, status)`` (named
    ``<name>_fk`` for a mechanism without a closed-form IK).

    Newton on Φ(x, q) = 0 (nx unknowns) from x0; a pose whose residual is
    not within ``tol`` after the iterations is ``not_converged``; then the
    checks.  The FK of mechanisms without a closed-form IK, and the fallback
    of :func:`fk_kernel` for the others.

    A closure solved through normal equations (``loops``): first
    :func:`gauss_newton_fk_kernel` (first derivatives only); a pose it does not
    settle as ``solved`` goes to Newton on the normal equations from x0 exactly
    as before (a CasADi Switch: only that branch is evaluated), so every status
    other than ``solved`` is Newton's.
    """
    opts = newton_options(config)

    def build() -> Kernel:
        c = closure
        newton = newton_fk_kernel(c, config)
        if c.loops is None:
            return newton
        gn = gauss_newton_fk_kernel(c, config).function
        fn = _settled_or(gn, newton.function, f"{c.name}_fk" if c.ik is None else f"{c.name}_fk_full", newton.outputs)
        return Kernel(fn, "fk", ("q", "x0"), newton.outputs, key, SHARED_INPUTS)

    key = ("full_fk_kernel", _options_key(opts))
    return closure.solvers.memo(key, build)


def newton_fk_kernel(closure: LoopClosure, config: SolverConfig | None = None) -> Kernel:
    """Newton on Φ(x, q) = 0 from x0 (CasADi ``fast_newton``) and the checks: :func:`full_fk_kernel`
    itself for a square closure, its fallback for normal equations (named ``..._newton``)."""
    opts = newton_options(config)

    def build() -> Kernel:
        c = closure
        rf = _rootfinder(f"{c.name}_fk_newton", c.fk_residual, c.nx, c.nq + c.np, opts)
        q, x0 = ca.MX.sym("q", c.nq), ca.MX.sym("x0", c.nx)
        shared = _shared_symbols(c)
        x = rf(x0, ca.vertcat(q, shared[0]))
        chk = _checks(c, x, q, shared)
        status = _first(ca.logic_not(_converged(x, chk["residual"], shared[3])), Status.NOT_CONVERGED, chk["status"])
        names = ("x", "passive", *_STATUS_OUTPUTS)
        outs = [x] + [chk[n] for n in names[1:-1]] + [status]
        suffix = "_newton" if c.loops is not None else ""
        name = (f"{c.name}_fk" if c.ik is None else f"{c.name}_fk_full") + suffix
        fn = ca.Function(name, [q, x0, *shared], outs, ["q", "x0", *SHARED_INPUTS], list(names))
        return Kernel(fn, "fk", ("q", "x0"), names, key, SHARED_INPUTS)

    key = ("newton_fk_kernel", _options_key(opts))
    return closure.solvers.memo(key, build)


def _settled_or(first: ca.Function, fallback: ca.Function, name: str, names: Sequence[str]) -> ca.Function:
    """``first``'s outputs where its status is ``solved``, else ``fallback``'s on the same inputs
    (a CasADi Switch: only the branch taken is evaluated).  Both take (q, x0, shared...) and give
    ``names`` (status last)."""
    ins = [ca.MX.sym(first.name_in(k), first.sparsity_in(k)) for k in range(first.n_in())]
    r = first(*ins)
    r_in = [ca.MX.sym(f"first_{n}", first.sparsity_out(k)) for k, n in enumerate(names)]
    io = ([*first.name_in(), *[f"first_{n}" for n in names]], list(names))
    keep = ca.Function(f"{name}_keep", ins + r_in, r_in, *io)
    f = fallback(*ins)
    other = ca.Function(f"{name}_fallback", ins + r_in, list(f), *io)
    switch = ca.Function.if_else(f"{name}_switch", keep, other)
    outs = switch(r[-1] == code_of(Status.SOLVED), *ins, *r)
    return ca.Function(name, ins, list(outs), first.name_in(), list(names))


#: Gauss-Newton steps of the full FK of normal equations (unrolled); from home, four reach
#: machine precision within +-2 mm strokes of the shipped pantograph file, five within +-10 mm
GAUSS_NEWTON_STEPS = 5


def left_inverse_step(e_x: ca.SX, e: ca.SX, blocks: LeftInverseBlocks) -> ca.SX:
    """v = X e with X the block left inverse of e_x of :func:`cond2_left_inverse_bound`: block by
    block from the last, v_i = D_i⁺ (e_i - Σ_{k>i} U_ik v_k), D_i⁺ by the QR of the diagonal block
    (a single column: dᵀ/‖d‖²).  Where e_x v = e has a solution (every closure equation holds to
    first order) v is it; x - v is then a Gauss-Newton step with the rows grouped as the blocks,
    quadratically convergent to a root of e (e_x X projects onto e_x's range, where e lies to
    first order near the root)."""
    rows, cols = blocks.rows, blocks.cols
    nb = len(rows)
    v: list[ca.SX | None] = [None] * nb
    for i in reversed(range(nb)):
        r = list(rows[i])
        rhs = e[r]
        for k in range(i + 1, nb):
            u = e_x[r, list(cols[k])]
            if u.nnz():
                rhs = rhs - ca.mtimes(u, v[k])
        d = ca.densify(e_x[r, list(cols[i])])
        if d.size2() == 1:
            v[i] = ca.dot(d, rhs) / ca.dot(d, d)
        else:
            qf, t = ca.qr(d)
            v[i] = ca.solve(t, ca.mtimes(qf.T, rhs))
    out = [None] * e_x.size2()
    for i in range(nb):
        for k, col in enumerate(cols[i]):
            out[col] = v[i][k]
    return ca.vertcat(*out)


def gauss_newton_fk_kernel(
    closure: LoopClosure, config: SolverConfig | None = None, steps: int = GAUSS_NEWTON_STEPS
) -> Kernel:
    """``<name>_fk_gauss_newton: (q, x0, p, lower, upper, tol) -> (x, passive, residual, ...,
    status)``: the full FK of a closure solved through normal equations (``loops``), by
    ``steps`` Gauss-Newton steps x <- x - X(x) e(x) on every closure equation e
    (:func:`left_inverse_step`; first derivatives only, where Newton on the normal equations
    needs their second) from x0: an MX graph of ``steps`` calls of one SX step (its C code
    generated once) and one SX call of the checks.

    ``status`` is ``solved`` only where max |e| <= abstol after the steps (as Newton's stopping
    test, on every equation) and every check passes, with a margin of 2 on the singularity
    screen; any other status means "not settled here": :func:`full_fk_kernel` then runs Newton.
    """
    opts = newton_options(config)
    abstol = float(opts.get("abstol", DEFAULT_OPTIONS["newton"]["abstol"]))

    def build() -> Kernel:
        c = closure
        if c.loops is None:  # pragma: no cover - guarded by full_fk_kernel
            raise ValueError(f"{c.name} is not solved through normal equations")
        blocks = closure_blocks(c)
        nl = n_joints(c)
        q, p = ca.SX.sym("q", c.nq), ca.SX.sym("p", c.np)
        lower, upper, tol = ca.SX.sym("lower", nl), ca.SX.sym("upper", nl), ca.SX.sym("tol")
        x_sym = ca.SX.sym("x", c.nx)
        e = c.loops(x_sym, q, p)
        if blocks is None:  # structurally rank deficient: nothing settles here
            x_next = x_sym + ca.nan
        else:
            x_next = x_sym - left_inverse_step(ca.jacobian(e, x_sym), e, blocks)
        # one step, and the checks of the last iterate, as Functions called from an MX graph: the
        # step's code is generated once, not once per step (straight-line SX would repeat it)
        step = ca.Function(f"{c.name}_fk_gauss_newton_step", [x_sym, q, p], [x_next], ["x", "q", "p"], ["x_next"])
        converged = _robust_max_abs(c.loops(x_sym, q, p)) <= abstol
        chk = check_expressions(c, x_sym, q, p, lower, upper)
        singular = is_singular(chk["cond1"], CASADI, factor=2 * screen_factor(c))
        status = status_code(status_rules(chk, tol, singular, CASADI), CASADI)
        status = _first(ca.logic_not(converged), Status.NOT_CONVERGED, status)
        names = ("x", "passive", *_STATUS_OUTPUTS)
        outs = ca.cse([ca.densify(chk[n]) for n in names[1:-1]] + [status])
        shared_names = list(SHARED_INPUTS)
        finish = ca.Function(
            f"{c.name}_fk_gauss_newton_checks",
            [x_sym, q, p, lower, upper, tol],
            outs,
            ["x", "q", *shared_names],
            list(names[1:]),
        )
        mq, mx0 = ca.MX.sym("q", c.nq), ca.MX.sym("x0", c.nx)
        shared = _shared_symbols(c)
        x = mx0
        for _ in range(steps):
            x = step(x, mq, shared[0])
        fn = ca.Function(
            f"{c.name}_fk_gauss_newton",
            [mq, mx0, *shared],
            [x, *finish(x, mq, *shared)],
            ["q", "x0", *shared_names],
            list(names),
        )
        return Kernel(fn, "fk", ("q", "x0"), names, key, SHARED_INPUTS)

    key = ("gauss_newton_fk_kernel", _options_key(opts), steps)
    return closure.solvers.memo(key, build)


#: Newton steps of the reduced FK (unrolled: straight-line code, no loop); from the
#: first-order guess two or three reach machine precision in the workspace
REDUCED_STEPS = 3


def reduced_fk_kernel(closure: LoopClosure, config: SolverConfig | None = None, steps: int = REDUCED_STEPS) -> Kernel:
    """``<name>_fk_reduced: (q, x0, p, lower, upper, tol, J_home, Phi_x_home_inv)
    -> (x, passive, residual, branch_margin, round_trip_error, cond1,
    limit_margin, status)``: FK by Newton on the task coordinates through the
    closed-form IK (mechanisms that have one).  One flat SX graph.

    Unknowns: the nq task coordinates t, solving g(t) = q_ik(t) - q = 0 by
    ``steps`` Newton steps t <- t - (dq/dt)⁻¹ g(t) (dq/dt = the inverse
    Jacobian J_inv from AD of the closed form, an nq x nq solve), from the
    first-order guess about x0: t0 = t_s + J_home (q - q_ik(t_s)), t_s =
    x0[task], J_home = dt/dq at the home pose (for x0 = home:
    t0 = t_home + J_home (q - q_home)).  The pose is x_ik(t).

    ``status`` is ``solved`` only where max |g| <= abstol after the steps
    (Newton converged) and every check of the full path passes on (x, q):
    residual of the full Φ, branch, reach and IK round trip, limits, with
    ``cond1`` the certified bound of :func:`cond1_bound` (no inverse of Φ_x;
    for a closure solved through normal equations, the bound of
    :func:`cond2_left_inverse_bound` at the pose on κ₂ of every closure
    equation's Jacobian) and a margin of 2 on the singularity threshold.  Any other status means
    "not settled here": the full path decides (see :func:`fk_kernel`).
    """
    opts = newton_options(config)
    abstol = float(opts.get("abstol", DEFAULT_OPTIONS["newton"]["abstol"]))

    def build() -> Kernel:
        c = closure
        if c.ik is None:  # pragma: no cover - guarded by fk_kernel
            raise ValueError(f"{c.name} has no closed-form IK")
        nl = n_joints(c)
        q, x0, p = ca.SX.sym("q", c.nq), ca.SX.sym("x0", c.nx), ca.SX.sym("p", c.np)
        lower, upper, tol = ca.SX.sym("lower", nl), ca.SX.sym("upper", nl), ca.SX.sym("tol")
        jac_home = ca.SX.sym("J_home", c.nq, c.nq)
        b = ca.SX.sym("Phi_x_home_inv", c.nx, c.nx)
        # one Newton step as a Function (inlined below: calls on SX expand)
        t_sym = ca.SX.sym("t", c.nq)
        q_of_t = c.ik(t_sym, p)[1]
        step = ca.Function(
            f"{c.name}_fk_task_step",
            [t_sym, q, p],
            [t_sym - ca.solve(ca.jacobian(q_of_t, t_sym), q_of_t - q)],
            ["t", "q", "p"],
            ["t_next"],
        )
        ts = x0[list(c.task_index)]
        t = ts + ca.mtimes(jac_home, q - c.ik(ts, p)[1])
        for _ in range(steps):
            t = step(t, q, p)
        x, q_ik, _reach = c.ik(t, p)
        converged = _robust_max_abs(q_ik - q) <= abstol
        # normal equations (an overconstrained graph): κ₂ of every closure equation's Jacobian, bounded at
        # the pose block by block (check_expressions); Φ_x⁻¹ at home serves the square closures
        chk = check_expressions(c, x, q, p, lower, upper, phi_x_home_inv=b)
        singular = is_singular(chk["cond1"], CASADI, factor=2 * screen_factor(c))  # margin 2 over the certified bound
        status = status_code(status_rules(chk, tol, singular, CASADI), CASADI)
        status = _first(ca.logic_not(converged), Status.NOT_CONVERGED, status)
        names = ("x", "passive", *_STATUS_OUTPUTS)
        outs = ca.cse([x] + [ca.densify(chk[n]) for n in names[1:-1]] + [status])
        fn = ca.Function(
            f"{c.name}_fk_reduced",
            [q, x0, p, lower, upper, tol, jac_home, b],
            outs,
            ["q", "x0", *REDUCED_SHARED_INPUTS],
            list(names),
        )
        return Kernel(fn, "fk", ("q", "x0"), names, key, REDUCED_SHARED_INPUTS)

    key = ("reduced_fk_kernel", _options_key(opts), steps)
    return closure.solvers.memo(key, build)


def fk_kernel(closure: LoopClosure, config: SolverConfig | None = None) -> Kernel:
    """``<name>_fk: (q, x0, p, lower, upper, tol[, J_home, Phi_x_home_inv]) ->
    (x, passive, residual, branch_margin, round_trip_error, cond1,
    limit_margin, status[, path])``: the FK of every path in cpm_nlp (single
    Newton solves, batches, the embedding Functions, exported code).

    Mechanisms with a closed-form IK: first :func:`reduced_fk_kernel` (nq
    unknowns); a pose it does not settle as ``solved`` -- Newton did not
    converge, a check failed, or the conditioning bound is not certified --
    goes to :func:`full_fk_kernel` from x0 (only that branch is evaluated: a
    CasADi Switch), so every status other than ``solved`` comes from the full
    path exactly as it did before the reduced one existed.  ``path`` says
    which one answered (0 reduced, 1 full; :data:`PATHS`).  Mechanisms without
    a closed-form IK: :func:`full_fk_kernel` alone (no ``path`` output).
    """
    c = closure
    if c.ik is None:
        return full_fk_kernel(c, config)
    opts = newton_options(config)

    def build() -> Kernel:
        reduced = reduced_fk_kernel(c, config).function
        full = full_fk_kernel(c, config).function
        q, x0 = ca.MX.sym("q", c.nq), ca.MX.sym("x0", c.nx)
        shared = _shared_symbols(c) + [ca.MX.sym("J_home", c.nq, c.nq), ca.MX.sym("Phi_x_home_inv", c.nx, c.nx)]
        r = reduced(q, x0, *shared)
        names = ("x", "passive", *_STATUS_OUTPUTS)
        # the Switch's branches share one signature: (q, x0, p, lower, upper, tol, reduced outputs)
        in_names = ["q", "x0", *SHARED_INPUTS][: 2 + len(shared[:4])]
        ins = [ca.MX.sym(n, s.sparsity()) for n, s in zip(in_names, [q, x0, *shared[:4]])]
        r_names = [f"reduced_{n}" for n in names]
        r_in = [ca.MX.sym(n, reduced.sparsity_out(k)) for k, n in enumerate(r_names)]
        # outputs: (x, passive, checks..., path, status): status stays last
        out_names = [*names[:-1], "path", "status"]
        # names from the lists, not the symbols: a symbol of size 0 (no passive joints) is a constant
        io = (in_names + r_names, out_names)
        keep = ca.Function(f"{c.name}_fk_keep", ins + r_in, r_in[:-1] + [ca.MX(0), r_in[-1]], *io)
        f = list(full(*ins))
        fallback = ca.Function(f"{c.name}_fk_fallback", ins + r_in, f[:-1] + [ca.MX(1), f[-1]], *io)
        switch = ca.Function.if_else(f"{c.name}_fk_switch", keep, fallback)
        settled = r[-1] == code_of(Status.SOLVED)
        outs = switch(settled, q, x0, *shared[:4], *r)
        fn = ca.Function(f"{c.name}_fk", [q, x0, *shared], list(outs), ["q", "x0", *REDUCED_SHARED_INPUTS], out_names)
        return Kernel(fn, "fk", ("q", "x0"), tuple(out_names), key, REDUCED_SHARED_INPUTS)

    key = ("fk_kernel", _options_key(opts))
    return c.solvers.memo(key, build)


def ik_kernel(closure: LoopClosure, config: SolverConfig | None = None) -> Kernel:
    """``<name>_ik: (t[, y0], p, lower, upper, tol) -> (x, q, passive, reach,
    residual, ..., status)``.

    The closed form where the mechanism has one (``unreachable`` when its
    reach margin is negative); otherwise Newton on Φ for the dependent pose
    coordinates and q from the guess y0 = (x_dep, q).
    """
    c = closure
    opts = newton_options(config) if c.ik is None else {}

    def build() -> Kernel:
        # SX where there is no rootfinder: one flat expression graph, which
        # CasADi's virtual machine evaluates faster than MX calls
        sym = ca.SX if c.ik is not None else ca.MX
        t = sym.sym("t", c.nq)
        shared = _shared_symbols(c, sym)
        if c.ik is not None:
            x, q, reach = c.ik(t, shared[0])
            pose_inputs: tuple[str, ...] = ("t",)
            ins = [t]
            chk = _checks(c, x, q, shared)
            status = _first(ca.logic_not(reach >= 0), Status.UNREACHABLE, chk["status"])
        else:
            nd = len(c.dep_index)
            y0 = ca.MX.sym("y0", nd + c.nq)
            rf = _rootfinder(f"{c.name}_ik_newton", c.ik_residual, nd + c.nq, c.nq + c.np, opts)
            y = rf(y0, ca.vertcat(t, shared[0]))
            x, q = c.assemble_x(t, y[:nd]), y[nd:]
            pose_inputs = ("t", "y0")
            ins = [t, y0]
            reach = ca.MX(0)
            chk = _checks(c, x, q, shared)
            status = _first(
                ca.logic_not(_converged(y, chk["residual"], shared[3])), Status.NOT_CONVERGED, chk["status"]
            )
        names = ("x", "q", "passive", "reach", *_STATUS_OUTPUTS)
        outs = [x, q, chk["passive"], reach] + [chk[n] for n in _STATUS_OUTPUTS[:-1]] + [status]
        fn = ca.Function(f"{c.name}_ik", [*ins, *shared], outs, [*pose_inputs, *SHARED_INPUTS], list(names))
        return Kernel(fn, "ik", pose_inputs, names, key, SHARED_INPUTS)

    key = ("ik_kernel", _options_key(opts))
    return closure.solvers.memo(key, build)


def jacobian_kernel(closure: LoopClosure) -> Kernel:
    """``<name>_jacobian: (x, q, p) -> (J, J_inv, Phi_x, Phi_q)`` (dense, AD)."""

    def build() -> Kernel:
        c = closure
        x, q, p = ca.SX.sym("x", c.nx), ca.SX.sym("q", c.nq), ca.SX.sym("p", c.np)
        outs = [ca.densify(f(x, q, p)) for f in (c.jacobian, c.inverse_jacobian, c.phi_x, c.phi_q)]
        names = ("J", "J_inv", "Phi_x", "Phi_q")
        fn = ca.Function(f"{c.name}_jacobian", [x, q, p], outs, ["x", "q", "p"], list(names))
        return Kernel(fn, "jacobian", ("x", "q"), names, key, ("p",))

    key = ("jacobian_kernel",)
    return closure.solvers.memo(key, build)


def kernel(closure: LoopClosure, kind: str, config: SolverConfig | None = None) -> Kernel:
    """The kernel of one kind ("fk", "ik", "jacobian")."""
    if kind == "fk":
        return fk_kernel(closure, config)
    if kind == "ik":
        return ik_kernel(closure, config)
    if kind == "jacobian":
        return jacobian_kernel(closure)
    raise ValueError(f"unknown kernel kind {kind!r}")  # pragma: no cover - programming error


def linearization(model: Model) -> dict[str, np.ndarray]:
    """The model's numbers behind the reduced FK (cached on the model):
    ``J_home`` = dt/dq at the home pose (nq x nq, the first-order guess) and
    ``Phi_x_home_inv`` = Φ_x⁻¹ at home (nx x nx, the conditioning
    certificate).  Non-finite (a singular home pose) becomes zeros: the guess
    is then x0's task coordinates and nothing is certified."""
    cached = model.__dict__.get("_fk_linearization")
    if cached is not None:
        return cached
    c = model.closure
    x, q, p = model.x_home, model.q_home, model.p
    with np.errstate(all="ignore"):
        jac = np.asarray(c.jacobian(x, q, p))[c.task_index, :]
        try:
            b = np.linalg.inv(np.asarray(c.phi_x(x, q, p)))
        except np.linalg.LinAlgError:
            b = np.zeros((c.nx, c.nx))
    jac = jac if np.all(np.isfinite(jac)) else np.zeros((c.nq, c.nq))
    b = b if np.all(np.isfinite(b)) else np.zeros((c.nx, c.nx))
    out = {"J_home": jac.reshape(-1, order="F"), "Phi_x_home_inv": b.reshape(-1, order="F")}
    model.__dict__["_fk_linearization"] = out
    return out


def shared_values(kern: Kernel, model: Model, tolerance: float) -> list[np.ndarray]:
    """The values of the kernel's shared inputs for a model (flat, column-major)."""
    lower, upper = limit_vectors(model)
    values = {"p": model.p, "lower": lower, "upper": upper, "tol": np.array([float(tolerance)])}
    if "J_home" in kern.shared_inputs:
        values.update(linearization(model))
    return [values[n] for n in kern.shared_inputs]


def bake(
    kern: Kernel,
    model: Model,
    tolerance: float,
    function: ca.Function | None = None,
    outputs: Sequence[str] | None = None,
) -> ca.Function:
    """The kernel with one model's parameters, limits and tolerance built in:
    a Function of the per-pose inputs only, same output names.

    function: the Function to wrap (default the kernel's own; the compiled
    library's twin for the compiled path).  outputs: the outputs to keep, by
    name (default all, in the kernel's order).
    """
    fn = kern.function if function is None else function
    syms = [ca.MX.sym(n, fn.size_in(i)) for i, n in enumerate(kern.pose_inputs)]
    n_pose = len(kern.pose_inputs)
    fixed = [
        ca.DM(ca.Sparsity.dense(*fn.size_in(n_pose + k)), v)
        for k, v in enumerate(shared_values(kern, model, tolerance))
    ]
    outs = fn(*syms, *fixed)
    outs = list(outs) if isinstance(outs, (list, tuple)) else [outs]
    names = list(kern.outputs if outputs is None else outputs)
    by_name = dict(zip(fn.name_out(), outs))
    return ca.Function(kern.name, syms, [by_name[n] for n in names], list(kern.pose_inputs), names)


# -- fast numeric calls ---------------------------------------------------------------------


class FastFunction:
    """Call a CasADi Function on numpy arrays with minimal overhead.

    Uses one :class:`casadi.FunctionBuffer` per thread (a few µs per call
    instead of the ~30 µs of a regular call from Python); safe to call from
    several threads.  Returns the outputs as flat float arrays (dense,
    column-major, as CasADi stores them).
    """

    def __init__(self, function: ca.Function) -> None:
        if not all(function.sparsity_out(i).is_dense() for i in range(function.n_out())):
            args = function.mx_in()
            res = function.call(args)
            function = ca.Function(
                function.name(), args, [ca.densify(r) for r in res], function.name_in(), function.name_out()
            )
        self.function = function
        self.names_out = tuple(function.name_out())
        self._nnz_in = [function.nnz_in(i) for i in range(function.n_in())]
        self._nnz_out = [function.nnz_out(i) for i in range(function.n_out())]
        self._local = threading.local()

    def _buffer(self):
        state = getattr(self._local, "state", None)
        if state is None:
            state = self.function.buffer()
            self._local.state = state
        return state

    def __call__(self, *args: Any) -> list[np.ndarray]:
        buf, evaluate = self._buffer()
        keep = []
        for i, (a, n) in enumerate(zip(args, self._nnz_in)):
            arr = np.ascontiguousarray(a, dtype=float).reshape(-1)
            if arr.size != n:
                raise ValueError(f"{self.function.name()}: input {i} needs {n} values, got {arr.size}")
            keep.append(arr)
            buf.set_arg(i, memoryview(arr))
        outs = [np.empty(n) for n in self._nnz_out]
        for i, o in enumerate(outs):
            buf.set_res(i, memoryview(o))
        evaluate()
        if buf.ret() != 0:
            raise RuntimeError(f"evaluation of {self.function.name()} failed (code {buf.ret()})")
        return outs

    def named(self, *args: Any) -> dict[str, np.ndarray]:
        return dict(zip(self.names_out, self(*args)))


class BoundCall:
    """One kernel for one model, called on one pose at a time with the least
    overhead: the model's shared inputs (parameters, limits, tolerance,
    linearization) and every input and output array are bound to a
    FunctionBuffer once per thread; a call copies the pose inputs in,
    evaluates, and returns the (per-thread, reused) output arrays -- copy
    what you keep.  ``defaults``: a value per pose input (or None), used
    where a call passes None (e.g. the home pose as x0).
    """

    def __init__(self, function: ca.Function, shared: Sequence[np.ndarray], defaults: Sequence[Any]) -> None:
        self.function = function
        self._shared = [np.ascontiguousarray(v, dtype=float).reshape(-1) for v in shared]
        self._defaults = [None if d is None else np.asarray(d, dtype=float).reshape(-1) for d in defaults]
        self._local = threading.local()

    def _state(self):
        state = getattr(self._local, "state", None)
        if state is None:
            fn = self.function
            buf, evaluate = fn.buffer()
            pose = [np.zeros(fn.nnz_in(i)) for i in range(len(self._defaults))]
            for i, arr in enumerate(pose + self._shared):
                buf.set_arg(i, memoryview(arr))
            outs = [np.empty(fn.nnz_out(i)) for i in range(fn.n_out())]
            for i, arr in enumerate(outs):
                buf.set_res(i, memoryview(arr))
            state = self._local.state = [buf, evaluate, pose, outs, [False] * len(pose)]
        return state

    def _fill(self, state: list, pose: Sequence[Any]) -> None:
        arrays, is_default = state[2], state[4]
        for k, value in enumerate(pose):
            if value is None:
                if not is_default[k]:
                    arrays[k][:] = self._defaults[k]
                    is_default[k] = True
            else:
                arrays[k][:] = value
                is_default[k] = False

    def __call__(self, *pose: Any) -> list[np.ndarray]:
        state = self._state()
        self._fill(state, pose)
        buf = state[0]
        state[1]()
        if buf.ret() != 0:
            raise RuntimeError(f"evaluation of {self.function.name()} failed (code {buf.ret()})")
        return state[3]


def fast(closure: LoopClosure, key: tuple, function: Callable[[], ca.Function]) -> FastFunction:
    """A :class:`FastFunction` built once per closure and key."""
    return closure.solvers.memo(("fast",) + key, lambda: FastFunction(function()))
