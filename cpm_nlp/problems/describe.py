"""What a problem kind takes and gives, for one mechanism, from the declared options.

``cpm-nlp describe KIND --mechanism NAME`` prints `kind_text`; the documentation's
reference page is `reference_markdown` (generated when the site is built), so the two
say the same and neither can drift from the code.  A kind's inputs may depend on the
mechanism (``input_options(model)``), so a model is built: from the mechanism section of
its first shipped problem file (``Mechanism.problem_files``), else from its defaults.
"""

from __future__ import annotations

import dataclasses
import logging
from collections import Counter
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ..core.errors import CpmError, InputError
from ..core.kind import ProblemKind
from ..core.mechanism import Mechanism
from ..core.model import Model
from ..core.options import Option
from ..core.outputs import Output
from ..core.schema import Either, ListOf, MappingOf, Named, Node, Quantity, Record, children, type_text
from ..core.units import DIMENSIONS, format_quantity
from ..mechanisms.registry import PluginError, build_model, mechanism_names, mechanism_type
from .reader import read_yaml
from .registry import kind_names, kind_origin, problem_kind
from .shipped import shipped_problems_dir

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class InputRow:
    """One input of a kind: name, unit (the display unit of its dimension, or its type),
    default ("required", "optional" or the value) and meaning (description and what it accepts);
    ``children``: the keys nested in it (a record's keys, a mapping's value, the alternatives
    of an input that takes one of several forms), from the declared schema."""

    name: str
    unit: str
    default: str
    meaning: str
    children: tuple[InputRow, ...] = ()

    def walk(self, depth: int = 0, prefix: str = "") -> list[tuple[int, str, InputRow]]:
        """This row and every nested one, depth first: (depth, dotted key path, row)."""
        path = f"{prefix}.{self.name}" if prefix else self.name
        out = [(depth, path, self)]
        for child in self.children:
            out += child.walk(depth + 1, path)
        return out


@dataclass(frozen=True)
class ValueRow:
    """One value a kind declares ([`Output`][cpm_nlp.core.result.Output]): name, the unit a
    result writes for it (SI, or what a matrix's rows and columns are), dimension, and what it
    is where that is not the value itself ("pz relative to home": an offset)."""

    name: str
    unit: str
    dimension: str
    meaning: str


def _value_rows(kind: ProblemKind, model: Model, names: tuple[str, ...]) -> tuple[ValueRow, ...]:
    """The kind's declared outputs as rows; none where it declares only their names."""
    try:
        outputs = kind.outputs(model)
    except NotImplementedError:
        return ()
    if tuple(o.name for o in outputs if not o.family and not o.when) != names:  # names it does not declare
        return ()
    return tuple(ValueRow(o.name, o.si, o.dimension, _value_meaning(o)) for o in outputs)


def _value_meaning(o: Output) -> str:
    """What a value is where that is not the value itself: an offset, a family's members, one
    that an input asks for."""
    what = [f"{o.refers_to} relative to home"] if o.role == "reference" else []
    what += [f"one per {o.per}"] if o.family else []
    what += [f"with {o.when}"] if o.when else []
    return "; ".join(what)


@dataclass(frozen=True)
class KindDescription:
    """A kind described for one mechanism; ``unsupported`` is the reason it does not apply
    (then ``inputs`` and ``values`` are empty)."""

    kind: str
    description: str
    origin: str
    mechanism: str
    model_from: str
    unsupported: str | None
    inputs: tuple[InputRow, ...]
    values: tuple[str, ...]
    #: the values with their units and dimensions, where the kind declares them (empty: names only)
    outputs: tuple[ValueRow, ...] = ()


def _mechanism_section(mech: Mechanism) -> tuple[dict[str, Any], str]:
    """The mechanism section of the first shipped problem file of ``mech`` (and its name),
    or the defaults."""
    for name in mech.problem_files:
        path = Path(name) if Path(name).is_absolute() else shipped_problems_dir() / name
        if path.is_file():
            section = read_yaml(path).get("mechanism")
            # the mechanism's own example: by type, or by its file (a mechanism described in a file)
            if isinstance(section, dict) and (section.get("type") == mech.name or "file" in section):
                shipped = not Path(name).is_absolute() or path.parent == shipped_problems_dir()
                return section, f"problems/{path.name}" if shipped else str(path)
    return {"type": mech.name}, "the declared defaults"


