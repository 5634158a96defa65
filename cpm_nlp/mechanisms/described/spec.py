"""The description of a mechanism: dataclasses (the Python builder API) and
their reading from a mapping (a mechanism file).

A mechanism file::

    name: my_stage                     # the type name (an identifier)
    title: one line
    parameters:                        # declared like the built-ins' options
      b: {dimension: length, default: 47.91 mm, bounds: [0 mm, 1 m], description: ...}
    derived:                           # named expressions of the parameters
      a: b + L*cos(alpha0)
    platform:
      coordinates: {px: length, ..., psi: angle}
      position: [px, py, pz]           # P, an expression over the coordinates
      rotation: [[y, theta], [x, psi], [z, phi]]   # R = Ry(theta) Rx(psi) Rz(phi)
      task: [pz, psi, theta]           # nq of them; the others are dependent (reported)
      fixed: {}                        # coordinates fixed by the structure: name -> value
      home: {pz: L*sin(alpha0)}        # the reference pose (others 0)
    legs:
      - name: leg
        repeat: {index: i, values: [1, 2, 3], rotate: 2*pi*(i-1)/3}
        joints:                        # base -> platform, at the reference pose
          - {type: P, at: [a, 0, 0], axis: [-1, 0, 0], actuated: "s{i}"}
          - {type: R, at: [a, 0, 0], axis: [0, -1, 0], coordinates: ["alpha{i}"], home: [alpha0]}
          - {type: S, at: [b, 0, L*sin(alpha0)], coordinates: ["bm{i}", "bn{i}", "bl{i}"]}

Every location and axis is a vector expression in the parameters, in the base
frame at the reference configuration (the home pose).  See the README for the
full list of keys.
"""

from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

from ...analysis.compliance import HINGE_KEYS, JointStiffness
from ...core.errors import InputError, suggest, unknown_key_error
from ...core.finite import check_numbers
from ...core.joints import JOINT_TYPES, joint_type
from ...core.options import REQUIRED
from ...core.units import parse_quantity

DIMENSIONS = ("length", "angle", "dimensionless")
AXES = ("x", "y", "z")

Expr = Any  # an expression: a string, a number, or a list of them (a vector)


@dataclass
class Parameter:
    """A geometry parameter (declared like a built-in mechanism's options)."""

    name: str
    dimension: str = "length"
    default: Any = REQUIRED
    lower: float | None = None
    upper: float | None = None
    description: str = ""
    #: the bounds exclude their ends (``strict: true``, as a built-in option's ``strict=True``)
    strict: bool = False


@dataclass
class Quantity:
    """A named expression with its dimension (derived values, reported passive coordinates)."""

    name: str
    value: Expr
    dimension: str | None = None
    description: str = ""
    family: str = ""


@dataclass
class Flexure:
    """A flexure hinge that sets a joint's limits: hinge type, dimensions, material
    (the keys of :data:`cpm_nlp.analysis.hinge_types.HINGE_LIMIT_OPTIONS`)."""

    values: dict[str, Any]


@dataclass
class Joint:
    """One joint of a leg, base side first.

    at: its location (vector expression, base frame, reference configuration);
    for ``distance`` the point on the proximal body, ``to`` the one on the distal.
    axis: its axis (R, P, C, planar_P); axes: the two axes of a U, the three
    axes an S reports its angles about (default x, y, z).
    actuated: the actuator coordinate driving it (a name), with ``gain``
    (displacement per actuator unit) and ``home`` (the actuator value at the
    reference configuration).
    coordinates: names of its reported joint values (one per degree of freedom),
    ``home`` their values at the reference configuration.
    limit: the limit family of its coordinates (default: the name without digits).
    """

    type: str
    at: Expr = None
    to: Expr = None
    axis: Expr = None
    axes: tuple[Expr, ...] = ()
    actuated: str | None = None
    gain: Expr = 1
    home: tuple[Expr, ...] = ()
    coordinates: tuple[str, ...] = ()
    limit: str | None = None
    range: tuple[Any, Any] | None = None
    flexure: Flexure | None = None
    body: str | None = None  # the body it carries (distal side); optional, for connectivity checks
    path: tuple = ()
    #: a joint of a bodies-and-joints file: its name, the two bodies it joins (proximal first)
    #: and, for a distance joint, the rod's length (default: the distance in the drawing)
    name: str | None = None
    between: tuple[str, ...] = ()
    length: Expr = None


