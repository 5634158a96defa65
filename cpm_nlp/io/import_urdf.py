"""A URDF mechanism, with the loop closures of an "Extended URDF" sidecar, as a mechanism file.

The formats read (learnt from their public descriptions, no code taken from them):

* **URDF** (ROS): a ``<robot>`` of ``<link name>`` and ``<joint name type>`` elements; a joint
  has a ``<parent link>``, a ``<child link>``, an ``<origin xyz rpy>`` (the child link's frame
  in the parent link's frame at joint value 0; rpy are fixed-axis roll, pitch, yaw:
  R = Rz(yaw) Ry(pitch) Rx(roll)) and an ``<axis xyz>`` in that frame (default 1 0 0).  Types
  read: ``revolute`` and ``continuous`` (R), ``prismatic`` (P), ``fixed`` (the two links are one
  body).  The links form a tree.
* **The Extended URDF sidecar** (``robot.yaml``; V. Batto, L. de Matteis, N. Mansard,
  "Extended URDF: accounting for parallel mechanism in robot description", arXiv:2504.04767,
  and its examples github.com/Gepetto/example-parallel-robots, robots/*/robot.yaml):
  ``closed_loop: [[frame_A, frame_B], ...]`` the loop closures, each between two frames (a
  joint or link name: the frame of that joint's child link, or of that link);
  ``type: ['6d' | '3d', ...]`` for each closure (6d: the two frames coincide -- the two bodies
  are welded; 3d: their origins coincide -- a spherical joint); ``name_mot: [joint, ...]`` the
  actuated joints; ``joint_name`` / ``joint_type``: joints read as another type
  (``SPHERICAL``, ``FIXED``, ``UJOINT_XY`` ... -- a universal joint about the joint frame's
  X then Y axis).

What is written: a mechanism file of bodies and joints (``bodies:``, ``joints:``; see
docs/site/guide/mechanism-files.md) whose drawing is the URDF's zero configuration in world
coordinates (the root link's frame), lengths in metres.  Every non-fixed URDF joint is a joint
between the bodies of its parent and child links, at the origin of its frame, its axis a world
direction; each 3d closure is an S joint, each 6d closure merges the two bodies.  A body that
only links two joints turning about one axis or point (the dummy links at which example files
close their loops, or between revolutes crossing at one point: a U, an S) is removed and its
two joints become one; a passive joint to a body that
carries nothing else (a free spin) is dropped; a rod between two S joints is a distance joint
(or, where the mechanism hangs on it, keeps its body with a U instead of one S).  An actuated
joint's actuator is named after it, its own coordinate ``<name>_joint``.  All R axes parallel
(and P axes normal to them): a planar file, in the plane normal to the axes.

The URDF is data: it is parsed with :mod:`xml.etree.ElementTree` after refusing any document
type declaration or entity (``<!DOCTYPE``, ``<!ENTITY``), nothing it names (meshes, xacro
includes, ``package://`` paths) is ever opened, and its size and element count are capped.
Errors are :class:`~cpm_nlp.core.errors.InputError` naming the file and the element
(``joint[mot1].origin.rpy``) or the sidecar's key path (``closed_loop[0][1]``).
"""

from __future__ import annotations

import logging
import math
import re
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import casadi as ca
import numpy as np

from ..core.errors import InputError, suggest, unknown_key_error
from ..core.screws import axis_rotation
from .inputs import MAX_INPUT_BYTES, display_name, read_input_text
from .yamlfile import read_yaml

log = logging.getLogger(__name__)

#: Most links and joints a URDF may hold (a mechanism file holds at most 512 joints).
MAX_LINKS = MAX_JOINTS = 512
#: Most XML elements in a URDF (visuals, inertias, ... included).
MAX_ELEMENTS = 50_000
#: Most closures a sidecar may name.
MAX_CLOSURES = 256
#: Two lengths closer than this (times the drawing's size) are one point; two unit vectors
#: closer than this are one direction.
TOL = 1e-9
#: |coordinate| below this (times the drawing's size) is written as 0 (round-off of the frames).
ZERO = 1e-14

_URDF_TYPES = {"revolute": "R", "continuous": "R", "prismatic": "P", "fixed": "fixed"}
_UNSUPPORTED_TYPES = {
    "floating": "a floating joint (6 degrees of freedom) joins nothing",
    "planar": "a URDF planar joint (3 degrees of freedom) has no joint type in a mechanism file",
}
_SIDECAR_KEYS = {
    "closed_loop": "[[frame_A, frame_B], ...]: the loop closures",
    "type": "['6d' | '3d', ...]: one per closure",
    "name_mot": "[joint, ...]: the actuated joints",
    "joint_name": "[joint, ...]: joints read as another type (joint_type)",
    "joint_type": "[SPHERICAL | FIXED | UJOINT_XY | ..., ...]: one per joint_name",
}
_REPLACEMENTS = ("SPHERICAL", "FIXED") + tuple(f"UJOINT_{a}{b}" for a in "XYZ" for b in "XYZ" if a != b)
#: names a file's expressions keep for themselves (functions, constants)
_RESERVED = {
    "sin", "cos", "tan", "asin", "acos", "atan", "atan2", "sqrt", "exp", "log", "abs", "min", "max",
    "hypot", "norm", "dot", "cross", "unit", "select", "pi",
}  # fmt: skip
#: words YAML 1.1 reads as booleans or null (quoted when written)
_YAML_WORDS = {"y", "n", "yes", "no", "on", "off", "true", "false", "null"}
_GROUND_NAMES = ("ground", "base")
_NAME = re.compile(r"[A-Za-z](?:_?[A-Za-z0-9]){0,63}")
_DECLARATION = re.compile(r"<!(?!--|\[CDATA\[)")


# -- reading the URDF ----------------------------------------------------------------------------


@dataclass
class _Joint:
    """A URDF joint as read (lengths in metres, angles in radians)."""

    name: str
    kind: str  # R, P, fixed; S, U after the sidecar's joint_type
    parent: str
    child: str
    origin: np.ndarray  # 4x4: the child link's frame in the parent link's frame
    axis: np.ndarray  # unit, in the joint (child) frame
    limits: tuple[float, float] | None
    path: tuple
    u_axes: tuple[int, int] = (0, 1)  # a U joint: which axes of the joint frame (0 x, 1 y, 2 z)


def _rpy(roll: float, pitch: float, yaw: float) -> np.ndarray:
    """URDF's fixed-axis roll, pitch, yaw: R = Rz(yaw) Ry(pitch) Rx(roll)."""
    cr, sr, cp, sp, cy, sy = (
        math.cos(roll),
        math.sin(roll),
        math.cos(pitch),
        math.sin(pitch),
        math.cos(yaw),
        math.sin(yaw),
    )
    rx = np.array([[1.0, 0.0, 0.0], [0.0, cr, -sr], [0.0, sr, cr]])
    ry = np.array([[cp, 0.0, sp], [0.0, 1.0, 0.0], [-sp, 0.0, cp]])
    rz = np.array([[cy, -sy, 0.0], [sy, cy, 0.0], [0.0, 0.0, 1.0]])
    return rz @ ry @ rx


