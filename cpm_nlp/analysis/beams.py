"""Flexible beam bodies: Euler-Bernoulli or Timoshenko beam elements, geometrically
nonlinear, for the six-axis hinge model (`cpm_nlp.analysis.hinge_chains`) and on
their own (a cantilever, `BeamChain`).

Formulation (a node-frame, co-rotational discretisation, as the flexure models of
SPACAR use deformation parameters measured in the element's own moving frame:
J. B. Jonker, J. P. Meijaard, "SPACAR -- computer program for dynamic analysis of
flexible spatial mechanisms and manipulators", in W. Schiehlen (ed.), Multibody Systems
Handbook, Springer 1990; the element here is a different one, described below):

* a beam of length ℓ is cut into n elements; element e joins its start node frame to
  its end node frame.  Its six deformations ε_e are the coordinates of the end frame
  in the start frame: T_e = Trans(u_x x + u_y y + u_z z) · Rot(x, θ_x) Rot(y, θ_y)
  Rot(z, θ_z), the rotations about the element's spring point, in the element's
  reference axes (x along the beam, y = the compliant bending axis "bend", z = "bend2").
  The chain of elements is a product of exponentials, so any rigid motion of the beam
  (of its start frame) leaves every ε_e unchanged: large displacements and rotations
  are exact; only each element's own deformation is taken as small (it is ℓ/n of
  the whole), and the discretisation converges to the geometrically exact (Reissner)
  beam as n grows (the tests: the elastica under an end load, and the circle of
  radius EI/M under an end moment).
* the element's energy is U_e = ½ ε_eᵀ K_e ε_e with K_e its linear stiffness at the
  spring point, which depends on the element's stiffness model:

  - ``distributed``: K_e = C_e⁻¹, C_e the element's cantilever compliance at its end
    node (the spring point), the Castigliano integral over the element
    C_e = ∫ Bᵀ(s) C_s(s) B(s) ds, B(s) carrying the end wrench to the section at s and
    C_s = diag(1/EA, 1/κGA, 1/κGA, 1/GJ, 1/EI_y, 1/EI_z) the section's compliance per
    length (no shear terms for Euler-Bernoulli).  Gauss-Legendre quadrature: exact for a
    prismatic element, converging for a varying section (a notch).  The linear
    compliance of a chain of distributed elements is the beam's exact one for any n.
  - ``lumped``: the element's stiffness concentrated in one six-axis spring at its
    midpoint, K_e = diag(EA, κGA, κGA, GJ, EI_y, EI_z)/ℓ_e of the midpoint section
    (without the two shear springs for Euler-Bernoulli: 4 deformations), rigid halves on
    either side: the finite-segment (pseudo-rigid-body) discretisation, whose linear
    compliance converges as 1/n².

* mass (for the natural frequencies; the compliance does not use it), the element's 12 x 12
  mass matrix over its two nodes' velocities (v_0, ω_0, v_1, ω_1), in the element axes
  (`element_mass`), as the element's stiffness model declares:

  - ``distributed``: the consistent mass matrix, M_e = ∫ ρ (A NᵀN + I_p n_φᵀn_φ) ds with
    N the cubic Hermite interpolation of the two transverse displacements from the nodes'
    displacements and rotations, linear axial displacement and twist n_φ (I_p = I_y + I_z
    the polar moment), plus the sections' rotary inertia ρ (I_y θ_y² + I_z θ_z²) with
    θ = the Hermite slopes for ``timoshenko`` (none for ``euler_bernoulli``, the classical
    Euler-Bernoulli consistent mass); Gauss-Legendre quadrature, so a notch's varying
    section too.  It moves every rigid motion of the element exactly (a rigid bar's
    kinetic energy, for ``timoshenko``);
  - ``lumped``: half the element's mass ρ∫A ds, as a point mass, and half its polar
    inertia ρ∫I_p ds, about the beam's axis, at each node (no rotary inertia about the
    bending axes: the classical lumped mass).

Sections: a rectangle b x h (h the thickness across which the beam bends about its
compliant axis y, b the width along y), a round d, given A, I (I2, J, kappa), or the
right-circular notch profile t(x) = t + 2(r - sqrt(r² - x²)) of width w (x from the
notch centre; a hinge modelled as a beam of varying section).  Shear coefficients κ:
G. R. Cowper, "The shear coefficient in Timoshenko's beam theory", J. Appl. Mech. 33
(1966) 335-340: 10(1+ν)/(12+11ν) for a rectangle, 6(1+ν)/(7+6ν) for a circle.
Torsion of a rectangle: Roark, 7th ed., Table 10.7, case 4
(`cpm_nlp.analysis.flexure_compliance.rectangle_torsion_constant`).

Every section property and element compliance is written in CasADi arithmetic, so a
section dimension may be a symbol (a design variable).
"""

