"""Natural frequencies with flexible bodies (the six-axis model's ``hinge_axes: all`` with
``bodies``; issue 25): the beams' element variables and strain energy in the six-axis model,
their element masses (consistent or lumped) in M_z.

Independent checks: the element's consistent mass matrix against the textbook one (written
out); a leg's beam clamped at its first joint and free at the platform against the
Euler-Bernoulli cantilever frequencies (beta_n L = 1.8751, 4.6941), converging with the
element count (consistent mass from above, lumped from below); a very stiff beam against
the rigid link of the same bar (the error going as 1/E); modes that do not depend on the
basis of the closures' null space; bad input named."""

from __future__ import annotations

import math

import numpy as np
import pytest
import scipy.linalg

from cpm_nlp.analysis import compliance as cm
from cpm_nlp.analysis import link_masses as lm
from cpm_nlp.analysis.beams import Section, element_mass
from cpm_nlp.analysis.hinge_chains import six_axis_model
from cpm_nlp.core.errors import InputError
from cpm_nlp.mechanisms.registry import build_model
from cpm_nlp.problems.file import problem_from_dict, solve

PRS3 = {"b": "47.91 mm", "L": "109.215 mm", "alpha0": "45 deg"}
L = 109.215e-3  # the legs C_iB_i, prs3-ruiz.md section 4
E, NU, RHO = 72e9, 0.33, 2810.0  # Al 7075 of the prs3 mechanism file
#: a 120 x 120 x 10 mm plate of the material on the pose coordinates
MASSES = {
    "px": {"length": "120 mm", "width": "120 mm", "height": "10 mm"},
    "py": {"length": "120 mm", "width": "120 mm", "height": "10 mm"},
    "pz": {"length": "120 mm", "width": "120 mm", "height": "10 mm"},
    "psi": {"length": "120 mm", "width": "120 mm", "height": "10 mm", "about": "x"},
    "theta": {"length": "120 mm", "width": "120 mm", "height": "10 mm", "about": "y"},
    "phi": {"length": "120 mm", "width": "120 mm", "height": "10 mm", "about": "z"},
}


def _legs(n, model="distributed", theory="euler_bernoulli", h="5 mm", E_text="72 GPa"):
    material = {"E": E_text, "nu": NU, "density": "2810 kg/m^3"}
    section = {"b": "10 mm", "h": h}
    spec = {"between": ["alpha", "beta_m"], "section": section, "elements": n, "stiffness": model, "beam": theory}
    return {"leg": spec | {"material": material}}


def test_consistent_mass_is_the_textbooks():
    """A prismatic Euler-Bernoulli element: the consistent mass over (v_0, ω_0, v_1, ω_1) is the
    textbook one, rho A l/420 [156, 22l, 54, -13l; 4l^2, 13l, -3l^2; 156, -22l; 4l^2] in each
    bending plane (the sign of l flips in the x-z plane, dw/ds = -theta_y), rho A l/6 [2, 1; 1, 2]
    axially and rho I_p l/6 [2, 1; 1, 2] in torsion (written out here); lumped: m/2 and I_p l/2."""
    b, h, ell = 0.01, 0.005, 0.02
    sec = Section("rectangle", {"b": b, "h": h})
    M = element_mass(sec, RHO, NU, 0.0, ell, 0.0, "euler_bernoulli", "distributed")
    m, ip = RHO * b * h * ell, RHO * (b * h**3 + h * b**3) / 12 * ell
    bend = (
        m
        / 420
        * np.array(
            [
                [156, 22 * ell, 54, -13 * ell],
                [22 * ell, 4 * ell**2, 13 * ell, -3 * ell**2],
                [54, 13 * ell, 156, -22 * ell],
                [-13 * ell, -3 * ell**2, -22 * ell, 4 * ell**2],
            ]
        )
    )
    flip = np.diag([1.0, -1.0, 1.0, -1.0])
    two = np.array([[2.0, 1.0], [1.0, 2.0]]) / 6
    np.testing.assert_allclose(M[np.ix_([1, 5, 7, 11], [1, 5, 7, 11])], bend, rtol=1e-12, atol=1e-20)
    np.testing.assert_allclose(M[np.ix_([2, 4, 8, 10], [2, 4, 8, 10])], flip @ bend @ flip, rtol=1e-12, atol=1e-20)
    np.testing.assert_allclose(M[np.ix_([0, 6], [0, 6])], m * two, rtol=1e-12)
    np.testing.assert_allclose(M[np.ix_([3, 9], [3, 9])], ip * two, rtol=1e-12)
    lumped = element_mass(sec, RHO, NU, 0.0, ell, 0.0, "euler_bernoulli", "lumped")
    np.testing.assert_allclose(np.diag(lumped), [m / 2] * 3 + [ip / 2, 0, 0] + [m / 2] * 3 + [ip / 2, 0, 0])
    assert np.count_nonzero(lumped - np.diag(np.diag(lumped))) == 0


