"""From a :class:`~.spec.Description` to a :class:`~cpm_nlp.core.model.LoopClosure`
and a :class:`~cpm_nlp.core.mechanism.Mechanism`, symbolically in CasADi.

Each leg is a serial chain given at the reference configuration (product of
exponentials: a joint's variable is its displacement from there).  Its closure
with the platform is written without the passive joints' variables, by
eliminating them from the platform end (the classical leg constraints):

* the last joint is a point joint (S; planar R) at B: the leg's side must put B
  where the platform does,
* before it, an R (spatial) at c with axis w: B stays on a circle about the
  axis, 2 equations (axial offset, radius),
* before it, a U, an S or a planar R at c (or a ``distance`` joint): B stays on
  a sphere (circle) about c, 1 equation,
* before it, a C: B stays on a cylinder, 1 equation,
* before it, a P along c->B after a U, S or planar R at c: |cB| = its length,
  1 equation,
* the joints left before those (the proximal chain) must be actuated: they
  move c by known amounts.

The eliminated joints' values (the passive joint angles) are recovered from
the chain afterwards, and each elimination gives a branch indicator, an
invariant of a mode (it changes sign only at a singularity of the sub-chain
it separates, never because a link turned far), positive at the reference
configuration (:meth:`Generator.elimination_indicators`):

* the link closes a sub-chain of its own (its rows make a diagonal block of
  Φ_x in block-triangular form with no other elimination: a four-bar's
  coupler and rocker, an RSSR's coupler and output crank, a slider-crank's
  rod and slider): that block's determinant (the passive Jacobian of the
  sub-chain) over its value at home -- its assembly mode (a triangle closed
  at a revolute: its orientation);
* the link is one of several holding a platform: the leg's working mode, the
  derivative of its closure with respect to the joint before the eliminated
  one -- for a revolute at a (axis w) moving c: the triple product
  w·((c - a) × (B - c)), the side of B of the plane through the crank and its
  axis (planar: the orientation of the triangle a, c, B, the elbow); for a P
  along e: e·(B - c); over its value at home; the platform's assembly mode
  is the ``aspect``;
* a P leg: its length over its reference length (its working mode) and the
  cosine of the leg to its reference direction.

A pure legs file keeps this generator for its closures: with each leg's passive joints
eliminated, Φ has one to three rows per leg in the platform coordinates alone, and its FK and
batch run within 1.1x of the hand-written modules (benchmarks/bench_described.py).  The same
file expanded into bodies and joints (:mod:`.expand`, every passive joint an unknown of a
spanning tree) serves ``describe``, the assembly of a rough drawing and files that mix legs
with bodies; it would be the slower closure.
"""

from __future__ import annotations

import dataclasses
import math
import re
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import casadi as ca

from ...analysis import hinge_types
from ...core.aspect import ASPECT, ASPECT_DESCRIPTION, ASPECT_MAX_NX, twist_determinant
from ...core.aspect import aspect as aspect_indicator
from ...core.errors import InputError, format_key_path, suggest
from ...core.joints import JOINT_TYPES, joint_types
from ...core.model import Coordinate
from ...core.options import Option, validate_mapping
from ...core.screws import axis_rotation
from ...core.units import parse_quantity
from . import expr as ex
from .spec import Description, Joint, Leg

# Aliases derived from the joint table (cpm_nlp.core.joints.JOINT_TYPES), for the modules that import them:
#: point joints (a leg reaches its platform point through one: S; planar R)
POINT_JOINTS = {n for n, t in JOINT_TYPES.items() if t.point}
#: what the generated indicators measure
_COSINE = "cosine of the link to the platform joint to its reference direction"
_ASSEMBLY = (
    "assembly mode of the sub-chain this link closes: det of its passive Jacobian (a block of Φ_x) "
    "over its value at home"
)
_WORKING_R = (
    "working mode: w·((c - a) × (B - c)) of the joint before it (axis w at a) and the link c -> B, "
    "over its value at home"
)
_WORKING_PLANAR = (
    "working mode (elbow): the signed area of the triangle (a, c, B) of the joint before it and the "
    "link c -> B, over its value at home"
)
_WORKING_P = "working mode: e·(B - c) of the P joint before it (axis e) and the link c -> B, over its value at home"

#: joints about a point: the link after it sweeps a sphere (circle): U, S, planar R
SPHERE_JOINTS = {n for n, t in JOINT_TYPES.items() if t.sphere}
#: the letter a drawing marks each joint type with (a distance joint: a rod between two spherical joints)
_LETTER = {n: t.letter for n, t in JOINT_TYPES.items()}
#: the dimension of the coordinates of each joint type whose coordinates share one (not C, not distance)
JOINT_DIMS = {n: t.dims[0] for n, t in JOINT_TYPES.items() if len(set(t.dims)) == 1}
#: the base frame's axes, for an S joint given without its ``axes``
_BASE_AXES = {"x": ca.DM([1.0, 0, 0]), "y": ca.DM([0, 1.0, 0]), "z": ca.DM([0, 0, 1.0])}


def _rot(axis: Any, angle: Any) -> ca.SX:
    """Rotation by ``angle`` about a unit axis k, or about "x", "y", "z" (Rodrigues,
    :func:`~cpm_nlp.core.screws.axis_rotation`: R = cos I + sin [k]x + (1 - cos) k kᵀ, whose
    zero entries of k drop out about a base axis)."""
    if isinstance(axis, str):
        axis = ca.DM([1.0 if axis == a else 0.0 for a in "xyz"])
    return ca.SX(axis_rotation(ca.SX(axis), angle))


def _is_identity(M: ca.SX) -> bool:
    """M is the constant identity (a proximal chain that only slides)."""
    return bool(M.is_constant()) and float(ca.norm_inf(ca.DM(M) - ca.DM.eye(M.size1()))) == 0.0


def _xyz_angles(M: ca.SX) -> list[ca.SX]:
    """(a, b, c) with M = Rx(a) Ry(b) Rz(c)."""
    return [ca.atan2(-M[1, 2], M[2, 2]), ca.asin(ca.fmin(ca.fmax(M[0, 2], -1), 1)), ca.atan2(-M[0, 1], M[0, 0])]


@dataclass
class _Joint:
    """A joint resolved to CasADi: location, axis, variable."""

    spec: Joint
    at: ca.SX | None = None
    to: ca.SX | None = None
    axis: ca.SX | None = None
    axes: list = field(default_factory=list)
    value: ca.SX | None = None  # displacement from the reference configuration, when known
    home: list = field(default_factory=list)
    #: elementary motions ("P" | "R", axis, displacement) of a joint in the proximal chain
    motions: list = field(default_factory=list)
    #: the coordinate names of its degrees of freedom (given, or made up for a passive unknown)
    names: tuple = ()
    #: a distance joint's given length (None: |to - at| in the drawing)
    length: ca.SX | None = None
    #: at, to, axis and axes in the leg's own frame, before a repeated leg's turn (the same as them
    #: for a leg that is not turned): the scalar products of the leg's constant vectors are taken
    #: there, where a leg's axes are the file's own (a zero product of perpendicular axes is zero)
    local: dict = field(default_factory=dict)

    @property
    def type(self) -> str:
        return self.spec.type