@dataclass
class Leg:
    """A serial chain from the base to the platform, optionally repeated: the
    ``index`` symbol takes each of ``values`` and every vector of the leg is
    turned by ``rotate`` (an angle expression in the index) about ``rotate_axis``."""

    name: str
    joints: list[Joint]
    index: str | None = None
    values: tuple[Any, ...] = ()
    rotate: Expr = None
    rotate_axis: str = "z"
    path: tuple = ()
    #: definitions of the leg (name -> expression, in order; may use the index)
    let: dict[str, Expr] = field(default_factory=dict)


@dataclass
class Platform:
    coordinates: dict[str, str]
    position: Expr
    rotation: list[tuple[str, Expr]]
    task: tuple[str, ...]
    fixed: dict[str, Expr] = field(default_factory=dict)
    home: dict[str, Expr] = field(default_factory=dict)
    bounds: dict[str, tuple[Expr, Expr]] = field(default_factory=dict)
    descriptions: dict[str, str] = field(default_factory=dict)
    planar: bool = False
    offsets: dict[str, str] = field(default_factory=dict)
    #: a bodies-and-joints file: the body whose frame the pose coordinates locate, and its point
    #: that ``position`` locates (None: the body's frame origin, the world origin in the drawing)
    body: str | None = None
    point: str | None = None
    #: the platform coordinates place the platform body (a legs file expanded into bodies and
    #: joints, :mod:`.expand`): its pose is P(x), R(x) R_home^T, the legs close on it
    placed: bool = False


@dataclass
class Body:
    """A rigid body of a bodies-and-joints file: its named points in the drawing (world frame at
    the drawing configuration, which is also the body's own frame); None: the global point."""

    name: str
    points: dict[str, Expr]
    description: str = ""
    path: tuple = ()


@dataclass
class ClosedFormIK:
    """A closed-form inverse kinematics: ``let`` definitions in order, the
    dependent coordinates and the actuators as expressions of the task
    coordinates, and ``reach`` (< 0 when the pose cannot be assembled)."""

    let: dict[str, Expr]
    pose: dict[str, Expr]
    actuators: dict[str, Expr]
    reach: Expr = None


@dataclass
class Description:
    """A whole mechanism, as a file describes it (also built in code)."""

    name: str
    title: str
    parameters: list[Parameter]
    platform: Platform
    legs: list[Leg] = field(default_factory=list)
    derived: list[Quantity] = field(default_factory=list)
    #: actuators declared without joints: name -> (dimension, value at the reference configuration)
    actuators: dict[str, tuple[str, Expr]] = field(default_factory=dict)
    closures: list[Expr] = field(default_factory=list)
    #: the branch indicators: None (absent) the generated ones; a list: exactly these (an item is a
    #: generated indicator's name, an expression, or {name: expression}; [] none); a mapping
    #: {keep, remove, add}: the generated ones filtered and extended (see :func:`_branch`)
    branch: list[Any] | dict[str, Any] | None = None
    passive: list[Quantity] = field(default_factory=list)
    ik: ClosedFormIK | None = None
    characteristic_length: Expr = None
    paper: str = ""
    examples: tuple[str, ...] = ()
    #: joint-limit family -> its description (what ``describe`` and the error messages call it)
    limits: dict[str, str] = field(default_factory=dict)
    #: the compliant joints (hinges, material, source): the compliance kinds' defaults
    stiffness: JointStiffness | None = None
    file: str | None = None
    #: a bodies-and-joints file (see :mod:`.graph`): the drawing's named points, the bodies, the
    #: joints between any two of them, and points of any body reported as outputs (name -> (body, point))
    points: dict[str, Expr] = field(default_factory=dict)
    bodies: list[Body] = field(default_factory=list)
    joints: list[Joint] = field(default_factory=list)
    outputs: dict[str, tuple[str, str, str]] = field(default_factory=dict)

    @property
    def is_graph(self) -> bool:
        """Whether the mechanism is a graph of bodies and joints (not legs)."""
        return bool(self.bodies)


# -- reading a mapping ---------------------------------------------------------------------------

TOP = {
    "name": "the mechanism type name (an identifier)",
    "title": "a one-line title",
    "paper": "where the mechanism comes from",
    "parameters": "name -> {dimension, default, bounds, strict, description}",
    "derived": "name -> expression (or {value, dimension, description})",
    "platform": "{coordinates, position, rotation, task, fixed, home, bounds}",
    "legs": "list of {name, repeat, joints}",
    "actuators": "name -> dimension or {dimension, home} (for closures written as expressions)",
    "branch": "assembly-branch indicators as expressions, positive on the working branch",
    "closures": "list of closure equations as expressions (an escape hatch)",
    "passive": "name -> {value, dimension, family, description}: extra reported joint values",
    "ik": "{let, pose, actuators, reach}: a closed-form inverse kinematics",
    "characteristic_length": "length expression for conditioning measures",
    "examples": "problem files that use the mechanism (relative to this file)",
    "limits": "joint-limit family -> its description (text)",
    "stiffness": "{hinges, material, source}: the compliant joints, defaults of the compliance kinds",
    "points": "name -> vector: named points of the drawing (bodies-and-joints files)",
    "bodies": "name -> [point names] or {points, description}: the rigid bodies (the ground is 'ground')",
    "joints": "list of {type, between: [body, body], at, axis, ...}: joints between any two bodies",
    "outputs": "name -> body.point: points of any body reported with every result",
}


