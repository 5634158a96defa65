"""Flexible beam elements (cpm_nlp.analysis.beams) against independent derivations:
the Euler-Bernoulli and Timoshenko cantilever closed forms (6 x 6), the elastica under a
dead end load (solved here by shooting with scipy), the circle of radius EI/M under an end
moment, Lobontiu's notch integrals, and AD against central differences."""

from __future__ import annotations

import casadi as ca
import numpy as np
import pytest
import scipy.integrate
import scipy.optimize

from cpm_nlp.analysis.beams import BeamChain, BeamSpec, Section, element_compliance
from cpm_nlp.analysis.flexure_compliance import circular_notch_compliances

E, NU = 72e9, 0.33
G = E / (2 * (1 + NU))
B, H, L = 10e-3, 4e-3, 0.1


def _chain(theory="timoshenko", n=4, model="distributed", section=None, length=L):
    sec = section if section is not None else Section("rectangle", {"b": B, "h": H})
    spec = BeamSpec("beam", sec, theory, n, (model,))
    return BeamChain(spec, np.zeros(3), np.array([length, 0.0, 0.0]), E, NU, np.array([0.0, 1.0, 0.0]))


def _closed_form(theory: str) -> np.ndarray:
    """The cantilever's tip compliance, x along the beam, y the compliant axis (I_y = b h^3/12,
    deflection along z), written out (Gere and Timoshenko, Mechanics of Materials; Cowper's kappa)."""
    A, Iy, Iz = B * H, B * H**3 / 12, H * B**3 / 12
    a, c = max(B, H), min(B, H)
    J = a * c**3 * (1 / 3 - 0.21 * (c / a) * (1 - (c / a) ** 4 / 12))  # Roark Table 10.7 case 4
    kappa = 10 * (1 + NU) / (12 + 11 * NU)
    shear = 0.0 if theory == "euler_bernoulli" else L / (kappa * G * A)
    C = np.zeros((6, 6))
    C[0, 0] = L / (E * A)
    C[1, 1] = L**3 / (3 * E * Iz) + shear  # F_y bends about z
    C[2, 2] = L**3 / (3 * E * Iy) + shear  # F_z bends about y
    C[3, 3] = L / (G * J)
    C[4, 4] = L / (E * Iy)
    C[5, 5] = L / (E * Iz)
    C[1, 5] = C[5, 1] = L**2 / (2 * E * Iz)  # F_y turns the tip about +z
    C[2, 4] = C[4, 2] = -(L**2) / (2 * E * Iy)  # F_z turns it about -y
    return C


@pytest.mark.parametrize("theory", ["euler_bernoulli", "timoshenko"])
@pytest.mark.parametrize("n", [1, 3])
def test_distributed_elements_give_the_cantilever_closed_form(theory, n):
    C = _chain(theory, n).linear_compliance()
    ref = _closed_form(theory)
    np.testing.assert_allclose(C, ref, rtol=1e-10, atol=1e-12 * np.max(np.abs(ref)))


@pytest.mark.parametrize("theory", ["euler_bernoulli", "timoshenko"])
def test_lumped_elements_converge_to_the_closed_form(theory):
    ref = _closed_form(theory)
    errs = []
    for n in (2, 4, 8, 16):
        C = _chain(theory, n, "lumped").linear_compliance()
        errs.append(abs(C[2, 2] / ref[2, 2] - 1))
        np.testing.assert_allclose(np.diag(C)[[0, 3, 4, 5]], np.diag(ref)[[0, 3, 4, 5]], rtol=1e-12)
    # the midpoint rule: the bending deflection's error falls as 1/n^2 (x4 per halving)
    ratios = [errs[k] / errs[k + 1] for k in range(3)]
    assert all(3.5 < r < 4.5 for r in ratios), ratios
    assert errs[-1] < 1e-3


