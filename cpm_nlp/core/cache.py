"""The user cache directory of cpm_nlp (compiled kernels, generated closures of mechanism
files): ``$CPM_NLP_CACHE``, else ``$XDG_CACHE_HOME/cpm_nlp``, else ``~/.cache/cpm_nlp``
(macOS ``~/Library/Caches/cpm_nlp``).  A module of its own, importing only ``os`` and
``pathlib``, so that a reader of the cache (`cpm_nlp.mechanisms.described.stored`, on the
start-up path of every solve) does not load the compiler's machinery
(`cpm_nlp.core.compiled`, which re-exports both functions)."""

from __future__ import annotations

import os
import sys
from pathlib import Path


def cache_dir() -> Path:
    """Where compiled libraries and generated closures are kept (created on demand)."""
    env = os.environ.get("CPM_NLP_CACHE")
    if env:
        return Path(env)
    if sys.platform == "darwin":
        return Path.home() / "Library" / "Caches" / "cpm_nlp"
    if os.name == "nt":  # pragma: no cover - not tested on Windows
        return Path(os.environ.get("LOCALAPPDATA", Path.home())) / "cpm_nlp" / "Cache"
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "cpm_nlp"


def cache_key() -> tuple[str | None, ...]:
    """The environment that decides `cache_dir` (``CPM_NLP_CACHE``, ``XDG_CACHE_HOME``,
    ``HOME``, ``LOCALAPPDATA``), as a key of the per-process memos: a changed variable (a test's
    fresh cache) means other libraries, and no path is built on every call."""
    env = os.environ
    return (env.get("CPM_NLP_CACHE"), env.get("XDG_CACHE_HOME"), env.get("HOME"), env.get("LOCALAPPDATA"))


__all__ = ("cache_dir", "cache_key")
