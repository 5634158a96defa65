"""3-PRS compliant parallel stage (Ruiz, Campa, Roldán-Paraponiaris, Altuzarra,
Pinto; ``../shared/papers/prs3-ruiz.md``): the hand-written closures, an independent
reference for the tests.

The package's ``prs3`` is the mechanism file ``problems/mechanisms/prs3.yaml`` (its
closures generated from the legs).  These closures, derived by hand from the paper's
equations, were the built-in module ``cpm_nlp.mechanisms.prs3`` until issue 21 (item 5)
wrote the mechanism once, in the file; they stay here as the independent derivation the
file is checked against (``tests/mechanisms/prs3/test_prs3_written_once.py``, to 1e-12).  Not part of the
package: import it from the tests only.

Symbols follow the paper:

* a -- radius of the circle of the actuator zero positions A_i (eq 2),
* b -- radius of the circle of the spherical joints B_i on the platform (eq 3),
* L -- leg length C_iB_i,
* alpha0 -- angle between the legs and the horizontal at the home pose
  (45 deg in the paper), so that the revolute angles alpha_i (eq 22) equal
  alpha0 when s = 0,
* x = (px, py, pz, psi, theta, phi) -- platform pose, R = Ry(θ)Rx(ψ)Rz(φ) (eq 4),
* q = (s1, s2, s3) -- actuator displacements, positive towards the axis
  (s_i0 = -OA_i/|OA_i|, eq 18).

Reading of the paper chosen here (documented, not tuned):

* The paper gives b, L and alpha0 but never a.  At the home pose (s = 0, the
  platform level at the centre) the leg C_1B_1 runs from (a, 0, 0) to
  (b, 0, pz0); its angle with the slider direction is alpha0 (eq 22), so
  **a = b + L cos(alpha0)** and **pz0 = L sin(alpha0)**.  With the paper's
  b = 47.91 mm, L = 109.215 mm, alpha0 = 45°: a = 125.137 mm, pz0 = 77.227 mm.
* IK (eq 20) has two roots; the model takes the minus root, the one that gives
  s = 0 at the home pose.  On it the leg leans towards the axis
  (l_i0 · s_i0 > 0) and rises from slider to platform (l_i0 · z > 0): that is
  the assembly branch every FK solution is checked against.
* Eq 33 is written with atan; atan2 is used (identical for the small rotations
  of the paper, and quadrant-correct beyond them).
* The loop-closure residuals are scaled to lengths: eq 35 as
  (|B_i - C_i|² - L²)/(2L) and eq 7-9 as the distance of B_i from its leg
  plane, so one tolerance in metres applies to all six.
"""

from __future__ import annotations

import math

import casadi as ca
import numpy as np

from cpm_nlp.analysis.compliance import JointStiffness
from cpm_nlp.core.aspect import ASPECT, ASPECT_DESCRIPTION, aspect
from cpm_nlp.core.mechanism import Drawing, Mechanism
from cpm_nlp.core.model import Coordinate, LoopClosure, Model
from cpm_nlp.core.options import Option

from . import reference_model_of

SQRT3 = math.sqrt(3.0)
#: angular positions of the legs, eq 2-3
GAMMA = (0.0, 2.0 * math.pi / 3.0, 4.0 * math.pi / 3.0)


PARAMETERS = (
    Option(
        "b", "length", "radius of the spherical-joint circle on the platform (eq 3)", lower=0.0, upper=1.0, strict=True
    ),
    Option("L", "length", "leg length C_iB_i (eq 17)", lower=0.0, upper=1.0, strict=True),
    Option(
        "alpha0",
        "angle",
        "leg angle to the horizontal at the home pose (eq 22; 45 deg in the paper)",
        default=math.pi / 4,
        lower=0.0,
        upper=math.pi / 2,
        strict=True,
    ),
)

LIMITS = (
    Option("s", "length", "actuator stroke [low, high] of every s_i", default=None, shape="range"),
    Option(
        "alpha",
        "angle",
        "revolute angle range [low, high] of every alpha_i (eq 22, absolute)",
        default=None,
        shape="range",
    ),
    Option("beta_m", "angle", "spherical-joint bending range of every beta_mi (eq 33)", default=None, shape="range"),
    Option("beta_n", "angle", "spherical-joint bending range of every beta_ni (eq 33)", default=None, shape="range"),
    Option("beta_l", "angle", "spherical-joint torsion range of every beta_li (eq 33)", default=None, shape="range"),
)

