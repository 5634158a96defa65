"""Six-axis compliance matrices of notch flexure joints (companion of
`cpm_nlp.analysis.flexure`, which holds the one-axis hinge formulas and materials).

Every function works on floats and on CasADi symbols (the integrals are
evaluated by a fixed Gauss-Legendre rule, so a design optimisation can
differentiate through them).  All values are SI.  Compliance matrices follow
`cpm_nlp.core.screws`: C maps the wrench (f; m) at the hinge centre to the
displacement (δ; φ) of that point.

Notch frame: x along the hinge (the line through the two attached bodies),
y across the thinnest section (thickness t), z the rotation axis (width b).

Sources:

* N. Lobontiu, *Compliant Mechanisms: Design of Flexure Hinges*, CRC Press,
  2002, ch. 2: the compliances of a variable-section flexure are the
  Euler-Bernoulli/Timoshenko integrals over its length
  ∫ dx/(E A), ∫ dx/(E I), ∫ x² dx/(E I) + ∫ α_s dx/(G A), ∫ dx/(G I_t);
  for the right-circular profile t(x) = t + 2 (r - sqrt(r² - x²)) they have the
  closed forms of its section 2.3 (Paros and Weisbord, Machine Design 1965, for
  the rotational one).  They are evaluated here by Gauss-Legendre quadrature in
  the variable ψ with tan(φ/2) = sqrt(t/(t+4r)) tan ψ (x = r sin φ), which
  makes the integrands smooth, so 32 nodes reproduce the closed forms to
  round-off (tests compare with adaptive quadrature and with the simplified
  Paros-Weisbord formula of `cpm_nlp.analysis.flexure.circular_notch_stiffness`).
* Torsion constant of a rectangle a x c (a >= c): J = a c³ [1/3 - 0.21 (c/a)
  (1 - c⁴/(12 a⁴))] (W. C. Young, R. G. Budynas, *Roark's Formulas for Stress
  and Strain*, 7th ed., Table 10.7, case 4).
* Shear coefficient α_s = 6/5 of a rectangular section (Timoshenko), as
  Lobontiu includes shear for short hinges.
* `circular_notch_compliances_3d` (the default ``circular_notch`` of the compliance kinds):
  those integrals corrected to a 3-D finite-element reference by a form fitted here (not
  published), with the restrained warping of a short notch in torsion (derived here from
  Vlasov's non-uniform torsion); docs/site/reference/flexures.md gives the reference, the
  fit and its residuals.
* Two orthogonal notches in series as a U joint (the notch-type universal
  flexure, e.g. G. Palmieri, M. C. Palpacelli, M. Callegari, J. Mech. Des.
  134(12), 2012): the series compliance is the sum of both notch compliances
  rotated and transported to the joint centre (`cpm_nlp.core.screws`).
"""

from __future__ import annotations

import functools
import math
from types import MappingProxyType
from typing import Any

import casadi as ca
import numpy as np

from ..core import screws


@functools.cache
def _gauss_legendre() -> tuple[np.ndarray, np.ndarray]:
    """32-point Gauss-Legendre nodes and weights on [-1, 1] (made on first use: numpy.polynomial
    is not imported by a solve that evaluates no hinge formula; issue 23, start-up)."""
    return np.polynomial.legendre.leggauss(32)


#: Timoshenko shear coefficient of a rectangle.
SHEAR_COEFFICIENT = 6.0 / 5.0

#: Notch frame axes (columns: the notch x, y, z) in a joint frame whose z runs
#: along the leg.  "y": rotation axis along the joint's y (e.g. the R joints of
#: legs 1 and 3, the first U axis); "x": rotation axis along the joint's x.
NOTCH_AXES = {
    "y": np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]]),
    "x": np.array([[0.0, 0.0, 1.0], [0.0, -1.0, 0.0], [1.0, 0.0, 0.0]]),
}


def _symbolic(*args: Any) -> bool:
    return any(isinstance(a, (ca.SX, ca.MX, ca.DM)) for a in args)


def _atan(v: Any) -> Any:
    return ca.atan(v) if _symbolic(v) else math.atan(v)


def _tan(v: Any) -> Any:
    return ca.tan(v) if _symbolic(v) else math.tan(v)


def _cos(v: Any) -> Any:
    return ca.cos(v) if _symbolic(v) else math.cos(v)


def _sin(v: Any) -> Any:
    return ca.sin(v) if _symbolic(v) else math.sin(v)


