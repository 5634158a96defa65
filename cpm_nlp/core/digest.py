"""SHA-256 digests without OpenSSL's start-up (issue 23, start-up).

``hashlib`` loads OpenSSL's ``_hashlib`` when it is imported, 2-3 ms of CPU on every
``cpm-nlp solve`` that hashes a mechanism file (its in-process memo and its cached
closure, `cpm_nlp.mechanisms.described.stored`).  CPython ships its own SHA-256 as a
small extension module (``_sha256`` up to Python 3.11, ``_sha2`` from 3.12): the same
digests, about 0.8 ms to load.  Where neither is there (another interpreter), hashlib's.
"""

from __future__ import annotations

from typing import Any


def _constructor() -> Any:
    try:  # Python >= 3.12
        from _sha2 import sha256
    except ImportError:
        try:  # Python <= 3.11
            from _sha256 import sha256
        except ImportError:  # pragma: no cover - an interpreter without CPython's modules
            from hashlib import sha256
    return sha256


sha256 = _constructor()


def sha256_hex(data: bytes) -> str:
    """The SHA-256 of ``data`` (hex), as ``hashlib.sha256(data).hexdigest()``."""
    return sha256(data).hexdigest()


__all__ = ("sha256", "sha256_hex")
