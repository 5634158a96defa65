"""3-PRC compliant parallel micromanipulator with secondary lever amplifiers
(Li, Li, Ding, Xu, Adv. Mech. Eng. 2018; ``../shared/papers/prc3-li-2018.md``): the
hand-written closures, an independent reference for the tests.

The package's ``prc3`` is the mechanism file ``problems/mechanisms/prc3.yaml`` (its closures
generated from the legs) with the add-on ``cpm_nlp.mechanisms.prc3.addon`` (the amplifier kind,
the dynamics, the hinge check).  These closures, derived by hand from the paper's equations,
were the built-in module ``cpm_nlp.mechanisms.prc3.kinematics`` until issue 21 (item 5) wrote
the mechanism once, in the file; they stay here as the independent derivation the file is
checked against (``tests/mechanisms/prc3/test_prc3_written_once.py``, to 1e-12).  Not part of the package:
import it from the tests only.

Symbols follow the paper:

* L1 ... L8, r (Table 1's R), t, b, h -- Table 1; L1..L4 are the lever arms of
  the amplifier, A1 = L2/L1 and A2 = L2 L4 / (L1 L3) (eq 1),
* q = (q1, q2, q3) -- piezo inputs (eq 2, 10, 27), the **actuated
  coordinates of the model**: the paper's joint limits (0 <= q_i <= 15 um,
  eq 27), its inverse kinematics (eq 10) and its generalized coordinates of
  the dynamics (section "Dynamics model") are all in q.  The slider
  displacements d_i = A2 q_i (eq 2) are reported with every pose as the
  passive coordinates d1..d3,
* x = p = (x, y, z) -- the platform centre P; the platform does not turn
  (R_p = I, eq 5),
* l = L7 -- the length of the R-C legs (eq 27).

Limb i (axis e_i = x, y, z for i = 1, 2, 3) closes the loop of eq 5,
l l_io = D_i - d_i d_io, with d_io = -e_i and D_i = p + l e_i, so that

    |p + (l + d_i) e_i|^2 = l^2                      (eq 6, with eq 9's terms)

whose root with d_i = 0 at p = 0 is eq 8-9: d_1 = -x - l + sqrt(l^2 - y^2 - z^2),
and cyclically.  Positive inputs move the platform towards -e_i (eq 26:
p = -A2 q).

Readings of the paper chosen here (documented, not tuned):

* **Both transverse coordinates under the root (eq 9).**  With the axes of the
  R joint and of the C joint parallel, the C joint's slide s_i (eq 11-12)
  would absorb the platform's motion along that axis and leave one transverse
  coordinate under the root.  The paper's eq 9 has both; so do its workspace
  (eq 10, 27) and its dynamics (eq 31-32: every leg turns by two angles,
  beta_i and gamma_i).  The model follows eq 9: each leg is a link of length l
  whose ends turn about two axes.  Over the workspace the other reading would
  change d_i by at most (A2 q_max)^2 / (2 l) = 0.118 um (0.09 % of the stroke).
* **Positive root.**  Eq 7 has two roots; eq 8 takes the positive one (d = 0
  at p = 0).  On it the leg points along +e_i from slider to platform:
  (p + (l + d_i) e_i) . e_i > 0 is the branch indicator.
* **The expanded Jacobian.**  Eq 21, J = J_d^-1 J_p with rows
  l_io^T / (l_io^T d_io), evaluated on eq 8's root gives
  J = -[[1, y/(x + l + d1), z/(x + l + d1)], ...]: the denominator is
  sqrt(l^2 - y^2 - z^2) = x + l + d1.  The printed expansion has x + l - d1
  (and eq 18 prints the other root's sign); the two differ by 2 d1 / l
  (0.36 %) in entries that are themselves below 2e-3.  :func:`jacobian_eq21`
  and :func:`jacobian_printed` give both; the model's own Jacobian comes from
  AD of the loop closures (dq/dx = J / A2).
* **Leg angles** beta_i, gamma_i are the exact angles of leg i towards the
  next and the previous axis (cyclic x -> y -> z -> x; for limb 2 the paper's
  beta_2 ~ z/L8 and gamma_2 ~ x/L7, eq 31), asin(component / l).
* Residuals are scaled to lengths, (|leg|^2 - l^2) / (2 l), so one tolerance
  in metres applies.

The Lagrange model (eq 28-41) is the add-on's, :mod:`cpm_nlp.mechanisms.prc3.dynamics`.
"""

from __future__ import annotations