def _numbers(elem: ET.Element, attr: str, n: int, default: tuple, file: str, path: tuple) -> tuple:
    text = elem.get(attr)
    if text is None:
        return default
    parts = text.split()
    try:
        values = tuple(float(p) for p in parts)
    except ValueError:
        values = ()
    if len(values) != n or not all(math.isfinite(v) for v in values):
        raise InputError(
            f"expected {n} finite numbers separated by spaces, got {text!r:.80}", file=file, path=path + (attr,)
        )
    return values


def _check_text(text: str, file: str) -> None:
    """Refuse what XML could expand or fetch: any declaration (DOCTYPE, ENTITY, ...)."""
    m = _DECLARATION.search(text)
    if m is not None:
        line = text.count("\n", 0, m.start()) + 1
        word = re.match(r"<!\s*([A-Za-z]*)", text[m.start() :]).group(1) or "declaration"
        raise InputError(
            f"line {line}: a <!{word}> declaration; a URDF is read without document types or entities",
            file=file,
            path=("robot",),
            hint="remove the declaration: entities are not expanded and nothing outside the file is read",
        )


def _parse(text: str, file: str) -> ET.Element:
    _check_text(text, file)
    try:
        root = ET.fromstring(text)
    except ET.ParseError as exc:
        line, col = getattr(exc, "position", (0, 0))
        raise InputError(f"malformed XML: line {line}, column {col + 1}: {str(exc).split(':')[0]}", file=file) from None
    count = 0
    for elem in root.iter():
        count += 1
        if count > MAX_ELEMENTS:
            raise InputError(f"more than {MAX_ELEMENTS} XML elements", file=file, path=("robot",))
        tag = elem.tag if isinstance(elem.tag, str) else ""
        if tag.startswith("{") or tag == "include":
            space, _, local = tag[1:].rpartition("}")
            raise InputError(
                f"the element <{local}>"
                + (f" of the namespace {space}" if space else "")
                + " is a macro or an include; a URDF is read as it is",
                file=file,
                path=("robot", local),
                hint="expand a .xacro file first with xacro; nothing it names is opened",
            )
    if root.tag != "robot":
        raise InputError(f"expected a URDF: the root element is <{root.tag}>, not <robot>", file=file)
    return root


def _read_urdf(root: ET.Element, file: str) -> tuple[str, list[str], list[_Joint]]:  # noqa: C901 - one check per element
    links: list[str] = []
    for k, elem in enumerate(root.findall("link")):
        name = elem.get("name")
        if not name:
            raise InputError("a link without a name", file=file, path=(f"link[{k}]", "name"))
        if name in links:
            raise InputError(f"the link {name!r} is declared twice", file=file, path=(f"link[{name}]",))
        links.append(name)
        if len(links) > MAX_LINKS:
            raise InputError(f"more than {MAX_LINKS} links", file=file, path=("link",))
    joints: list[_Joint] = []
    names: set[str] = set()
    for k, elem in enumerate(root.findall("joint")):
        name = elem.get("name")
        if not name:
            raise InputError("a joint without a name", file=file, path=(f"joint[{k}]", "name"))
        path = (f"joint[{name}]",)
        if name in names:
            raise InputError(f"the joint {name!r} is declared twice", file=file, path=path)
        names.add(name)
        if len(names) > MAX_JOINTS:
            raise InputError(f"more than {MAX_JOINTS} joints", file=file, path=("joint",))
        urdf_type = elem.get("type")
        if urdf_type in _UNSUPPORTED_TYPES:
            raise InputError(
                f"unsupported joint type {urdf_type!r}: {_UNSUPPORTED_TYPES[urdf_type]}",
                file=file,
                path=path + ("type",),
            )
        if urdf_type not in _URDF_TYPES:
            raise InputError(
                f"unknown joint type {urdf_type!r}; expected one of: {', '.join(_URDF_TYPES)}",
                file=file,
                path=path + ("type",),
                suggestions=suggest(str(urdf_type), _URDF_TYPES),
            )
        ends = {}
        for end in ("parent", "child"):
            sub = elem.find(end)
            link = None if sub is None else sub.get("link")
            if not link:
                raise InputError(f"expected <{end} link='...'/>", file=file, path=path + (end,))
            if link not in links:
                raise InputError(
                    f"unknown link {link!r}",
                    file=file,
                    path=path + (end, "link"),
                    suggestions=suggest(link, links),
                )
            ends[end] = link
        if ends["parent"] == ends["child"]:
            raise InputError(f"the joint joins the link {ends['parent']!r} to itself", file=file, path=path)
        if elem.find("mimic") is not None:
            raise InputError(
                "a mimic joint (one joint's value a function of another's) is not a joint between bodies",
                file=file,
                path=path + ("mimic",),
                hint="remove <mimic> and make the coupling a closure of the sidecar",
            )
        origin = np.eye(4)
        sub = elem.find("origin")
        if sub is not None:
            xyz = _numbers(sub, "xyz", 3, (0.0, 0.0, 0.0), file, path + ("origin",))
            rpy = _numbers(sub, "rpy", 3, (0.0, 0.0, 0.0), file, path + ("origin",))
            origin[:3, :3] = _rpy(*rpy)
            origin[:3, 3] = xyz
        axis = np.array([1.0, 0.0, 0.0])
        sub = elem.find("axis")
        if sub is not None:
            axis = np.array(_numbers(sub, "xyz", 3, (1.0, 0.0, 0.0), file, path + ("axis",)))
        kind = _URDF_TYPES[urdf_type]
        if kind != "fixed":
            norm = float(np.linalg.norm(axis))
            if not norm > 1e-12:
                raise InputError("expected a nonzero axis, got 0 0 0", file=file, path=path + ("axis", "xyz"))
            axis = axis / norm
        limits = None
        sub = elem.find("limit")
        if sub is not None and urdf_type in ("revolute", "prismatic") and sub.get("lower") and sub.get("upper"):
            lo = _numbers(sub, "lower", 1, (0.0,), file, path + ("limit",))[0]
            hi = _numbers(sub, "upper", 1, (0.0,), file, path + ("limit",))[0]
            limits = (lo, hi) if lo < hi else None
        joints.append(_Joint(name, kind, ends["parent"], ends["child"], origin, axis, limits, path))
    if not links:
        raise InputError("the robot has no links", file=file, path=("robot",))
    return root.get("name") or "", links, joints


