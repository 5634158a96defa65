"""The flexure hinge types: one table (`HINGE_TABLE`), one frozen `HingeType`
per type, read by the compliance model (`cpm_nlp.analysis.compliance`: a hinge's
stiffness, six-axis stiffness and stress), the hinge rotation limits of mechanisms and
files (`hinge_rotation`, a joint's ``flexure``), the file reader, ``describe`` and
the docs.  Where a type may sit is said once, by the joint types
(`cpm_nlp.core.joints.JointType.hinges`); `HingeType.joints` reads it there.

Each type gives what its sources give: a stiffness per axis and a stress (the compliance
model's types), and/or the largest rotation at the allowable stress (the rotation limits).
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from types import MappingProxyType

import casadi as ca
import numpy as np

from ..core.errors import InputError
from ..core.joints import JOINT_TYPES
from ..core.options import Option
from .flexure import (
    MATERIALS,
    cantilever_notch_rotation,
    circular_notch_max_rotation,
    circular_notch_stiffness_exact,
    elastic_limits,
    leaf_spring_max_rotation,
)
from .flexure_compliance import circular_notch_compliances, circular_notch_compliances_3d, rectangle_torsion_constant


def _larger(a, c):
    """max(a, c), on floats and on CasADi symbols (a design variable)."""
    return ca.fmax(a, c) if isinstance(a, ca.SX | ca.MX) or isinstance(c, ca.SX | ca.MX) else max(a, c)


def _smaller(a, c):
    return ca.fmin(a, c) if isinstance(a, ca.SX | ca.MX) or isinstance(c, ca.SX | ca.MX) else min(a, c)


def rectangle_torsion_stress(T, a, c):
    """Largest shear stress of an a x c rectangle (a >= c) under torsion T,
    τ = 3T/(8 A B²) [1 + 0.6095 (B/A) + 0.8865 (B/A)² - 1.8023 (B/A)³ + 0.9100 (B/A)⁴]
    with 2A = a, 2B = c (W. C. Young, R. G. Budynas, Roark's Formulas for Stress
    and Strain, 7th ed., Table 10.7, case 4)."""
    a, c = _larger(a, c), _smaller(a, c)
    A, B = a / 2.0, c / 2.0
    ratio = B / A
    return 3.0 * T / (8.0 * A * B**2) * (1 + 0.6095 * ratio + 0.8865 * ratio**2 - 1.8023 * ratio**3 + 0.91 * ratio**4)


def circular_notch_kt(t, r):
    """Stress-concentration factor K_t of a circular notch hinge in bending about its compliant
    axis, on the nominal stress 6M/(w t²) of its thinnest section: the hinge is a bar of height
    H = t + 2r with two opposite U-notches of depth h = r and radius r (h/r = 1), whose fit is
    W. C. Young, R. G. Budynas, Roark's Formulas for Stress and Strain, 7th ed. (2002),
    Table 17.1, case 2b (two U-notches in a member of rectangular section, in-plane bending),
    for 0.25 <= h/r <= 2.0:
        K_t = C1 + C2 (2h/H) + C3 (2h/H)² + C4 (2h/H)³,
        C1 = 0.723 + 2.845 √(h/r) - 0.504 h/r,   C2 = -1.836 - 5.746 √(h/r) + 1.314 h/r,
        C3 = 7.254 - 1.885 √(h/r) + 1.646 h/r,   C4 = -5.140 + 4.785 √(h/r) - 2.456 h/r.
    Coefficients as read in a transcription of that table (eng-calculations.com, "Two U-notches
    in a member of rectangular section for elastic stress, in-plane bending"), not in the book.
    At h/r = 1 the coefficients sum to 1.000: K_t -> 1 as t/r -> 0 (2h/H -> 1), and
    K_t -> C1 = 3.064 for a shallow notch in a wide bar (2h/H -> 0)."""
    h_over_r = 1.0
    s = math.sqrt(h_over_r)
    c1 = 0.723 + 2.845 * s - 0.504 * h_over_r
    c2 = -1.836 - 5.746 * s + 1.314 * h_over_r
    c3 = 7.254 - 1.885 * s + 1.646 * h_over_r
    c4 = -5.140 + 4.785 * s - 2.456 * h_over_r
    x = 2.0 * r / (t + 2.0 * r)  # 2h/H
    return c1 + c2 * x + c3 * x**2 + c4 * x**3


def filleted_rod_kt(d, r):
    """Stress-concentration factor K_t of a filleted round neck (diameter d, fillets of radius r
    rising to D = d + 2r) in bending, on the nominal 32M/(π d³): each end is a square shoulder
    with a fillet of height h = r (h/r = 1) in a circular shaft, whose fit is W. C. Young,
    R. G. Budynas, Roark's Formulas for Stress and Strain, 7th ed. (2002), Table 17.1 (square
    shoulder with fillet in a circular shaft, bending), for 0.25 <= h/r <= 2.0:
        K_t = C1 + C2 (2h/D) + C3 (2h/D)² + C4 (2h/D)³,
        C1 = 0.927 + 1.149 √(h/r) - 0.086 h/r,   C2 = 0.015 - 3.281 √(h/r) + 0.837 h/r,
        C3 = 0.847 + 1.716 √(h/r) - 0.506 h/r,   C4 = -0.790 + 0.417 √(h/r) - 0.246 h/r
    (coefficients as read in a transcription of that table, eng-calculations.com, "Square
    shoulder with fillet in circular shaft for elastic stress, bending", not in the book).
    A shoulder fit: it assumes the neck long enough that its two fillets do not interact; a
    neck of no straight length is a U-groove, for which the same table's fit gives more
    (1.128 against 1.073 for the 3-PRS neck, d 3 mm, r 4 mm).  At h/r = 1 the coefficients
    sum to 0.999: K_t -> 1 as d/r -> 0."""
    h_over_r = 1.0
    s = math.sqrt(h_over_r)
    c1 = 0.927 + 1.149 * s - 0.086 * h_over_r
    c2 = 0.015 - 3.281 * s + 0.837 * h_over_r
    c3 = 0.847 + 1.716 * s - 0.506 * h_over_r
    c4 = -0.790 + 0.417 * s - 0.246 * h_over_r
    x = 2.0 * r / (d + 2.0 * r)  # 2h/D
    return c1 + c2 * x + c3 * x**2 + c4 * x**3


#: the range of h/r over which Roark's shoulder-fillet fits hold (the transcription's "requirements")
LEAF_KT_H_OVER_R = (0.1, 20.0)


def leaf_fillet_kt(t, r, h=None):
    """Stress-concentration factor K_t of a leaf spring (thickness t) whose ends run into its
    blocks through corner fillets of radius r, in bending about its compliant axis, on the
    nominal 6M/(w t²): each end is a square shoulder with a fillet in a member of rectangular
    section, the block of height D = t + 2h standing h proud of each face of the leaf (h
    default r, the filleted rod's assumption: a block just high enough to hold the fillet).
    The fit is W. C. Young, R. G. Budynas, Roark's Formulas for Stress and Strain, 7th ed.
    (2002), Table 17.1 (square shoulder with fillet in a member of rectangular section,
    in-plane bending):
        K_t = C1 + C2 (2h/D) + C3 (2h/D)² + C4 (2h/D)³,
    for 0.1 <= h/r <= 2.0:
        C1 = 1.007 + 1.000 √(h/r) - 0.031 h/r,   C2 = -0.270 - 2.404 √(h/r) + 0.749 h/r,
        C3 = 0.677 + 1.133 √(h/r) - 0.904 h/r,   C4 = -0.414 + 0.271 √(h/r) + 0.186 h/r,
    for 2.0 < h/r <= 20:
        C1 = 1.042 + 0.982 √(h/r) - 0.036 h/r,   C2 = -3.599 + 1.619 √(h/r) - 0.431 h/r,
        C3 = 6.084 - 5.607 √(h/r) + 1.158 h/r,   C4 = -2.527 + 3.006 √(h/r) - 0.691 h/r,
    and L/D > 0.8/[r/(D - 2h)]^(1/4) with L the length of the wide part (the block) along the
    leaf.  Coefficients as read in a transcription of that table (eng-calculations.com,
    "Square shoulder with fillet in a member of rectangular section for elastic stress,
    in-plane bending"), not in the book.  At h/r = 1 the coefficients sum to 1.000 (at 2,
    1.000 and 0.9998): K_t -> 1 as t/r -> 0 (2h/D -> 1).  The caller checks h/r
    (`LEAF_KT_H_OVER_R`, `cpm_nlp.analysis.compliance.check_geometry`)."""
    h = r if h is None else h
    hr = h / r
    s = hr**0.5  # ** 0.5: also on CasADi symbols (a designed r)
    low = (
        1.007 + 1.000 * s - 0.031 * hr,
        -0.270 - 2.404 * s + 0.749 * hr,
        0.677 + 1.133 * s - 0.904 * hr,
        -0.414 + 0.271 * s + 0.186 * hr,
    )
    high = (
        1.042 + 0.982 * s - 0.036 * hr,
        -3.599 + 1.619 * s - 0.431 * hr,
        6.084 - 5.607 * s + 1.158 * hr,
        -2.527 + 3.006 * s - 0.691 * hr,
    )
    x = 2.0 * h / (t + 2.0 * h)  # 2h/D

    def kt(c):
        return c[0] + c[1] * x + c[2] * x**2 + c[3] * x**3

    if isinstance(hr, ca.SX | ca.MX):
        return ca.if_else(hr <= 2.0, kt(low), kt(high))
    return kt(low) if hr <= 2.0 else kt(high)


def check_leaf_fillet(d: Mapping[str, float], path: tuple) -> None:
    """Refuse a leaf spring's fillet outside its K_t fit: h without r, or h/r outside Roark's
    `LEAF_KT_H_OVER_R` (the fit's other requirement, L/D > 0.8/[r/t]^(1/4) with L the block's
    length along the leaf, is not checked: a hinge does not know its blocks' length)."""
    if d.get("h") is not None and d.get("r") is None:
        raise InputError(
            "h is the shoulder height of a filleted leaf spring's blocks; give the fillet radius r too "
            "(or leave h out: a sharp corner has no K_t fit)",
            path=path + ("h",),
        )
    if d.get("r") is not None:
        low, high = LEAF_KT_H_OVER_R
        ratio = (d["r"] if d.get("h") is None else d["h"]) / d["r"]
        if not low <= ratio <= high:
            raise InputError(
                f"leaf spring fillet: shoulder height over fillet radius h/r = {ratio:g} is outside the range of "
                f"Roark's fit for its K_t (Table 17.1, square shoulder with fillet), {low:g} <= h/r <= {high:g}; "
                "give Kt yourself, or h and r within it",
                path=path + ("h",),
            )


def _leaf_kt(d: Mapping[str, float]) -> float:
    """A leaf spring's K_t: Roark's shoulder fillet where its fillet radius r is given, else 1
    (a sharp corner has no finite K_t; a hinge's ``Kt`` overrides both)."""
    if d.get("r") is None:
        return 1.0
    return leaf_fillet_kt(d["t"], d["r"], d.get("h"))


def _von_mises(sigma: float, tau: float) -> float:
    return (sigma**2 + 3.0 * tau**2) ** 0.5  # ** 0.5: also on CasADi symbols


def _rect_stress(d: Mapping[str, float], loads: Mapping[str, float]) -> float:
    """Nominal stress at the thinnest section t x w of a rectangular hinge:
    σ = (6|M_bend|/(w t²) + 6|M_bend2|/(t w²) + |F|/(w t)), τ from Roark's
    rectangle torsion, combined by von Mises."""
    t, w = d["t"], d["w"]
    sigma = 6.0 * abs(loads.get("bend", 0.0)) / (w * t**2) + 6.0 * abs(loads.get("bend2", 0.0)) / (t * w**2)
    sigma += abs(loads.get("axial", 0.0)) / (w * t)
    tau = rectangle_torsion_stress(abs(loads.get("torsion", 0.0)), w, t)
    return _von_mises(sigma, tau)


def _rod_stress(d: Mapping[str, float], loads: Mapping[str, float]) -> float:
    """Round neck of diameter d: σ = (32 |M|/(π d³) + 4|F|/(π d²)) with M the
    resultant of both bending moments, τ = 16 T/(π d³), von Mises (Euler-Bernoulli
    and Saint-Venant torsion of a circular section)."""
    dia = d["d"]
    m = (loads.get("bend", 0.0) ** 2 + loads.get("bend2", 0.0) ** 2) ** 0.5
    sigma = 32.0 * m / (math.pi * dia**3) + 4.0 * abs(loads.get("axial", 0.0)) / (math.pi * dia**2)
    tau = 16.0 * abs(loads.get("torsion", 0.0)) / (math.pi * dia**3)
    return _von_mises(sigma, tau)


def _notch_stiffness(E, G, d, compliances=circular_notch_compliances_3d) -> dict[str, float]:
    if G is None:  # without Poisson's ratio only the bending stiffness (Paros-Weisbord exact)
        return {"bend": float(circular_notch_stiffness_exact(E, d["w"], d["t"], d["r"]))}
    c = compliances(E, G, d["w"], d["t"], d["r"])
    return {"bend": 1 / c["rz"], "bend2": 1 / c["ry"], "torsion": 1 / c["rx"], "axial": 1 / c["x"]}


def _rod_stiffness(E, G, d) -> dict[str, float]:
    dia, length = d["d"], d["l"]
    inertia = math.pi * dia**4 / 64.0
    out = {"bend": E * inertia / length, "bend2": E * inertia / length, "axial": E * math.pi * dia**2 / 4 / length}
    if G is not None:
        out["torsion"] = G * 2.0 * inertia / length
    return out


def _leaf_stiffness(E, G, d) -> dict[str, float]:
    t, w, length = d["t"], d["w"], d["l"]
    out = {"bend": E * w * t**3 / 12 / length, "bend2": E * t * w**3 / 12 / length, "axial": E * w * t / length}
    if G is not None:
        out["torsion"] = G * rectangle_torsion_constant(_larger(w, t), _smaller(w, t)) / length
    return out


#: the six axes of a hinge in its own frame: three rotations (bend about the compliant
#: axis, bend2 about the second bending axis, torsion about its length) and three
#: translations (axial along its length, shear across its thinnest section, i.e. the
#: direction bending about the compliant axis moves, shear2 along the compliant axis)
SIX_AXES = ("bend", "bend2", "torsion", "axial", "shear", "shear2")


def _beam_shear(E, G, length, inertia, area, alpha_s):
    """Transverse stiffness of a straight beam at its centre, 1/(l³/(12 E I) + α_s l/(G A)):
    the compliance of a cantilever's free end (l³/3EI, coupling l²/2EI, l/EI) transported
    to the mid-point, where the force-moment coupling vanishes (the definition of
    `circular_notch_compliances`), plus Timoshenko shear."""
    return 1.0 / (length**3 / (12.0 * E * inertia) + alpha_s * length / (G * area))


def _notch_six(E, G, d, compliances=circular_notch_compliances_3d) -> dict[str, float]:
    c = compliances(E, G, d["w"], d["t"], d["r"])
    return {
        "bend": 1 / c["rz"],
        "bend2": 1 / c["ry"],
        "torsion": 1 / c["rx"],
        "axial": 1 / c["x"],
        "shear": 1 / c["y"],
        "shear2": 1 / c["z"],
    }


def _rod_six(E, G, d) -> dict[str, float]:
    out = _rod_stiffness(E, G, d)
    dia, length = d["d"], d["l"]
    area, inertia = math.pi * dia**2 / 4.0, math.pi * dia**4 / 64.0
    out["shear"] = out["shear2"] = _beam_shear(E, G, length, inertia, area, 10.0 / 9.0)
    return out


def _leaf_six(E, G, d) -> dict[str, float]:
    out = _leaf_stiffness(E, G, d)
    t, w, length = d["t"], d["w"], d["l"]
    out["shear"] = _beam_shear(E, G, length, w * t**3 / 12.0, w * t, 1.2)
    out["shear2"] = _beam_shear(E, G, length, t * w**3 / 12.0, w * t, 1.2)
    return out


@functools.cache
def _gauss_legendre() -> tuple[np.ndarray, np.ndarray]:
    """32-point Gauss-Legendre nodes and weights on [-1, 1] (made on first use: numpy.polynomial
    is not imported by a solve that evaluates no hinge formula; issue 23, start-up)."""
    return np.polynomial.legendre.leggauss(32)


def _filleted_rod_integrals(d: Mapping[str, float]) -> dict[str, float]:
    """The section integrals of a round neck of diameter d and straight length l with
    circular fillets of radius r at both ends (a revolved corner-filleted flexure,
    Lobontiu 2002 ch. 2, with a circular section): over x from the centre,
    ∫ dx/I, ∫ dx/J, ∫ dx/A, ∫ x² dx/I, the fillet diameter D(s) = d + 2r (1 - cos φ)
    at s = r sin φ past the neck's end (32-point Gauss-Legendre in φ)."""
    dia, length, r = d["d"], d["l"], d["r"]
    half = length / 2.0
    inertia, area = math.pi * dia**4 / 64.0, math.pi * dia**2 / 4.0
    out = {"I": length / inertia, "A": length / area, "x2I": 2.0 * half**3 / 3.0 / inertia}
    for node, weight in zip(*_gauss_legendre()):
        phi = (float(node) + 1.0) * math.pi / 4.0  # [0, pi/2]
        ds = r * math.cos(phi) * float(weight) * math.pi / 4.0
        D = dia + 2.0 * r * (1.0 - math.cos(phi))
        x = half + r * math.sin(phi)
        i_x, a_x = math.pi * D**4 / 64.0, math.pi * D**2 / 4.0
        out["I"] += 2.0 * ds / i_x  # both fillets
        out["A"] += 2.0 * ds / a_x
        out["x2I"] += 2.0 * ds * x**2 / i_x
    out["J"] = out["I"] / 2.0  # J = 2 I of a circle
    return out


def _filleted_rod_stiffness(E, G, d) -> dict[str, float]:
    n = _filleted_rod_integrals(d)
    out = {"bend": E / n["I"], "bend2": E / n["I"], "axial": E / n["A"]}
    if G is not None:
        out["torsion"] = G / n["J"]
    return out


def _filleted_rod_six(E, G, d) -> dict[str, float]:
    n = _filleted_rod_integrals(d)
    out = _filleted_rod_stiffness(E, G, d)
    out["shear"] = out["shear2"] = 1.0 / (n["x2I"] / E + (10.0 / 9.0) * n["A"] / G)
    return out


#: the dimensions a hinge type may take (each a length)
DIM_OPTIONS: Mapping[str, Option] = MappingProxyType(
    {
        "t": Option("t", "length", "thickness at the thinnest section", lower=0.0, strict=True),
        "r": Option("r", "length", "notch (or fillet) radius", lower=0.0, strict=True),
        "w": Option("w", "length", "hinge width (along its compliant axis)", lower=0.0, strict=True),
        "d": Option("d", "length", "neck diameter", lower=0.0, strict=True),
        "l": Option("l", "length", "hinge length", lower=0.0, strict=True),
        "h": Option(
            "h",
            "length",
            "shoulder height: how far the block stands proud of each face of a filleted leaf spring "
            "(its K_t; default r)",
            lower=0.0,
            strict=True,
        ),
    }
)


@dataclass(frozen=True)
class HingeType:
    """A flexure hinge geometry.

    Attributes
    ----------
    name
        its ``type`` (a hinge's) or ``hinge`` (a joint limit's) in a file.
    dims
        the dimensions its stiffness and stress take (`DIM_OPTIONS`).
    stiffness
        ``(E, G, dims) -> {axis: k}`` about the axes of `cpm_nlp.analysis.compliance.AXES` (G
        None when the material gives no Poisson's ratio), None if no source gives it.
    six_axis
        ``(E, G, dims) -> {axis: k}`` over all of `SIX_AXES`, at its centre.
    stress
        ``(dims, loads) -> σ``, its largest nominal stress for the loads per axis.
    kt
        ``(dims) -> K_t``, its stress-concentration factor on that nominal stress (peak = K_t ×
        nominal), None where no published fit is shipped (a hinge's ``Kt``, else 1).
    kt_source
        the source of ``kt``.
    source
        the sources of stiffness, six-axis stiffness and stress.
    limit_dims
        the dimensions its largest rotation takes.
    rotation
        ``(E, σ_allow, dims) -> δ_max`` [rad], the largest rotation at the allowable stress (a
        joint's rotation limit), None if no source gives it.
    limit_source
        the source of ``rotation``.
    optional_dims
        the dimensions it may take besides (a leaf spring's fillet r and shoulder h, for its K_t).
    """

    name: str
    dims: tuple[str, ...] = ()
    stiffness: Callable[..., dict[str, float]] | None = None
    six_axis: Callable[..., dict[str, float]] | None = None
    stress: Callable[..., float] | None = None
    source: str = ""
    kt: Callable[..., float] | None = None
    kt_source: str = ""
    limit_dims: tuple[str, ...] = ()
    rotation: Callable[..., float] | None = None
    limit_source: str = ""
    optional_dims: tuple[str, ...] = ()

    @property
    def parameters(self) -> tuple[Option, ...]:
        """Its dimensions, each with its unit and meaning."""
        return tuple(DIM_OPTIONS[d] for d in dict.fromkeys(self.dims + self.optional_dims + self.limit_dims))

    @property
    def takes(self) -> str:
        """Its dimensions as a message names them: "t, l, w (optionally r, h)"."""
        return ", ".join(self.dims) + (f" (optionally {', '.join(self.optional_dims)})" if self.optional_dims else "")

    @property
    def joints(self) -> tuple[str, ...]:
        """The joint types it can sit at (said by `cpm_nlp.core.joints.JOINT_TYPES`)."""
        return tuple(n for n, j in JOINT_TYPES.items() if self.name in j.hinges)


#: the hinge types by name: the one table
HINGE_TABLE: Mapping[str, HingeType] = MappingProxyType(
    {
        t.name: t
        for t in (
            HingeType(
                "cantilever_notch",
                limit_dims=("l", "t"),
                rotation=lambda E, sigma, d: cantilever_notch_rotation(E, d["l"], d["t"], sigma),
                limit_source="Elgammal et al. 2016, eq 30-31",
            ),
            HingeType(
                "circular_notch",
                ("t", "r", "w"),
                _notch_stiffness,
                _notch_six,
                _rect_stress,
                "stiffness: Lobontiu 2002 ch. 2 integrals (flexure_compliance) with a correction fitted here to a "
                "3-D finite-element reference (circular_notch_compliances_3d, not published; the flexure reference "
                "page), Paros-Weisbord exact without nu; "
                "stress: nominal 6M/(w t^2) at the thinnest section (the stress of Elgammal et al. 2016 "
                "eq 38); peak: K_t x nominal",
                kt=lambda d: circular_notch_kt(d["t"], d["r"]),
                kt_source="Roark's Formulas for Stress and Strain, 7th ed., Table 17.1 case 2b (two U-notches, "
                "in-plane bending), h/r = 1",
                limit_dims=("t", "r"),
                rotation=lambda E, sigma, d: circular_notch_max_rotation(E, d["t"], d["r"], sigma),
                limit_source="Elgammal et al. 2016, eq 38",
            ),
            HingeType(
                "circular_notch_paros_weisbord",
                ("t", "r", "w"),
                lambda E, G, d: _notch_stiffness(E, G, d, circular_notch_compliances),
                lambda E, G, d: _notch_six(E, G, d, circular_notch_compliances),
                _rect_stress,
                "stiffness: Lobontiu 2002 ch. 2 integrals (flexure_compliance; the rotation is Paros and Weisbord's "
                "exact integral, 1965), the formulas the papers use, uncorrected; "
                "stress: nominal 6M/(w t^2) at the thinnest section (the stress of Elgammal et al. 2016 "
                "eq 38); peak: K_t x nominal",
                kt=lambda d: circular_notch_kt(d["t"], d["r"]),
                kt_source="Roark's Formulas for Stress and Strain, 7th ed., Table 17.1 case 2b (two U-notches, "
                "in-plane bending), h/r = 1",
            ),
            HingeType(
                "circular_rod",
                ("d", "l"),
                _rod_stiffness,
                _rod_six,
                _rod_stress,
                "stiffness: E I/l, G J/l, E A/l of a round neck of diameter d and length l (fillets ignored: "
                "stiffer); stress: 32M/(pi d^3), 16T/(pi d^3), von Mises; peak: Kt x nominal (Kt given, default 1)",
            ),
            HingeType(
                "filleted_rod",
                ("d", "l", "r"),
                _filleted_rod_stiffness,
                _filleted_rod_six,
                _rod_stress,
                "stiffness: Euler-Bernoulli integrals over a round neck of diameter d and straight length l with "
                "circular fillets of radius r at both ends (a revolved corner-filleted hinge, Lobontiu 2002 ch. 2); "
                "stress: 32M/(pi d^3), 16T/(pi d^3) at the neck, von Mises; peak: K_t x nominal",
                kt=lambda d: filleted_rod_kt(d["d"], d["r"]),
                kt_source="Roark's Formulas for Stress and Strain, 7th ed., Table 17.1 (square shoulder with fillet "
                "in a circular shaft, bending), h/r = 1",
            ),
            HingeType(
                "leaf_spring",
                ("t", "l", "w"),
                _leaf_stiffness,
                _leaf_six,
                _rect_stress,
                "stiffness: E w t^3/(12 l) (Euler-Bernoulli), G J/l with Roark's rectangle J; "
                "stress: 6M/(w t^2), Roark Table 10.7 torsion, von Mises; peak: K_t x nominal (Kt given, else "
                "the fillet fit where a fillet radius r is given, else 1: a sharp corner has no finite K_t)",
                kt=_leaf_kt,
                kt_source="Roark's Formulas for Stress and Strain, 7th ed., Table 17.1 (square shoulder with fillet "
                "in a member of rectangular section, in-plane bending), shoulder height h (default r)",
                optional_dims=("r", "h"),
                limit_dims=("l", "t"),
                rotation=lambda E, sigma, d: leaf_spring_max_rotation(E, d["t"], d["l"], sigma),
                limit_source="Euler-Bernoulli leaf spring under a pure moment",
            ),
        )
    }
)

#: the circular notch hinges: one geometry, the default formula and the papers' (same checks)
NOTCH_TYPES = ("circular_notch", "circular_notch_paros_weisbord")

#: the hinge types that set a joint's rotation limit (a joint's ``flexure``, a mechanism's limits)
LIMIT_TYPES = tuple(n for n, t in HINGE_TABLE.items() if t.rotation is not None)


# -- hinge rotation limits from a problem file --------------------------------------------------
#
# A mechanism whose joint limits follow from its flexure hinges declares
# HINGE_LIMIT_OPTIONS among its LIMITS and calls `hinge_rotation` on the
# validated limits: the hinge type, its dimensions and its material give the
# largest rotation delta_max at the allowable stress.

HINGE_LIMIT_OPTIONS = (
    Option(
        "hinge",
        "choice",
        "flexure hinge that sets the joint-angle limits (instead of giving them directly)",
        default=None,
        choices=LIMIT_TYPES,
    ),
    Option("l", "length", "hinge length (cantilever notch, leaf spring)", default=None, lower=0.0, strict=True),
    Option("t", "length", "hinge thickness at its thinnest point", default=None, lower=0.0, strict=True),
    Option("r", "length", "notch radius (circular notch)", default=None, lower=0.0, strict=True),
    Option("material", "str", f"hinge material, one of: {', '.join(MATERIALS)}", default=None),
    Option("E", "stress", "Young's modulus (overrides the material's)", default=None, lower=0.0, strict=True),
    Option(
        "sigma_all",
        "stress",
        "allowable stress (default: the material's allowable stress, else its yield strength)",
        default=None,
        lower=0.0,
        strict=True,
    ),
)

#: names of HINGE_LIMIT_OPTIONS (a mechanism's limits may hold others too)
HINGE_KEYS = tuple(o.name for o in HINGE_LIMIT_OPTIONS)


def hinge_rotation(limits: dict, path: tuple = ("mechanism", "limits")) -> float | None:
    """Largest hinge rotation [rad] from validated HINGE_LIMIT_OPTIONS values,
    or None when ``limits`` names no hinge.  Raises InputError for a hinge
    that lacks a dimension, a material (or E and sigma_all), or has keys it
    does not use."""
    kind = limits.get("hinge")
    given = [k for k in HINGE_KEYS if k != "hinge" and limits.get(k) is not None]
    if kind is None:
        if given:
            raise InputError(
                f"{', '.join(given)} describe a flexure hinge; also give hinge (one of: {', '.join(LIMIT_TYPES)})",
                path=path,
            )
        return None
    hinge = HINGE_TABLE[kind]
    rotation, dims = hinge.rotation, hinge.limit_dims
    missing = [d for d in dims if limits.get(d) is None]
    if missing:
        raise InputError(f"hinge {kind} needs {', '.join(missing)} (its dimensions: {', '.join(dims)})", path=path)
    unused = [d for d in ("l", "t", "r") if d not in dims and limits.get(d) is not None]
    if unused:
        raise InputError(f"hinge {kind} has no dimension {', '.join(unused)} (it takes {', '.join(dims)})", path=path)
    E, sigma = elastic_limits(limits, path, f"hinge {kind}")
    return float(rotation(E, sigma, {d: limits[d] for d in dims}))
