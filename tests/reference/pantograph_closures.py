"""3D compliant pantograph (Elgammal, Fanni, Mohamed 2016;
``../shared/papers/pantograph-3d-elgammal-2016.md``): the hand-written closures, an
independent reference for the tests.

The package's ``pantograph`` is the mechanism file ``problems/mechanisms/pantograph.yaml``
(bodies and joints; its loops found from the graph) with the add-on
``cpm_nlp.mechanisms.pantograph.addon`` (the paper's limits, workspace, cuboid and synthesis).
These closures, derived by hand from eq 1-8, were the built-in module
``cpm_nlp.mechanisms.pantograph.kinematics`` until issue 21 (item 5) wrote the mechanism once,
in the file; they stay here as the independent derivation the file is checked against
(``tests/mechanisms/pantograph/test_pantograph_written_once.py``, to 1e-12).  Not part of the package: import it
from the tests only.  The paper's analyses (limits of eq 31, workspace, cuboid) are the
package's (``cpm_nlp.mechanisms.pantograph.analysis``): :func:`build` uses its eq 31.

Symbols follow the paper:

* a = AC = BC = DF, b = CD = BF = FE (section 3),
* q = (dx, dy, dz) -- actuators: dy, dz move point A, dx moves point B;
  OA = (0, dy, dz), OB = (dx, 0, 0) (Fig. 2, eq 1-8),
* x = (px, py, pz, theta1, theta2, phi) -- the end-effector E and the three
  passive coordinates of the loops: theta1 is the angle of the links AD and
  BF (CD ∥ BF), theta2 that of DE and BC (DF ∥ CB), both measured in the
  plane of the pantograph, which turns by phi about the y axis.  With
  u(θ) = (cos θ cos φ, sin θ, -cos θ sin φ) the loops read
  OE = OA + (a + b)(u1 + u2) (eq 1, 3-5) and OE = OB + b (u1 + u2) (eq 2, 6-8).
* psi -- the hinge angle ACB at C (eq 17).  Subtracting the loops gives
  AB = a (u1 + u2), so |AB|² = 2a²(1 + cos(θ1 - θ2)) = 2a²(1 - cos ψ) with
  **ψ = π - (θ1 - θ2)** on the designated branch (θ1 > θ2).

Readings of the paper chosen here (documented, not tuned):

* **Home configuration**: the flexures are undeflected at ψ = π/2, φ = 0
  (eq 31 puts ψ_min, ψ_max symmetric about π/2; section 8: "the
  configuration corresponding to the middle of the input displacement
  ranges has zero deflection"): θ1 = π/4, θ2 = -π/4, dx0 = √2 a, dy = dz = 0
  (the prototype's dx range 28.234 ... 28.334 mm is centred on √2 · 20 mm).
* **Branch**: the elbow with θ1 > θ2 (point C on the +y side of AB at home;
  the mirror elbow has the mirrored, identical workspace).  The singularity
  of section 5 (eq 25-29, θ_i = ±π/2, "main pantograph links aligned with
  the guiding mechanism") belongs to the guiding parallelograms, which eq
  1-8 do not contain (Φ_x is regular there: det Φ_x ∝ (cos θ1 + cos θ2)
  sin(θ2 - θ1)).  It enters as the branch condition cos θ_i > 0; with it,
  sin(θ1 - θ2) > 0 and cos φ > 0 the indicator is positive exactly inside
  the region bounded by eq 24-29 (proof in :func:`paper_membership`).
* **Magnification factors** Mx, My, Mz are read off the AD Jacobian of the
  loops at the home configuration (Model.derived), not typed in; the
  closed form Mx = 1 + b/a, My = Mz = b/a (eq 9-10) is used only by the
  closed-form IK and in tests, which check the two against each other.
* **Joint limits** are those of the paper: ψ ∈ [ψ_min, ψ_max] for the hinges
  with horizontal axes and |φ| <= φ_max for those with vertical axes
  (section 5.2), given directly or from the hinge by eq 31:
  ψ = π/2 ∓ δ_max, φ_max = δ_max with δ_max of the flexure (eq 30 or 38).
  The hinges at A and B also turn, by θ1 - π/4 and θ2 + π/4 (at the edges of
  the paper's cuboid by more than three times φ_max); the paper puts no
  limit on them (an optional ``theta`` limit on these rotations adds one).
* **Eq 31 discrepancy**: with l = 5 mm, t = 0.1 mm, E = 2 GPa, σ_all = 23.5
  MPa eq 30-31 give δ_max = 0.148·5·23.5e6/(2e9·0.1) = 0.0870 rad, while the
  paper prints φ_max = 0.0795 rad and ψ = 1.49/1.65 rad (= π/2 ∓ 0.08).  The
  printed limits are the ones its cuboid (V = 1.78e-6 m³) is computed with;
  problems/pantograph_cuboid_hinge.yaml shows both.
* **Eq 34c** as printed, ẑ <= a Mz x̂ tan φ_max / Mx, is not a length (a·x̂) and
  bounds ẑ at the far face x̂; the cuboid's corners on its near face px = k
  then leave the φ planes (eq 18: |pz| <= (Mz/Mx) px tan φ_max).  The paper's
  own optimum (ẑ = 0.0054 m) satisfies the bound at the near face,
  ẑ <= (Mz/Mx) k tan φ_max, which is also what membership requires.  See
  :func:`paper_cuboid` (``reading``).
"""

