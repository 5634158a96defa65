"""A proof that a task point is outside the workspace of a mechanism without a closed-form IK.

A point t is inside when some pose y = (dependent pose coordinates, actuators) in the
box of the unknowns (`unknown_box`: the
actuator strokes, the declared pose limits and the closure's bounds) satisfies
Φ(t, y) = 0 with every limited quantity within its limits and every branch indicator
>= 0 (all to the membership tolerance).  The proof covers the whole box by branch and
bound: a sub-box is excluded when the interval enclosure
(`IntervalProgram`, outward rounding) of one
closure row does not contain 0, or that of one limited quantity lies wholly beyond
its limit; a sub-box not excluded is split in two along the unknown with the largest
width × Σ|∂Φ/∂y| at its centre over the rows not yet excluded.  The point is proven
outside when no sub-box is left; the search gives up (no proof) beyond
`PROOF_BOXES` live sub-boxes or `PROOF_ROUNDS` rounds.  All points are
searched together, one vectorised interval evaluation per round; each point's search
depends on that point alone.  A box with an unbounded side is never proven.
"""

from __future__ import annotations

import casadi as ca
import numpy as np

from ...core.batch import evaluate_points
from ...core.model import LoopClosure, Model
from ...core.solver import solvers_of
from ..intervals import IntervalProgram, UnsupportedOperation
from .point_ik import NEWTON_KEY, newton_function, unknown_box

#: live sub-boxes per point before the search gives up
PROOF_BOXES = 256
#: rounds (splits of every live sub-box) before the search gives up
PROOF_ROUNDS = 40
#: cache key of the interval program
PROGRAM_KEY = ("workspace", "exclusion_program")


def _program(closure: LoopClosure, limited: ca.Function) -> IntervalProgram | None:
    """``(y, t, p) -> (phi, v)`` replayed on intervals (None if an operation has no interval version)."""

    def build():
        c = closure
        nd = len(c.dep_index)
        y, t, p = ca.SX.sym("y", nd + c.nq), ca.SX.sym("t", c.nq), ca.SX.sym("p", c.np)
        x = c.assemble_x(t, y[:nd])
        fn = ca.Function(f"{c.name}_exclusion", [y, t, p], [c.phi(x, y[nd:], p), limited(x, y[nd:], p)])
        try:
            return IntervalProgram(fn)
        except UnsupportedOperation:
            return False

    got = solvers_of(closure).memo(PROGRAM_KEY, build)
    return got or None


def prove_outside(
    model: Model, T: np.ndarray, tolerance: float, limited: ca.Function, lo_v: np.ndarray, hi_v: np.ndarray
) -> np.ndarray:
    """For each task point of T (N, nq): True where it is proven that no pose in the box
    of the unknowns passes the membership test (see the module docstring)."""
    c = model.closure
    T = np.atleast_2d(T)
    N = T.shape[0]
    proven = np.zeros(N, dtype=bool)
    lo_y, hi_y = unknown_box(model)
    if N == 0 or not (np.all(np.isfinite(lo_y)) and np.all(np.isfinite(hi_y))):
        return proven
    prog = _program(c, limited)
    if prog is None:
        return proven
    ny = lo_y.size
    lo_y, hi_y = lo_y - tolerance, hi_y + tolerance
    lo_v, hi_v = lo_v - tolerance, hi_v + tolerance
    owner = np.arange(N)
    BL = np.tile(lo_y, (N, 1))
    BH = np.tile(hi_y, (N, 1))
    failed = np.zeros(N, dtype=bool)
    pvec = np.tile(model.p, (1, 1))
    jac = newton_function(c)
    for _ in range(PROOF_ROUNDS):
        if not owner.size:
            break
        B = owner.size
        (plo, phi), (vlo, vhi) = prog.evaluate(
            [(BL, BH), (T[owner], T[owner]), (np.repeat(pvec, B, axis=0), np.repeat(pvec, B, axis=0))]
        )
        with np.errstate(invalid="ignore"):
            row_out = (plo > 0) | (phi < 0)
            excluded = np.any(row_out, axis=1) | np.any((vhi < lo_v) | (vlo > hi_v), axis=1)
        keep = ~excluded
        owner, BL, BH, row_out = owner[keep], BL[keep], BH[keep], row_out[keep]
        if not owner.size:
            break
        counts = np.bincount(owner, minlength=N)
        failed |= counts > PROOF_BOXES // 2
        live = ~failed[owner]
        owner, BL, BH, row_out = owner[live], BL[live], BH[live], row_out[live]
        if not owner.size:
            break
        mid = 0.5 * (BL + BH)
        _r, J = evaluate_points(c, NEWTON_KEY, jac, [mid, T[owner]], model.p)
        J = np.abs(J.reshape(owner.size, ny, ny))  # rows: residuals, columns: unknowns
        J = np.where(np.isfinite(J), J, 1.0)
        score = (BH - BL) * np.einsum("kr,krj->kj", (~row_out).astype(float), J)
        score = np.where(np.isfinite(score), score, 0.0) + 1e-300 * (BH - BL)
        axis = np.argmax(score, axis=1)
        k = np.arange(owner.size)
        cut = mid[k, axis]
        L2, H1 = BL.copy(), BH.copy()
        H1[k, axis] = cut
        L2[k, axis] = cut
        owner = np.r_[owner, owner]
        BL, BH = np.vstack([BL, L2]), np.vstack([H1, BH])
    failed[owner] = True
    proven[:] = ~failed
    return proven