def _tree(links: list[str], joints: list[_Joint], file: str) -> tuple[str, list[str], dict[str, _Joint]]:
    """The root link, the links in tree order (each after its parent) and each link's parent joint."""
    parent_joint: dict[str, _Joint] = {}
    for j in joints:
        if j.child in parent_joint:
            other = parent_joint[j.child].name
            raise InputError(
                f"the link {j.child!r} is the child of two joints, {other!r} and {j.name!r}: a URDF is a tree",
                file=file,
                path=j.path + ("child", "link"),
                hint="close a loop in the sidecar's closed_loop: [[frame_A, frame_B]], not with a second parent",
            )
        parent_joint[j.child] = j
    roots = [lk for lk in links if lk not in parent_joint]
    children: dict[str, list[_Joint]] = {lk: [] for lk in links}
    for j in joints:
        children[j.parent].append(j)
    if len(roots) > 1:
        raise InputError(
            f"the links are not one tree: {', '.join(roots[:6])} have no parent joint",
            file=file,
            path=("robot",),
            hint="join every link to the rest by a joint (a fixed joint for a rigid attachment)",
        )
    order = [roots[0]] if roots else []
    for lk in order:
        order += [j.child for j in children[lk]]
    if len(order) < len(links):
        start = next(lk for lk in links if lk not in order)
        cycle, lk = [start], parent_joint[start].parent
        while lk not in cycle:
            cycle.append(lk)
            lk = parent_joint[lk].parent
        loop = cycle[cycle.index(lk) :][::-1]  # parent -> child
        raise InputError(
            f"the joints form a cycle: {' -> '.join(loop + [loop[0]])}; a URDF is a tree",
            file=file,
            path=parent_joint[start].path,
            hint="cut the loop at one joint and close it in the sidecar's closed_loop",
        )
    return roots[0], order, parent_joint


# -- the sidecar ----------------------------------------------------------------------------------


@dataclass
class _Sidecar:
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


def _read_sidecar(path: str) -> _Sidecar:  # noqa: C901 - one check per key
    file = display_name(path)
    data = read_yaml(path)
    if data is None:
        return _Sidecar()
    if not isinstance(data, dict):
        raise InputError(f"expected a mapping of {', '.join(_SIDECAR_KEYS)}, got {type(data).__name__}", file=file)
    for key in data:
        if key not in _SIDECAR_KEYS:
            raise unknown_key_error(str(key), _SIDECAR_KEYS, (str(key),), "Extended URDF sidecar key").at(file=file)
    out = _Sidecar()
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
        out.closures.append((pair[0], pair[1], str(kind).lower(), ("closed_loop", k)))
    out.motors = [(m, ("name_mot", k)) for k, m in enumerate(_names_list(data.get("name_mot"), "name_mot", file))]
    names = _names_list(data.get("joint_name"), "joint_name", file)
    kinds = _names_list(data.get("joint_type"), "joint_type", file)
    if len(names) != len(kinds):
        raise InputError(
            f"expected one joint_type for each of the {len(names)} joint_name entries, got {len(kinds)}",
            file=file,
            path=("joint_type",),
        )
    for k, (n, t) in enumerate(zip(names, kinds)):
        if t not in _REPLACEMENTS:
            raise InputError(
                f"unknown joint type {t!r}; expected one of: {', '.join(_REPLACEMENTS)}",
                file=file,
                path=("joint_type", k),
                suggestions=suggest(t, _REPLACEMENTS),
            )
        out.replace[n] = (t, ("joint_name", k))
    return out


# -- the graph --------------------------------------------------------------------------------------


@dataclass
class _GJoint:
    """A joint of the graph being built (bodies by key, coordinates in world at the drawing)."""

    kind: str  # R, P, S, U
    a: str
    b: str
    point: str
    axis: np.ndarray | None = None
    axes: tuple[np.ndarray, np.ndarray] | None = None
    actuated: bool = False
    name: str = ""
    source: str = ""  # the URDF joint or closure it comes from
    limits: tuple[float, float] | None = None
    coordinate: str = ""  # an actuated joint's own coordinate (its actuator is named after the joint)
    to: str = ""  # a distance joint: its point on b
    home: float = 0.0  # an R or P joint's URDF value at the drawing
    rod: np.ndarray | None = None  # ... and the rod (b's end less a's end, in the rod's drawing)


@dataclass
class _Graph:
    names: dict[str, str]  # body key -> name written
    points: dict[str, dict[str, np.ndarray]]  # body key -> point -> world coordinates at the drawing
    joints: list[_GJoint]
    notes: list[str]
    scale: float = 1.0
    renamed: dict[str, str] = field(default_factory=dict)  # URDF name -> name written


class _Names:
    """Names as a mechanism file takes them (a letter, then letters, digits and single
    underscores), each used once; the renamed ones are remembered for the file's header."""

    def __init__(self) -> None:
        self.used: set[str] = set()
        self.renamed: dict[str, str] = {}

    def take(self, raw: str, prefix: str = "", avoid: tuple = ()) -> str:
        text = re.sub(r"[^A-Za-z0-9]+", "_", prefix + raw).strip("_")
        if not text or not text[0].isalpha():
            text = "n_" + text if text else "n"
        text = text[:60].rstrip("_")
        if text.lower() in _YAML_WORDS or text in _RESERVED or text in avoid:
            text += "_1"
        name, k = text, 2
        while name in self.used:
            name, k = f"{text}_{k}", k + 1
        self.used.add(name)
        if name != prefix + raw:
            self.renamed[prefix + raw] = name
        return name


#: Gauss-Newton steps of the assembly, and the residual it reaches (times the drawing's size)
ASSEMBLY_STEPS, ASSEMBLY_TOL = 500, 1e-12
_DOF = {"R": 1, "P": 1, "S": 3, "U": 2, "fixed": 0}


def _rot(axis: Any, angle: Any) -> ca.SX:
    """Rodrigues: the rotation by ``angle`` about the unit ``axis`` (:func:`~cpm_nlp.core.screws.axis_rotation`)."""
    return ca.SX(axis_rotation(ca.SX(ca.DM(np.asarray(axis, dtype=float).reshape(3, 1))), angle))


def _motion(j: _Joint, v: ca.SX) -> ca.SX:
    """The child's frame in the joint frame for the joint values ``v`` (4x4)."""
    m = ca.SX.eye(4)
    e = np.eye(3)
    if j.kind == "R":
        m[:3, :3] = _rot(j.axis, v[0])
    elif j.kind == "P":
        m[:3, 3] = ca.DM(j.axis) * v[0]
    elif j.kind == "S":
        m[:3, :3] = _rot(e[0], v[0]) @ _rot(e[1], v[1]) @ _rot(e[2], v[2])
    elif j.kind == "U":
        m[:3, :3] = _rot(e[j.u_axes[0]], v[0]) @ _rot(e[j.u_axes[1]], v[1])
    return m


