"""3D compliant pantograph (pantograph-3d-elgammal-2016.md): loop closures (eq 1-8),
magnification and Jacobian (eq 9-13), manipulability (eq 16), hinge angle (eq 17),
FK against IK, AD Jacobians against central differences."""

import math

import numpy as np
import pytest

import cpm_nlp as cn
from cpm_nlp.core.result import Status
from cpm_nlp.mechanisms.pantograph import analysis as P
from tests.mechanisms.prs3.test_prs3_kinematics import central_difference

NEWTON = cn.SolverConfig(method="newton")
IPOPT = cn.SolverConfig(method="ipopt")

#: section 5: a = 20 mm, b = 50 mm, the printed limits psi = 1.49 / 1.65 rad, phi_max = 0.0795 rad
PAPER = {"a": "20 mm", "b": "50 mm"}
PAPER_LIMITS = {"psi_min": "1.49 rad", "psi_max": "1.65 rad", "phi_max": "0.0795 rad"}
GEOMETRIES = [(0.02, 0.05), (0.015, 0.03), (0.01, 0.056948), (0.02, 0.02), (0.03, 0.01)]


@pytest.fixture(scope="module")
def panto():
    return cn.build_model("pantograph", PAPER, PAPER_LIMITS)


def at(model, x, *names):
    """The values of the named pose coordinates of x (the file's twelve, by name)."""
    return np.array([x[model.closure.x_names.index(n)] for n in names])


def pose(model, **values):
    """A pose of the file's coordinates: home, with the named ones set."""
    x = model.x_home.copy()
    for n, v in values.items():
        x[model.closure.x_names.index(n)] = v
    return x


def rigid(a, b):
    return cn.build_model("pantograph", {"a": a, "b": b})


def random_q(model, rng, n, spread=0.25):
    """Actuator positions around home: |AB| within +-spread*|AB0|, mild angles."""
    a = model.parameters["a"]
    r = math.sqrt(2) * a * (1 + spread * rng.uniform(-1, 1, n))
    phi = rng.uniform(-0.3, 0.3, n)
    m = rng.uniform(-0.3, 0.3, n)
    return np.column_stack([r * np.cos(m) * np.cos(phi), -r * np.sin(m), r * np.cos(m) * np.sin(phi)])


def test_home_configuration(panto):
    # section 8: the flexures are undeflected at the middle of the strokes; eq 31: psi = pi/2 there
    a, b = 0.02, 0.05
    np.testing.assert_allclose(panto.q_home, [math.sqrt(2) * a, 0, 0], rtol=1e-15)
    np.testing.assert_allclose(
        at(panto, panto.x_home, "px", "py", "pz", "theta1", "theta2", "phi"),
        [math.sqrt(2) * (a + b), 0, 0, math.pi / 4, -math.pi / 4, 0],
        atol=1e-16,
    )
    assert np.max(np.abs(cn.residual(panto, panto.x_home, panto.q_home))) < 1e-15  # m (assembled from the drawing)
    assert cn.passive_joints(panto, panto.x_home, panto.q_home)["psi"] == pytest.approx(math.pi / 2, abs=1e-15)
    # section 8: the prototype's dx runs 28.234 ... 28.334 mm around sqrt(2) * 20 mm = 28.284 mm
    assert panto.derived["dx0"] == pytest.approx(0.5 * (28.234e-3 + 28.334e-3), abs=1e-6)


@pytest.mark.parametrize("a, b", GEOMETRIES)
def test_magnification_from_ad_matches_eq_9_10(a, b):
    """Mx, My, Mz are read off the AD Jacobian of the loops at home (Model.derived);
    eq 9-10 give Mx = 1 + b/a, My = Mz = b/a."""
    m = rigid(a, b)
    assert m.derived["Mx"] == pytest.approx(1 + b / a, rel=1e-12)
    assert m.derived["My"] == pytest.approx(b / a, rel=1e-12)
    assert m.derived["Mz"] == pytest.approx(b / a, rel=1e-12)
    # eq 16: omega = det J = b^2 (a + b) / a^3
    assert m.derived["omega"] == pytest.approx(b**2 * (a + b) / a**3, rel=1e-12)


def test_section8_magnifications():
    # section 8: a = 20 mm, b = 50 mm give Mx, My, Mz = 3.5, 2.5, 2.5
    m = rigid(0.02, 0.05)
    assert (m.derived["Mx"], m.derived["My"], m.derived["Mz"]) == pytest.approx((3.5, 2.5, 2.5), rel=1e-12)


