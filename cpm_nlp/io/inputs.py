"""Reading input files defensively, and remembering what was read.

Every file cpm_nlp reads on a user's behalf (problem files, presets, results
files, JSON results) goes through `read_input_text` or
`check_input_file`:

* only a regular file is read: a directory, a FIFO, a device (``/dev/zero``,
  ``/dev/stdin``), a socket is refused before it is opened, so nothing blocks
  or reads forever;
* at most `MAX_INPUT_BYTES` are read; a longer file is refused at once,
  without reading the rest (its size is checked before it is opened, so a
  16 GB sparse file is refused in microseconds).

The file named on the command line (a problem file, a mechanism file given to
``describe``) may also be a pipe (``allow_pipe``): standard input (``-``),
``<(cat p.yaml)`` (``/dev/fd/63``) or a named FIFO.  A pipe is read up to the
same limit (``limit + 1`` bytes at most, refused if over), without blocking
forever: a FIFO that no program writes to is refused at once, and a pipe
whose writer stays silent for `PIPE_IDLE_SECONDS` is refused then.  A
terminal or a device on standard input is refused like any special file.

The files read inside an `inputs_scope` (one CLI command) are recorded,
so that `cpm_nlp.io.atomic` can refuse to write an output over any of
them (``cpm-nlp solve p.yaml -o p.yaml``).
"""

from __future__ import annotations

import contextlib
import contextvars
import os
import select
import stat
import time
from collections.abc import Iterable, Iterator
from pathlib import Path

from ..core.errors import InputError

#: Largest input file read (bytes).  The largest shipped problem file is about
#: 3 KB; a results file of a large sweep is read by its own reader (Parquet)
#: or checked against `MAX_RESULTS_BYTES`.
MAX_INPUT_BYTES = 1 << 20  # 1 MiB
#: Largest CSV/JSON results file read back (``plot``, resume).
MAX_RESULTS_BYTES = 1 << 30  # 1 GiB
#: A pipe whose writer sends nothing for this long (seconds) is refused.
PIPE_IDLE_SECONDS = 10.0
#: The name that reads the problem from standard input (``cpm-nlp solve -``).
STDIN = "-"

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
    """Record the files read inside the block (see `was_read`)."""
    token = _READ.set(set())
    try:
        yield _READ.get()  # type: ignore[misc]
    finally:
        _READ.reset(token)


def record_read(path: str | os.PathLike) -> None:
    """Remember that ``path`` was read (no-op outside an `inputs_scope`)."""
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


def display_name(path: str | os.PathLike) -> str:
    """How messages name an input: ``<stdin>`` for ``-``, else the path as given."""
    return "<stdin>" if str(path) == STDIN else str(path)


def input_dir(path: str | os.PathLike) -> Path:
    """The folder that relative paths inside an input are resolved against:
    the file's own folder, or the working directory for standard input and
    for a pipe (``<(cat p.yaml)`` has no folder of its own)."""
    if str(path) == STDIN:
        return Path.cwd()
    with contextlib.suppress(OSError):
        if stat.S_ISFIFO(os.stat(path).st_mode):
            return Path.cwd()
    return resolve(path).parent


def check_input_file(
    path: str | os.PathLike, limit: int | None = MAX_INPUT_BYTES, allow_pipe: bool = False
) -> os.stat_result:
    """The ``stat`` of a regular, readable input file no larger than ``limit``
    (or of a pipe, with ``allow_pipe``); an [`InputError`][cpm_nlp.core.errors.InputError] naming the
    file otherwise (nothing is opened)."""
    try:
        st = os.stat(path)
    except FileNotFoundError:
        raise InputError("file not found", file=str(path)) from None
    except OSError as exc:
        raise InputError(f"cannot read the file ({exc.strerror or exc.__class__.__name__})", file=str(path)) from None
    if allow_pipe and stat.S_ISFIFO(st.st_mode):
        return st
    if not stat.S_ISREG(st.st_mode):
        what = file_kind(st.st_mode)
        raise InputError(f"expected a regular file, got {what}", file=str(path))
    if limit is not None and st.st_size > limit:
        raise InputError(f"the file is {_size(st.st_size)}; the limit is {_size(limit)}", file=str(path))
    return st


