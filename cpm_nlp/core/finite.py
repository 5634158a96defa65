"""Every number is finite, or there is a status.

Input files are untrusted: YAML reads a 1500-digit integer as a Python int
that no float can hold, which `check_numbers` refuses anywhere in a
parsed file, naming the key path, before anything is built from it.  YAML
reads ``.inf``, ``.nan`` and a 400-digit ``1111...1.5`` as non-finite floats:
the declared options (`cpm_nlp.core.options`, `cpm_nlp.core.units`)
refuse them with what they expect, and the expression language
(`cpm_nlp.mechanisms.described.expr`) refuses an operation that makes one.

On the way out, `nonfinite_paths` finds the non-finite numbers in the
values of a result, which [`cpm_nlp.problems.file.solve`][cpm_nlp.problems.file.solve] turns into the
failed status ``not_finite`` (never a printed ``inf`` that looks like an
answer); JSON output writes a non-finite number as ``null``
(`cpm_nlp.core.result.jsonable`).
"""

from __future__ import annotations

import math
import sys
from collections.abc import Iterator, Mapping
from typing import Any

import numpy as np

from .errors import InputError

#: the largest finite float (about 1.8e308)
LARGEST = sys.float_info.max


def too_large(value: int) -> str:
    """The message for an integer no float can hold."""
    digits = int(abs(value).bit_length() * math.log10(2)) + 1  # str() of a huge int is refused by Python
    return f"a number of about {digits} digits is too large (the largest is about {LARGEST:.3g})"


def check_numbers(data: Any, path: tuple = ()) -> None:
    """Refuse ([`InputError`][cpm_nlp.core.errors.InputError] naming the key path) an integer too large for a float
    anywhere in parsed file data.  A non-finite float (``.inf``, ``.nan``, ``1e999``) is
    refused by the key that reads it, whose message says what it expects there."""
    stack: list[tuple[Any, tuple]] = [(data, path)]
    while stack:
        node, where = stack.pop()
        if isinstance(node, Mapping):
            stack.extend((v, where + (str(k),)) for k, v in reversed(list(node.items())))
        elif isinstance(node, (list, tuple)):
            stack.extend((v, where + (i,)) for i, v in reversed(list(enumerate(node))))
        elif isinstance(node, int) and not isinstance(node, bool) and abs(node) > LARGEST:
            raise InputError(too_large(node), path=where)


def _numeric(value: Any) -> np.ndarray | None:
    """A list or tuple as one numeric array (numbers only, rectangular), whose first
    non-finite entry in C order is the one the walk meets first, at the same indices;
    None for anything else (a None, a string, a mapping, ragged rows, an object array)."""
    if isinstance(value, np.ndarray) or len(value) < 2:
        return None
    try:
        arr = np.asarray(value)
    except (ValueError, TypeError, OverflowError):
        return None
    return arr if arr.dtype.kind in "biufc" else None


def _walk(value: Any, name: str) -> Iterator[str]:
    if isinstance(value, Mapping):
        for k, v in value.items():
            yield from _walk(v, f"{name}.{k}")
    elif isinstance(value, np.ndarray) and value.dtype.kind in "fc":
        bad = np.argwhere(~np.isfinite(value))
        if bad.size:
            yield name + "".join(f"[{int(i)}]" for i in bad[0])
    elif isinstance(value, np.ndarray) and value.dtype.kind in "biu":
        return  # integers and booleans are finite
    elif isinstance(value, (list, tuple, np.ndarray)):
        numbers = _numeric(value)
        if numbers is not None:  # a list of numbers (100 000 values of a batch) at once
            yield from _walk(numbers, name)
            return
        for i, v in enumerate(value):
            yield from _walk(v, f"{name}[{i}]")
    elif isinstance(value, (float, np.floating, complex, np.complexfloating)) and not np.isfinite(value):
        yield name


def nonfinite_paths(values: Mapping[str, Any]) -> list[str]:
    """The names (with indices) of the values holding a non-finite number, the
    first such entry of each value."""
    out = []
    for key, value in values.items():
        first = next(_walk(value, str(key)), None)
        if first is not None:
            out.append(first)
    return out


def nulled(value: Any) -> Any:
    """``value`` with every non-finite number replaced by None (containers as lists)."""
    if isinstance(value, Mapping):
        return {k: nulled(v) for k, v in value.items()}
    if isinstance(value, np.ndarray):
        return nulled(value.tolist())
    if isinstance(value, (list, tuple)):
        return [nulled(v) for v in value]
    if isinstance(value, (float, np.floating, complex, np.complexfloating)) and not np.isfinite(value):
        return None
    return value
