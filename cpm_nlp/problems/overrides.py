"""``--set dotted.key=VALUE``: overriding values of a problem file."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import yaml

from ..core.errors import InputError, format_key_path
from .reader import load_yaml_text


def parse_override(text: str) -> tuple[list[str | int], Any]:
    """``"mechanism.parameters.b=50 mm"`` -> (["mechanism", "parameters", "b"], "50 mm")."""
    if not isinstance(text, str) or "=" not in text:
        raise InputError(f"expected dotted.key=VALUE, got {text!r}", path=("--set",))
    key, _, raw = text.partition("=")
    key = key.strip()
    if not key or any(not part for part in key.replace("]", "").split(".")):
        raise InputError(f"expected dotted.key=VALUE with a non-empty key, got {text!r}", path=("--set",))
    parts: list[str | int] = []
    for part in key.split("."):
        head, bracket, rest = part.partition("[")
        if head:
            parts.append(int(head) if head.isdigit() else head)
        if bracket:  # one or more list indices: name[i][j]
            indices = ("[" + rest).split("]")[:-1]
            if not indices or not part.endswith("]") or not all(i.startswith("[") for i in indices):
                raise InputError(f"expected an integer list index in {text!r}", path=("--set",))
            try:
                parts += [int(i[1:]) for i in indices]
            except ValueError:
                raise InputError(f"expected an integer list index in {text!r}", path=("--set",)) from None
    try:
        value = load_yaml_text(raw) if raw.strip() else None
    except yaml.YAMLError:
        value = raw
    return parts, value


def apply_overrides(data: Any, overrides: Sequence[str]) -> dict[str, Any]:
    """Apply ``--set`` overrides (like Hydra) to a parsed problem file.

    Keys are dotted paths; integers or ``[i]`` index lists; under
    ``solver.options`` the rest of the path is one option name
    (``solver.options.ipopt.tol=1e-8``).  Missing mappings are created.
    """
    if not overrides:
        return data
    if not isinstance(data, dict):
        raise InputError("--set needs the problem file to be a mapping of keys (problem, mechanism, inputs ...)")
    data = _deep_copy(data)
    for text in overrides:
        parts, value = parse_override(text)
        if len(parts) > 2 and parts[:2] == ["solver", "options"]:
            parts = parts[:2] + [".".join(str(p) for p in parts[2:])]
        if len(parts) > 1 and parts[0] == "solver" and isinstance(data.get("solver"), str):
            data["solver"] = {"preset": data["solver"]}  # a preset name, now refined
        node = _parent_node(data, parts, text)
        _set_last(node, parts, value, text)
    return data


def _parent_node(data: dict, parts: list[str | int], text: str) -> Any:
    """The list or mapping that holds the last key of ``parts``; missing mappings are created."""
    node: Any = data
    for depth, part in enumerate(parts[:-1]):
        where = tuple(parts[: depth + 1])
        if isinstance(node, list):
            if not _is_index(part, node):
                raise InputError(
                    f"--set {text}: no list element {part!r} at {format_key_path(where[:-1])}", path=("--set",)
                )
            node = node[part]
            continue
        if not isinstance(node, dict):
            raise InputError(f"--set {text}: {format_key_path(where[:-1])} is not a mapping", path=("--set",))
        if part not in node or node[part] is None:
            node[part] = {}
        node = node[part]
    return node


def _set_last(node: Any, parts: list[str | int], value: Any, text: str) -> None:
    last = parts[-1]
    if isinstance(node, list):
        if not _is_index(last, node):
            raise InputError(f"--set {text}: no list element {last!r}", path=("--set",))
        node[last] = value
    elif isinstance(node, dict):
        node[last] = value
    else:
        raise InputError(f"--set {text}: {format_key_path(parts[:-1])} is not a mapping", path=("--set",))


def _is_index(part: str | int, node: list) -> bool:
    """Whether ``part`` is an index of the list ``node`` (negative ones too)."""
    return isinstance(part, int) and -len(node) <= part < len(node)


def _deep_copy(value: Any) -> Any:
    if isinstance(value, dict):
        return {k: _deep_copy(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_deep_copy(v) for v in value]
    return value


# -- presets ----------------------------------------------------------------------------------
