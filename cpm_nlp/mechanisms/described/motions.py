"""Joints resolved to CasADi: their location, axes and values, their elementary motions
(product of exponentials about their reference axes), the rotations they are written with,
and the aliases of the joint table (`cpm_nlp.core.joints.JOINT_TYPES`) the generators
use."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import casadi as ca

from ...core.joints import JOINT_TYPES
from ...core.screws import axis_rotation
from .spec import Joint

# aliases derived from the joint table (cpm_nlp.core.joints.JOINT_TYPES)
#: point joints (a leg reaches its platform point through one: S; planar R)
POINT_JOINTS = {n for n, t in JOINT_TYPES.items() if t.point}
#: joints about a point: the link after it sweeps a sphere (circle): U, S, planar R
SPHERE_JOINTS = {n for n, t in JOINT_TYPES.items() if t.sphere}
#: the letter a drawing marks each joint type with (a distance joint: a rod between two spherical joints)
LETTER = {n: t.letter for n, t in JOINT_TYPES.items()}
#: the dimension of the coordinates of each joint type whose coordinates share one (not C, not distance)
JOINT_DIMS = {n: t.dims[0] for n, t in JOINT_TYPES.items() if len(set(t.dims)) == 1}
#: the base frame's axes, for an S joint given without its ``axes``
BASE_AXES = {"x": ca.DM([1.0, 0, 0]), "y": ca.DM([0, 1.0, 0]), "z": ca.DM([0, 0, 1.0])}


def rot(axis: Any, angle: Any) -> ca.SX:
    """Rotation by ``angle`` about a unit axis k, or about "x", "y", "z" (Rodrigues,
    `axis_rotation`: R = cos I + sin [k]x + (1 - cos) k kᵀ, whose
    zero entries of k drop out about a base axis)."""
    if isinstance(axis, str):
        axis = ca.DM([1.0 if axis == a else 0.0 for a in "xyz"])
    return ca.SX(axis_rotation(ca.SX(axis), angle))


def is_identity(M: ca.SX) -> bool:
    """M is the constant identity (a proximal chain that only slides)."""
    return bool(M.is_constant()) and float(ca.norm_inf(ca.DM(M) - ca.DM.eye(M.size1()))) == 0.0


def xyz_angles(M: ca.SX) -> list[ca.SX]:
    """(a, b, c) with M = Rx(a) Ry(b) Rz(c)."""
    return [ca.atan2(-M[1, 2], M[2, 2]), ca.asin(ca.fmin(ca.fmax(M[0, 2], -1), 1)), ca.atan2(-M[0, 1], M[0, 0])]


@dataclass
class ResolvedJoint:
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


def elementary_motions(j: ResolvedJoint) -> list[tuple[str, Any]]:
    """A joint's degrees of freedom as elementary motions ("P" | "R", axis), in the order
    of its coordinates (product of exponentials about its reference axes): the joint table's
    motions (`cpm_nlp.core.joints.JOINT_TYPES`) with the joint's axes."""
    t = JOINT_TYPES[j.type]
    axes = j.axes or [BASE_AXES[a] for a in t.default_axes]
    return [(kind, j.axis if source == "axis" else axes[source]) for kind, source in t.motion]


def chain_motion(joints: list[ResolvedJoint]) -> tuple[ca.SX, ca.SX]:
    """The motion y -> Rm y + tm of the proximal chain's last body (product of exponentials)."""
    Rm, tm = ca.SX.eye(3), ca.SX.zeros(3)
    for j in joints:
        motions = j.motions or [(JOINT_TYPES[j.type].motion[0][0], j.axis, j.value)]
        for kind, axis, value in motions:
            if kind == "P":
                Rk, tk = ca.SX.eye(3), value * axis
            else:  # a rotation about the axis through j.at
                Rk = rot(axis, value)
                tk = j.at - Rk @ j.at
            Rm, tm = Rm @ Rk, Rm @ tk + tm
    return Rm, tm