def _mapping(value: Any, path: tuple, what: str, allowed: Mapping[str, str] | None = None) -> dict:
    if not isinstance(value, Mapping):
        raise InputError(f"expected {what}, got {type(value).__name__} {value!r:.60}", path=path)
    if allowed is not None:
        for key in value:
            if key not in allowed:
                raise unknown_key_error(str(key), allowed, path, "key")
    return dict(value)


def _list(value: Any, path: tuple, what: str) -> list:
    if not isinstance(value, list):
        raise InputError(f"expected {what}, got {type(value).__name__} {value!r:.60}", path=path)
    return value


def _name(value: Any, path: tuple, what: str) -> str:
    if not isinstance(value, str) or not value.isidentifier():
        raise InputError(f"expected {what} (a name such as 'alpha1'), got {value!r}", path=path)
    return value


#: longest mechanism type name: it names CasADi Functions, C functions and files (``<name>_kinematics.c``)
MAX_TYPE_NAME = 64
#: a name CasADi takes for a Function (a letter, then letters, digits and single underscores) and C takes
#: for an identifier: ASCII only
_TYPE_NAME = re.compile(r"[A-Za-z](?:_?[A-Za-z0-9])*")


def _type_name(value: Any, path: tuple) -> str:
    """The mechanism type name: it becomes part of CasADi Function names, C identifiers and file names."""
    _name(value, path, "a mechanism type name")
    if len(value) > MAX_TYPE_NAME or not _TYPE_NAME.fullmatch(value):
        raise InputError(
            f"expected a mechanism type name of at most {MAX_TYPE_NAME} ASCII letters, digits and single "
            f"underscores, starting with a letter and not ending with an underscore, got {value!r:.80}"
            + (f" ({len(value)} characters)" if len(value) > MAX_TYPE_NAME else ""),
            path=path,
        )
    return value


def _text(value: Any, path: tuple) -> str:
    if value is None:
        return ""
    if not isinstance(value, str):
        raise InputError(f"expected free text, got {value!r:.60}", path=path)
    return value


def _dimension(value: Any, path: tuple) -> str:
    if value not in DIMENSIONS:
        raise InputError(
            f"expected a dimension, one of: {', '.join(DIMENSIONS)}; got {value!r}",
            path=path,
            suggestions=suggest(str(value), DIMENSIONS),
        )
    return value


PARAMETER_KEYS = {"dimension": "", "default": "", "bounds": "", "strict": "", "description": ""}


def _parameter(name: str, raw: Any, path: tuple) -> Parameter:
    if isinstance(raw, str) and raw in DIMENSIONS:
        raw = {"dimension": raw}
    raw = _mapping(raw, path, "{dimension, default, bounds, strict, description}", PARAMETER_KEYS)
    dim = _dimension(raw.get("dimension", "length"), path + ("dimension",))
    lower = upper = None
    if raw.get("bounds") is not None:
        b = raw["bounds"]
        if not isinstance(b, list) or len(b) != 2:
            raise InputError(f"expected [low, high] (null for none), got {b!r}", path=path + ("bounds",))
        lower, upper = (None if v is None else parse_quantity(v, dim, path + ("bounds", k)) for k, v in enumerate(b))
        if lower is not None and upper is not None and not lower < upper:
            raise InputError(f"expected [low, high] with low < high, got {b!r}", path=path + ("bounds",))
    default = REQUIRED if raw.get("default") is None else parse_quantity(raw["default"], dim, path + ("default",))
    strict = raw.get("strict", False)
    if not isinstance(strict, bool):
        raise InputError(
            f"expected true (the bounds exclude their ends) or false, got {strict!r:.60}", path=path + ("strict",)
        )
    if strict and lower is None and upper is None:
        raise InputError("'strict' makes the bounds exclusive, and there are no bounds", path=path + ("strict",))
    return Parameter(
        name, dim, default, lower, upper, _text(raw.get("description"), path + ("description",)), strict=strict
    )


QUANTITY_KEYS = {"value": "", "dimension": "", "description": "", "family": ""}


