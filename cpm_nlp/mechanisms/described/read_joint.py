"""Reading one joint of a mechanism file: a joint of a leg (``legs[k].joints[n]``) or of a
bodies-and-joints file (``joints[k]``), key by key; a leg's ``{i}`` placeholders filled in."""

from __future__ import annotations

import re
from collections.abc import Callable, Mapping
from typing import Any

from ...core.errors import InputError
from ...core.joints import JOINT_TYPES, joint_type
from .read_fields import as_list, as_mapping, as_name, as_pair
from .spec import Flexure, Joint

JOINT_KEYS = {
    "type": "one of " + ", ".join(JOINT_TYPES),
    "at": "location (vector expression)",
    "to": "the distal point of a distance joint",
    "length": "a distance joint's length (default: |to - at| in the drawing; given: the drawing may be rough)",
    "axis": "axis (vector expression)",
    "axes": "the axes of a U (2) or of an S's reported angles (3)",
    "actuated": "the actuator coordinate's name",
    "gain": "displacement per actuator unit (expression)",
    "home": "values at the reference configuration (list)",
    "coordinates": "names of its reported joint values",
    "limit": "limit family of its coordinates",
    "range": "[low, high] default limits",
    "flexure": "{hinge, t, r, l, material, E, sigma_all}",
    "body": "the body it carries (distal side)",
}
#: the keys of a joint of a bodies-and-joints file
GRAPH_JOINT_KEYS = {
    "name": "the joint's name (default J1, J2, ... in file order)",
    "between": "[proximal body, distal body]",
    **{k: v for k, v in JOINT_KEYS.items() if k != "body"},
    "length": "the rod's length (a distance joint; default: its length in the drawing)",
}


def read_joint(raw: Any, path: tuple, template: dict, graph: bool = False) -> Joint:
    """A joint (``template``: the leg's index -> its value, for the placeholders; ``graph``: a
    joint of a bodies-and-joints file, with its name and the two bodies it joins)."""
    raw = as_mapping(raw, path, "a joint {type, at, axis, ...}", GRAPH_JOINT_KEYS if graph else JOINT_KEYS)
    kind = joint_type(raw.get("type"), path + ("type",)).name
    fields = {key: read(raw.get(key), path + (key,), template) for key, read in _FIELDS.items()}
    return Joint(
        kind,
        at=raw.get("at"),
        to=raw.get("to"),
        axis=raw.get("axis"),
        gain=raw.get("gain", 1),
        path=path,
        between=_between(raw, path) if graph else (),
        length=raw.get("length"),
        **fields,
    )


def _actuated(value: Any, path: tuple, template: dict) -> str | None:
    return None if value is None else as_name(fill(value, template, path), path, "an actuator name")


def _coordinates(value: Any, path: tuple, template: dict) -> tuple[str, ...]:
    return tuple(
        as_name(fill(c, template, path + (k,)), path + (k,), "a coordinate name")
        for k, c in enumerate(as_list(value or [], path, "a list of names"))
    )


def _home(value: Any, _path: tuple, _template: dict) -> tuple:
    return tuple(value) if isinstance(value, list) else (() if value is None else (value,))


def _axes(value: Any, path: tuple, _template: dict) -> tuple:
    axes = value or []
    if not isinstance(axes, list):
        raise InputError(f"expected a list of vectors, got {axes!r:.60}", path=path)
    return tuple(axes)


def _range(value: Any, path: tuple, _template: dict) -> tuple[Any, Any] | None:
    return None if value is None else as_pair(value, path)


def _flexure(value: Any, path: tuple, _template: dict) -> Flexure | None:
    return None if value is None else Flexure(as_mapping(value, path, "{hinge, t, r, l, material}"))


def _limit(value: Any, path: tuple, _template: dict) -> str | None:
    return None if value is None else as_name(value, path, "a limit family name")


def _body(value: Any, path: tuple, template: dict) -> str | None:
    return None if value is None else as_name(fill(value, template, path), path, "a body name")


def _name(value: Any, path: tuple, _template: dict) -> str | None:
    return None if value is None else as_name(value, path, "a joint name")


#: the keys of a joint read into its fields, in the order they are checked
_FIELDS: dict[str, Callable[[Any, tuple, dict], Any]] = {
    "actuated": _actuated,
    "coordinates": _coordinates,
    "home": _home,
    "axes": _axes,
    "range": _range,
    "flexure": _flexure,
    "limit": _limit,
    "body": _body,
    "name": _name,
}


def _between(raw: Mapping, path: tuple) -> tuple[str, str]:
    pair = raw.get("between")
    if not isinstance(pair, list) or len(pair) != 2:
        raise InputError(
            f"expected [proximal body, distal body], got {pair!r:.60}",
            path=path + ("between",),
            hint="a joint of a bodies-and-joints file joins two bodies: between: [ground, crank]",
        )
    a, b = (as_name(v, path + ("between", k), "a body name") for k, v in enumerate(pair))
    if a == b:
        raise InputError(f"a joint joins two different bodies, got {a!r} twice", path=path + ("between",))
    return a, b


_PLACEHOLDER = re.compile(r"\{(\w+)\}")


def fill(text: Any, template: dict, path: tuple) -> Any:
    """``"s{i}"`` with i = 2 -> ``"s2"``."""
    if not isinstance(text, str):
        return text

    def sub(m: re.Match) -> str:
        if m.group(1) not in template:
            raise InputError(
                f"unknown placeholder {{{m.group(1)}}} in {text!r}; the leg's index is "
                + (", ".join(template) or "not declared (repeat: {index: i, values: [...]})"),
                path=path,
            )
        v = template[m.group(1)]
        return f"{v:g}" if isinstance(v, float) else str(v)

    return _PLACEHOLDER.sub(sub, text)
