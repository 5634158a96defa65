"""Declared nested inputs: records, mappings, lists, alternatives and named tables,
built from `Option` leaves.

An `Option` declares one value (a quantity with its dimension and bounds, an
integer, a choice ...); it cannot nest.  The nodes here nest options, so that an input
such as ``hinges`` (name -> {joints, type, k, t, r, ...}) or ``stress_limit`` (true or
{sigma_allow, safety_factor, hinges, material}) is declared once and

* parsed by one walk: unknown keys refused with their key path and a "did you mean",
  quantities read in SI, choices checked, missing required keys named;
* described by the same declaration (``cpm-nlp describe`` and the documentation's
  reference page print the nested keys, their dimension, unit, default and choices).

Every node has the interface of an `Option` that `validate_mapping` uses
(``name``, ``description``, ``default``, ``required``, ``expectation()``, ``parse()``), so
a node may stand wherever an option does.  Two hooks, as in OpenMDAO's
``options.declare(check_valid=)``:

``check(value, path)``
    a validator of the parsed value (raises [`InputError`][cpm_nlp.core.errors.InputError]);
``convert(value, path)``
    turns the parsed value into what the algorithm consumes (a material, a model with
    limits ...); it runs after ``check``.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from .errors import InputError, suggest, unknown_key_error
from .options import REQUIRED, Option, validate_mapping
from .units import DIMENSIONS, parse_quantity

#: A validator or converter: ``(value, key path) -> None`` or the converted value.
Hook = Callable[[Any, tuple], Any]


def _type_name(value: Any) -> str:
    return type(value).__name__


class Node:
    """Base of the nested declarations (not instantiated itself)."""

    name: str
    description: str
    default: Any
    check: Hook | None
    convert: Hook | None
    #: an option's dimension or type; a node's kind of nesting ("record", "mapping" ...)
    kind = "node"
    #: nodes are single values to the data-file and sweep readers (never a grid)
    shape = "scalar"
    #: a missing essential node is named before unknown keys (see `validate_mapping`)
    essential = False

    @property
    def required(self) -> bool:
        return self.default is REQUIRED

    #: text after the description in the message of a missing required node
    missing = ""

    def missing_message(self, what: str) -> str:
        """The message for this node left out where it is required (its description says what it takes)."""
        return f"missing required {what} '{self.name}' ({self.description}){self.missing}"

    def absent(self, path: tuple) -> Any:
        """The value when the input does not give this key: the default, converted
        (``convert`` of an optional node takes its default too)."""
        if self.convert is not None and not self.required:
            return self.convert(self.default, path)
        return self.default

    def parse(self, value: Any, path: tuple) -> Any:
        """Validate ``value`` found at ``path``; return it parsed (SI), checked and converted."""
        out = self._parse(value, path)
        if self.check is not None:
            self.check(out, path)
        if self.convert is not None:
            out = self.convert(out, path)
        return out

    def _parse(self, value: Any, path: tuple) -> Any:  # pragma: no cover - abstract
        raise NotImplementedError

    def expectation(self) -> str:  # pragma: no cover - abstract
        raise NotImplementedError

    def accepts(self, _value: Any) -> bool:
        """Whether ``value`` has the Python shape this node reads (for `Either`)."""
        return True

    def type_text(self) -> str:
        """Short type of the node, as ``describe`` prints it."""
        return self.kind

    def children(self) -> list[Any]:
        """The declarations nested in this one (for ``describe``)."""
        return []


def accepts(decl: Any, value: Any) -> bool:
    """Whether ``decl`` (an option or a node) reads a value of this Python shape."""
    if isinstance(decl, Node):
        return decl.accepts(value)
    kind = decl.kind
    if kind == "bool":
        return isinstance(value, bool)
    if kind in ("str", "choice"):
        return isinstance(value, str)
    if isinstance(value, bool):
        return False
    if decl.shape in ("list", "range") and not isinstance(value, (list, tuple)):
        return False
    if kind == "int":
        return isinstance(value, (int, float))
    return isinstance(value, (int, float, str, list, tuple)) or (decl.shape == "grid" and isinstance(value, Mapping))


def type_text(decl: Any) -> str:
    """Short type of an option (its display unit or type) or a node."""
    if isinstance(decl, Node):
        return decl.type_text()
    if decl.kind in DIMENSIONS:
        return DIMENSIONS[decl.kind].display or "1"
    return decl.kind


def children(decl: Any) -> list[Any]:
    return decl.children() if isinstance(decl, Node) else []


@dataclass(frozen=True, eq=False)
class Record(Node):
    """A mapping of fixed keys, each an option or a node.

    ``sparse``: return only the keys given (no defaults filled in): an override merged
    key by key over declared defaults (a hinge over a mechanism's own).  ``what`` names
    a key in the messages ("unknown hinge key 'x'").
    """

    name: str
    description: str
    fields: tuple = ()
    default: Any = REQUIRED
    what: str = "key"
    sparse: bool = False
    mismatch: str = ""
    missing: str = ""
    #: the message of an unknown key, ``{key}`` in it (default: "unknown <what> 'x'; expected one of: ...")
    unknown: str = ""
    check: Hook | None = None
    convert: Hook | None = None
    kind = "record"

    def _parse(self, value: Any, path: tuple) -> Any:
        if self.mismatch and not isinstance(value, Mapping):
            raise InputError(f"{self.mismatch}, got {_type_name(value)} {value!r}", path=path)
        if self.unknown and isinstance(value, Mapping):
            names = {f.name for f in self.fields}
            for key in value:
                if key not in names:
                    raise InputError(self.unknown.format(key=repr(key)), path=path)
        if not self.sparse:
            return validate_mapping(value, self.fields, path, what=self.what)
        if not isinstance(value, Mapping):
            raise InputError(f"expected {self.expectation()}, got {_type_name(value)} {value!r}", path=path)
        by_name = {f.name: f for f in self.fields}
        out = {}
        for key, v in value.items():
            if key not in by_name:
                raise unknown_key_error(str(key), by_name, path, self.what)
            out[key] = None if v is None else by_name[key].parse(v, path + (key,))
        return out

    def expectation(self) -> str:
        return "a mapping {" + ", ".join(f.name for f in self.fields) + "}"

    def accepts(self, value: Any) -> bool:
        return isinstance(value, Mapping)

    def type_text(self) -> str:
        return "mapping"

    def children(self) -> list[Any]:
        return list(self.fields)


@dataclass(frozen=True, eq=False)
class MappingOf(Node):
    """A mapping of names to values of one declaration (hinges by name, a mass per coordinate).

    ``keys``: the names allowed (an unknown one gets a "did you mean"); empty: any name.
    ``nullable``: a name may map to null (kept as None: "remove this default").
    ``non_empty``: at least one name.  ``mismatch``: the message for a value that is
    not a mapping (default: what the node expects).
    """

    name: str
    description: str
    value: Any = None
    keys: tuple = ()
    key_what: str = "name"
    default: Any = REQUIRED
    nullable: bool = False
    non_empty: bool = False
    mismatch: str = ""
    missing: str = ""
    check: Hook | None = None
    convert: Hook | None = None
    kind = "mapping"

    def _parse(self, value: Any, path: tuple) -> Any:
        if not isinstance(value, Mapping) or (self.non_empty and not value):
            text = self.mismatch or f"expected {self.expectation()}"
            raise InputError(f"{text}, got {_type_name(value)} {value!r}", path=path)
        out = {}
        for key, v in value.items():
            if not isinstance(key, str):
                raise InputError(f"expected {self.key_what} names to be strings, got {key!r}", path=path)
            if self.keys and key not in self.keys:
                raise unknown_key_error(key, self.keys, path, self.key_what)
            if v is None and self.nullable:
                out[key] = None
                continue
            out[key] = self.value.parse(v, path + (key,))
        return out

    def expectation(self) -> str:
        names = f" ({', '.join(self.keys)})" if self.keys else ""
        return f"a mapping {self.key_what}{names} -> {_short(self.value)}"

    def accepts(self, value: Any) -> bool:
        return isinstance(value, Mapping)

    def type_text(self) -> str:
        return f"mapping {self.key_what} ->"

    def children(self) -> list[Any]:
        return [self.value]


@dataclass(frozen=True, eq=False)
class ListOf(Node):
    """A list of values of one declaration (a list of records)."""

    name: str
    description: str
    item: Any = None
    default: Any = REQUIRED
    min_len: int = 1
    max_len: int | None = None
    check: Hook | None = None
    convert: Hook | None = None
    kind = "list"

    def _parse(self, value: Any, path: tuple) -> Any:
        if not isinstance(value, (list, tuple)) or len(value) < self.min_len:
            raise InputError(f"expected {self.expectation()}, got {_type_name(value)} {value!r}", path=path)
        if self.max_len is not None and len(value) > self.max_len:
            raise InputError(f"expected at most {self.max_len} items, got {len(value)}", path=path)
        return [self.item.parse(v, path + (i,)) for i, v in enumerate(value)]

    def expectation(self) -> str:
        return f"a {'non-empty ' if self.min_len else ''}list of {_short(self.item)}"

    def accepts(self, value: Any) -> bool:
        return isinstance(value, (list, tuple))

    def type_text(self) -> str:
        return "list of"

    def children(self) -> list[Any]:
        return [self.item]


@dataclass(frozen=True, eq=False)
class Either(Node):
    """One of several declarations, told apart by the value's shape: a boolean, a
    string, a number, a mapping, a list (``true`` or a mapping; 'rigid' or a stiffness)."""

    name: str
    description: str
    alternatives: tuple = ()
    default: Any = REQUIRED
    mismatch: str = ""
    missing: str = ""
    essential: bool = False
    check: Hook | None = None
    convert: Hook | None = None
    kind = "either"

    def _parse(self, value: Any, path: tuple) -> Any:
        errors: list[InputError] = []
        for alt in self.alternatives:
            if not accepts(alt, value):
                continue
            try:
                return alt.parse(value, path)
            except InputError as exc:  # a string may be a choice or a quantity: try the next reading
                errors.append(exc)
        if errors:  # the reading with a "did you mean" ('rigd' -> 'rigid'), else the last one's message
            raise next((e for e in errors if e.suggestions), errors[-1])
        text = self.mismatch or f"expected {self.expectation()}"
        raise InputError(f"{text}, got {value!r}", path=path)

    def expectation(self) -> str:
        return " or ".join(_short(a) for a in self.alternatives)

    def accepts(self, value: Any) -> bool:
        return any(accepts(a, value) for a in self.alternatives)

    def type_text(self) -> str:
        return "one of"

    def children(self) -> list[Any]:
        return list(self.alternatives)


@dataclass(frozen=True, eq=False)
class Named(Node):
    """An entry of a table by its name, or one given inline as a record (a material:
    'Al 7075-T6' or {E: 72 GPa, nu: 0.33}).  ``what`` names an entry in the messages;
    ``inline_text`` shows the inline keys people mostly give; ``build`` makes the entry
    of the parsed inline record."""

    name: str
    description: str
    table: Mapping = None  # type: ignore[assignment]
    inline: Any = None
    build: Hook | None = None
    what: str = "entry"
    inline_text: str = ""
    default: Any = REQUIRED
    #: the type of an entry: a value of it is taken as parsed already
    entry: type | None = None
    check: Hook | None = None
    convert: Hook | None = None
    kind = "named"

    def _parse(self, value: Any, path: tuple) -> Any:
        if self.entry is not None and isinstance(value, self.entry):
            return value
        names = ", ".join(self.table)
        inline = self.inline_text or "{" + ", ".join(f.name for f in self.inline.fields) + "}"
        if isinstance(value, str):
            if value not in self.table:
                raise InputError(
                    f"unknown {self.what} {value!r}; expected one of: {names} or an inline mapping {inline}",
                    path=path,
                    suggestions=suggest(value, self.table),
                )
            return self.table[value]
        if not isinstance(value, Mapping):
            raise InputError(
                f"expected a {self.what} name ({names}) or an inline mapping {inline}, "
                f"got {_type_name(value)} {value!r}",
                path=path,
            )
        parsed = self.inline.parse(value, path)
        return parsed if self.build is None else self.build(parsed, path)

    def expectation(self) -> str:
        return f"a {self.what} name ({', '.join(self.table)}) or an inline mapping"

    def accepts(self, value: Any) -> bool:
        return isinstance(value, (str, Mapping))

    def type_text(self) -> str:
        return "name or mapping"

    def children(self) -> list[Any]:
        return list(self.inline.fields)


@dataclass(frozen=True, eq=False)
class Quantity(Node):
    """A quantity of one of several dimensions, whose dimension is only known where
    it is used (a hinge stiffness: N*m/rad on a rotation, N/m on a slide).  Checked
    here to be a quantity of one of them (positive when ``positive``); kept as written,
    so that the use reads it with its own dimension and bounds."""

    name: str
    description: str
    kinds: tuple = ()
    default: Any = REQUIRED
    positive: bool = False
    #: return the SI value (of the first dimension that reads it) instead of the value as written
    si: bool = False
    check: Hook | None = None
    convert: Hook | None = None
    kind = "quantity"

    def _parse(self, value: Any, path: tuple) -> Any:
        if isinstance(value, bool) or not isinstance(value, (int, float, str)):
            raise InputError(f"expected {self.expectation()}, got {_type_name(value)} {value!r}", path=path)
        first: InputError | None = None
        for kind in self.kinds:
            try:
                number = parse_quantity(value, kind, path)
            except InputError as exc:
                first = first or exc
                continue
            if self.positive and not number > 0:
                raise InputError(f"expected {self.expectation()}, got {value!r}", path=path)
            return number if self.si else value
        if len(self.kinds) == 1 and first is not None:
            raise first  # the quantity's own message ("'3 mm' is not a mass; expected a unit like ...")
        raise InputError(
            f"expected {self.expectation()}, got {value!r}", path=path, hint=first.message if first else None
        )

    def expectation(self) -> str:
        units = " or ".join(f"{DIMENSIONS[k].example!r}" for k in self.kinds)
        kinds = " or ".join(k.replace("_", " ") for k in self.kinds)
        return f"{'a positive ' if self.positive else 'a '}{kinds} ({units})"

    def accepts(self, value: Any) -> bool:
        return isinstance(value, (int, float, str)) and not isinstance(value, bool)

    def type_text(self) -> str:
        return " or ".join(DIMENSIONS[k].display or "1" for k in self.kinds)


def _short(decl: Any) -> str:
    """A short text of what a declaration takes, for the text of an enclosing one."""
    if isinstance(decl, Record):
        return decl.expectation()
    if isinstance(decl, Node):
        return decl.expectation()
    if decl.kind == "choice":
        return "one of " + ", ".join(repr(c) for c in decl.choices)
    if decl.kind in DIMENSIONS:
        return "a number" if decl.kind == "dimensionless" else f"a {decl.kind.replace('_', ' ')}"
    return {"int": "an integer", "bool": "true or false", "str": "a string"}.get(decl.kind, decl.kind)


def walk(decls: Sequence[Any], depth: int = 0) -> list[tuple[int, Any]]:
    """Every declaration and those nested in it, depth first, with its depth."""
    out: list[tuple[int, Any]] = []
    for d in decls:
        out.append((depth, d))
        out += walk(children(d), depth + 1)
    return out


def parse_with(decls: Sequence[Any], raw: Any, path: tuple, *, what: str = "input") -> dict[str, Any]:
    """The shared parse of a kind's inputs: `validate_mapping` over the declarations."""
    return validate_mapping(raw, decls, path, what=what)


__all__ = (
    "Either",
    "ListOf",
    "MappingOf",
    "Named",
    "Node",
    "Option",
    "Quantity",
    "Record",
    "accepts",
    "children",
    "parse_with",
    "type_text",
    "walk",
)
