"""Reading the sections of a bodies-and-joints file: the drawing's ``points``, the ``bodies``
(the points each carries), the ``joints`` between any two bodies and the ``outputs`` (points
of any body reported with every result).  With legs (a mixed file), the legs' bodies join the
file's."""

from __future__ import annotations

from collections.abc import Hashable, Mapping
from typing import Any

from ...core.errors import InputError, suggest
from .read_fields import as_list, as_mapping, as_name, as_text, check_size
from .read_joint import read_joint
from .read_legs import MAX_JOINTS, leg_bodies
from .spec import GROUND_NAMES, Body, Expr, Joint, Leg

BODY_KEYS = {"points": "name -> vector (null: the global point), or a list of global point names", "description": ""}


def read_graph(data: Mapping, legs: list[Leg]) -> tuple[dict, list[Body], list[Joint], dict]:
    """The ``points``, ``bodies``, ``joints`` and ``outputs`` of a bodies-and-joints file; with
    ``legs``, the bodies and joints besides the legs (a mixed file: the legs' bodies -- the ground,
    each leg's links, the platform -- may be joined to the file's)."""
    for key in ("closures", "actuators"):
        if data.get(key):
            raise InputError(
                f"a file describes its mechanism by bodies and joints or by {key}, not both",
                path=(key,),
                hint="write every loop as joints between bodies (the loops are found from the graph), and mark "
                "the actuated joints 'actuated: name'",
            )
    of_legs = leg_bodies(legs)
    points = {}
    for name, v in as_mapping(data.get("points") or {}, ("points",), "name -> vector").items():
        points[as_name(name, ("points", name), "a point name")] = v
    bodies = [
        _body(name, raw, points)
        for name, raw in as_mapping(data["bodies"], ("bodies",), "name -> the points it carries").items()
    ]
    bodies += _leg_bodies(of_legs, [b.name for b in bodies])
    names = [b.name for b in bodies]
    _check_ground(names)
    joints_raw = as_list(data.get("joints"), ("joints",), "a list of joints {type, between: [body, body], at, ...}")
    check_size(len(joints_raw), MAX_JOINTS, "joints", ("joints",))
    check_size(len(bodies), MAX_JOINTS, "bodies", ("bodies",))
    joints = [read_joint(j, ("joints", k), {}, graph=True) for k, j in enumerate(joints_raw)]
    seen: dict[str, int] = {}
    for k, j in enumerate(joints):
        _check_joint(k, j, bodies, points, seen)
    outputs = {
        name: _output(name, raw, bodies)
        for name, raw in as_mapping(data.get("outputs") or {}, ("outputs",), "name -> body.point").items()
    }
    return points, bodies, joints, outputs


def _body(name: str, raw: Any, points: dict[str, Expr]) -> Body:
    """A body: name -> vector (null: the drawing's point), a list of the drawing's point names,
    or {points, description}."""
    path = ("bodies", name)
    as_name(name, path, "a body name")
    desc = ""
    if isinstance(raw, Mapping):
        raw = as_mapping(raw, path, "{points, description}", BODY_KEYS)
        desc = as_text(raw.get("description"), path + ("description",))
        raw, path = raw.get("points") or [], path + ("points",)
    own = _named_points(raw, path, points) if isinstance(raw, list) else _own_points(raw, path, points)
    return Body(name, own, desc, ("bodies", name))


def _named_points(raw: list, path: tuple, points: dict[str, Expr]) -> dict[str, None]:
    """A list of the drawing's point names: each the global point."""
    own = {}
    for k, n in enumerate(raw):
        if not isinstance(n, Hashable) or n not in points:
            raise InputError(
                f"unknown point {n!r}; the drawing's points: {', '.join(points) or 'none (declare them under points)'}",
                path=path + (k,),
                suggestions=suggest(str(n), points),
            )
        own[n] = None
    return own


def _own_points(raw: Any, path: tuple, points: dict[str, Expr]) -> dict[str, Expr]:
    """name -> vector (null: the drawing's point of that name)."""
    own = as_mapping(raw, path, "name -> vector (null: the global point)")
    for n, v in own.items():
        as_name(n, path + (n,), "a point name")
        if v is None and n not in points:
            raise InputError(
                f"{n!r} is not a point of the drawing; give its coordinates",
                path=path + (n,),
                suggestions=suggest(str(n), points),
            )
    return own


def _leg_bodies(of_legs: list[str], names: list[str]) -> list[Body]:
    """A mixed file: the legs' bodies the file does not declare (the legs' ground is 'ground')."""
    if of_legs and "base" in names:
        raise InputError(
            "the legs' fixed body is 'ground': name it so here too", path=("bodies", "base"), suggestions=["ground"]
        )
    return [Body(b, {}, "", ("legs",)) for b in of_legs if b not in names]


def _check_ground(names: list[str]) -> None:
    """One ground: 'ground' or 'base'."""
    if not any(n in GROUND_NAMES for n in names):
        raise InputError(
            f"no ground: name the fixed body 'ground' (or 'base'); the bodies are {', '.join(names)}",
            path=("bodies",),
            suggestions=suggest("ground", names),
        )
    if all(n in names for n in GROUND_NAMES):
        raise InputError("two grounds: 'ground' and 'base' name the same fixed body; keep one", path=("bodies", "base"))


def _check_joint(k: int, j: Joint, bodies: list[Body], points: dict[str, Expr], seen: dict[str, int]) -> None:
    """Joint k joins two bodies of the file, has a name of its own (default J<k+1>, set here)
    and its points (a name) are on its bodies or the drawing's."""
    names = [b.name for b in bodies]
    for n, b in enumerate(j.between):
        if b not in names:
            raise InputError(
                f"unknown body {b!r}; the bodies are {', '.join(names)}",
                path=("joints", k, "between", n),
                suggestions=suggest(b, names),
            )
    name = j.name or f"J{k + 1}"
    if name in seen:
        raise InputError(f"the joint name {name!r} is also joint {seen[name] + 1}'s", path=("joints", k, "name"))
    seen[name] = k
    j.name = name
    for key, v in (("at", j.at), ("to", j.to)):
        if not (isinstance(v, str) and v.isidentifier()):
            continue
        for b in j.between:
            body = bodies[names.index(b)]
            if v not in body.points and v not in points:
                raise InputError(
                    f"{v!r} is not a point of {b!r} nor of the drawing; {b!r} carries "
                    f"{', '.join(body.points) or 'no points'}",
                    path=("joints", k, key),
                    suggestions=suggest(v, list(body.points) + list(points)),
                )


def _output(name: str, raw: Any, bodies: list[Body]) -> tuple[str, str, str]:
    """An output: body.point, or {point: body.point, description}."""
    path = ("outputs", name)
    as_name(name, path, "an output name")
    desc = ""
    if isinstance(raw, Mapping):
        raw = as_mapping(raw, path, "{point, description}", {"point": "body.point", "description": ""})
        desc = as_text(raw.get("description"), path + ("description",))
        raw, path = raw.get("point"), path + ("point",)
    body, _, point = str(raw).partition(".")
    names = [b.name for b in bodies]
    if body not in names:
        raise InputError(
            f"expected body.point with a body of the file, got {raw!r}", path=path, suggestions=suggest(body, names)
        )
    b = bodies[names.index(body)]
    if point not in b.points:
        raise InputError(
            f"{point!r} is not a point of {body!r}; it carries {', '.join(b.points) or 'no points'}",
            path=path,
            suggestions=suggest(point, b.points),
        )
    return body, point, desc