X = (
    Coordinate("px", "length", "platform centre P, x (parasitic, eq 14)"),
    Coordinate("py", "length", "platform centre P, y (parasitic, eq 15)"),
    Coordinate("pz", "length", "platform centre P, z (height above the actuator plane)"),
    Coordinate("psi", "angle", "rotation about x (eq 4)"),
    Coordinate("theta", "angle", "rotation about y (eq 4)"),
    Coordinate("phi", "angle", "rotation about z (parasitic, eq 13)"),
)
Q = tuple(Coordinate(f"s{i}", "length", f"actuator {i} displacement towards the axis (eq 18)", "s") for i in (1, 2, 3))
TASK = ("pz", "psi", "theta")
PASSIVE = (
    tuple(
        Coordinate(f"alpha{i}", "angle", f"revolute joint {i}, leg-to-slider angle (eq 22)", "alpha") for i in (1, 2, 3)
    )
    + tuple(
        Coordinate(f"beta_m{i}", "angle", f"spherical joint {i}, rotation about m (eq 33)", "beta_m") for i in (1, 2, 3)
    )
    + tuple(
        Coordinate(f"beta_n{i}", "angle", f"spherical joint {i}, rotation about n (eq 33)", "beta_n") for i in (1, 2, 3)
    )
    + tuple(
        Coordinate(f"beta_l{i}", "angle", f"spherical joint {i}, torsion about l (eq 33)", "beta_l") for i in (1, 2, 3)
    )
)


def actuator_radius(b, L, alpha0):
    """a = b + L cos(alpha0): the home pose has alpha_i = alpha0 at s = 0 (eq 22)."""
    return b + L * ca.cos(alpha0) if isinstance(b, (ca.SX, ca.MX)) else b + L * math.cos(alpha0)


def Rx(t):
    return ca.vertcat(ca.horzcat(1, 0, 0), ca.horzcat(0, ca.cos(t), -ca.sin(t)), ca.horzcat(0, ca.sin(t), ca.cos(t)))


def Ry(t):
    return ca.vertcat(ca.horzcat(ca.cos(t), 0, ca.sin(t)), ca.horzcat(0, 1, 0), ca.horzcat(-ca.sin(t), 0, ca.cos(t)))


def Rz(t):
    return ca.vertcat(ca.horzcat(ca.cos(t), -ca.sin(t), 0), ca.horzcat(ca.sin(t), ca.cos(t), 0), ca.horzcat(0, 0, 1))


def rotation(psi, theta, phi):
    """R = Ry(θ) Rx(ψ) Rz(φ), eq 4."""
    return Ry(theta) @ Rx(psi) @ Rz(phi)


def _radial(i):
    g = GAMMA[i]
    return ca.DM([math.cos(g), math.sin(g), 0.0])


def OA(i, a):
    """Actuator zero position A_i, eq 2."""
    return a * _radial(i)


def PB_m(i, b):
    """Spherical joint B_i in the moving frame, eq 3."""
    return b * _radial(i)


def s0(i):
    """Unit direction of positive actuator motion, s_i0 = -OA_i/|OA_i|, eq 18."""
    return -_radial(i)


def m0(i):
    """Revolute axis of leg i, normal to its leg plane, eq 25."""
    g = GAMMA[i]
    return ca.DM([math.sin(g), -math.cos(g), 0.0])


def OB(i, P, R, b):
    """OB_i = OP + R PB_im, eq 5-6."""
    return P + R @ PB_m(i, b)


def OC(i, s_i, a):
    """OC_i = OA_i + s_i s_i0, eq A.2, A.6, A.10."""
    return OA(i, a) + s_i * s0(i)


def parasitic(psi, theta, b):
    """(phi, px, py) as functions of the tilts, eq 13-15."""
    phi = ca.atan(ca.sin(psi) * ca.sin(theta) / (ca.cos(psi) + ca.cos(theta)))  # eq 13
    px = (
        b / 2 * (ca.cos(theta) * ca.cos(phi) + ca.sin(psi) * ca.sin(theta) * ca.sin(phi) - ca.cos(psi) * ca.cos(phi))
    )  # eq 14
    py = -b * ca.cos(psi) * ca.sin(phi)  # eq 15
    return phi, px, py


def _symbols():
    x = ca.SX.sym("x", 6)
    q = ca.SX.sym("q", 3)
    p = ca.SX.sym("p", 3)
    b, L, alpha0 = p[0], p[1], p[2]
    return x, q, p, b, L, alpha0, actuator_radius(b, L, alpha0)


