"""Reading input files defensively, and remembering what was read.

Every file cpm_nlp reads on a user's behalf (problem files, presets, results
files, JSON results) goes through :func:`read_input_text` or
:func:`check_input_file`:

* only a regular file is read: a directory, a FIFO, a device (``/dev/zero``,
  ``/dev/stdin``), a socket is refused before it is opened, so nothing blocks
  or reads forever;
* at most :data:`MAX_INPUT_BYTES` are read; a longer file is refused at once,
  without reading the rest.

The files read inside an :func:`inputs_scope` (one CLI command) are recorded,
so that :mod:`cpm_nlp.io.atomic` can refuse to write an output over any of
them (``cpm-nlp solve p.yaml -o p.yaml``).
"""

from __future__ import annotations

import contextlib
import contextvars
import os
import stat
from collections.abc import Iterator
from pathlib import Path

from ..core.errors import InputError

#: Largest input file read (bytes).  The largest shipped problem file is about
#: 3 KB; a results file of a large sweep is read by its own reader (Parquet)
#: or checked against :data:`MAX_RESULTS_BYTES`.
MAX_INPUT_BYTES = 1 << 20  # 1 MiB
#: Largest CSV/JSON results file read back (``plot``, resume).
MAX_RESULTS_BYTES = 1 << 30  # 1 GiB

_FILE_KINDS = (
    (stat.S_ISDIR, "a directory"),
    (stat.S_ISFIFO, "a named pipe (FIFO)"),
    (stat.S_ISCHR, "a character device"),
    (stat.S_ISBLK, "a block device"),
    (stat.S_ISSOCK, "a socket"),
)

#: the set of files read in the current scope (None outside any scope)
_READ: contextvars.ContextVar[set[tuple[int, int]] | None] = contextvars.ContextVar("cpm_nlp_inputs", default=None)


def file_kind(mode: int) -> str:
    """``"a directory"``, ``"a character device"`` ... for a ``st_mode``."""
    for test, name in _FILE_KINDS:
        if test(mode):
            return name
    return "not a regular file"


@contextlib.contextmanager
def inputs_scope() -> Iterator[set[tuple[int, int]]]:
    """Record the files read inside the block (see :func:`was_read`)."""
    token = _READ.set(set())
    try:
        yield _READ.get()  # type: ignore[misc]
    finally:
        _READ.reset(token)


def record_read(path: str | os.PathLike) -> None:
    """Remember that ``path`` was read (no-op outside an :func:`inputs_scope`)."""
    seen = _READ.get()
    if seen is None:
        return
    try:
        st = os.stat(path)
    except OSError:
        return
    seen.add((st.st_dev, st.st_ino))


def was_read(path: str | os.PathLike) -> bool:
    """Whether ``path`` (after symbolic links) is a file read in this scope."""
    seen = _READ.get()
    if not seen:
        return False
    try:
        st = os.stat(path)
    except OSError:
        return False
    return (st.st_dev, st.st_ino) in seen


def check_input_file(path: str | os.PathLike, limit: int | None = MAX_INPUT_BYTES) -> os.stat_result:
    """The ``stat`` of a regular, readable input file no larger than ``limit``;
    an :class:`InputError` naming the file otherwise (nothing is opened)."""
    try:
        st = os.stat(path)
    except FileNotFoundError:
        raise InputError("file not found", file=str(path)) from None
    except OSError as exc:
        raise InputError(f"cannot read the file ({exc.strerror or exc.__class__.__name__})", file=str(path)) from None
    if not stat.S_ISREG(st.st_mode):
        what = file_kind(st.st_mode)
        raise InputError(f"expected a regular file, got {what}", file=str(path))
    if limit is not None and st.st_size > limit:
        raise InputError(f"the file is {_size(st.st_size)}; the limit is {_size(limit)}", file=str(path))
    return st


def read_input_bytes(path: str | os.PathLike, limit: int = MAX_INPUT_BYTES, record: bool = True) -> bytes:
    """The bytes of a regular file of at most ``limit`` bytes (an :class:`InputError` otherwise).

    The size is checked before reading, and again while reading (a file that
    grows, or a special file in /proc that reports size 0), so at most
    ``limit + 1`` bytes are ever read.  ``record``: remember the file as an
    input (not for a results file that a sweep resumes and rewrites)."""
    check_input_file(path, limit)
    try:
        with open(path, "rb") as fh:
            data = fh.read(limit + 1)
    except OSError as exc:
        raise InputError(f"cannot read the file ({exc.strerror or exc.__class__.__name__})", file=str(path)) from None
    if len(data) > limit:
        raise InputError(f"the file is larger than the limit of {_size(limit)}", file=str(path))
    if record:
        record_read(path)
    return data


def read_input_text(path: str | os.PathLike, limit: int = MAX_INPUT_BYTES, record: bool = True) -> str:
    """The UTF-8 text of a regular file of at most ``limit`` bytes."""
    data = read_input_bytes(path, limit, record)
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise InputError(f"expected UTF-8 text; byte {exc.start} is not ({exc.reason})", file=str(path)) from None


def _size(n: int) -> str:
    for unit, factor in (("GiB", 1 << 30), ("MiB", 1 << 20), ("KiB", 1 << 10)):
        if n >= factor:
            return f"{n / factor:.3g} {unit}"
    return f"{n} bytes"


def same_file(a: str | os.PathLike, b: str | os.PathLike) -> bool:
    """Whether two paths name the same existing file (after symbolic links)."""
    try:
        return os.path.samefile(a, b)
    except OSError:
        return False


def resolve(path: str | os.PathLike) -> Path:
    """``path`` with symbolic links followed (also a dangling one's target)."""
    return Path(os.path.realpath(path))
