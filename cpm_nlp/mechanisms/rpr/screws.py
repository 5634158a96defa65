"""Screw theory of the RPR compliant mechanism (Zhang, Liu, Ding, "Design and Analysis of a Novel
Compliant Mechanism with RPR Degrees of Freedom", Chin. J. Mech. Eng. 2022): the motion screw system, the bases of each
leg's twist and wrench subspaces (appendix), the Jacobian by screw theory (eq 7-13) and the
displacement twists of section 5.1.

These are analyses of the paper, beside the mechanism's kinematics, which is its file
``problems/mechanisms/rpr.yaml`` (loop closures, IK, passive joints, drawing).  The screw
bases are written in the paper's own points: A_i (eq 5), B_i = R B_i' + o' (eq 3-4),
R = Ry(theta) Rx(alpha) (eq 2), o' = (P sin theta, 0, P cos theta); the screw-theory
Jacobian they give is checked against the AD Jacobian of the file's closures (the kind
``rpr_screw_jacobian`` reports the difference, ``dJ``; tests/mechanisms/rpr/test_rpr_kinematics.py).

Symbols follow the paper: pose x = (theta, alpha, P), actuators q = (l1, l2, l3) (eq 6),
parameters p = (r1, r2, P0); legs 1 and 3 are RPU (R at A_i about y, U at B_i about y then
x'), leg 2 is UPR (U at A2 about y then x', R at B2 about x').

Readings of the paper chosen here (documented, not tuned):

* **Motion screw system S_t (eq 7).**  As printed, its first column has the
  linear part (P sθ, 0, -P cθ) and its second column the direction
  (-cθ, 0, sθ).  Differentiating eq 2 and o' gives, at the reference point o'
  of the appendix, ω = θ̇ y + α̇ x' and v_o' = θ̇ P (cθ, 0, -sθ) + Ṗ (sθ, 0, cθ):
  the first column is (0, 1, 0; P cθ, 0, -P sθ) and the second (cθ, 0, -sθ; 0).
  The derived columns are used (`motion_screws`); only then does the
  screw-theory Jacobian of eq 9-11 agree with the loop closures (it does, to
  round-off; see the tests).
* **Displacement twists (eq 45).**  Rotational rows and the translation along
  oo' follow from the kinematics.  The printed translational rows of eq 45
  and 47 take the moment of the rotation about oA2 as oo' × y, the position
  vector running from the axis to the reference point; the appendix's own rule
  (o'A_i × s) and the velocity of o' give o'o × y, the opposite sign of that
  contribution (row 4 of eq 45: +5e-6 printed, -5e-6 as velocity of o').
  Eq 49 is printed with the velocity convention.  Both conventions are
  available (`motion_screws`, ``convention``), with any reference point.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Sequence
from dataclasses import dataclass

import casadi as ca
import numpy as np

from ...core import screws
from ...core.errors import InputError
from ...core.model import Model

#: index of the actuated (P) joint among each leg's permitted twists (appendix)
ACTUATED = (1, 2, 1)
#: the passive joints of each leg among its permitted twists (eq 13), in the order of the
#: file's passive joints theta_a11, theta_a13, theta_a14, theta_a21, ... (eq 13's G_p)
PASSIVE_INDEX = ((0, 2, 3), (0, 1, 3), (0, 2, 3))

REFERENCES = ("o_prime", "o", "point")
CONVENTIONS = ("velocity", "eq45")

Y = ca.DM([0.0, 1.0, 0.0])


# -- the paper's points, eq 2-5 ---------------------------------------------------------------------


def rotation(theta, alpha):
    """R of eq 2 (= Ry(θ) Rx(α))."""
    ct, st, ca_, sa = ca.cos(theta), ca.sin(theta), ca.cos(alpha), ca.sin(alpha)
    return ca.vertcat(
        ca.horzcat(ct, st * sa, st * ca_),
        ca.horzcat(0, ca_, -sa),
        ca.horzcat(-st, ct * sa, ct * ca_),
    )


def origin(theta, P):
    """o' = (P sθ, 0, P cθ) in the fixed frame (section 2.1)."""
    return ca.vertcat(P * ca.sin(theta), 0, P * ca.cos(theta))


def x_axis(theta):
    """x' = R (1, 0, 0) = (cθ, 0, -sθ), the axis of alpha (B1B3)."""
    return ca.vertcat(ca.cos(theta), 0, -ca.sin(theta))