def elementary_motions(j: _Joint) -> list[tuple[str, Any]]:
    """A joint's degrees of freedom as elementary motions ("P" | "R", axis), in the order
    of its coordinates (product of exponentials about its reference axes): the joint table's
    motions (:data:`cpm_nlp.core.joints.JOINT_TYPES`) with the joint's axes."""
    t = JOINT_TYPES[j.type]
    axes = j.axes or [_BASE_AXES[a] for a in t.default_axes]
    return [(kind, j.axis if source == "axis" else axes[source]) for kind, source in t.motion]


@dataclass
class _Reported:
    coord: Coordinate
    value: ca.SX
    limit: tuple | None = None
    path: tuple = ()


def family(name: str) -> str:
    """The limit family of a coordinate name: the name less its trailing digits (``s1`` -> ``s``)."""
    return re.sub(r"\d+$", "", name) or name


class Generator:
    """Builds the symbolic closure of one description (errors carry key paths)."""

    def __init__(self, d: Description) -> None:
        self.d = d
        self.p = ca.SX.sym("p", len(d.parameters))
        self.env: dict[str, ex.Value] = {}
        for k, par in enumerate(d.parameters):
            if par.name in ex.RESERVED:
                raise InputError(f"{par.name!r} is a function or constant name", path=("parameters", par.name))
            self.env[par.name] = ex.Value(self.p[k], ex.DIMENSION_OF[par.dimension])
        self.derived: list[tuple[str, ca.SX, str]] = []
        for q in d.derived:
            v = self.value(q.value, ("derived", q.name), self.env, q.dimension)
            self._bind(self.env, q.name, v, ("derived", q.name))
            self.derived.append((q.name, v.sx, q.dimension or _dim_name(v.dim)))
        self.reported: list[_Reported] = []
        self.rows: list[tuple[ca.SX, str]] = []
        #: the assembly-branch indicators: (expression, name, what it measures)
        self.branch: list[tuple[ca.SX, str, str]] = []
        #: eliminated links whose indicator waits for Φ_x: (position in branch, rows, working mode, what)
        self.pending: list[tuple[int, list[int], ca.SX | None, str]] = []
        self.q_coords: list[Coordinate] = []
        self.q_syms: list[ca.SX] = []
        self.q_home: list[ca.SX] = []
        self.q_limits: dict[str, tuple] = {}
        self.platform_radius: list[ca.SX] = []
        #: (quantity that must vanish at the reference configuration, what it means, key path)
        self.requirements: list[tuple[ca.SX, str, tuple]] = []
        #: passive joints of the proximal chains: (coordinate, symbol, home value, limit, key path)
        self.extra: list[tuple] = []
        self.extra_limits: dict[str, tuple] = {}
        #: each leg's resolved joints, base first (for the chains of the six-axis hinge model)
        self.leg_joints: list[tuple[Leg, list[_Joint]]] = []
        #: per leg, for the drawing: (leg name, [(joint letter, location at the pose, actuated, slides)])
        self.drawn: list[tuple[str, list[tuple[str, ca.SX, bool, bool]]]] = []

    # -- expressions -----------------------------------------------------------------------
    def value(self, text: Any, path: tuple, env: Mapping[str, ex.Value], dimension: str | None = None) -> ex.Value:
        try:
            v = ex.parse(text, env)
        except ex.ExpressionError as exc:
            shown = "[" + ", ".join(str(t) for t in text) + "]" if isinstance(text, list) else str(text)
            if len(shown) > 80:  # the message, not the expression, must fit in the line
                shown = f"{shown[:60]}... ({len(shown) - 60} more characters)"
            hint = None
            if "never closed" in exc.message:
                hint = "inside a YAML [list] or {mapping}, quote an expression that contains a comma"
            if len(shown) > 80:  # the reason must fit in the one message line
                shown = shown[:60] + f"... ({len(shown)} characters)"
            raise InputError(f"in {shown!r}: column {exc.column}: {exc.message}", path=path, hint=hint) from None
        if dimension is None:
            return v
        want = ex.DIMENSION_OF[dimension]
        if not (ex.adapts(v) or ex.compatible(v.dim, want)):
            raise InputError(f"expected {ex.describe(want)}, got {ex.describe(v.dim)} in {text!r}", path=path)
        # the declared dimension is the value's (a bare number is SI of it; a plain number an angle in rad)
        return ex.Value(v.sx, want)

    def scalar(self, text: Any, path: tuple, env: Mapping[str, ex.Value], dimension: str | None = None) -> ca.SX:
        v = self.value(text, path, env, dimension)
        if v.size != 1:
            raise InputError(f"expected a scalar, got a vector of {v.size} in {text!r}", path=path)
        return v.sx

    def vector(self, text: Any, path: tuple, env: Mapping[str, ex.Value], dimension: str | None) -> ca.SX:
        v = self.value(text, path, env, dimension)
        n = 2 if self.d.platform.planar else 3
        if v.size != n:
            raise InputError(f"expected a vector of {n} elements, got {v.size} in {text!r}", path=path)
        return ca.vertcat(v.sx, 0) if n == 2 else v.sx

    @staticmethod
    def _bind(env: dict, name: str, v: ex.Value, path: tuple) -> None:
        if name in env or name in ex.RESERVED:
            raise InputError(f"the name {name!r} is already taken (a parameter, coordinate or function)", path=path)
        env[name] = v

    # -- platform ----------------------------------------------------------------------------
    def platform(self) -> None:
        pf = self.d.platform
        for t in pf.task:
            if t in pf.fixed:
                raise InputError(f"{t!r} is both a task coordinate and fixed", path=("platform", "task"))
        self.x_names = [c for c in pf.coordinates if c not in pf.fixed]
        self.x_coords = [
            Coordinate(n, pf.coordinates[n], pf.descriptions.get(n, "platform coordinate")) for n in self.x_names
        ]
        self.x = ca.SX.sym("x", len(self.x_names))
        self.xenv = dict(self.env)
        for k, name in enumerate(self.x_names):
            self._bind(
                self.xenv,
                name,
                ex.Value(self.x[k], ex.DIMENSION_OF[pf.coordinates[name]]),
                ("platform", "coordinates", name),
            )
        for name, text in pf.fixed.items():
            v = self.value(text, ("platform", "fixed", name), self.env, pf.coordinates[name])
            self._bind(self.xenv, name, v, ("platform", "fixed", name))
        if self.d.is_graph and pf.position == []:  # the platform body's point is the position (graph)
            self.P = None
        else:
            self.P = self.vector(pf.position, ("platform", "position"), self.xenv, "length")
        R = ca.SX.eye(3)
        for k, (axis, angle) in enumerate(pf.rotation):
            if pf.planar and axis != "z":
                raise InputError("a planar platform turns about z only", path=("platform", "rotation", k))
            R = R @ _rot(axis, self.scalar(angle, ("platform", "rotation", k, 1), self.xenv, "angle"))
        self.R = R
        home = []
        for name in self.x_names:
            text = pf.home.get(name, 0)
            home.append(self.scalar(text, ("platform", "home", name), self.env, pf.coordinates[name]))
        self.x_home = ca.vertcat(*home)
        self.P_home = ca.SX.zeros(3) if self.P is None else ca.substitute(self.P, self.x, self.x_home)
        self.R_home = ca.substitute(self.R, self.x, self.x_home)

    def platform_point(self, B0: ca.SX) -> ca.SX:
        """The platform point that is at B0 at the reference pose, at the pose x."""
        self.platform_radius.append(ca.norm_2(B0 - self.P_home))
        return self.P + self.R @ self.R_home.T @ (B0 - self.P_home)

    # -- actuators -------------------------------------------------------------------------
    def actuator(self, j: Joint, env: Mapping[str, ex.Value]) -> ca.SX:
        name = j.actuated
        if name in [c.name for c in self.q_coords]:
            raise InputError(f"actuator {name!r} drives two joints", path=j.path + ("actuated",))
        dim = JOINT_DIMS.get(j.type)
        if not JOINT_TYPES[j.type].actuable:
            can = ", ".join(n for n, t in JOINT_TYPES.items() if t.actuable)
            raise InputError(f"a {j.type} joint cannot be actuated ({can} can)", path=j.path + ("actuated",))
        fam = j.limit or family(name)
        self.q_coords.append(Coordinate(name, dim, f"actuator of the {j.type} joint at {_where(j.path)}", fam))
        sym = ca.SX.sym(name)
        self.q_syms.append(sym)
        home = j.home[0] if j.home else 0
        qh = self.scalar(home, j.path + ("home",), env, dim)
        self.q_home.append(qh)
        gain = self.scalar(j.gain, j.path + ("gain",), env, "dimensionless")
        if j.range is not None and fam not in self.q_limits:
            self.q_limits[fam] = (dim, j.range, j.path + ("range",))
        return gain * (sym - qh)

    # -- legs ------------------------------------------------------------------------------
    def leg(self, leg: Leg) -> None:
        env = dict(self.env)
        if leg.index is not None:
            self._bind(env, leg.index, ex.Value(ca.SX(float(leg.values[0])), None), leg.path + ("repeat", "index"))
        for name, text in leg.let.items():
            self._bind(env, name, self.value(text, leg.path + ("let", name), env), leg.path + ("let", name))
        turn = ca.SX.eye(3)
        if leg.rotate is not None:
            turn = _rot(leg.rotate_axis, self.scalar(leg.rotate, leg.path + ("repeat", "rotate"), env, "angle"))
        joints = [self.resolve(j, env, turn) for j in leg.joints]
        self.leg_joints.append((leg, joints))
        self.close(leg, joints, turn if leg.rotate is not None else None)

    def resolve(self, j: Joint, env: Mapping[str, ex.Value], turn: ca.SX) -> _Joint:  # noqa: C901 - one rule per joint part
        out = _Joint(j)
        planar = self.d.platform.planar
        kind = JOINT_TYPES[j.type]
        allowed = joint_types(planar)
        if j.type not in allowed:
            other = kind.twin
            raise InputError(
                f"a {'planar' if planar else 'spatial'} mechanism takes {', '.join(allowed)} joints, got {j.type}",
                path=j.path + ("type",),
                suggestions=[other] if other else (),
            )
        if j.at is None:
            raise InputError(f"a {j.type} joint needs its location 'at'", path=j.path)
        out.local["at"] = self.vector(j.at, j.path + ("at",), env, "length")
        out.at = turn @ out.local["at"]
        if j.type == "distance":
            if j.to is None:
                raise InputError("a distance joint needs 'to' (the point on the distal body)", path=j.path)
            out.local["to"] = self.vector(j.to, j.path + ("to",), env, "length")
            out.to = turn @ out.local["to"]
            if j.length is not None:  # the rod's length, the drawing's `to` only roughly there (assembled)
                out.length = self.scalar(j.length, j.path + ("length",), env, "length")
                self.requirements.append(
                    (ca.if_else(out.length > 0, 0, 1), "expected a positive length", j.path + ("length",))
                )
        elif j.to is not None:
            raise InputError("only a distance joint has 'to'", path=j.path + ("to",))
        if j.length is not None and j.type != "distance":
            raise InputError(
                f"only a distance joint has 'length' (a {j.type} joint's links are drawn by their joints)",
                path=j.path + ("length",),
            )
        if kind.axis == "given":
            if j.axis is None:
                raise InputError(f"a {j.type} joint needs its 'axis'", path=j.path)
            a = self.vector(j.axis, j.path + ("axis",), env, None)
            out.local["axis"] = a / ca.norm_2(a)
            a = turn @ a
            out.axis = a / ca.norm_2(a)
        elif kind.axis == "z":
            out.axis = ca.SX(_BASE_AXES["z"])
            out.local["axis"] = turn.T @ out.axis  # z itself when the leg turns about z (planar)
        out.local["axes"] = []
        for k, a in enumerate(j.axes):
            v = self.vector(a, j.path + ("axes", k), env, None)
            out.local["axes"].append(v / ca.norm_2(v))
            v = turn @ v
            out.axes.append(v / ca.norm_2(v))
        need = kind.n_axes
        if j.axes and len(j.axes) != need:
            raise InputError(f"a {j.type} joint takes {need or 'no'} axes, got {len(j.axes)}", path=j.path + ("axes",))
        if need and not kind.default_axes and not j.axes:
            raise InputError(f"a {j.type} joint needs its {need} 'axes'", path=j.path)
        if need == 3 and j.axes:
            self._independent_axes(out.axes, j.path + ("axes",))
        dof = kind.dof
        if j.coordinates and len(j.coordinates) != dof:
            raise InputError(
                f"a {j.type} joint has {dof} coordinate(s), got {len(j.coordinates)}", path=j.path + ("coordinates",)
            )
        if j.actuated is not None:
            out.value = self.actuator(j, env)
        elif j.home:
            dims = kind.dims
            out.home = [
                self.scalar(h, j.path + ("home", k), env, dims[k] if k < len(dims) else None)
                for k, h in enumerate(j.home)
            ]
        return out

    #: |det| of an S joint's three unit axes below which they count as linearly dependent
    DEPENDENT_AXES = 1e-6

    def _independent_axes(self, axes: list, path: tuple) -> None:
        """An S joint's three axes span space: its angles about them (and its motion as three
        revolutes) need three independent directions.  Axes that depend on the parameters are
        checked with the parameters' values (a requirement of the reference configuration)."""
        det = ca.det(ca.horzcat(*axes))
        text = "the S joint's three axes are linearly dependent (parallel or in one plane)"
        if det.is_constant():
            value = float(ca.DM(det))
            if not abs(value) > self.DEPENDENT_AXES:
                raise InputError(
                    f"expected three independent axes, got axes whose triple product is {value:.3g}: {text}; "
                    "give three directions that span space (default: x, y, z)",
                    path=path,
                )
            return
        text = f"expected three independent axes; with these parameters {text}"
        self.requirements.append((ca.if_else(ca.fabs(det) > self.DEPENDENT_AXES, 0, 1), text, path))

    def close(self, leg: Leg, joints: list[_Joint], turn: ca.SX | None = None) -> None:  # noqa: C901 - one branch per leg ending
        """The leg's closure rows, indicators and reported joint values (turn: a repeated leg's turn)."""
        last = joints[-1]
        rod = None  # a distance joint's given length
        if last.type == "distance":
            tip, elim = last.to, _Joint(Joint("S", path=last.spec.path), at=last.at, local={"at": last.local["at"]})
            tip_l = last.local["to"]
            rod = last.length
            before = joints[:-1]
        elif last.type in POINT_JOINTS and (last.type == "S") != self.d.platform.planar:
            tip, tip_l = last.at, last.local["at"]
            before = joints[:-1]
            elim = None
            if before and before[-1].value is None and before[-1].type in ("R", "C", *SPHERE_JOINTS):
                elim = before.pop()
        else:
            want = "planar_R" if self.d.platform.planar else "S"
            raise InputError(
                f"leg {leg.name}: it must reach the platform through a point joint ({want}) or a distance joint; "
                f"its last joint is {last.type}",
                path=last.spec.path + ("type",),
            )
        slide = None
        if elim is None and before and before[-1].type in ("P", "planar_P") and len(before) >= 2:
            if before[-2].value is None and before[-2].type in SPHERE_JOINTS | {"R"}:
                slide, elim = before.pop(), before.pop()
        for k, j in enumerate(before):
            if j.value is None:
                self.unknowns(j, leg, k)
        Rm, tm = self.chain(before)
        B = self.platform_point(tip)
        self.draw_leg(leg, last, before, elim, slide, Rm, tm, B)
        R_rel = self.R @ self.R_home.T
        rows = 2 if self.d.platform.planar else 3
        if elim is None:
            v = B - (Rm @ tip + tm)
            for k in range(rows):
                self.rows.append((v[k], f"leg {leg.name}: point {'xyz'[k]}"))
            self.report_tip(last, Rm, R_rel, leg.name)
            return
        c = Rm @ elim.at + tm
        u0 = tip - elim.at
        u = Rm @ u0
        v = B - c
        # the link's constants in the leg's frame (the same for every copy of a repeated leg)
        u0_l, axis_l = tip_l - elim.local["at"], elim.local.get("axis")
        r = ca.norm_2(u0_l)
        Rb = Rm
        if slide is not None:
            if slide.value is None:
                raise InputError(
                    f"leg {leg.name}: a passive P between two point joints constrains nothing", path=slide.spec.path
                )
            self.requirements.append(
                (
                    ca.norm_2(ca.cross(slide.axis, u0)) / r,
                    "the P joint's axis is not along the leg (c -> B)",
                    slide.spec.path,
                )
            )
            # squared (polynomial in the pose): Newton from far starts converges far more often than on
            # |v| - length; near a solution it is (length / r)(|v| - length)
            self.rows.append(((ca.dot(v, v) - (r + slide.value) ** 2) / (2 * r), f"leg {leg.name}: length"))
            self.indicator((r + slide.value) / r, leg, slide, "the leg's length over its reference length")
            self.indicator(ca.dot(u, v) / (r * ca.norm_2(v)), leg, elim, _COSINE)
            if elim.type == "R":  # R-P-S: the leg also stays in the plane normal to the R axis
                w = Rm @ elim.axis
                self.rows.append((ca.dot(v, w) - ca.dot(u0_l, axis_l), f"leg {leg.name}: plane of the R joint"))
                theta = ca.atan2(ca.dot(w, ca.cross(u, v)), ca.dot(u, v))
                self.report(elim, [theta], leg.name)
                Rb = _rot(w, theta) @ Rm
            else:
                Rb = self.report_sphere(elim, Rm, u0, v, leg)
        elif elim.type == "R":
            w = Rm @ elim.axis
            h = ca.dot(u0_l, axis_l)
            up, vp = u - ca.dot(u, w) * w, v - ca.dot(v, w) * w
            self.rows.append((ca.dot(v, w) - h, f"leg {leg.name}: plane of the R joint"))
            self.rows.append(
                ((ca.dot(v, v) - ca.dot(u0_l, u0_l)) / (2 * r), f"leg {leg.name}: radius about the R joint")
            )
            self.eliminated(leg, elim, before, c, v, 2, w)
            if turn is not None and _is_identity(Rm):
                # a turned leg whose proximal chain only slides: its angle and its link's rotation in
                # the leg's own frame (v_l = turnᵀ v), where the file's axes are (0, 1, 0) and the
                # like -- the rotation about w_l keeps a U or S axis along w_l exactly, and the tip's
                # angles need no turned constant (:meth:`report_tip`)
                v_l, w_l = turn.T @ v, axis_l
                # w·(up × vp) = v·(w × u) and up·vp = u·v - (u·w)(v·w), with u·w = h
                theta = ca.atan2(ca.dot(v_l, ca.cross(w_l, u0_l)), ca.dot(u0_l, v_l) - h * ca.dot(v_l, w_l))
                self.report(elim, [theta], leg.name)
                self.report_tip(last, _rot(w_l, theta), R_rel, leg.name, turn)
                return
            theta = ca.atan2(ca.dot(w, ca.cross(up, vp)), ca.dot(up, vp))
            self.report(elim, [theta], leg.name)
            Rb = _rot(w, theta) @ Rm
        elif elim.type == "C":
            w = Rm @ elim.axis
            up, vp = u - ca.dot(u, w) * w, v - ca.dot(v, w) * w
            rp = ca.norm_2(u0_l - ca.dot(u0_l, axis_l) * axis_l)
            self.rows.append(((ca.dot(vp, vp) - rp**2) / (2 * rp), f"leg {leg.name}: cylinder of the C joint"))
            self.eliminated(leg, elim, before, c, v, 1, w)
            theta = ca.atan2(ca.dot(w, ca.cross(up, vp)), ca.dot(up, vp))
            self.report(elim, [theta, ca.dot(v, w) - ca.dot(u0_l, axis_l)], leg.name)
            Rb = _rot(w, theta) @ Rm
        else:
            if rod is None:
                self.rows.append(((ca.dot(v, v) - ca.dot(u0_l, u0_l)) / (2 * r), f"leg {leg.name}: distance"))
            else:  # its given length: the drawing need not close (the reference is assembled)
                self.rows.append(((ca.dot(v, v) - rod**2) / (2 * rod), f"leg {leg.name}: distance"))
            self.eliminated(leg, elim, before, c, v, 1)
            Rb = self.report_sphere(elim, Rm, u0, v, leg)
        self.report_tip(last, Rb, R_rel, leg.name)

    def indicator(self, value: ca.SX | None, leg: Leg, j: _Joint, what: str) -> None:
        """A generated branch indicator, named after its leg and joint (``a1.U1``: leg a1, its
        first joint, a U); value None: filled in by :meth:`elimination_indicators`."""
        n = j.spec.path[-1] + 1 if j.spec.path and isinstance(j.spec.path[-1], int) else 0
        name = f"{leg.name}.{JOINT_TYPES[j.type].letter}{n}"
        self.branch.append((value, name, f"leg {leg.name}, joint {n} ({j.type}): {what}"))

    def eliminated(
        self,
        leg: Leg,
        elim: _Joint,
        before: list[_Joint],
        c: ca.SX,
        v: ca.SX,
        nrows: int,
        along: ca.SX | None = None,
    ) -> None:
        """Record an eliminated link c -> B (its last ``nrows`` closure rows; v: c -> B, vp: its part
        normal to the axis ``along`` of an eliminated R or C, else v) and its working-mode expression:
        the closure's rate with respect to the joint before it, w·((c - a) × vp) for a revolute (axis
        w at a), e·vp for a P along e (None: no joint before it, or one with several motions).  The
        indicator itself is chosen once Φ_x is known (:meth:`elimination_indicators`)."""
        vp = v if along is None else v - ca.dot(v, along) * along
        working, what = None, ""
        if before and JOINT_TYPES[before[-1].type].dof == 1:
            b = before[-1]
            Rk, tk = self.chain(before[:-1])  # the joint before, moved by the joints before it
            if JOINT_TYPES[b.type].motion[0][0] == "R":
                rate = ca.cross(Rk @ b.axis, c - (Rk @ b.at + tk))
                what = _WORKING_PLANAR if self.d.platform.planar else _WORKING_R
                working = ca.dot(rate, vp)
            else:
                rate = Rk @ b.axis
                what = _WORKING_P
                # e·vp = e·v - (v·w)(e·w): a P moves its link without turning it, so e·w is the
                # product of the two axes in the leg's frame, a constant of the file (an exact 0 for
                # the usual P normal to the R: e·vp is e·v).  Same branch decisions as e·vp on the
                # turned axes, whose e·w was a rounded 0 (|e·w| <= 1e-16): the two differ by at most
                # |v·w| 1e-16 plus rounding, so their signs agree wherever |e·v| exceeds that
                # (tests/mechanisms/described/test_generated_lean.py: 900 legs, 600 within 1e-14..1e-3 L of e·v = 0)
                working = ca.dot(rate, v)
                if along is not None:
                    e_l, w_l = b.local.get("axis"), elim.local.get("axis")
                    ew = ca.dot(rate, along) if e_l is None or w_l is None else ca.dot(e_l, w_l)
                    working = working - ca.dot(v, along) * ew
        rows = list(range(len(self.rows) - nrows, len(self.rows)))
        self.pending.append((len(self.branch), rows, working, what))
        self.indicator(None, leg, elim, "")

    def elimination_indicators(self, q: ca.SX) -> None:
        """The indicator of each eliminated link (recorded by :meth:`eliminated`), a mode invariant.

        If the link's rows make a diagonal block of Φ_x (block-triangular form, Dulmage-Mendelsohn)
        holding no other elimination, the link closes a sub-chain of its own (a four-bar's coupler
        with the rocker, a slider-crank's rod with the slider): its indicator is the determinant of
        that block -- the sub-chain's passive Jacobian -- over its value at home.  It changes sign
        only where the sub-chain is singular (the coupler and rocker aligned), i.e. between its
        assembly modes; for a triangle closed at a revolute it is the triangle's orientation, for
        an S-S link the side of the output crank's plane.  Otherwise the link is one of several
        holding the platform, whose assembly mode is the ``aspect``; its indicator is the leg's
        working mode, the closure's rate with respect to the joint before the link over its
        value at home (the Delta's and the five-bar's elbows), changing sign only where the
        leg is stretched or folded (a singularity of the leg).  A link with neither (fixed c and
        a shared block) gets no indicator."""
        if not self.pending:
            return
        phi = ca.vertcat(*[r[0] for r in self.rows])
        J = ca.jacobian(phi, self.x)
        xq, home = ca.vertcat(self.x, q), ca.vertcat(self.x_home, *self.q_home)
        block_of, blocks = {}, []
        if ca.sprank(J.sparsity()) == J.size1() == J.size2():
            nb, rowperm, colperm, rowblock, colblock, *_ = J.sparsity().btf()
            for k in range(nb):
                rows, cols = rowperm[rowblock[k] : rowblock[k + 1]], colperm[colblock[k] : colblock[k + 1]]
                blocks.append((rows, cols))
                block_of.update({r: k for r in rows})
        owners: dict[int, int] = {}
        for _pos, rows, _w, _what in self.pending:
            ks = {block_of.get(r) for r in rows}
            if len(ks) == 1 and None not in ks:
                k = ks.pop()
                owners[k] = owners.get(k, 0) + 1
        drop = []
        for pos, rows, working, what in self.pending:
            _v, name, desc = self.branch[pos]
            ks = {block_of.get(r) for r in rows}
            k = next(iter(ks)) if len(ks) == 1 else None
            value = None
            if k is not None and owners.get(k) == 1 and len(blocks[k][1]) <= ASPECT_MAX_NX:
                brows, bcols = blocks[k]
                d = twist_determinant(phi[brows], ca.vertcat(*[self.x[j] for j in bcols]), self.R)
                value, what = d / ca.substitute(d, xq, home), _ASSEMBLY
            elif working is not None:
                # over its value at home: polynomial in the pose (an interval proof of outside stays tight)
                value = working / ca.substitute(working, xq, home)
            if value is None:
                drop.append(pos)
                continue
            self.branch[pos] = (value, name, desc + what)
        self.branch = [b for k, b in enumerate(self.branch) if k not in drop]

    def draw_leg(
        self,
        leg: Leg,
        last: _Joint,
        before: list[_Joint],
        elim: _Joint | None,
        slide: _Joint | None,
        Rm: ca.SX,
        tm: ca.SX,
        B: ca.SX,
    ) -> None:
        """The leg's joints located at the pose x (with q, p), for the drawing: the proximal
        chain's joints moved by the joints before them, the eliminated joint by the whole
        proximal chain, a P along the leg at its reference distance from there, the last
        joint where the platform puts it."""
        planar = self.d.platform.planar
        out: list[tuple[str, ca.SX, bool, bool]] = []
        Rk, tk = ca.SX.eye(3), ca.SX.zeros(3)
        for j in before:
            out.append((_LETTER[j.type], Rk @ j.at + tk, j.value is not None and j.spec.actuated is not None, False))
            Rj, tj = self.chain([j])
            Rk, tk = Rk @ Rj, Rk @ tj + tk
        if elim is not None:
            c = Rm @ elim.at + tm
            letter = "R" if planar and last.type == "distance" else _LETTER[elim.type]
            out.append((letter, c, False, elim.type == "C"))
            if slide is not None:
                reach = ca.norm_2(slide.at - elim.at)
                out.append(
                    (_LETTER[slide.type], c + reach * (B - c) / ca.norm_2(B - c), slide.spec.actuated is not None, True)
                )
        tip = "R" if planar and last.type == "distance" else _LETTER[last.type]
        out.append((tip, B, False, False))
        # a segment after a P (or C) joint changes length: mark the joints that slide
        out = [(t, v, act, slides or t in ("P", "C")) for t, v, act, slides in out]
        self.drawn.append((leg.name, out))

    def chain(self, joints: list[_Joint]) -> tuple[ca.SX, ca.SX]:
        """The motion y -> Rm y + tm of the proximal chain's last body (product of exponentials)."""
        Rm, tm = ca.SX.eye(3), ca.SX.zeros(3)
        for j in joints:
            motions = j.motions or [(JOINT_TYPES[j.type].motion[0][0], j.axis, j.value)]
            for kind, axis, value in motions:
                if kind == "P":
                    Rk, tk = ca.SX.eye(3), value * axis
                else:  # a rotation about the axis through j.at
                    Rk = _rot(axis, value)
                    tk = j.at - Rk @ j.at
                Rm, tm = Rm @ Rk, Rm @ tk + tm
        return Rm, tm

    def unknowns(self, j: _Joint, leg: Leg, k: int) -> None:
        """A passive joint of the proximal chain: its values become pose unknowns (dependent coordinates)."""
        if j.type == "distance":
            raise InputError(f"leg {leg.name}: a distance joint must be the last of its leg", path=j.spec.path)
        elementary = elementary_motions(j)
        names = j.spec.coordinates or tuple(f"{leg.name}_j{k + 1}_{n + 1}" for n in range(len(elementary)))
        j.names = tuple(names)
        dims = JOINT_TYPES[j.type].dims
        for n, ((kind, axis), name) in enumerate(zip(elementary, names)):
            dim = dims[n]
            sym = ca.SX.sym(name)
            home = j.home[n] if n < len(j.home) else ca.SX(0)
            fam = j.spec.limit or family(name)
            coord = Coordinate(name, dim, f"passive {j.type} joint of leg {leg.name} (an unknown of the loops)", fam)
            self.extra.append((coord, sym, home, self._limit(j, dim), j.spec.path))
            j.motions.append((kind, axis, sym - home))

    def report(self, j: _Joint, values: list, leg: str) -> None:
        names = j.spec.coordinates
        if not names:
            return
        for k, (name, val) in enumerate(zip(names, values)):
            home = j.home[k] if k < len(j.home) else 0
            dim = JOINT_TYPES[j.type].dims[k]
            fam = j.spec.limit or family(name)
            desc = f"{j.type} joint of leg {leg}" + (f", axis {k + 1}" if len(names) > 1 else "")
            self.reported.append(
                _Reported(Coordinate(name, dim, desc, fam), home + val, self._flexure_range(j, dim, home), j.spec.path)
            )

    def _flexure_range(self, j: _Joint, dim: str, home: Any) -> tuple | None:
        """The joint's limits; a flexure's are a deflection about the reference value."""
        lim = self._limit(j, dim)
        if lim is None or j.spec.flexure is None or (isinstance(home, (int, float)) and home == 0):
            return lim
        home_sx = ca.SX(home)
        if not home_sx.is_constant():
            raise InputError(
                "a flexure hinge limits the deflection from the reference configuration, and this joint's "
                "reference value depends on the parameters; report the deflection (home 0) or give its range",
                path=j.spec.path + ("flexure",),
            )
        h = float(ca.DM(home_sx))
        return (h + lim[0], h + lim[1])

    def report_sphere(self, elim: _Joint, Rm: ca.SX, u0: ca.SX, v: ca.SX, leg: Leg) -> ca.SX | None:
        """The angles of a U (or planar R) whose link is eliminated, and the link's rotation (None: not determined)."""
        if elim.type == "planar_R":
            u = Rm @ u0
            theta = ca.atan2(u[0] * v[1] - u[1] * v[0], u[0] * v[0] + u[1] * v[1])
            self.report(elim, [theta], leg.name)
            return _rot("z", theta) @ Rm
        if elim.type == "U":
            a1, a2 = elim.axes
            F = ca.horzcat(a1, a2, ca.cross(a1, a2))
            self.requirements.append((ca.dot(a1, a2), "the U joint's axes are not perpendicular", elim.spec.path))
            self.requirements.append(
                (
                    ca.norm_2(ca.cross(F[:, 2], u0)) / ca.norm_2(u0),
                    "the U joint's link is not normal to both axes",
                    elim.spec.path,
                )
            )
            w = F.T @ Rm.T @ v
            theta2 = ca.atan2(w[0], ca.sqrt(w[1] ** 2 + w[2] ** 2))
            theta1 = ca.atan2(-w[1], w[2])
            self.report(elim, [theta1, theta2], leg.name)
            return Rm @ F @ _rot("x", theta1) @ _rot("y", theta2) @ F.T
        if elim.spec.coordinates:
            raise InputError(
                f"leg {leg.name}: the spin of a link between two spherical joints is not determined; "
                "report no coordinates for this S (or use a U)",
                path=elim.spec.path + ("coordinates",),
            )
        return None

    def report_tip(
        self, last: _Joint, Rb: ca.SX | None, R_rel: ca.SX, leg_name: str, turn: ca.SX | None = None
    ) -> None:
        """The tip joint's angles from the rotation Rb of the link before it and the platform's
        R_rel (turn: Rb is in the turned leg's own frame, Rb_world = turn Rb turnᵀ)."""
        names = last.spec.coordinates
        if not names or last.type == "distance":
            return
        if Rb is None:
            raise InputError(
                "the rotation of this joint is not determined (the link before it may spin); report no coordinates",
                path=last.spec.path + ("coordinates",),
            )
        if turn is not None:  # Rb in the leg's frame: back to the base frame for a planar R
            if last.type == "planar_R":
                Rb = turn @ Rb @ turn.T
            else:  # Fᵀ Rb_worldᵀ R_rel F with F = turn F_l: (Rb F_l)ᵀ (turnᵀ R_rel turn F_l)
                F = ca.horzcat(*last.local["axes"]) if last.axes else ca.SX.eye(3)
                self.report(last, _xyz_angles((Rb @ F).T @ (turn.T @ (R_rel @ (turn @ F)))), leg_name)
                return
        if last.type == "planar_R":
            M = Rb.T @ R_rel
            self.report(last, [ca.atan2(M[1, 0], M[0, 0])], leg_name)
            return
        F = ca.horzcat(*last.axes) if last.axes else ca.SX.eye(3)
        self.report(last, _xyz_angles(F.T @ Rb.T @ R_rel @ F), leg_name)

    def _limit(self, j: _Joint, dim: str) -> tuple | None:
        if j.spec.flexure is not None:
            path = j.spec.path + ("flexure",)
            values = validate_mapping(j.spec.flexure.values, hinge_types.HINGE_LIMIT_OPTIONS, path, what="flexure key")
            if values.get("hinge") is None:
                raise InputError(f"missing key 'hinge' (one of: {', '.join(hinge_types.LIMIT_TYPES)})", path=path)
            rot = hinge_types.hinge_rotation(values, path)
            return (-rot, rot)
        if j.spec.range is not None:
            rng = tuple(parse_quantity(v, dim, j.spec.path + ("range", k)) for k, v in enumerate(j.spec.range))
            if not rng[0] < rng[1]:
                raise InputError(f"expected low < high, got {list(j.spec.range)}", path=j.spec.path + ("range",))
            return rng
        return None

    # -- the whole closure -----------------------------------------------------------------------
    def build(self) -> dict[str, Any]:  # noqa: C901 - one step per section of the description
        d = self.d
        self.platform()
        for leg in d.legs:
            self.leg(leg)
        for name, (dim, home) in d.actuators.items():
            if name not in [c.name for c in self.q_coords]:
                self.q_coords.append(Coordinate(name, dim, "actuator", family(name)))
                self.q_syms.append(ca.SX.sym(name))
                self.q_home.append(self.scalar(home, ("actuators", name, "home"), self.env, dim))
        if not self.q_coords:
            raise InputError("no actuators: mark joints 'actuated: name' (or declare 'actuators')", path=("legs",))
        q = ca.vertcat(*self.q_syms)
        full = dict(self.xenv)
        for c, s in zip(self.q_coords, self.q_syms):
            self._bind(full, c.name, ex.Value(s, ex.DIMENSION_OF[c.kind]), ("actuators", c.name))
        for k, text in enumerate(d.closures):
            self.rows.append((self.scalar(text, ("closures", k), full), f"closures[{k}]"))
        added = self.branch_expressions(full)
        families = list(dict.fromkeys(r.coord.group for r in self.reported))
        self.reported.sort(key=lambda r: families.index(r.coord.group))  # alpha1..3, beta1..3, as the papers list them
        for qty in d.passive:
            v = self.value(qty.value, ("passive", qty.name), full, qty.dimension)
            dim = qty.dimension or _dim_name(v.dim)
            fam = qty.family or family(qty.name)
            self.reported.append(
                _Reported(Coordinate(qty.name, dim, qty.description, fam), v.sx, None, ("passive", qty.name))
            )
        self.add_unknowns()
        self._unique_names()
        nx, nrows = len(self.x_names), len(self.rows)
        if nrows != nx:
            what = "over" if nrows > nx else "under"
            raise InputError(
                f"wrong mobility: the legs and closures give {nrows} equation(s) for {nx} pose coordinate(s) "
                f"({', '.join(self.x_names)}): {what}-constrained; equations: {'; '.join(r[1] for r in self.rows)}",
                path=("platform", "coordinates"),
                hint="declare the coordinates the structure fixes under platform.fixed, or add legs",
            )
        self.elimination_indicators(q)
        self.aspect(q)
        self.select_branch(added)
        self.check_task_count()
        return self.functions(q)

    def check_task_count(self) -> None:
        """As many task coordinates as actuators."""
        task = self.d.platform.task
        if len(task) != len(self.q_coords):
            raise InputError(
                f"{len(task)} task coordinate(s) for {len(self.q_coords)} actuator(s) "
                f"({', '.join(c.name for c in self.q_coords)}); they must be as many",
                path=("platform", "task"),
            )

    def branch_expressions(self, env: Mapping[str, ex.Value]) -> list[tuple[ca.SX, str, str]]:
        """The indicators the ``branch`` section writes as expressions (named ``branch[k]`` unless given
        a name); an item that is a generated indicator's name is a selection, not an expression."""
        spec = self.d.branch
        items = spec if isinstance(spec, list) else (spec or {}).get("add", []) if isinstance(spec, dict) else []
        base = ("branch",) if isinstance(spec, list) else ("branch", "add")
        names = {b[1] for b in self.branch} | {ASPECT}  # the aspect indicator is generated after the closures
        out = []
        for k, item in enumerate(items):
            if isinstance(item, str) and item in names and isinstance(spec, list):
                continue
            name, text = next(iter(item.items())) if isinstance(item, dict) else (f"branch[{k}]", item)
            out.append((self.scalar(text, base + (k,), env), name, f"declared: {text}"))
        return out

    def select_branch(self, added: list[tuple[ca.SX, str, str]]) -> None:
        """Apply the ``branch`` section to the generated indicators (absent: all of them)."""
        spec, generated = self.d.branch, self.branch
        names = [b[1] for b in generated]

        def check(name: str, path: tuple) -> None:
            if name not in names:
                raise InputError(
                    f"no generated branch indicator {name!r}; they are: {', '.join(names) or 'none'}",
                    path=path,
                    suggestions=suggest(name, names),
                )

        if spec is None:
            keep = names
        elif isinstance(spec, list):
            keep = [v for v in spec if isinstance(v, str) and v in names]
            if ASPECT in spec and ASPECT not in names:
                check(ASPECT, ("branch", spec.index(ASPECT)))
        else:
            keep = names if spec["keep"] == "all" else [] if spec["keep"] == "none" else spec["keep"]
            for k, name in enumerate(() if isinstance(keep, list) and keep is names else keep):
                check(name, ("branch", "keep", k))
            for k, name in enumerate(spec["remove"]):
                check(name, ("branch", "remove", k))
            keep = [n for n in keep if n not in spec["remove"]]
        self.branch = [b for b in generated if b[1] in keep] + added
        taken = [b[1] for b in self.branch]
        dup = sorted({n for n in taken if taken.count(n) > 1})
        if dup:
            raise InputError(f"the branch indicator name {dup[0]!r} is used twice", path=("branch",))

    def aspect(self, q: ca.SX) -> None:
        """The aspect indicator (:mod:`cpm_nlp.core.aspect`): negative in an assembly mode across a
        forward singularity from the reference configuration."""
        if self.x.numel() > ASPECT_MAX_NX:
            return
        phi = ca.vertcat(*[r[0] for r in self.rows])
        value = aspect_indicator(phi, self.x, q, self.R, self.x_home, ca.vertcat(*self.q_home))
        self.branch.append((value, ASPECT, ASPECT_DESCRIPTION))

    def add_unknowns(self) -> None:
        if not self.extra:
            return
        self.x = ca.vertcat(self.x, *[e[1] for e in self.extra])
        self.x_home = ca.vertcat(self.x_home, *[e[2] for e in self.extra])
        for coord, _sym, _home, limit, path in self.extra:
            if coord.name in self.x_names or coord.name in [c.name for c in self.q_coords]:
                raise InputError(f"the coordinate name {coord.name!r} is used twice", path=path + ("coordinates",))
            self.x_names.append(coord.name)
            self.x_coords.append(coord)
            self.extra_limits[coord.group] = (coord.kind, limit, coord.description)

    def _unique_names(self) -> None:
        """Every reported joint value has a name of its own (two joints declaring one
        coordinate name would lose one value from the result)."""
        seen = {n: ("platform", "coordinates", n) for n in self.x_names}
        seen.update({c.name: ("actuators", c.name) for c in self.q_coords})
        for r in self.reported:
            name = r.coord.name
            if name in seen:
                path = r.path + ("coordinates",) if r.path and r.path[0] != "passive" else r.path
                also = "by every copy of this repeated leg" if seen[name] == r.path else f"also at {_where(seen[name])}"
                raise InputError(
                    f"the coordinate name {name!r} is declared twice ({also}); give each joint value its own "
                    "name (in a repeated leg, with its index: e.g. 'alpha{i}')",
                    path=path,
                )
            seen[name] = r.path

    def functions(self, q: ca.SX) -> dict[str, Any]:
        x, p = self.x, self.p
        io = ["x", "q", "p"]
        # common subexpressions merged (ca.cse: each distinct operation on the same operands once;
        # the values are the same to the bit): the legs share the platform's rotation and its
        # sines and cosines, each indicator the squared norm of its leg's closure
        phi = ca.Function("phi", [x, q, p], [ca.cse(ca.vertcat(*[r[0] for r in self.rows]))], io, ["phi"])
        g = ca.cse(ca.vertcat(*[b[0] for b in self.branch]))
        branch = ca.Function("branch", [x, q, p], [g], io, ["g"]) if self.branch else None
        frame = ca.Function("frame", [x, p], ca.cse([self.R, self.P]), ["x", "p"], ["R", "position"])
        passive = None
        if self.reported:
            j = ca.cse(ca.vertcat(*[r.value for r in self.reported]))
            passive = ca.Function("passive", [x, q, p], [j], io, ["j"])
        home = ca.Function("home", [p], [self.x_home, ca.vertcat(*self.q_home)], ["p"], ["x", "q"])
        radius = ca.mmax(ca.vertcat(*self.platform_radius)) if self.platform_radius else ca.SX(0)
        if self.d.characteristic_length is not None:
            radius = self.scalar(self.d.characteristic_length, ("characteristic_length",), self.env, "length")
        lo, hi = self.bounds(radius)
        req = ca.vertcat(*[r[0] for r in self.requirements]) if self.requirements else ca.SX(0, 1)
        extras = ca.Function(
            "described_values",
            [p],
            [lo, hi, radius, ca.vertcat(*[dv[1] for dv in self.derived]) if self.derived else ca.SX(0, 1), req],
            ["p"],
            ["lower", "upper", "length", "derived", "requirements"],
        )
        points = [v for _leg, joints in self.drawn for _t, v, _a, _s in joints] + [self.P]
        drawing = ca.Function("drawing_points", [x, q, p], [ca.horzcat(*points)], io, ["points"])
        return {
            "drawing": drawing,
            "drawing_legs": [(name, [(t, a, sl) for t, _v, a, sl in joints]) for name, joints in self.drawn],
            "phi": phi,
            "branch": branch,
            "branch_names": [b[1] for b in self.branch],
            "branch_descriptions": [b[2] for b in self.branch],
            "frame": frame,
            "passive": passive,
            "home": home,
            "extras": extras,
            "ik": self.closed_form_ik(),
            "row_names": [r[1] for r in self.rows],
            "requirements": [(r[1], r[2]) for r in self.requirements],
        }

    def bounds(self, radius: ca.SX) -> tuple[ca.SX, ca.SX]:
        pf = self.d.platform
        lo, hi = [], []
        span = 2 * ca.fmax(radius, ca.norm_2(self.P_home))
        for k, coord in enumerate(self.x_coords):
            name, dim = coord.name, coord.kind
            if name in pf.bounds:
                a, b = pf.bounds[name]
                lo.append(self.scalar(a, ("platform", "bounds", name, 0), self.env, dim))
                hi.append(self.scalar(b, ("platform", "bounds", name, 1), self.env, dim))
            elif dim == "angle":
                # a passive joint of a graph turns up to a half turn either way from the drawing
                half = math.pi / 3 if name in pf.coordinates else math.pi if self.d.is_graph else math.pi / 2
                lo.append(self.x_home[k] - half)
                hi.append(self.x_home[k] + half)
            else:
                lo.append(self.x_home[k] - span)
                hi.append(self.x_home[k] + span)
        return ca.vertcat(*lo), ca.vertcat(*hi)

    def closed_form_ik(self) -> ca.Function | None:  # noqa: C901 - one check per part of the ik section
        ik = self.d.ik
        if ik is None:
            return None
        pf = self.d.platform
        t = ca.SX.sym("t", len(pf.task))
        env = dict(self.env)
        for k, name in enumerate(pf.task):
            env[name] = ex.Value(t[k], ex.DIMENSION_OF[pf.coordinates[name]])
        for name in pf.fixed:
            env[name] = self.xenv[name]
        for name, text in ik.let.items():
            self._bind(env, name, self.value(text, ("ik", "let", name), env), ("ik", "let", name))
        xs = []
        for name in self.x_names:
            if name in pf.task:
                xs.append(env[name].sx)
            elif name in ik.pose:
                dim = self.x_coords[self.x_names.index(name)].kind
                xs.append(self.scalar(ik.pose[name], ("ik", "pose", name), env, dim))
            else:
                raise InputError(
                    f"missing the dependent coordinate {name!r} (an expression of the task coordinates)",
                    path=("ik", "pose"),
                )
        qs = []
        for c in self.q_coords:
            if c.name not in ik.actuators:
                raise InputError(f"missing the actuator {c.name!r}", path=("ik", "actuators"))
            qs.append(self.scalar(ik.actuators[c.name], ("ik", "actuators", c.name), env, c.kind))
        if ik.reach is None:
            raise InputError("missing 'reach': an expression < 0 where the pose cannot be assembled", path=("ik",))
        reach = self.scalar(ik.reach, ("ik", "reach"), env)
        return ca.Function(
            "ik", [t, self.p], ca.cse([ca.vertcat(*xs), ca.vertcat(*qs), reach]), ["t", "p"], ["x", "q", "reach"]
        )

    # -- declared options -----------------------------------------------------------------------
    def limit_options(self) -> tuple[Option, ...]:
        seen: dict[str, Option] = {}
        for fam, (dim, rng, path) in self.q_limits.items():
            lim = tuple(parse_quantity(v, dim, path + (k,)) for k, v in enumerate(rng))
            seen[fam] = Option(fam, dim, f"range [low, high] of every actuator {fam}*", default=lim, shape="range")
        for c in self.q_coords:
            if c.group not in seen:
                seen[c.group] = Option(
                    c.group, c.kind, f"range [low, high] of every actuator {c.group}*", default=None, shape="range"
                )
        for c in self.q_coords:  # one actuator alone (its homes may differ: the 3-RRR's cranks)
            if c.name not in seen and sum(o.group == c.group for o in self.q_coords) > 1:
                seen[c.name] = Option(
                    c.name,
                    c.kind,
                    f"range [low, high] of {c.name} alone (overrides {c.group})",
                    default=None,
                    shape="range",
                )
        for fam, (dim, lim, desc) in self.extra_limits.items():
            if fam not in seen:
                seen[fam] = Option(fam, dim, f"range [low, high] of every {fam}* ({desc})", default=lim, shape="range")
        for r in self.reported:
            fam = r.coord.group
            if fam not in seen:
                seen[fam] = Option(
                    fam,
                    r.coord.kind,
                    f"range [low, high] of every {fam}* ({r.coord.description})",
                    default=r.limit,
                    shape="range",
                )
        return tuple(seen.values())


