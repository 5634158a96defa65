"""CasADi Functions of one model, for composing into your own CasADi code.

``functions(model)`` gives the loop closures, forward and inverse kinematics
and the Jacobians of a model as named CasADi Functions with its parameters,
joint limits and tolerance built in::

    import casadi as ca
    import cpm_nlp as cn

    fns = cn.functions(cn.build_model("prs3", {"b": "47.91 mm", "L": "109.215 mm"}))
    q = ca.MX.sym("q", 3)
    x = fns.fk(q=q, x0=fns.x_home)["x"]          # differentiable (implicit function theorem)
    nlp = {"x": q, "f": -x[3], "g": x[2]}          # ... your own optimization

Every Function takes numbers (numpy arrays) or CasADi symbols: MX for
``fk`` and ``ik`` (they contain a rootfinder), SX or MX for the others.  The
FK is the kernel of every Newton FK in cpm_nlp: for a mechanism with a
closed-form IK, Newton on the task coordinates through the IK from the
first-order guess about ``x0``, else (or where that does not settle the pose)
Newton on Φ from ``x0`` (CasADi ``fast_newton``); its ``status`` output is 0
only where the pose passed every check of cpm_nlp (``cn.status_of(code)``
names it).  (Which formulation answered is reported by the solvers'
``PoseSolution.path`` and ``BatchResult.path(i)``; the Function keeps the
outputs it always had.)  Nothing here prints or keeps global
state; the Functions may be called from several threads.

Called on numbers (numpy arrays, lists, floats), ``fk``, ``ik`` and ``jacobian``
go straight to the kernel (`KernelFunction`): the compiled C through
ctypes where a C compiler is available (built once per machine, as
``backend="auto"`` of the solvers), else a CasADi FunctionBuffer, with the
buffers allocated once per thread -- the same numbers, to the bit, as CasADi's
own call, returned as numpy arrays of the shapes ``np.asarray`` gives the DMs
((n, 1) for a column vector), a 1 x 1 output as a float64.  Called on CasADi
types (MX, SX, DM) they are CasADi's own call.
"""

from __future__ import annotations

import functools
import threading
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import casadi as ca
import numpy as np

from ..core.compiled import BACKENDS, BoundNative, backend_function, native_loop
from ..core.errors import InputError, suggest
from ..core.fast_calls import BoundCall
from ..core.kernels import FK_OUTPUTS, Kernel, bake, fk_kernel, ik_kernel, jacobian_kernel, shared_values
from ..core.model import Model
from ..core.solver import SolverConfig


@dataclass(frozen=True)
class ModelFunctions:
    """The CasADi Functions of one model (its numbers built in).

    fk, ik and jacobian are `KernelFunction` s: called on numbers they return numpy
    arrays, straight from the (compiled) kernel; on CasADi types, CasADi's own call.

    Attributes
    ----------
    phi
        ``(x, q) -> phi``, the loop closures Φ (nx residuals);
    fk
        ``(q, x0) -> (x, passive, residual, branch_margin, round_trip_error, cond1,
        limit_margin, status)``;
    ik
        ``(t) -> (x, q, passive, reach, residual, ..., status)`` (closed form; mechanisms
        without one take ``(t, y0)`` and solve by Newton);
    jacobian
        ``(x, q) -> (J, J_inv, Phi_x, Phi_q)``;
    passive
        ``(x, q) -> j``, passive joint angles (None if the mechanism has none);
    x_home, q_home
        the home pose and joints (the default Newton guess).
    """

    model: Model
    phi: ca.Function
    fk: ca.Function
    ik: ca.Function
    jacobian: ca.Function
    passive: ca.Function | None
    x_home: np.ndarray
    q_home: np.ndarray


#: CasADi's own types: a call on any of them is CasADi's call (symbols, or DM in and DM out)
_CASADI_TYPES = (ca.MX, ca.SX, ca.DM)


