"""From a [`Description`][cpm_nlp.mechanisms.described.spec.Description] to a
[`LoopClosure`][cpm_nlp.core.model.LoopClosure]
and a [`Mechanism`][cpm_nlp.core.mechanism.Mechanism], symbolically in CasADi.

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
configuration (`branches.elimination_indicators`):

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
file expanded into bodies and joints (`expand`, every passive joint an unknown of a
spanning tree) serves ``describe``, the assembly of a rough drawing and files that mix legs
with bodies; it would be the slower closure.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import casadi as ca

from ...core.errors import InputError
from ...core.joints import JOINT_TYPES, joint_types
from ...core.model import Coordinate
from . import expr as ex
from .branches import (
    COSINE,
    WORKING_P,
    WORKING_PLANAR,
    WORKING_R,
    aspect,
    branch_expressions,
    elimination_indicators,
    select_branch,
)
from .builder import ClosureBuilder, Reported, dim_name, family
from .drawing import leg_points
from .dyads import closed_form_fk
from .emit import closure_functions
from .motions import (
    BASE_AXES,
    POINT_JOINTS,
    SPHERE_JOINTS,
    ResolvedJoint,
    chain_motion,
    elementary_motions,
    is_identity,
    rot,
    xyz_angles,
)
from .spec import Description, Joint, Leg


@dataclass
class _Link:
    """An eliminated link c -> B of a leg: the joint at c, the proximal chain before it and its motion
    Rm, c and B - c at the pose (v), the link at the reference configuration (u0) and moved (u = Rm
    u0), and in the leg's own frame its vector, the joint's axis and the link's length r."""

    leg: Leg
    elim: ResolvedJoint
    before: list[ResolvedJoint]
    Rm: ca.SX
    c: ca.SX
    u0: ca.SX
    u: ca.SX
    v: ca.SX
    u0_l: ca.SX
    axis_l: ca.SX | None
    r: ca.SX