from __future__ import annotations

import math

import casadi as ca
import numpy as np

from cpm_nlp.analysis import hinge_types
from cpm_nlp.core.mechanism import Drawing, Mechanism
from cpm_nlp.core.model import Coordinate, LoopClosure, Model
from cpm_nlp.core.options import Option
from cpm_nlp.mechanisms.pantograph.analysis import check_limits, joint_limits

from . import reference_model_of

HALF_PI = math.pi / 2
SQRT2 = math.sqrt(2.0)

PARAMETERS = (
    Option("a", "length", "link length AC = BC = DF (section 3)", lower=0.0, upper=10.0, strict=True),
    Option("b", "length", "link length CD = BF = FE (section 3)", lower=0.0, upper=10.0, strict=True),
)

LIMITS = (
    Option("psi_min", "angle", "lowest hinge angle ACB (eq 17, 24)", default=None, lower=0.0, upper=math.pi),
    Option("psi_max", "angle", "highest hinge angle ACB (eq 17, 23)", default=None, lower=0.0, upper=math.pi),
    Option(
        "phi_max",
        "angle",
        "largest rotation |phi| of the vertical-axis hinges (eq 18)",
        default=None,
        lower=0.0,
        upper=HALF_PI,
        strict=True,
    ),
    Option(
        "theta",
        "angle",
        "range [low, high] of the rotations theta1 - pi/4 and theta2 + pi/4 of the hinges at A and B from home "
        "(not limited in the paper)",
        default=None,
        shape="range",
    ),
    Option(
        "stroke",
        "length",
        "actuator range [low, high] about the home configuration (dx0 = sqrt(2) a, dy0 = dz0 = 0), for each actuator",
        default=None,
        shape="range",
    ),
) + hinge_types.HINGE_LIMIT_OPTIONS

X = (
    Coordinate("px", "length", "end-effector E, x (eq 3, 6)"),
    Coordinate("py", "length", "end-effector E, y (eq 4, 7)"),
    Coordinate("pz", "length", "end-effector E, z (eq 5, 8)"),
    Coordinate("theta1", "angle", "angle of links AD and BF in the pantograph plane (eq 3-8)", "theta"),
    Coordinate("theta2", "angle", "angle of links DE and BC in the pantograph plane (eq 3-8)", "theta"),
    Coordinate("phi", "angle", "rotation of the pantograph plane about y (eq 18)"),
)
Q = (
    Coordinate("dx", "length", "actuator at B along x (eq 6)", "stroke"),
    Coordinate("dy", "length", "actuator at A along y (eq 4)", "stroke"),
    Coordinate("dz", "length", "actuator at A along z (eq 5)", "stroke"),
)
TASK = ("px", "py", "pz")
PASSIVE = (Coordinate("psi", "angle", "hinge angle ACB at C, psi = pi - (theta1 - theta2) (eq 17)"),)


def _u(theta, phi):
    """Unit vector of a pantograph link at angle theta in the plane turned by phi."""
    return ca.vertcat(ca.cos(theta) * ca.cos(phi), ca.sin(theta), -ca.cos(theta) * ca.sin(phi))


def loop_closure() -> ca.Function:
    """Φ(x, q; p): eq 3-5 (loop 1, OE = OA + AD + DE) and eq 6-8 (loop 2, OE = OB + BF + FE)."""
    x = ca.SX.sym("x", 6)
    q = ca.SX.sym("q", 3)
    p = ca.SX.sym("p", 2)
    a, b = p[0], p[1]
    P = x[0:3]
    w = _u(x[3], x[5]) + _u(x[4], x[5])  # (cos θ1 + cos θ2) cos φ, sin θ1 + sin θ2, -(...) sin φ
    OA = ca.vertcat(0, q[1], q[2])
    OB = ca.vertcat(q[0], 0, 0)
    loop1 = OA + (a + b) * w - P  # eq 3-5
    loop2 = OB + b * w - P  # eq 6-8
    return ca.Function("phi", [x, q, p], [ca.vertcat(loop1, loop2)], ["x", "q", "p"], ["phi"])