def _elastica(P: float, EI: float, length: float) -> tuple[float, float, float]:
    """The inextensible elastica of a cantilever under a dead tip force P normal to its
    undeformed axis: EI theta'' = -P cos(theta), theta(0) = 0, theta'(L) = 0, shot on theta'(0)."""

    def rhs(_s, y):
        th, dth, _, _ = y
        return [dth, -P / EI * np.cos(th), np.cos(th), np.sin(th)]

    def end(k0):
        sol = scipy.integrate.solve_ivp(rhs, (0, length), [0, k0, 0, 0], rtol=1e-12, atol=1e-14)
        return sol.y[:, -1]

    k0 = scipy.optimize.brentq(lambda k: end(k)[1], 1e-9, P * length / EI * 1.0001, xtol=1e-15)
    th, _, x, y = end(k0)
    return x, y, th


def test_large_deflection_converges_to_the_elastica():
    EIz = E * H * B**3 / 12
    P = 2.0 * EIz / L**2  # P L^2 / EI = 2: a tip rotation of 0.78 rad
    x_ref, y_ref, th_ref = _elastica(P, EIz, L)
    assert th_ref > 0.75  # large: 45 degrees
    errs = []
    for n in (4, 8, 16, 32):
        # the elastica is inextensible: an axially (near) rigid section of the same I_z
        sec = Section("given", {"A": 1e6 * B * H, "I": B * H**3 / 12, "I2": H * B**3 / 12})
        bc = _chain("euler_bernoulli", n, section=sec)
        ok, eps = bc.solve([0.0, P, 0.0])
        assert ok
        p, R = bc.tip(eps)
        th = np.arctan2(R[1, 0], R[0, 0])
        errs.append(max(abs(p[0] - x_ref), abs(p[1] - y_ref)) / L)
        assert abs(p[2]) < 1e-15
    # converging with the number of elements, about as 1/n^2
    assert all(3.0 < errs[k] / errs[k + 1] < 5.0 for k in range(3)), errs
    assert errs[-1] < 2e-4
    assert abs(th - th_ref) < 1e-3


@pytest.mark.parametrize("model", ["distributed", "lumped"])
def test_end_moment_bends_into_a_circle_of_radius_EI_over_M(model):
    EIz = E * H * B**3 / 12
    M = np.pi / 2 * EIz / L  # a quarter circle: L / rho = pi/2
    rho = EIz / M
    x_ref, y_ref = rho * np.sin(L / rho), rho * (1 - np.cos(L / rho))
    errs = []
    for n in (8, 16, 32):
        bc = _chain("timoshenko", n, model)
        ok, eps = bc.solve([0.0, 0.0, 0.0], M)
        assert ok
        p, R = bc.tip(eps)
        assert np.arctan2(R[1, 0], R[0, 0]) == pytest.approx(np.pi / 2, abs=1e-12)  # exact for every n
        errs.append(np.hypot(p[0] - x_ref, p[1] - y_ref) / L)
    assert errs[0] > errs[1] > errs[2]
    assert errs[-1] < 5e-4


@pytest.mark.parametrize("w", [10e-3, 20e-3])
def test_notch_as_a_beam_matches_lobontius_integrals(w):
    """A right-circular notch as a beam of varying section (t(x) = t + 2(r - sqrt(r^2 - x^2))),
    distributed elements, its compliance carried to the notch centre, against
    circular_notch_compliances (Lobontiu 2002 ch. 2, shear coefficient 6/5).  Torsion only where
    Lobontiu's formula holds, t + 2r <= w (it takes the width as the rectangle's long side; the
    beam takes the longer side at each section)."""
    t, r = 2e-3, 8e-3
    sec = Section("circular_notch", {"t": t, "r": r, "w": w, "kappa": 5 / 6})
    ref = circular_notch_compliances(E, G, w, t, r)
    for n in (8, 32):
        C = _chain("timoshenko", n, section=sec, length=2 * r).linear_compliance()
        # to the centre c = tip - r e_x, rigid with the tip: w_tip = T w_c, (delta, theta)_c = T^T (delta, theta)_tip
        Ad = np.eye(6)
        Ad[:3, 3:] = np.array([[0, 0, 0], [0, 0, -r], [0, r, 0]])  # -[c - tip]x
        Cc = Ad @ C @ Ad.T
        got = {"x": Cc[0, 0], "z": Cc[1, 1], "y": Cc[2, 2], "rx": Cc[3, 3], "rz": Cc[4, 4], "ry": Cc[5, 5]}
        # (the beam's y is the notch's rotation axis z: the names swap)
        for key, val in got.items():
            if key == "rx" and t + 2 * r > w:
                continue
            assert val == pytest.approx(ref[key], rel=1e-6), (n, key)
        assert abs(Cc[2, 4]) < 1e-12 * abs(Cc[4, 4]) * r  # symmetric: no coupling at the centre


