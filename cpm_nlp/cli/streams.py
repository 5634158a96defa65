"""Where the C libraries' output goes while a command computes: nowhere (logged at debug
level), or, with ``--debug`` or a solver preset that asks for its log, on stdout (stderr with
``--json``, which keeps stdout for the one JSON document)."""

from __future__ import annotations

import argparse
import contextlib
import ctypes
import io
import logging
import os
import sys
from collections.abc import Iterator

TYPE_CHECKING = False  # typing itself is not imported at start-up; the annotations are strings
if TYPE_CHECKING:
    from typing import Any


def _flush_c_stdio() -> None:
    """Flush the C library's stdout buffer (IPOPT and CasADi print through it)."""
    with contextlib.suppress(OSError, AttributeError, TypeError):
        ctypes.CDLL(None).fflush(None)


@contextlib.contextmanager
def solver_output_to_stderr(active: bool) -> Iterator[None]:
    """While active: whatever is written to file descriptor 1 (IPOPT's log, its
    option documentation, CasADi's messages) goes to stderr, so that stdout
    carries exactly the one JSON document of ``--json``."""
    if not active:
        yield
        return
    try:
        sys.stdout.flush()
        saved = os.dup(1)
    except (OSError, ValueError):  # no file descriptor 1 (embedded use): nothing to protect
        yield
        return
    try:
        _flush_c_stdio()
        os.dup2(2, 1)
        yield
    finally:
        with contextlib.suppress(OSError, ValueError):
            sys.stdout.flush()
        _flush_c_stdio()
        os.dup2(saved, 1)
        os.close(saved)


@contextlib.contextmanager
def library_output_quiet() -> Iterator[None]:
    """While active: what the C libraries print (IPOPT through C stdio on file
    descriptor 1; CasADi's warnings and messages through Python's
    ``sys.stdout``/``sys.stderr``) is kept off the terminal, so that stderr
    carries only our one message.  CasADi's lines are logged at debug level
    (``-vv`` shows them); ``--debug`` or a solver preset that asks for its log
    (`solver_log_asked`) shows everything instead."""
    saved_py = sys.stdout, sys.stderr
    sink = io.StringIO()
    try:
        sys.stdout.flush()
        saved = os.dup(1)
        devnull = os.open(os.devnull, os.O_WRONLY)
    except (OSError, ValueError, AttributeError):  # no file descriptor 1 (embedded use): Python's streams only
        saved = devnull = None
    try:
        if saved is not None:
            _flush_c_stdio()
            os.dup2(devnull, 1)
        sys.stdout = sys.stderr = sink
        yield
    finally:
        sys.stdout, sys.stderr = saved_py
        if saved is not None:
            _flush_c_stdio()
            os.dup2(saved, 1)
            os.close(saved)
            os.close(devnull)
        for line in sink.getvalue().splitlines()[:100]:
            if line.strip():
                logging.getLogger("cpm_nlp.solver").debug("%s", line)


def solver_log_asked(solver: Any) -> bool:
    """Whether a solver configuration asks for the solver's own log (a preset
    such as configs/ipopt_verbose.yaml: an IPOPT print level, CasADi's timings)."""
    options = getattr(solver, "options", None) or {}
    level = options.get("ipopt.print_level", 0)
    return bool(
        (isinstance(level, int) and level > 0)
        or options.get("print_time") is True
        or options.get("verbose") is True
        or options.get("print_iteration") is True
    )


def solver_output(args: argparse.Namespace, solver: Any = None) -> contextlib.AbstractContextManager[None]:
    """Where the libraries' output goes while ``args``'s command computes: nowhere
    (`library_output_quiet`), or with ``--debug`` or a solver that asks for
    its log, on stdout (on stderr with ``--json``, which keeps stdout for the
    JSON document)."""
    if getattr(args, "debug", False) or solver_log_asked(solver):
        return solver_output_to_stderr(bool(getattr(args, "json", False)))
    return library_output_quiet()