def _quantity(name: str, raw: Any, path: tuple) -> Quantity:
    if not isinstance(raw, Mapping):
        return Quantity(name, raw)
    raw = _mapping(raw, path, "{value, dimension, description}", QUANTITY_KEYS)
    if "value" not in raw:
        raise InputError("missing key 'value' (an expression)", path=path)
    dim = None if raw.get("dimension") is None else _dimension(raw["dimension"], path + ("dimension",))
    fam = raw.get("family") or ""
    return Quantity(name, raw["value"], dim, _text(raw.get("description"), path + ("description",)), fam)


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


def _platform(raw: Any, path: tuple, graph: bool = False) -> Platform:  # noqa: C901 - one check per key
    raw = _mapping(raw, path, "a mapping {coordinates, position, rotation, task ...}", PLATFORM_KEYS)
    if graph:  # the pose may be the joints' alone: no platform coordinates, no position
        raw.setdefault("coordinates", {})
        raw.setdefault("position", [])
    coords, descs = {}, {}
    for name, spec in _mapping(raw.get("coordinates"), path + ("coordinates",), "name -> dimension").items():
        p = path + ("coordinates", name)
        _name(name, p, "a coordinate name")
        if isinstance(spec, Mapping):
            spec = _mapping(spec, p, "{dimension, description}", {"dimension": "", "description": ""})
            descs[name] = _text(spec.get("description"), p + ("description",))
            spec = spec.get("dimension")
        coords[name] = _dimension(spec, p)
    for key in ("position", "task"):
        if key not in raw:
            raise InputError(f"missing key {key!r} ({PLATFORM_KEYS[key]})", path=path)
    rotation = []
    for k, item in enumerate(_list(raw.get("rotation") or [], path + ("rotation",), "[[axis, angle], ...]")):
        if not isinstance(item, list) or len(item) != 2 or item[0] not in AXES:
            raise InputError(f"expected [axis, angle] with axis x, y or z; got {item!r}", path=path + ("rotation", k))
        rotation.append((item[0], item[1]))
    task = _list(raw["task"], path + ("task",), "a list of coordinate names")
    for k, t in enumerate(task):
        if t not in coords and not graph:  # a graph's task may name a joint coordinate (checked when built)
            raise InputError(
                f"unknown coordinate {t!r}; declared: {', '.join(coords)}",
                path=path + ("task", k),
                suggestions=suggest(str(t), coords),
            )
    fixed = _mapping(raw.get("fixed") or {}, path + ("fixed",), "name -> value")
    home = _mapping(raw.get("home") or {}, path + ("home",), "name -> value")
    bounds = {}
    for name, b in _mapping(raw.get("bounds") or {}, path + ("bounds",), "name -> [low, high]").items():
        if not isinstance(b, list) or len(b) != 2:
            raise InputError(f"expected [low, high], got {b!r}", path=path + ("bounds", name))
        bounds[name] = (b[0], b[1])
    for section, names in (("fixed", fixed), ("home", home), ("bounds", bounds)):
        for name in names:
            if name not in coords:
                raise InputError(
                    f"unknown coordinate {name!r}; declared: {', '.join(coords)}",
                    path=path + (section, name),
                    suggestions=suggest(str(name), coords),
                )
    planar = raw.get("planar", False)
    if not isinstance(planar, bool):
        raise InputError(f"expected true or false, got {planar!r}", path=path + ("planar",))
    offsets = _mapping(raw.get("offsets") or {}, path + ("offsets",), "name -> coordinate")
    for name, target in offsets.items():
        _name(name, path + ("offsets", name), "an offset name")
        if target not in coords or target in fixed:
            raise InputError(f"expected a pose coordinate, got {target!r}", path=path + ("offsets", name))
    body = None if raw.get("body") is None else _name(raw["body"], path + ("body",), "a body name")
    point = None if raw.get("point") is None else _name(raw["point"], path + ("point",), "a point name")
    return Platform(
        coords, raw["position"], rotation, tuple(task), fixed, home, bounds, descs, planar, offsets, body, point
    )


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


