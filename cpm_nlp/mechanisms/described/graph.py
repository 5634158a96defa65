"""Bodies and joints: a mechanism file as a graph of rigid bodies joined by joints, any topology.

The formulation (relative coordinates with cut joints, as multibody codes write closed loops):

* Every body's frame is the world frame at the *drawing* (the configuration the file draws); a
  body's points, given there, are its geometry.  A pose of a body is (R, t): a point p of the body
  is at R p + t.
* A spanning tree of the graph, grown from the ground (actuated joints first, then in file order;
  a ``distance`` joint is a rod, never a tree edge), places every body by the product of the
  exponentials of the tree joints' displacements from the drawing.  A tree joint brings its point
  on the distal body onto its point on the proximal one, so a rough drawing (the two points apart)
  costs nothing.
* Each joint left out of the tree closes one loop (the fundamental cycles of the tree: a cycle
  basis).  Its rows say that the two bodies' relative motion is one the joint allows: a point joint
  (S; planar R) keeps its two points together, an R also keeps the axes parallel, a P keeps the
  relative rotation and the offset along the axis, a distance joint the rod's length.
* Mobility is the number of tree coordinates less the rank of the loops' Jacobian at the reference
  configuration (so an overconstrained linkage such as the Bennett linkage loads); the rows are
  kept that are independent there, in file order.  Grübler-Kutzbach is counted beside it.
* The reference configuration is assembled from the drawing: a Gauss-Newton solve on the loops
  with the actuators at their ``home`` values, for any parameter values (:class:`Assembler`).
* The pose coordinates are the platform's (``platform.body``, ``platform.point``): rows that say
  the platform coordinates locate that body, then the passive tree coordinates.

See docs/site/guide/mechanism-files.md, "Bodies and joints".
"""

from __future__ import annotations

import logging
import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import casadi as ca
import numpy as np

from ...core.aspect import ASPECT_MAX_NX, twist_determinant
from ...core.errors import InputError, suggest
from ...core.joints import JOINT_TYPES, joint_types
from ...core.mechanism import Drawing
from ...core.model import Coordinate
from ...core.options import REQUIRED
from ...core.screws import vee
from . import expr as ex
from .branches import branch_expressions, select_branch
from .builder import ClosureBuilder, Reported, family
from .drawing import _polygon
from .emit import closure_functions
from .expand import InLeg
from .generate import Generator
from .motions import JOINT_DIMS, elementary_motions, rot, xyz_angles
from .spec import GROUND_NAMES, Description, Joint

log = logging.getLogger(__name__)

#: the freedom a distance joint (a rod with a spherical joint at each end) leaves between the
#: two bodies it joins, spatial and planar (Grübler-Kutzbach); other joints: their dof (the table)
_ROD_FREEDOM = {False: 5, True: 2}
#: a row is independent of the rows kept before it when its part outside their span is at least
#: this share of its norm (the rank test at the reference configuration, in file order)
RANK_TOL = 1e-8
#: the assembly: Gauss-Newton steps, and the residual (over the characteristic length) it reaches
ASSEMBLY_STEPS, ASSEMBLY_TOL = 60, 1e-12


@dataclass
class _GJoint:
    """A joint of the graph resolved to CasADi."""

    spec: Joint
    type: str
    a: str  # the proximal body
    b: str  # the distal body
    pa: ca.SX  # its point on a (a's frame = the world at the drawing)
    pb: ca.SX  # its point on b
    axis: ca.SX | None = None
    axes: list = field(default_factory=list)
    tree: bool = False
    reversed: bool = False  # in the tree, b is the parent of a
    values: list = field(default_factory=list)  # displacements from the drawing, one per dof
    names: tuple = ()
    loop: int = 0  # the loop it closes (cut joints), 1-based
    length: ca.SX | None = None

    @property
    def name(self) -> str:
        return str(self.spec.name)


@dataclass
class GraphInfo:
    """What ``describe`` shows of a graph: bodies, tree and cut joints, loops, mobility."""

    bodies: list[str]
    ground: str
    joints: list[tuple[str, str, str, str, bool, bool, int]]  # name, type, a, b, actuated, tree, loop
    loops: list[tuple[int, str, list[str]]]  # number, the joint closing it, the bodies around it
    gruebler: int
    mobility: int
    dropped: list[tuple[int, str]]  # (loop, row name) of the rows that repeat others at the reference


def _compose(A: tuple, B: tuple) -> tuple:
    return A[0] @ B[0], A[0] @ B[1] + A[1]


def _shift(v: ca.SX) -> tuple:
    return ca.SX.eye(3), v