from __future__ import annotations

import functools
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import casadi as ca
import numpy as np

from ..core.screws import axis_rotation, vee

#: the section shapes a beam body takes, with their keys
SECTION_KINDS: Mapping[str, tuple[str, ...]] = {
    "rectangle": ("b", "h"),
    "round": ("d",),
    "given": ("A", "I"),
    "circular_notch": ("t", "r", "w"),
}
#: the beam theories
THEORIES = ("timoshenko", "euler_bernoulli")
#: the stiffness models of an element
ELEMENT_MODELS = ("distributed", "lumped")
#: the element's deformations, in chart order: translations then rotations (x along the beam)
DEFORMATIONS = ("u_x", "u_y", "u_z", "theta_x", "theta_y", "theta_z")


def _min(a: Any, b: Any) -> Any:
    return ca.fmin(a, b) if isinstance(a, (ca.SX, ca.MX)) or isinstance(b, (ca.SX, ca.MX)) else min(a, b)


def _max(a: Any, b: Any) -> Any:
    return ca.fmax(a, b) if isinstance(a, (ca.SX, ca.MX)) or isinstance(b, (ca.SX, ca.MX)) else max(a, b)


def _sqrt(a: Any) -> Any:
    return ca.sqrt(a) if isinstance(a, (ca.SX, ca.MX)) else math.sqrt(a)


@dataclass(frozen=True)
class Section:
    """A beam's cross-section: ``kind`` of `SECTION_KINDS` and its dimensions (SI; floats or
    CasADi symbols).  ``values`` may add, for ``given``: I2 (default I), J (default I + I2),
    kappa (default 5/6); for any kind: kappa (the shear coefficient, default Cowper's)."""

    kind: str
    values: Mapping[str, Any]

    @property
    def length(self) -> Any:
        """The length a profile fixes (a notch: 2r), else None."""
        return 2.0 * self.values["r"] if self.kind == "circular_notch" else None

    def thickness(self, x: Any) -> Any:
        """The notch thickness at x from its centre, t + 2(r - sqrt(r² - x²))."""
        v = self.values
        return v["t"] + 2.0 * (v["r"] - _sqrt(_max(v["r"] ** 2 - x**2, 0.0)))

    def properties(self, nu: Any, x: Any = 0.0) -> dict[str, Any]:
        """A, I_y (bending about the compliant axis y), I_z, J, kappa at x (x: from the notch
        centre; a prismatic section ignores it)."""
        v, k = self.values, self.kind
        if k == "rectangle" or k == "circular_notch":
            b, h = (v["b"], v["h"]) if k == "rectangle" else (v["w"], self.thickness(x))
            long, short = _max(b, h), _min(b, h)
            out = {
                "A": b * h,
                "I_y": b * h**3 / 12.0,
                "I_z": h * b**3 / 12.0,
                "J": long * short**3 * (1.0 / 3.0 - 0.21 * (short / long) * (1.0 - (short / long) ** 4 / 12.0)),
                "kappa": 10.0 * (1.0 + nu) / (12.0 + 11.0 * nu),
            }
        elif k == "round":
            d = v["d"]
            inertia = math.pi * d**4 / 64.0
            out = {"A": math.pi * d**2 / 4.0, "I_y": inertia, "I_z": inertia, "J": 2.0 * inertia}
            out["kappa"] = 6.0 * (1.0 + nu) / (7.0 + 6.0 * nu)
        else:
            i2 = v.get("I2") if v.get("I2") is not None else v["I"]
            j = v.get("J") if v.get("J") is not None else v["I"] + i2
            out = {"A": v["A"], "I_y": v["I"], "I_z": i2, "J": j, "kappa": 5.0 / 6.0}
        if v.get("kappa") is not None:
            out["kappa"] = v["kappa"]
        return out

    def stress(self, x: Any, wrench: np.ndarray) -> float | None:
        """Largest nominal stress of the section at x under the section wrench (N_x, V_y, V_z,
        T, M_y, M_z): σ = |N|/A + |M_y| c_y/I_y + |M_z| c_z/I_z, τ from torsion, von Mises
        (a rectangle's corner, a round's resultant moment)."""
        p = self.properties(0.3, x)
        N, _, _, T, My, Mz = (float(w) for w in wrench)
        v, k = self.values, self.kind
        if k == "round":
            d = float(v["d"])
            sigma = abs(N) / p["A"] + math.hypot(My, Mz) * d / 2.0 / p["I_y"]
            tau = abs(T) * d / 2.0 / p["J"]
        elif k == "given":
            return None  # no dimensions: no stress
        else:
            b, h = (v["b"], v["h"]) if k == "rectangle" else (v["w"], self.thickness(x))
            b, h = float(b), float(h)
            sigma = abs(N) / (b * h) + 6.0 * abs(My) / (b * h**2) + 6.0 * abs(Mz) / (h * b**2)
            long, short = max(b, h), min(b, h)
            ratio = short / long  # Roark Table 10.7 case 4 (as hinge_types.rectangle_torsion_stress)
            tau = (
                3.0
                * abs(T)
                / (8.0 * (long / 2) * (short / 2) ** 2)
                * (1 + 0.6095 * ratio + 0.8865 * ratio**2 - 1.8023 * ratio**3 + 0.91 * ratio**4)
            )
        return math.sqrt(sigma**2 + 3.0 * tau**2)