def read_input_bytes(
    path: str | os.PathLike, limit: int = MAX_INPUT_BYTES, record: bool = True, allow_pipe: bool = False
) -> bytes:
    """The bytes of a regular file of at most ``limit`` bytes (an [`InputError`][cpm_nlp.core.errors.InputError]
    otherwise).

    The size is checked before reading, and again while reading (a file that
    grows, or a special file in /proc that reports size 0), so at most
    ``limit + 1`` bytes are ever read.  ``record``: remember the file as an
    input (not for a results file that a sweep resumes and rewrites).
    ``allow_pipe``: ``path`` may also be ``-`` (standard input) or a pipe
    (see the module docstring)."""
    if allow_pipe and str(path) == STDIN:
        return _read_stdin(limit)
    st = check_input_file(path, limit, allow_pipe)
    if stat.S_ISFIFO(st.st_mode):
        data = _read_fifo(path, limit)
    else:
        try:
            with open(path, "rb") as fh:
                data = fh.read(limit + 1)
        except OSError as exc:
            raise InputError(
                f"cannot read the file ({exc.strerror or exc.__class__.__name__})", file=str(path)
            ) from None
        if len(data) > limit:
            raise InputError(f"the file is larger than the limit of {_size(limit)}", file=str(path))
    if record:
        record_read(path)
    return data


def read_input_text(
    path: str | os.PathLike, limit: int = MAX_INPUT_BYTES, record: bool = True, allow_pipe: bool = False
) -> str:
    """The UTF-8 text of a regular file of at most ``limit`` bytes (or of a pipe, with ``allow_pipe``)."""
    data = read_input_bytes(path, limit, record, allow_pipe)
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise InputError(
            f"expected UTF-8 text; byte {exc.start} is not ({exc.reason})", file=display_name(path)
        ) from None


def _read_stdin(limit: int) -> bytes:
    """Standard input: a regular file (redirected, ``< p.yaml``) or a pipe, up to ``limit`` bytes."""
    name = display_name(STDIN)
    try:
        st = os.fstat(0)
    except OSError:
        raise InputError("standard input is closed; pipe a problem file in", file=name) from None
    if stat.S_ISREG(st.st_mode):
        if st.st_size > limit:
            raise InputError(f"the file is {_size(st.st_size)}; the limit is {_size(limit)}", file=name)
    elif not stat.S_ISFIFO(st.st_mode):
        what = "a terminal" if os.isatty(0) else file_kind(st.st_mode)
        raise InputError(f"expected a pipe or a file on standard input, got {what}", file=name)
    return _read_fd(0, limit, name)


def _read_fifo(path: str | os.PathLike, limit: int) -> bytes:
    """A pipe named by a path: opened without blocking (opening a FIFO for
    reading waits for a writer otherwise); refused at once if nothing writes to it."""
    try:
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK)
    except OSError as exc:
        raise InputError(f"cannot read the pipe ({exc.strerror or exc.__class__.__name__})", file=str(path)) from None
    try:
        try:
            first = os.read(fd, limit + 1)
        except BlockingIOError:  # a writer is there, and has not written yet
            first = None
        if first == b"":  # no writer, nothing buffered: nothing will ever come (we do not wait for one)
            raise InputError("a named pipe that no program writes to; nothing to read", file=str(path))
        return _read_fd(fd, limit, str(path), first or b"")
    finally:
        os.close(fd)


def _read_fd(fd: int, limit: int, name: str, start: bytes = b"") -> bytes:
    """Read ``fd`` to its end, at most ``limit + 1`` bytes, waiting at most
    `PIPE_IDLE_SECONDS` for each piece (in steps of 0.2 s, so that
    Ctrl-C is seen)."""
    data = bytearray(start)
    idle_since = time.monotonic()
    while len(data) <= limit:
        ready, _, _ = select.select([fd], [], [], 0.2)
        if not ready:
            if time.monotonic() - idle_since > PIPE_IDLE_SECONDS:
                raise InputError(f"nothing was written to the pipe for {PIPE_IDLE_SECONDS:g} s", file=name)
            continue
        try:
            chunk = os.read(fd, min(1 << 16, limit + 1 - len(data)))
        except BlockingIOError:
            continue
        except OSError as exc:
            raise InputError(f"cannot read ({exc.strerror or exc.__class__.__name__})", file=name) from None
        if not chunk:
            break
        data += chunk
        idle_since = time.monotonic()
    if len(data) > limit:
        raise InputError(f"more than the limit of {_size(limit)} was written to the pipe", file=name)
    return bytes(data)


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


def unique_paths(paths: Iterable[str | os.PathLike]) -> list[Path]:
    """``paths`` without repeats: two paths of one file or folder (after symbolic links)
    count once, the first kept as given."""
    seen: set[Path] = set()
    out: list[Path] = []
    for p in paths:
        key = Path(p).resolve()
        if key not in seen:
            seen.add(key)
            out.append(Path(p))
    return out