def reference_model(mechanism: str | Mechanism) -> tuple[Model, str]:
    """A model of ``mechanism`` (a name, or a declaration: a mechanism file, not registered) to
    describe kinds on, and where its values come from."""
    mech = mechanism if isinstance(mechanism, Mechanism) else mechanism_type(mechanism, path=("--mechanism",))
    section, source = _mechanism_section(mech)
    return build_model(mech, section.get("parameters"), section.get("limits")), source


def model_of(mech: Mechanism) -> tuple[Model | None, str]:
    """A model of a mechanism (registered or not: a mechanism file being described) from its
    first example's parameters, else its defaults; None, and why, when a parameter has neither."""
    section, source = _mechanism_section(mech)
    missing = [o.name for o in mech.parameters if o.required] if section.get("parameters") is None else []
    if missing:
        return None, f"no example and no default for {', '.join(missing)}"
    try:
        return mech.model(mech.closure(), section.get("parameters"), section.get("limits"), ("mechanism",)), source
    except InputError as exc:  # an example that does not build: the text says so, without values
        return None, f"the parameters of {source} do not build a model: {exc.message}"


def _unit(option: Any) -> str:
    return type_text(option)


def _default(option: Any) -> str:
    if option.required:
        return "required"
    value = option.default
    if value is None or (isinstance(value, Mapping) and not value):
        return "optional"
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(option, Quantity) and isinstance(value, (int, float)):
        return format_quantity(float(value), option.kinds[0])
    if isinstance(option, Node):
        return str(value)
    if isinstance(value, (int, float)) and option.kind in DIMENSIONS:
        return option.format_value(float(value))
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_default_item(option, v) for v in value) + "]"
    return str(value)


def _default_item(option: Option, value: Any) -> str:
    if isinstance(value, (int, float)) and not isinstance(value, bool) and option.kind in DIMENSIONS:
        return option.format_value(float(value))
    return str(value)


_SHAPES = {
    "list": "a list of ",
    "grid": "a list or {from, to, count} of ",
    "range": "a pair [low, high] of ",
}


def _meaning(option: Any) -> str:
    text = option.description.rstrip(".")
    if isinstance(option, Named):
        return f"{text}; a name ({', '.join(option.table)}) or a mapping"
    if isinstance(option, Quantity):
        return f"{text}; {option.expectation()}"
    if isinstance(option, Node):
        return text
    accepts = "" if option.kind == "str" else option.expectation()
    prefix = _SHAPES.get(option.shape, "")
    return f"{text}; {prefix}{accepts}" if accepts else text


def _form(alt: Any) -> str:
    """The label of one form of an input that takes one of several (true, a mapping, 'rigid' ...)."""
    if isinstance(alt, Record):
        return "{...}"
    if isinstance(alt, MappingOf):
        return f"{{<{alt.key_what}>: ...}}"
    if isinstance(alt, ListOf):
        return "[...]"
    if isinstance(alt, Node):
        return f"<{alt.kind}>"
    if alt.kind == "choice":
        return " | ".join(alt.choices)
    return {"bool": "true | false", "str": "<text>", "int": "<integer>"}.get(alt.kind, "<number>")


def _row(option: Any, name: str | None = None, slot: bool = False) -> InputRow:
    """The row of a declared input, with the rows nested in it; a ``slot`` (a form of an
    input, a mapping's value, a list's item) is not a key and has no default."""
    if isinstance(option, Either):  # its forms, by what each takes
        kids = [_row(alt, _form(alt), slot=True) for alt in option.alternatives]
    elif isinstance(option, (MappingOf, ListOf)):
        kids = [_row(c, slot=True) for c in children(option)]
    else:
        kids = [_row(c) for c in children(option)]
    default = "" if slot else _default(option)
    return InputRow(name or option.name, _unit(option), default, _meaning(option), tuple(kids))


