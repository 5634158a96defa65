"""Reading the ``platform`` section of a mechanism file: its pose coordinates, position,
rotation, task, fixed coordinates, home pose, bounds and offsets."""

from __future__ import annotations

from collections.abc import Hashable, Mapping
from typing import Any

from ...core.errors import InputError
from .read_fields import as_bool, as_dimension, as_list, as_mapping, as_name, as_pair, as_text, check_known
from .spec import AXES, Platform

PLATFORM_KEYS = {
    "coordinates": "name -> dimension (or {dimension, description})",
    "position": "P as an expression of the coordinates",
    "rotation": "[[axis, angle], ...]: R as a product of rotations",
    "task": "the task coordinates",
    "fixed": "coordinates fixed by the structure: name -> value",
    "home": "the reference pose: name -> value",
    "bounds": "name -> [low, high]: the box IPOPT keeps the pose in",
    "planar": "true for a planar mechanism (P in the plane, R about z)",
    "offsets": "name -> coordinate: inputs/outputs measured from the home pose (dz: pz)",
    "body": "the body the pose coordinates locate (bodies-and-joints files; default 'platform')",
    "point": "the point of that body that position locates (default: its frame origin)",
}


def read_platform(raw: Any, path: tuple, graph: bool = False) -> Platform:
    """The ``platform`` section (``graph``: of a bodies-and-joints file, whose pose may be the
    joints' alone: no platform coordinates, no position, and a task that may name a joint
    coordinate, checked when the mechanism is built)."""
    raw = as_mapping(raw, path, "a mapping {coordinates, position, rotation, task ...}", PLATFORM_KEYS)
    if graph:
        raw.setdefault("coordinates", {})
        raw.setdefault("position", [])
    coords, descs = _coordinates(raw.get("coordinates"), path + ("coordinates",))
    for key in ("position", "task"):
        if key not in raw:
            raise InputError(f"missing key {key!r} ({PLATFORM_KEYS[key]})", path=path)
    rotation = _rotation(raw.get("rotation") or [], path + ("rotation",))
    task = as_list(raw["task"], path + ("task",), "a list of coordinate names")
    # a graph's task may name a joint coordinate (checked when it is built): here, a name at least
    check_known(
        ((k, t) for k, t in enumerate(task) if not graph or not isinstance(t, Hashable)), coords, path + ("task",)
    )
    fixed = as_mapping(raw.get("fixed") or {}, path + ("fixed",), "name -> value")
    home = as_mapping(raw.get("home") or {}, path + ("home",), "name -> value")
    bounds = {
        name: as_pair(b, path + ("bounds", name))
        for name, b in as_mapping(raw.get("bounds") or {}, path + ("bounds",), "name -> [low, high]").items()
    }
    for section, names in (("fixed", fixed), ("home", home), ("bounds", bounds)):
        check_known(((n, n) for n in names), coords, path + (section,))
    planar = as_bool(raw.get("planar", False), path + ("planar",))
    offsets = _offsets(raw.get("offsets") or {}, path + ("offsets",), coords, fixed)
    body = None if raw.get("body") is None else as_name(raw["body"], path + ("body",), "a body name")
    point = None if raw.get("point") is None else as_name(raw["point"], path + ("point",), "a point name")
    return Platform(
        coords, raw["position"], rotation, tuple(task), fixed, home, bounds, descs, planar, offsets, body, point
    )


def _coordinates(raw: Any, path: tuple) -> tuple[dict[str, str], dict[str, str]]:
    """name -> dimension, or name -> {dimension, description}: the dimensions and descriptions."""
    coords, descs = {}, {}
    for name, spec in as_mapping(raw, path, "name -> dimension").items():
        p = path + (name,)
        as_name(name, p, "a coordinate name")
        if isinstance(spec, Mapping):
            spec = as_mapping(spec, p, "{dimension, description}", {"dimension": "", "description": ""})
            descs[name] = as_text(spec.get("description"), p + ("description",))
            spec = spec.get("dimension")
        coords[name] = as_dimension(spec, p)
    return coords, descs


def _rotation(raw: Any, path: tuple) -> list[tuple[str, Any]]:
    """[[axis, angle], ...]: R as a product of rotations about base axes."""
    rotation = []
    for k, item in enumerate(as_list(raw, path, "[[axis, angle], ...]")):
        if not isinstance(item, list) or len(item) != 2 or item[0] not in AXES:
            raise InputError(f"expected [axis, angle] with axis x, y or z; got {item!r}", path=path + (k,))
        rotation.append((item[0], item[1]))
    return rotation


def _offsets(raw: Any, path: tuple, coords: dict, fixed: dict) -> dict[str, str]:
    """name -> the pose coordinate it measures from the home pose."""
    offsets = as_mapping(raw, path, "name -> coordinate")
    for name, target in offsets.items():
        as_name(name, path + (name,), "an offset name")
        if not isinstance(target, Hashable) or target not in coords or target in fixed:
            raise InputError(f"expected a pose coordinate, got {target!r}", path=path + (name,))
    return offsets