@dataclass(frozen=True)
class BeamSpec:
    """One flexible body as declared: its section, theory, number of elements and each
    element's stiffness model; ``length`` the flexible part (default: the whole link)."""

    name: str
    section: Section
    theory: str = "timoshenko"
    elements: int = 4
    models: tuple[str, ...] = ("distributed",)
    length: float | None = None

    def model_of(self, e: int) -> str:
        return self.models[e] if len(self.models) > 1 else self.models[0]


@dataclass(frozen=True)
class Element:
    """One beam element in the reference configuration (base frame, SI).

    Attributes
    ----------
    point
        its spring point;
    axes
        3 x 3, columns x (along the beam), y (bend), z (bend2);
    dofs
        the indices of `DEFORMATIONS` it has;
    K
        its stiffness over those dofs;
    s0, s1, s_spring
        its ends and spring point along the beam, from the beam's start (x_centre: where the
        beam's profile centre is)."""

    point: np.ndarray
    axes: np.ndarray
    dofs: tuple[int, ...]
    K: np.ndarray
    s0: float
    s1: float
    s_spring: float
    x_centre: float
    mass: float = 0.0
    #: 12 x 12 mass over the nodes' velocities (v_0, ω_0, v_1, ω_1) in ``axes`` (`element_mass`;
    #: None without a density)
    M: np.ndarray | None = None

    @property
    def nodes(self) -> tuple[np.ndarray, np.ndarray]:
        """Its two nodes (start, end) in the reference configuration."""
        x = self.axes[:, 0]
        return self.point + (self.s0 - self.s_spring) * x, self.point + (self.s1 - self.s_spring) * x


@functools.cache
def _gauss(n: int) -> tuple[np.ndarray, np.ndarray]:
    """n-point Gauss-Legendre nodes and weights on [-1, 1] (made on first use: numpy.polynomial
    costs every solve's start-up otherwise)."""
    return np.polynomial.legendre.leggauss(n)


def _section_compliance(sec: Section, E: Any, G: Any, nu: Any, x: Any, theory: str) -> list[Any]:
    p = sec.properties(nu, x)
    shear = 0.0 if theory == "euler_bernoulli" else 1.0 / (p["kappa"] * G * p["A"])
    return [1.0 / (E * p["A"]), shear, shear, 1.0 / (G * p["J"]), 1.0 / (E * p["I_y"]), 1.0 / (E * p["I_z"])]


