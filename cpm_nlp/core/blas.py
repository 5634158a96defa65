"""One BLAS thread for the toolkit's small dense algebra (threadpoolctl).

The matrices here are small (a 63 x 63 KKT matrix of the six-axis hinge model,
6 x 6 compliances, 3 x 3 mass matrices).  OpenBLAS starts its threads for each
call all the same, and on a loaded machine that is most of the time: the six-axis
compliance took 20-28 ms per pose against 1.1 ms with one BLAS thread
(benchmarks/bench_compliance.py, ``six_axis_capped`` beside ``six_axis_compliance``).

* `cap_process` -- one BLAS thread for the whole process: the CLI and the
  sweep's worker processes call it (they run nothing but small algebra; parallel
  work is CasADi's thread pool and Dask's processes, not BLAS).  Called before
  any BLAS library is loaded (``cpm-nlp solve`` calls it first), it only sets the
  libraries' environment variables (`BLAS_THREAD_VARIABLES`), which they
  read when they load: threadpoolctl is not imported and costs nothing (issue 23,
  start-up); processes started from this one inherit the cap.
* `small_algebra` -- the same for a block of library code, for a program that
  calls the library (its own BLAS threads are restored after); cheap when the
  process is already capped; `one_blas_thread` decorates a function with it.

The limit is the process's (BLAS has no per-thread setting): two threads that
enter and leave `small_algebra` at once may leave it capped, which costs
nothing here.
"""

from __future__ import annotations

import contextlib
import functools
import os
import sys
import threading
from collections.abc import Callable, Iterator
from typing import Any, TypeVar

F = TypeVar("F", bound=Callable[..., Any])

#: the environment variables that set the threads of a BLAS library when it loads (OpenBLAS,
#: Intel MKL, BLIS, Apple's vecLib)
BLAS_THREAD_VARIABLES = ("OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "BLIS_NUM_THREADS", "VECLIB_MAXIMUM_THREADS")

#: "by_environment": capped before any BLAS library was loaded (each reads its variable)
_STATE: dict[str, Any] = {"controller": None, "seen": None, "capped": False, "by_environment": False}
_LOCK = threading.Lock()
#: the modules that load a BLAS library (numpy's, and scipy's own)
_BLAS_MODULES = ("numpy", "scipy.linalg")


def _loaded() -> tuple[str, ...]:
    return tuple(m for m in _BLAS_MODULES if m in sys.modules)


def _controller() -> Any:
    """threadpoolctl's controller of the BLAS libraries loaded so far (about 10 ms to
    make; made again when scipy's library was loaded since)."""
    with _LOCK:
        if _STATE["controller"] is None or _STATE["seen"] != _loaded():
            from threadpoolctl import ThreadpoolController

            _STATE["seen"] = _loaded()
            _STATE["controller"] = ThreadpoolController()
        return _STATE["controller"]


def cap_process() -> None:
    """One BLAS thread from now on, in this process.  Before any BLAS library is loaded:
    their environment variables, read when each loads (nothing imported).  Else, for the
    libraries loaded so far, through threadpoolctl (a solve that needs no scipy loads
    none; a library loaded later is capped by the next `small_algebra`)."""
    if _STATE["by_environment"]:
        return
    if not _loaded():
        for name in BLAS_THREAD_VARIABLES:
            os.environ[name] = "1"
        _STATE["by_environment"] = _STATE["capped"] = True
        return
    _controller().limit(limits=1, user_api="blas")
    _STATE["capped"] = True


@contextlib.contextmanager
def small_algebra() -> Iterator[None]:
    """One BLAS thread within the block (a no-op where `cap_process` ran)."""
    if _STATE["capped"]:
        if not _STATE["by_environment"] and _STATE["seen"] != _loaded():
            cap_process()
        yield
        return
    with _controller().limit(limits=1, user_api="blas"):
        yield


def one_blas_thread(fn: F) -> F:
    """``fn`` run within `small_algebra` (about 50 µs a call where the process
    is not capped: for functions that do many small solves, not for each solve)."""

    @functools.wraps(fn)
    def capped(*args: Any, **kwargs: Any) -> Any:
        with small_algebra():
            return fn(*args, **kwargs)

    return capped  # type: ignore[return-value]
