"""Natural frequencies with the six-axis hinge model and the links' masses
(cpm_nlp.analysis.link_masses, the ``natural_frequencies`` kind's ``hinge_axes: all``
and ``links``; issue 25 item 4c).

Independent checks: the platform on its hinges with the actuators held against the
compliance-matrix method written out in numpy from the paper's geometry; the legs'
kinetic energy against the slender bar's T = m/6 (v_A² + v_A·v_B + v_B²) from the end
velocities; the limit of stiff extra axes against the kinematic model; and modes that do
not depend on the basis of the closures' null space."""

from __future__ import annotations

import math

import numpy as np
import pytest
import scipy.linalg

from cpm_nlp.analysis import compliance as cm
from cpm_nlp.analysis import link_masses as lm
from cpm_nlp.analysis.hinge_chains import LegChains, SixAxisModel, six_axis_model
from cpm_nlp.mechanisms.registry import build_model
from cpm_nlp.problems.file import problem_from_dict, solve

PRS3 = {"b": "47.91 mm", "L": "109.215 mm", "alpha0": "45 deg"}
B, L, A0 = 47.91e-3, 109.215e-3, math.radians(45)
#: a 120 x 120 x 10 mm plate of Al 7075 (2810 kg/m^3) on the pose coordinates
PLATE = 2810.0 * 0.12 * 0.12 * 0.01
M_X = np.array([PLATE] * 3 + [PLATE * (0.12**2 + 0.01**2) / 12] * 2 + [PLATE * 2 * 0.12**2 / 12])


@pytest.fixture(scope="module")
def prs3():
    m = build_model("prs3", PRS3)
    hs = cm.hinge_set(m, None)
    sm = six_axis_model(m, hs)
    ok, z, lam, _ = sm.newton(sm.start(m.x_home, m.q_home), np.zeros(6), m.q_home, None, None)
    assert ok
    return m, hs, sm, z, lam


def _rz(angle):
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def _skew(r):
    return np.array([[0.0, -r[2], r[1]], [r[2], 0.0, -r[0]], [-r[1], r[0], 0.0]])


def _platform_stiffness(hs):
    """6 x 6 stiffness of the platform at P0 with the sliders held: each leg the series sum
    of its two hinges' six-axis compliances transported to P0, the legs in parallel
    (prs3-ruiz.md eq 2-3, section 4; hinge frames from the joints' axes)."""
    a, pz0 = B + L * math.cos(A0), L * math.sin(A0)
    P0 = np.array([0.0, 0.0, pz0])
    k6 = {h.name: cm.six_axis_stiffness(h) for h in hs.hinges}
    K = np.zeros((6, 6))
    for i in range(3):
        R = _rz(2 * math.pi * i / 3)
        Ai, Bi = R @ [a, 0.0, 0.0], R @ [B, 0.0, pz0]
        t = (Bi - Ai) / np.linalg.norm(Bi - Ai)
        y = R @ [0.0, 1.0, 0.0]
        m_ax, n_ax = R @ [0.0, -1.0, 0.0], R @ [math.sin(A0), 0.0, math.cos(A0)]
        C_leg = np.zeros((6, 6))
        for name, (tt, b1, b2), c in (
            (f"revolute{i + 1}", (t, y, np.cross(y, t)), Ai),
            (f"spherical{i + 1}", (t, m_ax, n_ax), Bi),
        ):
            k = k6[name]
            C = np.zeros((6, 6))
            C[:3, :3] = np.outer(tt, tt) / k["axial"] + np.outer(b2, b2) / k["shear"] + np.outer(b1, b1) / k["shear2"]
            C[3:, 3:] = np.outer(b1, b1) / k["bend"] + np.outer(b2, b2) / k["bend2"] + np.outer(tt, tt) / k["torsion"]
            W = np.eye(6)
            W[3:, :3] = _skew(P0 - c)
            C_leg += W.T @ C @ W
        K += np.linalg.inv(C_leg)
    return K


def test_held_actuators_give_the_compliance_matrix_methods_frequencies(prs3):
    """Platform masses only, sliders held: the six frequencies are those of
    |K_P - (2 pi f)^2 M_x| = 0 with K_P of the compliance-matrix method (numpy)."""
    m, hs, sm, z, lam = prs3
    M_z = np.zeros((sm.nz, sm.nz))
    M_z[:6, :6] = np.diag(M_X)
    modes = lm.six_axis_modes(sm, z, lam, M_z, None, held=True)
    expected = np.sqrt(scipy.linalg.eigh(_platform_stiffness(hs), np.diag(M_X), eigvals_only=True)) / (2 * math.pi)
    assert len(modes.frequencies) == 6  # only the platform has mass
    np.testing.assert_allclose(modes.frequencies, expected, rtol=1e-7)
    # the two lateral modes and the two tilts are repeated (the 120 deg symmetry), each pair canonical
    assert [len(c) for c in modes.clusters] == [2, 1, 1, 2]
    assert modes.modes_z[0, 0] == 0.0 and modes.modes_z[1, 1] == 0.0  # each pair's first mode has no px