@pytest.mark.parametrize("seed", range(3))
def test_jacobian_is_eq_13_everywhere(panto, seed):
    """Eq 13: J = diag(Mx, -My, -Mz) at every pose (configuration independent), so the
    manipulability of eq 14-16 is constant."""
    rng = np.random.default_rng(seed)
    for q in random_q(panto, rng, 5):
        fk = cn.forward_kinematics(rigid(0.02, 0.05), q, NEWTON)
        assert fk.status is Status.SOLVED, fk.message
        rep = cn.jacobians(panto, fk.x, fk.q)
        np.testing.assert_allclose(rep.J_task, np.diag([3.5, -2.5, -2.5]), atol=1e-12)
        np.testing.assert_allclose(rep.J_inv, np.diag([1 / 3.5, -1 / 2.5, -1 / 2.5]), atol=1e-12)
        assert rep.manipulability == pytest.approx(21.875, rel=1e-12)  # eq 16: 2.5^2 * 70 / 20^3 (mm)


@pytest.mark.parametrize("seed", range(3))
def test_ad_jacobians_against_central_differences(seed):
    model = rigid(0.015, 0.04)
    rng = np.random.default_rng(10 + seed)
    q = random_q(model, rng, 1)[0]
    fk = cn.forward_kinematics(model, q, NEWTON)
    assert fk.ok
    x = fk.x
    rep = cn.jacobians(model, x, q)
    np.testing.assert_allclose(rep.phi_x, central_difference(lambda v: cn.residual(model, v, q), x, 1e-7), atol=1e-8)
    np.testing.assert_allclose(rep.phi_q, central_difference(lambda v: cn.residual(model, x, v), q, 1e-7), atol=1e-8)

    def fk_x(v):
        return cn.forward_kinematics(model, v, NEWTON, guess=x).x

    np.testing.assert_allclose(rep.J, central_difference(fk_x, q, 1e-8), atol=1e-6)

    def ik_q(t):
        return cn.inverse_kinematics(model, t).q

    np.testing.assert_allclose(rep.J_inv, central_difference(ik_q, x[:3], 1e-8), atol=1e-7)


@pytest.mark.parametrize("solver", [NEWTON, IPOPT], ids=["newton", "ipopt"])
def test_fk_against_ik(panto, solver):
    """FK (solved) against the closed-form IK, 20 poses; assess() also checks the branch."""
    rng = np.random.default_rng(3)
    model = rigid(0.02, 0.05)
    for q in random_q(model, rng, 20):
        fk = cn.forward_kinematics(model, q, solver)
        assert fk.status is Status.SOLVED, fk.message
        ik = cn.inverse_kinematics(model, fk.x[:3])
        assert ik.status is Status.SOLVED
        np.testing.assert_allclose(ik.q, q, atol=1e-12)
        np.testing.assert_allclose(ik.x, fk.x, atol=1e-10)
        # and the solved IK agrees with the closed form
        solved = cn.inverse_kinematics(model, fk.x[:3], method="solve")
        np.testing.assert_allclose(solved.q, q, atol=1e-10)


def test_eq_9_10_linear_decoupled(panto):
    """p = (Mx dx, -My dy, -Mz dz) (eq 9-10), exactly, far from home too."""
    model = rigid(0.02, 0.05)
    for q in ([0.03, 0.005, 0.002], [0.02, -0.01, 0.004], [0.035, 0.0, -0.003]):
        fk = cn.forward_kinematics(model, q, NEWTON)
        assert fk.ok
        np.testing.assert_allclose(fk.x[:3], [3.5 * q[0], -2.5 * q[1], -2.5 * q[2]], rtol=1e-12, atol=1e-15)


def test_eq_17_and_18(panto):
    """|AB|^2 = dx^2 + dy^2 + dz^2 = 2a^2 (1 - cos psi) (eq 17) and tan phi = dz/dx (eq 18)."""
    rng = np.random.default_rng(7)
    model = rigid(0.02, 0.05)
    for q in random_q(model, rng, 10):
        fk = cn.forward_kinematics(model, q, NEWTON)
        psi = fk.passive[0]
        assert float(q @ q) == pytest.approx(2 * 0.02**2 * (1 - math.cos(psi)), rel=1e-12)
        theta1, theta2, phi = at(model, fk.x, "theta1", "theta2", "phi")
        assert math.tan(phi) == pytest.approx(q[2] / q[0], rel=1e-12)
        assert psi == pytest.approx(math.pi - (theta1 - theta2), abs=1e-15)


def test_mirrored_elbow_is_wrong_branch():
    """The loops also close with theta1 and theta2 swapped (the mirrored elbow);
    the model designates theta1 > theta2 and reports the other as wrong_branch."""
    model = rigid(0.02, 0.05)
    # theta1 and theta2 swapped: the parallelogram's angles are psi = pi - (theta1 - theta2) (eq 17)
    x = pose(model, theta1=-math.pi / 4, theta2=math.pi / 4, psiD=3 * math.pi / 2, psiB=3 * math.pi / 2)
    assert np.max(np.abs(cn.residual(model, x, model.q_home))) < 1e-15
    status, message, _ = cn.assess(model, x, model.q_home, 1e-10)
    assert status is Status.WRONG_BRANCH