class KernelFunction(ca.Function):
    """A kernel with one model's numbers built in (`bake`): a
    `casadi.Function` in every respect, whose call on numbers goes straight to the kernel.

    A call whose arguments are all numbers (numpy arrays, lists, floats; positional or by
    name, a missing name taking CasADi's default 0) evaluates the unbaked kernel with the
    model's shared inputs bound once: the compiled library's loop through ctypes (``backend``
    "auto": where a C compiler is available, built once per machine; "compiled"; or "map":
    CasADi's virtual machine), one set of buffers per thread.  The numbers are those of
    CasADi's own call to the bit (the compiled C is built without floating-point contraction,
    ``tests/io/test_embed.py`` compares them on many poses and threads); they come back as
    numpy arrays (copies) of the shape ``np.asarray`` gives the DM ((n, 1) for a column
    vector), a 1 x 1 output as a float64 (``int()`` and ``float()`` work as on the DM).
    Anything else -- an MX, SX or DM argument, a mixed call, a size CasADi would have to
    interpret -- is CasADi's own call.
    Unpickled, it is a plain `casadi.Function`.
    """

    def __init__(self, baked: ca.Function, kern: Kernel, model: Model, tolerance: float, backend: str) -> None:
        super().__init__(baked)
        self._kern, self._model, self._tolerance, self._backend = kern, model, float(tolerance), backend
        self._names_in = tuple(baked.name_in())
        self._names_out = tuple(baked.name_out())
        self._nnz_in = tuple(baked.nnz_in(i) for i in range(baked.n_in()))
        self._defaults = tuple(np.full(n, baked.default_in(i)) for i, n in enumerate(self._nnz_in))
        self._pick = tuple(kern.outputs.index(n) for n in self._names_out)
        shapes = [baked.size_out(i) for i in range(baked.n_out())]
        self._out = tuple((k, None if shape == (1, 1) else shape) for k, shape in zip(self._pick, shapes))
        dense = [kern.function.sparsity_in(i).is_dense() for i in range(kern.function.n_in())]
        dense += [kern.function.sparsity_out(k).is_dense() for k in self._pick]
        self._direct_ok = all(dense)  # the buffers hold dense values only
        self._lock = threading.Lock()
        self._local = threading.local()
        self._bound: BoundCall | BoundNative | None = None
        self.backend_used = ""  # "compiled" or "map", once a call on numbers has bound the kernel

    def __reduce__(self):
        return ca.Function.deserialize, (self.serialize(),)

    def _direct(self) -> BoundCall | BoundNative:
        """The kernel bound to the model's shared inputs (built on the first call on numbers)."""
        bound = self._bound
        if bound is None:
            with self._lock:
                if self._bound is None:
                    kern, closure = self._kern, self._model.closure
                    fn, used = backend_function(closure, kern, self._backend)
                    shared = shared_values(kern, self._model, self._tolerance)
                    defaults = [None] * len(kern.pose_inputs)
                    if used == "compiled":  # straight into the library's loop, through ctypes
                        self._bound = BoundNative(native_loop(closure, kern), shared, defaults)
                    else:
                        self._bound = BoundCall(fn, shared, defaults)
                    self.backend_used = used
                bound = self._bound
        return bound

    def _thread_state(self) -> tuple[list[np.ndarray], list[np.ndarray], Callable[[], int]]:
        """This thread's (pose input buffers, output buffers, evaluate -> nonzero on failure)."""
        state = getattr(self._local, "state", None)
        if state is None:
            bound = self._direct()
            buffers = bound.buffers()  # this thread's buffers, bound to the kernel once
            if isinstance(bound, BoundNative):
                run: Callable[[], int] = functools.partial(bound.loop.call, *buffers[0])
            else:
                buf, evaluate = buffers[0], buffers[1]

                def run() -> int:
                    evaluate()
                    return buf.ret()

            # the buffers last: kept alive with the raw addresses the ctypes arguments hold
            state = self._local.state = (buffers[2], buffers[3], run, buffers)
        return state[:3]

    def _numbers(self, args: tuple, kwargs: dict) -> list[np.ndarray] | None:
        """The per-pose inputs as flat float arrays, or None where CasADi's call must decide."""
        if not self._direct_ok or (args and kwargs):
            return None
        if args:
            if len(args) != len(self._nnz_in):
                return None
            items: Any = args
        else:
            if any(k not in self._names_in for k in kwargs):
                return None
            items = [kwargs.get(n, d) for n, d in zip(self._names_in, self._defaults)]
        values = []
        for item, nnz in zip(items, self._nnz_in):
            if isinstance(item, _CASADI_TYPES):
                return None
            try:
                arr = np.asarray(item, dtype=float)
            except (TypeError, ValueError):
                return None
            if arr.size != nnz or arr.ndim > 2 or (arr.ndim == 2 and min(arr.shape) != 1):
                return None  # a vector of the input's size, in any orientation; else CasADi's rules
            values.append(arr.reshape(-1))
        return values

    def __call__(self, *args: Any, **kwargs: Any):
        values = self._numbers(args, kwargs)
        if values is None:
            return super().__call__(*args, **kwargs)
        pose, outs, run = self._thread_state()
        for buffer, value in zip(pose, values):
            buffer[:] = value
        if run():
            raise RuntimeError(f"evaluation of {self.name()} failed")
        # a 1 x 1 output as a float64 (int() and float() work as on a 1 x 1 DM), others a copy in
        # the shape np.asarray gives the DM
        res = [outs[k][0] if shape is None else outs[k].reshape(shape, order="F").copy() for k, shape in self._out]
        if kwargs or not args:
            return dict(zip(self._names_out, res))
        return res[0] if len(res) == 1 else tuple(res)