import casadi as ca
import numpy as np

from cpm_nlp.analysis import flexure
from cpm_nlp.core.mechanism import Drawing, Mechanism
from cpm_nlp.core.model import Coordinate, LoopClosure, Model
from cpm_nlp.core.options import Option

from . import reference_model_of


def _length(name: str, description: str, required: bool = True) -> Option:
    extra = {} if required else {"default": None}
    return Option(name, "length", description, lower=0.0, upper=1.0, strict=True, **extra)


PARAMETERS = (
    _length("L1", "first lever O1AB, input arm (Table 1, Fig. 2b; A1 = L2/L1, eq 1)"),
    _length("L2", "first lever O1AB, output arm (Table 1; eq 1, 28-29: theta_1 = A1 q/L2)"),
    _length("L3", "second lever O2CD, input arm (Table 1; A2 = L2 L4/(L1 L3), eq 1)"),
    _length("L4", "second lever O2CD, output arm (Table 1; eq 1, 28-29: theta_2 = A2 q/L4)"),
    _length("L7", "length l of the R-C legs (Table 1; eq 27: l = L7)"),
    _length("L5", "coupler link of the first lever (Table 1; I_G3, eq 29) -- used by the dynamics", False),
    _length("L6", "output link of the second lever (Table 1; I_G5, eq 29) -- used by the dynamics", False),
    _length("L8", "second bending length of the R-C legs (Table 1; beta_i, I_G6, eq 31-32) -- dynamics", False),
    _length("r", "notch radius of the circular flexure hinges (Table 1's R; eq 28)", False),
    _length("t", "notch thickness of the circular flexure hinges (Table 1; eq 28)", False),
    _length("b", "width of the circular flexure hinges (Table 1; eq 28)", False),
    _length("h", "h of Table 1 (the paper does not say what it is; no equation uses it)", False),
)
#: parameters of the loop closures, in the order of the CasADi vector p
KINEMATIC = ("L1", "L2", "L3", "L4", "L7")

LIMITS = (
    Option(
        "q", "length", "piezo input range [low, high] of every q_i (eq 27: [0, 15 um])", default=None, shape="range"
    ),
    Option("d", "length", "slider displacement range of every d_i = A2 q_i (eq 2)", default=None, shape="range"),
    Option("beta", "angle", "bending range of every leg towards the next axis", default=None, shape="range"),
    Option("gamma", "angle", "bending range of every leg towards the previous axis", default=None, shape="range"),
)

AXES = ("x", "y", "z")
X = tuple(Coordinate(a, "length", f"platform centre P, {a} (eq 5; R_p = I)") for a in AXES)
Q = tuple(Coordinate(f"q{i}", "length", f"piezo input of limb {i} (eq 2, 10, 27)", "q") for i in (1, 2, 3))
PASSIVE = (
    tuple(Coordinate(f"d{i}", "length", f"slider displacement of limb {i}, d = A2 q (eq 2)", "d") for i in (1, 2, 3))
    + tuple(Coordinate(f"beta{i}", "angle", f"leg {i} bending towards axis {AXES[i % 3]}", "beta") for i in (1, 2, 3))
    + tuple(
        Coordinate(f"gamma{i}", "angle", f"leg {i} bending towards axis {AXES[(i + 1) % 3]}", "gamma")
        for i in (1, 2, 3)
    )
)


def lever_ratios(L1, L2, L3, L4):
    """First-lever and total amplification of the secondary lever amplifier,
    A1 = L2/L1 and A2 = L2 L4 / (L1 L3) (eq 1); floats or CasADi symbols."""
    return L2 / L1, L2 * L4 / (L1 * L3)


def _e(i: int) -> ca.DM:
    v = [0.0, 0.0, 0.0]
    v[i % 3] = 1.0
    return ca.DM(v)


def leg_vector(i: int, P, d_i, l):
    """l_i l_io = D_i - d_i d_io with D_i = P + l e_i and d_io = -e_i (eq 5, 8-9)."""
    return P + (l + d_i) * _e(i)


def _unpack(p):
    L1, L2, L3, L4, l = (p[k] for k in range(5))
    return lever_ratios(L1, L2, L3, L4), l


