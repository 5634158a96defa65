"""Bodies and joints: a mechanism file as a graph of rigid bodies joined by joints, any topology.

The formulation (relative coordinates with cut joints, as multibody codes write closed loops):

* Every body's frame is the world frame at the *drawing* (the configuration the file draws); a
  body's points, given there, are its geometry.  A pose of a body is (R, t): a point p of the body
  is at R p + t.
* A spanning tree of the graph, grown from the ground (actuated joints first, then in file order;
  a ``distance`` joint is a rod, never a tree edge), places every body by the product of the
  exponentials of the tree joints' displacements from the drawing.  A tree joint brings its point
  on the distal body onto its point on the proximal one, so a rough drawing (the two points apart)
  costs nothing (`graph_tree`).
* Each joint left out of the tree closes one loop (the fundamental cycles of the tree: a cycle
  basis).  Its rows say that the two bodies' relative motion is one the joint allows: a point joint
  (S; planar R) keeps its two points together, an R also keeps the axes parallel, a P keeps the
  relative rotation and the offset along the axis, a distance joint the rod's length
  (`graph_rows`).
* Mobility is the number of tree coordinates less the rank of the loops' Jacobian at the reference
  configuration (so an overconstrained linkage such as the Bennett linkage loads); the rows are
  kept that are independent there, in file order.  Grübler-Kutzbach is counted beside it
  (`mobility`).
* The reference configuration is assembled from the drawing: a Gauss-Newton solve on the loops
  with the actuators at their ``home`` values, for any parameter values (`assembly.Assembler`).
* The pose coordinates are the platform's (``platform.body``, ``platform.point``): rows that say
  the platform coordinates locate that body, then the passive tree coordinates.

See docs/site/guide/mechanism-files.md, "Bodies and joints".
"""

from __future__ import annotations

from typing import Any

import casadi as ca
import numpy as np

from ...core.errors import InputError, suggest
from ...core.joints import JOINT_TYPES, joint_types
from ...core.model import Coordinate
from ...core.options import REQUIRED
from ...core.screws import vee
from . import expr as ex
from .assembly import Assembler
from .branches import branch_expressions, graph_indicators, select_branch
from .builder import ClosureBuilder, Reported, family
from .drawing import graph_drawing_points
from .emit import closure_functions
from .expand import InLeg
from .graph_dyads import graph_closed_form
from .graph_rows import Cut, axis_normals, cut_rows, cut_values
from .graph_spherical import spherical_closed_form
from .graph_tree import GraphJoint, spanning_tree
from .mobility import GraphInfo
from .motions import JOINT_DIMS, elementary_motions, rot
from .spec import GROUND_NAMES, Description, Joint


def _compose(A: tuple, B: tuple) -> tuple:
    return A[0] @ B[0], A[0] @ B[1] + A[1]


def _shift(v: ca.SX) -> tuple:
    return ca.SX.eye(3), v


