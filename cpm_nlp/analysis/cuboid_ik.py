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

The working-set NLP has its row slots in groups, one per quantity with rows
(K_r = 4, 6, 8, 12, 16, ... slots for quantity r; one IPOPT solver per layout
of groups, built once per mechanism type and configuration); a slot holds a
sample point s_k, a parameter, and evaluates (and differentiates) its own
quantity only; unused slots are free (bounds ±inf).
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

#: row slots of the smallest group of one quantity in the working-set NLP (see `slots`)
MIN_SLOTS = 4
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
    """Slots of the smallest group that holds ``rows`` rows of one quantity: MIN_SLOTS times
    1, 1.5, 2, 3, 4, 6, 8, ... (one IPOPT solver per layout of groups)."""
    K = MIN_SLOTS
    while K < rows:
        K = K * 3 // 2 if K & (K - 1) == 0 else K * 4 // 3
    return K


def _task_points(Z, S, centre, size, j: int, K: int):
    """The task points (d x K) of block j's K slots: t = c + D∘(u + s∘w)."""
    d = centre.numel()
    u, w, Sj = Z[:d, j], Z[d:, j], S[:, j * K : (j + 1) * K]
    return ca.repmat(centre, 1, K) + ca.repmat(size, 1, K) * (ca.repmat(u, 1, K) + Sj * ca.repmat(w, 1, K))


def _per_group(layout, fns: dict, T, p) -> list:
    """Each output of the slot functions ``fns[r]`` over the groups' slots of T, side by side
    (the groups in ``layout`` order: (quantity, slots) each)."""
    outs, offset = [], 0
    for r, Kr in layout:
        got = fns[r].map(Kr)(T[:, offset : offset + Kr], ca.repmat(p, 1, Kr))
        outs.append(list(got) if isinstance(got, (list, tuple)) else [got])  # one output: a matrix
        offset += Kr
    return [ca.horzcat(*[o[k] for o in outs]) for k in range(len(outs[0]))]


def hessian_of_lagrangian(name: str, rows_fn: ca.Function, layout, J: int, Z, p, S, centre, size, f):
    """``hess_lag`` of `SlotNLP`, through the task points: (z, p, lam_f, lam_g) -> triu(∇²_z L).

    A slot's row depends on its box z = (u, w) only through its task point
    t = c + D∘(u + s∘w), linear in z: with A = λ ∇²_t G_r(t) (d x d, one
    forward-over-reverse sweep of d directions, of the slot's own quantity r only),
    ∇²_z λ g = Jᵀ A J with J = [diag(D), diag(D∘s)], i.e. the blocks
    D_a D_b Σ A_ab, D_a D_b Σ A_ab s_b and D_a D_b Σ A_ab s_a s_b summed over the
    slots; the same matrix as CasADi's Hessian of the whole Lagrangian over the
    2d unknowns (2d directions through every slot), for a fraction of the instructions.
    """
    d, K = centre.numel(), sum(Kr for _, Kr in layout)
    t, pp = ca.SX.sym("t", d), ca.SX.sym("p", p.numel())
    fns = {
        r: ca.Function("cuboid_slot_hess", [t, pp], [ca.cse(ca.hessian(rows_fn(t, pp)[r], t)[0])], ["t", "p"], ["h"])
        for r, _ in layout
    }
    lam_f, lam_g = ca.SX.sym("lam_f"), ca.SX.sym("lam_g", K * J)
    blocks = []
    for j in range(J):
        Sj = S[:, j * K : (j + 1) * K]
        (Hs,) = _per_group(layout, fns, _task_points(Z, S, centre, size, j, K), p)  # d x dK
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
    params = ca.vertcat(p, ca.vec(S), centre, size)
    return ca.Function(
        name, [x, params, lam_f, lam_g], [ca.triu(H)], ["x", "p", "lam_f", "lam_g"], ["triu_hess_gamma_x_x"]
    )


def jacobian_of_rows(name: str, rows_fn: ca.Function, layout, J: int, Z, p, S, centre, size):
    """``jac_g`` of `SlotNLP`, through the task points: (z, p) -> (g, ∂g/∂z).  A slot's row
    g = G_r(t) has the gradient ∇_t g (one reverse sweep) and ∂g/∂z = (D∘∇_t g, D∘s∘∇_t g)
    (t = c + D∘(u + s∘w)); CasADi's own Jacobian takes 2d forward directions through each slot."""
    d, K = centre.numel(), sum(Kr for _, Kr in layout)
    t, pp = ca.SX.sym("t", d), ca.SX.sym("p", p.numel())
    fns = {}
    for r, _ in layout:
        g_t = rows_fn(t, pp)[r]
        fns[r] = ca.Function("cuboid_slot_grad", [t, pp], ca.cse([g_t, ca.gradient(g_t, t)]), ["t", "p"], ["g", "grad"])
    gs, jacs = [], []
    for j in range(J):
        G, grad = _per_group(layout, fns, _task_points(Z, S, centre, size, j, K), p)  # 1 x K, d x K
        scaled = grad * ca.repmat(size, 1, K)
        gs.append(G.T)
        jacs.append(ca.horzcat(scaled.T, (scaled * S[:, j * K : (j + 1) * K]).T))
    x = ca.vec(Z)
    params = ca.vertcat(p, ca.vec(S), centre, size)
    return ca.Function(name, [x, params], [ca.vertcat(*gs), ca.diagcat(*jacs)], ["x", "p"], ["g", "jac_g_x"])


