"""Progress of long loops (a batch solved pose by pose, the assembly-mode
search, the starts of a synthesis, the boxes of a certificate), for whoever
shows it.

Library code never prints: a loop calls `track` (or advances a
`task`) and the caller that wants to show progress (the CLI draws a
tqdm bar on a terminal) installs a callback with `reporting`.  Without
one, `track` costs one check per item.

Interruption: a long search returns to Python at least every
`INTERVAL` seconds in the calling thread (it runs its work in pieces of
about that size, or waits for worker threads with that timeout), so that a
Ctrl-C (``KeyboardInterrupt``) is seen at once; the work not yet started is
then cancelled.
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


class Task:
    """The progress of one long computation: `update` as it advances,
    `close` at the end.  Reports (what, done, total) to the installed
    callback about every `INTERVAL` seconds, and once at the end if it
    reported before (a computation shorter than `INTERVAL` shows nothing)."""

    def __init__(self, what: str, total: int) -> None:
        self.what, self.total = what, int(total)
        self.callback = _CALLBACK.get()
        self.last = time.monotonic()
        self.reported = False
        self.done = self.sent = 0

    def update(self, done: int) -> None:
        """``done`` items of ``total`` are finished."""
        self.done = done
        if self.callback is None:
            return
        now = time.monotonic()
        if now - self.last >= INTERVAL:
            self.callback(self.what, done, self.total)
            self.last, self.reported, self.sent = now, True, done

    def close(self) -> None:
        if self.callback is not None and self.reported and self.sent != self.done:
            self.callback(self.what, self.done, self.total)
        self.reported = False

    def __enter__(self) -> Task:
        return self

    def __exit__(self, kind: object, *rest: object) -> None:
        if kind is None:  # an interrupted or failed computation leaves its bar where it stopped
            self.close()


def task(what: str, total: int) -> Task:
    """A `Task` reporting to the callback installed here (use as a context manager)."""
    return Task(what, total)


def track(items: Iterable[T], what: str, total: int | None = None) -> Iterator[T]:
    """Yield ``items``, reporting (what, done, total) to the installed callback
    about every `INTERVAL` seconds and once at the end (if it reported before)."""
    if _CALLBACK.get() is None:
        yield from items
        return
    n = total if total is not None else (len(items) if isinstance(items, Sized) else 0)
    with task(what, n) as t:
        for done, item in enumerate(items, 1):
            yield item
            t.update(done)