def _joint(raw: Any, path: tuple, template: dict, graph: bool = False) -> Joint:  # noqa: C901 - one check per key
    raw = _mapping(raw, path, "a joint {type, at, axis, ...}", GRAPH_JOINT_KEYS if graph else JOINT_KEYS)
    kind = joint_type(raw.get("type"), path + ("type",)).name
    actuated = raw.get("actuated")
    if actuated is not None:
        actuated = _name(_fill(actuated, template, path + ("actuated",)), path + ("actuated",), "an actuator name")
    coords = tuple(
        _name(_fill(c, template, path + ("coordinates", k)), path + ("coordinates", k), "a coordinate name")
        for k, c in enumerate(_list(raw.get("coordinates") or [], path + ("coordinates",), "a list of names"))
    )
    home = raw.get("home")
    home = tuple(home) if isinstance(home, list) else (() if home is None else (home,))
    axes = raw.get("axes") or []
    if not isinstance(axes, list):
        raise InputError(f"expected a list of vectors, got {axes!r:.60}", path=path + ("axes",))
    rng = raw.get("range")
    if rng is not None and (not isinstance(rng, list) or len(rng) != 2):
        raise InputError(f"expected [low, high], got {rng!r}", path=path + ("range",))
    flex = raw.get("flexure")
    if flex is not None:
        flex = Flexure(_mapping(flex, path + ("flexure",), "{hinge, t, r, l, material}"))
    limit = raw.get("limit")
    if limit is not None:
        limit = _name(limit, path + ("limit",), "a limit family name")
    return Joint(
        kind,
        raw.get("at"),
        raw.get("to"),
        raw.get("axis"),
        tuple(axes),
        actuated,
        raw.get("gain", 1),
        home,
        coords,
        limit,
        None if rng is None else tuple(rng),
        flex,
        None
        if raw.get("body") is None
        else _name(_fill(raw["body"], template, path + ("body",)), path + ("body",), "a body name"),
        path,
        None if raw.get("name") is None else _name(raw["name"], path + ("name",), "a joint name"),
        _between(raw, path) if graph else (),
        raw.get("length"),
    )


def _between(raw: Mapping, path: tuple) -> tuple[str, str]:
    pair = raw.get("between")
    if not isinstance(pair, list) or len(pair) != 2:
        raise InputError(
            f"expected [proximal body, distal body], got {pair!r:.60}",
            path=path + ("between",),
            hint="a joint of a bodies-and-joints file joins two bodies: between: [ground, crank]",
        )
    a, b = (_name(v, path + ("between", k), "a body name") for k, v in enumerate(pair))
    if a == b:
        raise InputError(f"a joint joins two different bodies, got {a!r} twice", path=path + ("between",))
    return a, b


_PLACEHOLDER = re.compile(r"\{(\w+)\}")


def _fill(text: Any, template: dict, path: tuple) -> Any:
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


def _check_size(count: int, limit: int, what: str, path: tuple) -> None:
    if count > limit:
        raise InputError(
            f"{count} {what}; at most {limit} (a limit of cpm_nlp: see the mechanism files guide)", path=path
        )


def _legs(raw: Any, path: tuple) -> list[Leg]:  # noqa: C901 - one check per key and limit
    legs: list[Leg] = []
    joints_in_all = 0
    for k, item in enumerate(_list(raw, path, "a list of legs")):
        p = path + (k,)
        item = _mapping(item, p, "a leg {name, repeat, joints}", LEG_KEYS)
        name = _name(item.get("name", f"leg{k + 1}"), p + ("name",), "a leg name")
        rep = item.get("repeat")
        if rep is None:
            variants = [({}, None, None, "z")]
        else:
            rep = _mapping(rep, p + ("repeat",), "{index, values, rotate}", REPEAT_KEYS)
            index = _name(rep.get("index", "i"), p + ("repeat", "index"), "an index symbol")
            values = _list(rep.get("values"), p + ("repeat", "values"), "a list of index values")
            for j, v in enumerate(values):
                if isinstance(v, bool) or not isinstance(v, (int, float)):
                    raise InputError(f"expected a number, got {v!r}", path=p + ("repeat", "values", j))
            axis = rep.get("axis", "z")
            if axis not in AXES:
                raise InputError(f"expected x, y or z, got {axis!r}", path=p + ("repeat", "axis"))
            variants = [({index: v}, index, rep.get("rotate"), axis) for v in values]
        joints_raw = _list(item.get("joints"), p + ("joints",), "a list of joints, base -> platform")
        if not joints_raw:
            raise InputError("a leg needs at least one joint", path=p + ("joints",))
        where = p + (("repeat", "values") if rep is not None else ())
        _check_size(len(legs) + len(variants), MAX_LEGS, "legs (repeats counted)", where)
        _check_size(len(joints_raw), MAX_JOINTS_PER_LEG, "joints in one leg", p + ("joints",))
        joints_in_all += len(joints_raw) * len(variants)
        _check_size(joints_in_all, MAX_JOINTS, "joints in all legs (repeats counted)", where or p)
        for template, index, rotate, axis in variants:
            suffix = "" if index is None else str(template[index])
            joints = [_joint(j, p + ("joints", n), template) for n, j in enumerate(joints_raw)]
            let = _mapping(item.get("let") or {}, p + ("let",), "name -> expression")
            legs.append(Leg(name + suffix, joints, index, tuple(template.values()), rotate, axis, p, let))
    return legs


