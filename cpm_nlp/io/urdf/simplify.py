"""The graph of an imported URDF made smaller: bodies that only add a free spin are removed and
their joints merged (coaxial R: an R; crossing R: a U; about one point: an S; a rod between
two S joints: a distance joint)."""

from __future__ import annotations

import numpy as np

from .graph import TOL, GJoint, Graph


def simplify(graph: Graph, ground: str, keep: set[str]) -> None:
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


def _join(graph: Graph, key: str, ground: str, j1: GJoint, j2: GJoint) -> bool:
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
    new = GJoint(kind, a, b, name, name=j1.name)
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


def _common(d: dict, j1: GJoint, j2: GJoint, tol: float) -> tuple[np.ndarray, str, tuple] | None:
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


def _rod(graph: Graph, key: str, ground: str, j1: GJoint, j2: GJoint, ends: list[str]) -> bool:
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
    new = GJoint("distance", a, b, ja.point, name=j1.name, to=jb.point, rod=d[jb.point] - d[ja.point])
    graph.notes.append(
        f"{graph.names[key]!r} is a rod between {j1.source} and {j2.source}: a distance joint of its length"
    )
    _replace(graph, key, j1, j2, new, ends)
    return True


def _replace(graph: Graph, key: str, j1: GJoint, j2: GJoint, new: GJoint, ends: list[str]) -> None:
    """The body ``key`` and its joints j1, j2 gone, ``new`` in j1's place."""
    new.source = f"{j1.source} and {j2.source}"
    graph.joints[graph.joints.index(j1)] = new
    graph.joints.remove(j2)
    del graph.points[key]
    for other in ends:  # a point no joint uses any more is dropped
        used = {p for g in graph.joints if other in (g.a, g.b) for p in (g.point, g.to)}
        for p in [p for p in graph.points[other] if p not in used and p in (j1.point, j2.point)]:
            del graph.points[other][p]


def _reached(graph: Graph, ground: str, without: tuple) -> set[str]:
    """The bodies joined to the ground by joints (distance joints and ``without`` left out)."""
    reach, grew = {ground}, True
    while grew:
        grew = False
        for g in graph.joints:
            if g.kind != "distance" and all(g is not w for w in without) and (g.a in reach) != (g.b in reach):
                reach |= {g.a, g.b}
                grew = True
    return reach
