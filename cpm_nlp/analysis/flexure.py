"""Flexure hinges and materials, shared by every mechanism.

Every formula works on floats and on CasADi symbols alike (plain arithmetic,
``** 0.5`` and ``ca.atan``, which returns a float for a float), so the same
function serves a number, a constraint inside an IPOPT synthesis, and AD.  All
arguments and results are SI.

Sources are cited per function; "rotation" is the bending angle of the hinge
about its compliant axis.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import casadi as ca

from ..core.errors import InputError
from ..core.options import REQUIRED, Option
from ..core.schema import Named, Record

#: properties of a `Material`, in the order the papers list them
PROPERTIES = {
    "E": "Young's modulus",
    "nu": "Poisson's ratio",
    "density": "mass density",
    "yield_strength": "yield strength",
    "allowable": "allowable (design) stress",
}


@dataclass(frozen=True)
class Material:
    """Elastic material.  E: Young's modulus [Pa], nu: Poisson's ratio,
    density [kg/m^3], yield_strength [Pa]; ``None`` where no source gives it
    (never a handbook value typed in without a source).  ``allowable`` [Pa] is
    a design stress a paper uses instead of the yield strength (with its
    safety factor already applied), when it gives one."""

    name: str
    E: float | None
    nu: float | None = None
    density: float | None = None
    yield_strength: float | None = None
    allowable: float | None = None
    source: str = ""

    def require(self, prop: str, path: tuple = ("material",), why: str = "") -> float:
        """The property ``prop`` (one of `PROPERTIES`), or an
        [`InputError`][cpm_nlp.core.errors.InputError] saying that this material does not give it."""
        value = getattr(self, prop)
        if value is None:
            need = f" ({why})" if why else ""
            raise InputError(
                f"material '{self.name}' has no {PROPERTIES[prop]} {prop}{need}: no source gives it; "
                f"give the material inline, e.g. {{name: {self.name}, {prop}: ...}}",
                path=path,
            )
        return value

    @property
    def G(self) -> float:
        """Shear modulus E / (2 (1 + nu))."""
        return self.require("E") / (2.0 * (1.0 + self.require("nu")))


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
            allowable=400e6,
            source="Li et al. 2018, section 'Modal analysis' (E, nu, density); Ruiz et al., section 5 "
            "('Al 7075': yield 503 MPa, and 400 MPa never exceeded, its safety factor)",
        ),
        Material(
            "Ti-6Al-4V",
            E=113.8e9,
            nu=0.342,
            yield_strength=880e6,
            source="Elgammal et al. 2016, Table 1 (density not given)",
        ),
        Material(
            "polypropylene",
            E=2e9,
            allowable=23.5e6,
            source="Elgammal et al. 2016, section 5 (E = 2 GPa, sigma_all = 23.5 MPa; "
            "nu, density and yield strength not given)",
        ),
        Material(
            "Flexible-T",
            E=None,
            source="Elgammal et al. 2016, section 8 (the 3D-printed prototype's material; "
            "the paper gives none of its properties)",
        ),
    )
}

MATERIAL_OPTIONS = (
    Option("name", "str", "a label for the material", default="custom"),
    Option("E", "stress", "Young's modulus", lower=0.0, strict=True),
    # -1 < nu < 0.5: the bounds of an isotropic elastic material (a positive shear and bulk
    # modulus); nu = -1 makes G = E / (2 (1 + nu)) infinite
    Option("nu", "dimensionless", "Poisson's ratio", default=None, lower=-1.0, upper=0.5, strict=True),
    Option("density", "density", "mass density", default=None, lower=0.0, strict=True),
    Option("yield_strength", "stress", "yield strength", default=None, lower=0.0, strict=True),
    Option("allowable", "stress", "allowable (design) stress", default=None, lower=0.0, strict=True),
)


def material_node(name: str = "material", description: str = "the hinge material", default=REQUIRED) -> Named:
    """The declaration of a material input: a name of `MATERIALS` or inline
    ``{E: 72 GPa, nu: 0.33, ...}`` (parsed to a `Material`)."""
    return Named(
        name,
        description,
        table=MATERIALS,
        inline=Record("material", "an inline material", MATERIAL_OPTIONS, what="material property"),
        build=lambda values, _path: Material(**values, source="inline"),
        what="material",
        inline_text="{E, nu, density, yield_strength}",
        default=default,
        entry=Material,
    )


MATERIAL = material_node()


def material(spec: str | dict | Material, path: tuple = ("material",)) -> Material:
    """A material by name (see `MATERIALS`) or inline ``{E: 72 GPa, ...}``
    (a `Material` already parsed is returned as it is)."""
    return MATERIAL.parse(spec, path)


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


def circular_notch_stiffness_exact(E, b, t, r):
    """Rotational stiffness of a right-circular notch hinge from the
    Euler-Bernoulli integral over the whole notch, without the t << r
    approximation  [N m/rad].

    The thickness along the hinge is h(x) = t + 2 (r - sqrt(r^2 - x^2)) for
    -r <= x <= r, and the compliance is C = 12/(E b) * int dx / h(x)^3
    (Paros and Weisbord, "How to design flexure hinges", Machine Design 37,
    1965; their "exact" equation).  With a = t + 2r, c = 2r, u = a^2 - c^2 =
    t (t + 4r) and T = atan(sqrt((t + 4r)/t)) the integral is

        int dx / h^3 = 3 a c^2 T / u^2.5 + c (3 a^2 - u) / (2 a u^2),

    obtained from int dphi / (a - c cos phi) = 4 T / sqrt(u) (x = r sin phi)
    by differentiating twice with respect to a.  For t/r -> 0 it tends to
    `circular_notch_stiffness` (tests/analysis/test_flexure.py checks both the
    limit and the integral by quadrature).  For the 3-PRC hinge of
    prc3-li-2018.md Table 1 (t/r = 1/6) the simplified formula is 2.1 % softer.
    """
    a = t + 2.0 * r
    c = 2.0 * r
    u = t * (t + 4.0 * r)
    T = ca.atan(((t + 4.0 * r) / t) ** 0.5)
    integral = 3.0 * a * c**2 * T / u**2.5 + c * (3.0 * a**2 - u) / (2.0 * a * u**2)
    return E * b / (12.0 * integral)


def check_circular_notch(t: float, r: float, path: tuple = ()) -> None:
    """Reject a notch the simplified formula k = 2 E b t^2.5 / (9 pi r^0.5)
    does not describe: it needs t > 0, r > 0 and t <= r (it is the t << r
    limit of `circular_notch_stiffness_exact`; at t = r it is already
    12 % too soft).  ``path`` locates t in the problem file."""
    if not (t > 0 and r > 0):
        raise InputError(f"expected a positive notch thickness t and radius r, got t = {t!r}, r = {r!r}", path=path)
    if t > r:
        raise InputError(
            f"expected the notch thickness t ({t * 1e3:g} mm) to be at most the notch radius r ({r * 1e3:g} mm): "
            "the circular-notch formula k = 2 E b t^2.5 / (9 pi r^0.5) holds for t << r",
            path=path,
        )


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


def allowable_stress(m: Material, path: tuple = ("material",)) -> float:
    """The design stress of a material: its allowable stress if a source gives
    one, else its yield strength."""
    if m.allowable is not None:
        return m.allowable
    if m.yield_strength is not None:
        return m.yield_strength
    raise InputError(f"material '{m.name}' has no allowable stress or yield strength; give sigma_all", path=path)


def elastic_limits(values: dict, path: tuple, what: str = "the hinge") -> tuple[float, float]:
    """(E, sigma_all) from validated ``material``, ``E`` and ``sigma_all`` values: the
    material's, overridden by E or sigma_all where given."""
    E, sigma = values.get("E"), values.get("sigma_all")
    name = values.get("material")
    if name is not None:
        m = material(name, path + ("material",))
        E = m.E if E is None else E
        sigma = allowable_stress(m, path + ("material",)) if sigma is None else sigma
    if E is None or sigma is None:
        need = " and ".join(n for n, v in (("E", E), ("sigma_all", sigma)) if v is None)
        raise InputError(f"{what} needs a material (or {need})", path=path)
    return float(E), float(sigma)
