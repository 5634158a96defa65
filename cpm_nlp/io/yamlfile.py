"""Reading YAML input files (problem files, presets, mechanism files).

Input is untrusted: a file is read only if it is a regular file of at most
`MAX_INPUT_BYTES`, and YAML's aliases and nesting
are bounded while the file is composed (before anything is built), so a
"billion laughs" file, a recursive alias or a deeply nested list is refused
in milliseconds.  A key given twice in one mapping is an error naming both
lines (YAML says keys are unique; PyYAML would keep the last silently).
Each of these errors names its line and column and, where it is known, the
key path of the value at fault (``mechanism.parameters.b``).
"""

from __future__ import annotations

import os
import re
from collections.abc import Iterator
from typing import Any

import yaml
from yaml.composer import ComposerError
from yaml.constructor import ConstructorError
from yaml.nodes import MappingNode, ScalarNode, SequenceNode

from ..core.errors import InputError
from .inputs import display_name, read_input_text

#: Most aliases (``*name``) a file may use.
MAX_ALIASES = 100
#: Deepest nesting of lists and mappings, aliases expanded.
MAX_DEPTH = 32
#: Most values (scalars, lists, mappings) a file may hold, aliases expanded.
MAX_NODES = 100_000

_MERGE = "tag:yaml.org,2002:merge"


def _at(error: yaml.YAMLError, path: list | tuple) -> yaml.YAMLError:
    """``error`` with the key path of the value at fault (read by `parse_yaml`)."""
    error.key_path = tuple(path)  # type: ignore[attr-defined]
    return error


class _UniqueKeys:
    """A key given twice in one mapping is an error naming both lines and the
    key path (``self._paths``: id(mapping node) -> its key path)."""

    _paths: dict[int, tuple]

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
                    raise _at(
                        ConstructorError(
                            None,
                            None,
                            f"duplicate key {str(key)[:40]!r} (first given on line {earlier.line + 1})",
                            key_node.start_mark,
                        ),
                        self._paths.get(id(node), ()) + (str(key)[:40],),
                    )
                first[key] = key_node.start_mark
        return super().construct_mapping(node, deep)


class _Loader(_UniqueKeys, yaml.SafeLoader):
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
        self._path: list[Any] = []  # key path of the node being composed
        self._paths: dict[int, tuple] = {}  # id(mapping node) -> its key path (for duplicate keys)

    def compose_node(self, parent: Any, index: Any) -> Any:
        if isinstance(index, int) and not isinstance(index, bool):  # an item of a list
            self._path.append(index)
        elif isinstance(index, ScalarNode):  # the value of a key
            self._path.append(index.value[:40])
        elif parent is not None:  # a key (complex keys are rare): its mapping's path
            self._path.append("<key>")
        try:
            return self._compose_node(parent, index)
        finally:
            if parent is not None or index is not None:
                self._path.pop()

    def _compose_node(self, parent: Any, index: Any) -> Any:
        if self.check_event(yaml.AliasEvent):
            event = self.peek_event()
            self._aliases += 1
            if self._aliases > MAX_ALIASES:
                raise _at(ComposerError(None, None, f"more than {MAX_ALIASES} aliases", event.start_mark), self._path)
            if event.anchor in self._open:
                raise _at(
                    ComposerError(
                        None, None, f"the alias *{event.anchor} refers to a value that contains it", event.start_mark
                    ),
                    self._path,
                )
            return super().compose_node(parent, index)
        event = self.peek_event()
        anchor = event.anchor
        if self._level > MAX_DEPTH:
            raise _at(
                ComposerError(None, None, f"nested more than {MAX_DEPTH} levels deep", event.start_mark), self._path
            )
        if anchor is not None:
            self._open.append(anchor)
        self._level += 1
        try:
            node = super().compose_node(parent, index)
        finally:
            self._level -= 1
            if anchor is not None:
                self._open.pop()
        try:
            self._measure(node)
        except ComposerError as exc:
            raise _at(exc, self._path) from None
        if isinstance(node, MappingNode):
            self._paths[id(node)] = tuple(self._path)
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


