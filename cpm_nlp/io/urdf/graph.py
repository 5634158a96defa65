"""The bodies and joints of an imported URDF: links joined by fixed joints are one body, the
sidecar's closures become S joints or welds, and the platform is found."""

from __future__ import annotations

import re
from dataclasses import dataclass, field

import numpy as np

from ...core.errors import InputError, suggest
from .assembly import assemble, link_frames, world_frames
from .read import UrdfJoint
from .sidecar import Sidecar

#: Two lengths closer than this (times the drawing's size) are one point; two unit vectors
#: closer than this are one direction.
TOL = 1e-9
#: |coordinate| below this (times the drawing's size) is written as 0 (round-off of the frames).
ZERO = 1e-14
#: names a file's expressions keep for themselves (functions, constants)
_RESERVED = {
    "sin", "cos", "tan", "asin", "acos", "atan", "atan2", "sqrt", "exp", "log", "abs", "min", "max",
    "hypot", "norm", "dot", "cross", "unit", "select", "pi",
}  # fmt: skip
#: words YAML 1.1 reads as booleans or null (quoted when written)
YAML_WORDS = {"y", "n", "yes", "no", "on", "off", "true", "false", "null"}
_GROUND_NAMES = ("ground", "base")


@dataclass
class GJoint:
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
class Graph:
    names: dict[str, str]  # body key -> name written
    points: dict[str, dict[str, np.ndarray]]  # body key -> point -> world coordinates at the drawing
    joints: list[GJoint]
    notes: list[str]
    scale: float = 1.0
    renamed: dict[str, str] = field(default_factory=dict)  # URDF name -> name written


class Names:
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
        if text.lower() in YAML_WORDS or text in _RESERVED or text in avoid:
            text += "_1"
        name, k = text, 2
        while name in self.used:
            name, k = f"{text}_{k}", k + 1
        self.used.add(name)
        if name != prefix + raw:
            self.renamed[prefix + raw] = name
        return name


def frame_link(name: str, links: list[str], by_name: dict[str, UrdfJoint], file: str, path: tuple) -> str:
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


#: a sidecar joint_type -> the joint type read (UJOINT_XY ... are U joints)
_REPLACED_KIND = {"FIXED": "fixed", "SPHERICAL": "S"}


def build_graph(
    links: list[str],
    joints: list[UrdfJoint],
    root: str,
    order: list[str],
    sidecar: Sidecar,
    actuated: list[str] | None,
    platform: str | None,
    urdf: str,
    side: str,
) -> tuple[Graph, str, str, np.ndarray, bool]:
    """The bodies, joints and drawing of the mechanism; the platform body and its point; whether
    the drawing is the URDF's zero configuration moved to close the loops."""
    b = _Builder(links, joints, root, sidecar, side)
    b.apply_joint_types()
    b.actuated(actuated)
    b.draw(order)
    b.bodies(order)
    b.tree_joints()
    for fa, fb, kind, path in sidecar.closures:
        b.close(fa, fb, kind, path)
    for g in b.gjoints:
        g.a, g.b = b.find(g.a), b.find(g.b)
    pbody, ppoint, pframe = b.platform(platform, urdf)
    graph = Graph(b.body_names, b.points, b.gjoints, b.notes, b.scale, {**b.bnames.renamed, **b.names.renamed})
    return graph, pbody, ppoint, pframe, b.assembled