def _kinematics(order: list[str], parent_joint: dict[str, _Joint]) -> tuple[ca.Function, dict[str, tuple[int, int]]]:
    """Every link's frame in the world (4x4, column-major, one after another in ``order``) as a
    function of the joint values, and each joint's slice of those values."""
    slots, n = {}, 0
    for lk in order[1:]:
        j = parent_joint[lk]
        slots[j.name] = (n, n + _DOF[j.kind])
        n += _DOF[j.kind]
    q = ca.SX.sym("q", n)
    frame = {order[0]: ca.SX.eye(4)}
    for lk in order[1:]:
        j = parent_joint[lk]
        frame[lk] = frame[j.parent] @ ca.DM(j.origin) @ _motion(j, q[slots[j.name][0] : slots[j.name][1]])
    out = ca.vertcat(*[ca.reshape(frame[lk], 16, 1) for lk in order])
    return ca.Function("urdf_frames", [q], [out], ["q"], ["frames"]), slots


def _world(frames: ca.Function, values: np.ndarray, order: list[str]) -> dict[str, np.ndarray]:
    flat = np.asarray(frames(values)).ravel()
    return {lk: flat[16 * k : 16 * k + 16].reshape(4, 4, order="F") for k, lk in enumerate(order)}


def _assemble(
    frames: ca.Function, order: list[str], pairs: list[tuple[str, str, str]], held: list[int], scale: float
) -> tuple[np.ndarray, str]:
    """Joint values that close the loops, from the URDF's zero configuration: a 3d closure brings
    the two frames' origins together, a 6d closure the frames.  Levenberg-Marquardt steps with
    CasADi's AD Jacobian (redundant rows are fine), first with the ``held`` (actuated) joints at
    0, then, if that fails, with them free too.  If the loops do not close, the zero
    configuration, and a note that says by how much they stay open."""
    q = ca.SX.sym("q", frames.size1_in(0))
    flat = frames(q)
    index = {lk: k for k, lk in enumerate(order)}

    def frame(lk: str) -> ca.SX:
        return ca.reshape(flat[16 * index[lk] : 16 * index[lk] + 16], 4, 4)

    rows = []
    for la, lb, kind in pairs:
        ta, tb = frame(la), frame(lb)
        rows.append(ta[:3, 3] - tb[:3, 3])
        if kind == "6d":  # the whole rotation matrices: zero at the same frame only (not at a half turn)
            rows.append(ca.reshape(ta[:3, :3] - tb[:3, :3], 9, 1) * scale)
    fn = ca.Function("urdf_loops", [q], [ca.vertcat(*rows), ca.jacobian(ca.vertcat(*rows), q)], ["q"], ["r", "J"])
    tol = ASSEMBLY_TOL * scale
    start = float(np.max(np.abs(np.asarray(fn(np.zeros(q.size1()))[0]))))
    if start <= tol:
        return np.zeros(q.size1()), ""
    left = start
    for fixed in (set(held), set()):
        free = [k for k in range(q.size1()) if k not in fixed]
        if not free:
            continue
        values, reached = _levenberg_marquardt(fn, q.size1(), free, tol)
        if reached <= tol:
            return values, ""
        left = min(left, reached)
    return np.zeros(q.size1()), (
        f"the loops do not close from the URDF's zero configuration (largest closure residual {start:.3g}, "
        f"at best {left:.3g}): the drawing is the zero configuration"
    )


def _levenberg_marquardt(fn: ca.Function, n: int, free: list[int], tol: float) -> tuple[np.ndarray, float]:
    """Minimise |r(q)|^2 over the ``free`` values from q = 0; the values and the largest |r|."""
    values = np.zeros(n)
    r, jac = (np.asarray(v) for v in fn(values))
    r = r.ravel()
    cost, lam = float(r @ r), 1e-3
    for _step in range(ASSEMBLY_STEPS):
        if float(np.max(np.abs(r))) <= tol:
            break
        j = jac[:, free]
        g = j.T @ j
        step = np.linalg.solve(g + lam * (np.diag(np.diag(g)) + 1e-12 * np.eye(len(free))), -j.T @ r)
        longest = float(np.max(np.abs(step)))
        if longest > 0.5:  # at most half a radian (or half a metre) a step
            step *= 0.5 / longest
        trial = values.copy()
        trial[free] += step
        r2, jac2 = (np.asarray(v) for v in fn(trial))
        r2 = r2.ravel()
        if float(r2 @ r2) < cost:
            values, r, jac, cost, lam = trial, r2, jac2, float(r2 @ r2), max(lam / 3, 1e-12)
        else:
            lam *= 4
            if lam > 1e12:
                break
    return values, float(np.max(np.abs(r)))


def _frame(name: str, links: list[str], by_name: dict[str, _Joint], file: str, path: tuple) -> str:
    """The link whose frame a sidecar frame name is: a joint's child link, or the link itself."""
    if name in by_name:
        return by_name[name].child
    if name in links:
        return name
    raise InputError(
        f"no joint or link of the URDF is named {name!r}",
        file=file,
        path=path,
        suggestions=suggest(name, list(by_name) + links),
    )