_CParser = getattr(getattr(yaml, "cyaml", None), "CParser", None)  # LibYAML, when PyYAML has it

if _CParser is not None:

    class _CLoader(_UniqueKeys, _CParser, yaml.constructor.SafeConstructor, yaml.resolver.Resolver):  # type: ignore[misc, valid-type]
        """The rules of `_Loader` on LibYAML's parser and composer (C: a
        list of 20 000 values composes in milliseconds, not seconds); the limits
        on the composed graph by `_check_graph`."""

        yaml_implicit_resolvers = _Loader.yaml_implicit_resolvers

        def __init__(self, stream: Any) -> None:
            _CParser.__init__(self, stream)
            yaml.constructor.SafeConstructor.__init__(self)
            yaml.resolver.Resolver.__init__(self)
            self._paths = {}


def _entry(key: Any, value: Any, path: tuple) -> list[tuple[Any, tuple]]:
    """(node, key path) of a key and its value in a mapping at ``path``."""
    name = key.value[:40] if isinstance(key, ScalarNode) else "<key>"
    return [(key, path + ("<key>",)), (value, path + (name,))]


def _check_graph(root: Any) -> dict[int, tuple]:
    """The limits of `_Loader` on a composed node graph (shared by aliases):
    values and depth with aliases expanded, no alias inside the value it names (the
    number of aliases is counted by `_precheck`, where each has its position).
    Returns the key path of every mapping node (for duplicate keys)."""
    sizes: dict[int, tuple[int, int]] = {}
    paths: dict[int, tuple] = {}
    open_: set[int] = set()

    def walk(node: Any, path: tuple) -> tuple[int, int]:
        key = id(node)
        if key in sizes:  # an alias: measured where its anchor is
            return sizes[key]
        if key in open_:
            raise _at(ComposerError(None, None, "an alias refers to a value that contains it", node.start_mark), path)
        if len(path) > MAX_DEPTH:
            raise _at(ComposerError(None, None, f"nested more than {MAX_DEPTH} levels deep", node.start_mark), path)
        if isinstance(node, MappingNode):
            paths[key] = path
            children = [pair for k, v in node.value for pair in _entry(k, v, path)]
        elif isinstance(node, SequenceNode):
            children = [(child, path + (i,)) for i, child in enumerate(node.value)]
        else:
            sizes[key] = (1, 0)
            return sizes[key]
        open_.add(key)
        size, depth = 1, 0
        for child, where in children:
            s, d = walk(child, where)
            size, depth = size + s, max(depth, d + 1)
        open_.discard(key)
        if size > MAX_NODES:
            problem = f"more than {MAX_NODES} values once aliases are expanded"
            raise _at(ComposerError(None, None, problem, node.start_mark), path)
        if depth > MAX_DEPTH:
            raise _at(ComposerError(None, None, f"nested more than {MAX_DEPTH} levels deep", node.start_mark), path)
        sizes[key] = (size, depth)
        return sizes[key]

    walk(root, ())
    return paths


def _place(frames: list[list[Any]], event: Any) -> None:
    """Advance the key or index of the innermost open list or mapping to the value ``event`` starts."""
    if not frames:
        return
    top = frames[-1]
    if not top[0]:
        top[1] += 1
    elif top[2]:
        top[1] = event.value[:40] if isinstance(event, yaml.ScalarEvent) else "<key>"
    top[2] = top[0] and not top[2]


def _events(text: str, loader: Any) -> Iterator[Any]:
    """LibYAML's events of ``text``, up to a syntax error (PyYAML reports it later, in its own words)."""
    try:
        yield from yaml.parse(text, Loader=loader)
    except yaml.YAMLError as exc:
        if "nesting depth" in str(getattr(exc, "problem", "")):  # LibYAML's own limit (1000), ours is lower
            problem = f"nested more than {MAX_DEPTH} levels deep"
            raise ComposerError(None, None, problem, getattr(exc, "problem_mark", None)) from None