def magnification(a, b):
    """Closed form Mx = 1 + b/a, My = Mz = b/a (eq 9-10)."""
    return 1 + b / a, b / a, b / a


def inverse_kinematics() -> ca.Function:
    """Closed-form IK: q by eq 9-10, then φ by eq 18, θ1, θ2 from AB = a(u1 + u2).

    With AB = (dx, -dy, -dz): the mean angle m = (θ1 + θ2)/2 = atan2(-dy, sqrt(dx² + dz²)),
    the half difference h = (θ1 - θ2)/2 = acos(|AB| / 2a) (eq 17 with ψ = π - 2h);
    reach = 2a - |AB| < 0 when A and B are further apart than the links allow.
    """
    t = ca.SX.sym("t", 3)
    p = ca.SX.sym("p", 2)
    a, b = p[0], p[1]
    Mx, My, Mz = magnification(a, b)
    dx, dy, dz = t[0] / Mx, -t[1] / My, -t[2] / Mz  # eq 9-10
    phi = ca.atan2(dz, dx)  # eq 18
    rho = ca.sqrt(dx**2 + dz**2)
    n = ca.sqrt(dx**2 + dy**2 + dz**2)
    m = ca.atan2(-dy, rho)
    h = ca.acos(ca.fmin(n / (2 * a), 1))
    x = ca.vertcat(t[0], t[1], t[2], m + h, m - h, phi)
    return ca.Function("ik", [t, p], [x, ca.vertcat(dx, dy, dz), 2 * a - n], ["t", "p"], ["x", "q", "reach"])


def passive_joints() -> ca.Function:
    """ψ = π - (θ1 - θ2), the hinge angle ACB (eq 17) on the designated branch."""
    x = ca.SX.sym("x", 6)
    q = ca.SX.sym("q", 3)
    p = ca.SX.sym("p", 2)
    return ca.Function("passive", [x, q, p], [math.pi - (x[3] - x[4])], ["x", "q", "p"], ["j"])


def branch_indicator() -> ca.Function:
    """g > 0 on the designated branch: cos θ1, cos θ2 (away from the guiding-mechanism
    singularity, eq 25-29), sin(θ1 - θ2) (the elbow, 0 < ψ < π), cos φ."""
    x = ca.SX.sym("x", 6)
    q = ca.SX.sym("q", 3)
    p = ca.SX.sym("p", 2)
    g = ca.vertcat(ca.cos(x[3]), ca.cos(x[4]), ca.sin(x[3] - x[4]), ca.cos(x[5]))
    return ca.Function("branch", [x, q, p], [g], ["x", "q", "p"], ["g"])


def home_pose(a, b):
    """Home: ψ = π/2, φ = 0 (θ1 = π/4, θ2 = -π/4); dx0 = √2 a; E at ((a + b)√2, 0, 0).
    Works on floats and CasADi symbols."""
    x0 = [(a + b) * SQRT2, 0.0, 0.0, math.pi / 4, -math.pi / 4, 0.0]
    q0 = [SQRT2 * a, 0.0, 0.0]
    return x0, q0