def _with_parameters(fn: ca.Function, model: Model, name: str) -> ca.Function:
    """``fn(x, q, p)`` as ``name(x, q)`` with the model's p."""
    c = model.closure
    x, q = ca.SX.sym("x", c.nx), ca.SX.sym("q", c.nq)
    outs = fn(x, q, model.p)
    outs = list(outs) if isinstance(outs, (list, tuple)) else [outs]
    return ca.Function(name, [x, q], outs, ["x", "q"], fn.name_out())


def _kernel_function(kern: Kernel, model: Model, tolerance: float, backend: str, outputs=None) -> KernelFunction:
    return KernelFunction(bake(kern, model, tolerance, outputs=outputs), kern, model, tolerance, backend)


def model_functions(model: Model, solver: SolverConfig | None = None, *, backend: str = "auto") -> ModelFunctions:
    """The CasADi Functions of a model (``cpm_nlp.functions`` also takes a problem file).

    Parameters
    ----------
    solver
        tolerance and Newton options (abstol, abstolStep, max_iter) built into fk and ik
        (default: ``SolverConfig("newton")``).
    backend
        what evaluates ``fk``, ``ik`` and ``jacobian`` called on numbers (`KernelFunction`):
        "auto" (compiled C where a C compiler is available), "compiled" or "map".
    """
    if backend not in BACKENDS:
        raise InputError(
            f"unknown backend {backend!r}; expected one of: {', '.join(BACKENDS)}",
            path=("backend",),
            suggestions=suggest(str(backend), BACKENDS),
        )
    if not isinstance(model, Model):
        raise InputError(f"expected a Model or the path of a problem file, got {type(model).__name__}")
    config = solver or SolverConfig("newton")
    c = model.closure
    name = c.name
    return ModelFunctions(
        model=model,
        phi=_with_parameters(c.phi, model, f"{name}_phi"),
        fk=_kernel_function(fk_kernel(c, config), model, config.tolerance, backend, FK_OUTPUTS),
        ik=_kernel_function(ik_kernel(c, config), model, config.tolerance, backend),
        jacobian=_kernel_function(jacobian_kernel(c), model, config.tolerance, backend),
        passive=_with_parameters(c.passive, model, f"{name}_passive") if c.passive is not None else None,
        x_home=model.x_home.copy(),
        q_home=model.q_home.copy(),
    )
