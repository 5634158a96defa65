"""The mechanism file of an imported URDF: planar when its R axes are one direction, numbers
as YAML reads them back, names as a mechanism file takes them."""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Any

import numpy as np

from ...core.errors import InputError, suggest
from ...core.joints import JOINT_TYPES
from .graph import TOL, YAML_WORDS, ZERO, GJoint, Graph

NAME = re.compile(r"[A-Za-z](?:_?[A-Za-z0-9]){0,63}")


def plane_basis(graph: Graph) -> np.ndarray | None:
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


def num(v: float, scale: float) -> str:
    if abs(v) < ZERO * scale:
        return "0"
    text = repr(float(v))
    if "e" in text and "." not in text:  # YAML 1.1 reads 1e-05 as a string
        text = text.replace("e", ".0e")
    return text


def vec(v: np.ndarray, scale: float) -> str:
    return "[" + ", ".join(num(x, scale) for x in v) + "]"


def word(name: str) -> str:
    return f"'{name}'" if name.lower() in YAML_WORDS else name


def title_text(text: str) -> str:
    """A title word safe in a plain YAML scalar (quotes, colons and hashes removed)."""
    return re.sub(r"[^A-Za-z0-9_ .()-]+", "_", text)[:80]


def mechanism_name(raw: str) -> str:
    """The robot's name as a mechanism name: ASCII letters, digits and single underscores, starting with a letter."""
    text = re.sub(r"[^A-Za-z0-9]+", "_", raw).strip("_")
    if not text or not text[0].isalpha():
        text = "urdf_" + text
    text = re.sub(r"_+", "_", text)[:64].rstrip("_")
    return text


@dataclass(frozen=True)
class Layout:
    """How a graph is written: in the plane of ``basis`` (e1, e2, n; None: spatial), numbers
    below `ZERO` times ``scale`` written as 0."""

    basis: np.ndarray | None
    scale: float

    def coords(self, v: np.ndarray) -> np.ndarray:
        return self.basis[:2] @ v if self.basis is not None else v


def drawing_points(graph: Graph, layout: Layout) -> tuple[dict[str, np.ndarray], dict[str, dict]]:
    """The drawing's points: a point's global value is its first body's; a body that differs says
    its own (each body's points: None where the global value holds)."""
    glob: dict[str, np.ndarray] = {}
    for key in graph.points:
        for p, v in graph.points[key].items():
            glob.setdefault(p, layout.coords(v))
    bodies: dict[str, dict[str, list[float] | None]] = {}
    for key, pts in graph.points.items():
        own: dict[str, list[float] | None] = {}
        for p, v in pts.items():
            c = layout.coords(v)
            own[p] = None if np.linalg.norm(c - glob[p]) <= TOL * layout.scale else [float(x) for x in c]
        bodies[graph.names[key]] = own
    return glob, bodies


def joint_entry(g: GJoint, graph: Graph, layout: Layout, flipped: list[str]) -> tuple[dict[str, Any], str]:
    """A joint as data and as its line of the file (``flipped`` collects the R joints whose angle
    is minus the URDF's: their URDF axis is -n)."""
    kind, flip = g.kind, 1.0
    if layout.basis is not None:
        kind = JOINT_TYPES[kind].in_plane
        if g.kind == "R" and float(np.dot(g.axis, layout.basis[2])) < 0:
            flip = -1.0
            if g.actuated or g.limits is not None or " and " not in g.source:
                flipped.append(g.name)
    entry: dict[str, Any] = {"name": g.name, "type": kind, "between": [graph.names[g.a], graph.names[g.b]]}
    entry["at"] = g.point
    fields = [f"name: {word(g.name)}", f"type: {kind}", f"between: [{', '.join(map(word, entry['between']))}]"]
    fields.append(f"at: {word(g.point)}")
    _geometry(g, layout, entry, fields)
    _coordinates(g, flip, entry, fields)
    return entry, "  - {" + ", ".join(fields) + "}"


def _geometry(g: GJoint, layout: Layout, entry: dict[str, Any], fields: list[str]) -> None:
    """A distance joint's other point and length, a P (or spatial R) joint's axis, a U's axes."""
    if g.kind == "distance":
        length = float(np.linalg.norm(layout.coords(g.rod)))  # in a planar file, the rod's length in the plane
        entry["to"], entry["length"] = g.to, length
        fields += [f"to: {word(g.to)}", f"length: {num(length, layout.scale)}"]
    if g.kind == "P" or (g.kind == "R" and layout.basis is None):
        axis = layout.coords(g.axis)
        axis = axis / np.linalg.norm(axis)
        entry["axis"] = [float(x) for x in axis]
        fields.append(f"axis: {vec(axis, 1.0)}")
    if g.kind == "U":
        entry["axes"] = [[float(x) for x in a] for a in g.axes]
        fields.append(f"axes: [{vec(g.axes[0], 1.0)}, {vec(g.axes[1], 1.0)}]")