def element_compliance(
    sec: Section, E: Any, nu: Any, s0: Any, s1: Any, x_centre: Any, theory: str, model: str
) -> tuple[Any, Any]:
    """(C_e, s_spring): the 6 x 6 compliance of the element [s0, s1] at its spring point (the
    end node for ``distributed``, the midpoint for ``lumped``), wrench (F; M) -> (δ; θ) in the
    element axes, and where the spring point is.  CasADi arithmetic (floats give a DM)."""
    G = E / (2.0 * (1.0 + nu))
    ell = s1 - s0
    if model == "lumped":
        mid = 0.5 * (s0 + s1)
        return ca.diag(ca.vertcat(*[c * ell for c in _section_compliance(sec, E, G, nu, mid - x_centre, theory)])), mid
    nodes, weights = _gauss(4 if sec.kind != "circular_notch" else 24)
    C = ca.DM.zeros(6, 6) if not any(isinstance(a, (ca.SX, ca.MX)) for a in (E, nu, s0, s1)) else ca.SX.zeros(6, 6)
    for xi, w in zip(nodes, weights):
        s = s0 + 0.5 * (xi + 1.0) * ell
        cs = _section_compliance(sec, E, G, nu, s - x_centre, theory)
        a = s1 - s  # lever arm from the section to the end node, along x
        # B: section wrench = B (F; M) at the end node: F_s = F, M_s = M + (a e_x) x F
        B = ca.vertcat(ca.horzcat(ca.DM.eye(3), ca.DM.zeros(3, 3)), ca.horzcat(_skew_x(a), ca.DM.eye(3)))
        C = C + 0.5 * ell * float(w) * ca.mtimes([B.T, ca.diag(ca.vertcat(*cs)), B])
    return C, s1


def element_mass(
    sec: Section, density: float, nu: float, s0: float, s1: float, x_centre: float, theory: str, model: str
) -> np.ndarray:
    """The element's 12 x 12 mass matrix over its nodes' velocities (v_0, ω_0, v_1, ω_1) in its
    axes (x along it): ``distributed`` the consistent one (cubic Hermite transverse, linear axial
    and twist; rotary inertia for ``timoshenko``), ``lumped`` half the mass and half the polar
    inertia at each node (the module's docstring).  Numeric."""
    ell = s1 - s0
    nodes, weights = _gauss(6 if sec.kind != "circular_notch" else 24)
    M = np.zeros((12, 12))
    if model == "lumped":
        m = ip = 0.0
        for xi, w in zip(nodes, weights):
            p = sec.properties(nu, s0 + 0.5 * (xi + 1.0) * ell - x_centre)
            m += 0.5 * ell * w * density * float(p["A"])
            ip += 0.5 * ell * w * density * float(p["I_y"] + p["I_z"])
        M[np.diag_indices(12)] = [m / 2] * 3 + [ip / 2, 0.0, 0.0] + [m / 2] * 3 + [ip / 2, 0.0, 0.0]
        return M
    for xi, w in zip(nodes, weights):
        u = 0.5 * (xi + 1.0)  # ξ in [0, 1]
        p = sec.properties(nu, s0 + u * ell - x_centre)
        A, Iy, Iz = (float(p[k]) for k in ("A", "I_y", "I_z"))
        h = (1 - 3 * u**2 + 2 * u**3, ell * (u - 2 * u**2 + u**3), 3 * u**2 - 2 * u**3, ell * (-(u**2) + u**3))
        dh = ((-6 * u + 6 * u**2) / ell, 1 - 4 * u + 3 * u**2, (6 * u - 6 * u**2) / ell, -2 * u + 3 * u**2)
        N = np.zeros((3, 12))  # the centroid's velocity
        N[0, [0, 6]] = 1 - u, u
        N[1, [1, 5, 7, 11]] = h  # v, its slope θ_z
        N[2, [2, 4, 8, 10]] = h[0], -h[1], h[2], -h[3]  # w, its slope -θ_y
        twist = np.zeros(12)
        twist[[3, 9]] = 1 - u, u
        Mq = density * (A * N.T @ N + (Iy + Iz) * np.outer(twist, twist))
        if theory == "timoshenko":  # the sections' rotary inertia, θ from the Hermite slopes
            tz, ty = np.zeros(12), np.zeros(12)
            tz[[1, 5, 7, 11]] = dh
            ty[[2, 4, 8, 10]] = -dh[0], dh[1], -dh[2], dh[3]
            Mq += density * (Iz * np.outer(tz, tz) + Iy * np.outer(ty, ty))
        M += 0.5 * ell * w * Mq
    return 0.5 * (M + M.T)


