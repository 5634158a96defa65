"""The drawing of a mechanism described by its legs, or by its bodies and joints (the
``geometry`` capability).

The generator locates every joint of every leg at a pose symbolically (the
``drawing_points`` function of x, q, p): the joints of the proximal chain moved
by the joints before them, the eliminated joint by the whole proximal chain, a
passive P along the leg at its reference distance from there, and the last
joint where the platform puts it.  This module turns those points into a
`Drawing`: the base through the legs' first
joints, each leg's joints and links, the platform through the legs' last joints.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, Any

import casadi as ca
import numpy as np

from ...core.joints import JOINT_TYPES
from ...core.mechanism import Drawing

if TYPE_CHECKING:
    from .motions import ResolvedJoint

#: (leg name, [(joint letter, actuated, the link after it changes length)])
Layout = Sequence[tuple[str, Sequence[tuple[str, bool, bool]]]]


def _polygon(pts: dict[str, np.ndarray], names: list[str], tol: float) -> list[str]:
    """The distinct points among ``names`` in order around their centroid (in their best-fit plane)."""
    kept: list[str] = []
    for n in names:
        if all(np.linalg.norm(pts[n] - pts[k]) > tol for k in kept):
            kept.append(n)
    if len(kept) < 3:
        return kept
    P = np.array([pts[n] for n in kept])
    mid = P.mean(axis=0)
    _u, s, vt = np.linalg.svd(P - mid)
    if s[1] <= tol:  # collinear
        return kept
    a = (P - mid) @ vt[0]
    b = (P - mid) @ vt[1]
    ring = [int(k) for k in np.argsort(np.arctan2(b, a))]
    # canonical: the SVD's in-plane axes have no sign of their own (and any direction in
    # the plane when s[0] = s[1], as for a regular polygon), which turns or mirrors the
    # ring; start it at the first point given, towards the lower-numbered of its neighbours
    start = ring.index(0)
    ring = ring[start:] + ring[:start]
    if ring[-1] < ring[1]:
        ring = [ring[0]] + ring[:0:-1]
    return [kept[k] for k in ring]


def _ring(part: str, names: list[str]) -> tuple[tuple, tuple]:
    """A face through three or more points, else a segment through two (else nothing)."""
    if len(names) >= 3:
        return (), ((part, tuple(names)),)
    if len(names) == 2:
        return ((names[0], names[1], part),), ()
    return (), ()


def build_drawing(values: Any, layout: Layout, planar: bool) -> Drawing:
    """A drawing from the joints' locations (3 x n: the legs' joints in order, then the platform centre)."""
    V = np.asarray(values, dtype=float).reshape(3, -1)
    pts: dict[str, np.ndarray] = {}
    joints: dict[str, str] = {}
    segments: list[tuple[str, str, str]] = []
    first, last, driven = [], [], []
    col = 0
    for leg, legjoints in layout:
        names = []
        for n, (letter, is_actuated, _slides) in enumerate(legjoints):
            name = f"{leg}_{n + 1}"
            pts[name] = V[:, col].copy()
            joints[name] = letter
            names.append(name)
            if is_actuated:
                driven.append(name)
            col += 1
        for n in range(len(names) - 1):
            actuated = legjoints[n][1]
            part = "actuator" if actuated else ("leg" if n == len(names) - 2 else "link")
            segments.append((names[n], names[n + 1], part))
        first.append(names[0])
        last.append(names[-1])
    centre = "P" if "P" not in pts else "P0"
    pts[centre] = V[:, col].copy()
    span = float(np.ptp(np.array(list(pts.values())), axis=0).max()) or 1.0
    tol = 1e-9 * span
    segments = [s for s in segments if np.linalg.norm(pts[s[0]] - pts[s[1]]) > tol]  # not a zero-length link
    base_segments, base_faces = _ring("base", _polygon(pts, first, tol))
    plat_segments, plat_faces = _ring("platform", _polygon(pts, last, tol))
    note = "joints at their locations from the legs' chains; links straight between consecutive joints"
    if planar:
        note += "; a planar mechanism, drawn in its plane z = 0"
    return Drawing(
        points=pts,
        segments=tuple(base_segments) + tuple(segments) + tuple(plat_segments),
        faces=tuple(base_faces) + tuple(plat_faces),
        joints=joints,
        actuated=tuple(driven),
        note=note,
    )


def geometry_of(fn: Any, layout: Layout, planar: bool) -> Callable[[Any, Any, Any], Drawing] | None:
    """The ``geometry`` capability of a described mechanism (None when it has no legs to draw)."""
    if not layout:
        return None

    def geometry(model: Any, x: Any, q: Any) -> Drawing:
        x = np.asarray(x, dtype=float).ravel()
        q = np.asarray(q, dtype=float).ravel()
        values = np.asarray(fn(x, q, np.asarray(model.p, dtype=float).ravel()), dtype=float)
        return build_drawing(values, layout, planar)

    return geometry


def fixed_links(layout: Layout) -> list[tuple[str, str]]:
    """The segments of the legs whose length the kinematics keeps (the link after a joint that does not slide)."""
    out = []
    for leg, legjoints in layout:
        for n in range(len(legjoints) - 1):
            if not legjoints[n][2]:
                out.append((f"{leg}_{n + 1}", f"{leg}_{n + 2}"))
    return out


def _named_point(g: Any) -> bool:
    """Whether a graph joint sits at a named point of its bodies (``at: C``), not at coordinates."""
    return isinstance(g.spec.at, str) and g.spec.at.isidentifier()


def _graph_joints(gen: Any, layout: list) -> tuple[dict[str, str], list[tuple[str, str]], list[str]]:
    """A graph's joints as drawn: the letter at each drawn point, the strokes of the actuated P
    joints (from their point on the proximal body to the distal one's) and the actuated points.
    A joint is marked at its point on its distal body: a point name on several bodies is drawn
    once where a joint keeps them together, primed across a P joint (A, A', A''); where several
    joints share a point, the actuated joint's letter marks it."""
    drawn = {(body, name.rstrip("'")): name for body, name in layout}
    named = [(g, drawn.get((g.b, g.spec.at), g.spec.at) if _named_point(g) else g.name) for g in gen.gjoints]
    named.sort(key=lambda gk: gk[0].spec.actuated is not None)
    letters = {key: JOINT_TYPES[g.type].letter for g, key in named if g.type not in ("distance", "pose")}
    strokes = [
        (drawn.get((g.a, g.spec.at), g.spec.at), key)
        for g, key in named
        if g.spec.actuated is not None and g.type == "P" and _named_point(g)
    ]
    driven = [key for g, key in named if g.spec.actuated is not None and g.type not in ("distance", "pose")]
    return letters, strokes, driven


def _strokes(pts: dict, strokes: list[tuple[str, str]], tol: float) -> list[tuple[str, str, str]]:
    """The actuator segments of actuated P joints: each stroke from where it starts (none at home)."""
    return [(a, b, "actuator") for a, b in strokes if a in pts and b in pts and np.linalg.norm(pts[a] - pts[b]) > tol]


def graph_geometry(fn: Any, layout: list, gen: Any) -> Callable[[Any, Any, Any], Drawing]:
    """The ``geometry`` capability of a graph (``gen``: its `GraphGenerator`; ``fn``:
    its ``drawing_points`` of (x, q, p), ``layout`` the body and name of each point): every body's
    points, each body a segment (two points) or a face (three or more); the ground as the base,
    the platform body as the platform."""
    d = gen.d
    ground, platform = gen.ground, gen.platform_body
    actuated = {g.b if not g.reversed else g.a for g in gen.gjoints if g.tree and g.spec.actuated is not None}
    letters, strokes, driven = _graph_joints(gen, layout)
    ends = [(g.spec.at, g.spec.to) for g in gen.gjoints if g.type == "distance"]

    def rods(pts: dict) -> list[tuple[str, str, str]]:
        return [(a, b, "leg") for a, b in ends if isinstance(a, str) and isinstance(b, str) and a in pts and b in pts]

    def geometry(model: Any, x: Any, q: Any) -> Drawing:
        V = np.asarray(
            fn(np.asarray(x, dtype=float), np.asarray(q, dtype=float), np.asarray(model.p, dtype=float)), dtype=float
        )
        pts: dict[str, np.ndarray] = {}
        of_body: dict[str, list[str]] = {}
        for k, (body, name) in enumerate(layout):
            if name not in pts:
                pts[name] = V[:, k].copy()
            of_body.setdefault(body, []).append(name)
        if platform != ground:  # the platform point (none when the pose is the joints' alone)
            pts["P" if "P" not in pts else "P0"] = V[:, -1].copy()
        span = float(np.ptp(np.array(list(pts.values())), axis=0).max()) or 1.0
        segments, faces = [], []
        for body in [b.name for b in d.bodies]:
            names = list(dict.fromkeys(of_body.get(body, [])))
            part = (
                "base"
                if body == ground
                else "platform"
                if body == platform
                else "actuator"
                if body in actuated
                else "link"
            )
            ring = _polygon(pts, names, 1e-9 * span)
            if len(ring) >= 3:
                faces.append((part, tuple(ring)))
            elif len(ring) == 2:
                segments.append((ring[0], ring[1], part))
        segments += rods(pts) + _strokes(pts, strokes, 1e-9 * span)
        note = "bodies as straight links (two points) or polygons (three or more) through their points"
        if d.platform.planar:
            note += "; a planar mechanism, drawn in its plane z = 0"
        return Drawing(
            points=pts,
            segments=tuple(segments),
            faces=tuple(faces),
            joints={n: letter for n, letter in letters.items() if n in pts},
            actuated=tuple(dict.fromkeys(n for n in driven if n in pts and n in letters)),
            note=note,
        )

    return geometry


def graph_drawing_points(gen: Any, q: Any) -> tuple[Any, list]:
    """A graph's drawing (``gen``: its `GraphGenerator`): every body's points at
    the pose (x, q, p), and what to draw: the layout."""
    # a point name on several bodies is one drawn point where a joint keeps them together
    # (R, U, S, planar R at that point); across a P or C joint, or unjoined, a point of its own
    root: dict[tuple, tuple] = {}

    def find(k: tuple) -> tuple:
        while root.get(k, k) != k:
            k = root[k]
        return k

    for g in gen.gjoints:
        at = g.spec.at
        if isinstance(at, str) and g.type in ("R", "U", "S", "planar_R"):
            root[find((g.b, at))] = find((g.a, at))
    drawn: dict[tuple, str] = {}
    cols, layout = [], []
    for body in gen.d.bodies:
        for name, p in gen.body_points[body.name].items():
            key = find((body.name, name))
            if key not in drawn:
                drawn[key] = name + "'" * sum(1 for k in drawn if k[1] == name)
            cols.append(gen.world(body.name, p))
            layout.append((body.name, drawn[key]))
    for g in gen.gjoints:
        if (isinstance(g.spec.at, str) and g.spec.at.isidentifier()) or g.type == "pose":
            continue
        cols.append(gen.world(g.a, g.pa))
        layout.append((g.a, g.name))
    cols.append(gen.P)
    fn = ca.Function("drawing_points", [gen.x, q, gen.p], [ca.horzcat(*cols)], ["x", "q", "p"], ["points"])
    return fn, layout


def leg_points(
    last: ResolvedJoint,
    before: list[ResolvedJoint],
    elim: ResolvedJoint | None,
    slide: ResolvedJoint | None,
    Rm: ca.SX,
    tm: ca.SX,
    B: ca.SX,
    planar: bool,
) -> list[tuple[str, ca.SX, bool, bool]]:
    """A leg's joints located at the pose x (with q, p), for the drawing: the proximal
    chain's joints moved by the joints before them, the eliminated joint by the whole
    proximal chain, a P along the leg at its reference distance from there, the last
    joint where the platform puts it."""
    from .motions import LETTER, chain_motion  # generation only: a kept closure's drawing needs neither

    out: list[tuple[str, ca.SX, bool, bool]] = []
    Rk, tk = ca.SX.eye(3), ca.SX.zeros(3)
    for j in before:
        out.append((LETTER[j.type], Rk @ j.at + tk, j.value is not None and j.spec.actuated is not None, False))
        Rj, tj = chain_motion([j])
        Rk, tk = Rk @ Rj, Rk @ tj + tk
    if elim is not None:
        c = Rm @ elim.at + tm
        letter = "R" if planar and last.type == "distance" else LETTER[elim.type]
        out.append((letter, c, False, elim.type == "C"))
        if slide is not None:
            reach = ca.norm_2(slide.at - elim.at)
            out.append(
                (LETTER[slide.type], c + reach * (B - c) / ca.norm_2(B - c), slide.spec.actuated is not None, True)
            )
    tip = "R" if planar and last.type == "distance" else LETTER[last.type]
    out.append((tip, B, False, False))
    # a segment after a P (or C) joint changes length: mark the joints that slide
    out = [(t, v, act, slides or t in ("P", "C")) for t, v, act, slides in out]
    return out