def _build(  # noqa: C901 - one pass per step of the conversion
    links: list[str],
    joints: list[_Joint],
    root: str,
    order: list[str],
    sidecar: _Sidecar,
    actuated: list[str] | None,
    platform: str | None,
    urdf: str,
    side: str,
) -> tuple[_Graph, str, str, np.ndarray, bool]:
    """The bodies, joints and drawing of the mechanism; the platform body and its point; whether
    the drawing is the URDF's zero configuration moved to close the loops."""
    by_name = {j.name: j for j in joints}
    notes: list[str] = []
    # the sidecar's joint types
    for jname, (jtype, path) in sidecar.replace.items():
        if jname not in by_name:
            raise InputError(
                f"no joint of the URDF is named {jname!r}", file=side, path=path, suggestions=suggest(jname, by_name)
            )
        j = by_name[jname]
        if jtype == "FIXED":
            j.kind = "fixed"
        elif jtype == "SPHERICAL":
            j.kind = "S"
        else:
            j.kind = "U"
            j.u_axes = ("XYZ".index(jtype[-2]), "XYZ".index(jtype[-1]))
    # actuated joints: the option, else the sidecar
    if actuated is not None:
        wanted = [(a, ("--actuated",)) for a in actuated]
        afile = None
    else:
        wanted, afile = sidecar.motors, side
    act: set[str] = set()
    for a, path in wanted:
        j = by_name.get(a)
        if j is None:
            raise InputError(
                f"no joint of the URDF is named {a!r}", file=afile, path=path, suggestions=suggest(a, by_name)
            )
        if j.kind not in ("R", "P"):
            raise InputError(
                f"the joint {a!r} is {'fixed' if j.kind == 'fixed' else 'a ' + j.kind + ' joint'}; "
                "an actuated joint is revolute, continuous or prismatic",
                file=afile,
                path=path,
            )
        act.add(a)
    # the drawing: each link's frame in the world (the root link's frame), the loops closed from
    # the URDF's zero configuration with the actuated joints held at 0 where they can be
    parent_joint = {j.child: j for j in joints}
    frames, slots = _kinematics(order, parent_joint)
    values = np.zeros(frames.size1_in(0))
    world = _world(frames, values, order)
    assembled = False
    scale = max([1e-3] + [float(np.linalg.norm(t[:3, 3])) for t in world.values()])
    if sidecar.closures:
        pairs = [
            (_frame(fa, links, by_name, side, path + (0,)), _frame(fb, links, by_name, side, path + (1,)), kind)
            for fa, fb, kind, path in sidecar.closures
        ]
        held = [k for j in joints if j.name in act for k in range(*slots[j.name])]
        values, note = _assemble(frames, order, pairs, held, scale)
        if note:
            notes.append(note)
        world = _world(frames, values, order)
        assembled = bool(np.any(values != 0))
        moved = [j.name for j in joints if j.name in act and np.any(values[slots[j.name][0] : slots[j.name][1]])]
        if moved:
            notes.append(
                f"the loops do not close with the actuated joints at 0: the drawing has {', '.join(moved)} "
                "at other values (their home)"
            )
    # bodies: the links joined by fixed joints are one body (its key: its top link)
    body_of: dict[str, str] = {}
    for lk in order:
        j = parent_joint.get(lk)
        body_of[lk] = body_of[j.parent] if j is not None and j.kind == "fixed" else lk
    points: dict[str, dict[str, np.ndarray]] = {body_of[lk]: {} for lk in order}
    names, bnames, pnames = _Names(), _Names(), _Names()  # joints and coordinates, bodies, points
    bnames.used.add("ground")
    body_names: dict[str, str] = {}
    for key in points:
        body_names[key] = "ground" if key == root else bnames.take(key, avoid=_GROUND_NAMES)
    # the tree's joints
    gjoints: list[_GJoint] = []
    for j in joints:
        if j.kind == "fixed":
            continue
        frame = world[j.child]
        name = names.take(j.name)
        point = pnames.take(name, prefix="P_")
        pos = frame[:3, 3].copy()
        a, b = body_of[j.parent], body_of[j.child]
        points[a][point] = pos
        points[b][point] = pos
        g = _GJoint(j.kind, a, b, point, name=name, source=f"joint {j.name!r}", actuated=j.name in act)
        if g.actuated:
            g.coordinate = names.take(name + "_joint")
        if j.kind in ("R", "P"):
            g.axis = frame[:3, :3] @ j.axis
            g.limits = j.limits
            g.home = float(values[slots[j.name][0]])  # the URDF's joint value at the drawing
        elif j.kind == "U":  # the first axis turns with the parent, the second with the child
            first = (world[j.parent] @ j.origin)[:3, j.u_axes[0]].copy()
            g.axes = (first, frame[:3, j.u_axes[1]].copy())
        gjoints.append(g)
    # the closures
    merged: dict[str, str] = {}  # a welded body -> the body it was welded to
    moves: dict[str, np.ndarray] = {}  # ... and the map of its drawing onto that body's

    def find(key: str) -> str:
        while key in merged:
            key = merged[key]
        return key

    def placed(link: str) -> np.ndarray:
        """The link's frame in the drawing of the body it is part of now (welds applied)."""
        key, t = body_of[link], world[link]
        while key in merged:
            t, key = moves[key] @ t, merged[key]
        return t

    for fa, fb, kind, path in sidecar.closures:
        la = _frame(fa, links, by_name, side, path + (0,))
        lb = _frame(fb, links, by_name, side, path + (1,))
        ba, bb = find(body_of[la]), find(body_of[lb])
        wa, wb = placed(la), placed(lb)
        if kind == "6d" and bb == root:  # the ground stays: the other body is welded to it
            fa, fb, la, lb, ba, bb, wa, wb = fb, fa, lb, la, bb, ba, wb, wa
        gap = float(np.linalg.norm(wa[:3, 3] - wb[:3, 3]))
        if ba == bb:
            raise InputError(
                f"the frames {fa!r} and {fb!r} are on one rigid body ({body_names[ba]!r}): the closure joins nothing",
                file=side,
                path=path,
            )
        if kind == "3d":
            name = names.take(fa)
            point = pnames.take(name, prefix="P_")
            points[ba][point] = wa[:3, 3].copy()
            points[bb][point] = wb[:3, 3].copy()
            gjoints.append(_GJoint("S", ba, bb, point, name=name, source=f"closure {fa!r}-{fb!r} (3d)"))
            continue
        # 6d: the frames coincide -- body bb is welded to body ba, its drawing moved by Wa Wb^-1
        move = wa @ np.linalg.inv(wb)
        turn = float(np.degrees(np.arccos(np.clip((np.trace(move[:3, :3]) - 1) / 2, -1.0, 1.0))))
        opened = ""
        if gap > TOL * scale or turn > 1e-7:
            opened = f" (the frames are {gap:.3g} m and {turn:.3g} deg apart in the URDF's zero configuration)"
        for p, v in points.pop(bb).items():
            points[ba].setdefault(p, move[:3, :3] @ v + move[:3, 3])
        merged[bb], moves[bb] = ba, move
        notes.append(f"closure {fa!r}-{fb!r} (6d): {body_names[bb]!r} is welded to {body_names[ba]!r}{opened}")
        for g in gjoints:
            g.a, g.b = find(g.a), find(g.b)
        for g in [g for g in gjoints if g.a == g.b]:
            notes.append(f"{g.source} is locked by the weld and left out")
            gjoints.remove(g)
    for g in gjoints:
        g.a, g.b = find(g.a), find(g.b)
    # the platform: a frame (a joint or link name), else a link named platform/effector/end_effector
    if platform is None:
        platform = next((lk for lk in ("platform", "effector", "end_effector") if lk in links), None)
        if platform is None:
            raise InputError(
                "which body is the platform? No link is named platform, effector or end_effector",
                file=urdf,
                path=("robot",),
                hint="give --platform FRAME, a link or joint name of the URDF",
            )
        plink, ppath, pfile = platform, ("link", platform), urdf
    else:
        plink, ppath, pfile = _frame(platform, links, by_name, None, ("--platform",)), ("--platform",), None
    pbody = find(body_of[plink])
    if pbody == root:
        raise InputError(f"the platform frame {platform!r} is on the ground", file=pfile, path=ppath)
    ppoint = pnames.take(platform, prefix="P_")
    pframe = placed(plink)
    points[pbody][ppoint] = pframe[:3, 3].copy()
    graph = _Graph(body_names, points, gjoints, notes, scale, {**bnames.renamed, **names.renamed})
    _simplify(graph, root, keep={root, pbody})
    return graph, pbody, ppoint, pframe, assembled