def _skew_x(a: Any) -> Any:
    """[a e_x]×: (a e_x) × F = (0, -a F_z, a F_y)."""
    m = ca.SX.zeros(3, 3) if isinstance(a, (ca.SX, ca.MX)) else ca.DM.zeros(3, 3)
    m[1, 2] = -a
    m[2, 1] = a
    return m


def beam_frame(t: np.ndarray, bend: np.ndarray | None) -> np.ndarray:
    """Axes x = t, y = the compliant axis (``bend`` made normal to t, else any normal), z = x × y."""
    t = t / np.linalg.norm(t)
    y = None
    if bend is not None:
        y = bend - np.dot(bend, t) * t
        y = y / np.linalg.norm(y) if np.linalg.norm(y) > 1e-9 else None
    if y is None:
        trial = np.eye(3)[int(np.argmin(np.abs(t)))]
        y = trial - np.dot(trial, t) * t
        y = y / np.linalg.norm(y)
    return np.column_stack([t, y, np.cross(t, y)])


def beam_elements(
    spec: BeamSpec,
    start: np.ndarray,
    end: np.ndarray,
    bend: np.ndarray | None,
    E: float,
    nu: float,
    density: float | None = None,
) -> list[Element]:
    """The elements of a beam body between the points ``start`` and ``end`` (the flexible part
    of length ``spec.length`` centred between them; a notch profile takes its own 2r), in the
    reference configuration, numeric."""
    start, end = np.asarray(start, dtype=float), np.asarray(end, dtype=float)
    span = float(np.linalg.norm(end - start))
    axes = beam_frame(end - start, bend)
    ell = spec.length if spec.length is not None else span
    if spec.section.length is not None:
        ell = float(spec.section.length)
    a = 0.5 * (span - ell)
    x_centre = a + 0.5 * ell
    out = []
    for e in range(spec.elements):
        s0, s1 = a + ell * e / spec.elements, a + ell * (e + 1) / spec.elements
        model = spec.model_of(e)
        C, s_spring = element_compliance(spec.section, E, nu, s0, s1, x_centre, spec.theory, model)
        C = np.array(C, dtype=float)
        dofs = (0, 3, 4, 5) if model == "lumped" and spec.theory == "euler_bernoulli" else tuple(range(6))
        K = np.linalg.inv(C[np.ix_(dofs, dofs)]) if model == "lumped" else np.linalg.inv(C)
        K = 0.5 * (K + K.T)
        mass, M = 0.0, None
        if density is not None:
            M = element_mass(spec.section, density, nu, s0, s1, x_centre, spec.theory, model)
            mass = float(M[0, 0] + M[0, 6])  # the axial row: a rigid translation carries the whole mass
        point = start + axes[:, 0] * float(s_spring)
        out.append(Element(point, axes, dofs, K, float(s0), float(s1), float(s_spring), float(x_centre), mass, M))
    return out


def element_motions(el: Element, values: Sequence[Any]) -> list[tuple[str, np.ndarray, Any, np.ndarray]]:
    """The element's elementary motions (kind, axis, value, point), in product order:
    the translations, then the rotations about its spring point."""
    out = []
    for d, v in zip(el.dofs, values):
        out.append(("P" if d < 3 else "R", el.axes[:, d % 3], v, el.point))
    return out


def product(motions: Sequence[tuple[str, np.ndarray, Any, np.ndarray]]) -> tuple[Any, Any]:
    """The rigid motion (R, t) of a product of exponentials of elementary motions
    (kind "P" or "R", unit axis, value, point on a rotation's axis), in the base frame."""
    Rm, tm = ca.SX.eye(3), ca.SX.zeros(3)
    for kind, axis, value, point in motions:
        if kind == "P":
            Rk, tk = ca.SX.eye(3), value * ca.DM(np.asarray(axis, dtype=float))
        else:
            Rk = axis_rotation(ca.DM(np.asarray(axis, dtype=float).reshape(3, 1)), value)
            tk = ca.DM(point) - Rk @ ca.DM(point)
        Rm, tm = Rm @ Rk, Rm @ tk + tm
    return Rm, tm


