"""Writing output files safely: the one helper every writer of cpm_nlp uses.

A file is written to a temporary name in its directory and renamed over the
target at the end, so a reader (or a crash) never sees half a file.  Before
anything is written:

* an output that is a file this command read (``solve p.yaml -o p.yaml``, a
  preset, the results file being plotted) is refused;
* only a regular file is ever replaced: a directory, a device, a FIFO ... is
  refused; a symbolic link is followed, and the file it points to is replaced
  (the link stays);
* a directory that cannot be written (``/proc``, read-only, missing) is an
  [`InputError`][cpm_nlp.core.errors.InputError] naming the file (exit 2), not a traceback.
"""

from __future__ import annotations

import os
import stat
import tempfile
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import Any

from ..core.errors import InputError
from .inputs import file_kind, resolve, same_file, was_read


def _refuse(path: str | os.PathLike, message: str, option: str) -> InputError:
    return InputError(message, file=str(path), path=(option,) if option else ())


def _check_target(path: str | os.PathLike, inputs: Iterable[str | os.PathLike], option: str) -> Path:
    """The real file to replace (symbolic links followed), after the checks above."""
    real = resolve(path)
    try:
        st = os.stat(real)
    except FileNotFoundError:
        st = None
    except OSError as exc:
        raise _refuse(path, f"cannot write here ({exc.strerror or exc.__class__.__name__})", option) from None
    if st is not None:
        if stat.S_ISDIR(st.st_mode):
            raise _refuse(path, "is a directory; expected a file name", option)
        if not stat.S_ISREG(st.st_mode):
            raise _refuse(path, f"is {file_kind(st.st_mode)}; only a regular file is replaced", option)
        if was_read(real) or any(same_file(real, f) for f in inputs):
            raise _refuse(path, "is an input of this command; refusing to overwrite it (give another file)", option)
    parent = real.parent
    if not parent.is_dir():
        raise _refuse(path, f"the output directory {parent} does not exist", option)
    return real


def check_output_path(path: str | None, inputs: Iterable[str | os.PathLike] = (), option: str = "-o") -> None:
    """Fail early (exit 2) if the output cannot be written there, before solving:
    the checks of the module docstring, and a trial file in its directory."""
    if path is None:
        return
    real = _check_target(path, inputs, option)
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{real.name}.", suffix=".check", dir=real.parent)
    except OSError as exc:
        raise _refuse(
            path, f"cannot write in {real.parent} ({exc.strerror or exc.__class__.__name__})", option
        ) from None
    os.close(fd)
    os.unlink(tmp)


def replace_atomically(
    path: str | os.PathLike,
    write: Callable[[str], Any],
    suffix: str = ".tmp",
    inputs: Iterable[str | os.PathLike] = (),
    option: str = "-o",
) -> None:
    """Create ``path`` all at once: ``write(temporary path)``, then rename.  The
    file gets the permissions of any new file (the umask), not mkstemp's 0600.
    Refused (an [`InputError`][cpm_nlp.core.errors.InputError], nothing written) as the module docstring says."""
    target = _check_target(path, inputs, option)
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{target.name}.", suffix=suffix, dir=target.parent)
    except OSError as exc:
        raise _refuse(
            path, f"cannot write in {target.parent} ({exc.strerror or exc.__class__.__name__})", option
        ) from None
    os.close(fd)
    try:
        write(tmp)
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)
        os.replace(tmp, target)
    except OSError as exc:
        raise _refuse(path, f"cannot write the file ({exc.strerror or exc.__class__.__name__})", option) from None
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)


def write_atomic(path: str, text: str, inputs: Iterable[str | os.PathLike] = (), option: str = "-o") -> None:
    """Write ``text`` to ``path`` all at once (temp file + rename)."""
    replace_atomically(path, lambda tmp: Path(tmp).write_text(text, encoding="utf-8"), inputs=inputs, option=option)