class GraphGenerator(ClosureBuilder):
    """Builds the symbolic closure of a bodies-and-joints description (errors carry key paths)."""

    def __init__(self, d: Description) -> None:
        super().__init__(d)
        self.gjoints: list[_GJoint] = []
        self.body_points: dict[str, dict[str, ca.SX]] = {}
        self.pose: dict[str, tuple[ca.SX, ca.SX]] = {}
        self.parent: dict[str, tuple[str, _GJoint] | None] = {}
        self.loop_rows: list[tuple[ca.SX, str, int]] = []
        self.platform_rows: list[tuple[ca.SX, str]] = []
        #: (joint value - its actuator's, what, dimension): one per actuated joint
        self.actuation_rows: list[tuple[ca.SX, str, str]] = []
        self.actuated_coords: set[str] = set()
        self.info: GraphInfo | None = None
        self.assembler: Assembler | None = None
        #: an expanded legs file: each leg's environment and rotation (id of the leg -> (env, turn))
        self._frames: dict[int, tuple[dict, ca.SX]] = {}

    # -- expressions of an expanded legs file (in a leg's frame: its let, index and rotation) ----
    def _leg_frame(self, leg: Any) -> tuple[dict, ca.SX]:
        """A leg's environment (parameters, derived values, its index and ``let``) and its rotation,
        as the legs generator resolves them (:meth:`Generator.leg`)."""
        frames = self._frames
        if id(leg) not in frames:
            env = dict(self.env)
            if leg.index is not None:
                self.bind(env, leg.index, ex.Value(ca.SX(float(leg.values[0])), None), leg.path + ("repeat", "index"))
            for name, text in leg.let.items():
                self.bind(env, name, super().value(text, leg.path + ("let", name), env), leg.path + ("let", name))
            turn = ca.SX.eye(3)
            if leg.rotate is not None:
                angle = super().scalar(leg.rotate, leg.path + ("repeat", "rotate"), env, "angle")
                turn = rot(leg.rotate_axis, angle)
            frames[id(leg)] = (env, turn)
        return frames[id(leg)]

    def value(self, text: Any, path: tuple, env: Any, dimension: str | None = None) -> ex.Value:
        if isinstance(text, InLeg):
            return super().value(text.text, text.path or path, self._leg_frame(text.leg)[0], dimension)
        return super().value(text, path, env, dimension)

    def vector(self, text: Any, path: tuple, env: Any, dimension: str | None) -> ca.SX:
        if not isinstance(text, InLeg):
            return super().vector(text, path, env, dimension)
        lenv, turn = self._leg_frame(text.leg)
        path = text.path or path
        if text.across is None:
            v = super().vector(text.text, path, lenv, dimension)
            return turn @ v if text.turn else v
        a, b = (super(GraphGenerator, self).vector(t, path, lenv, "length") for t in text.across)
        u = turn @ (b - a) / ca.norm_2(b - a)
        if text.normal == 0:  # the point at a length from `from` towards `to`
            return turn @ a + self.scalar(text.text, path, lenv, "length") * u
        # two unit vectors across u: n1 = unit(u x e), n2 = u x n1, e the basis vector least aligned
        # with u (with the parameters' defaults), as for a joint's normals
        value = np.abs(np.asarray(ca.Function("u", [self.p], [u])(self.p_default), dtype=float).ravel())
        e = ca.DM.zeros(3)
        e[int(np.argmin(value))] = 1.0
        n1 = ca.cross(u, e)
        n1 = n1 / ca.norm_2(n1)
        return n1 if text.normal == 1 else ca.cross(u, n1)

    # -- the drawing ------------------------------------------------------------------------
    @property
    def ground(self) -> str:
        return next(b.name for b in self.d.bodies if b.name in GROUND_NAMES)

    def read_bodies(self) -> None:
        glob = {}
        for name, text in self.d.points.items():
            glob[name] = self.vector(text, ("points", name), self.env, "length")
        self.global_points = glob
        for body in self.d.bodies:
            pts = {}
            for name, text in body.points.items():
                path = body.path + ("points", name) if isinstance(text, (str, list)) else body.path
                pts[name] = glob[name] if text is None else self.vector(text, path, self.env, "length")
            self.body_points[body.name] = pts

    def point_of(self, body: str, ref: Any, path: tuple) -> ca.SX:
        """A joint's point on a body: its own point of that name, else the drawing's, else a vector."""
        if isinstance(ref, str) and ref.isidentifier():
            if ref in self.body_points[body]:
                return self.body_points[body][ref]
            return self.global_points[ref]
        if ref is None:
            raise InputError("missing 'at': the joint's point (a point name or a vector)", path=path)
        return self.vector(ref, path, self.env, "length")

    def read_joints(self) -> None:  # noqa: C901 - one rule per joint part
        planar = self.d.platform.planar
        allowed = joint_types(planar)
        if self.d.platform.placed:  # the platform coordinates place the platform (an expanded legs file)
            zero = ca.SX.zeros(3)
            spec = Joint("pose", name="platform_pose", path=("platform", "coordinates"))
            self.gjoints.append(_GJoint(spec, "pose", self.ground, "platform", zero, zero, tree=True))
        for j in self.d.joints:
            jt = JOINT_TYPES[j.type]
            kind = jt.twin if planar and jt.twin and not jt.planar else j.type  # a planar file reads R, P as planar
            if kind not in allowed:
                raise InputError(
                    f"a {'planar' if planar else 'spatial'} mechanism takes {', '.join(allowed)} joints, got {j.type}",
                    path=j.path + ("type",),
                    suggestions=suggest(j.type, allowed),
                )
            a, b = j.between
            pa = self.point_of(a, j.at, j.path + ("at",))
            if kind == "distance":
                if j.to is None:
                    raise InputError("a distance joint needs 'to' (its point on the distal body)", path=j.path)
                pb = self.point_of(b, j.to, j.path + ("to",))
            else:
                if j.to is not None:
                    raise InputError("only a distance joint has 'to'", path=j.path + ("to",))
                pb = self.point_of(b, j.at, j.path + ("at",))
            g = _GJoint(j, kind, a, b, pa, pb)
            if kind in ("P", "R", "C", "planar_P"):
                if j.axis is None:
                    raise InputError(f"a {j.type} joint needs its 'axis'", path=j.path)
                v = self.vector(j.axis, j.path + ("axis",), self.env, None)
                g.axis = v / ca.norm_2(v)
            elif kind == "planar_R":
                g.axis = ca.SX(ca.DM([0.0, 0.0, 1.0]))
            for k, v in enumerate(j.axes):
                w = self.vector(v, j.path + ("axes", k), self.env, None)
                g.axes.append(w / ca.norm_2(w))
            need = {"U": 2, "S": 3}.get(kind)
            if j.axes and (need is None or len(j.axes) != need):
                raise InputError(
                    f"a {j.type} joint takes {need or 'no'} axes, got {len(j.axes)}", path=j.path + ("axes",)
                )
            if kind == "U" and not j.axes:
                raise InputError("a U joint needs its two 'axes' (the first on the proximal body)", path=j.path)
            if kind == "S" and j.axes:
                self.independent_axes(g.axes, j.path + ("axes",))
            dof = JOINT_TYPES[kind].dof
            if j.coordinates and len(j.coordinates) != dof:
                raise InputError(
                    f"a {j.type} joint has {dof} coordinate(s), got {len(j.coordinates)}",
                    path=j.path + ("coordinates",),
                )
            if kind != "distance" and j.length is not None:
                raise InputError(
                    f"only a distance joint has 'length' (a {j.type} joint's bodies carry its points)",
                    path=j.path + ("length",),
                )
            if kind == "distance":
                if j.actuated is not None:
                    raise InputError(
                        "a distance joint cannot be actuated (a P joint between two bodies can)", path=j.path
                    )
                if j.length is not None:
                    g.length = self.scalar(j.length, j.path + ("length",), self.env, "length")
                else:
                    g.length = ca.norm_2(pb - pa)
            self.gjoints.append(g)

    # -- the tree and its loops ----------------------------------------------------------------
    def spanning_tree(self) -> None:
        """Grow the tree from the ground: actuated joints first, then the joints whose values are
        task coordinates, then in file order (a distance joint never); the joints left out close
        one loop each."""
        bodies = [b.name for b in self.d.bodies]
        root = {b: b for b in bodies}

        def find(b: str) -> str:
            while root[b] != b:
                root[b] = root[root[b]]
                b = root[b]
            return b

        task = set(self.d.platform.task)  # a joint whose value is a task coordinate joins the tree early

        def rank(k: int) -> tuple:
            j = self.gjoints[k].spec
            return (j.type != "pose", j.actuated is None, not task & set(j.coordinates), k)

        order = sorted(range(len(self.gjoints)), key=rank)
        for k in order:
            g = self.gjoints[k]
            if g.type == "distance":
                continue
            ra, rb = find(g.a), find(g.b)
            if ra != rb:
                root[ra] = rb
                g.tree = True
            elif g.spec.actuated is not None:
                raise InputError(
                    f"the actuated joint {g.name} closes a loop of actuated joints only (they form a cycle)",
                    path=g.spec.path + ("actuated",),
                )
        self._orient(bodies)
        loop = 0
        for g in self.gjoints:
            if not g.tree:
                loop += 1
                g.loop = loop

    def _orient(self, bodies: list[str]) -> None:
        """Each body's parent in the tree (breadth first from the ground), and each tree joint's direction."""
        ground = self.ground
        self.parent = {ground: None}
        frontier = [ground]
        while frontier:
            nxt = []
            for body in frontier:
                for g in self.gjoints:
                    if not g.tree or body not in (g.a, g.b):
                        continue
                    other = g.b if body == g.a else g.a
                    if other in self.parent:
                        continue
                    g.reversed = other == g.a
                    self.parent[other] = (body, g)
                    nxt.append(other)
            frontier = nxt
        loose = [b for b in bodies if b not in self.parent]
        if loose:
            raise InputError(
                f"the bodies {', '.join(loose)} are not joined to the ground by joints (a distance joint "
                "is a rod between two bodies, not a joint that carries one)",
                path=("bodies", loose[0]),
                hint="join every body to another by a P, R, C, U or S joint",
            )

    def path_to_ground(self, body: str) -> list[str]:
        out = [body]
        while self.parent[out[-1]] is not None:
            out.append(self.parent[out[-1]][0])
        return out

    def loop_bodies(self, g: _GJoint) -> list[str]:
        """The bodies around the loop a cut joint closes: a -> ... -> common ancestor -> ... -> b."""
        pa, pb = self.path_to_ground(g.a), self.path_to_ground(g.b)
        common = next(x for x in pa if x in pb)
        return pa[: pa.index(common) + 1] + list(reversed(pb[: pb.index(common)]))

    # -- coordinates and poses -------------------------------------------------------------------
    def tree_coordinates(self) -> None:
        """Each tree joint's values become pose coordinates (unknowns); an actuated joint's also
        gets its actuator (q) and a row that ties the two (:attr:`actuation_rows`), so that every
        body's pose is a function of the pose coordinates alone."""
        for g in self.gjoints:
            if g.type == "pose":  # its values are the platform coordinates
                g.names = tuple(self.x_names)
                continue
            if not g.tree:
                continue
            j = g.spec
            motions = elementary_motions(g)  # type: ignore[arg-type]
            names = j.coordinates or (
                (g.name,) if len(motions) == 1 else tuple(f"{g.name}_{n + 1}" for n in range(len(motions)))
            )
            g.names = tuple(names)
            actuated = None
            if j.actuated is not None:
                if len(motions) != 1:
                    raise InputError(
                        f"a {j.type} joint cannot be actuated (P, R and the planar joints can)",
                        path=j.path + ("actuated",),
                    )
                spec = Joint(g.type, home=j.home, actuated=j.actuated, gain=j.gain, limit=j.limit, range=j.range)
                spec.path = j.path
                actuated = self.actuator(spec, self.env)  # gain (q - q_home)
            for n, ((kind, _axis), name) in enumerate(zip(motions, names)):
                dim = "length" if kind == "P" else "angle"
                home = self.scalar(j.home[n], j.path + ("home", n), self.env, dim) if n < len(j.home) else ca.SX(0)
                sym = ca.SX.sym(name)
                fam = j.limit or family(name)
                what = "its actuator's joint" if actuated is not None else "a tree coordinate"
                coord = Coordinate(name, dim, f"{j.type} joint {g.name} ({g.a} - {g.b}), {what}", fam)
                # a flexure's limits are a deflection about the joint's value in the drawing
                limit = None if actuated is not None else self.flexure_range(g, dim, home)  # type: ignore[arg-type]
                self.extra.append((coord, sym, home, limit, j.path))
                g.values.append(sym - home)
                if actuated is not None:
                    self.actuation_rows.append((sym - home - actuated, f"actuator {j.actuated}: joint {g.name}", dim))
                    self.actuated_coords.add(name)

    def motion(self, g: _GJoint) -> tuple[ca.SX, ca.SX]:
        """The pose of b relative to a (both frames the world at the drawing): b's point onto a's,
        then the joint's motions about axes through it."""
        if g.type == "pose":  # the platform where its coordinates put it (the legs generator's platform_point)
            R = self.R @ self.R_home.T
            return R, self.P - R @ self.P_home
        T = _shift(g.pa)
        motions = elementary_motions(g) if g.type != "distance" else []  # type: ignore[arg-type]
        for (kind, axis), value in zip(motions, g.values):
            T = _compose(T, (ca.SX.eye(3), value * axis) if kind == "P" else (rot(axis, value), ca.SX.zeros(3)))
        return _compose(T, _shift(-g.pb))

    def poses(self) -> None:
        ground = self.ground
        self.pose[ground] = (ca.SX.eye(3), ca.SX.zeros(3))
        self.angle = {ground: ca.SX(0)}
        order = [ground]
        k = 0
        while k < len(order):
            body = order[k]
            for child, link in self.parent.items():
                if link is not None and link[0] == body:
                    g = link[1]
                    R, t = self.motion(g)
                    if g.reversed:  # a = child: T_a = T_b M^-1
                        R, t = R.T, -R.T @ t
                    self.pose[child] = _compose(self.pose[body], (R, t))
                    turn = g.values[0] if g.type == "planar_R" else 0  # planar: a body's angle, summed exactly
                    self.angle[child] = self.angle[body] + (-turn if g.reversed else turn)
                    order.append(child)
            k += 1

    def tree_columns(self) -> list[int]:
        """The pose coordinates that are tree joints' values (the platform's too when it is placed)."""
        placed = self.d.platform.placed
        return [k for k, n in enumerate(self.x_names) if placed or n not in self.d.platform.coordinates]

    def world(self, body: str, p: ca.SX) -> ca.SX:
        R, t = self.pose[body]
        return R @ p + t

    # -- rows --------------------------------------------------------------------------------
    def cut_rows(self, g: _GJoint, scale: ca.SX) -> list[tuple[ca.SX, str]]:  # noqa: C901 - one rule per joint type
        """The loop a cut joint closes: its rows (all of them; the independent ones are kept later)."""
        Ra, Rb = self.pose[g.a][0], self.pose[g.b][0]
        wa, wb = self.world(g.a, g.pa), self.world(g.b, g.pb)
        d = wb - wa
        planar = self.d.platform.planar
        rows: list[tuple[ca.SX, str]] = []
        if g.type == "distance":
            return [((ca.dot(d, d) - g.length**2) / (2 * g.length), "length")]
        if g.type in ("S", "planar_R", "R", "U"):
            rows += [(d[k], f"point {'xyz'[k]}") for k in range(2 if planar else 3)]
        if g.type in ("C", "P", "planar_P"):
            if planar:
                rows.append((ca.cross(Ra @ g.axis, d)[2], "offset across the axis"))
            else:
                n1, n2 = self.normals(g)
                rows += [
                    (ca.dot(Ra @ n1, d), "offset across the axis, 1"),
                    (ca.dot(Ra @ n2, d), "offset across the axis, 2"),
                ]
        if g.type in ("R", "C"):
            n1, n2 = self.normals(g)
            wa_axis = Ra @ g.axis
            rows += [(ca.dot(wa_axis, Rb @ n) * scale, f"axes parallel, {k + 1}") for k, n in enumerate((n1, n2))]
        if g.type == "U":
            rows.append((ca.dot(Ra @ g.axes[0], Rb @ g.axes[1]) * scale, "axes normal"))
        if g.type == "P":
            v = vee(Ra.T @ Rb) * scale
            rows += [(v[k], f"no relative rotation, {'xyz'[k]}") for k in range(3)]
        if g.type == "planar_P":
            rows.append(((Ra.T @ Rb)[1, 0] * scale, "no relative rotation"))
        return rows

    def normals(self, g: _GJoint) -> tuple[ca.SX, ca.SX]:
        """Two unit vectors normal to a joint's axis (and to each other): n1 = unit(w × e), n2 = w × n1,
        e the basis vector least aligned with w (with the parameters' defaults)."""
        w = g.axis
        value = np.abs(np.asarray(ca.Function("axis", [self.p], [w])(self.p_default), dtype=float).ravel())
        e = ca.DM.zeros(3)
        e[int(np.argmin(value))] = 1.0
        n1 = ca.cross(w, e)
        n1 = n1 / ca.norm_2(n1)
        return n1, ca.cross(w, n1)

    def report_cut(self, g: _GJoint) -> None:
        """A cut joint's values (when named): home + its displacement from the drawing."""
        j = g.spec
        if not j.coordinates:
            return
        Ra, Rb = self.pose[g.a][0], self.pose[g.b][0]
        M = Ra.T @ Rb
        d = Ra.T @ (self.world(g.b, g.pb) - self.world(g.a, g.pa))
        if g.type == "planar_R":
            vals = [ca.atan2(M[1, 0], M[0, 0])]
        elif g.type in ("R", "C"):
            vals = [ca.atan2(ca.dot(g.axis, vee(M)), (ca.trace(M) - 1) / 2)]
            if g.type == "C":
                vals.append(ca.dot(g.axis, d))
        elif g.type in ("P", "planar_P"):
            vals = [ca.dot(g.axis, d)]
        elif g.type == "U":
            F = ca.horzcat(g.axes[0], g.axes[1], ca.cross(g.axes[0], g.axes[1]))
            vals = xyz_angles(F.T @ M @ F)[:2]
        else:  # S
            F = ca.horzcat(*g.axes) if g.axes else ca.SX.eye(3)
            vals = xyz_angles(F.T @ M @ F)
        for k, (name, v) in enumerate(zip(j.coordinates, vals)):
            dim = JOINT_DIMS.get(g.type, "angle") if not (g.type == "C" and k == 1) else "length"
            home = self.scalar(j.home[k], j.path + ("home", k), self.env, dim) if k < len(j.home) else 0
            desc = f"{j.type} joint {g.name} ({g.a} - {g.b}), closing loop {g.loop}"
            self.reported.append(
                Reported(
                    Coordinate(name, dim, desc, j.limit or family(name)),
                    home + v,
                    self.flexure_range(g, dim, home),  # type: ignore[arg-type]
                    j.path,
                )
            )

    def platform_graph(self, scale: ca.SX) -> None:
        """The rows that say the platform coordinates locate the platform body (and its point)."""
        pf = self.d.platform
        names = [b.name for b in self.d.bodies]
        if pf.placed:  # placed by the coordinates (a joint of the tree): no rows
            self.platform_body = "platform"
            self.platform_radius += [ca.norm_2(p - self.P_home) for p in self.body_points["platform"].values()]
            return
        if not pf.coordinates and pf.body is None:  # the pose is the joints': the platform is the ground
            self.platform_body = self.ground
            self.P, self.R = ca.SX.zeros(3), ca.SX.eye(3)
            return
        body = pf.body or "platform"
        if body not in names:
            raise InputError(
                f"no body {body!r} for the platform coordinates; the bodies are {', '.join(names)}",
                path=("platform", "body"),
                suggestions=suggest(body, names),
            )
        if pf.point is not None and pf.point not in self.body_points[body]:
            raise InputError(
                f"{pf.point!r} is not a point of {body!r}; it carries "
                f"{', '.join(self.body_points[body]) or 'no points'}",
                path=("platform", "point"),
                suggestions=suggest(pf.point, self.body_points[body]),
            )
        self.platform_body = body
        self.x_pf = self.x  # the platform coordinates alone (the tree coordinates come later)
        point = self.body_points[body][pf.point] if pf.point is not None else ca.SX.zeros(3)
        Rb, _t = self.pose[body]
        where = self.world(body, point)
        n = 2 if pf.planar else 3
        if self.P is None:
            self.P = where
        else:
            self.platform_rows += [
                (self.P[k] - where[k], f"platform: {'xyz'[k]} of {body}.{pf.point or 'origin'}") for k in range(n)
            ]
        if not pf.rotation:
            self.R = Rb
        else:
            if pf.planar:  # the body's angle is a sum of joint values: a linear row, no spurious half turn
                path = ("platform", "rotation")
                phi = sum(self.scalar(a, path + (k, 1), self.xenv, "angle") for k, (_axis, a) in enumerate(pf.rotation))
                phi_home = ca.substitute(phi, self.x_pf, self.x_home)
                self.platform_rows.append(((self.angle[body] + phi_home - phi) * scale, f"platform: angle of {body}"))
            else:
                M = self.R.T @ Rb @ self.R_home
                v = vee(M) * scale
                self.platform_rows += [(v[k], f"platform: rotation of {body}, {'xyz'[k]}") for k in range(3)]
                # the rows also vanish at a half turn: that solution is not the platform's
                self.branch.append(
                    (
                        (ca.trace(M) - 1) / 2,
                        "platform_rotation",
                        f"cos of the turn between the platform coordinates' rotation and the body {body}'s "
                        "(negative: the spurious solution half a turn away)",
                    )
                )
        self.platform_radius.append(
            ca.mmax(ca.vertcat(*[ca.norm_2(p - point) for p in self.body_points[body].values()] or [ca.SX(0)]))
        )

    # -- the whole closure ---------------------------------------------------------------------
    def build(self) -> dict[str, Any]:  # noqa: C901 - one step per section of the description
        d = self.d
        self.p_default = _defaults(d)
        self.platform()
        self.read_bodies()
        self.read_joints()
        self.spanning_tree()
        self.tree_coordinates()
        if not self.q_coords:
            raise InputError("no actuators: mark joints 'actuated: name'", path=("joints",))
        self.poses()
        pts = [p for pts in self.body_points.values() for p in pts.values()]
        span = ca.mmax(ca.vertcat(*[ca.norm_2(p - pts[0]) for p in pts])) if pts else ca.SX(1)
        scale = ca.fmax(span, 1e-9)
        self.scale = scale
        for g in self.gjoints:
            if not g.tree:
                self.loop_rows += [
                    (r, f"loop {g.loop} ({g.name}, {g.type}): {what}", g.loop) for r, what in self.cut_rows(g, scale)
                ]
                self.report_cut(g)
        self.platform_graph(scale)
        if self.platform_body == self.ground:  # no platform body: the linkage's size is its drawing's
            self.platform_radius.append(span / 2)
        self.add_unknowns()
        q = ca.vertcat(*self.q_syms)
        for name, (body, point, desc) in d.outputs.items():
            w = self.world(body, self.body_points[body][point])
            for k in range(2 if d.platform.planar else 3):
                coord = Coordinate(
                    f"{name}_{'xyz'[k]}", "length", desc or f"{'xyz'[k]} of {body}.{point}", f"{name}_{'xyz'[k]}"
                )
                self.reported.append(Reported(coord, w[k], None, ("outputs", name)))
        full = dict(self.xenv)
        for c, s in zip(self.q_coords, self.q_syms):
            self.bind(full, c.name, ex.Value(s, ex.DIMENSION_OF[c.kind]), ("joints", c.name))
        for k, name in enumerate(self.x_names):
            if name not in full:
                full[name] = ex.Value(self.x[k], ex.DIMENSION_OF[self.x_coords[k].kind])
        added = branch_expressions(self, full)
        for qty in d.passive:
            v = self.value(qty.value, ("passive", qty.name), full, qty.dimension)
            dim = qty.dimension or ("length" if v.dim and v.dim[0] else "angle")
            self.reported.append(
                Reported(
                    Coordinate(qty.name, dim, qty.description, qty.family or family(qty.name)),
                    v.sx,
                    None,
                    ("passive", qty.name),
                )
            )
        self.unique_names()
        self.assembler = Assembler(self, q, span)
        keep = self.assembler.select_rows()
        if self.assembler.info.mobility != len(self.q_coords):
            raise InputError(self.assembler.mobility_message(), path=("joints",))
        self.normal_form = len(keep) < len(self.loop_rows)
        act = self.actuation()
        if self.normal_form:  # overconstrained: the normal equations of every loop row (see normal_rows)
            self.rows = self.normal_rows(scale) + act + self.platform_rows
        else:
            self.rows = [(r, name) for r, name, _loop in self.loop_rows] + act + self.platform_rows
        npf = len([n for n in self.x_names if n in d.platform.coordinates])
        if len(self.platform_rows) != npf and not d.platform.placed:
            raise InputError(
                f"the platform's position and rotation locate {len(self.platform_rows)} coordinate(s) of the body "
                f"{self.platform_body!r}, and {npf} platform coordinate(s) are declared "
                f"({', '.join(self.x_names[:npf])})",
                path=("platform", "coordinates"),
                hint="each coordinate of position and rotation is one platform coordinate; fix the others",
            )
        if len(self.rows) != len(self.x_names):
            raise InputError(self.assembler.mobility_message(), path=("joints",))
        for k, t in enumerate(d.platform.task):
            if t not in self.x_names:
                raise InputError(
                    f"unknown task coordinate {t!r}; the pose coordinates are {', '.join(self.x_names)} (the "
                    "platform's coordinates and the joints' values; an actuator's name is an input)",
                    path=("platform", "task", k),
                    suggestions=suggest(t, self.x_names),
                )
        if not self.normal_form:
            self.graph_indicators(q)
        select_branch(self, added)
        self.check_task_count()
        fns = closure_functions(self, q)
        fns["assemble"] = self.assembler
        if self.normal_form:
            # every closure equation: the loop rows, then Φ's own rows (actuation, platform).  The
            # normal equations also vanish where |r| is least but not zero: a pose is checked on
            # these, and the closure's conditioning is their Jacobian's (LoopClosure.cond_matrix)
            act = self.actuation()
            e = ca.vertcat(*[row[0] for row in self.loop_rows], *[r[0] for r in act + self.platform_rows])
            fns["loops"] = ca.Function("loops", [self.x, q, self.p], [e], ["x", "q", "p"], ["r"])
        fns["graph_drawing"] = self.drawing_function(q)
        self.info = self.assembler.info
        return fns

    def graph_indicators(self, q: ca.SX) -> None:
        """One indicator per diagonal block of Φ_x (block-triangular form) that holds loop rows: the
        sign of the block's determinant is the assembly mode of the loops it holds; it is taken as
        the reference configuration's, and scaled by the determinant's size at the drawing."""
        phi = ca.vertcat(*[r[0] for r in self.rows])
        J = ca.jacobian(phi, self.x)
        if ca.sprank(J.sparsity()) < J.size1():
            return
        nb, rowperm, colperm, rowblock, colblock, *_ = J.sparsity().btf()
        nloop = sum(1 for r in self.rows if r[1].startswith("loop "))
        xq = ca.vertcat(self.x, q)
        draw = ca.vertcat(self.x_home, *self.q_home)
        for k in range(nb):
            rows = rowperm[rowblock[k] : rowblock[k + 1]]
            cols = colperm[colblock[k] : colblock[k + 1]]
            loops = sorted({int(self.rows[r][1].split()[1]) for r in rows if r < nloop})
            if not loops or len(cols) > ASPECT_MAX_NX:
                continue
            d = twist_determinant(phi[rows], ca.vertcat(*[self.x[c] for c in cols]), None)
            sign = self.assembler.reference_sign(d)
            scale = ca.fmax(ca.fabs(ca.substitute(d, xq, draw)), 1e-300)
            name = "loop" + "_".join(str(n) for n in loops)
            taken, base, m = {b[1] for b in self.branch}, name, 2
            while name in taken:  # another block of the same loops (the 3-PRC's platform closes two)
                name, m = f"{base}_block{m}", m + 1
            what = (
                f"assembly mode of loop{'s' if len(loops) > 1 else ''} {', '.join(map(str, loops))}: det of "
                f"{'their' if len(loops) > 1 else 'its'} block of Φ_x, signed as at the reference configuration"
            )
            self.branch.append((sign * d / scale, name, what))

    def limit_options(self) -> tuple:
        """As the legs', less the families of the actuated joints' own coordinates (their actuators' limits hold)."""
        own = {c.group for c in self.x_coords if c.name in self.actuated_coords}
        others = {c.group for c in self.x_coords if c.name not in self.actuated_coords} | {
            r.coord.group for r in self.reported
        }
        return tuple(o for o in super().limit_options() if o.name not in own - others)

    def actuation(self) -> list[tuple[ca.SX, str]]:
        """The actuation rows, in the units of the loops' (an angle times the drawing's size)."""
        return [(r * self.scale if dim == "angle" else r, name) for r, name, dim in self.actuation_rows]

    def normal_rows(self, scale: ca.SX) -> list[tuple[ca.SX, str]]:
        """An overconstrained graph (loop rows that repeat others at the reference configuration,
        as the Bennett linkage's): Φ's loop part is J_tᵀ r / size, r every loop row, J_t its
        Jacobian in the passive tree coordinates -- square, zero on the mechanism's motion, and
        regular wherever the loops' Jacobian keeps its rank (any fixed choice of rows loses rank
        somewhere along the motion, where the rows it left out would not).  The passive tree
        coordinates are :meth:`tree_columns` less the actuated joints': with a placed platform (an
        expanded legs file) the platform coordinates too, which then have no rows of their own."""
        r = ca.vertcat(*[row[0] for row in self.loop_rows])
        tree = [k for k in self.tree_columns() if self.x_names[k] not in self.actuated_coords]
        xt = ca.vertcat(*[self.x[k] for k in tree])
        g = ca.jacobian(r, xt).T @ r / scale
        return [(g[k], f"loops, normal equation of {self.x_names[tree[k]]}") for k in range(len(tree))]

    # -- drawing ---------------------------------------------------------------------------
    def drawing_function(self, q: ca.SX) -> tuple[ca.Function, list]:
        """Every body's points at the pose (x, q, p), and what to draw: the layout."""
        # a point name on several bodies is one drawn point where a joint keeps them together
        # (R, U, S, planar R at that point); across a P or C joint, or unjoined, a point of its own
        root: dict[tuple, tuple] = {}

        def find(k: tuple) -> tuple:
            while root.get(k, k) != k:
                k = root[k]
            return k

        for g in self.gjoints:
            at = g.spec.at
            if isinstance(at, str) and g.type in ("R", "U", "S", "planar_R"):
                root[find((g.b, at))] = find((g.a, at))
        drawn: dict[tuple, str] = {}
        cols, layout = [], []
        for body in self.d.bodies:
            for name, p in self.body_points[body.name].items():
                key = find((body.name, name))
                if key not in drawn:
                    drawn[key] = name + "'" * sum(1 for k in drawn if k[1] == name)
                cols.append(self.world(body.name, p))
                layout.append((body.name, drawn[key]))
        for g in self.gjoints:
            if (isinstance(g.spec.at, str) and g.spec.at.isidentifier()) or g.type == "pose":
                continue
            cols.append(self.world(g.a, g.pa))
            layout.append((g.a, g.name))
        cols.append(self.P)
        fn = ca.Function("drawing_points", [self.x, q, self.p], [ca.horzcat(*cols)], ["x", "q", "p"], ["points"])
        return fn, layout