def element_wrenches(el: Element, eps: np.ndarray, sec: Section) -> list[float | None]:
    """The nominal stress at the element's two ends (None for a given section, which has no
    dimensions), from the wrench K ε at its spring point (the element's axes; the force
    carried to each end)."""
    full = np.zeros(6)
    full[list(el.dofs)] = el.K @ np.asarray(eps, dtype=float)
    F, M = full[:3], full[3:]
    out = []
    for s in (el.s0, el.s1):
        lever = np.array([el.s_spring - s, 0.0, 0.0])  # from the section to the spring point
        Ms = M + np.cross(lever, F)
        out.append(sec.stress(s - el.x_centre, np.concatenate([F, Ms])))
    return out


@dataclass
class BeamChain:
    """A beam clamped at its start, on its own: the tip frame as a function of the elements'
    deformations, the energy, the linear tip compliance and the nonlinear statics under a
    dead end force and moment (for the tests and for a designer's own check)."""

    spec: BeamSpec
    start: np.ndarray
    end: np.ndarray
    E: float
    nu: float
    bend: np.ndarray | None = None
    elements: list[Element] = field(init=False)

    def __post_init__(self) -> None:
        self.elements = beam_elements(self.spec, self.start, self.end, self.bend, self.E, self.nu)
        n = sum(len(el.dofs) for el in self.elements)
        eps = ca.SX.sym("eps", n)
        motions, U, k = [], 0, 0
        for el in self.elements:
            e = eps[k : k + len(el.dofs)]
            motions += element_motions(el, [e[i] for i in range(len(el.dofs))])
            U += 0.5 * ca.dot(e, ca.mtimes(ca.DM(el.K), e))
            k += len(el.dofs)
        R, t = product(motions)
        tip = ca.DM(np.asarray(self.end, dtype=float))
        p = R @ tip + t
        F, M, phi = ca.SX.sym("F", 3), ca.SX.sym("M", 3), ca.SX.sym("phi", 3)
        # a dead end load: the force's potential -F·p; the moment's for a rotation about a
        # fixed axis (planar bending): -M·(axis angle), the angle read from R (exact up to pi)
        ang = ca.atan2(R[1, 0] - R[0, 1], R[0, 0] + R[1, 1])
        V = U - ca.dot(F, p - tip) - M[2] * ang
        self.n = n
        self.tip_fn = ca.Function("beam_tip", [eps], [p, R], ["eps"], ["p", "R"])
        self.energy_fn = ca.Function("beam_energy", [eps], [U], ["eps"], ["U"])
        self._newton = ca.Function(
            "beam_statics_kkt",
            [eps, F, M],
            [ca.gradient(V, eps), ca.hessian(V, eps)[0]],
            ["eps", "F", "M"],
            ["grad", "H"],
        )
        small = ca.vertcat(p - tip, vee(R))
        self._jac = ca.Function("beam_tip_jacobian", [eps], [ca.jacobian(small, eps)], ["eps"], ["J"])
        self._phi = phi
        self.K = np.zeros((n, n))
        k = 0
        for el in self.elements:
            d = len(el.dofs)
            self.K[k : k + d, k : k + d] = el.K
            k += d

    def linear_compliance(self) -> np.ndarray:
        """The 6 x 6 compliance of the tip (wrench (F; M) at the tip, base axes -> (δ; θ))."""
        J = np.array(self._jac(np.zeros(self.n)), dtype=float)
        return J @ np.linalg.solve(self.K, J.T)

    def solve(self, force: Sequence[float], moment_z: float = 0.0, steps: int = 5) -> tuple[bool, np.ndarray]:
        """The equilibrium under a dead end force and an end moment about z (planar), by Newton
        with load steps: (converged, ε)."""
        eps = np.zeros(self.n)
        F = np.asarray(force, dtype=float)
        for k in range(1, steps + 1):
            lam = k / steps
            for _ in range(50):
                g, H = self._newton(eps, lam * F, [0.0, 0.0, lam * moment_z])
                step = np.linalg.solve(np.array(H, dtype=float), -np.array(g, dtype=float).ravel())
                eps += step
                if np.max(np.abs(step)) < 1e-13:
                    break
            else:
                return False, eps
        return True, eps

    def tip(self, eps: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        p, R = self.tip_fn(eps)
        return np.array(p, dtype=float).ravel(), np.array(R, dtype=float)


__all__ = [
    "BeamChain",
    "BeamSpec",
    "Element",
    "Section",
    "beam_elements",
    "element_compliance",
    "element_mass",
    "element_motions",
    "product",
]
