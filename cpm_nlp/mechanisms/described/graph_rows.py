"""The rows a cut joint writes (the loop it closes) and the values it reports: its two bodies'
relative motion must be one the joint allows -- a point joint (S; planar R) keeps its two points
together, an R also keeps the axes parallel, a U its axes normal, a P keeps the relative rotation
and the offset along the axis, a C the offset and the axes, a distance joint the rod's length."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import casadi as ca
import numpy as np

from ...core.screws import vee
from .graph_tree import GraphJoint
from .motions import xyz_angles


def axis_normals(w: ca.SX, p: ca.SX, p_default: np.ndarray) -> tuple[ca.SX, ca.SX]:
    """Two unit vectors normal to a joint's axis w (and to each other): n1 = unit(w × e), n2 = w × n1,
    e the basis vector least aligned with w (with the parameters' defaults)."""
    value = np.abs(np.asarray(ca.Function("axis", [p], [w])(p_default), dtype=float).ravel())
    e = ca.DM.zeros(3)
    e[int(np.argmin(value))] = 1.0
    n1 = ca.cross(w, e)
    n1 = n1 / ca.norm_2(n1)
    return n1, ca.cross(w, n1)


@dataclass
class Cut:
    """A cut joint at the pose: its bodies' rotations Ra, Rb, the offset d = (its point on b) - (its
    point on a) in the world, the mechanism's plane, the size that makes an angle a length, and the
    normals to its axis (called when a row needs them)."""

    g: GraphJoint
    Ra: ca.SX
    Rb: ca.SX
    d: ca.SX
    planar: bool
    scale: ca.SX
    normals: Callable[[], tuple[ca.SX, ca.SX]]


Rows = list[tuple[ca.SX, str]]


def _length(c: Cut) -> Rows:
    return [((ca.dot(c.d, c.d) - c.g.length**2) / (2 * c.g.length), "length")]


def _point(c: Cut) -> Rows:
    return [(c.d[k], f"point {'xyz'[k]}") for k in range(2 if c.planar else 3)]


def _offset(c: Cut) -> Rows:
    if c.planar:
        return [(ca.cross(c.Ra @ c.g.axis, c.d)[2], "offset across the axis")]
    n1, n2 = c.normals()
    return [
        (ca.dot(c.Ra @ n1, c.d), "offset across the axis, 1"),
        (ca.dot(c.Ra @ n2, c.d), "offset across the axis, 2"),
    ]


def _parallel(c: Cut) -> Rows:
    n1, n2 = c.normals()
    wa_axis = c.Ra @ c.g.axis
    return [(ca.dot(wa_axis, c.Rb @ n) * c.scale, f"axes parallel, {k + 1}") for k, n in enumerate((n1, n2))]


def _normal_axes(c: Cut) -> Rows:
    return [(ca.dot(c.Ra @ c.g.axes[0], c.Rb @ c.g.axes[1]) * c.scale, "axes normal")]


def _no_rotation(c: Cut) -> Rows:
    v = vee(c.Ra.T @ c.Rb) * c.scale
    return [(v[k], f"no relative rotation, {'xyz'[k]}") for k in range(3)]


def _no_planar_rotation(c: Cut) -> Rows:
    return [((c.Ra.T @ c.Rb)[1, 0] * c.scale, "no relative rotation")]


#: the rows each joint type writes when it closes a loop, in order
CUT_ROWS: dict[str, tuple[Callable[[Cut], Rows], ...]] = {
    "distance": (_length,),
    "S": (_point,),
    "planar_R": (_point,),
    "R": (_point, _parallel),
    "U": (_point, _normal_axes),
    "C": (_offset, _parallel),
    "P": (_offset, _no_rotation),
    "planar_P": (_offset, _no_planar_rotation),
}


def cut_rows(c: Cut) -> Rows:
    """The loop a cut joint closes: its rows (all of them; the independent ones are kept later)."""
    return [row for rows in CUT_ROWS[c.g.type] for row in rows(c)]


def _frame(g: GraphJoint) -> ca.SX:
    """The frame an S (its axes, default the base's) or a U (its two axes and their normal) reports its angles in."""
    if g.type == "U":
        return ca.horzcat(g.axes[0], g.axes[1], ca.cross(g.axes[0], g.axes[1]))
    return ca.horzcat(*g.axes) if g.axes else ca.SX.eye(3)


def cut_values(g: GraphJoint, M: ca.SX, d: ca.SX) -> list:
    """A cut joint's displacements from the drawing, from its bodies' relative rotation M = Raᵀ Rb
    and offset d (in a's frame); an S's: its angles about its axes."""
    values = {
        "planar_R": lambda: [ca.atan2(M[1, 0], M[0, 0])],
        "R": lambda: [_turn(g, M)],
        "C": lambda: [_turn(g, M), ca.dot(g.axis, d)],
        "P": lambda: [ca.dot(g.axis, d)],
        "planar_P": lambda: [ca.dot(g.axis, d)],
        "U": lambda: _angles(g, M)[:2],
    }
    return values.get(g.type, lambda: _angles(g, M))()


def _turn(g: GraphJoint, M: ca.SX) -> ca.SX:
    """The angle of M about the joint's axis."""
    return ca.atan2(ca.dot(g.axis, vee(M)), (ca.trace(M) - 1) / 2)


def _angles(g: GraphJoint, M: ca.SX) -> list:
    F = _frame(g)
    return xyz_angles(F.T @ M @ F)
