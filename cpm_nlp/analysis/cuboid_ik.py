"""The cuboid NLP of
[`cpm_nlp.analysis.workspace.inscribed_cuboid`][cpm_nlp.analysis.workspace.cuboid.inscribed_cuboid] for a mechanism
with a closed-form IK: no pose unknowns.

The same discretised semi-infinite program as the general formulation (box
[c + D∘u, c + D∘(u + w)], sample points s_j of its surface, objective
-Σ log w_i), but every limited quantity is an explicit function of its
sample point through the closed-form IK, v_r(t_j) = v_r(x(t_j), q(t_j)), and
the unknowns are the 2d box variables (u, w) alone.  The IK's reach margin is
one more quantity (>= 0); where it is negative every quantity evaluates to
NaN, so that IPOPT's line search never accepts a trial point at which the
mechanism does not assemble.

Such an NLP has few unknowns and many constraint rows (samples × quantities),
and IPOPT's cost per iteration grows with the rows; at the optimum only a
handful are active.  It is therefore solved on a **working set** of rows
(j, r), with every row verified afterwards:

1. solve IPOPT with the rows of the working set only;
2. evaluate every quantity at every sample at the solution (one mapped call);
3. add the rows outside their bounds to the working set and solve again, until
   none is.

The result satisfies every row; the rows left out are inactive, with zero
multipliers, so it is a KKT point of the NLP with all rows -- the optimum the
full NLP has, not an approximation of it.  The first start begins with the
rows of the corners and face centres of the quantities that bind somewhere in the
search region;
the later ones with the rows active at the optima found before (a warm start
of the working set across starts), and each start runs from its own initial
box.  An exchange round adds sample points and continues from the current
optimum the same way.

The starts after the first are solved together (`ClosedFormCuboid.start_all`):
J copies of the working-set NLP, one per start with its own box and rows, as one
block-separable NLP (no constraint couples two blocks, the objective is the sum),
whose KKT points are exactly the tuples of the starts' KKT points; IPOPT's fixed
cost per iteration, which dominates for so few unknowns, is then paid once.  If
that joint solve fails the starts run one by one, as the first.

The working-set NLP has K row slots (K = 16, 32, 64, ...; one IPOPT solver
per K, built once per mechanism type and configuration); a slot holds a
sample point s_k and a one-hot selector e_k of the quantity it bounds, both
parameters, and unused slots are free (bounds ±inf).
"""

from __future__ import annotations

import logging
import threading

import casadi as ca
import numpy as np

from ..core.batch import evaluate_points
from ..core.model import LoopClosure, Model
from ..core.solver import SolverConfig, solvers_of

log = logging.getLogger(__name__)

#: row slots of the smallest working-set NLP (see `slots`)
MIN_SLOTS = 16
#: a row is active (kept for the next starts) when its multiplier exceeds this, relative to the largest
ACTIVE_MULTIPLIER = 1e-6
#: rows of one quantity added per solve (the most violated ones)
ADD_PER_QUANTITY = 4
#: after this many solves of one start every violated row is added (the working set then
#: reaches all violated rows in a few solves)
ESCALATE = 6
#: solves of one start before it is reported not settled (each adds at least one row)
MAX_SETTLE = 40
#: CasADi options of the working-set NLP: NaN (no assembly) is a rejected trial point, not a warning
QUIET = {"show_eval_warnings": False, "calc_lam_p": False}
#: IPOPT's defaults of ``bound_relax_factor`` and ``constr_viol_tol`` (where the options do not set them)
IPOPT_BOUND_RELAX, IPOPT_CONSTR_VIOL_TOL = 1e-8, 1e-4


def relaxation(bound: np.ndarray, options: dict) -> np.ndarray:
    """How far IPOPT relaxes a constraint bound before it starts (``bound_relax_factor`` times
    max(1, |bound|), at most ``constr_viol_tol``): the rows of a working set may end that far
    outside their bounds, so a row left out counts as violated only beyond the same slack."""
    factor = float(options.get("ipopt.bound_relax_factor", IPOPT_BOUND_RELAX))
    most = float(options.get("ipopt.constr_viol_tol", IPOPT_CONSTR_VIOL_TOL))
    bound = np.asarray(bound, dtype=float)
    finite = np.isfinite(bound)  # an infinite bound stays infinite (no 0 * inf)
    return np.where(finite, np.minimum(factor * np.maximum(1.0, np.abs(np.where(finite, bound, 0.0))), most), 0.0)