def joint_points(x, p):
    """(A_i, B_i) in the fixed frame for the pose x: A_i of eq 5, B_i = R B_i' + o' (eq 3-4)."""
    theta, alpha, P = x[0], x[1], x[2]
    r1, r2 = p[0], p[1]
    R = rotation(theta, alpha)
    o_ = origin(theta, P)
    local = [ca.vertcat(r1, 0, 0), ca.vertcat(0, r2, 0), ca.vertcat(-r1, 0, 0)]  # eq 3 (and eq 5: A_i)
    return local, [R @ b + o_ for b in local]


def _symbols():
    return ca.SX.sym("x", 3), ca.SX.sym("p", 3)


def paper_parameters(model: Model) -> np.ndarray:
    """(r1, r2, P0) of the model, by name (whatever order the file's closure keeps them in)."""
    return np.array([float(model.parameters[k]) for k in ("r1", "r2", "P0")])


# -- screw theory, eq 7-13 and the appendix -------------------------------------------------------


def motion_screws(x, p, reference=None, convention: str = "velocity"):  # noqa: ARG001 - same (x, p) signature as the other screw functions
    """S_t (6 x 3): the platform twist is S_t (θ̇, α̇, Ṗ) (eq 7).

    Parameters
    ----------
    reference
        point (fixed frame) the linear rows refer to; default o'.
    convention
        "velocity" -- the linear rows are the velocity of the body point at the reference
        (Plücker (s; (a - c) × s), as in the appendix); "eq45" -- the moment of each rotation is
        taken with the position vector from the axis point a to the reference c, (s; (c - a) ×
        s), which is how the translational rows of eq 45 and 47 are printed (see the module
        notes).
    """
    if convention not in CONVENTIONS:
        raise ValueError(f"unknown twist convention {convention!r}")
    theta, P = x[0], x[2]
    o_ = origin(theta, P)
    c = o_ if reference is None else reference
    xp = x_axis(theta)
    u = ca.vertcat(ca.sin(theta), 0, ca.cos(theta))  # direction of oo'
    sign = 1.0 if convention == "velocity" else -1.0
    col_theta = ca.vertcat(Y, sign * ca.cross(ca.DM.zeros(3) - c, Y))  # rotation about oA2 (through o)
    col_alpha = ca.vertcat(xp, sign * ca.cross(o_ - c, xp))  # rotation about B1B3 (through o')
    col_P = screws.translation(u)
    return ca.horzcat(col_theta, col_alpha, col_P)


def branch_screws(i: int, x, p) -> dict:
    """Bases of leg i's subspaces, referred to o' (appendix): permitted twists
    ``ta`` (6 x 4), constrained twists ``tc`` (6 x 2), actuated wrenches ``wa``
    (6 x 4) and constrained wrenches ``wc`` (6 x 2).  i = 0, 1, 2."""
    theta = x[0]
    A, B = joint_points(x, p)
    o_ = origin(theta, x[2])
    xp = x_axis(theta)
    AB = B[i] - A[i]
    u = AB / ca.norm_2(AB)  # unit: the rate of the prismatic twist is l̇_i (the appendix writes A_iB_i)

    def ln(direction, point):
        return screws.line(direction, point, o_)

    if i in (0, 2):
        ta = [ln(Y, A[i]), screws.translation(u), ln(Y, B[i]), ln(xp, B[i])]
        tc = [ln(AB, B[i]), screws.translation(Y)]
        wc = [screws.couple(ca.cross(B[2] - B[0], Y)), ln(Y, B[i])]
        wa = [ln(ca.cross(AB, Y), B[i]), ln(AB, A[i]), ln(xp, A[i]), screws.couple(xp)]
    else:
        ta = [ln(Y, A[1]), ln(xp, A[1]), screws.translation(u), ln(xp, B[1])]
        tc = [ln(AB, A[1]), screws.translation(xp)]
        wc = [screws.couple(ca.vertcat(-ca.sin(theta), 0, -ca.cos(theta))), ln(xp, A[1])]
        wa = [screws.couple(Y), ln(Y, B[1]), ln(AB, A[1]), ln(Y, A[1])]
    return {"ta": ca.horzcat(*ta), "tc": ca.horzcat(*tc), "wa": ca.horzcat(*wa), "wc": ca.horzcat(*wc)}


@functools.lru_cache(maxsize=1)
def screw_function() -> ca.Function:
    """``("rpr_screws", [x, p], [S_t, ta1, tc1, wa1, wc1, ..., wc3])``, built
    once per process (code, not data)."""
    x, p = _symbols()
    outs, names = [motion_screws(x, p)], ["S_t"]
    for i in range(3):
        bases = branch_screws(i, x, p)
        for key in ("ta", "tc", "wa", "wc"):
            outs.append(bases[key])
            names.append(f"{key}{i + 1}")
    return ca.Function("rpr_screws", [x, p], outs, ["x", "p"], names)


