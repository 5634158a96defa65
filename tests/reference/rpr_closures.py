"""RPR compliant mechanism from a 2-RPU-UPR parallel mechanism (Zhang, Liu, Ding, Chin. J.
Mech. Eng. 2022; ``../shared/papers/rpr-2rpu-upr-zhang-2022.md``): the hand-written
closures, an independent reference for the tests.

The package's ``rpr`` is the mechanism file ``problems/mechanisms/rpr.yaml`` (its closures
generated from the legs, its passive joints and closed-form IK written in it) with the add-on
``cpm_nlp.mechanisms.rpr.addon`` (the paper's kinds, its synthesis formulation).  These
closures, derived by hand from the paper's eq 2-13, were the built-in module
``cpm_nlp.mechanisms.rpr.kinematics`` until issue 21 (item 5) wrote the mechanism once, in the
file; they stay here as the independent derivation the file is checked against
(``tests/mechanisms/rpr/test_rpr_written_once.py``, to 1e-12).  Not part of the package: import it from the
tests only.  The screw theory of eq 7-13 (an analysis, not the closures) is the add-on's
:mod:`cpm_nlp.mechanisms.rpr.screws`.

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
* The loop-closure residuals are |A_iB_i| - l_i (lengths, metres).
"""

from __future__ import annotations

import math

import casadi as ca
import numpy as np

from cpm_nlp.core.mechanism import Drawing, Mechanism
from cpm_nlp.core.model import Coordinate, LoopClosure, Model
from cpm_nlp.core.options import Option

from . import reference_model_of

#: the reference's name (the registered ``rpr`` is the file)
NAME = "rpr_reference"

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
        NAME,
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


MECHANISM = Mechanism(
    name=NAME,
    title="RPR compliant mechanism from a 2-RPU-UPR (Zhang, Liu, Ding)",
    paper=(
        "S. Zhang, J. Liu, H. Ding, Design and Analysis of a Novel Compliant Mechanism with RPR Degrees of Freedom, "
        "Chin. J. Mech. Eng. 35, 2022, doi:10.1186/s10033-022-00777-2"
    ),
    parameters=PARAMETERS,
    limits=LIMITS,
    closure=closure,
    build=build,
    geometry=geometry,
)

#: eq 26's initial design
PAPER = {"r1": "40 mm", "r2": "80 mm", "P0": "40 mm"}


def reference_model(parameters: dict | None = None, limits: dict | None = None) -> Model:
    """A model of the reference closures (parameters and limits as in a problem file; eq 26's
    by default), not registered: built from :data:`MECHANISM` directly."""
    return reference_model_of(MECHANISM, closure, PAPER if parameters is None else parameters, limits)
