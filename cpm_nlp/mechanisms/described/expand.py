"""Legs as a shorthand: a legs file expanded into the bodies and joints it stands for (issue 21).

`expand_legs` turns a [`Description`][cpm_nlp.mechanisms.described.spec.Description] with ``legs`` into the equivalent
description of bodies and joints, read by `GraphGenerator`:

* the ground, one body per link of each leg (``{leg}_link{n}``, or the leg's ``body:`` names) and
  the platform; joint ``n`` of a leg joins the body before it to the body after it, with its type,
  location, axes, actuator (gain, home), coordinates, limit family, range and flexure hinge;
* the platform is *placed* by the platform coordinates (``Platform.placed``): its pose is
  ``P(x)``, ``R(x) R_home^T`` exactly as the legs generator writes it, so every leg's last joint
  closes a loop, the pose coordinates are the legs file's (the platform's, then the passive tree
  joints'), and a platform the file restricts (``rotation: []``, the Delta's and the 3-PRC's
  translational platform; the RPR's three coordinates) stays restricted.  ``describe`` shows
  this as the joint ``platform_pose`` between the ground and the platform, with as many
  freedoms as the platform has coordinates;
* a ``distance`` joint (a rod with a spherical joint at each end) becomes a rod body: a U at
  ``at`` (its axes across the rod) and an S at ``to``; the rod's spin about itself, which the
  legs generator never writes, is kept out of the mobility by the U;
* likewise a passive S whose link ends at the leg's last point joint (an S-S link, or S-P-S as
  the RPR's legs) becomes a U with its axes across the link: the legs generator eliminates that
  joint and refuses coordinates on it, so nothing it reports is lost.

Every expression keeps its text; it is evaluated in its leg's frame -- the leg's ``let``
definitions, its index and its rotation -- through `InLeg` (the key paths of errors stay
the legs file's).

The expansion serves ``describe`` (the body graph, loops and both mobility counts), the
assembly of a reference configuration from a rough drawing, and files that mix legs with
bodies and joints (``legs`` and ``bodies``/``joints`` in one file: a lever between an actuator
and a leg's slider): their bodies join the legs' by name and the whole is read as one graph.

**A pure legs file keeps the elimination generator for its closures**
(`Generator`): it eliminates each leg's passive joints, so Φ has one to three
rows per leg in the platform coordinates alone, and its FK and batch run within 1.1x of the
hand-written modules (benchmarks/bench_described.py); the expanded graph has every passive joint
as an unknown and would be slower.

What has no bodies-and-joints equivalent yet (`expansion_gap`): ``closures`` and
``actuators`` written as expressions (a graph's loops come from its joints).  A closed-form
``ik`` is dropped (it names only the legs' coordinates; the expanded graph solves its IK), and
so are the legs' generated branch indicators (the graph generates its own; the declared
``branch.add`` expressions are kept).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any

from ...core.errors import InputError
from .spec import Body, Description, Joint, Leg

#: the body name of the ground and of the platform in an expanded legs file
GROUND, PLATFORM = "ground", "platform"


@dataclass(frozen=True)
class InLeg:
    """An expression of a leg, evaluated in its frame: its ``let`` definitions and index, and, for
    a vector (``turn``), turned by the leg's ``rotate``.  ``across`` = (from, to): instead, unit
    vector ``normal`` (1 or 2) across the link from -> to (the axes of a U that keeps a rod's or an
    S-S link's spin), or with ``normal`` 0 the point at ``text`` (a length) from ``from`` towards
    ``to`` (the end of a rod of a given length)."""

    leg: Leg
    text: Any
    turn: bool = False
    across: tuple[Any, Any] | None = None
    normal: int = 0
    #: the key path of the text in the legs file (for errors)
    path: tuple = ()


def expansion_gap(d: Description) -> str | None:
    """Why a legs file has no bodies-and-joints equivalent yet (None: it has one)."""
    if not d.legs:
        return "it has no legs"
    if d.closures:
        return "its closures are written as expressions (a graph's loops come from its joints)"
    if d.actuators:
        return "it declares actuators without joints (a graph actuates its joints)"
    return None


def _spin_joint(leg: Leg) -> int | None:
    """The joint whose link's spin the legs generator leaves out: a passive S just before the last
    point joint (S), or before a P just before it (S-P-S); None when there is none."""
    joints = leg.joints
    if len(joints) < 2 or joints[-1].type != "S":
        return None
    k = len(joints) - 2
    if joints[k].type in ("P",) and k >= 1 and joints[k - 1].type == "S":
        k -= 1
    j = joints[k]
    if j.type == "S" and j.actuated is None:
        return k
    return None


def expand_legs(d: Description, defaults: dict[str, float] | None = None) -> Description:
    """The bodies-and-joints description a legs file stands for (see the module's docstring).

    ``defaults``: parameter values (SI) that replace the file's defaults -- the graph's loops are
    ranked at the reference configuration with them, and a parameter without a default needs one
    (e.g. the parameters of the problem being described).  An [`InputError`][cpm_nlp.core.errors.InputError] names what
    has no
    equivalent yet (`expansion_gap`)."""
    gap = expansion_gap(d)
    if gap is not None:
        raise InputError(
            f"the legs have no bodies-and-joints equivalent yet: {gap}",
            path=("legs",) if d.legs else (),
        )
    pf = d.platform
    if d.bodies and (not pf.position or pf.body not in (None, PLATFORM) or pf.point is not None):
        raise InputError(
            "a file with legs places its platform by its coordinates: give platform.position (and rotation) "
            "as a legs file does, not the body or point they locate",
            path=("platform", "position") if not pf.position else ("platform", "body" if pf.body else "point"),
            hint="the legs end at the body 'platform'; join other bodies to it by joints",
        )
    points: dict[str, dict[str, Any]] = {GROUND: {}}
    paths: dict[str, tuple] = {GROUND: ("legs",)}
    joints: list[Joint] = []

    def add_point(body: str, name: str, value: Any, path: tuple) -> None:
        points.setdefault(body, {})[name] = value
        paths.setdefault(body, path)

    for leg in d.legs:
        prev = GROUND
        spin = _spin_joint(leg)
        tip = leg.joints[-1].at
        for n, j in enumerate(leg.joints):
            last = n == len(leg.joints) - 1
            body = j.body or (PLATFORM if last else f"{leg.name}_link{n + 1}")
            name = f"{leg.name}_j{n + 1}"
            at = InLeg(leg, j.at, turn=True, path=j.path + ("at",))
            add_point(prev, name, at, leg.path)
            if last and j.type == "distance":  # a rod: U at `at` (no spin), S at `to`
                rod, end = f"{leg.name}_rod", f"{name}_end"
                to = InLeg(leg, j.to, turn=True, path=j.path + ("to",))
                add_point(rod, name, at, leg.path)
                # the rod's own end: the drawing's, or its given length from `at` towards the drawing's
                own = to if j.length is None else InLeg(leg, j.length, True, (j.at, j.to), 0, j.path + ("length",))
                add_point(rod, end, own, leg.path)
                add_point(body, end, to, leg.path)
                axes = tuple(InLeg(leg, None, True, (j.at, j.to), k, j.path) for k in (1, 2))
                joints.append(Joint("U", at=name, axes=axes, path=j.path, name=name, between=(prev, rod)))
                joints.append(Joint("S", at=end, path=j.path, name=end, between=(rod, body)))
                continue
            add_point(body, name, at, leg.path)
            kind, axes = j.type, tuple(InLeg(leg, a, True, path=j.path + ("axes", k)) for k, a in enumerate(j.axes))
            if n == spin:  # an S whose link ends at the last S: a U across the link (its spin left out)
                kind = "U"
                axes = tuple(InLeg(leg, None, True, (j.at, tip), k, j.path) for k in (1, 2))
            joints.append(
                dataclasses.replace(
                    j,
                    type=kind,
                    at=name,
                    axis=None if j.axis is None else InLeg(leg, j.axis, True, path=j.path + ("axis",)),
                    axes=axes,
                    gain=InLeg(leg, j.gain, path=j.path + ("gain",)),
                    home=tuple(InLeg(leg, h, path=j.path + ("home", k)) for k, h in enumerate(j.home)),
                    body=None,
                    name=name,
                    between=(prev, body),
                )
            )
            prev = body
    # a mixed file: its own bodies join the legs' (a body of both -- the ground, the platform, a
    # link it names -- carries the points of both), its joints come after the legs'
    own = {b.name: b for b in d.bodies}
    order = [GROUND] + [b for b in points if b not in (GROUND, PLATFORM)]
    order += [b for b in own if b not in order and b != PLATFORM] + [PLATFORM]
    bodies = [
        Body(
            b,
            {**(own[b].points if b in own else {}), **points.get(b, {})},
            own[b].description if b in own else "",
            own[b].path if b in own else paths.get(b, ("legs",)),
        )
        for b in order
    ]
    joints += d.joints
    params = d.parameters
    if defaults:
        params = [dataclasses.replace(p, default=defaults[p.name]) if p.name in defaults else p for p in params]
    branch = d.branch
    if branch is not None:  # the legs' generated indicators are not the graph's: keep the declared ones
        items = branch if isinstance(branch, list) else branch.get("add", [])
        branch = {"keep": "all", "remove": [], "add": [v for v in items if not _generated_name(v)]}
    return dataclasses.replace(
        d,
        parameters=params,
        platform=dataclasses.replace(d.platform, body=PLATFORM, point=None, placed=True),
        legs=[],
        branch=branch,
        ik=None,
        bodies=bodies,
        joints=joints,
    )


def _generated_name(item: Any) -> bool:
    """A name of an indicator the legs generator makes (``leg1.R2``, ``aspect``): a selection, not an
    expression."""
    return isinstance(item, str) and ("." in item or item == "aspect") and item.replace(".", "_").isidentifier()


__all__ = ["InLeg", "expand_legs", "expansion_gap"]
