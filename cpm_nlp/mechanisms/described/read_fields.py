"""The checks every section of a mechanism file is read with: a mapping (with its allowed
keys), a list, a name, free text, a dimension, the type name, a size limit.  Each raises an
[`InputError`][cpm_nlp.core.errors.InputError] at the key path of the value it was given."""

from __future__ import annotations

import re
from collections.abc import Hashable, Mapping
from typing import Any

from ...core.errors import InputError, suggest, unknown_key_error
from .spec import DIMENSIONS


def as_mapping(value: Any, path: tuple, what: str, allowed: Mapping[str, str] | None = None) -> dict:
    """``value`` as a dict (``allowed``: the only keys it may have, with a "did you mean")."""
    if not isinstance(value, Mapping):
        raise InputError(f"expected {what}, got {type(value).__name__} {value!r:.60}", path=path)
    if allowed is not None:
        for key in value:
            if key not in allowed:
                raise unknown_key_error(str(key), allowed, path, "key")
    return dict(value)


def as_list(value: Any, path: tuple, what: str) -> list:
    if not isinstance(value, list):
        raise InputError(f"expected {what}, got {type(value).__name__} {value!r:.60}", path=path)
    return value


def as_name(value: Any, path: tuple, what: str) -> str:
    if not isinstance(value, str) or not value.isidentifier():
        raise InputError(f"expected {what} (a name such as 'alpha1'), got {value!r}", path=path)
    return value


#: longest mechanism type name: it names CasADi Functions, C functions and files (``<name>_kinematics.c``)
MAX_TYPE_NAME = 64
#: a name CasADi takes for a Function (a letter, then letters, digits and single underscores) and C takes
#: for an identifier: ASCII only
_TYPE_NAME = re.compile(r"[A-Za-z](?:_?[A-Za-z0-9])*")


def as_type_name(value: Any, path: tuple) -> str:
    """The mechanism type name: it becomes part of CasADi Function names, C identifiers and file names."""
    as_name(value, path, "a mechanism type name")
    if len(value) > MAX_TYPE_NAME or not _TYPE_NAME.fullmatch(value):
        raise InputError(
            f"expected a mechanism type name of at most {MAX_TYPE_NAME} ASCII letters, digits and single "
            f"underscores, starting with a letter and not ending with an underscore, got {value!r:.80}"
            + (f" ({len(value)} characters)" if len(value) > MAX_TYPE_NAME else ""),
            path=path,
        )
    return value


def as_text(value: Any, path: tuple) -> str:
    if value is None:
        return ""
    if not isinstance(value, str):
        raise InputError(f"expected free text, got {value!r:.60}", path=path)
    return value


def as_dimension(value: Any, path: tuple) -> str:
    if value not in DIMENSIONS:
        raise InputError(
            f"expected a dimension, one of: {', '.join(DIMENSIONS)}; got {value!r}",
            path=path,
            suggestions=suggest(str(value), DIMENSIONS),
        )
    return value


def as_bool(value: Any, path: tuple, what: str = "true or false") -> bool:
    if not isinstance(value, bool):
        raise InputError(f"expected {what}, got {value!r}", path=path)
    return value


def as_pair(value: Any, path: tuple, what: str = "[low, high]") -> tuple[Any, Any]:
    """A list of two items (``[low, high]``) as a tuple."""
    if not isinstance(value, list) or len(value) != 2:
        raise InputError(f"expected {what}, got {value!r}", path=path)
    return value[0], value[1]


def check_size(count: int, limit: int, what: str, path: tuple) -> None:
    if count > limit:
        raise InputError(
            f"{count} {what}; at most {limit} (a limit of cpm_nlp: see the mechanism files guide)", path=path
        )


def check_known(items: Any, known: Mapping | list, path: tuple, what: str = "coordinate") -> None:
    """Each (key, name) of ``items`` names one of ``known`` (the error at ``path`` + its key)."""
    for key, name in items:
        if not isinstance(name, Hashable) or name not in known:
            raise InputError(
                f"unknown {what} {name!r}; declared: {', '.join(known)}",
                path=path + (key,),
                suggestions=suggest(str(name), known),
            )