def rectangle_torsion_constant(a, c):
    """J = a c³ [1/3 - 0.21 (c/a)(1 - c⁴/(12 a⁴))] of an a x c rectangle,
    a >= c (Roark, 7th ed., Table 10.7, case 4)."""
    ratio = c / a
    return a * c**3 * (1.0 / 3.0 - 0.21 * ratio * (1.0 - ratio**4 / 12.0))


def _notch_nodes(t, r):
    """The quadrature nodes over the notch, (x, dx, h(x)): Gauss-Legendre in ψ with
    tan(φ/2) = sqrt(t/(t+4r)) tan ψ, x = r sin φ, h = t + 2r (1 - cos φ)."""
    k = (t / (t + 4.0 * r)) ** 0.5
    psi_end = _atan(1.0 / k)
    for node, weight in zip(*_gauss_legendre()):
        psi = float(node) * psi_end
        u = k * _tan(psi)
        phi = 2.0 * _atan(u)
        # dx = r cos(φ) dφ, dφ = 2 du / (1 + u²), du = k sec²(ψ) dψ
        dx = r * _cos(phi) * 2.0 / (1.0 + u**2) * k / _cos(psi) ** 2 * float(weight) * psi_end
        yield r * _sin(phi), dx, t + 2.0 * r * (1.0 - _cos(phi))


def circular_notch_compliances(E, G, b, t, r) -> dict[str, Any]:
    """The six compliances of a right-circular notch hinge at its centre
    (Lobontiu 2002, ch. 2), for width b, thinnest section t and notch radius r.

    Keys (notch frame): ``x`` axial [m/N]; ``y`` in-plane transverse,
    bending about z plus shear [m/N]; ``z`` out-of-plane transverse [m/N];
    ``rx`` torsion [rad/(N m)]; ``ry`` out-of-plane bending [rad/(N m)];
    ``rz`` the rotation the hinge is made for [rad/(N m)].
    Valid for t + 2r <= b (the torsion formula takes the width as the long side).
    """
    acc = {key: 0.0 for key in ("x", "y", "z", "rx", "ry", "rz")}
    for x, dx, th in _notch_nodes(t, r):
        area = b * th
        i_z = b * th**3 / 12.0  # bending about the rotation axis
        i_y = th * b**3 / 12.0  # out-of-plane bending
        j = rectangle_torsion_constant(b, th)
        shear = SHEAR_COEFFICIENT / (G * area)
        acc["x"] += dx / (E * area)
        acc["rz"] += dx / (E * i_z)
        acc["ry"] += dx / (E * i_y)
        acc["rx"] += dx / (G * j)
        acc["y"] += dx * (x**2 / (E * i_z) + shear)
        acc["z"] += dx * (x**2 / (E * i_y) + shear)
    return acc


#: The constants of `circular_notch_compliances_3d`, per compliance: (s0, a, p) of
#: c = c_beam (1 - ν² (w/t)/(w/t + s0)) (1 + a (t/r)^p).  Fitted here (not published) to the 3-D
#: finite-element reference tests/data/notch_fem_reference.json by benchmarks/fit_notch_3d.py,
#: which prints them and their residuals (docs/site/reference/flexures.md).
NOTCH_3D_FIT = MappingProxyType(
    {
        "rz": (5.654, 0.292, 0.8774),
        "ry": (40.7, 0.08151, 0.05),
        "x": (30.64, 0.2251, 0.1336),
        "rx": (1.884, 1.916, 0.8596),
    }
)


def notch_warping_compliance(E, b, t, r):
    """Torsional compliance of a notch whose section cannot warp at its ends (the blocks),
    from the warping alone: 144/(E b³) ∫ x² dx / h(x)³ over the notch [rad/(N m)].

    Derived here from Vlasov's non-uniform torsion T = G J θ' - (E I_w θ'')' with the warping
    constant of a narrow rectangle, I_w = ∫∫ (y z)² dA = b³ h³/144 (y z: the Saint-Venant warping
    function of a thin strip).  When the notch is short against its width the warping term carries
    the torque: E I_w θ'' = -T x, and with θ' = 0 at both ends (the blocks) the twist is
    θ = T ∫ x² dx/(E I_w(x)), the compliance above ((12/b²) times the bending part of the notch's
    transverse compliance).  `circular_notch_compliances_3d` puts it in parallel with Saint-Venant's
    torsion (tests/analysis/test_notch_fem.py checks 3-D torsion of a thin strip between a clamp and a
    rigid cap against Vlasov's restrained torsion of a uniform bar)."""
    acc = 0.0
    for x, dx, th in _notch_nodes(t, r):
        acc += dx * x**2 / th**3
    return 144.0 * acc / (E * b**3)