class Assembler:
    """The reference configuration of a graph by assembly from its drawing, and the loops' rank.

    ``assembler(p) -> (x_home, q_home)``: Gauss-Newton (minimum-norm steps, halved until the
    residual falls) on every loop row and the platform rows, from the drawing, with the actuators
    at their drawing values; an :class:`InputError` when it does not assemble."""

    def __init__(self, gen: GraphGenerator, q: ca.SX, span: ca.SX) -> None:
        self.gen = gen
        x, p = gen.x, gen.p
        act = gen.actuation()
        rows = ca.vertcat(*[r[0] for r in gen.loop_rows], *[r[0] for r in act], *[r[0] for r in gen.platform_rows])
        self.names = [r[1] for r in gen.loop_rows] + [r[1] for r in act] + [r[1] for r in gen.platform_rows]
        self.nloop = len(gen.loop_rows)
        self.F = ca.Function(
            "assembly_rows",
            [x, q, p],
            [rows, ca.jacobian(rows, x), ca.jacobian(rows, q)],
            ["x", "q", "p"],
            ["r", "r_x", "r_q"],
        )
        self.draw = ca.Function(
            "drawing_pose", [p], [gen.x_home, ca.vertcat(*gen.q_home), span], ["p"], ["x", "q", "span"]
        )
        self.defaults = gen.p_default
        self.info: GraphInfo | None = None
        self._cache: dict[bytes, tuple[np.ndarray, np.ndarray]] = {}

    # -- assembly ----------------------------------------------------------------------------
    def solve(self, p: np.ndarray) -> tuple[np.ndarray, np.ndarray, dict[str, Any]]:
        x0, q0, span = (np.asarray(v, dtype=float).ravel() for v in self.draw(p))
        x = x0.copy()
        tol = ASSEMBLY_TOL * max(float(span[0]), 1e-9)
        r, J, _Jq = (np.asarray(v, dtype=float) for v in self.F(x, q0, p))
        r = r.ravel()
        start = float(np.max(np.abs(r))) if r.size else 0.0
        steps = 0
        while r.size and np.all(np.isfinite(r)) and np.max(np.abs(r)) > tol and steps < ASSEMBLY_STEPS:
            if not np.all(np.isfinite(J)):  # a derivative that is not finite (a root at 0): no step to take
                break
            step = np.linalg.lstsq(J, -r, rcond=None)[0]
            norm, alpha = float(np.linalg.norm(r)), 1.0
            while alpha > 1e-6:
                trial = x + alpha * step
                rt = np.asarray(self.F(trial, q0, p)[0], dtype=float).ravel()
                if np.all(np.isfinite(rt)) and np.linalg.norm(rt) < norm:
                    break
                alpha /= 2
            else:
                break
            x = trial
            r, J, _Jq = (np.asarray(v, dtype=float) for v in self.F(x, q0, p))
            r = r.ravel()
            steps += 1
        worst = int(np.argmax(np.abs(r))) if r.size else 0
        ok = bool(r.size == 0 or (np.all(np.isfinite(r)) and abs(r[worst]) <= tol))
        moved = x - x0
        status = {
            "assembled": ok,
            "steps": steps,
            "residual_at_drawing": start,
            "residual": float(np.max(np.abs(r))) if r.size else 0.0,
            "worst_row": self.names[worst] if r.size else "",
            "largest_move": (self.gen.x_names[int(np.argmax(np.abs(moved)))], float(np.max(np.abs(moved))))
            if moved.size
            else ("", 0.0),
        }
        return x, q0, status

    def __call__(self, p: Any) -> tuple[np.ndarray, np.ndarray]:
        p = np.asarray(p, dtype=float).ravel()
        key = p.tobytes()
        hit = self._cache.get(key)
        if hit is not None:
            return hit[0].copy(), hit[1].copy()
        x, q, status = self.solve(p)
        if not status["assembled"]:
            raise InputError(
                f"the reference configuration does not assemble from the drawing: after {status['steps']} "
                f"Gauss-Newton step(s) the residual is {status['residual']:.3e} (SI) in {status['worst_row']} "
                f"(at the drawing {status['residual_at_drawing']:.3e})",
                path=("joints",),
                hint="draw the mechanism closer to an assembled configuration on the branch you want, or check "
                "that the links can close with these parameters",
            )
        log.debug("%s: assembled from the drawing in %d step(s)", self.gen.d.name, status["steps"])
        if len(self._cache) < 64:
            self._cache[key] = (x.copy(), q.copy())
        return x, q

    # -- the loops' rank -------------------------------------------------------------------------
    def select_rows(self) -> list[int]:
        """The loop rows independent at the reference configuration (with the parameters'
        defaults), in file order; the mobility and Grübler-Kutzbach counts for ``describe``."""
        gen = self.gen
        x, q, status = self.solve(self.defaults)
        if not status["assembled"]:
            x0, _q0, _span = (np.asarray(v, dtype=float).ravel() for v in self.draw(self.defaults))
            Jx = np.asarray(self.F(x0, _q0, self.defaults)[1], dtype=float)
            cols = gen.tree_columns()
            free = len(cols) - int(np.linalg.matrix_rank(Jx[: self.nloop][:, cols]))
            if free < len(gen.q_coords):  # the actuators lock the loops against each other
                raise InputError(
                    f"wrong mobility: at the drawing the loops leave {free} degree(s) of freedom, and "
                    f"{len(gen.q_coords)} joint(s) are actuated ({', '.join(c.name for c in gen.q_coords)}); "
                    "actuate fewer joints (the reference configuration cannot assemble with all of them held)",
                    path=("joints",),
                )
            raise InputError(
                f"the reference configuration does not assemble from the drawing with the parameters' defaults: "
                f"after {status['steps']} step(s) the residual is {status['residual']:.3e} (SI) in "
                f"{status['worst_row']}",
                path=("joints",),
                hint="draw the mechanism closer to an assembled configuration, or check the link lengths",
            )
        _r, Jx, Jq = (np.asarray(v, dtype=float) for v in self.F(x, q, self.defaults))
        cols = gen.tree_columns()
        ntree = len(cols)
        J = Jx[: self.nloop][:, cols]
        keep, basis = [], np.zeros((0, J.shape[1]))
        for k in range(J.shape[0]):
            row = J[k]
            n = np.linalg.norm(row)
            if n == 0:
                continue
            rest = row - basis.T @ (basis @ row) if basis.size else row
            if np.linalg.norm(rest) > RANK_TOL * n:
                keep.append(k)
                basis = np.vstack([basis, rest / np.linalg.norm(rest)])
        self.J_ref, self.tree_names = J, [gen.x_names[k] for k in cols]
        rank = len(keep)
        mobility = ntree - rank
        lam = 3 if gen.d.platform.planar else 6
        freedom = [
            _ROD_FREEDOM[gen.d.platform.planar]
            if g.type == "distance"
            else len(g.names)
            if g.type == "pose"
            else JOINT_TYPES[g.type].dof
            for g in gen.gjoints
        ]
        gk = lam * (len(gen.d.bodies) - 1) - sum(lam - f for f in freedom)
        dropped = [(int(self.names[k].split()[1]), self.names[k]) for k in range(self.nloop) if k not in keep]
        loops = [(g.loop, g.name, gen.loop_bodies(g)) for g in gen.gjoints if not g.tree]
        self.info = GraphInfo(
            bodies=[b.name for b in gen.d.bodies],
            ground=gen.ground,
            joints=[(g.name, g.type, g.a, g.b, g.spec.actuated is not None, g.tree, g.loop) for g in gen.gjoints],
            loops=loops,
            gruebler=gk,
            mobility=mobility,
            dropped=dropped,
        )
        self.x_ref, self.q_ref = x, q
        return keep

    def mobility_message(self) -> str:
        info, gen = self.info, self.gen
        nq = len(gen.q_coords)
        text = (
            f"wrong mobility: the loops' Jacobian at the reference configuration gives {info.mobility} degree(s) "
            f"of freedom (Grübler-Kutzbach: {info.gruebler}), and {nq} joint(s) are actuated "
            f"({', '.join(c.name for c in gen.q_coords)})"
        )
        if info.mobility > nq:
            # the joints the free motions move: the rows of the whole null space (not one basis vector)
            _u, sv, vt = (
                np.linalg.svd(self.J_ref) if self.J_ref.size else (None, np.zeros(0), np.eye(len(self.tree_names)))
            )
            rank = int(np.sum(sv > RANK_TOL * max(float(sv[0]) if sv.size else 1.0, 1e-300)))
            share = np.linalg.norm(vt[rank:], axis=0)
            moving = [n for n, v in zip(self.tree_names, share) if v > 1e-6 * max(float(np.max(share)), 1e-300)]
            text += f"; the free motions move {', '.join(moving)}: actuate more joints, or join those bodies"
        else:
            text += "; actuate fewer joints (an actuated joint is locked against the others)"
        return text

    def reference_sign(self, d: ca.SX) -> float:
        gen = self.gen
        f = ca.Function("block_det", [gen.x, ca.vertcat(*gen.q_syms), gen.p], [d])
        v = float(f(self.x_ref, self.q_ref, self.defaults))
        if not (math.isfinite(v) and v != 0.0):
            raise InputError(
                "the reference configuration is singular: a loop's Jacobian loses rank there (its links are "
                "aligned); draw the mechanism away from the singular configuration",
                path=("joints",),
            )
        return 1.0 if v > 0 else -1.0