class SlotNLP:
    """IPOPT on the working-set cuboid NLP with row slots in groups, one group of K_r slots
    per quantity r (``layout``: (r, K_r) each; positions in the output of ``rows_fn``; the
    other quantities are not evaluated), K = Σ K_r slots in all (see the module docstring).

    With ``blocks`` = J > 1 it solves J such NLPs (J starts, each with its own box
    z_j = (u_j, w_j) and K slots) as one block-separable NLP: the
    objective is the sum of theirs and no constraint couples two blocks, so its
    KKT points are exactly the tuples of KKT points of the J NLPs; IPOPT's
    fixed cost per iteration is then paid once for all J starts.  The unknowns
    are (z_1, ..., z_J), the parameters (p, S_1 ... S_J, c, D).
    """

    def __init__(self, closure: LoopClosure, rows_fn: ca.Function, layout: tuple, options: dict, blocks: int = 1):
        c = closure
        d, J = c.nq, blocks
        K = sum(Kr for _, Kr in layout)
        self.d, self.K, self.J, self.layout = d, K, J, tuple(layout)
        Z = ca.SX.sym("z", 2 * d, J)
        p = ca.SX.sym("p", c.np)
        S = ca.SX.sym("S", d, K * J)
        centre, size = ca.SX.sym("c", d), ca.SX.sym("D", d)
        t, q = ca.SX.sym("t", d), ca.SX.sym("p", c.np)
        fns = {r: ca.Function("cuboid_slot_row", [t, q], [rows_fn(t, q)[r]], ["t", "p"], ["g"]) for r, _ in layout}
        f, g = 0, []
        for j in range(J):
            (G,) = _per_group(layout, fns, _task_points(Z, S, centre, size, j, K), p)
            f -= ca.sum1(ca.log(Z[d:, j]))
            g.append(G.T)
        nlp = {"x": ca.vec(Z), "p": ca.vertcat(p, ca.vec(S), centre, size), "f": f, "g": ca.vertcat(*g)}
        name = f"{c.name}_cuboid_slots_" + "_".join(f"{r}x{Kr}" for r, Kr in layout) + (f"_x{J}" if J > 1 else "")
        derivatives = {
            "hess_lag": hessian_of_lagrangian(f"{name}_hess_l", rows_fn, layout, J, Z, p, S, centre, size, f),
            "jac_g": jacobian_of_rows(f"{name}_jac_g", rows_fn, layout, J, Z, p, S, centre, size),
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

    def _nlp(self, layout: tuple, blocks: int = 1) -> SlotNLP:
        key = ("cuboid_slots", self.rows, layout, blocks, repr(sorted(self.options.items())))
        return solvers_of(self.closure).get(
            repr(key), self.config, lambda: SlotNLP(self.closure, self.fn, layout, self.options, blocks)
        )

    @staticmethod
    def _layout(works: list[list[tuple[int, int]]]) -> tuple:
        """The groups of slots that hold every working set of ``works``: (quantity, slots) for
        each quantity with rows (only those are evaluated), in order."""
        most: dict[int, int] = {}
        for work in works:
            for r in {r for _, r in work}:
                most[r] = max(most.get(r, 0), sum(1 for _, q in work if q == r))
        return tuple((r, slots(n)) for r, n in sorted(most.items()))

    def _slots(self, work: list[tuple[int, int]], layout: tuple):
        """The parameters of the slots of ``layout`` holding the rows ``work``: S (K, d), lbg,
        ubg, and the slot of each row of ``work``."""
        K = sum(Kr for _, Kr in layout)
        S = np.full((K, self.d), 0.5)
        lbg, ubg = np.full(K, -np.inf), np.full(K, np.inf)
        offsets, used = {}, {}
        offset = 0
        for r, Kr in layout:
            offsets[r], used[r] = offset, 0
            offset += Kr
        where = np.empty(len(work), dtype=int)
        for i, (j, r) in enumerate(work):
            k = offsets[r] + used[r]
            used[r] += 1
            S[k], lbg[k], ubg[k], where[i] = self.S[j], self.lo[r], self.hi[r], k
        return S, lbg, ubg, where

    def _solve(self, z0: np.ndarray, work: list[tuple[int, int]]):
        """One solve on the rows ``work``: (z, ok, status, iterations, the multiplier of each row)."""
        layout = self._layout([work])
        S, lbg, ubg, where = self._slots(work, layout)
        params = np.r_[self.model.p, S.ravel(), self.centre, self.size]
        z, ok, status, iters, lam = self._nlp(layout).solve(z0, params, self._lbx, lbg, ubg)
        return z, ok, status, iters, lam[where]

    def _solve_blocks(self, z0s: list[np.ndarray], works: list[list[tuple[int, int]]]):
        """Several starts, each on its own working set, as one block-separable NLP
        (`SlotNLP` with blocks): (Z (J, 2d), ok, status, iterations, the multiplier of each
        row of each start)."""
        J = len(works)
        layout = self._layout(works)
        parts = [self._slots(w, layout) for w in works]
        params = np.r_[self.model.p, np.concatenate([S.ravel() for S, *_ in parts]), self.centre, self.size]
        lbg = np.concatenate([q[1] for q in parts])
        ubg = np.concatenate([q[2] for q in parts])
        z, ok, status, iters, lam = self._nlp(layout, J).solve(
            np.concatenate(z0s), params, np.tile(self._lbx, J), lbg, ubg
        )
        lam = lam.reshape(J, -1)
        return z.reshape(J, 2 * self.d), ok, status, iters, [lam[j][q[3]] for j, q in enumerate(parts)]

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
                lam = np.abs(lam)
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
                    lj = np.abs(lj)
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