def loop_closure() -> ca.Function:
    """Φ(x, q; p): one leg-length equation per limb (eq 5-6), scaled to a length."""
    x, q, p = ca.SX.sym("x", 3), ca.SX.sym("q", 3), ca.SX.sym("p", len(KINEMATIC))
    (_A1, A2), l = _unpack(p)
    phi = []
    for i in range(3):
        v = leg_vector(i, x, A2 * q[i], l)  # d_i = A2 q_i, eq 2
        phi.append((ca.dot(v, v) - l**2) / (2 * l))
    return ca.Function("phi", [x, q, p], [ca.vertcat(*phi)], ["x", "q", "p"], ["phi"])


def inverse_kinematics() -> ca.Function:
    """Closed-form IK, eq 8-10 (positive root): t = (x, y, z) -> x, q = d/A2, reach."""
    t, p = ca.SX.sym("t", 3), ca.SX.sym("p", len(KINEMATIC))
    (_A1, A2), l = _unpack(p)
    d, margin = [], []
    for i in range(3):
        rad = l**2 - t[(i + 1) % 3] ** 2 - t[(i + 2) % 3] ** 2
        margin.append(rad / (2 * l))
        d.append(-t[i] - l + ca.sqrt(ca.fmax(rad, 0)))  # eq 9
    q = ca.vertcat(*d) / A2  # eq 10
    return ca.Function("ik", [t, p], [t, q, ca.mmin(ca.vertcat(*margin))], ["t", "p"], ["x", "q", "reach"])


def passive_joints() -> ca.Function:
    """Slider displacements d_i = A2 q_i (eq 2) and the leg angles beta_i, gamma_i."""
    x, q, p = ca.SX.sym("x", 3), ca.SX.sym("q", 3), ca.SX.sym("p", len(KINEMATIC))
    (_A1, A2), l = _unpack(p)
    d = A2 * q
    beta, gamma = [], []
    for i in range(3):
        v = leg_vector(i, x, d[i], l)
        for out, k in ((beta, (i + 1) % 3), (gamma, (i + 2) % 3)):
            out.append(ca.atan2(v[k], ca.sqrt(ca.dot(v, v) - v[k] ** 2)))  # asin(v_k / |v|)
    j = ca.vertcat(d, *beta, *gamma)
    return ca.Function("passive", [x, q, p], [j], ["x", "q", "p"], ["j"])


def branch_indicator() -> ca.Function:
    """g_i > 0 on eq 8's root: leg i points along +e_i from slider to platform."""
    x, q, p = ca.SX.sym("x", 3), ca.SX.sym("q", 3), ca.SX.sym("p", len(KINEMATIC))
    (_A1, A2), l = _unpack(p)
    g = [leg_vector(i, x, A2 * q[i], l)[i] / l for i in range(3)]
    return ca.Function("branch", [x, q, p], [ca.vertcat(*g)], ["x", "q", "p"], ["g"])