def loop_closure() -> ca.Function:
    """Φ(x, q; p): leg lengths (eq 35, A.4/A.8/A.12) and leg planes (eq 7-9)."""
    x, q, p, b, L, _alpha0, a = _symbols()
    P = x[0:3]
    R = rotation(x[3], x[4], x[5])
    B = [OB(i, P, R, b) for i in range(3)]
    legs = []
    for i in range(3):
        d = B[i] - OC(i, q[i], a)
        legs.append((ca.dot(d, d) - L**2) / (2 * L))  # eq 35, scaled to a length
    planes = [
        B[0][1],  # eq 7: OB_1y = 0
        (B[1][1] + SQRT3 * B[1][0]) / 2,  # eq 8: OB_2y = -sqrt(3) OB_2x
        (B[2][1] - SQRT3 * B[2][0]) / 2,  # eq 9: OB_3y = sqrt(3) OB_3x
    ]
    return ca.Function("phi", [x, q, p], [ca.vertcat(*legs, *planes)], ["x", "q", "p"], ["phi"])


def inverse_kinematics() -> ca.Function:
    """Closed-form IK: t = (pz, psi, theta) -> x (eq 13-15), q (eq 20, minus root)."""
    t = ca.SX.sym("t", 3)
    p = ca.SX.sym("p", 3)
    b, L, alpha0 = p[0], p[1], p[2]
    a = actuator_radius(b, L, alpha0)
    pz, psi, theta = t[0], t[1], t[2]
    phi, px, py = parasitic(psi, theta, b)
    P = ca.vertcat(px, py, pz)
    R = rotation(psi, theta, phi)
    s, disc = [], []
    for i in range(3):
        AB = OB(i, P, R, b) - OA(i, a)  # eq 16
        k = ca.dot(s0(i), AB)
        d = k**2 - ca.dot(AB, AB) + L**2
        disc.append(d / (2 * L))
        s.append(k - ca.sqrt(ca.fmax(d, 0)))  # eq 20, the root with s = 0 at home
    x = ca.vertcat(px, py, pz, psi, theta, phi)
    reach = ca.mmin(ca.vertcat(*disc))
    return ca.Function("ik", [t, p], [x, ca.vertcat(*s), reach], ["t", "p"], ["x", "q", "reach"])


def _leg_frames(i, x, q, p):
    b, L, alpha0 = p[0], p[1], p[2]
    a = actuator_radius(b, L, alpha0)
    P = x[0:3]
    R = rotation(x[3], x[4], x[5])
    l0 = (OB(i, P, R, b) - OC(i, q[i], a)) / L  # eq 21
    return R, l0, alpha0


def passive_joints() -> ca.Function:
    """Revolute alpha_i (eq 22) and spherical beta_mi, beta_ni, beta_li (eq 23-33)."""
    x = ca.SX.sym("x", 6)
    q = ca.SX.sym("q", 3)
    p = ca.SX.sym("p", 3)
    alpha, bm, bn, bl = [], [], [], []
    for i in range(3):
        R, l0, alpha0 = _leg_frames(i, x, q, p)
        alpha.append(ca.acos(ca.dot(l0, s0(i)) / ca.norm_2(l0)))  # eq 22 (|s_i0| = 1)
        m_i0 = m0(i)
        n_i0 = ca.cross(l0, m_i0)  # eq 26
        R_R = ca.horzcat(m_i0, n_i0, l0)  # eq 27
        g = GAMMA[i]
        m_im = m_i0  # eq 28-30, m column
        n_im = ca.vertcat(ca.sin(alpha0) * math.cos(g), ca.sin(alpha0) * math.sin(g), ca.cos(alpha0))
        l_im = ca.vertcat(-ca.cos(alpha0) * math.cos(g), -ca.cos(alpha0) * math.sin(g), ca.sin(alpha0))
        R_im = ca.horzcat(m_im, n_im, l_im)  # eq 31
        R_S = R_R.T @ R @ R_im  # eq 24
        bm.append(ca.atan2(-R_S[1, 2], R_S[2, 2]))  # eq 33
        bn.append(ca.asin(R_S[0, 2]))
        bl.append(ca.atan2(-R_S[0, 1], R_S[0, 0]))
    j = ca.vertcat(*alpha, *bm, *bn, *bl)
    return ca.Function("passive", [x, q, p], [j], ["x", "q", "p"], ["j"])