def test_modes_do_not_depend_on_the_null_space_basis(prs3, monkeypatch):
    """Another orthonormal basis of the closures' null space gives the same frequencies and the
    same (canonical) modes: nothing depends on the basis LAPACK returns."""
    m, hs, sm, z, lam = prs3
    bodies = lm.link_bodies(
        sm,
        {"legs": {"leg": "leg", "after_joint": 2, "section": lm.LinkSection(0.01, 0.01)}},
        2810.0,
        ("inputs", "links"),
    )
    M_z = lm.link_mass_matrix(sm, bodies, z)
    M_z[:6, :6] += np.diag(M_X)
    first = lm.six_axis_modes(sm, z, lam, M_z, None, held=True)
    original = scipy.linalg.null_space
    rng = np.random.default_rng(7)

    def rotated(A):
        N = original(A)
        Q, _ = np.linalg.qr(rng.standard_normal((N.shape[1], N.shape[1])))
        return N @ Q

    monkeypatch.setattr(lm.scipy.linalg, "null_space", rotated)
    second = lm.six_axis_modes(sm, z, lam, M_z, None, held=True)
    np.testing.assert_allclose(second.frequencies, first.frequencies, rtol=1e-9)
    # per mode, to 1e-5 of its largest component: the legs' three nearly equal bending modes are
    # sensitive to round-off at that level (their frequencies differ by parts per million)
    scale = np.abs(first.modes_z).max(axis=0)
    assert np.all(np.abs(second.modes_z - first.modes_z) <= 1e-5 * scale)


def test_leg_masses_are_the_slender_bars_kinetic_energy(prs3):
    """Legs of mass m given without a section are slender bars: with the rigid kinematics their
    kinetic energy is m/6 (v_C² + v_C·v_B + v_B²) from the velocities of their ends, the slider
    point C_i (s_i along -u_i) and the platform point B_i (the platform's twist from J)."""
    m, hs, sm, z, lam = prs3
    mass = 0.05
    bodies = lm.link_bodies(sm, {"legs": {"leg": "leg", "after_joint": 2, "mass": mass}}, None, ("links",))
    T = lm.rigid_velocity_map(sm, z)
    Mq = T.T @ lm.link_mass_matrix(sm, bodies, z) @ T
    J = cm.static_point(m, hs, m.x_home, m.q_home).J
    pz0 = L * math.sin(A0)
    expected = np.zeros((3, 3))
    for i in range(3):
        R = _rz(2 * math.pi * i / 3)
        u = R @ [1.0, 0.0, 0.0]
        vC = np.zeros((3, 3))
        vC[:, i] = -u  # the slider moves towards the axis (prs3.yaml: axis [-1, 0, 0])
        # B_i = P + R_P b u_i: at home R_P = I and omega = (dpsi, dtheta, dphi) (R = Ry Rx Rz at 0)
        vB = J[:3] - _skew(B * u) @ J[3:]
        expected += mass / 3.0 * (vC.T @ vC + 0.5 * (vC.T @ vB + vB.T @ vC) + vB.T @ vB)
    assert pz0 > 0
    np.testing.assert_allclose(Mq, expected, rtol=1e-9, atol=1e-12)
    # the rigid velocity map's pose rows are the kinematic Jacobian
    np.testing.assert_allclose(T[:6], J, atol=1e-12)


def test_a_bar_of_the_material_weighs_density_times_volume(prs3):
    m, hs, sm, z, lam = prs3
    sec = lm.LinkSection(0.01, 0.01)
    (body, *_) = lm.link_bodies(sm, {"legs": {"leg": "leg1", "after_joint": 2, "section": sec}}, 2810.0, ("l",))
    mass, (It, I1, I2) = body.mass_inertia()
    assert body.length == pytest.approx(L, rel=1e-12)
    assert mass == pytest.approx(2810.0 * 1e-4 * L, rel=1e-12)  # 30.7 g, the paper's 10 x 10 mm^2 leg
    assert It == pytest.approx(mass * 2e-4 / 12) and I1 == pytest.approx(mass * (L**2 + 1e-4) / 12)
    rnd = lm.LinkSection(d=0.01)
    assert rnd.area() == pytest.approx(math.pi * 0.01**2 / 4)
    assert rnd.bar_inertia(1.0, 0.1) == pytest.approx((1e-4 / 8, 0.01 / 12 + 1e-4 / 16, 0.01 / 12 + 1e-4 / 16))


