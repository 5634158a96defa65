"""The aspect indicator: on which side of the forward singularities a pose lies.

Assembly modes of one working mode (the same leg configurations) are separated
by forward (type II) singularities, where det Φ_x = 0.  The sign of det Φ_x,
relative to its sign at the reference configuration, therefore tells a mode
across such a singularity from the designated one.  det Φ_x depends on how the
rotation is parametrized: with three angles it carries the determinant of the
map from the angles' rates to the angular velocity (e.g. cos θ for Z-Y-X
angles), which vanishes at a gimbal lock and changes sign between the two angle
triples of one rotation.  `twist_determinant` divides it out, so the
indicator is a property of the pose, not of its angles.

A negative aspect proves another assembly mode; a positive one does not prove
the same mode (two crossings cancel), so it is one indicator among the others.
"""

from __future__ import annotations

import casadi as ca

#: the name of the aspect indicator
ASPECT = "aspect"
ASPECT_DESCRIPTION = "det Φ_x per platform twist over its value at home; negative: another assembly mode"
#: an aspect indicator is built for at most this many pose coordinates (a symbolic determinant)
ASPECT_MAX_NX = 6


def twist_determinant(phi: ca.SX, x: ca.SX, R: ca.SX | None) -> ca.SX:
    """det Φ_x, divided by det E when the rotation matrix R depends on exactly
    three coordinates of x (E: their rates -> body angular velocity)."""
    det = ca.det(ca.jacobian(phi, x))
    if R is None:
        return det
    rot = [k for k in range(x.numel()) if ca.depends_on(R, x[k])]
    if len(rot) != 3:
        return det
    cols = []
    for k in rot:
        W = R.T @ ca.reshape(ca.jacobian(ca.vec(R), x[k]), 3, 3)
        cols.append(ca.vertcat(W[2, 1], W[0, 2], W[1, 0]))
    return det / ca.det(ca.horzcat(*cols))


def aspect(phi: ca.SX, x: ca.SX, q: ca.SX, R: ca.SX | None, x_home: ca.SX, q_home: ca.SX) -> ca.SX:
    """The aspect indicator: the twist determinant over its value at the reference (x_home, q_home),
    positive in the reference configuration's aspect."""
    d = twist_determinant(phi, x, R)
    return d / ca.substitute(d, ca.vertcat(x, q), ca.vertcat(x_home, q_home))