def closure_parts(d: Description) -> tuple[Generator, dict[str, Any]]:
    """The generator of a description -- its legs (:class:`Generator`) or its bodies and joints
    (:class:`GraphGenerator`) -- and the functions it built.  A legs file whose drawing need not
    close (:func:`assembled_from_drawing`) gets its reference configuration by the assembly of
    the graph its legs expand into (:class:`LegsAssembler`); its closures stay the legs'."""
    if d.is_graph:
        if d.legs:  # a mixed file: its legs expanded, one graph with its bodies and joints
            from .expand import expand_legs

            d = expand_legs(d)
        g = GraphGenerator(d)
        return g, g.build()
    g = Generator(d)
    fns = g.build()
    if assembled_from_drawing(d):
        fns["assemble"] = LegsAssembler(d, g)
    return g, fns


def assembled_from_drawing(d: Description) -> bool:
    """Whether a legs file's reference configuration is assembled: a leg's links are drawn by
    their joints, so its drawing closes by construction, except where a rod (a distance joint)
    gives its ``length``: then the drawing's ``to`` (and the platform's home) is only roughly
    there."""
    return any(j.length is not None for leg in d.legs for j in leg.joints)


class LegsAssembler:
    """The reference configuration of a legs file from a rough drawing: the :class:`Assembler` of
    the graph its legs expand into (:func:`.expand.expand_legs`; Gauss-Newton on its loops with the
    actuators at their drawn values), its pose coordinates read by name into the legs' (the
    platform's, then each proximal chain's passive joints')."""

    def __init__(self, d: Description, legs: Generator) -> None:
        from .expand import expand_legs, expansion_gap  # expand imports this module's reader

        gap = expansion_gap(d)
        if gap is not None:
            raise InputError(
                f"a rod's given length makes the reference configuration an assembly, and {gap}",
                path=("legs",),
                hint="give the rods' lengths by their drawing (no 'length'), or write the loops as legs",
            )
        for par in d.parameters:
            if par.default is REQUIRED:
                raise InputError(
                    f"a legs file assembled from its drawing (a rod gives its 'length') needs a default for every "
                    f"parameter ({par.name!r} has none): the loops' rank is taken with the defaults",
                    path=("parameters", par.name, "default"),
                )
        try:
            self.graph = GraphGenerator(expand_legs(d))
            self.graph.build()
        except InputError as exc:
            raise _in_legs(exc) from None
        self.assembler = self.graph.assembler
        where = {n: k for k, n in enumerate(self.graph.x_names)}
        self.columns = []
        for name in legs.x_names:
            # a passive joint of one motion is the graph's joint name (the legs add "_1")
            short = name[:-2] if name.endswith("_1") else name
            k = where.get(name, where.get(short))
            if k is None:  # every legs coordinate is a tree coordinate of the expansion
                raise RuntimeError(f"the expanded graph of {d.name} has no coordinate {name!r}")
            self.columns.append(k)

    def solve(self, p: np.ndarray) -> tuple[np.ndarray, np.ndarray, dict[str, Any]]:
        x, q, status = self.assembler.solve(p)
        return x[self.columns], q, status

    def __call__(self, p: Any) -> tuple[np.ndarray, np.ndarray]:
        try:
            x, q = self.assembler(p)
        except InputError as exc:
            raise _in_legs(exc) from None
        return x[self.columns], q


