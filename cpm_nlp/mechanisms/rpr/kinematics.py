"""RPR compliant mechanism from a 2-RPU-UPR parallel mechanism (Zhang, Liu,
Ding, Chin. J. Mech. Eng. 2022; ``../shared/papers/rpr-2rpu-upr-zhang-2022.md``).

Symbols follow the paper:

* pose x = (theta, alpha, P): rotation theta about the fixed y axis (the line
  oA2), rotation alpha about the moving x' axis (the line B1B3), and the
  distance P = |oo'|; R = Ry(theta) Rx(alpha) (eq 2), o' = (P sθ, 0, P cθ);
* actuators q = (l1, l2, l3), the lengths |A_iB_i| of the three legs (eq 6);
  legs 1 and 3 are RPU (R at A_i about y, U at B_i about y then x'), leg 2 is
  UPR (U at A2 about y then x', R at B2 about x');
* parameters r1 (|oA1| = |oA3| = |o'B1| = |o'B3|), r2 (|oA2| = |o'B2|) and P0,
  the P of the initial pose (eq 26: r1 = 40 mm, r2 = 80 mm, P = 40 mm), where
  the platforms are parallel and every leg has length P0.

Readings of the paper chosen here (documented, not tuned):

* **r1 and r2.**  The text of section 2 calls r1 the distance o'B2 and r2 the
  distance oA1; eq 3 and 5 put r1 on the x axis (A1, A3, B1, B3) and r2 on the y
  axis (A2, B2).  The equations are followed: eq 45 confirms them (10 µm on leg
  2 tilts the platform by 10 µm / r2 = 12.5e-5 rad with r2 = 80 mm, on leg 1 by
  10 µm / (2 r1) with r1 = 40 mm).
* **Motion screw system S_t (eq 7).**  As printed, its first column has the
  linear part (P sθ, 0, -P cθ) and its second column the direction
  (-cθ, 0, sθ).  Differentiating eq 2 and o' gives, at the reference point o'
  of the appendix, ω = θ̇ y + α̇ x' and v_o' = θ̇ P (cθ, 0, -sθ) + Ṗ (sθ, 0, cθ):
  the first column is (0, 1, 0; P cθ, 0, -P sθ) and the second (cθ, 0, -sθ; 0).
  The derived columns are used (:func:`motion_screws`); only then does the
  screw-theory Jacobian of eq 9-11 agree with the loop closures (it does, to
  round-off; see the tests).
* **Displacement twists (eq 45).**  Rotational rows and the translation along
  oo' follow from the kinematics.  The printed translational rows of eq 45
  and 47 take the moment of the rotation about oA2 as oo' × y, the position
  vector running from the axis to the reference point; the appendix's own rule
  (o'A_i × s) and the velocity of o' give o'o × y, the opposite sign of that
  contribution (row 4 of eq 45: +5e-6 printed, -5e-6 as velocity of o').
  Eq 49 is printed with the velocity convention.  Both conventions are
  available (:func:`motion_screws`, ``convention``), with any reference point.
* The loop-closure residuals are |A_iB_i| - l_i (lengths, metres).
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
from ...core.mechanism import Drawing
from ...core.model import Coordinate, LoopClosure, Model
from ...core.options import Option

PARAMETERS = (
    Option(
        "r1",
        "length",
        "|oA1| = |oA3| = |o'B1| = |o'B3|, legs 1 and 3 on the x axes (eq 3, 5)",
        lower=0.0,
        upper=10.0,
        strict=True,
    ),
    Option("r2", "length", "|oA2| = |o'B2|, leg 2 on the y axes (eq 3, 5)", lower=0.0, upper=10.0, strict=True),
    Option(
        "P0",
        "length",
        "P = |oo'| of the initial pose, platforms parallel, every leg P0 long (eq 26)",
        lower=0.0,
        upper=10.0,
        strict=True,
    ),
)

LIMITS = (
    Option("l", "length", "stroke [low, high] of every leg length l_i (eq 6)", default=None, shape="range"),
    Option("theta_R", "angle", "rotation range of every R flexure joint (passive, eq 13)", default=None, shape="range"),
    Option(
        "theta_U", "angle", "rotation range of every U flexure joint axis (passive, eq 13)", default=None, shape="range"
    ),
)

X = (
    Coordinate("theta", "angle", "rotation about the fixed y axis oA2 (eq 2)"),
    Coordinate("alpha", "angle", "rotation about the moving x' axis B1B3 (eq 2)"),
    Coordinate("P", "length", "distance |oo'| along oo' (eq 2-4)"),
)
Q = tuple(Coordinate(f"l{i}", "length", f"length |A{i}B{i}| of leg {i} (eq 6)", "l") for i in (1, 2, 3))
TASK = ("theta", "alpha", "P")

#: passive joints in the order of G_p (eq 13): the permitted twists of the
#: appendix without the actuated ones (S_ta,1,2, S_ta,2,3, S_ta,3,2).
PASSIVE = (
    Coordinate("theta_a11", "angle", "leg 1, R at A1 about y (S_ta,1,1)", "theta_R"),
    Coordinate("theta_a13", "angle", "leg 1, U at B1 about y (S_ta,1,3)", "theta_U"),
    Coordinate("theta_a14", "angle", "leg 1, U at B1 about x' (S_ta,1,4)", "theta_U"),
    Coordinate("theta_a21", "angle", "leg 2, U at A2 about y (S_ta,2,1)", "theta_U"),
    Coordinate("theta_a22", "angle", "leg 2, U at A2 about x' (S_ta,2,2)", "theta_U"),
    Coordinate("theta_a24", "angle", "leg 2, R at B2 about x' (S_ta,2,4)", "theta_R"),
    Coordinate("theta_a31", "angle", "leg 3, R at A3 about y (S_ta,3,1)", "theta_R"),
    Coordinate("theta_a33", "angle", "leg 3, U at B3 about y (S_ta,3,3)", "theta_U"),
    Coordinate("theta_a34", "angle", "leg 3, U at B3 about x' (S_ta,3,4)", "theta_U"),
)


def passive_names() -> list[str]:
    return [c.name for c in PASSIVE]


#: index of the actuated (P) joint among each leg's permitted twists (appendix)
ACTUATED = (1, 2, 1)
#: the passive joints of each leg among its permitted twists (eq 13)
PASSIVE_INDEX = ((0, 2, 3), (0, 1, 3), (0, 2, 3))

TWIST_ROWS = ("wx", "wy", "wz", "vx", "vy", "vz")
REFERENCES = ("o_prime", "o", "point")
CONVENTIONS = ("velocity", "eq45")

Y = ca.DM([0.0, 1.0, 0.0])
Z = ca.DM([0.0, 0.0, 1.0])


# -- geometry, eq 2-5 -----------------------------------------------------------------------------


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


def platform_points(r1, r2):
    """B_i' in the moving frame, eq 3."""
    return [ca.vertcat(r1, 0, 0), ca.vertcat(0, r2, 0), ca.vertcat(-r1, 0, 0)]