def circular_notch_compliances_3d(E, G, b, t, r, fit=None) -> dict[str, Any]:
    """The six compliances of a right-circular notch hinge (keys of `circular_notch_compliances`),
    closer to 3-D elasticity than the beam integrals: the toolkit's default ``circular_notch``.

    * ``rz``, ``ry``, ``x`` (rotation, the other bending, axial): the beam integrals of
      `circular_notch_compliances` times (1 - ν² (w/t)/(w/t + s0)) (1 + a (t/r)^p).  The first
      factor moves the modulus from E (a narrow hinge, plane stress) towards E/(1 - ν²) (a wide one,
      whose thin section cannot contract across its width: plane strain); the second is the
      compliance the beam integrals miss where the notch meets its blocks, growing with t/r.
    * ``rx`` (torsion): Saint-Venant's torsion (the beam integral) in parallel with the restrained
      warping of `notch_warping_compliance`, times the same kind of factors.
    * ``y``, ``z`` (transverse): the beam integrals, uncorrected (no 3-D reference computed).

    The constants (`NOTCH_3D_FIT`, or ``fit``) are fitted here, not published: to the 3-D
    finite-element reference tests/data/notch_fem_reference.json (scikit-fem, R = 1 mm,
    t/r 0.05 to 0.5, w/t 10 to 100, ν = 0.33), by benchmarks/fit_notch_3d.py; outside that range
    they extrapolate.  Works on floats and CasADi symbols."""
    constants = NOTCH_3D_FIT if fit is None else fit
    nu = E / (2.0 * G) - 1.0
    beam = circular_notch_compliances(E, G, b, t, r)
    out = dict(beam)
    out["rx"] = 1.0 / (1.0 / beam["rx"] + 1.0 / notch_warping_compliance(E, b, t, r))
    for key in ("rz", "ry", "x", "rx"):
        s0, a, p = constants[key]
        ratio = b / t
        out[key] = out[key] * (1.0 - nu**2 * ratio / (ratio + s0)) * (1.0 + a * (t / r) ** p)
    return out


def _diag(values) -> Any:
    if _symbolic(*values):
        return ca.diag(ca.vertcat(*values))
    return np.diag([float(v) for v in values])


def notch_compliance_matrix(E, G, b, t, r) -> Any:
    """6 x 6 compliance of a circular notch at its centre, notch frame,
    diag(x, y, z, rx, ry, rz) of `circular_notch_compliances`."""
    c = circular_notch_compliances(E, G, b, t, r)
    return _diag([c["x"], c["y"], c["z"], c["rx"], c["ry"], c["rz"]])


def r_joint_compliance(E, G, b, t, r, axis: str = "y") -> Any:
    """Compliance of an R flexure joint (one circular notch) at its centre, in
    the joint frame: z along the leg, rotation axis along ``axis`` ("y" or "x").
    Diagonal: the paper's C_R of eq 29 (rpr-2rpu-upr-zhang-2022.md)."""
    C = notch_compliance_matrix(E, G, b, t, r)
    return screws.rotate_compliance(C, NOTCH_AXES[axis])


def u_joint_compliance(E, G, h, t, r, spacing=None) -> Any:
    """Compliance of a notch-type U joint at its centre, in the joint frame.

    A square rod of side h along z carries two circular notches (radius r,
    thinnest section t, width h): the first, at z = -spacing/2, turns about y
    (the axis attached to the leg), the second, at z = +spacing/2, about x.
    ``spacing`` defaults to 2r, notches cut next to each other (the most compact
    joint).  The joint centre is the point between them; the off-diagonal
    force-moment terms this transport creates are kept (the paper's eq 28
    shows only the diagonal)."""
    e = 2.0 * r if spacing is None else spacing
    C = notch_compliance_matrix(E, G, h, t, r)
    first = screws.transport_compliance(screws.rotate_compliance(C, NOTCH_AXES["y"]), _point(-e / 2.0), _point(0.0))
    second = screws.transport_compliance(screws.rotate_compliance(C, NOTCH_AXES["x"]), _point(e / 2.0), _point(0.0))
    return first + second


def _point(z: Any) -> Any:
    return ca.vertcat(0.0, 0.0, z) if _symbolic(z) else np.array([0.0, 0.0, float(z)])


def rotation_limit_eq32(E, t, r, sigma_y, SF):
    """θ_max = r σ_Y / (E t SF), the rotation capability of a flexure joint as
    rpr-2rpu-upr-zhang-2022.md eq 32 prints it (r: notch radius, t: thinnest
    section, SF: safety factor)."""
    return r * sigma_y / (E * t * SF)
