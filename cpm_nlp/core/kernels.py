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

#: FK/IK round trips must agree to this multiple of the residual tolerance.
ROUND_TRIP_FACTOR = 100.0
#: Φ_x (or Φ_y) with a larger condition number is reported singular.
SINGULAR_CONDITION = 1e10
#: status code = position in this tuple (exported code reports codes)
STATUSES: tuple[Status, ...] = tuple(Status)
#: Newton options the kernels' rootfinder (CasADi ``fast_newton``) accepts
NEWTON_OPTIONS = ("abstol", "abstolStep", "max_iter")
#: options of CasADi's ``newton`` plugin that have no meaning here (fast_newton never raises or prints)
_IGNORED_NEWTON = ("error_on_fail", "print_iteration")

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


# -- symbolic checks ----------------------------------------------------------------------------


def _all_finite(v: ca.SX) -> ca.SX:
    return ca.sum1(v * 0) == 0  # x * 0 is NaN for inf and NaN


def _robust_max_abs(v: ca.SX) -> ca.SX:
    """max |v|, inf if any entry is NaN (C's fmax would skip NaN)."""
    return ca.if_else(_all_finite(v), ca.mmax(ca.fabs(v)), ca.inf)


def check_expressions(
    closure: LoopClosure, x: ca.SX, q: ca.SX, p: ca.SX, lower: ca.SX, upper: ca.SX
) -> dict[str, ca.SX]:
    """Symbolic checks of the pose (x, q): see :data:`CHECKS`.

    lower, upper: limits of :func:`limited_coordinates` (q, x, passive joints),
    ±inf where none is declared.
    """
    c = closure
    out: dict[str, ca.SX] = {"finite": _all_finite(ca.vertcat(x, q))}
    out["residual"] = _robust_max_abs(c.phi(x, q, p))
    if c.branch is not None:
        g = c.branch(x, q, p)
        out["branch_margin"] = ca.if_else(_all_finite(g), ca.mmin(g), -ca.inf)
    else:
        out["branch_margin"] = ca.SX(ca.inf)
    if c.ik is not None:
        x_ik, q_ik, reach = c.ik(x[list(c.task_index)], p)
        err = _robust_max_abs(ca.vertcat(x_ik - x, q_ik - q))
        out["round_trip_error"] = ca.if_else(reach >= 0, err, ca.inf)
    else:
        out["round_trip_error"] = ca.SX(0)
    phi_x = c.phi_x(x, q, p)
    out["phi_x"] = phi_x
    if ca.sprank(phi_x.sparsity()) < c.nx:  # structurally singular: no inverse to take
        out["cond1"] = ca.SX(ca.inf)
    else:
        out["cond1"] = ca.norm_1(phi_x) * ca.norm_1(ca.inv(phi_x))
    passive = c.passive(x, q, p) if c.passive is not None else ca.SX(0, 1)
    out["passive"] = passive
    joints = ca.vertcat(q, x, passive)  # the order of limited_coordinates
    if joints.numel():
        inside = ca.logic_and(joints >= lower, joints <= upper)
        margins = ca.if_else(inside, ca.fmin(joints - lower, upper - joints), -ca.inf)
        out["limit_margin"] = ca.mmin(margins)
    else:  # pragma: no cover - every mechanism has actuators
        out["limit_margin"] = ca.SX(ca.inf)
    return out


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
    branch_margin, round_trip_error, cond1, limit_margin, phi_x, status)``;
    status with the conservative (1-norm) singularity screen."""

    def build() -> ca.Function:
        c = closure
        x, q, p = ca.SX.sym("x", c.nx), ca.SX.sym("q", c.nq), ca.SX.sym("p", c.np)
        nl = n_joints(c)
        lower, upper, tol = ca.SX.sym("lower", nl), ca.SX.sym("upper", nl), ca.SX.sym("tol")
        chk = check_expressions(c, x, q, p, lower, upper)
        singular = is_singular(chk["cond1"], CASADI, factor=c.nx)
        status = status_code(status_rules(chk, tol, singular, CASADI), CASADI)
        names = ["passive", *CHECKS, "phi_x"]
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

    @property
    def name(self) -> str:
        return self.function.name()


SHARED_INPUTS = ("p", "lower", "upper", "tol")
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
    return ca.logic_and(ca.sum1(y * 0) == 0, residual <= tol)


def _rootfinder(name: str, residual: ca.Function, ny: int, nw: int, opts: Mapping[str, Any]) -> ca.Function:
    y, w = ca.SX.sym("y", ny), ca.SX.sym("w", nw)
    g = ca.Function(f"{name}_residual", [y, w], [residual(y, w)], ["y", "w"], ["g"])
    # a pose Newton cannot solve is reported by its status, never by an exception
    return ca.rootfinder(name, "fast_newton", g, {**opts, "error_on_fail": False})


def fk_kernel(closure: LoopClosure, config: SolverConfig | None = None) -> Kernel:
    """``<name>_fk: (q, x0, p, lower, upper, tol) -> (x, passive, residual,
    branch_margin, round_trip_error, cond1, limit_margin, status)``.

    Newton from x0; a pose whose residual is not within ``tol`` after the
    iterations is ``not_converged``; then the checks.
    """
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
        fn = ca.Function(f"{c.name}_fk", [q, x0, *shared], outs, ["q", "x0", *SHARED_INPUTS], list(names))
        return Kernel(fn, "fk", ("q", "x0"), names, key)

    key = ("fk_kernel", _options_key(opts))
    return closure.solvers.memo(key, build)


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
        return Kernel(fn, "ik", pose_inputs, names, key)

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
        return Kernel(fn, "jacobian", ("x", "q"), names, key)

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


def shared_values(kern: Kernel, model: Model, tolerance: float) -> list[np.ndarray]:
    """The values of the kernel's shared inputs for a model."""
    n_shared = kern.function.n_in() - len(kern.pose_inputs)
    lower, upper = limit_vectors(model)
    return [model.p, lower, upper, np.array([float(tolerance)])][:n_shared]


def bake(kern: Kernel, model: Model, tolerance: float, function: ca.Function | None = None) -> ca.Function:
    """The kernel with one model's parameters, limits and tolerance built in:
    a Function of the per-pose inputs only, same output names.

    function: the Function to wrap (default the kernel's own; the compiled
    library's twin for the compiled path).
    """
    fn = kern.function if function is None else function
    syms = [ca.MX.sym(n, fn.size_in(i)) for i, n in enumerate(kern.pose_inputs)]
    fixed = [ca.DM(v) for v in shared_values(kern, model, tolerance)]
    outs = fn(*syms, *fixed)
    outs = list(outs) if isinstance(outs, (list, tuple)) else [outs]
    return ca.Function(kern.name, syms, outs, list(kern.pose_inputs), list(kern.outputs))


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


def fast(closure: LoopClosure, key: tuple, function: Callable[[], ca.Function]) -> FastFunction:
    """A :class:`FastFunction` built once per closure and key."""
    return closure.solvers.memo(("fast",) + key, lambda: FastFunction(function()))
