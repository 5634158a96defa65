"""Flexure-hinge formulas against hand-computed values."""

import math

import casadi as ca
import pytest

from cpm_nlp.analysis import flexure
from cpm_nlp.core.errors import InputError


def test_circular_notch_stiffness_hand_value():
    # prc3-li-2018.md: k = 2 E b t^2.5 / (9 pi r^0.5); E = 71.7 GPa, b = 10 mm, t = 0.5 mm, r = 2 mm
    # by hand: 1.434e9 * 5.590e-9 / (28.274 * 0.044721) = 8.016 / 1.2645 = 6.3397 N m/rad
    k = flexure.circular_notch_stiffness(71.7e9, 0.01, 5e-4, 2e-3)
    assert k == pytest.approx(2 * 71.7e9 * 0.01 * 5e-4**2.5 / (9 * math.pi * math.sqrt(2e-3)), rel=1e-15)
    assert k == pytest.approx(6.3397, rel=1e-4)


def test_circular_notch_max_rotation_hand_value():
    # pantograph eq 38 with Table 1: E = 113.8 GPa, r = t = 1 mm, sigma_y = 880 MPa
    # by hand: 9.4248 / 4.552e11 * 880e6 = 0.018220 rad
    assert flexure.circular_notch_max_rotation(113.8e9, 1e-3, 1e-3, 880e6) == pytest.approx(0.018220, rel=1e-4)


def test_cantilever_notch_gives_the_pantograph_limits():
    # pantograph section 5: l = 5 mm, t = 0.1 mm, E = 2 GPa, sigma_all = 23.5 MPa
    # -> phi_max = 0.148 * 5e-3 * 23.5e6 / (2e9 * 1e-4) = 0.08695 rad (the paper prints 0.0795 rad
    #    and psi_min/max = 1.49/1.65 rad, i.e. pi/2 -+ 0.08)
    delta = flexure.cantilever_notch_rotation(2e9, 5e-3, 1e-4, 23.5e6)
    assert delta == pytest.approx(0.08695, rel=1e-4)


def test_leaf_spring():
    # k = E b t^3 / (12 l): E = 72 GPa, b = 10 mm, t = 0.5 mm, l = 10 mm -> 0.75 N m/rad
    assert flexure.leaf_spring_stiffness(72e9, 0.01, 5e-4, 0.01) == pytest.approx(0.75, rel=1e-12)
    # theta_max = 2 l sigma / (E t) = 2 * 0.01 * 400e6 / (72e9 * 5e-4) = 0.2222 rad
    assert flexure.leaf_spring_max_rotation(72e9, 5e-4, 0.01, 400e6) == pytest.approx(0.22222, rel=1e-4)


def test_formulas_accept_casadi_symbols():
    t = ca.SX.sym("t")
    k = flexure.circular_notch_stiffness(71.7e9, 0.01, t, 2e-3)
    dk = ca.Function("dk", [t], [ca.jacobian(k, t)])
    # d/dt of c t^2.5 = 2.5 k / t
    assert float(dk(5e-4)) == pytest.approx(2.5 * flexure.circular_notch_stiffness(71.7e9, 0.01, 5e-4, 2e-3) / 5e-4)


def test_materials():
    al = flexure.material("Al 7075-T6")
    assert al.E == 71.7e9 and al.density == 2810.0
    assert al.G == pytest.approx(71.7e9 / 2.66)
    custom = flexure.material({"E": "72 GPa", "nu": 0.33, "density": "2.81 g/cm^3"})
    assert custom.E == 72e9 and custom.density == pytest.approx(2810.0)
    with pytest.raises(InputError) as exc:
        flexure.material("Al 7057-T6")
    assert "did you mean 'Al 7075-T6'?" in str(exc.value)


# -- right-circular notch: the exact Euler-Bernoulli stiffness ---------------------------------


def _notch_integral_by_quadrature(t, r):
    """int_{-r}^{r} dx / h(x)^3 with h = t + 2 (r - sqrt(r^2 - x^2)), by adaptive quadrature."""
    from scipy.integrate import quad

    value, _ = quad(
        lambda x: (t + 2 * (r - math.sqrt(r * r - x * x))) ** -3, -r, r, epsrel=1e-13, limit=500, points=[0]
    )
    return value


@pytest.mark.parametrize("t, r", [(0.5e-3, 3e-3), (1e-3, 1e-3), (0.1e-3, 5e-3), (2e-3, 1e-3)])
def test_exact_circular_notch_against_quadrature(t, r):
    # Paros-Weisbord: k = E b / (12 int dx/h^3); the closed form must equal the integral
    E, b = 71.7e9, 6.5e-3
    k = flexure.circular_notch_stiffness_exact(E, b, t, r)
    assert k == pytest.approx(E * b / (12 * _notch_integral_by_quadrature(t, r)), rel=1e-11)


def test_simplified_notch_formula_is_the_thin_limit_of_the_exact_one():
    # k_simplified / k_exact -> 1 as t/r -> 0 (the simplified formula is its asymptote)
    E, b, r = 71.7e9, 6.5e-3, 3e-3
    ratios = [
        flexure.circular_notch_stiffness(E, b, t, r) / flexure.circular_notch_stiffness_exact(E, b, t, r)
        for t in (3e-4, 3e-5, 3e-6, 3e-7)
    ]
    assert all(a < b for a, b in zip(ratios, ratios[1:]))  # monotone towards 1 from below
    assert ratios[-1] == pytest.approx(1.0, abs=1e-3)