def _cantilever(n, model):
    """The lowest four frequencies of leg 1's beam clamped at its first joint (every other variable
    of the six-axis model held) and free at the platform: H and M_z on its element variables."""
    m = build_model("prs3", PRS3)
    sm = six_axis_model(m, cm.hinge_set(m, None, bodies=_legs(n, model)))
    ok, z, lam, _ = sm.newton(sm.start(m.x_home, m.q_home), np.zeros(6), m.q_home, None, None)
    assert ok
    H, _ = sm.linearization(z, lam)
    M = sm.beam_mass_matrix(z)
    idx = [i for _, ix in sm.beams[0][2] for i in ix]
    w2 = scipy.linalg.eigh(H[np.ix_(idx, idx)], M[np.ix_(idx, idx)], eigvals_only=True)
    return np.sqrt(w2[:4]) / (2 * math.pi)


def _euler_bernoulli():
    """The Euler-Bernoulli cantilever, f = (beta_n L)^2 / (2 pi L^2) sqrt(EI / rho A), beta_n L =
    1.875104, 4.694091 (Blevins, Formulas for natural frequency and mode shape, Table 8-1), in the
    two bending planes of the 10 x 5 mm section: the lowest four (axial and torsion lie above)."""
    b, h = 0.01, 0.005
    out = []
    for inertia in (b * h**3 / 12, h * b**3 / 12):
        out += [bl**2 / (2 * math.pi * L**2) * math.sqrt(E * inertia / (RHO * b * h)) for bl in (1.875104, 4.694091)]
    return np.sort(out)


def test_a_legs_beam_converges_to_the_euler_bernoulli_cantilever():
    expected = _euler_bernoulli()
    consistent = [_cantilever(n, "distributed") / expected - 1 for n in (2, 4, 8)]
    lumped = [_cantilever(n, "lumped") / expected - 1 for n in (2, 4, 8)]
    # the consistent mass converges from above (a Rayleigh-Ritz bound), as h^4: 4.8e-4, 3.3e-5, 2.2e-6
    # on the first mode, 8.0e-5 on the second in each plane with 8 elements
    assert all(np.all(e > 0) for e in consistent)
    np.testing.assert_allclose([consistent[0][0] / consistent[1][0], consistent[1][0] / consistent[2][0]], 16, rtol=0.1)
    assert np.max(consistent[2]) < 1e-4 and consistent[2][0] < 3e-6
    # the lumped mass: the first mode from below, as h^2 (-6.4 %, -1.7 %, -0.41 %)
    assert all(e[0] < 0 for e in lumped)
    np.testing.assert_allclose([lumped[0][0] / lumped[1][0], lumped[1][0] / lumped[2][0]], 4, rtol=0.05)
    assert np.all(np.abs(lumped[2]) < np.abs(lumped[1])) and np.max(np.abs(lumped[2])) < 5e-3


def _frequencies(inputs, n=12):
    problem = {"problem": "natural_frequencies", "mechanism": {"type": "prs3", "parameters": PRS3}}
    res = solve(problem_from_dict(problem | {"inputs": {"hinge_axes": "all", "masses": MASSES, "n_modes": n} | inputs}))
    assert res.ok, res.message
    return res, np.array([res.values[f"f{k}"] for k in range(1, n + 1)])


