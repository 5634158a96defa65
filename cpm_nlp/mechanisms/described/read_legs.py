"""Reading the ``legs`` section of a mechanism file: each leg's name, repetition, definitions
and joints (base -> platform), the size limits, and the bodies each leg runs through."""

from __future__ import annotations

from typing import Any

from ...core.errors import InputError
from .read_fields import as_list, as_mapping, as_name, check_size
from .read_joint import read_joint
from .spec import AXES, GROUND_NAMES, Joint, Leg

LEG_KEYS = {
    "name": "the leg's name",
    "repeat": "{index, values, rotate, axis}",
    "let": "definitions of the leg: name -> expression (in order; may use the index)",
    "joints": "base -> platform",
}
REPEAT_KEYS = {"index": "symbol", "values": "its values", "rotate": "angle expression", "axis": "x, y or z"}


#: Most legs of a mechanism (a repeated leg counts once per value of its index), joints of
#: one leg, and joints in all (documented in docs/site/guide/mechanism-files.md): far above
#: any parallel mechanism (a hexapod has 6 legs of 3 joints), low enough that a file is
#: checked and generated in seconds
MAX_LEGS, MAX_JOINTS_PER_LEG, MAX_JOINTS = 64, 32, 512

#: one copy of a leg: (index -> value, the index symbol, rotate, its axis)
_Variant = tuple[dict, Any, Any, str]


def read_legs(raw: Any, path: tuple) -> list[Leg]:
    """The legs, a repeated leg once per value of its index."""
    legs: list[Leg] = []
    joints_in_all = 0
    for k, item in enumerate(as_list(raw, path, "a list of legs")):
        p = path + (k,)
        item = as_mapping(item, p, "a leg {name, repeat, joints}", LEG_KEYS)
        name = as_name(item.get("name", f"leg{k + 1}"), p + ("name",), "a leg name")
        rep = item.get("repeat")
        variants = [({}, None, None, "z")] if rep is None else _variants(rep, p + ("repeat",))
        joints_raw = as_list(item.get("joints"), p + ("joints",), "a list of joints, base -> platform")
        if not joints_raw:
            raise InputError("a leg needs at least one joint", path=p + ("joints",))
        where = p + (("repeat", "values") if rep is not None else ())
        check_size(len(legs) + len(variants), MAX_LEGS, "legs (repeats counted)", where)
        check_size(len(joints_raw), MAX_JOINTS_PER_LEG, "joints in one leg", p + ("joints",))
        joints_in_all += len(joints_raw) * len(variants)
        check_size(joints_in_all, MAX_JOINTS, "joints in all legs (repeats counted)", where or p)
        legs += [_leg(name, item, joints_raw, variant, p) for variant in variants]
    return legs


def _variants(rep: Any, path: tuple) -> list[_Variant]:
    """The copies of a repeated leg (``repeat: {index, values, rotate, axis}``)."""
    rep = as_mapping(rep, path, "{index, values, rotate}", REPEAT_KEYS)
    index = as_name(rep.get("index", "i"), path + ("index",), "an index symbol")
    values = as_list(rep.get("values"), path + ("values",), "a list of index values")
    for j, v in enumerate(values):
        if isinstance(v, bool) or not isinstance(v, (int, float)):
            raise InputError(f"expected a number, got {v!r}", path=path + ("values", j))
    axis = rep.get("axis", "z")
    if axis not in AXES:
        raise InputError(f"expected x, y or z, got {axis!r}", path=path + ("axis",))
    return [({index: v}, index, rep.get("rotate"), axis) for v in values]


def _leg(name: str, item: dict, joints_raw: list, variant: _Variant, path: tuple) -> Leg:
    """One copy of a leg, its joints' placeholders filled with its index value."""
    template, index, rotate, axis = variant
    suffix = "" if index is None else str(template[index])
    joints = [read_joint(j, path + ("joints", n), template) for n, j in enumerate(joints_raw)]
    let = as_mapping(item.get("let") or {}, path + ("let",), "name -> expression")
    return Leg(name + suffix, joints, index, tuple(template.values()), rotate, axis, path, let)


def check_bodies(legs: list[Leg]) -> None:
    """Each leg is a serial chain base -> bodies -> platform: a joint carries the next body (its
    ``body``, default the leg's own next link, the platform for the last joint)."""
    owner: dict[str, str] = {}
    for leg in legs:
        prev, seen = "base", set()
        for n, j in enumerate(leg.joints):
            last = n == len(leg.joints) - 1
            body = j.body or ("platform" if last else f"{leg.name}.link{n + 1}")
            _check_link(leg, n, body, prev, seen, owner.get(body, leg.name))
            owner[body] = leg.name
            seen.add(body)
            prev = body


def _check_link(leg: Leg, n: int, body: str, prev: str, seen: set, owner: str) -> None:
    """The body the n-th joint of a leg carries (after ``prev``) continues its serial chain."""
    j: Joint = leg.joints[n]
    last = n == len(leg.joints) - 1
    where = j.path + ("body",)
    if body in GROUND_NAMES:
        raise InputError(f"a joint cannot carry the base (it joins {prev!r} to {body!r})", path=where)
    if body == prev or body in seen:
        raise InputError(
            f"two joints on the body {body!r} with no loop between them: this joint joins {prev!r} "
            f"to {body!r} again (a leg is a serial chain; name the body each joint carries)",
            path=where,
        )
    if last and body != "platform":
        raise InputError(f"leg {leg.name} does not reach the platform: its last joint carries {body!r}", path=where)
    if not last and body == "platform":
        rest = ", ".join(k.type for k in leg.joints[n + 1 :])
        raise InputError(
            f"leg {leg.name} reaches the platform at joint {n + 1}; the joints after it ({rest}) "
            "hang on the platform with no loop",
            path=where,
        )
    if body != "platform" and owner != leg.name:
        raise InputError(
            f"the body {body!r} is in legs {owner} and {leg.name}: legs are serial chains that "
            "share only the base and the platform",
            path=where,
        )


def leg_bodies(legs: list[Leg]) -> list[str]:
    """The bodies the legs run through: the ground, each leg's links (its joints' ``body``, else
    ``{leg}_link{n}``; a rod ``{leg}_rod`` for a last distance joint) and the platform (see
    `expand`)."""
    if not legs:
        return []
    out = ["ground"]
    for leg in legs:
        for n, j in enumerate(leg.joints):
            last = n == len(leg.joints) - 1
            if last and j.type == "distance":
                out.append(f"{leg.name}_rod")
            elif not last:
                out.append(j.body or f"{leg.name}_link{n + 1}")
    return out + ["platform"]