def test_element_compliance_is_differentiable_in_the_section():
    """Exact AD of the element compliance with respect to a section dimension (a design
    variable), against central differences."""
    h = ca.SX.sym("h")
    C, _ = element_compliance(Section("rectangle", {"b": B, "h": h}), E, NU, 0.0, L, L / 2, "timoshenko", "distributed")
    f = ca.Function("c", [h], [ca.reshape(C, 36, 1)])
    J = np.array(ca.Function("dc", [h], [ca.jacobian(ca.reshape(C, 36, 1), h)])(H), dtype=float).ravel()
    d = 1e-7 * H
    fd = (np.array(f(H + d)) - np.array(f(H - d))).ravel() / (2 * d)
    np.testing.assert_allclose(J, fd, rtol=1e-6, atol=1e-9 * np.max(np.abs(fd)))


def test_tip_jacobian_against_central_differences():
    bc = _chain("timoshenko", 3)
    rng = np.random.default_rng(0)
    eps = 1e-3 * rng.standard_normal(bc.n)
    J = np.array(bc._jac(eps), dtype=float)
    fd = np.zeros_like(J)
    for i in range(bc.n):
        d = np.zeros(bc.n)
        d[i] = 1e-6
        p1, R1 = bc.tip(eps + d)
        p0, R0 = bc.tip(eps - d)
        fd[:3, i] = (p1 - p0) / 2e-6
        Rv = lambda R: 0.5 * np.array([R[2, 1] - R[1, 2], R[0, 2] - R[2, 0], R[1, 0] - R[0, 1]])  # noqa: E731
        fd[3:, i] = (Rv(R1) - Rv(R0)) / 2e-6
    np.testing.assert_allclose(J, fd, rtol=1e-6, atol=1e-8)


def test_a_leg_as_beam_elements_against_the_3d_finite_element_reference():
    """The 3-PRS leg (10 x 10 mm^2, 109 mm, Al 7075-T6) as 4 Timoshenko elements, against the
    stored 3-D finite-element cantilever (scikit-fem, quadratic hexahedra, Richardson-extrapolated;
    tests/data/notch_fem_reference.json "leg", regenerated by benchmarks/bench_notch_fem.py): every
    entry of the 6 x 6 tip compliance within 1 % (the 3-D clamp stops the Poisson contraction and
    the warping at the base: 0.993 to 0.999 times the beam's), the zeros zero."""
    import json
    from pathlib import Path

    ref = json.loads((Path(__file__).parents[1] / "data" / "notch_fem_reference.json").read_text())
    leg, mat = ref["leg"], ref["material"]
    C3d = np.array(leg["C"])
    spec = BeamSpec("leg", Section("rectangle", {"b": leg["a"], "h": leg["b"]}), "timoshenko", 4, ("distributed",))
    chain = BeamChain(spec, np.zeros(3), np.array([leg["L"], 0.0, 0.0]), mat["E"], mat["nu"], np.array([0.0, 1.0, 0.0]))
    C = chain.linear_compliance()
    big = np.abs(C3d) > 1e-9 * np.abs(C3d).max()
    assert np.array_equal(big, np.abs(C) > 1e-9 * np.abs(C).max())  # the same couplings
    np.testing.assert_allclose(C3d[big], C[big], rtol=0.01)
    assert np.all(C3d[big] / C[big] < 1.0)  # the clamp only stiffens