class _Builder:
    """The conversion's state, one method per step: the sidecar's joint types, the actuated
    joints, the drawing (loops closed), the bodies, the tree's joints, each closure, the
    platform."""

    def __init__(self, links: list[str], joints: list[UrdfJoint], root: str, sidecar: Sidecar, side: str) -> None:
        self.links, self.joints, self.root, self.sidecar, self.side = links, joints, root, sidecar, side
        self.by_name = {j.name: j for j in joints}
        self.parent_joint = {j.child: j for j in joints}
        self.notes: list[str] = []
        self.act: set[str] = set()
        self.names, self.bnames, self.pnames = Names(), Names(), Names()  # joints and coordinates, bodies, points
        self.gjoints: list[GJoint] = []
        self.merged: dict[str, str] = {}  # a welded body -> the body it was welded to
        self.moves: dict[str, np.ndarray] = {}  # ... and the map of its drawing onto that body's

    def apply_joint_types(self) -> None:
        """The sidecar's joint types (joint_name, joint_type)."""
        for jname, (jtype, path) in self.sidecar.replace.items():
            if jname not in self.by_name:
                raise InputError(
                    f"no joint of the URDF is named {jname!r}",
                    file=self.side,
                    path=path,
                    suggestions=suggest(jname, self.by_name),
                )
            j = self.by_name[jname]
            j.kind = _REPLACED_KIND.get(jtype, "U")
            if j.kind == "U":
                j.u_axes = ("XYZ".index(jtype[-2]), "XYZ".index(jtype[-1]))

    def actuated(self, actuated: list[str] | None) -> None:
        """The actuated joints: the option, else the sidecar."""
        if actuated is not None:
            wanted = [(a, ("--actuated",)) for a in actuated]
            afile = None
        else:
            wanted, afile = self.sidecar.motors, self.side
        for a, path in wanted:
            j = self.by_name.get(a)
            if j is None:
                raise InputError(
                    f"no joint of the URDF is named {a!r}", file=afile, path=path, suggestions=suggest(a, self.by_name)
                )
            if j.kind not in ("R", "P"):
                raise InputError(
                    f"the joint {a!r} is {'fixed' if j.kind == 'fixed' else 'a ' + j.kind + ' joint'}; "
                    "an actuated joint is revolute, continuous or prismatic",
                    file=afile,
                    path=path,
                )
            self.act.add(a)

    def draw(self, order: list[str]) -> None:
        """The drawing: each link's frame in the world (the root link's frame), the loops closed from
        the URDF's zero configuration with the actuated joints held at 0 where they can be."""
        frames, self.slots = link_frames(order, self.parent_joint)
        self.values = np.zeros(frames.size1_in(0))
        self.world = world_frames(frames, self.values, order)
        self.assembled = False
        self.scale = max([1e-3] + [float(np.linalg.norm(t[:3, 3])) for t in self.world.values()])
        if not self.sidecar.closures:
            return
        pairs = [
            (self.link_of(fa, path + (0,)), self.link_of(fb, path + (1,)), kind)
            for fa, fb, kind, path in self.sidecar.closures
        ]
        held = [k for j in self.joints if j.name in self.act for k in range(*self.slots[j.name])]
        self.values, note = assemble(frames, order, pairs, held, self.scale)
        if note:
            self.notes.append(note)
        self.world = world_frames(frames, self.values, order)
        self.assembled = bool(np.any(self.values != 0))
        moved = [
            j.name
            for j in self.joints
            if j.name in self.act and np.any(self.values[self.slots[j.name][0] : self.slots[j.name][1]])
        ]
        if moved:
            self.notes.append(
                f"the loops do not close with the actuated joints at 0: the drawing has {', '.join(moved)} "
                "at other values (their home)"
            )

    def link_of(self, name: str, path: tuple) -> str:
        """The link of a sidecar frame name (`frame_link`)."""
        return frame_link(name, self.links, self.by_name, self.side, path)

    def bodies(self, order: list[str]) -> None:
        """The links joined by fixed joints are one body (its key: its top link)."""
        self.body_of: dict[str, str] = {}
        for lk in order:
            j = self.parent_joint.get(lk)
            self.body_of[lk] = self.body_of[j.parent] if j is not None and j.kind == "fixed" else lk
        self.points: dict[str, dict[str, np.ndarray]] = {self.body_of[lk]: {} for lk in order}
        self.bnames.used.add("ground")
        self.body_names = {
            key: "ground" if key == self.root else self.bnames.take(key, avoid=_GROUND_NAMES) for key in self.points
        }

    def tree_joints(self) -> None:
        """Every joint of the URDF's tree that is not fixed, at the origin of its frame."""
        world, names, pnames = self.world, self.names, self.pnames
        for j in self.joints:
            if j.kind == "fixed":
                continue
            frame = world[j.child]
            name = names.take(j.name)
            point = pnames.take(name, prefix="P_")
            pos = frame[:3, 3].copy()
            a, b = self.body_of[j.parent], self.body_of[j.child]
            self.points[a][point] = pos
            self.points[b][point] = pos
            g = GJoint(j.kind, a, b, point, name=name, source=f"joint {j.name!r}", actuated=j.name in self.act)
            if g.actuated:
                g.coordinate = names.take(name + "_joint")
            if j.kind in ("R", "P"):
                g.axis = frame[:3, :3] @ j.axis
                g.limits = j.limits
                g.home = float(self.values[self.slots[j.name][0]])  # the URDF's joint value at the drawing
            elif j.kind == "U":  # the first axis turns with the parent, the second with the child
                first = (world[j.parent] @ j.origin)[:3, j.u_axes[0]].copy()
                g.axes = (first, frame[:3, j.u_axes[1]].copy())
            self.gjoints.append(g)

    def find(self, key: str) -> str:
        """The body a body is part of now (welds applied)."""
        while key in self.merged:
            key = self.merged[key]
        return key

    def placed(self, link: str) -> np.ndarray:
        """The link's frame in the drawing of the body it is part of now (welds applied)."""
        key, t = self.body_of[link], self.world[link]
        while key in self.merged:
            t, key = self.moves[key] @ t, self.merged[key]
        return t

    def close(self, fa: str, fb: str, kind: str, path: tuple) -> None:
        """One closure of the sidecar: a 3d closure is an S joint, a 6d one welds two bodies."""
        la = self.link_of(fa, path + (0,))
        lb = self.link_of(fb, path + (1,))
        ba, bb = self.find(self.body_of[la]), self.find(self.body_of[lb])
        wa, wb = self.placed(la), self.placed(lb)
        if kind == "6d" and bb == self.root:  # the ground stays: the other body is welded to it
            fa, fb, ba, bb, wa, wb = fb, fa, bb, ba, wb, wa
        if ba == bb:
            raise InputError(
                f"the frames {fa!r} and {fb!r} are on one rigid body ({self.body_names[ba]!r}): "
                "the closure joins nothing",
                file=self.side,
                path=path,
            )
        if kind == "3d":
            name = self.names.take(fa)
            point = self.pnames.take(name, prefix="P_")
            self.points[ba][point] = wa[:3, 3].copy()
            self.points[bb][point] = wb[:3, 3].copy()
            self.gjoints.append(GJoint("S", ba, bb, point, name=name, source=f"closure {fa!r}-{fb!r} (3d)"))
            return
        self.weld(fa, fb, ba, bb, wa, wb)

    def weld(self, fa: str, fb: str, ba: str, bb: str, wa: np.ndarray, wb: np.ndarray) -> None:
        """6d: the frames coincide -- body bb is welded to body ba, its drawing moved by Wa Wb^-1."""
        gap = float(np.linalg.norm(wa[:3, 3] - wb[:3, 3]))
        move = wa @ np.linalg.inv(wb)
        turn = float(np.degrees(np.arccos(np.clip((np.trace(move[:3, :3]) - 1) / 2, -1.0, 1.0))))
        opened = ""
        if gap > TOL * self.scale or turn > 1e-7:
            opened = f" (the frames are {gap:.3g} m and {turn:.3g} deg apart in the URDF's zero configuration)"
        for p, v in self.points.pop(bb).items():
            self.points[ba].setdefault(p, move[:3, :3] @ v + move[:3, 3])
        self.merged[bb], self.moves[bb] = ba, move
        names = self.body_names
        self.notes.append(f"closure {fa!r}-{fb!r} (6d): {names[bb]!r} is welded to {names[ba]!r}{opened}")
        for g in self.gjoints:
            g.a, g.b = self.find(g.a), self.find(g.b)
        for g in [g for g in self.gjoints if g.a == g.b]:
            self.notes.append(f"{g.source} is locked by the weld and left out")
            self.gjoints.remove(g)

    def platform(self, platform: str | None, urdf: str) -> tuple[str, str, np.ndarray]:
        """The platform: a frame (a joint or link name), else a link named platform/effector/end_effector;
        its body, its point and its frame in that body's drawing."""
        links = self.links
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
            plink, ppath, pfile = (
                frame_link(platform, links, self.by_name, None, ("--platform",)),
                ("--platform",),
                None,
            )
        pbody = self.find(self.body_of[plink])
        if pbody == self.root:
            raise InputError(f"the platform frame {platform!r} is on the ground", file=pfile, path=ppath)
        ppoint = self.pnames.take(platform, prefix="P_")
        pframe = self.placed(plink)
        self.points[pbody][ppoint] = pframe[:3, 3].copy()
        return pbody, ppoint, pframe