def describe_kind(
    kind_name: str, mechanism: str | Mechanism, model: Model | None = None, source: str = ""
) -> KindDescription:
    """Describe ``kind_name`` on ``mechanism`` (a name, or a declaration read from a file and
    not registered; a model is built unless given)."""
    kind: ProblemKind = problem_kind(kind_name, path=("describe",))
    declared = mechanism if isinstance(mechanism, Mechanism) else None
    mechanism = mechanism.name if isinstance(mechanism, Mechanism) else mechanism
    if model is None:
        if declared is None:
            mechanism_type(mechanism, path=("--mechanism",))  # an unknown name, with a "did you mean"
        try:
            model, source = reference_model(declared or mechanism)
        except InputError as exc:  # a mechanism described without an example or defaults
            reason = f"no model to describe it on ({exc.message})"
            return KindDescription(kind.name, kind.description, kind_origin(kind.name), mechanism, "", reason, (), ())
    reason = kind.supports(model)
    if reason:
        return KindDescription(kind.name, kind.description, kind_origin(kind.name), mechanism, source, reason, (), ())
    origin = kind_origin(kind.name)
    try:
        options = kind.input_options(model)  # the declared options: the same the file reader validates against
        values = tuple(kind.output_names(model))
    except NotImplementedError:  # a plugin's kind that declares neither (it cannot be solved either)
        reason = "the kind declares no inputs and values (input_options, output_names)"
        return KindDescription(kind.name, kind.description, origin, mechanism, source, reason, (), ())
    except CpmError:
        raise
    except Exception as exc:
        raise PluginError(f"problem kind {kind.name!r} ({origin}): describing its inputs failed: {exc}") from exc
    rows = tuple(_row(o) for o in options)
    outputs = _value_rows(kind, model, values)
    return KindDescription(kind.name, kind.description, origin, mechanism, source, None, rows, values, outputs)


def kind_text(desc: KindDescription) -> str:
    """Plain text, as ``cpm-nlp describe KIND --mechanism NAME`` prints it."""
    lines = [f"{desc.kind}: {desc.description}", f"[{desc.origin}]", f"mechanism: {desc.mechanism}"]
    if desc.unsupported:
        lines.append(f"does not apply: {desc.unsupported}")
        return "\n".join(lines) + "\n"
    lines.append(f"(defaults and bounds for the model of {desc.model_from})")
    lines.append("inputs:")
    if not desc.inputs:
        lines.append("  (none)")
    for top in desc.inputs:
        for depth, _path, row in top.walk():
            pad = "  " * (depth + 1)
            width = max(14 - 2 * depth, 1)
            lines.append(f"{pad}{row.name:<{width}} [{row.unit}] {row.default}".rstrip())
            lines.append(f"{pad}{'':<{width}} {row.meaning}")
    lines.append("values:")
    for row in desc.outputs:
        what = f"; {row.meaning}" if row.meaning else ""
        lines.append(f"  {row.name:<14} [{row.unit}] {row.dimension}{what}")
    if not desc.outputs:
        lines.append("  " + (", ".join(desc.values) if desc.values else "(none)"))
    return "\n".join(lines) + "\n"


def _cell(text: str) -> str:
    return text.replace("|", "\\|").replace("\n", " ")


def _table(rows: list[tuple[str, InputRow]]) -> list[str]:
    out = ["| input | unit | default | meaning |", "| --- | --- | --- | --- |"]
    out += [f"| `{_cell(p)}` | {_cell(r.unit)} | {_cell(r.default)} | {_cell(r.meaning)} |" for p, r in rows]
    return out


def _schema_key(top: InputRow) -> tuple:
    """What identifies the schema nested in an input: its name and every nested row."""
    return (top.name, tuple((p, r.unit, r.default, r.meaning) for _d, p, r in top.walk()[1:]))