def test_very_stiff_legs_give_the_rigid_links_frequencies():
    """Sliders free, plate masses: a Timoshenko beam 10, 30 and 120 times stiffer than Al 7075 (the
    same 10 x 10 mm bar of 2810 kg/m^3) against the rigid link of that bar (``links``).  The
    consistent mass moves a rigid bar exactly, so the difference is the legs' compliance alone,
    a smooth function of 1/E: its extrapolation to 1/E = 0 (the quadratic through the three) is
    the rigid link's.  (120 x 72 GPa is near the inputs' sanity limit of 1e7 MPa.)"""
    links = {"legs": {"leg": "leg", "after_joint": 2, "section": {"width": "10 mm", "height": "10 mm"}}}
    _, rigid = _frequencies({"links": links})
    scales = (10, 30, 120)
    flex = []
    for scale in scales:
        res, f = _frequencies({"bodies": _legs(2, theory="timoshenko", h="10 mm", E_text=f"{72 * scale} GPa")})
        assert res.values["hinge_model"] == "all" and "flexible bodies (leg) are beams with consistent" in res.message
        flex.append(f)
    errors = [f / rigid - 1 for f in flex]
    assert all(np.all(e < 0) for e in errors)  # a flexible leg only lowers them
    # first order in 1/E: 2.8 %, 0.92 %, 0.23 % on the second mode
    assert np.all(np.abs(errors[2]) < np.abs(errors[1]) / 3.5) and np.max(np.abs(errors[2])) < 1e-2
    extrapolated = np.linalg.solve(np.vander(1.0 / np.array(scales), 3), np.array(flex))[2]
    np.testing.assert_allclose(extrapolated, rigid, rtol=5e-5)  # 1.5e-5 at most


def test_modes_with_flexible_legs_do_not_depend_on_the_null_space_basis(monkeypatch):
    """Another orthonormal basis of the closures' null space: the same frequencies and canonical modes."""
    m = build_model("prs3", PRS3)
    sm = six_axis_model(m, cm.hinge_set(m, None, bodies=_legs(2, theory="timoshenko", h="10 mm")))
    ok, z, lam, _ = sm.newton(sm.start(m.x_home, m.q_home), np.zeros(6), m.q_home, None, None)
    assert ok
    M_z = sm.beam_mass_matrix(z)
    M_z[:6, :6] += np.diag([0.4, 0.4, 0.4, 5e-4, 5e-4, 1e-3])
    first = lm.six_axis_modes(sm, z, lam, M_z, None, held=True)
    original = scipy.linalg.null_space
    rng = np.random.default_rng(11)

    def rotated(A):
        N = original(A)
        Q, _ = np.linalg.qr(rng.standard_normal((N.shape[1], N.shape[1])))
        return N @ Q

    monkeypatch.setattr(lm.scipy.linalg, "null_space", rotated)
    second = lm.six_axis_modes(sm, z, lam, M_z, None, held=True)
    np.testing.assert_allclose(second.frequencies, first.frequencies, rtol=1e-9)
    # per mode, to 1e-5 of its largest component, the 40 lowest (to 21 kHz): above, the three legs'
    # axial modes near 32 kHz split by 1.6e-6 of their frequency, and round-off mixes them at 5e-5
    scale = np.abs(first.modes_z[:, :40]).max(axis=0)
    assert np.all(np.abs(second.modes_z[:, :40] - first.modes_z[:, :40]) <= 1e-5 * scale)
    # the 120 deg symmetry: the lowest sway pair is repeated, and reported as one cluster
    assert len(first.clusters[0]) == 2


@pytest.mark.parametrize(
    ("inputs", "path", "words"),
    [
        (
            {
                "bodies": {
                    "leg": {
                        "between": ["alpha", "beta_m"],
                        "section": {"b": "10 mm", "h": "10 mm"},
                        "material": {"E": "72 GPa", "nu": 0.33},
                    }
                }
            },
            ("inputs", "bodies", "leg", "material"),
            "density",
        ),
        (
            {
                "bodies": _legs(1),
                "links": {"legs": {"leg": "leg", "after_joint": 2, "section": {"width": "10 mm", "height": "10 mm"}}},
            },
            ("inputs", "links"),
            "flexible body leg",
        ),
    ],
)
def test_bad_flexible_frequency_inputs_are_named(inputs, path, words):
    problem = {"problem": "natural_frequencies", "mechanism": {"type": "prs3", "parameters": PRS3}}
    with pytest.raises(InputError) as err:
        solve(problem_from_dict(problem | {"inputs": {"hinge_axes": "all", "masses": MASSES} | inputs}))
    assert err.value.path == path and words in err.value.message
