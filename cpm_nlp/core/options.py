"""Declared options: name, kind (a physical dimension or a plain type), bounds,
default and description -- validated the same way wherever they appear
(mechanism parameters, joint limits, problem inputs, solver settings).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from .errors import InputError, suggest, unknown_key_error
from .finite import LARGEST, too_large
from .units import DIMENSIONS, article, format_quantity, parse_quantity


class _Required:
    def __repr__(self) -> str:
        return "REQUIRED"


REQUIRED: Any = _Required()

#: Smallest nonzero magnitude (SI) of a declared option with a physical dimension: far
#: below any quantity of this toolkit, it keeps products and quotients of inputs (the
#: lever ratio L2 L4 / (L1 L3) of 1e-320 mm lengths) from underflowing to 0 or overflowing.
TINY = 1e-60

#: Largest number of points a grid may have (keeps a typo from exhausting memory).
MAX_GRID_POINTS = 1_000_000
#: Lists at least this long (a data file's columns) are checked column-wise (`Option._list`).
FAST_LIST = 256


@dataclass(frozen=True)
class Option:
    """One declared option.

    Attributes
    ----------
    kind
        a dimension of `cpm_nlp.core.units` ("length", "angle", ...), or one of "int", "bool",
        "str", "choice".
    shape
        "scalar"; "list" (a non-empty list of scalars); "grid" (a list, or a mapping ``{from,
        to, count}``); "range" (a pair ``[low, high]``).
    lower, upper
        bounds on the SI value; ``strict`` makes them exclusive.
    """

    name: str
    kind: str
    description: str
    default: Any = REQUIRED
    lower: float | None = None
    upper: float | None = None
    strict: bool = False
    choices: tuple[str, ...] = ()
    shape: str = "scalar"
    max_len: int | None = None
    #: a validator of the parsed value, ``(value, key path) -> None`` raising InputError
    check: Any = None

    #: a missing essential input is named before unknown keys (see `validate_mapping`)
    essential = False

    @property
    def required(self) -> bool:
        return self.default is REQUIRED

    def missing_message(self, what: str) -> str:
        """The message for this option left out where it is required."""
        return f"missing required {what} '{self.name}' ({self.description}; expected {self.expectation()})"

    def absent(self, _path: tuple) -> Any:
        """The value of the option when the input does not give it: its default."""
        return self.default

    def expectation(self) -> str:
        """Human text of what the option accepts."""
        if self.kind == "choice":
            return "one of " + ", ".join(f"'{c}'" for c in self.choices)
        if self.kind in ("int", "bool", "str"):
            base = {"int": "an integer", "bool": "true or false", "str": "a string"}[self.kind]
        else:
            dim = DIMENSIONS[self.kind]
            base = "a number" if self.kind == "dimensionless" else article(self.kind.replace("_", " "))
            if self.kind != "dimensionless":
                base += f" such as '{dim.example}'"
        bounds = self._bounds_text()
        return base + (f" {bounds}" if bounds else "")

    def format_value(self, v: float) -> str:
        if self.kind == "int":
            return f"{int(v)}"
        if self.kind in DIMENSIONS and self.kind != "dimensionless":
            return format_quantity(v, self.kind)
        return f"{v:g}"

    def _bounds_text(self) -> str:
        lo, hi = self.lower, self.upper
        if lo is None and hi is None:
            return ""
        left = "(" if self.strict else "["
        right = ")" if self.strict else "]"
        if lo is not None and hi is not None:
            return f"in {left}{self.format_value(lo)}, {self.format_value(hi)}{right}"
        if lo is not None:
            return f"{'>' if self.strict else '>='} {self.format_value(lo)}"
        return f"{'<' if self.strict else '<='} {self.format_value(hi)}"

    # -- validation -------------------------------------------------------
    def parse(self, value: Any, path: tuple) -> Any:
        """Validate ``value`` found at ``path``; return it in SI."""
        out = self._parse(value, path)
        if self.check is not None:
            self.check(out, path)
        return out

    def _parse(self, value: Any, path: tuple) -> Any:
        if self.shape == "scalar":
            return self._scalar(value, path)
        if self.shape == "list":
            return self._list(value, path)
        if self.shape == "range":
            values = self._list(value, path)
            if len(values) != 2:
                raise InputError(f"expected a pair [low, high] of {self.expectation()}, got {value!r}", path=path)
            if not values[0] < values[1]:
                raise InputError(
                    f"expected low < high, got [{self.format_value(values[0])}, {self.format_value(values[1])}]",
                    path=path,
                )
            return tuple(values)
        if self.shape == "grid":
            return self._grid(value, path)
        raise ValueError(f"unknown option shape {self.shape!r}")  # pragma: no cover - programming error

    def _list(self, value: Any, path: tuple) -> list:
        if not isinstance(value, (list, tuple)) or not value:
            raise InputError(f"expected a non-empty list of {self.expectation()}, got {value!r}", path=path)
        if self.max_len is not None and len(value) > self.max_len:
            raise InputError(f"expected at most {self.max_len} values, got {len(value)}", path=path)
        fast = self._list_of_floats(value)
        if fast is not None:
            return fast
        return [self._scalar(v, path + (i,)) for i, v in enumerate(value)]

    def _list_of_floats(self, value: list | tuple) -> list[float] | None:
        """A long list of bare floats of a physical dimension (a data file's column, 100 000
        values), checked column-wise with numpy: the checks of `_scalar` on every value
        at once.  None (check value by value) for a short list, another kind, or any value
        that is no float or fails a check: the per-value path then raises the same error,
        naming the same first value, as it always did."""
        if len(value) < FAST_LIST or self.kind not in DIMENSIONS or not all(type(v) is float for v in value):
            return None
        import numpy as np  # not at import: `cpm-nlp --help` loads this module without numpy

        number = np.array(value, dtype=float)
        bad = ~np.isfinite(number)  # parse_quantity: a bare number is finite
        lo, hi, size = self.lower, self.upper, np.abs(number)
        limit = DIMENSIONS[self.kind].limit
        if not (lo is not None and hi is not None and lo >= -limit and hi <= limit):
            bad |= size > limit
        if self.kind != "dimensionless":
            bad |= (number != 0) & (size < TINY)
        if lo is not None:
            bad |= (number <= lo) if self.strict else (number < lo)
        if hi is not None:
            bad |= (number >= hi) if self.strict else (number > hi)
        return None if bad.any() else number.tolist()

    def _grid(self, value: Any, path: tuple) -> list:
        if isinstance(value, Mapping):
            spec = {
                "from": Option("from", self.kind, "first value", lower=self.lower, upper=self.upper),
                "to": Option("to", self.kind, "last value", lower=self.lower, upper=self.upper),
                "count": Option("count", "int", "number of values", lower=1, upper=MAX_GRID_POINTS),
            }
            parsed = validate_mapping(value, spec.values(), path, what="grid key")
            n = parsed["count"]
            if n == 1:
                return [parsed["from"]]
            step = (parsed["to"] - parsed["from"]) / (n - 1)
            return [parsed["from"] + i * step for i in range(n)]
        if isinstance(value, (list, tuple)):
            return self._list(value, path)
        return self._scalar(value, path)

    def _scalar(self, value: Any, path: tuple) -> Any:
        kind = self.kind
        if kind == "bool":
            if not isinstance(value, bool):
                raise InputError(f"expected true or false, got {value!r}", path=path)
            return value
        if kind == "str":
            if not isinstance(value, str) or not value.strip():
                raise InputError(f"expected a non-empty string, got {value!r}", path=path)
            return value
        if kind == "choice":
            if not isinstance(value, str) or value not in self.choices:
                raise InputError(
                    f"expected {self.expectation()}, got {value!r}",
                    path=path,
                    suggestions=suggest(str(value), self.choices),
                )
            return value
        if kind == "int":
            return self._int(value, path)
        number = parse_quantity(value, kind, path)
        self._check_bounds(number, value, path)
        return number

    def _int(self, value: Any, path: tuple) -> int:
        if isinstance(value, bool) or not isinstance(value, int):
            if isinstance(value, float) and value.is_integer() and math.isfinite(value):
                value = int(value)
            else:
                raise InputError(f"expected {self.expectation()}, got {value!r}", path=path)
        if abs(value) > LARGEST:
            raise InputError(f"{too_large(value)}; expected {self.expectation()}", path=path)
        self._check_bounds(float(value), value, path)
        return int(value)

    def _check_bounds(self, number: float, raw: Any, path: tuple) -> None:
        lo, hi = self.lower, self.upper
        limit = DIMENSIONS[self.kind].limit if self.kind in DIMENSIONS else math.inf
        if abs(number) > limit and not (lo is not None and hi is not None and lo >= -limit and hi <= limit):
            raise InputError(
                f"{raw!r} is beyond the sanity limit of {self.format_value(limit)} for "
                f"{article(self.kind.replace('_', ' '))}; expected {self.expectation()}",
                path=path,
            )
        if number != 0 and abs(number) < TINY and self.kind in DIMENSIONS and self.kind != "dimensionless":
            raise InputError(
                f"{raw!r} is below the sanity limit of {self.format_value(TINY)} for a nonzero "
                f"{self.kind.replace('_', ' ')} (products of such numbers are 0 in floating point); "
                f"expected {self.expectation()}",
                path=path,
            )
        bad = (lo is not None and (number < lo or (self.strict and number == lo))) or (
            hi is not None and (number > hi or (self.strict and number == hi))
        )
        if not bad:
            return
        hint = None
        if isinstance(raw, (int, float)) and self.kind in DIMENSIONS and self.kind != "dimensionless":
            dim = DIMENSIONS[self.kind]
            hint = f"a bare number is read in SI ({dim.si}); did you mean '{raw:g} {dim.display}'?"
        raise InputError(f"expected {self.expectation()}, got {raw!r}", path=path, hint=hint)


def _essential_first(data: Mapping, by_name: Mapping[str, Any], path: tuple, what: str) -> None:
    """A missing essential input (what the problem is about: a synthesis's design) is named
    before keys unlike any declared one (the inputs of another kind); a key like a declared
    one is a typo, named first with a "did you mean"."""
    if any(isinstance(k, str) and k not in by_name and suggest(k, by_name) for k in data):
        return
    for opt in by_name.values():
        if opt.essential and opt.required and data.get(opt.name) is None:
            raise InputError(opt.missing_message(what), path=path)


def validate_mapping(
    data: Any,
    options: Sequence[Option] | Any,
    path: tuple,
    *,
    what: str = "key",
    allow_extra: bool = False,
) -> dict[str, Any]:
    """Validate a mapping against declared options; return SI values.

    Unknown keys are rejected with a "did you mean" (unless ``allow_extra``),
    missing required keys are named with their description, defaults filled in.
    """
    options = list(options)
    if data is None:
        data = {}
    if not isinstance(data, Mapping):
        raise InputError(f"expected a mapping of {what}s, got {type(data).__name__} {data!r}", path=path)
    by_name = {o.name: o for o in options}
    out: dict[str, Any] = {}
    _essential_first(data, by_name, path, what)
    for key in data:
        if not isinstance(key, str):
            raise InputError(f"expected {what} names to be strings, got {key!r}", path=path)
        if key not in by_name and not allow_extra:
            raise unknown_key_error(key, by_name, path, what)
    for opt in options:
        if opt.name in data and data[opt.name] is not None:
            out[opt.name] = opt.parse(data[opt.name], path + (opt.name,))
        elif opt.required:
            raise InputError(opt.missing_message(what), path=path)
        else:
            out[opt.name] = opt.absent(path + (opt.name,))
    return out