BRANCH_KEYS = {
    "keep": "generated indicators to keep (names, or all / none; default all)",
    "remove": "generated indicators to remove (names)",
    "add": "indicators to add (expressions, or {name: expression})",
}


def _branch(raw: Any, path: tuple) -> list[Any] | dict[str, Any]:
    """The ``branch`` section: a list (exactly these indicators) or {keep, remove, add}.  The
    names of generated indicators are checked when the mechanism is generated."""
    if raw is None:
        return []
    if isinstance(raw, list):
        return [_branch_item(v, path + (k,)) for k, v in enumerate(raw)]
    m = _mapping(raw, path, "a list of indicators, or {keep, remove, add}", BRANCH_KEYS)
    keep = m.get("keep", "all")
    if keep not in ("all", "none"):
        keep = [_text(v, path + ("keep", k)) for k, v in enumerate(_list(keep, path + ("keep",), "a list of names"))]
    removed = _list(m.get("remove") or [], path + ("remove",), "a list of names")
    remove = [_text(v, path + ("remove", k)) for k, v in enumerate(removed)]
    added = _list(m.get("add") or [], path + ("add",), "a list of expressions")
    add = [_branch_item(v, path + ("add", k)) for k, v in enumerate(added)]
    return {"keep": keep, "remove": remove, "add": add}


def _branch_item(v: Any, path: tuple) -> Any:
    if isinstance(v, dict):
        if len(v) != 1:
            raise InputError(f"expected one {{name: expression}}, got {v!r:.60}", path=path)
        ((name, text),) = v.items()
        return {_text(name, path): text}
    if isinstance(v, bool) or not isinstance(v, (str, int, float)):
        raise InputError(f"expected an indicator's name or an expression, got {v!r:.60}", path=path)
    return v


def check_bodies(legs: list[Leg]) -> None:  # noqa: C901 - one message per way a chain can break
    """Each leg is a serial chain base -> bodies -> platform: a joint carries the next body (its
    ``body``, default the leg's own next link, the platform for the last joint)."""
    owner: dict[str, str] = {}
    for leg in legs:
        prev, seen = "base", set()
        for n, j in enumerate(leg.joints):
            last = n == len(leg.joints) - 1
            body = j.body or ("platform" if last else f"{leg.name}.link{n + 1}")
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
                raise InputError(
                    f"leg {leg.name} does not reach the platform: its last joint carries {body!r}", path=where
                )
            if not last and body == "platform":
                rest = ", ".join(k.type for k in leg.joints[n + 1 :])
                raise InputError(
                    f"leg {leg.name} reaches the platform at joint {n + 1}; the joints after it ({rest}) "
                    "hang on the platform with no loop",
                    path=where,
                )
            if body != "platform" and owner.get(body, leg.name) != leg.name:
                raise InputError(
                    f"the body {body!r} is in legs {owner[body]} and {leg.name}: legs are serial chains that "
                    "share only the base and the platform",
                    path=where,
                )
            owner[body] = leg.name
            seen.add(body)
            prev = body


def leg_bodies(legs: list[Leg]) -> list[str]:
    """The bodies the legs run through: the ground, each leg's links (its joints' ``body``, else
    ``{leg}_link{n}``; a rod ``{leg}_rod`` for a last distance joint) and the platform (see
    :mod:`.expand`)."""
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


STIFFNESS_KEYS = {
    "hinges": "name -> {joints, type, k, t, r, w, d, l, Kt, material}, as a problem file's inputs.hinges",
    "material": "the hinge material: a name or an inline {name, E, nu, density, yield_strength, allowable}",
    "source": "where the values come from (paper, section, table)",
}


def _stiffness(raw: Any, path: tuple) -> JointStiffness:
    """The ``stiffness`` section: its shape and keys (the hinges are checked against the
    generated closure when the mechanism is built, by the rules of ``inputs.hinges``)."""
    raw = _mapping(raw, path, "a mapping {hinges, material, source}", STIFFNESS_KEYS)
    if not raw.get("hinges"):
        raise InputError("missing key 'hinges' (" + STIFFNESS_KEYS["hinges"] + ")", path=path)
    hinges = {}
    for name, spec in _mapping(raw["hinges"], path + ("hinges",), "name -> hinge mapping").items():
        p = path + ("hinges", name)
        _name(name, p, "a hinge name")
        hinges[name] = _mapping(spec, p, "a hinge mapping {joints, type, k, ...}")
        for key in hinges[name]:
            if key not in HINGE_KEYS:
                raise unknown_key_error(str(key), HINGE_KEYS, p + (str(key),), "hinge key")
    return JointStiffness(
        hinges=hinges, material=raw.get("material"), source=_text(raw.get("source"), path + ("source",))
    )