def _simplify(graph: _Graph, ground: str, keep: set[str]) -> None:
    """Remove the bodies (not the ground nor the platform's) that only carry passive joints
    adding a free spin, until none is left: a body on one joint and nothing else; a body joined
    by two joints that turn about one axis (R, R coaxial: an R) or one point (two R crossing: a
    U; an S, or three independent axes through it: an S), whose two joints become one between
    its neighbours (a chain of three revolutes crossing at a point is two steps); a rod between
    two S joints, which becomes a distance joint of its length -- unless a body would then hang
    on distance joints only (a mechanism file joins every body to the ground by joints): then
    its S joint on the side of the ground is a U normal to it (the rod's spin is gone)."""
    while True:
        for key in list(graph.points):
            if key in keep:
                continue
            js = [g for g in graph.joints if key in (g.a, g.b)]
            if any(g.actuated for g in js):
                continue
            if len(js) == 1:
                graph.joints.remove(js[0])
                graph.notes.append(
                    f"{graph.names[key]!r} turns freely on {js[0].source} and carries nothing else: left out"
                )
                del graph.points[key]
                break
            if len(js) == 2 and all(g.kind in ("R", "U", "S") for g in js) and _join(graph, key, ground, *js):
                break
        else:
            return


def _join(graph: _Graph, key: str, ground: str, j1: _GJoint, j2: _GJoint) -> bool:
    """Replace the body ``key`` and its joints j1, j2 by one joint between its neighbours if
    they turn about one axis (R) or one point (two R axes crossing there: U; three or more
    independent axes through it: S), or are two S joints apart (a rod); False if not."""
    d = graph.points[key]
    ends = [g.b if g.a == key else g.a for g in (j1, j2)]
    if ends[0] == ends[1]:
        return False
    if j1.kind == j2.kind == "S" and np.linalg.norm(d[j2.point] - d[j1.point]) > TOL * graph.scale:
        return _rod(graph, key, ground, j1, j2, ends)
    found = _common(d, j1, j2, TOL * graph.scale)
    if found is None:
        return False
    centre, kind, axes = found
    # the proximal side first: the body of the first joint's proximal end
    a, b = (ends[0], ends[1]) if j1.b == key else (ends[1], ends[0])
    if kind == "U" and a != ends[0]:
        axes = (axes[1], axes[0])
    name = next((g.point for g in (j1, j2) if g.kind != "R"), j1.point)
    for g, other in zip((j1, j2), ends):
        # along the joint's axis (or zero): the same vector in both bodies
        graph.points[other][name] = graph.points[other][g.point] + (centre - d[g.point])
    new = _GJoint(kind, a, b, name, name=j1.name)
    if kind == "R":
        new.axis = axes[0]
    elif kind == "U":
        new.axes = axes
    graph.notes.append(
        f"{graph.names[key]!r} only joins {j1.source} and {j2.source} about one "
        f"{'axis' if kind == 'R' else 'point'}: one {kind} joint"
    )
    _replace(graph, key, j1, j2, new, ends)
    return True


def _common(d: dict, j1: _GJoint, j2: _GJoint, tol: float) -> tuple[np.ndarray, str, tuple] | None:
    """The point about which both joints turn (on the body between them) and the joint they make
    together: R (coaxial R), U (two R crossing) or S (three independent axes, or an S)."""
    rs = [g for g in (j1, j2) if g.kind == "R"]
    if len(rs) == 2:
        p1, p2, a1, a2 = d[j1.point], d[j2.point], j1.axis, j2.axis
        if np.linalg.norm(np.cross(a1, a2)) <= TOL:
            return (p1, "R", (a1,)) if np.linalg.norm(np.cross(p2 - p1, a1)) <= tol else None
        s, u = np.linalg.lstsq(np.column_stack([a1, -a2]), p2 - p1, rcond=None)[0]
        c1, c2 = p1 + s * a1, p2 + u * a2
        return ((c1 + c2) / 2, "U", (a1, a2)) if np.linalg.norm(c1 - c2) <= tol else None
    c = next(d[g.point] for g in (j1, j2) if g.kind != "R")
    if any(g.kind != "R" and np.linalg.norm(d[g.point] - c) > tol for g in (j1, j2)):
        return None
    if any(np.linalg.norm(np.cross(c - d[g.point], g.axis)) > tol for g in rs):
        return None
    if "S" not in (j1.kind, j2.kind):  # R and U, or U and U: S if their axes span every direction
        axes = [g.axis for g in rs] + [ax for g in (j1, j2) if g.kind == "U" for ax in g.axes]
        if np.linalg.matrix_rank(np.array(axes), tol=1e-6) < 3:
            return None
    return c, "S", ()


def _rod(graph: _Graph, key: str, ground: str, j1: _GJoint, j2: _GJoint, ends: list[str]) -> bool:
    """A rod between two S joints: a distance joint of its length -- unless a body would then
    hang on distance joints only: then its S joint on the ground's side is a U normal to it."""
    d = graph.points[key]
    reach = _reached(graph, ground, without=(j1, j2))
    if any(b not in reach for b in graph.points if b != key):
        near = j1 if ends[0] in reach else j2
        rod = d[(j2 if near is j1 else j1).point] - d[near.point]
        ref = np.eye(3)[int(np.argmin(np.abs(rod)))]
        a1 = np.cross(rod, ref) / np.linalg.norm(np.cross(rod, ref))
        near.kind, near.axes = "U", (a1, np.cross(rod, a1) / np.linalg.norm(np.cross(rod, a1)))
        graph.notes.append(
            f"{graph.names[key]!r} is a rod between two S joints that the mechanism hangs on: "
            f"{near.source} is a U normal to it (without the rod's spin)"
        )
        return True
    a, b = (ends[0], ends[1]) if j1.b == key else (ends[1], ends[0])
    ja, jb = (j1, j2) if a == ends[0] else (j2, j1)
    new = _GJoint("distance", a, b, ja.point, name=j1.name, to=jb.point, rod=d[jb.point] - d[ja.point])
    graph.notes.append(
        f"{graph.names[key]!r} is a rod between {j1.source} and {j2.source}: a distance joint of its length"
    )
    _replace(graph, key, j1, j2, new, ends)
    return True