class _Nested:
    """The nested keys of the inputs on the reference page: a schema that several tables
    share (the hinges of six kinds on every mechanism) is one table the kinds link to; one
    that a single table has (a mechanism's load coordinates) stays in it."""

    def __init__(self, counts: Mapping[tuple, int]) -> None:
        self.counts = counts
        self.anchors: dict[tuple, str] = {}
        self.sections: list[str] = []

    def link(self, top: InputRow) -> str | None:
        """The anchor of the schema nested in ``top`` (its table added on first sight), or
        None when no other table has it."""
        key = _schema_key(top)
        if self.counts.get(key, 0) < 2:
            return None
        if key not in self.anchors:
            n = sum(1 for k in self.anchors if k[0] == top.name)
            anchor = (f"nested-{top.name}" + (f"-{n + 1}" if n else "")).replace("_", "-").lower()
            self.anchors[key] = anchor
            title = f"`{top.name}`" + (f" ({n + 1})" if n else "")
            rows = [(p, r) for _d, p, r in top.walk()[1:]]
            self.sections += [f"### {title} {{ #{anchor} }}", "", *_table(rows), ""]
        return self.anchors[key]


def kind_markdown(desc: KindDescription, level: int = 3, nested: _Nested | None = None) -> str:
    """One kind on one mechanism as a Markdown section (a table of inputs, the values); the
    keys nested in an input follow it, or, with ``nested``, are linked to its one table."""
    head = "#" * level
    out = [f"{head} `{desc.kind}` on `{desc.mechanism}`", ""]
    if desc.unsupported:
        return "\n".join(out + [f"Does not apply: {_cell(desc.unsupported)}.", ""])
    out.append(f"Defaults and bounds for the model of `{desc.model_from}`.")
    out.append("")
    if desc.inputs:
        rows: list[tuple[str, InputRow]] = []
        for top in desc.inputs:
            anchor = nested.link(top) if nested is not None and top.children else None
            if anchor is None:
                rows += [(p, r) for _d, p, r in top.walk()]
                continue
            link = f"{top.meaning}; its keys: [{top.name}](#{anchor})"
            rows.append((top.name, dataclasses.replace(top, meaning=link)))
        out += _table(rows)
    else:
        out.append("No inputs.")
    if desc.outputs:
        out += ["", "| value | unit | dimension | what |", "| --- | --- | --- | --- |"]
        out += [
            f"| `{_cell(r.name)}` | {_cell(r.unit)} | {_cell(r.dimension)} | {_cell(r.meaning)} |" for r in desc.outputs
        ]
        return "\n".join(out + [""])
    out += ["", "Values: " + (", ".join(f"`{v}`" for v in desc.values) if desc.values else "none") + ".", ""]
    return "\n".join(out)


def reference_markdown() -> str:
    """The reference page of every problem kind on every registered mechanism it applies to."""
    models = {}
    for name in mechanism_names():
        try:
            models[name] = reference_model(name)
        except InputError as exc:  # e.g. a mechanism file with required parameters and no shipped example of its own
            log.info("kinds are not described on %s: %s", name, exc.message)
    out = [
        "# Problem kinds",
        "",
        "Generated from the declared inputs (options and the nested schema of `cpm_nlp/core/schema.py`) "
        "when the site is built (`cpm_nlp/problems/describe.py`); `cpm-nlp describe KIND --mechanism NAME` "
        "prints the same. Units are the display units; a bare number is read in SI. A list makes a batch "
        "where the kind allows it. The keys nested in an input (hinges, materials, stress limits ...) are "
        "in [Nested inputs](#nested-inputs), each schema once.",
        "",
    ]
    descs = {k: [describe_kind(k, m, model, source) for m, (model, source) in models.items()] for k in kind_names()}
    counts = Counter(_schema_key(top) for ds in descs.values() for d in ds for top in d.inputs if top.children)
    nested = _Nested(counts)
    for kind_name, kind_descs in descs.items():
        kind = problem_kind(kind_name)
        out += [f"## `{kind_name}`", "", f"{_cell(kind.description)} ({kind_origin(kind_name)}).", ""]
        skipped = []
        for desc in kind_descs:
            if desc.unsupported:
                skipped.append(f"`{desc.mechanism}` ({_cell(desc.unsupported)})")
                continue
            out.append(kind_markdown(desc, nested=nested))
        if skipped:
            out += ["Does not apply to: " + "; ".join(skipped) + ".", ""]
    out += ["## Nested inputs", "", "The keys of the inputs that nest, by the kinds' tables that link here.", ""]
    return "\n".join(out + nested.sections)