IK_KEYS = {"let": "definitions in order", "pose": "dependent coordinates", "actuators": "", "reach": ""}
BODY_KEYS = {"points": "name -> vector (null: the global point), or a list of global point names", "description": ""}
#: the names the ground body may take
GROUND_NAMES = ("ground", "base")


def _graph(data: Mapping, legs: list[Leg]) -> tuple[dict, list[Body], list[Joint], dict]:  # noqa: C901 - one check per key
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
    for name, v in _mapping(data.get("points") or {}, ("points",), "name -> vector").items():
        points[_name(name, ("points", name), "a point name")] = v
    bodies: list[Body] = []
    for name, raw in _mapping(data["bodies"], ("bodies",), "name -> the points it carries").items():
        path = ("bodies", name)
        _name(name, path, "a body name")
        desc = ""
        if isinstance(raw, Mapping):
            raw = _mapping(raw, path, "{points, description}", BODY_KEYS)
            desc = _text(raw.get("description"), path + ("description",))
            raw, path = raw.get("points") or [], path + ("points",)
        if isinstance(raw, list):
            own = {}
            for k, n in enumerate(raw):
                if n not in points:
                    raise InputError(
                        f"unknown point {n!r}; the drawing's points: "
                        f"{', '.join(points) or 'none (declare them under points)'}",
                        path=path + (k,),
                        suggestions=suggest(str(n), points),
                    )
                own[n] = None
        else:
            own = _mapping(raw, path, "name -> vector (null: the global point)")
            for n, v in own.items():
                _name(n, path + (n,), "a point name")
                if v is None and n not in points:
                    raise InputError(
                        f"{n!r} is not a point of the drawing; give its coordinates",
                        path=path + (n,),
                        suggestions=suggest(str(n), points),
                    )
        bodies.append(Body(name, own, desc, ("bodies", name)))
    names = [b.name for b in bodies]
    if of_legs:  # a mixed file: the legs' ground is 'ground'; its bodies join the file's
        if "base" in names:
            raise InputError(
                "the legs' fixed body is 'ground': name it so here too", path=("bodies", "base"), suggestions=["ground"]
            )
        for b in of_legs:
            if b not in names:
                bodies.append(Body(b, {}, "", ("legs",)))
        names = [b.name for b in bodies]
    if not any(n in GROUND_NAMES for n in names):
        raise InputError(
            f"no ground: name the fixed body 'ground' (or 'base'); the bodies are {', '.join(names)}",
            path=("bodies",),
            suggestions=suggest("ground", names),
        )
    if all(n in names for n in GROUND_NAMES):
        raise InputError("two grounds: 'ground' and 'base' name the same fixed body; keep one", path=("bodies", "base"))
    joints_raw = _list(data.get("joints"), ("joints",), "a list of joints {type, between: [body, body], at, ...}")
    _check_size(len(joints_raw), MAX_JOINTS, "joints", ("joints",))
    _check_size(len(bodies), MAX_JOINTS, "bodies", ("bodies",))
    joints = [_joint(j, ("joints", k), {}, graph=True) for k, j in enumerate(joints_raw)]
    seen: dict[str, int] = {}
    for k, j in enumerate(joints):
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
        for key in ("at", "to"):
            v = getattr(j, key)
            if isinstance(v, str) and v.isidentifier():
                for b in j.between:
                    body = bodies[names.index(b)]
                    if v not in body.points and v not in points:
                        raise InputError(
                            f"{v!r} is not a point of {b!r} nor of the drawing; {b!r} carries "
                            f"{', '.join(body.points) or 'no points'}",
                            path=("joints", k, key),
                            suggestions=suggest(v, list(body.points) + list(points)),
                        )
    outputs = {}
    for name, raw in _mapping(data.get("outputs") or {}, ("outputs",), "name -> body.point").items():
        path = ("outputs", name)
        _name(name, path, "an output name")
        desc = ""
        if isinstance(raw, Mapping):
            raw = _mapping(raw, path, "{point, description}", {"point": "body.point", "description": ""})
            desc = _text(raw.get("description"), path + ("description",))
            raw, path = raw.get("point"), path + ("point",)
        body, _, point = str(raw).partition(".")
        if body not in names:
            raise InputError(
                f"expected body.point with a body of the file, got {raw!r}",
                path=path,
                suggestions=suggest(body, names),
            )
        b = bodies[names.index(body)]
        if point not in b.points:
            raise InputError(
                f"{point!r} is not a point of {body!r}; it carries {', '.join(b.points) or 'no points'}",
                path=path,
                suggestions=suggest(point, b.points),
            )
        outputs[name] = (body, point, desc)
    return points, bodies, joints, outputs