def _stiff(m, hs, scale):
    """The six-axis model with the extra axes' stiffness times ``scale``."""
    import cpm_nlp.analysis.hinge_chains as hc

    original = cm.six_axis_stiffness

    def scaled(h):
        out = original(h)
        return None if out is None else {a: (v if a in h.k else v * scale) for a, v in out.items()}

    hc.six_axis_stiffness = scaled
    try:
        return SixAxisModel(m, hs, m.mechanism.part(LegChains).of(m))
    finally:
        hc.six_axis_stiffness = original


def test_stiff_extra_axes_give_the_kinematic_models_frequencies(prs3):
    """Actuators free (k_actuator 0), every extra hinge axis 1e5 times stiffer (the error goes as 1/scale;
    beyond 1e6 round-off takes over): the three
    lowest six-axis frequencies with platform, slider and leg masses are the kinematic
    model's (the natural_frequencies kind with the same links)."""
    m, hs, _, _, _ = prs3
    sm = _stiff(m, hs, 1e5)
    ok, z, lam, _ = sm.newton(sm.start(m.x_home, m.q_home), np.zeros(6), m.q_home, None, None)
    assert ok
    links = {"legs": {"leg": "leg", "after_joint": 2, "section": lm.LinkSection(0.01, 0.01)}}
    bodies = lm.link_bodies(sm, links, 2810.0, ("links",))
    M_z = lm.link_mass_matrix(sm, bodies, z)
    M_z[:6, :6] += np.diag(M_X)
    M_z[6:9, 6:9] += np.diag([0.1] * 3)
    six = lm.six_axis_modes(sm, z, lam, M_z, np.zeros(3), held=False)
    res = solve(
        problem_from_dict(
            {
                "problem": "natural_frequencies",
                "mechanism": {"type": "prs3", "parameters": PRS3},
                "inputs": {
                    "masses": {
                        n: f"{v} kg" if k < 3 else f"{v} kg*m^2"
                        for k, (n, v) in enumerate(zip(["px", "py", "pz", "psi", "theta", "phi"], M_X))
                    }
                    | {"s1": "100 g", "s2": "100 g", "s3": "100 g"},
                    "links": {
                        "legs": {"leg": "leg", "after_joint": 2, "section": {"width": "10 mm", "height": "10 mm"}}
                    },
                },
            }
        )
    )
    assert res.ok and res.values["hinge_model"] == "kinematic"
    kin = [res.values[f"f{k}"] for k in (1, 2, 3)]
    np.testing.assert_allclose(six.frequencies[:3], kin, rtol=1e-5)
    assert res.values["link_masses"] == pytest.approx([2810.0 * 1e-4 * L] * 3)


def _problem(**inputs):
    return {"problem": "natural_frequencies", "mechanism": {"type": "prs3", "parameters": PRS3}, "inputs": inputs}


@pytest.mark.parametrize(
    ("inputs", "path", "words"),
    [
        ({"k_actuator": "rigid", "masses": {"pz": "1 kg"}}, ("inputs", "k_actuator"), "no motion left"),
        ({"hinge_axes": "all", "k_actuator": "rigid", "masses": {"s1": "1 kg"}}, ("inputs", "masses"), "held"),
        (
            {"masses": {"pz": "1 kg"}, "links": {"x": {"leg": "legs", "after_joint": 2, "mass": "1 g"}}},
            ("inputs", "links", "x", "leg"),
            "no leg named",
        ),
        (
            {"masses": {"pz": "1 kg"}, "links": {"s": {"leg": "leg", "after_joint": 1, "section": {"d": "5 mm"}}}},
            ("inputs", "links", "s", "section"),
            "no length",
        ),
        (
            {"masses": {"pz": "1 kg"}, "links": {"s": {"leg": "leg", "after_joint": 4, "mass": "1 g"}}},
            ("inputs", "links", "s", "after_joint"),
            "has 3 joints",
        ),
    ],
)
def test_bad_frequency_inputs_are_named(inputs, path, words):
    from cpm_nlp.core.errors import InputError

    with pytest.raises(InputError) as err:
        solve(problem_from_dict(_problem(**inputs)))
    assert err.value.path == path and words in err.value.message


def test_the_shipped_six_axis_file_reports_its_model():
    """The shipped file: the six-axis model named, 30.7 g legs, a repeated sway pair below the
    spin and the vertical mode (consistency with the plate's symmetry, no published value)."""
    from pathlib import Path

    from cpm_nlp.problems.file import load_problem

    root = Path(__file__).resolve().parents[2]
    res = solve(load_problem(root / "problems" / "prs3_natural_frequencies_six_axis.yaml"))
    v = res.values
    assert res.ok and v["hinge_model"] == "all" and v["n_modes"] == 24
    assert v["link_masses"] == pytest.approx([2810.0 * 1e-4 * L] * 3)
    assert v["f1"] == v["f2"] < v["f3"] < v["f4"] and v["multiplicity"][:2] == [2, 2]
    assert "six-axis hinge model (actuators held)" in res.message
