"""Six-axis notch compliances (cpm_nlp.analysis.flexure_compliance) against adaptive
quadrature of the Lobontiu integrals, the Paros-Weisbord closed form, AD
against central differences, and the U joint as two notches in series."""

import casadi as ca
import numpy as np
import pytest
from scipy.integrate import quad

from cpm_nlp.analysis import flexure
from cpm_nlp.analysis import flexure_compliance as fc

AL = flexure.MATERIALS["Al 7075-T6"]


def reference(E, G, b, t, r):
    def th(x):
        return t + 2 * (r - np.sqrt(r * r - x * x))

    def q(f):
        return quad(f, -r, r, epsabs=0, epsrel=1e-13, limit=400)[0]

    return {
        "x": q(lambda x: 1 / (E * b * th(x))),
        "rz": q(lambda x: 12 / (E * b * th(x) ** 3)),
        "ry": q(lambda x: 12 / (E * th(x) * b**3)),
        "y": q(lambda x: 12 * x * x / (E * b * th(x) ** 3) + 1.2 / (G * b * th(x))),
        "z": q(lambda x: 12 * x * x / (E * th(x) * b**3) + 1.2 / (G * b * th(x))),
        "rx": q(lambda x: 1 / (G * fc.rectangle_torsion_constant(b, th(x)))),
    }


@pytest.mark.parametrize(
    "r, t, b", [(4e-3, 0.4e-3, 12e-3), (1e-3, 0.4e-3, 12e-3), (6e-3, 0.3e-3, 15e-3), (0.5e-3, 2e-3, 12e-3)]
)
def test_notch_compliances_match_adaptive_quadrature(r, t, b):
    got = fc.circular_notch_compliances(AL.E, AL.G, b, t, r)
    ref = reference(AL.E, AL.G, b, t, r)
    for key, value in ref.items():
        assert got[key] == pytest.approx(value, rel=1e-9), key


def test_rotational_compliance_tends_to_paros_weisbord():
    # k = 2 E b t^2.5 / (9 pi r^0.5) is the t << r limit (flexure.circular_notch_stiffness)
    b, t = 10e-3, 0.1e-3
    ratios = [
        fc.circular_notch_compliances(AL.E, AL.G, b, t, r)["rz"] * flexure.circular_notch_stiffness(AL.E, b, t, r)
        for r in (1e-3, 10e-3, 100e-3)  # r/t = 10, 100, 1000
    ]
    assert ratios == pytest.approx([0.98726, 0.99875, 0.99987], abs=1e-5)  # error ~ 1.3 t/r


def test_compliance_gradient_matches_central_differences():
    z = ca.SX.sym("z", 3)
    c = fc.circular_notch_compliances(AL.E, AL.G, z[0], z[1], z[2])
    out = ca.vertcat(*c.values())
    f = ca.Function("c", [z], [out])
    jac = ca.Function("dc", [z], [ca.jacobian(out, z)])
    z0 = np.array([12e-3, 0.4e-3, 4e-3])
    J = np.asarray(jac(z0))
    h = 1e-9
    for k in range(3):
        dz = np.zeros(3)
        dz[k] = h
        fd = (np.asarray(f(z0 + dz)) - np.asarray(f(z0 - dz))).ravel() / (2 * h)
        assert np.allclose(J[:, k], fd, rtol=1e-5), k


def test_r_joint_frame_puts_the_rotation_about_y():
    C = fc.r_joint_compliance(AL.E, AL.G, 12e-3, 0.4e-3, 4e-3, axis="y")
    c = fc.circular_notch_compliances(AL.E, AL.G, 12e-3, 0.4e-3, 4e-3)
    assert np.allclose(np.diag(C), [c["y"], c["z"], c["x"], c["ry"], c["rz"], c["rx"]])
    assert np.allclose(C, np.diag(np.diag(C)))


def test_u_joint_is_two_orthogonal_notches_in_series():
    h, t, r = 12e-3, 0.4e-3, 1e-3
    C = fc.u_joint_compliance(AL.E, AL.G, h, t, r)
    c = fc.circular_notch_compliances(AL.E, AL.G, h, t, r)
    assert np.allclose(C, C.T)
    # both working rotations, torsion doubled, axial doubled
    assert C[3, 3] == pytest.approx(c["rz"] + c["ry"])
    assert C[4, 4] == pytest.approx(c["rz"] + c["ry"])
    assert C[5, 5] == pytest.approx(2 * c["rx"])
    assert C[2, 2] == pytest.approx(2 * c["x"])
    # a force across the rod at the centre bends the other notch over the arm r
    assert C[0, 0] == pytest.approx(c["y"] + c["z"] + r**2 * (c["rz"] + c["ry"]))
    # the same as transporting the summed matrix: the work of any wrench is positive
    w = np.array([1.0, -0.5, 0.3, 0.01, 0.02, -0.01])
    assert w @ C @ w > 0
    assert np.allclose(C, fc.u_joint_compliance(AL.E, AL.G, h, t, r, spacing=2 * r))


def test_eq32_rotation_limit():
    # r sigma_Y / (E t SF); Table 1's R joint (r/t = 10) allows 2.01 deg with SF = 2
    theta = fc.rotation_limit_eq32(AL.E, 0.4e-3, 4e-3, AL.yield_strength, 2.0)
    assert np.degrees(theta) == pytest.approx(2.0098, abs=1e-3)
    # the printed form, term by term: linear in r and sigma_Y, inverse in E, t and SF
    assert theta == pytest.approx(4e-3 * AL.yield_strength / (AL.E * 0.4e-3 * 2.0), rel=1e-15)
    assert fc.rotation_limit_eq32(AL.E, 0.4e-3, 4e-3, AL.yield_strength, 4.0) == pytest.approx(theta / 2)
    assert fc.rotation_limit_eq32(AL.E, 0.8e-3, 4e-3, AL.yield_strength, 2.0) == pytest.approx(theta / 2)