def row_key(rows: tuple[int, ...]) -> tuple:
    """The key of `row_function` in the closure's cache."""
    return ("cuboid_rows", tuple(rows))


def row_function(closure: LoopClosure, limited: ca.Function, rows: tuple[int, ...]) -> ca.Function:
    """``<name>_cuboid_rows: (t, p) -> g``: the limited quantities ``rows`` of
    ``limited(x, q, p)`` at the closed-form IK of the task point t, then the
    reach margin; all NaN where the reach margin is negative."""

    def build() -> ca.Function:
        c = closure
        t, p = ca.SX.sym("t", c.nq), ca.SX.sym("p", c.np)
        x, q, reach = c.ik(t, p)
        v = ca.vertcat(limited(x, q, p)[list(rows)], reach)
        g = ca.if_else(reach >= 0, v, ca.DM.nan(v.size1()))
        return ca.Function(f"{c.name}_cuboid_rows", [t, p], [g], ["t", "p"], ["g"])

    return solvers_of(closure).memo(row_key(rows), build)


def slots(rows: int) -> int:
    """Slots of the smallest working-set NLP that holds ``rows`` rows: MIN_SLOTS times
    1, 1.5, 2, 3, 4, 6, 8, ... (one IPOPT solver per size)."""
    K = MIN_SLOTS
    while K < rows:
        K = K * 3 // 2 if K & (K - 1) == 0 else K * 4 // 3
    return K


def hessian_of_lagrangian(name: str, rows_fn: ca.Function, sel, K: int, J: int, Z, p, S, E, centre, size, f):
    """``hess_lag`` of `SlotNLP`, through the task points: (z, p, lam_f, lam_g) -> triu(∇²_z L).

    A slot's row depends on its box z = (u, w) only through its task point
    t = c + D∘(u + s∘w), linear in z: with A = λ ∇²_t(e·G(t)) (d x d, one
    forward-over-reverse sweep of d directions),
    ∇²_z λ g = Jᵀ A J with J = [diag(D), diag(D∘s)], i.e. the blocks
    D_a D_b Σ A_ab, D_a D_b Σ A_ab s_b and D_a D_b Σ A_ab s_a s_b summed over the
    slots; the same matrix as CasADi's Hessian of the whole Lagrangian over the
    2d unknowns (2d directions through every slot), for about half the instructions.
    """
    d, m = centre.numel(), len(sel)
    t, e, pp = ca.SX.sym("t", d), ca.SX.sym("e", m), ca.SX.sym("p", p.numel())
    H_t, _ = ca.hessian(ca.dot(e, rows_fn(t, pp)[list(sel)]), t)
    slot = ca.Function("cuboid_slot_hess", [t, e, pp], [ca.cse(H_t)], ["t", "e", "p"], ["h"])
    lam_f, lam_g = ca.SX.sym("lam_f"), ca.SX.sym("lam_g", K * J)
    blocks = []
    for j in range(J):
        u, w = Z[:d, j], Z[d:, j]
        Sj, Ej = S[:, j * K : (j + 1) * K], E[:, j * K : (j + 1) * K]
        T = ca.repmat(centre, 1, K) + ca.repmat(size, 1, K) * (ca.repmat(u, 1, K) + Sj * ca.repmat(w, 1, K))
        Hs = slot.map(K)(T, Ej, ca.repmat(p, 1, K))  # d x dK
        lam = lam_g[j * K : (j + 1) * K]
        uu, uw, ww = ca.SX(d, d), ca.SX(d, d), ca.SX(d, d)
        for k in range(K):
            A = lam[k] * Hs[:, k * d : (k + 1) * d]
            s = Sj[:, k]
            uu += A
            uw += A * ca.repmat(s.T, d, 1)
            ww += A * ca.mtimes(s, s.T)
        Dd = ca.mtimes(size, size.T)
        blocks.append(ca.blockcat([[Dd * uu, Dd * uw], [(Dd * uw).T, Dd * ww]]))
    H = ca.diagcat(*blocks) + lam_f * ca.hessian(f, ca.vec(Z))[0]
    x = ca.vec(Z)
    params = ca.vertcat(p, ca.vec(S), ca.vec(E), centre, size)
    return ca.Function(
        name, [x, params, lam_f, lam_g], [ca.triu(H)], ["x", "p", "lam_f", "lam_g"], ["triu_hess_gamma_x_x"]
    )