def base_points(r1, r2):
    """A_i in the fixed frame, eq 5."""
    return platform_points(r1, r2)


def joint_points(x, p):
    """(A_i, B_i) in the fixed frame for the pose x (eq 4-5)."""
    theta, alpha, P = x[0], x[1], x[2]
    r1, r2 = p[0], p[1]
    R = rotation(theta, alpha)
    o_ = origin(theta, P)
    B = [R @ b + o_ for b in platform_points(r1, r2)]  # eq 4
    return base_points(r1, r2), B


def _symbols():
    return ca.SX.sym("x", 3), ca.SX.sym("q", 3), ca.SX.sym("p", 3)


def loop_closure() -> ca.Function:
    """Φ(x, q; p) = |A_iB_i| - l_i (eq 6)."""
    x, q, p = _symbols()
    A, B = joint_points(x, p)
    phi = ca.vertcat(*[ca.norm_2(B[i] - A[i]) - q[i] for i in range(3)])
    return ca.Function("phi", [x, q, p], [phi], ["x", "q", "p"], ["phi"])


def inverse_kinematics() -> ca.Function:
    """Closed-form IK: l_i = |A_iB_i| (eq 6); reach = shortest leg."""
    t, p = ca.SX.sym("t", 3), ca.SX.sym("p", 3)
    A, B = joint_points(t, p)
    lengths = ca.vertcat(*[ca.norm_2(B[i] - A[i]) for i in range(3)])
    return ca.Function("ik", [t, p], [t, lengths, ca.mmin(lengths)], ["t", "p"], ["x", "q", "reach"])


def passive_angles(x, p):
    """The nine passive joint angles (order of :data:`PASSIVE`), zero at the
    initial pose.

    Legs 1 and 3 stay in the xz plane; the R joint turns the leg about y by
    atan2(u_x, u_z) (u = A_iB_i) and the U joint makes up the platform's
    Ry(θ) Rx(α): θ - that angle about y, then α about x'.  Leg 2 is turned by
    its U joint, Ry(a) Rx(b) z = u/|u|, and its R joint adds α - b about x'.
    """
    theta, alpha = x[0], x[1]
    A, B = joint_points(x, p)
    out = []
    for i in range(3):
        u = B[i] - A[i]
        if i == 1:
            a = ca.atan2(u[0], u[2])
            b = ca.atan2(-u[1], ca.sqrt(u[0] ** 2 + u[2] ** 2))
            out += [a, b, alpha - b]
        else:
            a = ca.atan2(u[0], u[2])
            out += [a, theta - a, alpha]
    return ca.vertcat(*out)


def passive_joints() -> ca.Function:
    x, q, p = _symbols()
    return ca.Function("passive", [x, q, p], [passive_angles(x, p)], ["x", "q", "p"], ["j"])


def branch_indicator() -> ca.Function:
    """g > 0 on the working assembly: P > 0 and every platform joint B_i above
    the base plane (the mirror assembly below the base solves eq 6 as well)."""
    x, q, p = _symbols()
    _A, B = joint_points(x, p)
    g = ca.vertcat(x[2], *[B[i][2] for i in range(3)])
    return ca.Function("branch", [x, q, p], [g], ["x", "q", "p"], ["g"])