def _where(path: tuple) -> str:
    return format_key_path(path)


def _dim_name(dim: ex.Dim) -> str:
    if dim is None or dim[0] == 0:
        return "angle" if dim is not None and dim[1] else "dimensionless"
    return "length"


def parameter_options(d: Description) -> tuple[Option, ...]:
    """The declared parameters as options (validated like a built-in mechanism's)."""
    return tuple(
        Option(
            p.name,
            p.dimension,
            p.description or p.name,
            default=p.default,
            lower=p.lower,
            upper=p.upper,
            strict=p.strict,
        )
        for p in d.parameters
    )


def described_limits(options: tuple[Option, ...], d: Description) -> tuple[Option, ...]:
    """The joint-limit options with the descriptions the file's ``limits:`` gives (a family
    the mechanism does not have is an error, with a "did you mean")."""
    names = [o.name for o in options]
    for fam in d.limits:
        if fam not in names:
            raise InputError(
                f"unknown joint-limit family {fam!r}; this mechanism's are: {', '.join(names) or 'none'}",
                path=("limits", fam),
                suggestions=suggest(fam, names),
            )
    return tuple(dataclasses.replace(o, description=d.limits[o.name]) if d.limits.get(o.name) else o for o in options)


__all__ = ["Generator", "described_limits", "parameter_options"]