def _precheck(text: str) -> None:
    """Nesting and aliases counted on LibYAML's event stream (C, linear time)
    before PyYAML's scanner sees the text: its look-ahead for simple keys is
    quadratic in the nesting depth, seconds for ``[[[[...`` ten thousand deep."""
    loader = getattr(yaml, "CSafeLoader", None)
    if loader is None:  # PyYAML without LibYAML: the composer's limits still hold
        return
    aliases = 0
    frames: list[list[Any]] = []  # per open list or mapping: [is_mapping, key or index, expecting a key]
    for event in _events(text, loader):
        if isinstance(event, (yaml.SequenceEndEvent, yaml.MappingEndEvent)):
            frames.pop()
            continue
        if not isinstance(event, yaml.NodeEvent):
            continue
        _place(frames, event)
        path = [f[1] for f in frames]
        if isinstance(event, (yaml.SequenceStartEvent, yaml.MappingStartEvent)):
            is_map = isinstance(event, yaml.MappingStartEvent)
            frames.append([is_map, None if is_map else -1, True])
            if len(frames) > MAX_DEPTH:
                problem = f"nested more than {MAX_DEPTH} levels deep"
                raise _at(ComposerError(None, None, problem, event.start_mark), path)
        elif isinstance(event, yaml.AliasEvent):
            aliases += 1
            if aliases > MAX_ALIASES:
                raise _at(ComposerError(None, None, f"more than {MAX_ALIASES} aliases", event.start_mark), path)


def load_yaml_text(text: str) -> Any:
    """Parse YAML text with the problem-file rules (see `_Loader`)."""
    if _CParser is None:  # PyYAML without LibYAML: the pure-Python composer, limits checked as it composes
        _precheck(text)
        return yaml.load(text, Loader=_Loader)  # noqa: S506 - a SafeLoader subclass
    if "&" in text:  # anchors, so maybe aliases: counted where they stand (a file without '&' has none)
        _precheck(text)
    loader = _CLoader(text)
    try:
        try:
            node = loader.get_single_node()
        except yaml.YAMLError as exc:
            if "nesting depth" in str(getattr(exc, "problem", "")):  # LibYAML's own limit (1000), ours is lower
                problem = f"nested more than {MAX_DEPTH} levels deep"
                raise ComposerError(None, None, problem, getattr(exc, "problem_mark", None)) from None
            _python_error(text)  # a syntax error: in PyYAML's words, the same with or without LibYAML
            raise
        if node is None:
            return None
        loader._paths = _check_graph(node)
        return loader.construct_document(node)
    finally:
        loader.dispose()


def _python_error(text: str) -> None:
    """Raise the error PyYAML's own parser finds in ``text`` (the limits first, so
    that it stays fast); return if it finds none."""
    _precheck(text)
    yaml.load(text, Loader=_Loader)  # noqa: S506 - a SafeLoader subclass


def read_yaml(path: str | os.PathLike, *, allow_pipe: bool = False) -> Any:
    """Parse a YAML file; errors name the file, the line and the key path.
    ``allow_pipe``: the file named on the command line may be ``-`` or a pipe
    (see `cpm_nlp.io.inputs`)."""
    return parse_yaml(read_input_text(path, allow_pipe=allow_pipe), display_name(path))


def parse_yaml(text: str, file: str | None) -> Any:
    """Parse YAML text read from ``file``; errors name the file, the line and the key path."""
    try:
        return load_yaml_text(text)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f"line {mark.line + 1}, column {mark.column + 1}: " if mark is not None else ""
        problem = getattr(exc, "problem", None) or str(exc).splitlines()[0]
        raise InputError(f"malformed YAML: {where}{problem}", file=file, path=getattr(exc, "key_path", ())) from None
    except (ValueError, OverflowError, RecursionError) as exc:  # e.g. timestamps out of range
        raise InputError(f"malformed YAML: {str(exc)[:200]}", file=file) from None
