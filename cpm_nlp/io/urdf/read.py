"""Reading a URDF: the XML refused where it could expand or fetch anything, then its links and
joints (lengths in metres, angles in radians), and the tree they form."""

from __future__ import annotations

import math
import re
import xml.etree.ElementTree as ET
from dataclasses import dataclass

import numpy as np

from ...core.errors import InputError, suggest

#: Most links and joints a URDF may hold (a mechanism file holds at most 512 joints).
MAX_LINKS = MAX_JOINTS = 512


#: Most XML elements in a URDF (visuals, inertias, ... included).
MAX_ELEMENTS = 50_000


_URDF_TYPES = {"revolute": "R", "continuous": "R", "prismatic": "P", "fixed": "fixed"}


_UNSUPPORTED_TYPES = {
    "floating": "a floating joint (6 degrees of freedom) joins nothing",
    "planar": "a URDF planar joint (3 degrees of freedom) has no joint type in a mechanism file",
}


_DECLARATION = re.compile(r"<!(?!--|\[CDATA\[)")


@dataclass
class UrdfJoint:
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


def parse_urdf(text: str, file: str) -> ET.Element:
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


def read_urdf(root: ET.Element, file: str) -> tuple[str, list[str], list[UrdfJoint]]:
    """The robot's name, its links and its joints, each element checked in document order."""
    links = _read_links(root, file)
    joints: list[UrdfJoint] = []
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
        joints.append(_read_joint(elem, name, path, links, file))
    if not links:
        raise InputError("the robot has no links", file=file, path=("robot",))
    return root.get("name") or "", links, joints


def _read_links(root: ET.Element, file: str) -> list[str]:
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
    return links


def _read_joint(elem: ET.Element, name: str, path: tuple, links: list[str], file: str) -> UrdfJoint:
    """One ``<joint>``: its type, the links it joins, its origin, axis and limits."""
    urdf_type = _joint_type(elem, path, file)
    ends = {end: _joint_end(elem, end, path, links, file) for end in ("parent", "child")}
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
    kind = _URDF_TYPES[urdf_type]
    axis = _joint_axis(elem, kind, path, file)
    limits = _joint_limits(elem, urdf_type, path, file)
    return UrdfJoint(name, kind, ends["parent"], ends["child"], origin, axis, limits, path)


def _joint_type(elem: ET.Element, path: tuple, file: str) -> str:
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
    return urdf_type


def _joint_end(elem: ET.Element, end: str, path: tuple, links: list[str], file: str) -> str:
    """The link of the joint's ``<parent>`` or ``<child>``."""
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
    return link


def _joint_axis(elem: ET.Element, kind: str, path: tuple, file: str) -> np.ndarray:
    """The joint's unit axis in its frame (default 1 0 0; a fixed joint's is kept as written)."""
    axis = np.array([1.0, 0.0, 0.0])
    sub = elem.find("axis")
    if sub is not None:
        axis = np.array(_numbers(sub, "xyz", 3, (1.0, 0.0, 0.0), file, path + ("axis",)))
    if kind == "fixed":
        return axis
    norm = float(np.linalg.norm(axis))
    if not norm > 1e-12:
        raise InputError("expected a nonzero axis, got 0 0 0", file=file, path=path + ("axis", "xyz"))
    return axis / norm


def _joint_limits(elem: ET.Element, urdf_type: str, path: tuple, file: str) -> tuple[float, float] | None:
    """A revolute or prismatic joint's ``<limit lower upper>``, None where there is none (or it is empty)."""
    sub = elem.find("limit")
    if sub is None or urdf_type not in ("revolute", "prismatic") or not sub.get("lower") or not sub.get("upper"):
        return None
    lo = _numbers(sub, "lower", 1, (0.0,), file, path + ("limit",))[0]
    hi = _numbers(sub, "upper", 1, (0.0,), file, path + ("limit",))[0]
    return (lo, hi) if lo < hi else None


def link_tree(links: list[str], joints: list[UrdfJoint], file: str) -> tuple[str, list[str], dict[str, UrdfJoint]]:
    """The root link, the links in tree order (each after its parent) and each link's parent joint."""
    parent_joint: dict[str, UrdfJoint] = {}
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
    children: dict[str, list[UrdfJoint]] = {lk: [] for lk in links}
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