def jacobian_of_rows(name: str, rows_fn: ca.Function, sel, K: int, J: int, Z, p, S, E, centre, size):
    """``jac_g`` of `SlotNLP`, through the task points: (z, p) -> (g, ∂g/∂z).  A slot's row
    g = e·G(t) has the gradient ∇_t g (one reverse sweep) and ∂g/∂z = (D∘∇_t g, D∘s∘∇_t g)
    (t = c + D∘(u + s∘w)); CasADi's own Jacobian takes 2d forward directions through each slot."""
    d, m = centre.numel(), len(sel)
    t, e, pp = ca.SX.sym("t", d), ca.SX.sym("e", m), ca.SX.sym("p", p.numel())
    g_t = ca.dot(e, rows_fn(t, pp)[list(sel)])
    slot = ca.Function(
        "cuboid_slot_grad", [t, e, pp], ca.cse([g_t, ca.gradient(g_t, t)]), ["t", "e", "p"], ["g", "grad"]
    )
    gs, jacs = [], []
    for j in range(J):
        u, w = Z[:d, j], Z[d:, j]
        Sj, Ej = S[:, j * K : (j + 1) * K], E[:, j * K : (j + 1) * K]
        T = ca.repmat(centre, 1, K) + ca.repmat(size, 1, K) * (ca.repmat(u, 1, K) + Sj * ca.repmat(w, 1, K))
        G, grad = slot.map(K)(T, Ej, ca.repmat(p, 1, K))  # 1 x K, d x K
        scaled = grad * ca.repmat(size, 1, K)
        gs.append(G.T)
        jacs.append(ca.horzcat(scaled.T, (scaled * Sj).T))
    x = ca.vec(Z)
    params = ca.vertcat(p, ca.vec(S), ca.vec(E), centre, size)
    return ca.Function(name, [x, params], [ca.vertcat(*gs), ca.diagcat(*jacs)], ["x", "p"], ["g", "jac_g_x"])


class SlotNLP:
    """IPOPT on the working-set cuboid NLP with K row slots (see the module docstring),
    for the quantities ``sel`` (positions in the output of ``rows_fn``; the others
    are not evaluated).

    With ``blocks`` = J > 1 it solves J such NLPs (J starts, each with its own box
    z_j = (u_j, w_j), K slots and selectors) as one block-separable NLP: the
    objective is the sum of theirs and no constraint couples two blocks, so its
    KKT points are exactly the tuples of KKT points of the J NLPs; IPOPT's
    fixed cost per iteration is then paid once for all J starts.  The unknowns
    are (z_1, ..., z_J), the parameters (p, S_1 ... S_J, E_1 ... E_J, c, D).
    """

    def __init__(
        self, closure: LoopClosure, rows_fn: ca.Function, sel: tuple[int, ...], K: int, options: dict, blocks: int = 1
    ):
        c = closure
        d, m, J = c.nq, len(sel), blocks
        self.d, self.m, self.K, self.J = d, m, K, J
        Z = ca.SX.sym("z", 2 * d, J)
        p = ca.SX.sym("p", c.np)
        S, E = ca.SX.sym("S", d, K * J), ca.SX.sym("E", m, K * J)
        centre, size = ca.SX.sym("c", d), ca.SX.sym("D", d)
        f, g = 0, []
        for j in range(J):
            u, w = Z[:d, j], Z[d:, j]
            Sj, Ej = S[:, j * K : (j + 1) * K], E[:, j * K : (j + 1) * K]
            T = ca.repmat(centre, 1, K) + ca.repmat(size, 1, K) * (ca.repmat(u, 1, K) + Sj * ca.repmat(w, 1, K))
            G = rows_fn.map(K)(T, ca.repmat(p, 1, K))[list(sel), :]
            f -= ca.sum1(ca.log(w))
            g.append(ca.sum1(Ej * G).T)
        nlp = {
            "x": ca.vec(Z),
            "p": ca.vertcat(p, ca.vec(S), ca.vec(E), centre, size),
            "f": f,
            "g": ca.vertcat(*g),
        }
        name = f"{c.name}_cuboid_slots_{K}" + (f"_x{J}" if J > 1 else "")
        derivatives = {
            "hess_lag": hessian_of_lagrangian(f"{name}_hess_l", rows_fn, sel, K, J, Z, p, S, E, centre, size, f),
            "jac_g": jacobian_of_rows(f"{name}_jac_g", rows_fn, sel, K, J, Z, p, S, E, centre, size),
        }
        self._solver = ca.nlpsol(name, "ipopt", nlp, {**options, **derivatives})
        self._out = {name: k for k, name in enumerate(self._solver.name_out())}
        self._local = threading.local()

    def solve(self, z0, params, lbx, lbg, ubg) -> tuple[np.ndarray, bool, str, int, np.ndarray]:
        """(z, converged, IPOPT status, iterations, multipliers of the slots).

        Called through a FunctionBuffer (one per thread): numpy in and out,
        without the conversions of a regular call.
        """
        buf, run = self._buffer()
        n, K = len(z0), self.K * self.J
        given = {"x0": z0, "p": params, "lbx": lbx, "ubx": np.full(n, np.inf), "lbg": lbg, "ubg": ubg}
        ins = [
            np.ascontiguousarray(given.get(name, np.zeros(self._solver.nnz_in(k))), dtype=float)
            for k, name in enumerate(self._solver.name_in())
        ]
        outs = [np.empty(self._solver.nnz_out(k)) for k in range(self._solver.n_out())]
        for k, a in enumerate(ins):
            buf.set_arg(k, memoryview(a))
        for k, a in enumerate(outs):
            buf.set_res(k, memoryview(a))
        try:
            run()
        except RuntimeError as exc:  # an evaluation error: a failed start, not a crash
            log.debug("working-set cuboid NLP raised: %s", exc)
            return np.full(n, np.nan), False, f"solver error: {exc}".splitlines()[0], 0, np.zeros(K)
        stats = buf.stats()
        z = outs[self._out["x"]]
        ok = bool(stats.get("success", False)) and bool(np.all(np.isfinite(z)))
        return z, ok, str(stats.get("return_status", "")), int(stats.get("iter_count", 0)), outs[self._out["lam_g"]]

    def _buffer(self):
        state = getattr(self._local, "buffer", None)
        if state is None:
            state = self._local.buffer = self._solver.buffer()
        return state