def description_from_dict(data: Any, file: str | None = None) -> Description:  # noqa: C901 - one step per section
    """Read a mechanism description from a parsed mechanism file (errors carry key paths)."""
    if not isinstance(data, Mapping):  # not echoed: the file may be any file a problem file names
        size = f" of {len(data)} characters" if isinstance(data, str) else ""
        raise InputError(
            f"expected a mechanism description (a mapping with name, parameters, platform, legs), "
            f"got {'an empty file' if data is None else type(data).__name__ + size}"
        )
    data = _mapping(data, (), "a mechanism description (a mapping with name, parameters, platform, legs)", TOP)
    check_numbers(data)  # no inf, NaN or 1500-digit integer anywhere
    for key in ("name", "platform"):
        if key not in data:
            raise InputError(f"missing required key {key!r} ({TOP[key]})")
    name = _type_name(data["name"], ("name",))
    params = [
        _parameter(_name(n, ("parameters", n), "a parameter name"), v, ("parameters", n))
        for n, v in _mapping(data.get("parameters") or {}, ("parameters",), "name -> {dimension, default}").items()
    ]
    derived = [
        _quantity(_name(n, ("derived", n), "a name"), v, ("derived", n))
        for n, v in _mapping(data.get("derived") or {}, ("derived",), "name -> expression").items()
    ]
    passive = [
        _quantity(_name(n, ("passive", n), "a name"), v, ("passive", n))
        for n, v in _mapping(data.get("passive") or {}, ("passive",), "name -> {value, dimension}").items()
    ]
    actuators = {}
    for n, v in _mapping(data.get("actuators") or {}, ("actuators",), "name -> dimension").items():
        path = ("actuators", n)
        _name(n, path, "an actuator name")
        if isinstance(v, Mapping):
            v = _mapping(v, path, "{dimension, home}", {"dimension": "", "home": ""})
            actuators[n] = (_dimension(v.get("dimension"), path + ("dimension",)), v.get("home", 0))
        else:
            actuators[n] = (_dimension(v, path), 0)
    ik = None
    if data.get("ik") is not None:
        raw = _mapping(data["ik"], ("ik",), "{let, pose, actuators, reach}", IK_KEYS)
        ik = ClosedFormIK(
            _mapping(raw.get("let") or {}, ("ik", "let"), "name -> expression"),
            _mapping(raw.get("pose") or {}, ("ik", "pose"), "name -> expression"),
            _mapping(raw.get("actuators") or {}, ("ik", "actuators"), "name -> expression"),
            raw.get("reach"),
        )
    examples = _list(data.get("examples") or [], ("examples",), "a list of problem files")
    limits = {
        _name(n, ("limits", n), "a joint-limit family"): _text(v, ("limits", n))
        for n, v in _mapping(data.get("limits") or {}, ("limits",), "joint-limit family -> description").items()
    }
    legs = _legs(data.get("legs") or [], ("legs",))
    check_bodies(legs)
    graph: tuple = ({}, [], [], {})
    if data.get("bodies") is not None:
        graph = _graph(data, legs)
    else:
        for key in ("points", "joints", "outputs"):
            if data.get(key) is not None:
                raise InputError(
                    f"{key!r} belongs to a file of bodies and joints, and this file has no 'bodies'",
                    path=(key,),
                    hint="declare the bodies (name -> the points it carries), or describe the legs",
                )
    return Description(
        name=name,
        title=_text(data.get("title"), ("title",)) or name,
        parameters=params,
        platform=_platform(data["platform"], ("platform",), graph=data.get("bodies") is not None),
        legs=legs,
        derived=derived,
        actuators=actuators,
        closures=list(_list(data.get("closures") or [], ("closures",), "a list of expressions")),
        branch=_branch(data.get("branch"), ("branch",)) if "branch" in data else None,
        passive=passive,
        ik=ik,
        characteristic_length=data.get("characteristic_length"),
        paper=_text(data.get("paper"), ("paper",)),
        examples=tuple(str(e) for e in examples),
        limits=limits,
        stiffness=None if data.get("stiffness") is None else _stiffness(data["stiffness"], ("stiffness",)),
        file=file,
        points=graph[0],
        bodies=graph[1],
        joints=graph[2],
        outputs=graph[3],
    )