@dataclass
class ScrewJacobian:
    """The screw-theory route of eq 7-13 at one pose (reference o').

    Attributes
    ----------
    S_t
        motion screw system (6 x 3, eq 7, derived columns);
    J_a, J_b
        eq 9; J = J_b⁻¹ J_a (q̇ = J V, eq 10); G = J⁻¹ (V = G q̇, eq 11);
    G_p
        passive joint rates per actuator rate (9 x 3, eq 12-13), rows in the order of the file's
        passive joints (theta_a11, ..., eq 13);
    branch_rates
        J_i⁻¹ S_t G per leg (6 x 3, eq 12), whose constrained-twist rows must vanish.
    """

    S_t: np.ndarray
    J_a: np.ndarray
    J_b: np.ndarray
    J: np.ndarray
    G: np.ndarray
    G_p: np.ndarray
    branch_rates: list[np.ndarray]


def screw_jacobian(model: Model, x: Sequence[float]) -> ScrewJacobian:
    """J, G and G_p of eq 9-13 from the screw bases of the appendix."""
    xv = np.asarray(x, dtype=float).ravel()
    out = [np.asarray(v) for v in screw_function()(xv, paper_parameters(model))]
    S_t = out[0]
    bases = [dict(zip(("ta", "tc", "wa", "wc"), out[1 + 4 * i : 5 + 4 * i])) for i in range(3)]
    D = screws.DELTA
    J_a = np.vstack([bases[i]["wa"][:, ACTUATED[i]] @ D @ S_t for i in range(3)])  # eq 9
    J_b = np.diag([bases[i]["wa"][:, ACTUATED[i]] @ D @ bases[i]["ta"][:, ACTUATED[i]] for i in range(3)])
    J = np.linalg.solve(J_b, J_a)  # eq 10
    G = np.linalg.inv(J)  # eq 11
    rates, rows = [], []
    for i in range(3):
        J_i = np.hstack([bases[i]["ta"], bases[i]["tc"]])  # eq 7
        r = np.linalg.solve(J_i, S_t @ G)  # eq 12
        rates.append(r)
        rows.append(r[list(PASSIVE_INDEX[i]), :])  # eq 13
    return ScrewJacobian(S_t, J_a, J_b, J, G, np.vstack(rows), rates)


# -- displacement twists (section 5.1) ----------------------------------------------------------------


@functools.lru_cache(maxsize=1)
def twist_function() -> ca.Function:
    """``("rpr_twist_basis", [x, p, c, k], [S_t])``: S_t referred to the point c
    (fixed frame); k = +1 velocity convention, -1 the eq 45 convention."""
    x, p = _symbols()
    c = ca.SX.sym("c", 3)
    k = ca.SX.sym("k")
    vel = motion_screws(x, p, c, "velocity")
    e45 = motion_screws(x, p, c, "eq45")
    S = (1 + k) / 2 * vel + (1 - k) / 2 * e45
    return ca.Function("rpr_twist_basis", [x, p, c, k], [S], ["x", "p", "c", "k"], ["S_t"])


def reference_point(model: Model, x: Sequence[float], reference: str, point: Sequence[float] | None) -> np.ndarray:  # noqa: ARG001 - same (model, x) signature as twist_basis
    """The reference point (fixed frame) named by ``reference``: o' of the
    pose, the fixed origin o, or the given ``point``."""
    if reference == "o_prime":
        theta, P = float(x[0]), float(x[2])
        return np.array([P * math.sin(theta), 0.0, P * math.cos(theta)])
    if reference == "o":
        return np.zeros(3)
    if reference == "point":
        if point is None:
            raise InputError("reference 'point' needs the input 'point' [x, y, z]", path=("inputs", "point"))
        return np.asarray(point, dtype=float).ravel()
    raise InputError(
        f"unknown reference {reference!r}; expected one of: {', '.join(REFERENCES)}", path=("inputs", "reference")
    )


def twist_basis(model: Model, x: Sequence[float], reference: np.ndarray, convention: str) -> np.ndarray:
    """S_t at the pose x, referred to ``reference``, in ``convention``."""
    if convention not in CONVENTIONS:
        raise InputError(
            f"unknown convention {convention!r}; expected one of: {', '.join(CONVENTIONS)}",
            path=("inputs", "convention"),
        )
    k = 1.0 if convention == "velocity" else -1.0
    return np.asarray(twist_function()(np.asarray(x, dtype=float), paper_parameters(model), reference, k))