def _replace(graph: _Graph, key: str, j1: _GJoint, j2: _GJoint, new: _GJoint, ends: list[str]) -> None:
    """The body ``key`` and its joints j1, j2 gone, ``new`` in j1's place."""
    new.source = f"{j1.source} and {j2.source}"
    graph.joints[graph.joints.index(j1)] = new
    graph.joints.remove(j2)
    del graph.points[key]
    for other in ends:  # a point no joint uses any more is dropped
        used = {p for g in graph.joints if other in (g.a, g.b) for p in (g.point, g.to)}
        for p in [p for p in graph.points[other] if p not in used and p in (j1.point, j2.point)]:
            del graph.points[other][p]


def _reached(graph: _Graph, ground: str, without: tuple) -> set[str]:
    """The bodies joined to the ground by joints (distance joints and ``without`` left out)."""
    reach, grew = {ground}, True
    while grew:
        grew = False
        for g in graph.joints:
            if g.kind != "distance" and all(g is not w for w in without) and (g.a in reach) != (g.b in reach):
                reach |= {g.a, g.b}
                grew = True
    return reach


# -- writing ----------------------------------------------------------------------------------------


def _plane(graph: _Graph) -> np.ndarray | None:
    """The plane's basis (e1, e2, n) if every R axis is one direction n and every P axis is
    normal to it (S joints turn about n there); None otherwise."""
    rs = [g for g in graph.joints if g.kind == "R"]
    if not rs or any(g.kind == "U" for g in graph.joints):
        return None
    n = rs[0].axis / np.linalg.norm(rs[0].axis)
    big = int(np.argmax(np.abs(n)))
    if n[big] < 0:
        n = -n
    for g in graph.joints:
        if g.kind == "R" and np.linalg.norm(np.cross(g.axis, n)) > TOL:
            return None
        if g.kind == "P" and abs(float(np.dot(g.axis, n))) > TOL:
            return None
    w = np.eye(3)[(big + 1) % 3]  # z -> x, x -> y, y -> z: e1, e2 = x, y for n = z
    e1 = w - np.dot(w, n) * n
    e1 /= np.linalg.norm(e1)
    return np.array([e1, np.cross(n, e1), n])


def _num(v: float, scale: float) -> str:
    if abs(v) < ZERO * scale:
        return "0"
    text = repr(float(v))
    if "e" in text and "." not in text:  # YAML 1.1 reads 1e-05 as a string
        text = text.replace("e", ".0e")
    return text


def _vec(v: np.ndarray, scale: float) -> str:
    return "[" + ", ".join(_num(x, scale) for x in v) + "]"


def _word(name: str) -> str:
    return f"'{name}'" if name.lower() in _YAML_WORDS else name


@dataclass
class Imported:
    """A URDF imported as a mechanism file: its text (YAML), what it holds, and the notes
    (what was merged, simplified, renamed) that its header also carries."""

    text: str
    planar: bool
    bodies: dict[str, dict[str, list[float]]]
    joints: list[dict[str, Any]]
    notes: list[str]