def home(p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:  # noqa: ARG001 - signature of LoopClosure.home
    """Home pose: platform at the origin, q = 0 (eq 9: d = 0 at p = 0)."""
    return np.zeros(3), np.zeros(3)


def bounds(p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """|x|, |y|, |z| <= l/2 keeps IPOPT on eq 8's root (leg along +e_i) for
    any slider displacement above -l/2; the workspace is micrometres wide."""
    half = 0.5 * float(p[KINEMATIC.index("L7")])
    return np.full(3, -half), np.full(3, half)


#: the name the reference's closure carries (the package's ``prc3`` is the file)
NAME = "prc3_reference"


def closure() -> LoopClosure:
    """The symbolic 3-PRC (built fresh)."""
    return LoopClosure(
        NAME,
        x=X,
        q=Q,
        parameters=KINEMATIC,
        phi=loop_closure(),
        task=AXES,
        ik=inverse_kinematics(),
        passive=passive_joints(),
        passive_coords=PASSIVE,
        branch=branch_indicator(),
        home=home,
        bounds=bounds,
    )


def check_parameters(params: dict, path: tuple) -> None:
    """The hinge must be one the circular-notch formula of eq 28 describes."""
    if params.get("t") is not None and params.get("r") is not None:
        flexure.check_circular_notch(params["t"], params["r"], path + ("t",))


def build(closure_: LoopClosure, parameters: dict, limits: dict) -> Model:
    """A 3-PRC model from validated parameters (SI) and limits."""
    given = {k: v for k, v in parameters.items() if v is not None}
    A1, A2 = lever_ratios(*(given[k] for k in ("L1", "L2", "L3", "L4")))
    dims = {k: "length" for k in given}
    dims.update(A1="dimensionless", A2="dimensionless")
    return Model(
        closure_,
        parameters=given,
        limits={k: v for k, v in limits.items() if v is not None},
        derived={"A1": A1, "A2": A2},
        dimensions=dims,
    )


# -- the paper's Jacobian (eq 19-21), for comparison with the AD Jacobian ------------------------


def _legs(x, d, l) -> np.ndarray:
    x, d = np.asarray(x, dtype=float), np.asarray(d, dtype=float)
    return np.array([x + (l + d[i]) * np.eye(3)[i] for i in range(3)])


def jacobian_eq21(x, d, l) -> np.ndarray:
    """J = J_d^-1 J_p (eq 19-21), d(d)/dp, with the unit vectors l_io of the
    leg on eq 8's root (eq 5) and d_io = -e_i: rows l_io^T / (l_io^T d_io)."""
    legs = _legs(x, d, l) / l
    return np.array([legs[i] / (-legs[i][i]) for i in range(3)])


def jacobian_printed(x, d, l) -> np.ndarray:
    """The expansion of eq 21 as printed: J = -[[1, y/(x+l-d1), z/(x+l-d1)], ...]
    (its x + l - d1 is x + l + d1 on eq 8's root; see the module docstring)."""
    x, d = np.asarray(x, dtype=float), np.asarray(d, dtype=float)
    J = np.empty((3, 3))
    for i in range(3):
        den = x[i] + l - d[i]
        J[i] = -x / den
        J[i, i] = -1.0
    return J


#: half size of the platform in the drawing, as a fraction of the leg length l (the paper's
#: kinematics treats the platform as its centre P: eq 5 has no platform dimension)
DRAWN_PLATFORM = 0.3


def geometry(model: Model, x, q) -> Drawing:
    """The 3-PRC at pose x (the platform centre P), inputs q: for limb i the slider
    C_i, displaced by d_i = A2 q_i (eq 2) along -e_i, the leg C_iB_i of length l
    (l l_io = P + (l + d_i) e_i, eq 5, 8-9) and the platform joint B_i.  The
    platform is drawn as a triangle of B_i = P + c e_i with c = 0.3 l (eq 5 has no
    platform size: a shift along e_i moves C_i and B_i alike); the lever
    amplifiers are not drawn."""
    l = float(model.parameters["L7"])
    A2 = float(model.derived["A2"])
    c = DRAWN_PLATFORM * l
    x = np.asarray(x, dtype=float).ravel()
    q = np.asarray(q, dtype=float).ravel()
    pts = {"P": x.copy()}
    for i in range(3):
        e = np.eye(3)[i]
        d_i = A2 * q[i]
        pts[f"B{i + 1}"] = x + c * e
        pts[f"C{i + 1}"] = (c - l - d_i) * e
        pts[f"A{i + 1}"] = (c - l) * e  # the slider at q = 0: the rail's origin
    return Drawing(
        points=pts,
        segments=tuple((f"A{i}", f"C{i}", "actuator") for i in (1, 2, 3))
        + tuple((f"C{i}", f"B{i}", "leg") for i in (1, 2, 3))
        + tuple((f"B{i}", "P", "platform") for i in (1, 2, 3)),
        faces=(("platform", ("B1", "B2", "B3")),),
        joints={**{f"C{i}": "R" for i in (1, 2, 3)}, **{f"B{i}": "C" for i in (1, 2, 3)}},
        note="platform size drawn at 0.3 l (the paper's model has none); lever amplifiers not drawn",
    )


MECHANISM = Mechanism(
    name=NAME,
    title="3-PRC micromanipulator with secondary lever amplifiers (Li et al. 2018)",
    paper=(
        "X.-C. Li, Y. Li, B.-X. Ding, H.-Y. Xu, An investigation on kinematics and dynamics performance of a novel "
        "3-PRC-compliant parallel micromanipulator, Adv. Mech. Eng. 10(7), 2018, doi:10.1177/1687814018789800"
    ),
    parameters=PARAMETERS,
    limits=LIMITS,
    closure=closure,
    build=build,
    check_parameters=check_parameters,
    geometry=geometry,
)

#: Table 1's five lengths of the closures
PAPER = {"L1": "9.5 mm", "L2": "25 mm", "L3": "9 mm", "L4": "30 mm", "L7": "73.5 mm"}


def reference_model(parameters: dict | None = None, limits: dict | None = None) -> Model:
    """A model of the reference closures (parameters and limits as in a problem file;
    Table 1's by default), not registered: built from :data:`MECHANISM` directly."""
    return reference_model_of(MECHANISM, closure, PAPER if parameters is None else parameters, limits)
