"""Where the shipped problem files and solver presets are.

They live at the top of the repository (``problems/``, ``configs/``).  A wheel or
sdist install carries them as the package data ``cpm_nlp/data/problems`` and
``cpm_nlp/data/configs`` (setup.py maps them there); an editable install or a
checkout reads them from the repository.  This module is the one place that
knows both.
"""

from __future__ import annotations

import os
import shutil
from importlib import resources
from pathlib import Path

from ..core.errors import InputError
from ..io.atomic import replace_atomically

#: the repository root, for a checkout or an editable install
_CHECKOUT = Path(__file__).resolve().parents[2]


def _shipped(name: str) -> Path:
    installed = Path(str(resources.files("cpm_nlp.data") / name))
    if installed.is_dir():
        return installed
    return _CHECKOUT / name


def shipped_problems_dir() -> Path:
    """The directory of the problem files shipped with cpm_nlp."""
    return _shipped("problems")


def shipped_configs_dir() -> Path:
    """The directory of the solver presets shipped with cpm_nlp."""
    return _shipped("configs")


def example_files() -> list[tuple[Path, Path]]:
    """(source, path relative to an examples directory) of every shipped problem
    file (``problems/...``) and solver preset (``configs/...``)."""
    out: list[tuple[Path, Path]] = []
    for name, root in (("problems", shipped_problems_dir()), ("configs", shipped_configs_dir())):
        if root.is_dir():
            out += [(f, Path(name) / f.relative_to(root)) for f in sorted(root.rglob("*.yaml"))]
    return out


def copy_examples(dest: str | os.PathLike, force: bool = False) -> list[Path]:
    """Copy the shipped problem files and presets into ``dest/problems`` and
    ``dest/configs`` (the layout ``cpm-nlp`` looks in) for the user to edit.
    Refuses ([`InputError`][cpm_nlp.core.errors.InputError], nothing copied) to overwrite an existing file
    unless ``force``, or to write anything but a regular file; returns the paths
    written."""
    target = Path(dest)
    files = example_files()
    if not files:
        raise InputError("no shipped problem files found; the installation is incomplete (reinstall cpm_nlp)")
    if target.exists() and not target.is_dir():
        raise InputError(f"{target} exists and is not a directory; expected a directory to copy the examples into")
    planned = [(src, target / rel) for src, rel in files]
    clash = [out for _, out in planned if out.exists() or out.is_symlink()]
    odd = [out for out in clash if out.is_symlink() or not out.is_file()]
    if odd:
        raise InputError(f"{odd[0]} exists and is not a regular file; not replacing it")
    if clash and not force:
        more = f" and {len(clash) - 1} more" if len(clash) > 1 else ""
        raise InputError(f"{clash[0]}{more} already exist; not overwriting them", hint="use --force to overwrite")
    try:
        for _, out in planned:
            out.parent.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise InputError(f"cannot create {exc.filename or target}: {exc.strerror}") from None
    written = []
    for src, out in planned:
        try:
            replace_atomically(out, lambda tmp, src=src: shutil.copyfile(src, tmp))
        except OSError as exc:
            raise InputError(f"cannot write {out}: {exc.strerror}") from None
        written.append(out)
    return written