def test_prc3_table1_hinge_hand_values():
    # prc3-li-2018.md Table 1: E = 71.7 GPa (section 'Modal analysis'), b = 6.5 mm, t = 0.5 mm, R = 3 mm.
    # by hand: t^2.5 = 2.5e-7 * 0.0223607 = 5.59017e-9; 2 E b = 9.321e8; 9 pi sqrt(r) = 28.2743 * 0.0547723 = 1.548669
    #          k = 9.321e8 * 5.59017e-9 / 1.548669 = 3.36458 N m/rad
    k = flexure.circular_notch_stiffness(71.7e9, 6.5e-3, 0.5e-3, 3e-3)
    assert k == pytest.approx(3.36458, rel=2e-5)
    # exact (Paros-Weisbord) by hand: a = 6.5 mm, c = 6 mm, u = t (t + 4r) = 6.25e-6 m^2,
    # T = atan(sqrt(12.5 / 0.5)) = atan(5) = 1.3734008;
    # integral = 3 a c^2 T / u^2.5 + c (3 a^2 - u) / (2 a u^2)
    #          = 9.64133e-7 / 9.765625e-14 + 7.23e-7 / 5.078125e-13
    #          = 9.87266e6 + 1.42375e6 = 1.129642e7 m^-2;  k = E b / (12 integral) = 4.6605e8 / 1.355570e8 = 3.43804
    k_exact = flexure.circular_notch_stiffness_exact(71.7e9, 6.5e-3, 0.5e-3, 3e-3)
    assert k_exact == pytest.approx(3.43804, rel=1e-5)
    assert 1 - k / k_exact == pytest.approx(0.0214, abs=5e-4)  # the simplified formula is 2.1 % softer here


def test_exact_notch_accepts_casadi_symbols():
    t = ca.SX.sym("t")
    k = flexure.circular_notch_stiffness_exact(71.7e9, 6.5e-3, t, 3e-3)
    dk = ca.Function("dk", [t], [ca.jacobian(k, t)])
    h = 1e-9
    fd = (
        flexure.circular_notch_stiffness_exact(71.7e9, 6.5e-3, 0.5e-3 + h, 3e-3)
        - flexure.circular_notch_stiffness_exact(71.7e9, 6.5e-3, 0.5e-3 - h, 3e-3)
    ) / (2 * h)
    assert float(dk(0.5e-3)) == pytest.approx(fd, rel=1e-6)


@pytest.mark.parametrize(
    "t, r, message",
    [
        (
            4e-3,
            3e-3,
            "expected the notch thickness t (4 mm) to be at most the notch radius r (3 mm): the circular-notch "
            "formula k = 2 E b t^2.5 / (9 pi r^0.5) holds for t << r",
        ),
        (0.5e-3, 0.0, "expected a positive notch thickness t and radius r, got t = 0.0005, r = 0.0"),
        (-1e-3, 3e-3, "expected a positive notch thickness t and radius r, got t = -0.001, r = 0.003"),
    ],
)
def test_check_circular_notch(t, r, message):
    with pytest.raises(InputError) as exc:
        flexure.check_circular_notch(t, r, ("mechanism", "parameters", "t"))
    assert str(exc.value) == f"mechanism.parameters.t: {message}"
    flexure.check_circular_notch(3e-3, 3e-3)  # t = r is accepted


# -- materials as the papers give them --------------------------------------------------------


@pytest.mark.parametrize(
    "name, E, nu, density, yield_strength, allowable",
    [
        # prc3-li-2018.md 'Modal analysis'; prs3-ruiz.md section 5 (yield 503 MPa, 400 MPa design limit)
        ("Al 7075-T6", 71.7e9, 0.33, 2810.0, 503e6, 400e6),
        # pantograph-3d-elgammal-2016.md Table 1 (no density)
        ("Ti-6Al-4V", 113.8e9, 0.342, None, 880e6, None),
        # pantograph-3d-elgammal-2016.md section 5 (E and sigma_all only)
        ("polypropylene", 2e9, None, None, None, 23.5e6),
        # pantograph-3d-elgammal-2016.md section 8: the prototype's material, no properties given
        ("Flexible-T", None, None, None, None, None),
    ],
)
def test_materials_as_the_papers_give_them(name, E, nu, density, yield_strength, allowable):
    m = flexure.material(name)
    assert (m.E, m.nu, m.density, m.yield_strength, m.allowable) == (E, nu, density, yield_strength, allowable)
    assert m.source


def test_missing_material_property_is_an_input_error():
    with pytest.raises(InputError) as exc:
        flexure.material("Flexible-T").require("E", ("inputs", "material"), "the hinge stiffness needs it")
    assert str(exc.value) == (
        "inputs.material: material 'Flexible-T' has no Young's modulus E (the hinge stiffness needs it): no source "
        "gives it; give the material inline, e.g. {name: Flexible-T, E: ...}"
    )
    with pytest.raises(InputError, match="has no Poisson's ratio nu"):
        _ = flexure.material("polypropylene").G


def test_material_neither_name_nor_mapping():
    with pytest.raises(InputError) as exc:
        flexure.material(5, ("inputs", "material"))
    assert str(exc.value) == (
        "inputs.material: expected a material name (Al 7075-T6, Ti-6Al-4V, polypropylene, Flexible-T) or an "
        "inline mapping {E, nu, density, yield_strength}, got int 5"
    )