class ClosedFormCuboid:
    """The cuboid NLP of one model through its closed-form IK, on working sets of rows.

    Attributes
    ----------
    rows
        indices of the bounded limited quantities in ``limited``'s output;
    lower, upper
        their bounds as the NLP keeps them (inside the declared ones by the caller's margin);
    reach_lower
        the bound of the reach margin;
    samples
        the unit-box sample points (N, d);
    centre, size
        the normalisation of the box;
    initial
        quantities (positions in ``rows``, and len(rows) for the reach margin) whose rows at the corners
        and (``face_centres``) the face centres start the first solve.
    """

    def __init__(
        self,
        model: Model,
        config: SolverConfig,
        limited: ca.Function,
        rows: tuple[int, ...],
        lower: np.ndarray,
        upper: np.ndarray,
        reach_lower: float,
        samples: np.ndarray,
        centre: np.ndarray,
        size: np.ndarray,
        options: dict,
        initial: list[int],
        face_centres: bool = True,
    ):
        c = model.closure
        self.model, self.config, self.closure = model, config, c
        self.rows = tuple(rows)
        self.fn = row_function(c, limited, self.rows)
        self.m = len(self.rows) + 1
        self.lo = np.r_[lower, reach_lower]
        self.hi = np.r_[upper, np.inf]
        self.S = np.array(samples, dtype=float)
        self.centre, self.size = np.asarray(centre, dtype=float), np.asarray(size, dtype=float)
        self.options = {**options, **QUIET}
        self._lo_slack = self.lo - relaxation(self.lo, self.options)
        self._hi_slack = self.hi + relaxation(self.hi, self.options)
        self.d = c.nq
        self._lbx = np.r_[np.full(self.d, -np.inf), np.full(self.d, 1e-10)]
        # the corners and the face centres (where the grid has them): a box whose limits bind at
        # a corner (a convex boundary) or at a face's middle (a concave one) starts from these rows
        ends = np.sum((self.S == 0.0) | (self.S == 1.0), axis=1)
        middles = np.sum(self.S == 0.5, axis=1)
        firsts = np.flatnonzero((ends == self.d) | (face_centres & (ends == 1) & (middles == self.d - 1)))
        self.initial = {(int(j), int(r)) for j in firsts for r in (initial or range(self.m))}
        self.memory: set[tuple[int, int]] = set()  # rows active at the optima found so far

    # -- the NLP ----------------------------------------------------------------------------------

    def _nlp(self, sel: tuple[int, ...], K: int, blocks: int = 1) -> SlotNLP:
        key = ("cuboid_slots", self.rows, sel, K, blocks, repr(sorted(self.options.items())))
        return solvers_of(self.closure).get(
            repr(key), self.config, lambda: SlotNLP(self.closure, self.fn, sel, K, self.options, blocks)
        )

    def _slots(self, work: list[tuple[int, int]], K: int, sel: tuple[int, ...]):
        """The parameters of K slots holding the rows ``work``: S (K, d), E (K, m), lbg, ubg."""
        S, E = np.full((K, self.d), 0.5), np.zeros((K, len(sel)))
        lbg, ubg = np.full(K, -np.inf), np.full(K, np.inf)
        for k, (j, r) in enumerate(work):
            S[k], E[k, sel.index(r)], lbg[k], ubg[k] = self.S[j], 1.0, self.lo[r], self.hi[r]
        return S, E, lbg, ubg

    def _solve(self, z0: np.ndarray, work: list[tuple[int, int]]):
        K = slots(len(work))
        sel = tuple(sorted({r for _, r in work}))  # the quantities with rows: only those are evaluated
        S, E, lbg, ubg = self._slots(work, K, sel)
        params = np.r_[self.model.p, S.ravel(), E.ravel(), self.centre, self.size]
        return self._nlp(sel, K).solve(z0, params, self._lbx, lbg, ubg)

    def _solve_blocks(self, z0s: list[np.ndarray], works: list[list[tuple[int, int]]]):
        """Several starts, each on its own working set, as one block-separable NLP
        (`SlotNLP` with blocks): (Z (J, 2d), ok, status, iterations, multipliers (J, K))."""
        J = len(works)
        K = slots(max(len(w) for w in works))
        sel = tuple(sorted({r for w in works for _, r in w}))
        parts = [self._slots(w, K, sel) for w in works]
        params = np.r_[
            self.model.p,
            np.concatenate([S.ravel() for S, *_ in parts]),
            np.concatenate([E.ravel() for _, E, *_ in parts]),
            self.centre,
            self.size,
        ]
        lbg = np.concatenate([q[2] for q in parts])
        ubg = np.concatenate([q[3] for q in parts])
        z, ok, status, iters, lam = self._nlp(sel, K, J).solve(
            np.concatenate(z0s), params, np.tile(self._lbx, J), lbg, ubg
        )
        return z.reshape(J, 2 * self.d), ok, status, iters, lam.reshape(J, K)

    def values(self, z: np.ndarray) -> np.ndarray:
        """Every quantity at every sample of the box z: (N, m)."""
        return self.values_of([z])[0]

    def values_of(self, boxes: list[np.ndarray]) -> list[np.ndarray]:
        """`values` of several boxes, in one mapped call."""
        T = np.vstack([self.centre + self.size * (z[: self.d] + self.S * z[self.d :]) for z in boxes])
        V = evaluate_points(self.closure, row_key(self.rows), self.fn, [T], self.model.p)[0]
        return np.split(V, len(boxes))

    def _violated(self, V: np.ndarray, work: set[tuple[int, int]], per_quantity: int | None) -> set[tuple[int, int]]:
        """Rows outside the working set that V (N, m) violates beyond IPOPT's relaxation of
        the bounds (`relaxation`: what the rows in the working set may violate too): of each
        quantity the ``per_quantity`` worst (all if None; NaN, a sample that does not
        assemble, counts as worst)."""
        with np.errstate(invalid="ignore"):
            excess = np.maximum(self._lo_slack - V, V - self._hi_slack)
        excess = np.where(np.isnan(excess), np.inf, excess)
        for j, r in work:
            excess[j, r] = -np.inf
        new = set()
        for r in range(self.m):
            col = excess[:, r]
            worst = np.argsort(-col, kind="stable")[:per_quantity]
            new |= {(int(j), r) for j in worst if col[j] > 0}
        return new

    def settle(self, z0: np.ndarray, work: set[tuple[int, int]]) -> tuple[np.ndarray, bool, str, int, set]:
        """Solve from z0 on the working set ``work``, adding the rows the solution
        violates until it violates none.  Returns (z, ok, status, iterations, the
        active rows of the final solution)."""
        work = set(work)
        iterations = 0
        for solve in range(MAX_SETTLE):
            order = sorted(work)
            z, ok, status, iters, lam = self._solve(z0, order)
            iterations += iters
            if not ok:
                return z, False, status, iterations, set()
            new = self._violated(self.values(z), work, ADD_PER_QUANTITY if solve < ESCALATE else None)
            if not new:
                lam = np.abs(lam[: len(order)])
                top = float(lam.max()) if lam.size else 0.0
                active = {row for row, v in zip(order, lam) if v > ACTIVE_MULTIPLIER * top}
                return z, True, status, iterations, active
            log.debug("working set: %d rows violated outside %d, solving again", len(new), len(work))
            work |= new
        return z, False, f"the working set did not settle in {MAX_SETTLE} solves", iterations, set()

    def settle_blocks(self, z0s: list[np.ndarray], works: list[set]) -> tuple[list, bool, str, int, list[set]]:
        """`settle` for several starts at once (one block-separable NLP per round;
        every start solved again from its own z0 while any start's rows grow).
        Returns (the z of each start, ok, status, iterations, the active rows of each)."""
        works = [set(w) for w in works]
        iterations = 0
        for solve in range(MAX_SETTLE):
            orders = [sorted(w) for w in works]
            Z, ok, status, iters, lam = self._solve_blocks(z0s, orders)
            iterations += iters
            if not ok:
                return [], False, status, iterations, []
            grown = False
            for j, V in enumerate(self.values_of(list(Z))):
                new = self._violated(V, works[j], ADD_PER_QUANTITY if solve < ESCALATE else None)
                if new:
                    works[j] |= new
                    grown = True
            if not grown:
                actives = []
                for order, lj in zip(orders, lam):
                    lj = np.abs(lj[: len(order)])
                    top = float(lj.max()) if lj.size else 0.0
                    actives.append({row for row, v in zip(order, lj) if v > ACTIVE_MULTIPLIER * top})
                return list(Z), True, status, iterations, actives
            log.debug("joint working sets grew, solving again")
        return [], False, f"the working sets did not settle in {MAX_SETTLE} solves", iterations, []

    # -- what inscribed_cuboid calls --------------------------------------------------------------

    def start(self, u0: np.ndarray, w0: np.ndarray, *_poses) -> tuple[bool, np.ndarray | None, str, int]:
        """One start from the box (u0, w0) (the poses of its samples are not
        unknowns here): (converged, z, status, iterations)."""
        z0 = np.r_[u0, w0]
        z, ok, status, iters, active = self.settle(z0, self.memory or self.initial)
        if not ok and self.memory:  # the rows of other optima did not hold the box: add the initial rows
            log.debug("start from the active rows failed (%s); again with the corner rows", status)
            z, ok, status, more, active = self.settle(z0, self.memory | self.initial)
            iters += more
        if ok:
            self.memory |= active
        return ok, (z if ok else None), status, iters

    def start_all(self, boxes: list[tuple[np.ndarray, np.ndarray]]) -> tuple[list[tuple] | None, int]:
        """Several starts from the boxes (u0, w0) at once, as one block-separable NLP,
        each from the rows of the optima found before (the first start's, run by
        `start`): ([(converged, z, status, 0) per start], IPOPT iterations).  The
        runs are None if the joint solve did not converge: the caller then runs the
        starts one by one (which also retries a start with the initial rows)."""
        if not self.memory or len(boxes) < 2:
            return None, 0
        z0s = [np.r_[u0, w0] for u0, w0 in boxes]
        Z, ok, status, iters, actives = self.settle_blocks(z0s, [self.memory] * len(boxes))
        if not ok:
            log.debug("joint start of %d boxes did not converge (%s); one by one", len(boxes), status)
            return None, iters
        for active in actives:
            self.memory |= active
        return [(True, z, status, 0) for z in Z], iters

    def exchange(self, z: np.ndarray, points: np.ndarray) -> tuple[np.ndarray, bool, str, int]:
        """Add sample points (unit box) and solve again from z."""
        self.S = np.vstack([self.S, points])
        z_new, ok, status, iters, active = self.settle(z, self.memory)
        if ok:
            self.memory |= active
        return z_new, ok, status, iters
