"""Solver configuration and construction.

The method (IPOPT or Newton) is chosen here; problem and mechanism know
nothing about it.  CasADi options are checked against a declared allow-list
(`cpm_nlp.core.solver_options`: type, range, refused options) before
CasADi sees them, then merged over quiet defaults (``{"ipopt.tol": 1e-10}``
overrides just that key).  CasADi validates them once more; its rejection
becomes an [`InputError`][cpm_nlp.core.errors.InputError] naming the option.
"""

from __future__ import annotations

import functools
import logging
import re
import threading
import time
import weakref
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Any

import casadi as ca
import numpy as np

from .errors import InputError, suggest
from .solver_options import NEWTON_DEFAULTS, check_options, ipopt_rules

log = logging.getLogger(__name__)

METHODS = ("ipopt", "newton")

#: Quiet, tight defaults.  Residuals of the shipped models are lengths in m.
DEFAULT_OPTIONS: Mapping[str, Mapping[str, Any]] = MappingProxyType(
    {
        "ipopt": MappingProxyType(
            {
                "ipopt.print_level": 0,
                "ipopt.sb": "yes",
                "print_time": False,
                "ipopt.tol": 1e-12,
                "ipopt.max_iter": 200,
            }
        ),
        "newton": NEWTON_DEFAULTS,  # the Newton options' table (solver_options.NEWTON_TABLE)
    }
)


def run_nlp(solver: ca.Function, what: str, **args: Any) -> tuple[np.ndarray, bool, str, int]:
    """One call of an IPOPT ``nlpsol``: ``(x, converged, return status, iterations)``.
    An evaluation error inside the NLP (a NaN in a start far from home) is a failed
    start, reported as such, not a crash."""
    try:
        out = solver(**args)
    except RuntimeError as exc:
        log.debug("%s raised: %s", what, exc)
        return np.full(len(np.atleast_1d(args["x0"])), np.nan), False, f"solver error: {exc}".splitlines()[0], 0
    stats = solver.stats()
    z = np.asarray(out["x"]).ravel()
    ok = bool(stats.get("success", False)) and bool(np.all(np.isfinite(z)))
    return z, ok, str(stats.get("return_status", "")), int(stats.get("iter_count", 0))


@dataclass(frozen=True)
class SolverConfig:
    """How to solve.

    Attributes
    ----------
    method
        "ipopt" (default; an NLP with bounds that select the assembly branch) or "newton"
        (CasADi's Newton rootfinder, the fast path).
    options
        CasADi/IPOPT options, checked against the allow-list (`check_options`), over
        `DEFAULT_OPTIONS`.
    tolerance
        largest accepted loop-closure residual (max norm, in the model's residual unit, m for
        every shipped mechanism).
    preset
        name of the preset this came from, for reporting.
    """

    method: str = "ipopt"
    options: Mapping[str, Any] = field(default_factory=dict)
    tolerance: float = 1e-10
    preset: str | None = None

    def __post_init__(self) -> None:
        if self.method not in METHODS:
            raise InputError(
                f"unknown solver method '{self.method}'; expected one of: {', '.join(METHODS)}",
                path=("solver", "method"),
                suggestions=suggest(self.method, METHODS),
            )
        if not (self.tolerance > 0 and np.isfinite(self.tolerance)):
            raise InputError(f"expected a positive tolerance, got {self.tolerance!r}", path=("solver", "tolerance"))
        # every configuration, from a file or from Python, passes the allow-list: nothing refused reaches CasADi
        object.__setattr__(self, "options", check_options(self.method, self.options))

    def casadi_options(self) -> dict[str, Any]:
        merged = dict(DEFAULT_OPTIONS[self.method])
        merged.update(self.options)
        return merged

    def validate(self) -> None:
        """Check the options by type and range (`check_options`), then let
        CasADi check them (on a one-variable problem), so that a bad option is
        reported while the problem file is read."""
        check_options(self.method, self.options)
        items = tuple(sorted(self.options.items(), key=lambda kv: kv[0]))
        try:
            hash(items)
        except TypeError:  # a mapping or list as an option value: checked, not cached
            _validate_options.__wrapped__(self.method, items)
            return
        _validate_options(self.method, items)

    def key(self) -> tuple:
        """Hashable identity (for caching built solvers)."""
        return self._key

    @functools.cached_property
    def _key(self) -> tuple:  # computed once: the configuration is frozen
        return (self.method, repr(sorted(self.casadi_options().items(), key=lambda kv: kv[0])))

    @property
    def name(self) -> str:
        return self.method