def test_guiding_mechanism_singularity_is_the_branch_limit():
    """theta_i = +-pi/2 (eq 25-29) is not a singularity of eq 1-8 (Phi_x regular) but of the
    guiding mechanism: the branch indicator vanishes there."""
    model = rigid(0.02, 0.05)
    a = 0.02
    # theta1 = pi/2, theta2 = 0: AB = a (u1 + u2) = a (1, 1, 0) -> q = (a, -a, 0); psi = pi/2 (eq 17)
    q = np.array([a, -a, 0.0])
    x = pose(model, px=3.5 * a, py=2.5 * a, pz=0.0, theta1=math.pi / 2, theta2=0.0, xB=a, yA=-a, zA=0.0)
    assert np.max(np.abs(cn.residual(model, x, q))) < 1e-15
    s = np.linalg.svd(np.asarray(model.closure.phi_x(x, q, model.p)), compute_uv=False)
    assert s.min() > 1e-6 * s.max()  # regular
    g = np.asarray(model.closure.branch(x, q, model.p)).ravel()
    assert g.min() == pytest.approx(0.0, abs=1e-15)


def test_joint_limits_give_outside_joint_limits(panto):
    # |AB| beyond 2a sin(psi_max/2): psi > psi_max
    q = [0.0299, 0.0, 0.0]
    fk = cn.forward_kinematics(panto, q, NEWTON)
    assert fk.status is Status.OUTSIDE_JOINT_LIMITS and fk.x is None
    assert "psi = " in fk.message
    # phi beyond phi_max: tan(phi) = dz / dx
    fk = cn.forward_kinematics(panto, [0.0282, 0.0, 0.0282 * math.tan(0.09)], NEWTON)
    assert fk.status is Status.OUTSIDE_JOINT_LIMITS and "phi = " in fk.message
    # unreachable IK: |AB| > 2a
    ik = cn.inverse_kinematics(panto, [3.5 * 0.041, 0, 0])
    assert ik.status is Status.UNREACHABLE


def test_actuator_ranges_eq_20_22(panto):
    """Eq 20-22: the actuator ranges from psi_max and phi_max."""
    r = P.actuator_ranges(panto)
    R = math.sqrt(2 * 0.02**2 * (1 - math.cos(1.65)))
    assert r["dx_max"] == pytest.approx(R) and r["dy_min"] == pytest.approx(-R)
    assert r["dz_max"] == pytest.approx(R / math.sqrt(1 + 1 / math.tan(0.0795) ** 2))
    # eq 22's dz_max is where the phi plane meets the outer sphere: on the boundary of the workspace
    q_edge = np.array([R * math.cos(0.0795), 0.0, r["dz_max"]])
    assert float(q_edge @ q_edge) == pytest.approx(R**2, rel=1e-12)
    assert math.atan2(q_edge[2], q_edge[0]) == pytest.approx(0.0795, rel=1e-12)


def test_joint_requirements_kind_runs_on_the_pantograph(panto):
    """The kinematic kinds of the foundation work unchanged on the pantograph."""
    problem = cn.problem_from_dict(
        {
            "problem": "joint_requirements",
            "mechanism": {"type": "pantograph", "parameters": PAPER, "limits": PAPER_LIMITS},
            "inputs": {"px": ["0.097 m", "0.1 m"], "py": ["-10 mm", "10 mm"], "pz": ["-2 mm", "2 mm"]},
        }
    )
    result = cn.solve(problem)
    assert result.status is Status.SOLVED
    v = result.values
    # the corners: dx = px / 3.5, dy = -py / 2.5 (eq 9-10)
    assert v["stroke_min"] == pytest.approx(-0.004, rel=1e-12)
    assert v["stroke_max"] == pytest.approx(0.1 / 3.5, rel=1e-12)
    assert 1.49 < v["psi_min"] < v["psi_max"] < 1.65


def test_hinge_beyond_the_geometry_does_not_limit():
    """A hinge that could turn by more than pi/2 leaves psi in its geometric range [0, pi]
    and phi unlimited (eq 31 clipped), so the workspace is the rigid one (section 5.1)."""
    m = cn.build_model(
        "pantograph", PAPER, {"hinge": "leaf_spring", "l": "50 mm", "t": "0.1 mm", "material": "polypropylene"}
    )
    assert m.derived["delta_max"] > math.pi / 2
    assert (m.derived["psi_min"], m.derived["psi_max"], m.derived["phi_max"]) == (0.0, math.pi, None)
    assert "phi" not in m.limits
