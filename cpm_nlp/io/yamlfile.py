"""Reading YAML input files (problem files, presets, mechanism files).

Input is untrusted: a file is read only if it is a regular file of at most
:data:`~cpm_nlp.io.inputs.MAX_INPUT_BYTES`, and YAML's aliases and nesting
are bounded while the file is composed (before anything is built), so a
"billion laughs" file, a recursive alias or a deeply nested list is refused
in milliseconds.  A key given twice in one mapping is an error naming both
lines (YAML says keys are unique; PyYAML would keep the last silently).
"""

from __future__ import annotations

import os
import re
from typing import Any

import yaml
from yaml.composer import ComposerError
from yaml.constructor import ConstructorError
from yaml.nodes import MappingNode, ScalarNode, SequenceNode

from ..core.errors import InputError
from .inputs import read_input_text

#: Most aliases (``*name``) a file may use.
MAX_ALIASES = 100
#: Deepest nesting of lists and mappings, aliases expanded.
MAX_DEPTH = 32
#: Most values (scalars, lists, mappings) a file may hold, aliases expanded.
MAX_NODES = 100_000

_MERGE = "tag:yaml.org,2002:merge"


class _Loader(yaml.SafeLoader):
    """YAML with two YAML 1.2 readings that users expect:

    * ``1e-10`` is a float (PyYAML's YAML 1.1 wants ``1.0e-10`` and would hand
      the solver the string "1e-10"),
    * only true/false are booleans (``ipopt.sb: yes`` stays the string IPOPT wants),

    and the limits of the module docstring.
    """

    def __init__(self, stream: Any) -> None:
        super().__init__(stream)
        self._aliases = 0
        self._open: list[str] = []  # anchors whose node is being composed
        self._level = 0  # nesting of the node being composed
        self._sizes: dict[int, tuple[int, int]] = {}  # id(node) -> (values, depth), aliases expanded

    def compose_node(self, parent: Any, index: Any) -> Any:
        if self.check_event(yaml.AliasEvent):
            event = self.peek_event()
            self._aliases += 1
            if self._aliases > MAX_ALIASES:
                raise ComposerError(None, None, f"more than {MAX_ALIASES} aliases", event.start_mark)
            if event.anchor in self._open:
                raise ComposerError(
                    None, None, f"the alias *{event.anchor} refers to a value that contains it", event.start_mark
                )
            return super().compose_node(parent, index)
        event = self.peek_event()
        anchor = event.anchor
        if self._level > MAX_DEPTH:
            raise ComposerError(None, None, f"nested more than {MAX_DEPTH} levels deep", event.start_mark)
        if anchor is not None:
            self._open.append(anchor)
        self._level += 1
        try:
            node = super().compose_node(parent, index)
        finally:
            self._level -= 1
            if anchor is not None:
                self._open.pop()
        self._measure(node)
        return node

    def _measure(self, node: Any) -> None:
        """Values and depth of ``node`` with aliases expanded (its children are measured already)."""
        if isinstance(node, SequenceNode):
            children = node.value
        elif isinstance(node, MappingNode):
            children = [n for pair in node.value for n in pair]
        else:
            self._sizes[id(node)] = (1, 0)
            return
        size, depth = 1, 0
        for child in children:
            s, d = self._sizes.get(id(child), (1, 0))
            size += s
            depth = max(depth, d + 1)
        if size > MAX_NODES:
            raise ComposerError(None, None, f"more than {MAX_NODES} values once aliases are expanded", node.start_mark)
        if depth > MAX_DEPTH:
            raise ComposerError(None, None, f"nested more than {MAX_DEPTH} levels deep", node.start_mark)
        self._sizes[id(node)] = (size, depth)

    def construct_mapping(self, node: Any, deep: bool = False) -> Any:
        if isinstance(node, MappingNode):
            first: dict[Any, Any] = {}
            for key_node, _value in node.value:
                if not isinstance(key_node, ScalarNode) or key_node.tag == _MERGE:
                    continue
                key = self.construct_object(key_node)
                try:
                    earlier = first.get(key)
                except TypeError:  # an unhashable key: reported by PyYAML below
                    continue
                if earlier is not None:
                    raise ConstructorError(
                        None,
                        None,
                        f"duplicate key {str(key)[:40]!r} (first given on line {earlier.line + 1})",
                        key_node.start_mark,
                    )
                first[key] = key_node.start_mark
        return super().construct_mapping(node, deep)


_Loader.yaml_implicit_resolvers = {
    first: [(tag, rx) for tag, rx in resolvers if tag != "tag:yaml.org,2002:bool"]
    for first, resolvers in yaml.SafeLoader.yaml_implicit_resolvers.items()
}
_Loader.add_implicit_resolver(
    "tag:yaml.org,2002:bool", re.compile(r"^(?:true|True|TRUE|false|False|FALSE)$"), list("tTfF")
)
_Loader.add_implicit_resolver(
    "tag:yaml.org,2002:float",
    re.compile(r"^[-+]?(?:[0-9][0-9_]*)(?:\.[0-9_]*)?[eE][-+]?[0-9]+$"),
    list("-+0123456789"),
)


def _precheck(text: str) -> None:
    """Nesting and aliases counted on LibYAML's event stream (C, linear time)
    before PyYAML's scanner sees the text: its look-ahead for simple keys is
    quadratic in the nesting depth, seconds for ``[[[[...`` ten thousand deep."""
    loader = getattr(yaml, "CSafeLoader", None)
    if loader is None:  # PyYAML without LibYAML: the composer's limits still hold
        return
    depth = aliases = 0
    events = yaml.parse(text, Loader=loader)
    while True:
        try:
            event = next(events)
        except StopIteration:
            return
        except yaml.YAMLError:  # a syntax error: PyYAML reports it below, in its own words
            return
        if isinstance(event, (yaml.SequenceStartEvent, yaml.MappingStartEvent)):
            depth += 1
            if depth > MAX_DEPTH:
                raise ComposerError(None, None, f"nested more than {MAX_DEPTH} levels deep", event.start_mark)
        elif isinstance(event, (yaml.SequenceEndEvent, yaml.MappingEndEvent)):
            depth -= 1
        elif isinstance(event, yaml.AliasEvent):
            aliases += 1
            if aliases > MAX_ALIASES:
                raise ComposerError(None, None, f"more than {MAX_ALIASES} aliases", event.start_mark)


def load_yaml_text(text: str) -> Any:
    """Parse YAML text with the problem-file rules (see :class:`_Loader`)."""
    _precheck(text)
    return yaml.load(text, Loader=_Loader)  # noqa: S506 - a SafeLoader subclass


def read_yaml(path: str | os.PathLike) -> Any:
    """Parse a YAML file; errors name the file and the line."""
    text = read_input_text(path)
    try:
        return load_yaml_text(text)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f"line {mark.line + 1}, column {mark.column + 1}: " if mark is not None else ""
        problem = getattr(exc, "problem", None) or str(exc).splitlines()[0]
        raise InputError(f"malformed YAML: {where}{problem}", file=str(path)) from None
    except (ValueError, OverflowError, RecursionError) as exc:  # e.g. timestamps out of range
        raise InputError(f"malformed YAML: {str(exc)[:200]}", file=str(path)) from None