def _trivial_solver(method: str, options: dict[str, Any]) -> None:
    y = ca.SX.sym("y")
    merged = dict(DEFAULT_OPTIONS[method])
    merged.update(options)
    if method == "ipopt":
        ca.nlpsol("check", "ipopt", {"x": y, "f": y**2}, merged)
    else:
        ca.rootfinder("check", "newton", ca.Function("g", [y], [y]), merged)


@functools.lru_cache(maxsize=64)
def _validate_options(method: str, items: tuple) -> None:
    options = dict(items)
    try:
        _trivial_solver(method, options)
    except RuntimeError as exc:
        error = translate_casadi_error(exc, options)
        if len(error.path) == 2:  # CasADi did not say which option: find it
            for key, value in options.items():
                try:
                    _trivial_solver(method, {key: value})
                except RuntimeError as inner:
                    lines = [ln.strip() for ln in str(inner).splitlines() if ln.strip()]
                    error = InputError(
                        f"CasADi rejected the value {value!r} of option '{key}' ({lines[-1] if lines else inner})",
                        path=("solver", "options", key),
                    )
                    break
        raise error from None


def translate_casadi_error(exc: Exception, options: Mapping[str, Any]) -> InputError:
    """Turn CasADi's rejection of an option into an [`InputError`][cpm_nlp.core.errors.InputError]."""
    text = str(exc)
    m = re.search(r"No such IPOPT option: (\S+)", text)
    if m:
        name = m.group(1)
        return InputError(
            f"IPOPT has no option '{name}'",
            path=("solver", "options", f"ipopt.{name}"),
            suggestions=[f"ipopt.{s}" for s in suggest(name, ipopt_rules()[0])],
            hint="see https://coin-or.github.io/Ipopt/OPTIONS.html",
        )
    m = re.search(r"Unknown option: (\S+)", text)
    if m:
        name = m.group(1)
        listed = re.findall(r'^> "([^"]+)"', text, flags=re.M)
        return InputError(
            f"CasADi has no option '{name}' for this solver",
            path=("solver", "options", name),
            suggestions=listed[:3] or suggest(name, options),
        )
    last = [ln.strip() for ln in text.splitlines() if ln.strip()]
    detail = last[-1] if last else text
    return InputError(f"CasADi rejected the solver options: {detail}", path=("solver", "options"))