def _coordinates(g: GJoint, flip: float, entry: dict[str, Any], fields: list[str]) -> None:
    """An actuated joint's actuator and coordinate, a passive URDF joint's coordinate, the home
    value and range of an R or P joint (about n in a planar file: ``flip``)."""
    if g.actuated:
        entry["actuated"], entry["coordinates"] = g.name, [g.coordinate]
        fields.append(f"actuated: {word(g.name)}, coordinates: [{word(g.coordinate)}]")
    elif g.kind in ("R", "P") and g.source.startswith("joint ") and " and " not in g.source:
        entry["coordinates"] = [g.name]
        fields.append(f"coordinates: [{word(g.name)}]")
    if abs(g.home) > ZERO and g.kind in ("R", "P"):
        entry["home"] = flip * g.home
        fields.append(f"home: {num(flip * g.home, 1.0)}")
    if g.limits is not None and g.kind in ("R", "P"):
        lo, hi = sorted((flip * g.limits[0], flip * g.limits[1]))
        entry["range"] = [lo, hi]
        fields.append(f"range: [{num(lo, 1.0)}, {num(hi, 1.0)}]")


@dataclass(frozen=True)
class PlatformFrame:
    """The platform's coordinates (name -> dimension), how its position and rotation are written,
    and the default task for a number of actuators (None: none)."""

    coordinates: dict[str, str]
    position: str
    rotation: str
    default_task: list[str] | None


def platform_frame(planar: bool, n_act: int) -> PlatformFrame:
    """The platform's coordinates of a planar or spatial file, and the default task: planar 1: phi,
    2: x, y, 3: x, y, phi; spatial 3: x, y, z, 6: all six."""
    if planar:
        dims = {"x": "length", "y": "length", "phi": "angle"}
        return PlatformFrame(dims, "[x, y]", "[[z, phi]]", {1: ["phi"], 2: ["x", "y"], 3: ["x", "y", "phi"]}.get(n_act))
    dims = {"x": "length", "y": "length", "z": "length", "psi": "angle", "theta": "angle", "phi": "angle"}
    return PlatformFrame(
        dims, "[x, y, z]", "[[z, phi], [y, theta], [x, psi]]", {3: ["x", "y", "z"], 6: list(dims)}.get(n_act)
    )


def check_task(task: list[str] | None, frame: PlatformFrame, joints: list[dict[str, Any]], n_act: int) -> list[str]:
    """The task coordinates, given (``--task``) or the default: one per actuated joint, each the
    platform's or a passive joint's coordinate."""
    coord_dims = frame.coordinates
    if task is None:
        if frame.default_task is None:
            raise InputError(
                f"which task coordinates for {n_act} actuated joint(s)? Choose {n_act} of {', '.join(coord_dims)}",
                path=("--task",),
                hint="give --task, e.g. --task " + ",".join(list(coord_dims)[:n_act]),
            )
        task = frame.default_task
    passive = [c for j in joints if "actuated" not in j for c in j.get("coordinates", [])]
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
    return task


def body_lines(glob: dict[str, np.ndarray], bodies: dict[str, dict], scale: float) -> list[str]:
    """The file's ``points:`` and ``bodies:`` sections."""
    lines = ["points:"]
    lines += [f"  {word(p)}: {vec(v, scale)}" for p, v in glob.items()]
    lines.append("bodies:")
    for bname, own in bodies.items():
        if all(v is None for v in own.values()):
            lines.append(f"  {word(bname)}: [{', '.join(map(word, own))}]")
        else:
            inner = ", ".join(f"{word(p)}: {'null' if v is None else vec(np.array(v), scale)}" for p, v in own.items())
            lines.append(f"  {word(bname)}: {{points: {{{inner}}}}}")
    return lines


def platform_lines(
    frame: PlatformFrame, layout: Layout, body: str, point: str, position: np.ndarray, task: list[str]
) -> list[str]:
    """The file's ``platform:`` section (its home: the platform point's drawing, no rotation)."""
    home = ", ".join(f"{c}: {num(v, layout.scale)}" for c, v in zip(frame.coordinates, list(position) + [0.0] * 6))
    return [
        "platform:",
        *(["  planar: true"] if layout.basis is not None else []),
        f"  body: {word(body)}",
        f"  point: {word(point)}",
        "  coordinates: {" + ", ".join(f"{c}: {d}" for c, d in frame.coordinates.items()) + "}",
        f"  position: {frame.position}",
        f"  rotation: {frame.rotation}",
        f"  task: [{', '.join(task)}]",
        f"  home: {{{home}}}",
    ]
