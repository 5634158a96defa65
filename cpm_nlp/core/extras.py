"""Optional dependencies: import one, or say which extra installs it."""

from __future__ import annotations

import importlib
from typing import Any

from .errors import InputError


def require(module: str, extra: str, purpose: str) -> Any:
    """Import an optional dependency, or say how to install it."""
    try:
        return importlib.import_module(module)
    except ImportError:
        raise InputError(
            f"{purpose} needs the Python package '{module.split('.')[0]}', which is not installed",
            hint=f"pip install 'cpm_nlp[{extra}]'",
        ) from None