def home(p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Initial pose: platforms parallel, P = P0, every leg P0 long."""
    P0 = float(p[2])
    return np.array([0.0, 0.0, P0]), np.full(3, P0)


def bounds(p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Box that keeps IPOPT on the working assembly: |θ|, |α| < 60°, 0 < P < 4 (P0 + r1 + r2)."""
    lim = math.pi / 3
    span = 4.0 * float(np.sum(p))
    return np.array([-lim, -lim, 0.0]), np.array([lim, lim, span])


def closure() -> LoopClosure:
    return LoopClosure(
        "rpr",
        x=X,
        q=Q,
        parameters=("r1", "r2", "P0"),
        phi=loop_closure(),
        task=TASK,
        ik=inverse_kinematics(),
        passive=passive_joints(),
        passive_coords=PASSIVE,
        branch=branch_indicator(),
        home=home,
        bounds=bounds,
    )


def build(closure_: LoopClosure, parameters: dict, limits: dict) -> Model:
    r1, r2, P0 = parameters["r1"], parameters["r2"], parameters["P0"]
    D = (r1 + r2 + P0) / 3.0  # eq 20
    return Model(
        closure_,
        parameters={"r1": r1, "r2": r2, "P0": P0},
        limits={k: v for k, v in limits.items() if v is not None},
        derived={"D": D},
        dimensions={"r1": "length", "r2": "length", "P0": "length", "D": "length"},
        characteristic_length=(r1 + r2) / 2.0,  # a tilt moves the leg joints by r1 dθ or r2 dα
    )


# -- screw theory, eq 7-13 and the appendix -------------------------------------------------------


def motion_screws(x, p, reference=None, convention: str = "velocity"):  # noqa: ARG001 - same (x, p) signature as the other screw functions
    """S_t (6 x 3): the platform twist is S_t (θ̇, α̇, Ṗ) (eq 7).

    reference: point (fixed frame) the linear rows refer to; default o'.
    convention: "velocity" -- the linear rows are the velocity of the body
    point at the reference (Plücker (s; (a - c) × s), as in the appendix);
    "eq45" -- the moment of each rotation is taken with the position vector
    from the axis point a to the reference c, (s; (c - a) × s), which is how
    the translational rows of eq 45 and 47 are printed (see the module notes).
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
    x, _q, p = _symbols()
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

    S_t: motion screw system (6 x 3, eq 7, derived columns);
    J_a, J_b: eq 9; J = J_b⁻¹ J_a (q̇ = J V, eq 10); G = J⁻¹ (V = G q̇, eq 11);
    G_p: passive joint rates per actuator rate (9 x 3, eq 12-13), rows in the
    order of :data:`PASSIVE`; branch_rates: J_i⁻¹ S_t G per leg (6 x 3, eq 12),
    whose constrained-twist rows must vanish.
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
    out = [np.asarray(v) for v in screw_function()(xv, model.p)]
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
    x, _q, p = _symbols()
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
    return np.asarray(twist_function()(np.asarray(x, dtype=float), model.p, reference, k))


@functools.lru_cache(maxsize=1)
def passive_jacobian() -> ca.Function:
    """``("passive_jacobian", [x, p], [dj_dx])``: d(passive angles)/dx (9 x 3) by
    AD; G_p = dj_dx G (eq 13)."""
    x, _q, p = _symbols()
    return ca.Function("passive_jacobian", [x, p], [ca.jacobian(passive_angles(x, p), x)], ["x", "p"], ["dj_dx"])


def geometry(model: Model, x, q) -> Drawing:  # noqa: ARG001 - q follows from x (|A_iB_i| = l_i)
    """The RPR at pose x = (theta, alpha, P): base joints A_i (eq 5), platform joints
    B_i (eq 4), the legs A_iB_i, and the frame origins o and o'."""
    p = np.array([float(model.parameters[k]) for k in ("r1", "r2", "P0")])
    x = np.asarray(x, dtype=float).ravel()
    A, B = joint_points(ca.DM(x), ca.DM(p))
    pts = {"o": np.zeros(3), "o'": np.asarray(origin(x[0], x[2]), dtype=float).ravel()}
    for i in range(3):
        pts[f"A{i + 1}"] = np.asarray(A[i], dtype=float).ravel()
        pts[f"B{i + 1}"] = np.asarray(B[i], dtype=float).ravel()
    return Drawing(
        points=pts,
        segments=tuple((f"A{i}", f"B{i}", "leg") for i in (1, 2, 3)) + (("o", "o'", "link"),),
        faces=(("base", ("A1", "A2", "A3")), ("platform", ("B1", "B2", "B3"))),
        joints={"A1": "R", "A2": "U", "A3": "R", "B1": "U", "B2": "R", "B3": "U"},
        note="legs 1 and 3 RPU, leg 2 UPR (prismatic legs A_iB_i); o-o' is P",
    )
