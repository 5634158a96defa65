"""Kinematics kernels: CasADi Functions built generically from a
[`LoopClosure`][cpm_nlp.core.model.LoopClosure], for single solves, batches, embedding
and exported code.  Each ends with the pose checks and status rule of
`cpm_nlp.core.pose_checks`, so every kernel -- and exported C code -- reports a status.

* **FK kernel**: Newton's method from a guess, with CasADi's ``fast_newton``
  rootfinder (it generates C code; its derivatives come from the implicit
  function theorem), followed by the checks.
* **IK kernel**: the closed form where the mechanism has one (else
  ``fast_newton`` on the IK residual), followed by the checks.
* **Jacobian kernel**: J = -Φ_x⁻¹ Φ_q and the inverse Jacobian, from AD.

Kernels take the parameters p, the joint limits and the tolerance as inputs,
so one kernel -- and one compiled library -- serves every model of a
mechanism type; `bake` substitutes one model's numbers (for export and
for the embedding API).  Status codes are the positions in
`STATUSES`.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import casadi as ca
import numpy as np

from .conditioning import LeftInverseBlocks, all_finite, closure_blocks, robust_max_abs
from .errors import InputError
from .model import LoopClosure, Model
from .pose_checks import (
    CASADI,
    check_expressions,
    checks_function,
    code_of,
    is_singular,
    limit_vectors,
    n_joints,
    screen_factor,
    status_code,
    status_rules,
)
from .result import Status
from .solver import DEFAULT_OPTIONS, SolverConfig, solvers_of
from .solver_options import NEWTON_BATCH, NEWTON_BATCH_IGNORED

#: Newton options the kernels' rootfinder (CasADi ``fast_newton``) accepts (from the one table,
#: `cpm_nlp.core.solver_options.NEWTON_TABLE`)
NEWTON_OPTIONS = NEWTON_BATCH
#: options of CasADi's ``newton`` plugin that have no meaning here (fast_newton never raises or prints)
_IGNORED_NEWTON = NEWTON_BATCH_IGNORED


# -- Newton options ---------------------------------------------------------------------------


def newton_options(config: SolverConfig | None) -> dict[str, Any]:
    """Options of the kernels' rootfinder (``fast_newton``) from a solver config.

    The kernels always solve by Newton's method; an IPOPT configuration only
    contributes its tolerance.  User options outside `NEWTON_OPTIONS`
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

    Attributes
    ----------
    function
        the CasADi Function; its inputs are ``pose_inputs`` (one row per pose in a batch)
        followed by ``SHARED_INPUTS``.
    kind
        "fk", "ik" or "jacobian".
    """

    function: ca.Function
    kind: str
    pose_inputs: tuple[str, ...]
    outputs: tuple[str, ...]
    key: tuple = ()  # identity in the closure's cache
    #: inputs shared by every pose (numbers of one model), after ``pose_inputs``
    shared_inputs: tuple[str, ...] = ()
    #: the kernel this one tries first (a flat SX kernel: the closed form, or the reduced Newton),
    #: whose outputs it returns unchanged where that one's status is ``solved`` (a CasADi Switch);
    #: the compiled loop over poses runs it directly and the whole kernel only where it does not
    #: settle (`cpm_nlp.core.compiled.first_pass_source`).  None: no such first kernel
    first: Kernel | None = None
    #: outputs of this kernel that ``first`` does not give, with their values where it settles
    #: (the reduced kernel's ``path``, 0)
    first_fills: tuple[tuple[str, float], ...] = ()
    #: builds ``first`` for a model without joint limits (``unlimited``: the limit check as
    #: `cpm_nlp.core.pose_checks.check_expressions` writes it then), for the compiled loop only
    first_unlimited: Callable[[], Kernel] | None = field(default=None, compare=False, repr=False)

    @property
    def name(self) -> str:
        return self.function.name()


SHARED_INPUTS = ("p", "lower", "upper", "tol")
#: shared inputs of the FK through the closed-form IK: also the model's linearization at home
REDUCED_SHARED_INPUTS = SHARED_INPUTS + ("J_home", "Phi_x_home_inv")
#: ``path`` output of the FK kernel: which formulation answered ("closed": the closed-form FK of a
#: dyad, `closed_fk_kernel`)
PATHS = ("reduced", "full", "closed")
#: outputs of the FK as embedded (`cpm_nlp.io.embed.functions`) and exported: without ``path``
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
    return ca.logic_and(all_finite(y), residual <= tol)


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
    of `fk_kernel` for the others.

    A closure solved through normal equations (``loops``): first
    `gauss_newton_fk_kernel` (first derivatives only); a pose it does not
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
    return solvers_of(closure).memo(key, build)


def newton_fk_kernel(closure: LoopClosure, config: SolverConfig | None = None) -> Kernel:
    """Newton on Φ(x, q) = 0 from x0 (CasADi ``fast_newton``) and the checks: `full_fk_kernel`
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
    return solvers_of(closure).memo(key, build)


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
    """v = X e with X the block left inverse of e_x of `cond2_left_inverse_bound`: block by
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
    (`left_inverse_step`; first derivatives only, where Newton on the normal equations
    needs their second) from x0: an MX graph of ``steps`` calls of one SX step (its C code
    generated once) and one SX call of the checks.

    ``status`` is ``solved`` only where max |e| <= abstol after the steps (as Newton's stopping
    test, on every equation) and every check passes, with a margin of 2 on the singularity
    screen; any other status means "not settled here": `full_fk_kernel` then runs Newton.
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
        converged = robust_max_abs(c.loops(x_sym, q, p)) <= abstol
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
    return solvers_of(closure).memo(key, build)


#: Newton steps of the reduced FK (unrolled: straight-line code, no loop); from the
#: first-order guess two or three reach machine precision in the workspace
REDUCED_STEPS = 3


def reduced_fk_kernel(
    closure: LoopClosure, config: SolverConfig | None = None, steps: int = REDUCED_STEPS, unlimited: bool = False
) -> Kernel:
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
    ``cond1`` the certified bound of `cond1_bound` (no inverse of Φ_x;
    for a closure solved through normal equations, the bound of
    `cond2_left_inverse_bound` at the pose on κ₂ of every closure
    equation's Jacobian) and a margin of 2 on the singularity threshold.  Any other status means
    "not settled here": the full path decides (see `fk_kernel`).
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
        converged = robust_max_abs(q_ik - q) <= abstol
        # normal equations (an overconstrained graph): κ₂ of every closure equation's Jacobian, bounded at
        # the pose block by block (check_expressions); Φ_x⁻¹ at home serves the square closures
        chk = check_expressions(c, x, q, p, lower, upper, phi_x_home_inv=b, unlimited=unlimited)
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

    key = ("reduced_fk_kernel", _options_key(opts), steps) + (("unlimited",) if unlimited else ())
    return solvers_of(closure).memo(key, build)


def fk_kernel(closure: LoopClosure, config: SolverConfig | None = None) -> Kernel:
    """``<name>_fk``: the FK of every path in cpm_nlp (single Newton solves, batches, the
    embedding Functions, exported code).

    A closure with a closed-form FK (``fk_closed``: planar dyads, `cpm_nlp.mechanisms.described.dyads`
    and `graph_dyads`): first
    `closed_fk_kernel`; a pose it does not settle as ``solved`` goes to the Newton FK
    below from x0 (a CasADi Switch), so every status other than ``solved`` is Newton's,
    exactly as without the closed form; ``path`` 2 ("closed") says it answered.  Others: the
    Newton FK (`_newton_fk_kernel`).
    """
    c = closure
    if c.fk_closed is None and c.fk_seed is not None:
        return _seeded_fk_kernel(c, config)
    if c.fk_closed is None:
        return _newton_fk_kernel(c, config, f"{c.name}_fk")
    opts = newton_options(config)

    def build() -> Kernel:
        newton = _newton_fk_kernel(c, config, f"{c.name}_fk_newton_paths" if c.ik is not None else f"{c.name}_fk")
        first = closed_fk_kernel(c, config)
        fn = _settled_or(first.function, newton.function, f"{c.name}_fk", newton.outputs)
        twin = lambda: closed_fk_kernel(c, config, unlimited=True)  # noqa: E731
        return Kernel(fn, "fk", ("q", "x0"), newton.outputs, key, newton.shared_inputs, first, (), twin)

    key = ("fk_kernel_closed", _options_key(opts))
    return solvers_of(c).memo(key, build)


def _seeded_fk_kernel(closure: LoopClosure, config: SolverConfig | None) -> Kernel:
    """The Newton FK from the guess of a partial closed form (``fk_seed``: the dyads it can place,
    in closed form; the rest from x0): Newton moves only what the dyads leave, its status stands."""
    c = closure
    opts = newton_options(config)

    def build() -> Kernel:
        newton = _newton_fk_kernel(c, config, f"{c.name}_fk_newton")
        fn = newton.function
        ins = [ca.MX.sym(fn.name_in(k), fn.sparsity_in(k)) for k in range(fn.n_in())]
        q, x0, p = ins[0], ins[1], ins[2]  # (q, x0, p, ...): SHARED_INPUTS start with p
        outs = fn(q, c.fk_seed(q, x0, p), *ins[2:])
        f = ca.Function(f"{c.name}_fk", ins, list(outs), fn.name_in(), fn.name_out())
        return Kernel(f, "fk", ("q", "x0"), newton.outputs, key, newton.shared_inputs)

    key = ("fk_kernel_seeded", _options_key(opts))
    return solvers_of(c).memo(key, build)


def closed_fk_kernel(closure: LoopClosure, config: SolverConfig | None = None, unlimited: bool = False) -> Kernel:
    """``<name>_fk_closed: (q, x0, p, lower, upper, tol[, J_home, Phi_x_home_inv]) -> (x, passive,
    residual, branch_margin, round_trip_error, cond1, limit_margin[, path], status)``: the pose from
    the closure's closed-form FK (``fk_closed``; x0 picks the side and the turn of an angle), one flat
    SX graph, with the same inputs and outputs as the Newton FK it fronts in `fk_kernel`.

    ``status`` is ``solved`` only where the closed form assembles the pose (every dyad's disc >= 0,
    finite), the guess x0 lies on each dyad's side of the pose (side > 0; else the root Newton seeks
    from x0 is another assembly: Newton answers), and every check passes on (x, q): residual of Φ, branch,
    IK round trip, limits, and the conditioning with a margin of 2 on the singularity threshold
    (``cond1`` the certified bound of `cond1_bound` where there is a closed-form IK, else
    the exact one).  Any other status means "not settled here": Newton decides.
    """
    opts = newton_options(config)

    def build() -> Kernel:
        c = closure
        if c.fk_closed is None:  # pragma: no cover - guarded by fk_kernel
            raise ValueError(f"{c.name} has no closed-form FK")
        nl = n_joints(c)
        q, x0, p = ca.SX.sym("q", c.nq), ca.SX.sym("x0", c.nx), ca.SX.sym("p", c.np)
        lower, upper, tol = ca.SX.sym("lower", nl), ca.SX.sym("upper", nl), ca.SX.sym("tol")
        ins, shared_names = [q, x0, p, lower, upper, tol], SHARED_INPUTS
        b = None
        if c.ik is not None:
            jac_home = ca.SX.sym("J_home", c.nq, c.nq)
            b = ca.SX.sym("Phi_x_home_inv", c.nx, c.nx)
            ins, shared_names = ins + [jac_home, b], REDUCED_SHARED_INPUTS
        x, disc, side = c.fk_closed(q, x0, p)
        chk = check_expressions(c, x, q, p, lower, upper, phi_x_home_inv=b, unlimited=unlimited)
        singular = is_singular(chk["cond1"], CASADI, factor=2 * screen_factor(c))  # margin 2 over the screen
        status = status_code(status_rules(chk, tol, singular, CASADI), CASADI)
        # every dyad assembles (disc >= 0) and the guess lies on the side of each dyad's two
        # assemblies that the closed form takes (side > 0): the root Newton is after from x0, so a
        # search from guesses in another assembly (analysis.assembly) still finds that one
        assembled = ca.logic_and(ca.logic_and(disc >= 0, all_finite(x)), side > 0)
        status = _first(ca.logic_not(assembled), Status.NOT_CONVERGED, status)
        names = ["x", "passive", *_STATUS_OUTPUTS]
        outs = [x] + [ca.densify(chk[n]) for n in names[1:-1]]
        if c.ik is not None:  # the Newton FK's outputs: path before status
            names.insert(-1, "path")
            outs.append(ca.SX(PATHS.index("closed")))
        outs = ca.cse(outs + [status])
        fn = ca.Function(f"{c.name}_fk_closed", ins, outs, ["q", "x0", *shared_names], names)
        return Kernel(fn, "fk", ("q", "x0"), tuple(names), key, shared_names)

    key = ("closed_fk_kernel", _options_key(opts)) + (("unlimited",) if unlimited else ())
    return solvers_of(closure).memo(key, build)


def _newton_fk_kernel(closure: LoopClosure, config: SolverConfig | None, name: str) -> Kernel:
    """``name: (q, x0, p, lower, upper, tol[, J_home, Phi_x_home_inv]) ->
    (x, passive, residual, branch_margin, round_trip_error, cond1,
    limit_margin[, path], status)``: the Newton FK -- `fk_kernel` itself for a
    closure without a closed-form FK, its fallback for the others.

    Mechanisms with a closed-form IK: first `reduced_fk_kernel` with
    `REDUCED_STEPS` steps (nq unknowns); where Newton did not converge in
    them, the same kernel again from the pose they reached (the guess about it and
    `REDUCED_STEPS` more steps: the number of steps adapts to the pose, and the
    C code has the kernel once); a pose neither settles as ``solved`` -- Newton
    did not converge, a check failed, or the conditioning bound is not certified --
    goes to `full_fk_kernel` from x0 (each branch evaluated only where taken:
    CasADi Switches), so every status other than ``solved`` comes from the full
    path exactly as it did before the reduced one existed.  ``path`` says
    which one answered (0 reduced, 1 full; `PATHS`).  Mechanisms without
    a closed-form IK: `full_fk_kernel` alone (no ``path`` output).
    """
    c = closure
    if c.ik is None:
        return full_fk_kernel(c, config)
    opts = newton_options(config)

    def build() -> Kernel:
        first = reduced_fk_kernel(c, config)
        reduced = first.function
        full = full_fk_kernel(c, config).function
        names = ("x", "passive", *_STATUS_OUTPUTS)
        # outputs: (x, passive, checks..., path, status): status stays last
        out_names = [*names[:-1], "path", "status"]
        in_names = ["q", "x0", *REDUCED_SHARED_INPUTS]
        ins = [ca.MX.sym(n, reduced.sparsity_in(k)) for k, n in enumerate(in_names)]
        # every branch of the Switches takes (q, x0, shared..., the reduced outputs): one signature
        r_names = [f"reduced_{n}" for n in names]
        r_in = [ca.MX.sym(n, reduced.sparsity_out(k)) for k, n in enumerate(r_names)]
        # names from the lists, not the symbols: a symbol of size 0 (no passive joints) is a constant
        io = (in_names + r_names, out_names)
        solved, not_converged = code_of(Status.SOLVED), code_of(Status.NOT_CONVERGED)

        def answer(name: str, outs: list, path: int) -> ca.Function:
            return ca.Function(f"{c.name}_fk_{name}", ins + r_in, outs[:-1] + [ca.MX(path), outs[-1]], *io)

        keep = answer("keep", r_in, 0)
        f = list(full(*ins[:6]))
        fallback = answer("fallback", f, 1)
        # the second try: the reduced kernel from the pose the first reached (a non-finite one
        # settles nothing); what it does not settle, the full path decides from x0
        m = list(reduced(ins[0], r_in[0], *ins[2:]))
        more_keep = answer("more_keep", m, 0)
        more_switch = ca.Function.if_else(f"{c.name}_fk_more_switch", more_keep, fallback)
        retry = ca.Function(f"{c.name}_fk_retry", ins + r_in, more_switch(m[-1] == solved, *ins, *r_in), *io)
        rest = ca.Function.if_else(f"{c.name}_fk_rest", retry, fallback)
        rest_fn = ca.Function(f"{c.name}_fk_unsettled", ins + r_in, rest(r_in[-1] == not_converged, *ins, *r_in), *io)
        switch = ca.Function.if_else(f"{c.name}_fk_switch", keep, rest_fn)
        r = reduced(*ins)
        outs = switch(r[-1] == solved, *ins, *r)
        fn = ca.Function(name, ins, list(outs), in_names, out_names)
        fills = (("path", float(PATHS.index("reduced"))),)
        twin = lambda: reduced_fk_kernel(c, config, unlimited=True)  # noqa: E731
        return Kernel(fn, "fk", ("q", "x0"), tuple(out_names), key, REDUCED_SHARED_INPUTS, first, fills, twin)

    key = ("fk_kernel", _options_key(opts), name)
    return solvers_of(c).memo(key, build)


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
    return solvers_of(closure).memo(key, build)


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
    return solvers_of(closure).memo(key, build)


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

    Parameters
    ----------
    function
        the Function to wrap (default the kernel's own; the compiled library's twin for the
        compiled path).
    outputs
        the outputs to keep, by name (default all, in the kernel's order).
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