def branch_indicator() -> ca.Function:
    """g > 0 on the designated branch: l_i0·s_i0 > 0 and l_i0·z > 0 for every leg
    (:data:`BRANCH_NAMES`), and the aspect of the home pose (det Φ_x per platform
    twist has its sign at home, :mod:`cpm_nlp.core.aspect`): with a leg folded
    down (alpha_i ~ 10 deg) and the platform tilted ~45 deg, the legs keep
    their signs and only the aspect tells that assembly mode from the working one."""
    x = ca.SX.sym("x", 6)
    q = ca.SX.sym("q", 3)
    p = ca.SX.sym("p", 3)
    g = []
    for i in range(3):
        _R, l0, _ = _leg_frames(i, x, q, p)
        g += [ca.dot(l0, s0(i)), l0[2]]
    R = rotation(x[3], x[4], x[5])
    x_home = ca.vertcat(0, 0, p[1] * ca.sin(p[2]), 0, 0, 0)
    g.append(aspect(loop_closure()(x, q, p), x, q, R, x_home, ca.SX.zeros(3)))
    return ca.Function("branch", [x, q, p], [ca.vertcat(*g)], ["x", "q", "p"], ["g"])


#: the names of the branch indicators, and what each measures
BRANCH_NAMES = tuple(n for i in (1, 2, 3) for n in (f"leg{i}.inward", f"leg{i}.rising")) + (ASPECT,)
BRANCH_DESCRIPTIONS = tuple(
    d
    for i in (1, 2, 3)
    for d in (
        f"leg {i}, R joint at C{i}: l{i}0 . s{i}0, the leg leans towards the axis (eq 20's minus root)",
        f"leg {i}, R joint at C{i}: l{i}0 . z, the leg rises from the slider to the platform",
    )
) + (ASPECT_DESCRIPTION,)


def frame() -> ca.Function:
    """The platform's rotation matrix (eq 4) and position."""
    x = ca.SX.sym("x", 6)
    p = ca.SX.sym("p", 3)
    return ca.Function("frame", [x, p], [rotation(x[3], x[4], x[5]), x[0:3]], ["x", "p"], ["R", "position"])


