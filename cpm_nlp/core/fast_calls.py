"""Fast numeric calls of CasADi Functions on numpy arrays: one
`casadi.FunctionBuffer` per thread (`FastFunction`), or one kernel bound to one
model's shared inputs (`BoundCall`)."""

from __future__ import annotations

import threading
from collections.abc import Callable, Sequence
from typing import Any

import casadi as ca
import numpy as np

from .model import LoopClosure
from .solver import solvers_of


class FastFunction:
    """Call a CasADi Function on numpy arrays with minimal overhead.

    Uses one `casadi.FunctionBuffer` per thread (a few µs per call
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

    def buffers(self) -> list:
        """This thread's state, built once: the evaluation (a FunctionBuffer and its evaluate,
        or the compiled loop's ctypes arguments), the inputs, the pose inputs, the outputs."""
        return self._state()

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
    """A `FastFunction` built once per closure and key."""
    return solvers_of(closure).memo(("fast",) + key, lambda: FastFunction(function()))