class GraphGenerator(ClosureBuilder):
    """Builds the symbolic closure of a bodies-and-joints description (errors carry key paths)."""

    def __init__(self, d: Description) -> None:
        super().__init__(d)
        self.gjoints: list[GraphJoint] = []
        self.body_points: dict[str, dict[str, ca.SX]] = {}
        self.pose: dict[str, tuple[ca.SX, ca.SX]] = {}
        self.parent: dict[str, tuple[str, GraphJoint] | None] = {}
        self.loop_rows: list[tuple[ca.SX, str, int]] = []
        self.platform_rows: list[tuple[ca.SX, str]] = []
        #: (joint value - its actuator's, what, dimension): one per actuated joint
        self.actuation_rows: list[tuple[ca.SX, str, str]] = []
        self.actuated_coords: set[str] = set()
        self.info: GraphInfo | None = None
        self.assembler: Assembler | None = None
        #: what ``describe`` says of the closed-form FK by dyads (`graph_dyads`), if any
        self.closed_form_summary: str | None = None
        #: an expanded legs file: each leg's environment and rotation (id of the leg -> (env, turn))
        self._frames: dict[int, tuple[dict, ca.SX]] = {}

    # -- expressions of an expanded legs file (in a leg's frame: its let, index and rotation) ----
    def _leg_frame(self, leg: Any) -> tuple[dict, ca.SX]:
        """A leg's environment (parameters, derived values, its index and ``let``) and its rotation,
        as the legs generator resolves them (`generate.Generator.leg`)."""
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
        # two unit vectors across u, as a joint's normals (`graph_rows.axis_normals`)
        n1, n2 = axis_normals(u, self.p, self.p_default)
        return n1 if text.normal == 1 else n2

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

    def read_joints(self) -> None:
        """Each joint resolved to CasADi (a placed platform: first its pose joint to the ground)."""
        if self.d.platform.placed:  # the platform coordinates place the platform (an expanded legs file)
            zero = ca.SX.zeros(3)
            spec = Joint("pose", name="platform_pose", path=("platform", "coordinates"))
            self.gjoints.append(GraphJoint(spec, "pose", self.ground, "platform", zero, zero, tree=True))
        for j in self.d.joints:
            kind = self._joint_kind(j)
            g = GraphJoint(j, kind, j.between[0], j.between[1], *self._joint_points(j, kind))
            self._joint_axes(g, j, kind)
            self._joint_dof_and_rod(g, j, kind)
            self.gjoints.append(g)

    def _joint_kind(self, j: Joint) -> str:
        """The joint's type, as the mechanism's plane takes it (a planar file reads R, P as planar)."""
        planar = self.d.platform.planar
        allowed = joint_types(planar)
        jt = JOINT_TYPES[j.type]
        kind = jt.twin if planar and jt.twin and not jt.planar else j.type
        if kind not in allowed:
            raise InputError(
                f"a {'planar' if planar else 'spatial'} mechanism takes {', '.join(allowed)} joints, got {j.type}",
                path=j.path + ("type",),
                suggestions=suggest(j.type, allowed),
            )
        return kind

    def _joint_points(self, j: Joint, kind: str) -> tuple[ca.SX, ca.SX]:
        """Its point on the proximal body (``at``) and on the distal one (a distance joint: ``to``)."""
        a, b = j.between
        pa = self.point_of(a, j.at, j.path + ("at",))
        if kind == "distance":
            if j.to is None:
                raise InputError("a distance joint needs 'to' (its point on the distal body)", path=j.path)
            return pa, self.point_of(b, j.to, j.path + ("to",))
        if j.to is not None:
            raise InputError("only a distance joint has 'to'", path=j.path + ("to",))
        return pa, self.point_of(b, j.at, j.path + ("at",))

    def _joint_axes(self, g: GraphJoint, j: Joint, kind: str) -> None:
        """Its unit axis (P, R, C, planar P; z for a planar R) and axes (a U's two, an S's three)."""
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
            raise InputError(f"a {j.type} joint takes {need or 'no'} axes, got {len(j.axes)}", path=j.path + ("axes",))
        if kind == "U" and not j.axes:
            raise InputError("a U joint needs its two 'axes' (the first on the proximal body)", path=j.path)
        if kind == "S" and j.axes:
            self.independent_axes(g.axes, j.path + ("axes",))

    def _joint_dof_and_rod(self, g: GraphJoint, j: Joint, kind: str) -> None:
        """Its coordinates, one per degree of freedom; a distance joint's length (a rod, never actuated)."""
        dof = JOINT_TYPES[kind].dof
        if j.coordinates and len(j.coordinates) != dof:
            raise InputError(
                f"a {j.type} joint has {dof} coordinate(s), got {len(j.coordinates)}", path=j.path + ("coordinates",)
            )
        if kind != "distance":
            if j.length is not None:
                raise InputError(
                    f"only a distance joint has 'length' (a {j.type} joint's bodies carry its points)",
                    path=j.path + ("length",),
                )
            return
        if j.actuated is not None:
            raise InputError("a distance joint cannot be actuated (a P joint between two bodies can)", path=j.path)
        if j.length is not None:
            g.length = self.scalar(j.length, j.path + ("length",), self.env, "length")
        else:
            g.length = ca.norm_2(g.pb - g.pa)

    # -- the tree and its loops ----------------------------------------------------------------
    def spanning_tree(self) -> None:
        """The spanning tree and its loops (`graph_tree.spanning_tree`): each body's parent."""
        bodies = [b.name for b in self.d.bodies]
        self.parent = spanning_tree(self.gjoints, bodies, self.ground, set(self.d.platform.task))

    # -- coordinates and poses -------------------------------------------------------------------
    def tree_coordinates(self) -> None:
        """Each tree joint's values become pose coordinates (unknowns); an actuated joint's also
        gets its actuator (q) and a row that ties the two (`actuation_rows`), so that every
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
                g.drive = actuated
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
                g.homes.append(home)
                if actuated is not None:
                    self.actuation_rows.append((sym - home - actuated, f"actuator {j.actuated}: joint {g.name}", dim))
                    self.actuated_coords.add(name)

    def motion(self, g: GraphJoint) -> tuple[ca.SX, ca.SX]:
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
    def cut(self, g: GraphJoint, scale: ca.SX) -> Cut:
        """A cut joint at the pose (`graph_rows.Cut`)."""
        return Cut(
            g,
            self.pose[g.a][0],
            self.pose[g.b][0],
            self.world(g.b, g.pb) - self.world(g.a, g.pa),
            self.d.platform.planar,
            scale,
            lambda: axis_normals(g.axis, self.p, self.p_default),
        )

    def report_cut(self, g: GraphJoint) -> None:
        """A cut joint's values (when named): home + its displacement from the drawing."""
        j = g.spec
        if not j.coordinates:
            return
        Ra, Rb = self.pose[g.a][0], self.pose[g.b][0]
        vals = cut_values(g, Ra.T @ Rb, Ra.T @ (self.world(g.b, g.pb) - self.world(g.a, g.pa)))
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
    def build(self) -> dict[str, Any]:
        """The closure: the graph, its loops and the platform's rows, the reported values, the loop
        rows kept by their rank at the reference configuration, the branch indicators, the functions."""
        self.p_default = parameter_defaults(self.d)
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
        self.scale = scale = ca.fmax(span, 1e-9)
        self.loops(scale)
        self.platform_graph(scale)
        if self.platform_body == self.ground:  # no platform body: the linkage's size is its drawing's
            self.platform_radius.append(span / 2)
        self.add_unknowns()
        q = ca.vertcat(*self.q_syms)
        self.report_outputs()
        full = self.full_env()
        added = branch_expressions(self, full)
        self.report_passive(full)
        self.unique_names()
        self.assembler = Assembler(self, q, span)
        self.select_rows(scale)
        self.check_rows()
        if not self.normal_form:
            graph_indicators(self, q)
        select_branch(self, added)
        self.check_task_count()
        fns = self.graph_functions(q)
        closed_form = graph_closed_form if self.d.platform.planar else spherical_closed_form
        fns["fk_closed"], fns["fk_seed"] = closed_form(self, q)
        self.info = self.assembler.info
        return fns

    def loops(self, scale: ca.SX) -> None:
        """Each cut joint's loop rows (`graph_rows`) and its reported values."""
        for g in self.gjoints:
            if not g.tree:
                self.loop_rows += [
                    (r, f"loop {g.loop} ({g.name}, {g.type}): {what}", g.loop)
                    for r, what in cut_rows(self.cut(g, scale))
                ]
                self.report_cut(g)

    def report_outputs(self) -> None:
        """The ``outputs``: each named point of a body, reported by its coordinates in the world."""
        d = self.d
        for name, (body, point, desc) in d.outputs.items():
            w = self.world(body, self.body_points[body][point])
            for k in range(2 if d.platform.planar else 3):
                coord = Coordinate(
                    f"{name}_{'xyz'[k]}", "length", desc or f"{'xyz'[k]} of {body}.{point}", f"{name}_{'xyz'[k]}"
                )
                self.reported.append(Reported(coord, w[k], None, ("outputs", name)))

    def full_env(self) -> dict[str, ex.Value]:
        """The symbols the ``branch`` and ``passive`` expressions may use: parameters, pose
        coordinates (the joints' too) and actuators."""
        full = dict(self.xenv)
        for c, s in zip(self.q_coords, self.q_syms):
            self.bind(full, c.name, ex.Value(s, ex.DIMENSION_OF[c.kind]), ("joints", c.name))
        for k, name in enumerate(self.x_names):
            if name not in full:
                full[name] = ex.Value(self.x[k], ex.DIMENSION_OF[self.x_coords[k].kind])
        return full

    def report_passive(self, full: dict[str, ex.Value]) -> None:
        """The ``passive`` section's values, reported beside the joints'."""
        for qty in self.d.passive:
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

    def select_rows(self, scale: ca.SX) -> None:
        """Φ's rows: the loop rows (overconstrained: their normal equations, `normal_rows`),
        the actuation rows and the platform's; the mobility checked against the actuators."""
        keep = self.assembler.select_rows()
        if self.assembler.info.mobility != len(self.q_coords):
            raise InputError(self.assembler.mobility_message(), path=("joints",))
        self.normal_form = len(keep) < len(self.loop_rows)
        act = self.actuation()
        if self.normal_form:  # overconstrained: the normal equations of every loop row (see normal_rows)
            self.rows = self.normal_rows(scale) + act + self.platform_rows
        else:
            self.rows = [(r, name) for r, name, _loop in self.loop_rows] + act + self.platform_rows

    def check_rows(self) -> None:
        """As many platform rows as platform coordinates, as many rows as pose coordinates, and
        task coordinates among the pose coordinates."""
        d = self.d
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

    def graph_functions(self, q: ca.SX) -> dict[str, Any]:
        """The closure's functions (`emit.closure_functions`), the assembly, every loop row
        of an overconstrained graph and the drawing's points."""
        fns = closure_functions(self, q)
        fns["assemble"] = self.assembler
        if self.normal_form:
            # every closure equation: the loop rows, then Φ's own rows (actuation, platform).  The
            # normal equations also vanish where |r| is least but not zero: a pose is checked on
            # these, and the closure's conditioning is their Jacobian's (LoopClosure.cond_matrix)
            act = self.actuation()
            e = ca.vertcat(*[row[0] for row in self.loop_rows], *[r[0] for r in act + self.platform_rows])
            fns["loops"] = ca.Function("loops", [self.x, q, self.p], [e], ["x", "q", "p"], ["r"])
        fns["graph_drawing"] = graph_drawing_points(self, q)
        return fns

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
        coordinates are `tree_columns` less the actuated joints': with a placed platform (an
        expanded legs file) the platform coordinates too, which then have no rows of their own."""
        r = ca.vertcat(*[row[0] for row in self.loop_rows])
        tree = [k for k in self.tree_columns() if self.x_names[k] not in self.actuated_coords]
        xt = ca.vertcat(*[self.x[k] for k in tree])
        g = ca.jacobian(r, xt).T @ r / scale
        return [(g[k], f"loops, normal equation of {self.x_names[tree[k]]}") for k in range(len(tree))]


def parameter_defaults(d: Description) -> np.ndarray:
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


__all__ = ["GraphGenerator", "parameter_defaults"]