class Generator(ClosureBuilder):
    """Builds the symbolic closure of a legs description, each leg's passive joints eliminated
    (errors carry key paths)."""

    def __init__(self, d: Description) -> None:
        super().__init__(d)
        #: Φ's circle rows (planar): (row, centre c, platform point B, radius), for `dyads`
        self.circles: list[tuple[int, ca.SX, ca.SX, ca.SX]] = []

    # -- legs ------------------------------------------------------------------------------
    def leg(self, leg: Leg) -> None:
        env = dict(self.env)
        if leg.index is not None:
            self.bind(env, leg.index, ex.Value(ca.SX(float(leg.values[0])), None), leg.path + ("repeat", "index"))
        for name, text in leg.let.items():
            self.bind(env, name, self.value(text, leg.path + ("let", name), env), leg.path + ("let", name))
        turn = ca.SX.eye(3)
        if leg.rotate is not None:
            turn = rot(leg.rotate_axis, self.scalar(leg.rotate, leg.path + ("repeat", "rotate"), env, "angle"))
        joints = [self.resolve(j, env, turn) for j in leg.joints]
        self.leg_joints.append((leg, joints))
        self.close(leg, joints, turn if leg.rotate is not None else None)

    def resolve(self, j: Joint, env: Mapping[str, ex.Value], turn: ca.SX) -> ResolvedJoint:
        """A joint of a leg resolved in the leg's environment (turn: the leg's rotation)."""
        out = ResolvedJoint(j)
        self._check_type(j)
        self._resolve_points(out, env, turn)
        self._resolve_axes(out, env, turn)
        self._resolve_values(out, env)
        return out

    def _check_type(self, j: Joint) -> None:
        """The mechanism's plane takes the joint's type."""
        planar = self.d.platform.planar
        allowed = joint_types(planar)
        if j.type not in allowed:
            other = JOINT_TYPES[j.type].twin
            raise InputError(
                f"a {'planar' if planar else 'spatial'} mechanism takes {', '.join(allowed)} joints, got {j.type}",
                path=j.path + ("type",),
                suggestions=[other] if other else (),
            )

    def _resolve_points(self, out: ResolvedJoint, env: Mapping[str, ex.Value], turn: ca.SX) -> None:
        """Its location ``at``; a distance joint's ``to`` and the rod's given ``length``."""
        j = out.spec
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

    def _resolve_axes(self, out: ResolvedJoint, env: Mapping[str, ex.Value], turn: ca.SX) -> None:
        """Its unit axis (given, or z) and axes, turned with the leg and in the leg's own frame."""
        j = out.spec
        kind = JOINT_TYPES[j.type]
        if kind.axis == "given":
            if j.axis is None:
                raise InputError(f"a {j.type} joint needs its 'axis'", path=j.path)
            a = self.vector(j.axis, j.path + ("axis",), env, None)
            out.local["axis"] = a / ca.norm_2(a)
            a = turn @ a
            out.axis = a / ca.norm_2(a)
        elif kind.axis == "z":
            out.axis = ca.SX(BASE_AXES["z"])
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
            self.independent_axes(out.axes, j.path + ("axes",))

    def _resolve_values(self, out: ResolvedJoint, env: Mapping[str, ex.Value]) -> None:
        """Its coordinates (one per degree of freedom); its actuator's displacement, or its home values."""
        j = out.spec
        kind = JOINT_TYPES[j.type]
        if j.coordinates and len(j.coordinates) != kind.dof:
            raise InputError(
                f"a {j.type} joint has {kind.dof} coordinate(s), got {len(j.coordinates)}",
                path=j.path + ("coordinates",),
            )
        if j.actuated is not None:
            out.value = self.actuator(j, env)
        elif j.home:
            dims = kind.dims
            out.home = [
                self.scalar(h, j.path + ("home", k), env, dims[k] if k < len(dims) else None)
                for k, h in enumerate(j.home)
            ]

    def close(self, leg: Leg, joints: list[ResolvedJoint], turn: ca.SX | None = None) -> None:
        """The leg's closure rows, indicators and reported joint values (turn: a repeated leg's turn)."""
        last = joints[-1]
        tip, tip_l, rod, before, elim = self._ending(leg, joints)
        slide = None
        if elim is None and before and before[-1].type in ("P", "planar_P") and len(before) >= 2:
            if before[-2].value is None and before[-2].type in SPHERE_JOINTS | {"R"}:
                slide, elim = before.pop(), before.pop()
        for k, j in enumerate(before):
            if j.value is None:
                self.unknowns(j, leg, k)
        Rm, tm = chain_motion(before)
        B = self.platform_point(tip)
        self.drawn.append((leg.name, leg_points(last, before, elim, slide, Rm, tm, B, self.d.platform.planar)))
        R_rel = self.R @ self.R_home.T
        if elim is None:
            v = B - (Rm @ tip + tm)
            for k in range(2 if self.d.platform.planar else 3):
                self.rows.append((v[k], f"leg {leg.name}: point {'xyz'[k]}"))
            self.report_tip(last, Rm, R_rel, leg.name)
            return
        c = Rm @ elim.at + tm
        u0 = tip - elim.at
        # the link's constants in the leg's frame (the same for every copy of a repeated leg)
        u0_l = tip_l - elim.local["at"]
        link = _Link(leg, elim, before, Rm, c, u0, Rm @ u0, B - c, u0_l, elim.local.get("axis"), ca.norm_2(u0_l))
        if slide is not None:
            Rb, tip_turn = self._close_slide(link, slide), None
        else:
            close = {"R": self._close_revolute, "C": self._close_cylinder}.get(elim.type, self._close_sphere)
            Rb, tip_turn = close(link, rod, turn)
        self.report_tip(last, Rb, R_rel, leg.name, tip_turn)

    def _ending(self, leg: Leg, joints: list[ResolvedJoint]) -> tuple:
        """How the leg reaches the platform: (the platform point B0, in the leg's frame too, a
        distance joint's given length, the joints before it, the joint whose link is eliminated --
        the point joint before a distance joint, else the R, C or point joint before the last one,
        when passive)."""
        last = joints[-1]
        before = joints[:-1]
        if last.type == "distance":
            elim = ResolvedJoint(Joint("S", path=last.spec.path), at=last.at, local={"at": last.local["at"]})
            return last.to, last.local["to"], last.length, before, elim
        if last.type in POINT_JOINTS and (last.type == "S") != self.d.platform.planar:
            elim = None
            if before and before[-1].value is None and before[-1].type in ("R", "C", *SPHERE_JOINTS):
                elim = before.pop()
            return last.at, last.local["at"], None, before, elim
        want = "planar_R" if self.d.platform.planar else "S"
        raise InputError(
            f"leg {leg.name}: it must reach the platform through a point joint ({want}) or a distance joint; "
            f"its last joint is {last.type}",
            path=last.spec.path + ("type",),
        )

    def _close_slide(self, link: _Link, slide: ResolvedJoint) -> ca.SX | None:
        """A P along the link c -> B between two point joints (or after an R): its length row."""
        leg, elim, u0, u, v, r = link.leg, link.elim, link.u0, link.u, link.v, link.r
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
        if self.d.platform.planar:  # a circle |B - c| = r + s about the passive R (.dyads)
            self.circles.append((len(self.rows) - 1, link.c, v + link.c, r + slide.value))
        self.indicator((r + slide.value) / r, leg, slide, "the leg's length over its reference length")
        self.indicator(ca.dot(u, v) / (r * ca.norm_2(v)), leg, elim, COSINE)
        if elim.type != "R":
            return self.report_sphere(elim, link.Rm, u0, v, leg)
        # R-P-S: the leg also stays in the plane normal to the R axis
        w = link.Rm @ elim.axis
        self.rows.append((ca.dot(v, w) - ca.dot(link.u0_l, link.axis_l), f"leg {leg.name}: plane of the R joint"))
        theta = ca.atan2(ca.dot(w, ca.cross(u, v)), ca.dot(u, v))
        self.report(elim, [theta], leg.name)
        return rot(w, theta) @ link.Rm

    def _close_revolute(self, link: _Link, _rod: ca.SX | None, turn: ca.SX | None) -> tuple:
        """An R at c: B stays on a circle about its axis (axial offset, radius)."""
        leg, elim, Rm, u, v, u0_l, axis_l, r = (
            link.leg,
            link.elim,
            link.Rm,
            link.u,
            link.v,
            link.u0_l,
            link.axis_l,
            link.r,
        )
        w = Rm @ elim.axis
        h = ca.dot(u0_l, axis_l)
        up, vp = u - ca.dot(u, w) * w, v - ca.dot(v, w) * w
        self.rows.append((ca.dot(v, w) - h, f"leg {leg.name}: plane of the R joint"))
        self.rows.append(((ca.dot(v, v) - ca.dot(u0_l, u0_l)) / (2 * r), f"leg {leg.name}: radius about the R joint"))
        self.eliminated(leg, elim, link.before, link.c, v, 2, w)
        if turn is not None and is_identity(Rm):
            # a turned leg whose proximal chain only slides: its angle and its link's rotation in
            # the leg's own frame (v_l = turnᵀ v), where the file's axes are (0, 1, 0) and the
            # like -- the rotation about w_l keeps a U or S axis along w_l exactly, and the tip's
            # angles need no turned constant (`report_tip`)
            v_l, w_l = turn.T @ v, axis_l
            # w·(up × vp) = v·(w × u) and up·vp = u·v - (u·w)(v·w), with u·w = h
            theta = ca.atan2(ca.dot(v_l, ca.cross(w_l, u0_l)), ca.dot(u0_l, v_l) - h * ca.dot(v_l, w_l))
            self.report(elim, [theta], leg.name)
            return rot(w_l, theta), turn
        theta = ca.atan2(ca.dot(w, ca.cross(up, vp)), ca.dot(up, vp))
        self.report(elim, [theta], leg.name)
        return rot(w, theta) @ Rm, None

    def _close_cylinder(self, link: _Link, _rod: ca.SX | None, _turn: ca.SX | None) -> tuple:
        """A C at c: B stays on a cylinder about its axis."""
        leg, elim, Rm, u, v, u0_l, axis_l = link.leg, link.elim, link.Rm, link.u, link.v, link.u0_l, link.axis_l
        w = Rm @ elim.axis
        up, vp = u - ca.dot(u, w) * w, v - ca.dot(v, w) * w
        rp = ca.norm_2(u0_l - ca.dot(u0_l, axis_l) * axis_l)
        self.rows.append(((ca.dot(vp, vp) - rp**2) / (2 * rp), f"leg {leg.name}: cylinder of the C joint"))
        self.eliminated(leg, elim, link.before, link.c, v, 1, w)
        theta = ca.atan2(ca.dot(w, ca.cross(up, vp)), ca.dot(up, vp))
        self.report(elim, [theta, ca.dot(v, w) - ca.dot(u0_l, axis_l)], leg.name)
        return rot(w, theta) @ Rm, None

    def _close_sphere(self, link: _Link, rod: ca.SX | None, _turn: ca.SX | None) -> tuple:
        """A U, S or planar R at c (or a distance joint): B stays on a sphere (circle) about c."""
        leg, v, u0_l, r = link.leg, link.v, link.u0_l, link.r
        if rod is None:
            self.rows.append(((ca.dot(v, v) - ca.dot(u0_l, u0_l)) / (2 * r), f"leg {leg.name}: distance"))
        else:  # its given length: the drawing need not close (the reference is assembled)
            self.rows.append(((ca.dot(v, v) - rod**2) / (2 * rod), f"leg {leg.name}: distance"))
        # a circle |B - c| = radius (planar): a dyad's half, for the closed-form FK (.dyads)
        self.circles.append((len(self.rows) - 1, link.c, v + link.c, r if rod is None else rod))
        self.eliminated(leg, link.elim, link.before, link.c, v, 1)
        return self.report_sphere(link.elim, link.Rm, link.u0, v, leg), None

    def indicator(self, value: ca.SX | None, leg: Leg, j: ResolvedJoint, what: str) -> None:
        """A generated branch indicator, named after its leg and joint (``a1.U1``: leg a1, its
        first joint, a U); value None: filled in by `branches.elimination_indicators`."""
        n = j.spec.path[-1] + 1 if j.spec.path and isinstance(j.spec.path[-1], int) else 0
        name = f"{leg.name}.{JOINT_TYPES[j.type].letter}{n}"
        self.branch.append((value, name, f"leg {leg.name}, joint {n} ({j.type}): {what}"))

    def eliminated(
        self,
        leg: Leg,
        elim: ResolvedJoint,
        before: list[ResolvedJoint],
        c: ca.SX,
        v: ca.SX,
        nrows: int,
        along: ca.SX | None = None,
    ) -> None:
        """Record an eliminated link c -> B (its last ``nrows`` closure rows; v: c -> B, vp: its part
        normal to the axis ``along`` of an eliminated R or C, else v) and its working-mode expression:
        the closure's rate with respect to the joint before it, w·((c - a) × vp) for a revolute (axis
        w at a), e·vp for a P along e (None: no joint before it, or one with several motions).  The
        indicator itself is chosen once Φ_x is known (`branches.elimination_indicators`)."""
        vp = v if along is None else v - ca.dot(v, along) * along
        working, what = None, ""
        if before and JOINT_TYPES[before[-1].type].dof == 1:
            b = before[-1]
            Rk, tk = chain_motion(before[:-1])  # the joint before, moved by the joints before it
            if JOINT_TYPES[b.type].motion[0][0] == "R":
                rate = ca.cross(Rk @ b.axis, c - (Rk @ b.at + tk))
                what = WORKING_PLANAR if self.d.platform.planar else WORKING_R
                working = ca.dot(rate, vp)
            else:
                rate = Rk @ b.axis
                what = WORKING_P
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

    def unknowns(self, j: ResolvedJoint, leg: Leg, k: int) -> None:
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
            self.extra.append((coord, sym, home, self.joint_limit(j, dim), j.spec.path))
            j.motions.append((kind, axis, sym - home))

    def report(self, j: ResolvedJoint, values: list, leg: str) -> None:
        names = j.spec.coordinates
        if not names:
            return
        for k, (name, val) in enumerate(zip(names, values)):
            home = j.home[k] if k < len(j.home) else 0
            dim = JOINT_TYPES[j.type].dims[k]
            fam = j.spec.limit or family(name)
            desc = f"{j.type} joint of leg {leg}" + (f", axis {k + 1}" if len(names) > 1 else "")
            self.reported.append(
                Reported(Coordinate(name, dim, desc, fam), home + val, self.flexure_range(j, dim, home), j.spec.path)
            )

    def report_sphere(self, elim: ResolvedJoint, Rm: ca.SX, u0: ca.SX, v: ca.SX, leg: Leg) -> ca.SX | None:
        """The angles of a U (or planar R) whose link is eliminated, and the link's rotation (None: not determined)."""
        if elim.type == "planar_R":
            u = Rm @ u0
            theta = ca.atan2(u[0] * v[1] - u[1] * v[0], u[0] * v[0] + u[1] * v[1])
            self.report(elim, [theta], leg.name)
            return rot("z", theta) @ Rm
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
            return Rm @ F @ rot("x", theta1) @ rot("y", theta2) @ F.T
        if elim.spec.coordinates:
            raise InputError(
                f"leg {leg.name}: the spin of a link between two spherical joints is not determined; "
                "report no coordinates for this S (or use a U)",
                path=elim.spec.path + ("coordinates",),
            )
        return None

    def report_tip(
        self, last: ResolvedJoint, Rb: ca.SX | None, R_rel: ca.SX, leg_name: str, turn: ca.SX | None = None
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
                self.report(last, xyz_angles((Rb @ F).T @ (turn.T @ (R_rel @ (turn @ F)))), leg_name)
                return
        if last.type == "planar_R":
            M = Rb.T @ R_rel
            self.report(last, [ca.atan2(M[1, 0], M[0, 0])], leg_name)
            return
        F = ca.horzcat(*last.axes) if last.axes else ca.SX.eye(3)
        self.report(last, xyz_angles(F.T @ Rb.T @ R_rel @ F), leg_name)

    # -- the whole closure -----------------------------------------------------------------------
    def build(self) -> dict[str, Any]:
        """The closure: the platform, each leg's rows (its passive joints eliminated), the declared
        actuators and closures, the reported values, the branch indicators, the functions."""
        self.platform()
        for leg in self.d.legs:
            self.leg(leg)
        self.declared_actuators()
        q = ca.vertcat(*self.q_syms)
        full = dict(self.xenv)
        for c, s in zip(self.q_coords, self.q_syms):
            self.bind(full, c.name, ex.Value(s, ex.DIMENSION_OF[c.kind]), ("actuators", c.name))
        for k, text in enumerate(self.d.closures):
            self.rows.append((self.scalar(text, ("closures", k), full), f"closures[{k}]"))
        added = branch_expressions(self, full)
        families = list(dict.fromkeys(r.coord.group for r in self.reported))
        self.reported.sort(key=lambda r: families.index(r.coord.group))  # alpha1..3, beta1..3, as the papers list them
        self.report_passive(full)
        self.add_unknowns()
        self.unique_names()
        self.check_mobility()
        elimination_indicators(self, q)
        aspect(self, q)
        select_branch(self, added)
        self.check_task_count()
        fns = closure_functions(self, q)
        fns["fk_closed"] = closed_form_fk(self, q, self.circles) if self.d.platform.planar else None
        return fns

    def declared_actuators(self) -> None:
        """The ``actuators`` section's (for closures written as expressions), after the joints'."""
        for name, (dim, home) in self.d.actuators.items():
            if name not in [c.name for c in self.q_coords]:
                self.q_coords.append(Coordinate(name, dim, "actuator", family(name)))
                self.q_syms.append(ca.SX.sym(name))
                self.q_home.append(self.scalar(home, ("actuators", name, "home"), self.env, dim))
        if not self.q_coords:
            raise InputError("no actuators: mark joints 'actuated: name' (or declare 'actuators')", path=("legs",))

    def report_passive(self, full: dict[str, ex.Value]) -> None:
        """The ``passive`` section's values, reported beside the joints'."""
        for qty in self.d.passive:
            v = self.value(qty.value, ("passive", qty.name), full, qty.dimension)
            dim = qty.dimension or dim_name(v.dim)
            fam = qty.family or family(qty.name)
            self.reported.append(
                Reported(Coordinate(qty.name, dim, qty.description, fam), v.sx, None, ("passive", qty.name))
            )

    def check_mobility(self) -> None:
        """As many equations as pose coordinates."""
        nx, nrows = len(self.x_names), len(self.rows)
        if nrows != nx:
            what = "over" if nrows > nx else "under"
            raise InputError(
                f"wrong mobility: the legs and closures give {nrows} equation(s) for {nx} pose coordinate(s) "
                f"({', '.join(self.x_names)}): {what}-constrained; equations: {'; '.join(r[1] for r in self.rows)}",
                path=("platform", "coordinates"),
                hint="declare the coordinates the structure fixes under platform.fixed, or add legs",
            )


__all__ = ["Generator"]