def home(p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Home pose: platform level, centred at pz0 = L sin(alpha0); s = 0."""
    _b, L, alpha0 = p
    return np.array([0.0, 0.0, L * math.sin(alpha0), 0.0, 0.0, 0.0]), np.zeros(3)


def bounds(p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Box that keeps IPOPT on the working branch: platform above the actuator
    plane, |px|, |py| <= L and tilts below 60 deg."""
    _b, L, _alpha0 = p
    lim = math.pi / 3
    return (np.array([-L, -L, 0.0, -lim, -lim, -lim]), np.array([L, L, 2 * L, lim, lim, lim]))


#: the name the reference registers under (the package's ``prs3`` is the file)
NAME = "prs3_reference"


def closure() -> LoopClosure:
    """The symbolic 3-PRS (built fresh)."""
    return LoopClosure(
        NAME,
        x=X,
        q=Q,
        parameters=("b", "L", "alpha0"),
        phi=loop_closure(),
        task=TASK,
        ik=inverse_kinematics(),
        passive=passive_joints(),
        passive_coords=PASSIVE,
        branch=branch_indicator(),
        branch_names=BRANCH_NAMES,
        branch_descriptions=BRANCH_DESCRIPTIONS,
        frame=frame(),
        offsets={"dz": "pz"},
        home=home,
        bounds=bounds,
    )


def build(closure_: LoopClosure, parameters: dict, limits: dict) -> Model:
    """A 3-PRS model from validated parameters (SI) and limits."""
    a = actuator_radius(parameters["b"], parameters["L"], parameters["alpha0"])
    return Model(
        closure_,
        parameters={k: parameters[k] for k in ("b", "L", "alpha0")},
        limits={k: v for k, v in limits.items() if v is not None},
        derived={"a": a, "pz0": parameters["L"] * math.sin(parameters["alpha0"])},
        dimensions={"b": "length", "L": "length", "alpha0": "angle", "a": "length", "pz0": "length"},
        characteristic_length=parameters["b"],  # a tilt dθ moves the joints B_i by about b dθ
    )


def geometry(model: Model, x, q) -> Drawing:
    """The 3-PRS at pose x, actuators q: actuator zero positions A_i (eq 2), sliders
    C_i (eq A.2) on their rails, legs C_iB_i and the platform B_1B_2B_3 (eq 5-6)."""
    b, L, alpha0 = (float(model.parameters[k]) for k in ("b", "L", "alpha0"))
    a = actuator_radius(b, L, alpha0)
    x = np.asarray(x, dtype=float).ravel()
    R = rotation(x[3], x[4], x[5])
    P = ca.DM(x[0:3])
    pts = {"P": x[0:3]}
    for i in range(3):
        pts[f"A{i + 1}"] = np.asarray(OA(i, a)).ravel()
        pts[f"C{i + 1}"] = np.asarray(OC(i, float(q[i]), a)).ravel()
        pts[f"B{i + 1}"] = np.asarray(OB(i, P, R, b)).ravel()
    return Drawing(
        points=pts,
        segments=tuple((f"A{i}", f"C{i}", "actuator") for i in (1, 2, 3))
        + tuple((f"C{i}", f"B{i}", "leg") for i in (1, 2, 3)),
        faces=(("base", ("A1", "A2", "A3")), ("platform", ("B1", "B2", "B3"))),
        joints={**{f"C{i}": "R" for i in (1, 2, 3)}, **{f"B{i}": "S" for i in (1, 2, 3)}},
        note="sliders C_i move on rails from A_i towards the axis (P joints); R at C_i, S at B_i",
    )


#: The flexure joints of section 5: the stiffnesses the paper measured on its FEM
#: models of the joints, the hinge geometry, and the material of section 4.
#: Readings (documented, not tuned): the revolute hinge is a circular notch of
#: radius R_rev and thinnest section t_rev across the 10 mm wide leg; the spherical
#: joint is a round neck of diameter t_sph and straight length l_sph with circular
#: fillets of radius R_sph at both ends (its K_Rsph/K_Tsph = 1.336 is a round section's
#: 1 + nu; the filleted neck's formula gives 34.9 and 26.2 N*m/rad against the printed
#: 32.67 and 24.46: the reproduce rows of prs3_fem_table2.yaml); K_Rsph applies to both
#: bending axes (beta_m, beta_n), K_Tsph to the torsion beta_l.
STIFFNESS = JointStiffness(
    hinges={
        "revolute": {
            "joints": "alpha",
            "type": "circular_notch_paros_weisbord",
            "t": "2 mm",
            "r": "8 mm",
            "w": "10 mm",
            "k": "98.37 N*m/rad",
        },
        "spherical": {
            "joints": {"bend": "beta_m", "bend2": "beta_n", "torsion": "beta_l"},
            "type": "filleted_rod",
            "d": "3 mm",
            "l": "5 mm",
            "r": "4 mm",
            "k": {"bend": "32.67 N*m/rad", "bend2": "32.67 N*m/rad", "torsion": "24.46 N*m/rad"},
        },
    },
    material={
        "name": "Al 7075 (prs3-ruiz)",
        "E": "72 GPa",
        "nu": 0.33,
        "density": "2.81 g/cm^3",
        "yield_strength": "503 MPa",
        "allowable": "400 MPa",
    },
    source="Ruiz et al. section 5 (K_Rrev, K_Rsph, K_Tsph; R_rev, t_rev, l_sph, t_sph, R_sph) and section 4 "
    "(10 x 10 mm^2 legs; Al 7075, E = 72 GPa, nu = 0.33, 2.81 g/cm^3; yield 503 MPa, 400 MPa never exceeded)",
)


MECHANISM = Mechanism(
    name=NAME,
    title="3-PRS compliant stage (Ruiz et al.)",
    paper=(
        "A. Ruiz, F. J. Campa, C. Roldan-Paraponiaris, O. Altuzarra, C. Pinto, Experimental validation of the "
        "kinematic design of 3PRS compliant parallel mechanisms, University of the Basque Country UPV/EHU"
    ),
    parameters=PARAMETERS,
    limits=LIMITS,
    closure=closure,
    build=build,
    geometry=geometry,
    parts=(STIFFNESS,),
)


def reference_model(parameters: dict | None = None, limits: dict | None = None) -> Model:
    """A model of the reference closures (parameters and limits as in a problem file;
    the paper's b, L by default), not registered: built from :data:`MECHANISM` directly."""
    return reference_model_of(
        MECHANISM, closure, {"b": "47.91 mm", "L": "109.215 mm"} if parameters is None else parameters, limits
    )
