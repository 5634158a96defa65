"""Flexure hinges and materials, shared by every mechanism.

Every formula works on floats and on CasADi symbols alike (plain arithmetic and
``** 0.5``), so the same function serves a number, a constraint inside an
IPOPT synthesis, and AD.  All arguments and results are SI.

Sources are cited per function; "rotation" is the bending angle of the hinge
about its compliant axis.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from .errors import InputError, suggest
from .options import Option, validate_mapping


@dataclass(frozen=True)
class Material:
    """Elastic material.  E: Young's modulus [Pa], nu: Poisson's ratio,
    density [kg/m^3], yield_strength [Pa]; ``None`` where no source gives it.
    ``allowable`` [Pa] is a design stress a paper uses instead of the yield
    strength (with its safety factor already applied), when it gives one."""

    name: str
    E: float
    nu: float | None = None
    density: float | None = None
    yield_strength: float | None = None
    allowable: float | None = None
    source: str = ""

    @property
    def G(self) -> float:
        """Shear modulus E / (2 (1 + nu))."""
        if self.nu is None:
            raise InputError(f"material '{self.name}' has no Poisson's ratio; give nu", path=("material",))
        return self.E / (2.0 * (1.0 + self.nu))


#: Materials as the papers give them (properties a paper does not give are None).
MATERIALS: dict[str, Material] = {
    m.name: m
    for m in (
        Material(
            "Al 7075-T6",
            E=71.7e9,
            nu=0.33,
            density=2810.0,
            yield_strength=503e6,
            source="prc3-li-2018.md section 'Modal analysis' (E, nu, density); prs3-ruiz.md section 5 "
            "(yield 503 MPa; that paper rounds E to 72 GPa)",
        ),
        Material(
            "Ti-6Al-4V",
            E=113.8e9,
            nu=0.342,
            yield_strength=880e6,
            source="pantograph-3d-elgammal-2016.md Table 1 (density not given)",
        ),
        Material(
            "polypropylene",
            E=2e9,
            allowable=23.5e6,
            source="pantograph-3d-elgammal-2016.md section 5 (E = 2 GPa, sigma_all = 23.5 MPa)",
        ),
    )
}

MATERIAL_OPTIONS = (
    Option("name", "str", "a label for the material", default="custom"),
    Option("E", "stress", "Young's modulus", lower=0.0, strict=True),
    Option("nu", "dimensionless", "Poisson's ratio", default=None, lower=-1.0, upper=0.5),
    Option("density", "density", "mass density", default=None, lower=0.0, strict=True),
    Option("yield_strength", "stress", "yield strength", default=None, lower=0.0, strict=True),
    Option("allowable", "stress", "allowable (design) stress", default=None, lower=0.0, strict=True),
)


def material(spec: str | dict, path: tuple = ("material",)) -> Material:
    """A material by name (see :data:`MATERIALS`) or inline ``{E: 72 GPa, ...}``."""
    if isinstance(spec, str):
        if spec not in MATERIALS:
            raise InputError(
                f"unknown material {spec!r}; expected one of: {', '.join(MATERIALS)} or an inline mapping "
                "{E, nu, density, yield_strength}",
                path=path,
                suggestions=suggest(spec, MATERIALS),
            )
        return MATERIALS[spec]
    values = validate_mapping(spec, MATERIAL_OPTIONS, path, what="material property")
    return Material(**values, source="inline")


# -- right-circular notch hinge ---------------------------------------------------------------


def circular_notch_stiffness(E, b, t, r):
    """Rotational stiffness of a right-circular notch hinge,
    k = 2 E b t^2.5 / (9 pi r^0.5)  [N m/rad].

    E: Young's modulus, b: hinge width (out of plane), t: thickness at the
    thinnest point, r: notch radius.  The simplified Paros-Weisbord formula,
    valid for t << r, as used by prc3-li-2018.md (eq 28-31 and the line after
    eq 28).
    """
    return 2.0 * E * b * t**2.5 / (9.0 * math.pi * r**0.5)


def circular_notch_max_rotation(E, t, r, sigma_all):
    """Largest rotation of a circular notch hinge at the allowable stress,
    delta_max = 3 pi / (4 E) sqrt(r / t) sigma_all  [rad]
    (pantograph-3d-elgammal-2016.md eq 38)."""
    return 3.0 * math.pi / (4.0 * E) * (r / t) ** 0.5 * sigma_all


# -- cantilevered (corner-filleted) notch of the pantograph paper ------------------------------


def cantilever_notch_rotation(E, l, t, sigma):
    """Angular deflection of the pantograph's flexure joint at stress sigma,
    delta = 0.148 l sigma / (E t)  [rad]
    (pantograph-3d-elgammal-2016.md eq 30; l: length, t: thickness)."""
    return 0.148 * l * sigma / (E * t)


# -- leaf-spring hinge ---------------------------------------------------------------------------


def leaf_spring_stiffness(E, b, t, l):
    """Rotational stiffness of a leaf spring (thin cantilever beam under an end
    moment), k = E b t^3 / (12 l) = E I / l  [N m/rad]
    (Euler-Bernoulli beam; e.g. Howell, Compliant Mechanisms, 2001, ch. 5)."""
    return E * b * t**3 / (12.0 * l)


def leaf_spring_max_rotation(E, t, l, sigma_all):
    """Largest end rotation of a leaf spring under a pure moment at the
    allowable stress: sigma = E t theta / (2 l), so theta_max = 2 l sigma_all / (E t)."""
    return 2.0 * l * sigma_all / (E * t)
