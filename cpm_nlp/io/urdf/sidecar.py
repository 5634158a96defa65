"""Reading an Extended URDF sidecar (``robot.yaml``): its closures, actuated joints and the
joints read as another type."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from ...core.errors import InputError, suggest, unknown_key_error
from ..inputs import display_name
from ..yamlfile import read_yaml
from .read import MAX_JOINTS

#: Most closures a sidecar may name.
MAX_CLOSURES = 256


_SIDECAR_KEYS = {
    "closed_loop": "[[frame_A, frame_B], ...]: the loop closures",
    "type": "['6d' | '3d', ...]: one per closure",
    "name_mot": "[joint, ...]: the actuated joints",
    "joint_name": "[joint, ...]: joints read as another type (joint_type)",
    "joint_type": "[SPHERICAL | FIXED | UJOINT_XY | ..., ...]: one per joint_name",
}


_REPLACEMENTS = ("SPHERICAL", "FIXED") + tuple(f"UJOINT_{a}{b}" for a in "XYZ" for b in "XYZ" if a != b)


@dataclass
class Sidecar:
    closures: list[tuple[str, str, str, tuple]] = field(default_factory=list)  # frame A, frame B, 3d/6d, path
    motors: list[tuple[str, tuple]] = field(default_factory=list)
    replace: dict[str, tuple[str, tuple]] = field(default_factory=dict)


def _names_list(raw: Any, key: str, file: str) -> list[str]:
    if raw is None:
        return []
    if not isinstance(raw, list) or len(raw) > MAX_JOINTS:
        raise InputError(f"expected a list of at most {MAX_JOINTS} names, got {raw!r:.60}", file=file, path=(key,))
    for k, v in enumerate(raw):
        if not isinstance(v, str) or not v:
            raise InputError(f"expected a name, got {v!r:.60}", file=file, path=(key, k))
    return raw


def read_sidecar(path: str) -> Sidecar:
    """The closures, actuated joints and joint types of the sidecar at ``path``, each key checked."""
    file = display_name(path)
    data = read_yaml(path)
    if data is None:
        return Sidecar()
    if not isinstance(data, dict):
        raise InputError(f"expected a mapping of {', '.join(_SIDECAR_KEYS)}, got {type(data).__name__}", file=file)
    for key in data:
        if key not in _SIDECAR_KEYS:
            raise unknown_key_error(str(key), _SIDECAR_KEYS, (str(key),), "Extended URDF sidecar key").at(file=file)
    out = Sidecar()
    out.closures = _closures(data, file)
    out.motors = [(m, ("name_mot", k)) for k, m in enumerate(_names_list(data.get("name_mot"), "name_mot", file))]
    out.replace = _replacements(data, file)
    return out


def _closures(data: dict, file: str) -> list[tuple[str, str, str, tuple]]:
    """``closed_loop`` and ``type``: (frame A, frame B, '3d' or '6d', key path) of each closure."""
    loops = data.get("closed_loop") or []
    if not isinstance(loops, list) or len(loops) > MAX_CLOSURES:
        raise InputError(
            f"expected a list of at most {MAX_CLOSURES} pairs [frame_A, frame_B], got {loops!r:.60}",
            file=file,
            path=("closed_loop",),
        )
    types = data.get("type")
    if types is None:
        types = ["6d"] * len(loops)
    if not isinstance(types, list) or len(types) != len(loops):
        raise InputError(
            f"expected one type ('6d' or '3d') for each of the {len(loops)} closures, got {types!r:.60}",
            file=file,
            path=("type",),
        )
    closures = []
    for k, (pair, kind) in enumerate(zip(loops, types)):
        if not (isinstance(pair, list) and len(pair) == 2 and all(isinstance(f, str) and f for f in pair)):
            raise InputError(
                f"expected a pair [frame_A, frame_B], got {pair!r:.60}", file=file, path=("closed_loop", k)
            )
        if str(kind).lower() not in ("3d", "6d"):
            raise InputError(
                f"expected '6d' (the frames coincide) or '3d' (their origins coincide), got {kind!r:.40}",
                file=file,
                path=("type", k),
                suggestions=suggest(str(kind), ["6d", "3d"]),
            )
        closures.append((pair[0], pair[1], str(kind).lower(), ("closed_loop", k)))
    return closures


def _replacements(data: dict, file: str) -> dict[str, tuple[str, tuple]]:
    """``joint_name`` and ``joint_type``: joint -> (the type it is read as, key path)."""
    names = _names_list(data.get("joint_name"), "joint_name", file)
    kinds = _names_list(data.get("joint_type"), "joint_type", file)
    if len(names) != len(kinds):
        raise InputError(
            f"expected one joint_type for each of the {len(names)} joint_name entries, got {len(kinds)}",
            file=file,
            path=("joint_type",),
        )
    replace = {}
    for k, (n, t) in enumerate(zip(names, kinds)):
        if t not in _REPLACEMENTS:
            raise InputError(
                f"unknown joint type {t!r}; expected one of: {', '.join(_REPLACEMENTS)}",
                file=file,
                path=("joint_type", k),
                suggestions=suggest(t, _REPLACEMENTS),
            )
        replace[n] = (t, ("joint_name", k))
    return replace