def _in_legs(exc: InputError) -> InputError:
    """An error of the expanded graph, located in the legs file (its joints are the legs')."""
    path = exc.path if exc.path and exc.path[0] != "joints" else ("legs",)
    return InputError(exc.message, path=path, suggestions=exc.suggestions, hint=exc.hint)


def _defaults(d: Description) -> np.ndarray:
    """The parameters' defaults: the loops' rank is taken with them at the reference configuration."""
    vals = []
    for par in d.parameters:
        if par.default is REQUIRED:
            raise InputError(
                f"a file of bodies and joints needs a default for every parameter ({par.name!r} has none): "
                "the loops' rank is taken at the reference configuration with the defaults",
                path=("parameters", par.name, "default"),
            )
        vals.append(float(par.default))
    return np.array(vals)


def graph_geometry(fn: ca.Function, layout: list, gen: GraphGenerator) -> Callable[[Any, Any, Any], Drawing]:
    """The ``geometry`` capability of a graph: every body's points, each body a segment (two
    points) or a face (three or more); the ground as the base, the platform body as the platform."""
    d = gen.d
    ground, platform = gen.ground, gen.platform_body
    actuated = {g.b if not g.reversed else g.a for g in gen.gjoints if g.tree and g.spec.actuated is not None}
    named = [(g, g.spec.at if isinstance(g.spec.at, str) and g.spec.at.isidentifier() else g.name) for g in gen.gjoints]
    letters = {key: JOINT_TYPES[g.type].letter for g, key in named if g.type not in ("distance", "pose")}
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
        segments += rods(pts)
        note = "bodies as straight links (two points) or polygons (three or more) through their points"
        if d.platform.planar:
            note += "; a planar mechanism, drawn in its plane z = 0"
        return Drawing(
            points=pts,
            segments=tuple(segments),
            faces=tuple(faces),
            joints={n: letter for n, letter in letters.items() if n in pts},
            note=note,
        )

    return geometry


__all__ = ["Assembler", "GraphGenerator", "GraphInfo", "closure_parts", "graph_geometry"]
