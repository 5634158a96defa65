"""Progress of long loops (a batch solved pose by pose), for whoever shows it.

Library code never prints: a loop calls :func:`track` and the caller that
wants to show progress (the CLI, on a terminal) installs a callback with
:func:`reporting`.  Without one, :func:`track` costs one check per item.
"""

from __future__ import annotations

import contextlib
import contextvars
import time
from collections.abc import Callable, Iterable, Iterator, Sized
from typing import TypeVar

T = TypeVar("T")

#: called with (what, done, total)
Callback = Callable[[str, int, int], None]

_CALLBACK: contextvars.ContextVar[Callback | None] = contextvars.ContextVar("cpm_nlp_progress", default=None)

#: a loop reports at most this often (seconds), and only if it is longer than one report
INTERVAL = 0.2


@contextlib.contextmanager
def reporting(callback: Callback | None) -> Iterator[None]:
    """Send the progress of loops run inside the block to ``callback``."""
    token = _CALLBACK.set(callback)
    try:
        yield
    finally:
        _CALLBACK.reset(token)


def track(items: Iterable[T], what: str, total: int | None = None) -> Iterator[T]:
    """Yield ``items``, reporting (what, done, total) to the installed callback
    about every :data:`INTERVAL` seconds and once at the end (if it reported before)."""
    callback = _CALLBACK.get()
    if callback is None:
        yield from items
        return
    n = total if total is not None else (len(items) if isinstance(items, Sized) else 0)
    last = time.monotonic()
    reported = False
    done = 0
    for item in items:
        yield item
        done += 1
        now = time.monotonic()
        if now - last >= INTERVAL:
            callback(what, done, n)
            last, reported = now, True
    if reported:
        callback(what, done, n)