def import_urdf(  # noqa: C901 - reads, builds and writes in one place
    path: str,
    sidecar: str | None = None,
    *,
    actuated: list[str] | None = None,
    name: str | None = None,
    platform: str | None = None,
    task: list[str] | None = None,
    planar: bool | None = None,
) -> Imported:
    """The mechanism file (bodies and joints) of the URDF ``path`` and its Extended URDF
    ``sidecar`` (closures, actuated joints, joint types).

    ``actuated``: the actuated joints (URDF names), instead of the sidecar's ``name_mot``.
    ``platform``: the frame (a link or joint name) whose body is the platform and whose origin
    is its point (default: a link named platform, effector or end_effector).  ``task``: the
    task coordinates, the platform's or passive joints' (default: by the number of actuators --
    planar 1: phi, 2: x, y, 3: x, y, phi; spatial 3: x, y, z, 6: all six).  ``planar``: None --
    a planar file when every R axis is one direction; False -- always spatial; True -- planar or
    an error.
    """
    file = display_name(path)
    text = read_input_text(path, limit=MAX_INPUT_BYTES)
    robot, links, joints = _read_urdf(_parse(text, file), file)
    root, order, _parents = _tree(links, joints, file)
    side = _read_sidecar(sidecar) if sidecar is not None else _Sidecar()
    side_name = display_name(sidecar) if sidecar is not None else None
    graph, pbody, ppoint, pframe, assembled = _build(
        links, joints, root, order, side, actuated, platform, file, side_name or file
    )
    n_act = sum(g.actuated for g in graph.joints)
    if n_act == 0:
        raise InputError(
            "no actuated joint: the sidecar names none (name_mot)",
            file=side_name or file,
            path=("name_mot",),
            hint="name them in the sidecar's name_mot or with --actuated J1,J2",
        )
    basis = _plane(graph)
    if planar is True and basis is None:
        raise InputError(
            "the mechanism is not planar: its R axes are not all one direction (or a P axis is not normal to them)",
            file=file,
            path=("robot",),
        )
    if planar is False:
        basis = None
    scale = graph.scale

    def coords(v: np.ndarray) -> np.ndarray:
        return basis[:2] @ v if basis is not None else v

    # the drawing's points: a point's global value is its first body's; a body that differs says its own
    glob: dict[str, np.ndarray] = {}
    for key in graph.points:
        for p, v in graph.points[key].items():
            glob.setdefault(p, coords(v))
    bodies: dict[str, dict[str, list[float] | None]] = {}
    for key, pts in graph.points.items():
        own: dict[str, list[float] | None] = {}
        for p, v in pts.items():
            c = coords(v)
            own[p] = None if np.linalg.norm(c - glob[p]) <= TOL * scale else [float(x) for x in c]
        bodies[graph.names[key]] = own
    lines_joints = []
    out_joints = []
    flipped: list[str] = []
    for g in graph.joints:
        kind = g.kind
        entry: dict[str, Any] = {"name": g.name}
        flip = 1.0
        if basis is not None:
            kind = {"R": "planar_R", "S": "planar_R", "P": "planar_P", "distance": "distance"}[kind]
            if g.kind == "R" and float(np.dot(g.axis, basis[2])) < 0:
                flip = -1.0
                if g.actuated or g.limits is not None or " and " not in g.source:
                    flipped.append(g.name)
        entry["type"] = kind
        entry["between"] = [graph.names[g.a], graph.names[g.b]]
        entry["at"] = g.point
        fields = [f"name: {_word(g.name)}", f"type: {kind}", f"between: [{', '.join(map(_word, entry['between']))}]"]
        fields.append(f"at: {_word(g.point)}")
        if g.kind == "distance":
            length = float(np.linalg.norm(coords(g.rod)))  # in a planar file, the rod's length in the plane
            entry["to"], entry["length"] = g.to, length
            fields += [f"to: {_word(g.to)}", f"length: {_num(length, scale)}"]
        if g.kind == "P" or (g.kind == "R" and basis is None):
            axis = coords(g.axis)
            axis = axis / np.linalg.norm(axis)
            entry["axis"] = [float(x) for x in axis]
            fields.append(f"axis: {_vec(axis, 1.0)}")
        if g.kind == "U":
            entry["axes"] = [[float(x) for x in a] for a in g.axes]
            fields.append(f"axes: [{_vec(g.axes[0], 1.0)}, {_vec(g.axes[1], 1.0)}]")
        if g.actuated:
            entry["actuated"], entry["coordinates"] = g.name, [g.coordinate]
            fields.append(f"actuated: {_word(g.name)}, coordinates: [{_word(g.coordinate)}]")
        elif g.kind in ("R", "P") and g.source.startswith("joint ") and " and " not in g.source:
            entry["coordinates"] = [g.name]
            fields.append(f"coordinates: [{_word(g.name)}]")
        if abs(g.home) > ZERO and g.kind in ("R", "P"):
            entry["home"] = flip * g.home
            fields.append(f"home: {_num(flip * g.home, 1.0)}")
        if g.limits is not None and g.kind in ("R", "P"):
            lo, hi = sorted((flip * g.limits[0], flip * g.limits[1]))
            entry["range"] = [lo, hi]
            fields.append(f"range: [{_num(lo, 1.0)}, {_num(hi, 1.0)}]")
        out_joints.append(entry)
        lines_joints.append("  - {" + ", ".join(fields) + "}")
    # the platform
    pxyz = coords(pframe[:3, 3])
    if basis is not None:
        coord_dims = {"x": "length", "y": "length", "phi": "angle"}
        position, rotation = "[x, y]", "[[z, phi]]"
        default_task = {1: ["phi"], 2: ["x", "y"], 3: ["x", "y", "phi"]}.get(n_act)
    else:
        coord_dims = {"x": "length", "y": "length", "z": "length", "psi": "angle", "theta": "angle", "phi": "angle"}
        position, rotation = "[x, y, z]", "[[z, phi], [y, theta], [x, psi]]"
        default_task = {3: ["x", "y", "z"], 6: list(coord_dims)}.get(n_act)
    if task is None:
        if default_task is None:
            raise InputError(
                f"which task coordinates for {n_act} actuated joint(s)? Choose {n_act} of {', '.join(coord_dims)}",
                path=("--task",),
                hint="give --task, e.g. --task " + ",".join(list(coord_dims)[:n_act]),
            )
        task = default_task
    passive = [c for j in out_joints if "actuated" not in j for c in j.get("coordinates", [])]
    for k, t in enumerate(task):
        if t not in coord_dims and t not in passive:
            raise InputError(
                f"unknown task coordinate {t!r}; expected one of: {', '.join(list(coord_dims) + passive)} "
                "(the platform's coordinates, or a passive joint's)",
                path=("--task", k),
                suggestions=suggest(t, list(coord_dims) + passive),
            )
    if len(set(task)) != len(task) or len(task) != n_act:
        raise InputError(
            f"expected {n_act} different task coordinates (one per actuated joint), got {', '.join(task)}",
            path=("--task",),
        )
    if name is not None and not _NAME.fullmatch(name):
        raise InputError(
            f"expected a mechanism name of at most 64 ASCII letters, digits and single underscores, "
            f"starting with a letter, got {name!r:.80}",
            path=("--name",),
        )
    mech_name = name or _mechanism_name(robot or Path(path).stem)
    header = [
        f"# {mech_name}: imported by cpm-nlp import from {Path(file).name} (URDF)"
        + (f" and {Path(side_name).name} (Extended URDF sidecar)" if side_name else "")
        + ".",
        "# The drawing is the URDF's "
        + ("configuration with the loops closed" if assembled else "zero configuration")
        + " in the root link's frame, lengths in metres (SI);",
        "# the reference pose is assembled from it with the actuators at 0 (their URDF zero).",
    ]
    if basis is not None:
        e1, e2, n = basis
        header.append(
            f"# Planar: every R axis is n = {_vec(n, 1.0)}; the plane's x, y are the URDF's "
            f"{_vec(e1, 1.0)}, {_vec(e2, 1.0)}."
        )
    notes = list(graph.notes)
    if flipped:
        notes.append("the URDF axis of " + ", ".join(flipped) + " is -n: the angle here (about n) is minus the URDF's")
    renamed = graph.renamed
    if renamed:
        notes.append("renamed: " + ", ".join(f"{k!r} -> {v}" for k, v in renamed.items()))
    header += [f"# - {n}" for n in notes]
    lines = header + [
        f"name: {mech_name}",
        f"title: {_title_text(robot or Path(file).stem)} imported from {_title_text(Path(file).name)}",
        "points:",
    ]
    lines += [f"  {_word(p)}: {_vec(v, scale)}" for p, v in glob.items()]
    lines.append("bodies:")
    for bname, own in bodies.items():
        if all(v is None for v in own.values()):
            lines.append(f"  {_word(bname)}: [{', '.join(map(_word, own))}]")
        else:
            inner = ", ".join(
                f"{_word(p)}: {'null' if v is None else _vec(np.array(v), scale)}" for p, v in own.items()
            )
            lines.append(f"  {_word(bname)}: {{points: {{{inner}}}}}")
    lines.append("joints:")
    lines += lines_joints
    home = ", ".join(f"{c}: {_num(v, scale)}" for c, v in zip(coord_dims, list(pxyz) + [0.0] * 6))
    lines += [
        "platform:",
        *(["  planar: true"] if basis is not None else []),
        f"  body: {_word(graph.names[pbody])}",
        f"  point: {_word(ppoint)}",
        "  coordinates: {" + ", ".join(f"{c}: {d}" for c, d in coord_dims.items()) + "}",
        f"  position: {position}",
        f"  rotation: {rotation}",
        f"  task: [{', '.join(task)}]",
        f"  home: {{{home}}}",
    ]
    log.info("imported %s: %d bodies, %d joints", file, len(bodies), len(out_joints))
    return Imported(
        "\n".join(lines) + "\n",
        basis is not None,
        {b: {p: (None if v is None else list(v)) for p, v in own.items()} for b, own in bodies.items()},
        out_joints,
        notes,
    )


def _title_text(text: str) -> str:
    """A title word safe in a plain YAML scalar (quotes, colons and hashes removed)."""
    return re.sub(r"[^A-Za-z0-9_ .()-]+", "_", text)[:80]


def _mechanism_name(raw: str) -> str:
    """The robot's name as a mechanism name: ASCII letters, digits and single underscores, starting with a letter."""
    text = re.sub(r"[^A-Za-z0-9]+", "_", raw).strip("_")
    if not text or not text[0].isalpha():
        text = "urdf_" + text
    text = re.sub(r"_+", "_", text)[:64].rstrip("_")
    return text
