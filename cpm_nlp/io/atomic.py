"""Writing output files safely: the one helper every writer of cpm_nlp uses.

A file is written to a temporary name in its directory and renamed over the
target at the end, so a reader (or a crash) never sees half a file.
"""

from __future__ import annotations

import os
import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import Any

from ..core.errors import InputError


def replace_atomically(path: str | os.PathLike, write: Callable[[str], Any], suffix: str = ".tmp") -> None:
    """Create ``path`` all at once: ``write(temporary path)``, then rename.  The
    file gets the permissions of any new file (the umask), not mkstemp's 0600."""
    target = Path(path)
    directory = target.parent if str(target.parent) else Path(".")
    fd, tmp = tempfile.mkstemp(prefix=f".{target.name}.", suffix=suffix, dir=directory)
    os.close(fd)
    try:
        write(tmp)
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)
        os.replace(tmp, target)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


def write_atomic(path: str, text: str) -> None:
    """Write ``text`` to ``path`` all at once (temp file + rename)."""
    replace_atomically(path, lambda tmp: Path(tmp).write_text(text, encoding="utf-8"))


def check_output_path(path: str | None) -> None:
    """Fail early (exit 2) if ``-o`` cannot be written, before solving."""
    if path is None:
        return
    target = Path(path)
    parent = target.parent if str(target.parent) else Path(".")
    if target.is_dir():
        raise InputError(f"output path {path} is a directory; expected a file name", path=("-o",))
    if not parent.is_dir():
        raise InputError(f"output directory {parent} does not exist", path=("-o",))
    if not os.access(parent, os.W_OK):
        raise InputError(f"output directory {parent} is not writable", path=("-o",))
