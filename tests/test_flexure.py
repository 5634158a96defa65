"""Flexure-hinge formulas against hand-computed values."""

import math

import casadi as ca
import pytest

from cpm_nlp import flexure
from cpm_nlp.errors import InputError


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