def home(p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    x0, q0 = home_pose(float(p[0]), float(p[1]))
    return np.array(x0), np.array(q0)


def bounds(p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Box that keeps IPOPT on the working branch: |θ_i|, |φ| <= π/2, E within 2(a + b)."""
    a, b = float(p[0]), float(p[1])
    r = 2 * (a + b)
    return (
        np.array([-r, -r, -r, -HALF_PI, -HALF_PI, -HALF_PI]),
        np.array([r, r, r, HALF_PI, HALF_PI, HALF_PI]),
    )


def closure() -> LoopClosure:
    """The symbolic pantograph (built fresh; the registry caches one per process)."""
    return LoopClosure(
        "pantograph",
        x=X,
        q=Q,
        parameters=("a", "b"),
        phi=loop_closure(),
        task=TASK,
        ik=inverse_kinematics(),
        passive=passive_joints(),
        passive_coords=PASSIVE,
        branch=branch_indicator(),
        home=home,
        bounds=bounds,
    )


# -- the model (the limits of eq 31 are the package's, cpm_nlp.mechanisms.pantograph.analysis) --

_DIRECT = ("psi_min", "psi_max", "phi_max")


def build(closure_: LoopClosure, parameters: dict, limits: dict) -> Model:
    """A pantograph model from validated parameters (SI) and limits."""
    a, b = parameters["a"], parameters["b"]
    angles = joint_limits(limits)
    lim: dict[str, tuple[float, float]] = {}
    if angles["psi_min"] is not None or angles["psi_max"] is not None:
        lim["psi"] = (
            angles["psi_min"] if angles["psi_min"] is not None else 0.0,
            angles["psi_max"] if angles["psi_max"] is not None else math.pi,
        )
    if angles["phi_max"] is not None:
        lim["phi"] = (-angles["phi_max"], angles["phi_max"])
    x0, q0 = home_pose(a, b)
    if limits.get("theta") is not None:
        lo, hi = limits["theta"]
        lim["theta1"] = (x0[3] + lo, x0[3] + hi)
        lim["theta2"] = (x0[4] + lo, x0[4] + hi)
    if limits.get("stroke") is not None:
        lo, hi = limits["stroke"]
        for name, centre in zip(("dx", "dy", "dz"), q0):
            lim[name] = (centre + lo, centre + hi)
    # magnification factors from the AD Jacobian of the loops at home (eq 9-13)
    J = np.asarray(closure_.jacobian(x0, q0, [a, b]))
    Mx, My, Mz = float(J[0, 0]), float(-J[1, 1]), float(-J[2, 2])
    derived = {
        "Mx": Mx,
        "My": My,
        "Mz": Mz,
        "omega": abs(float(np.linalg.det(J[:3, :]))),  # eq 15-16
        "dx0": q0[0],
        "psi_min": angles["psi_min"],
        "psi_max": angles["psi_max"],
        "phi_max": angles["phi_max"],
    }
    if angles["delta_max"] is not None:
        derived["delta_max"] = angles["delta_max"]
        derived.update({k: limits[k] for k in ("l", "t", "r") if limits.get(k) is not None})  # the hinge
    dims = {
        "a": "length",
        "b": "length",
        "dx0": "length",
        "delta_max": "angle",
        "l": "length",
        "t": "length",
        "r": "length",
    }
    dims.update({k: "dimensionless" for k in ("Mx", "My", "Mz", "omega")})
    dims.update({k: "angle" for k in _DIRECT})
    return Model(
        closure_,
        parameters={"a": a, "b": b},
        limits=lim,
        derived=derived,
        dimensions=dims,
    )


def geometry(model: Model, x, q) -> Drawing:
    """The pantograph at pose x, actuators q (Fig. 2, eq 1-8): inputs A = (0, dy, dz)
    and B = (dx, 0, 0), links A-C-D and D-F-E of length a + b at angles theta1 and
    theta2 (C = A + a u1, D = A + (a + b) u1, F = D + a u2, E = D + (a + b) u2), the
    links BC (parallel to DE) and BF (parallel to CD).  The guiding parallelograms
    that hold the plane at phi are not drawn."""
    a = float(model.parameters["a"])
    b = float(model.parameters["b"])
    x = np.asarray(x, dtype=float).ravel()
    q = np.asarray(q, dtype=float).ravel()
    u1 = np.asarray(_u(x[3], x[5]), dtype=float).ravel()
    u2 = np.asarray(_u(x[4], x[5]), dtype=float).ravel()
    A = np.array([0.0, q[1], q[2]])
    B = np.array([q[0], 0.0, 0.0])
    D = A + (a + b) * u1
    pts = {
        "O": np.zeros(3),
        "A": A,
        "B": B,
        "C": A + a * u1,
        "D": D,
        "F": D + a * u2,
        "E": D + (a + b) * u2,
    }
    return Drawing(
        points=pts,
        segments=(
            ("O", "A", "actuator"),
            ("O", "B", "actuator"),
            ("A", "C", "link"),
            ("C", "D", "link"),
            ("D", "F", "link"),
            ("F", "E", "leg"),
            ("B", "C", "link"),
            ("B", "F", "link"),
        ),
        joints={"A": "R", "B": "R", "C": "R", "D": "R", "F": "R"},
        note="actuators move A in y, z and B in x (from O); E is the end-effector; guiding mechanism not drawn",
    )


#: the paper's a = 20 mm, b = 50 mm (section 5)
PAPER = {"a": "20 mm", "b": "50 mm"}

MECHANISM = Mechanism(
    name="pantograph",
    title="3D compliant pantograph, decoupled XYZ (Elgammal et al.)",
    paper=(
        "A. T. Elgammal, M. Fanni, A. M. Mohamed, Design and Analysis of a Novel 3D Decoupled Manipulator Based on "
        "Compliant Pantograph for Micromanipulation, J. Intell. Robot. Syst., 2016 (published online 29 Dec 2016)"
    ),
    parameters=PARAMETERS,
    limits=LIMITS,
    closure=closure,
    build=build,
    check_limits=check_limits,
    geometry=geometry,
)


def reference_model(parameters: dict | None = None, limits: dict | None = None) -> Model:
    """A model of the reference closures (parameters and limits as in a problem file; the
    paper's a, b by default), not registered: built from :data:`MECHANISM` directly."""
    return reference_model_of(MECHANISM, closure, PAPER if parameters is None else parameters, limits)