class SquareSolver:
    """A built solver of a square system g(y; w) = 0 for y.

    Built once (per mechanism type and solver configuration) and reused for
    every call; calls from several threads are safe (CasADi checks out one
    memory block per call; the Newton path keeps one buffer per thread).
    """

    def __init__(
        self,
        name: str,
        residual: ca.Function,
        ny: int,
        nw: int,
        config: SolverConfig,
    ) -> None:
        self.name = name
        self.config = config
        y = ca.SX.sym("y", ny)
        w = ca.SX.sym("w", nw)
        g = residual(y, w)
        opts = config.casadi_options()
        try:
            if config.method == "ipopt":
                nlp = {"x": y, "p": w, "f": ca.SX(0), "g": g}
                self._fn = ca.nlpsol(name, "ipopt", nlp, opts)
            else:
                rf = ca.Function(f"{name}_residual", [y, w], [g], ["y", "w"], ["g"])
                self._fn = ca.rootfinder(name, "newton", rf, opts)
        except RuntimeError as exc:
            raise translate_casadi_error(exc, config.options) from exc
        self._ny = ny
        self._local = threading.local()

    def _buffer(self):
        state = getattr(self._local, "buffer", None)
        if state is None:
            state = self._local.buffer = self._fn.buffer()
        return state

    def solve(
        self, y0: np.ndarray, w: np.ndarray, lower: np.ndarray | None = None, upper: np.ndarray | None = None
    ) -> tuple[np.ndarray, bool, int, str, float]:
        """Return (y, converged, iterations, solver message, seconds)."""
        t0 = time.perf_counter()
        if self.config.method == "ipopt":
            args: dict[str, Any] = {"x0": y0, "p": w, "lbg": 0.0, "ubg": 0.0}
            if lower is not None:
                args["lbx"] = lower
            if upper is not None:
                args["ubx"] = upper
            try:
                out = self._fn(**args)
            except RuntimeError as exc:  # evaluation errors (NaN at the start point ...)
                log.debug("%s raised: %s", self.name, exc)
                return np.full(self._ny, np.nan), False, 0, f"solver error: {exc}".splitlines()[0], 0.0
            stats = self._fn.stats()
            y = np.asarray(out["x"]).ravel()
            ok = bool(stats.get("success", False))
            status = str(stats.get("return_status", ""))
            iters = int(stats.get("iter_count", 0))
        else:
            # a FunctionBuffer per thread: a few µs per call instead of ~30 µs
            buf, evaluate = self._buffer()
            y = np.empty(self._ny)
            args_ = [np.ascontiguousarray(y0, dtype=float), np.ascontiguousarray(w, dtype=float)]
            buf.set_arg(0, memoryview(args_[0]))
            buf.set_arg(1, memoryview(args_[1]))
            buf.set_res(0, memoryview(y))
            try:
                evaluate()
            except RuntimeError as exc:
                log.debug("%s raised: %s", self.name, exc)
                return np.full(self._ny, np.nan), False, 0, f"solver error: {exc}".splitlines()[0], 0.0
            if buf.ret() != 0:  # error_on_fail: the rootfinder gave up
                return np.full(self._ny, np.nan), False, 0, "solver error: the Newton iteration failed", 0.0
            stats = buf.stats()
            ok = bool(stats.get("success", False))
            status = str(stats.get("return_status", ""))
            iters = int(stats.get("iter_count", 0))
        seconds = time.perf_counter() - t0
        log.debug("%s: %s after %d iterations (%.3g s)", self.name, status, iters, seconds)
        return y, ok and bool(np.all(np.isfinite(y))), iters, status, seconds


class SolverCache:
    """Built solvers (and other built code) keyed by (purpose, configuration); thread-safe.

    A build (an IPOPT set-up, a C compilation) holds only the lock of its own
    key, so it never stalls threads that need other entries.
    """

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._solvers: dict[tuple, Any] = {}
        self._building: dict[tuple, threading.RLock] = {}

    def get(self, purpose: str, config: SolverConfig, build) -> SquareSolver:
        return self.memo((purpose,) + config.key(), build)

    def memo(self, key: tuple, build: Callable[[], Any]) -> Any:
        """The object built once for ``key`` (a built solver, a CasADi kernel,
        a loaded compiled library): code, never problem data."""
        with self._lock:
            built = self._solvers.get(key)
            if built is not None:
                return built
            key_lock = self._building.setdefault(key, threading.RLock())
        with key_lock:
            with self._lock:
                built = self._solvers.get(key)
            if built is None:
                built = build()
                with self._lock:
                    self._solvers[key] = built
                    self._building.pop(key, None)
            return built


#: each closure's built solvers and kernels (`solvers_of`), held here rather than on the
#: closure, and weakly keyed: freed with the closure.  Code, never problem data.
_BUILT: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()
_BUILT_LOCK = threading.Lock()


def solvers_of(closure: Any) -> SolverCache:
    """The cache of what is built from ``closure`` (solvers, CasADi kernels, compiled
    libraries), by the closure's identity; the closure itself stays a description."""
    with _BUILT_LOCK:
        cache = _BUILT.get(closure)
        if cache is None:
            cache = _BUILT[closure] = SolverCache()
        return cache
