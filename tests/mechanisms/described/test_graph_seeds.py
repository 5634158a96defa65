"""Seed mechanisms written with bodies and joints only (issue 21, item 5), against the built-in modules.

* tests/corpus/pantograph_joints.yaml -- the 3D pantograph of Elgammal et al. with the paper's own joints (links,
  the parallelogram CDFB, the two loops sharing links, U joints at A and B for the plane's turn phi, R hinges at
  C and F: overconstrained, normal equations): FK, IK, the task Jacobian dx/dq and the hinge angle psi equal the
  hand-written closures the built-in replaced (tests/reference/pantograph_closures.py, eq 1-8 by hand) to
  1e-12 (the built-in, problems/mechanisms/pantograph.yaml, closes its loops with S joints at C and F:
  tests/mechanisms/pantograph/test_pantograph_written_once.py); its task
  Jacobian is the paper's constant J = diag(Mx, -My, -Mz) (eq 9-13); Gruebler-Kutzbach is
  negative (section 2) while the loops' rank gives 3 degrees of freedom.
* tests/corpus/prc3_levers.yaml -- the 3-PRC of Li et al. with each limb's secondary lever
  amplifier (piezo block, lever 1, lever 2, links, slider): the slider moves by A2 q to first order
  (eq 1-2, A1 = 2.632 and A2 = 8.772 printed), exactly as an independent numpy model of the levers
  says; the platform is the built-in ``prc3``'s at the slider displacements (d_i = A2 q'_i, eq 2)
  and does not turn (R_p = I, eq 5).
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import cpm_nlp as cn
from cpm_nlp.core.result import Status
from cpm_nlp.mechanisms import described
from cpm_nlp.mechanisms.described import load_file
from cpm_nlp.mechanisms.described.closure import closure_parts
from tests.reference import pantograph_closures, prs3_closures, rpr_closures

CORPUS = Path(__file__).resolve().parents[2] / "corpus"
SHIPPED = Path(__file__).resolve().parents[3] / "problems" / "mechanisms"
#: the seed files (in the corpus unless named here)
FILES: dict[str, Path] = {}
NEWTON = cn.SolverConfig("newton")


def _file_model(name: str, parameters: dict | None = None) -> cn.Model:
    mech = load_file(FILES.get(name, CORPUS / f"{name}.yaml"))
    return mech.model(mech.closure(), parameters or {}, {}, ())


def _info(name: str):
    gen, _fns = closure_parts(described.read_description(FILES.get(name, CORPUS / f"{name}.yaml")))
    return gen.info


def _close(a, b, tol=1e-12):
    """|a - b| <= tol * max(1, |b|) (the comparison of tests/mechanisms/described/test_described.py)."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    np.testing.assert_allclose(a, b, rtol=0, atol=tol * max(1.0, float(np.max(np.abs(b)))))


# -- the pantograph ------------------------------------------------------------------------------

PANTO = {"a": "20 mm", "b": "50 mm"}  # the paper's Fig. 9-10 and the file's defaults


@pytest.fixture(scope="module")
def pantographs():
    return _file_model("pantograph_joints"), pantograph_closures.reference_model(PANTO)


def _pantograph_inputs(hm: cn.Model) -> np.ndarray:
    """Actuators of the working range: random within 3 mm of home (psi stays within 45 deg of
    pi/2, eq 31's printed limits), and the pose of problems/pantograph_file_forward_kinematics.yaml."""
    rng = np.random.default_rng(21)
    q = hm.q_home + rng.uniform(-3e-3, 3e-3, (10, 3))
    return np.vstack([q, [28.8557e-3, -0.4e-3, 0.4e-3]])


def test_pantograph_joints_equals_the_builtin_module(pantographs):
    fm, hm = pantographs
    names = fm.closure.x_names
    idx = [names.index(n) for n in hm.closure.x_names]  # px, py, pz, theta1, theta2, phi
    assert list(fm.closure.q_names) == list(hm.closure.q_names) == ["dx", "dy", "dz"]
    assert fm.closure.task == hm.closure.task
    _close(np.asarray(fm.x_home)[idx], hm.x_home, 1e-15)
    _close(fm.q_home, hm.q_home, 1e-15)
    for q in _pantograph_inputs(hm):
        a, b = cn.forward_kinematics(hm, q, NEWTON), cn.forward_kinematics(fm, q, NEWTON)
        assert a.status == b.status == Status.SOLVED, (a.message, b.message)
        xb = np.asarray(b.x)
        _close(xb[idx], a.x)
        # the joints the built-in does not have: the second U's turn, the parallelogram's angles, the sliders
        psi = math.pi - (a.x[3] - a.x[4])  # eq 17; the parallelogram's angles CDF and FBC are psi too
        _close([xb[names.index(n)] for n in ("phiB", "psiD", "psiB")], [a.x[5], psi, psi])
        _close([xb[names.index(n)] for n in ("xB", "yA", "zA")], q, 1e-15)
        pa, pb = cn.passive_joints(hm, a.x, q), cn.passive_joints(fm, b.x, q)
        _close(pb["psi"], pa["psi"])  # eq 17
        Ja = np.asarray(hm.closure.jacobian(a.x, q, hm.p))
        Jb = np.asarray(fm.closure.jacobian(b.x, q, fm.p))
        _close(Jb[:3], Ja[:3])  # dx/dq of the task (px, py, pz)
        _close(Jb[idx], Ja)  # and of the three angles
        t = hm.task_of(a.x)
        ia, ib = cn.inverse_kinematics(hm, t, NEWTON), cn.inverse_kinematics(fm, t, NEWTON)
        assert ia.status == ib.status == Status.SOLVED, (ia.message, ib.message)
        _close(ib.q, ia.q)
        _close(np.asarray(ib.x)[idx], ia.x)
        _close(ib.q, q)  # FK -> IK round trip gives the actuators back


def test_pantograph_joints_other_parameters_assemble_and_agree():
    """The drawing is written in a and b: other values assemble exactly and agree (section 6's
    synthesis varies them)."""
    fm = _file_model("pantograph_joints", {"a": 0.025, "b": 0.040})
    hm = pantograph_closures.reference_model({"a": "25 mm", "b": "40 mm"})
    for dq in ([1e-3, -2e-3, 1.5e-3], [-2e-3, 1e-3, -1e-3]):
        q = hm.q_home + np.array(dq)
        a, b = cn.forward_kinematics(hm, q, NEWTON), cn.forward_kinematics(fm, q, NEWTON)
        assert a.status == b.status == Status.SOLVED, (a.message, b.message)
        _close(np.asarray(b.x)[:3], a.x[:3])
        _close(np.asarray(fm.closure.jacobian(b.x, q, fm.p))[:3], np.asarray(hm.closure.jacobian(a.x, q, hm.p))[:3])


def test_pantograph_joints_task_jacobian_is_the_papers(pantographs):
    """Eq 9-13: J = diag(Mx, -My, -Mz), Mx = 1 + b/a, My = Mz = b/a, at every pose (derived by
    the paper from eq 3-8); omega = b^2 (a + b)/a^3 (eq 16)."""
    fm, hm = pantographs
    a, b = 0.020, 0.050
    J_paper = np.diag([1 + b / a, -b / a, -b / a])
    for q in _pantograph_inputs(hm)[:4]:
        sol = cn.forward_kinematics(fm, q, NEWTON)
        J = np.asarray(fm.closure.jacobian(sol.x, q, fm.p))[:3]
        _close(J, J_paper)
        assert abs(np.linalg.det(J)) == pytest.approx(b**2 * (a + b) / a**3, rel=1e-12)


def test_pantograph_joints_mobility_by_rank_against_gruebler():
    """Section 2: 'the application of Gruebler formula results in negative value'; the loops'
    rank gives the 3 degrees of freedom (one per actuator)."""
    info = _info("pantograph_joints")
    assert info.gruebler == -1
    assert info.mobility == 3
    assert len(info.loops) == 2  # through C (A-C-B) and the parallelogram (closed at F)
    # the shipped file closes both loops with S joints at C and F: no repeated equations
    gen, _fns = closure_parts(described.read_description(SHIPPED / "pantograph.yaml"))
    assert gen.info.gruebler == gen.info.mobility == 3 and len(gen.info.loops) == 2


# -- the 3-PRC with its lever amplifiers ---------------------------------------------------------

PRC3 = {"L1": "9.5 mm", "L2": "25 mm", "L3": "9 mm", "L4": "30 mm", "L7": "73.5 mm"}  # Table 1
TABLE1 = {"L0": 5e-3, "L1": 9.5e-3, "L2": 25e-3, "L3": 9e-3, "L4": 30e-3, "L5": 26e-3, "L6": 33e-3, "L7": 73.5e-3}


@pytest.fixture(scope="module")
def prc3s():
    return _file_model("prc3_levers"), cn.build_model("prc3", PRC3)


def _arm_angle(pivot, arm, point, length):
    """The angle theta of a lever (pivot, arm along +v turned by theta towards +s) whose arm's end is
    `length` from `point`, near theta = 0 (Newton in numpy)."""
    th = 0.0
    for _ in range(50):
        end = pivot + arm * np.array([math.sin(th), math.cos(th)])
        r = end - point
        f = r @ r - length**2
        df = 2 * r @ (arm * np.array([math.cos(th), -math.sin(th)]))
        step = f / df
        th -= step
        if abs(step) < 1e-17:
            break
    return th


def numpy_levers(q: float, L: dict) -> tuple[float, float, float, np.ndarray]:
    """One limb's amplifier, independent of cpm_nlp, in its plane: s along the motion (-e_i, from the
    platform centre), v across it.  Block at s = c + q; lever 1 pivot (b, L3 - L2), arms L1, L2; lever 2
    pivot (a, 0), arms L3, L4; slider at s = L7 + d; links L0, L5, L6 along s in the drawing.
    Returns (theta_A, theta_B, d, the tip of lever 2)."""
    a = L["L7"] + L["L6"]
    b = a + L["L5"]
    c = b + L["L0"]
    v = L["L3"] - L["L2"]
    thA = _arm_angle(np.array([b, v]), L["L1"], np.array([c + q, v + L["L1"]]), L["L0"])
    out1 = np.array([b, v]) + L["L2"] * np.array([math.sin(thA), math.cos(thA)])
    thB = _arm_angle(np.array([a, 0.0]), L["L3"], out1, L["L5"])
    tip = np.array([a, 0.0]) + L["L4"] * np.array([math.sin(thB), math.cos(thB)])
    d = tip[0] - math.sqrt(L["L6"] ** 2 - (tip[1] - L["L4"]) ** 2) - L["L7"]
    return thA, thB, d, tip


def test_prc3_lever_amplification_is_eq1(prc3s):
    """dd_i/dq_i at home is A2 = L2 L4/(L1 L3) (eq 1, printed 8.772) and the first lever's output
    moves by A1 q (eq 1, printed 2.632): AD Jacobian of the joints-only file."""
    fm, _hm = prc3s
    names = fm.closure.x_names
    J = np.asarray(fm.closure.jacobian(fm.x_home, fm.q_home, fm.p))
    L = TABLE1
    A2 = L["L2"] * L["L4"] / (L["L1"] * L["L3"])
    for i in (1, 2, 3):
        ratio = J[names.index(f"d{i}"), i - 1]
        assert ratio == pytest.approx(A2, rel=1e-12)
        assert abs(ratio - 8.772) < 5e-4  # eq 1 as printed (3 decimals)
        first = J[names.index(f"thetaA{i}"), i - 1] * L["L2"]  # lever 1's output: L2 dtheta_A
        assert abs(first - 2.632) < 5e-4
        # eq 28's lever angles: theta_1 = A1 q / L2, theta_2 = A2 q / L4 (to first order)
        assert J[names.index(f"thetaB{i}"), i - 1] == pytest.approx(A2 / L["L4"], rel=1e-12)
    # the other limbs' sliders do not move
    D = J[[names.index(f"d{i}") for i in (1, 2, 3)]]
    assert np.max(np.abs(D - np.diag(np.diag(D)))) < 1e-12


def test_prc3_levers_equal_a_numpy_model_and_the_builtin_platform(prc3s):
    """Over the paper's input range 0 <= q_i <= 15 um (eq 27): the sliders, lever angles and tips
    are the numpy model's (derived here); d_i = A2 q_i to first order (measured: 1.1e-8 relative
    at most); the platform is the built-in prc3's at q'_i = d_i / A2 (eq 2), it does not turn, and
    IK of its position gives the inputs back."""
    fm, hm = prc3s
    names = fm.closure.x_names
    L = TABLE1
    A2 = L["L2"] * L["L4"] / (L["L1"] * L["L3"])
    rng = np.random.default_rng(27)
    worst = 0.0
    for q in [*rng.uniform(0, 15e-6, (6, 3)), np.full(3, 15e-6)]:
        sol = cn.forward_kinematics(fm, q, NEWTON)
        assert sol.status == Status.SOLVED, sol.message
        x = np.asarray(sol.x)
        out = cn.passive_joints(fm, sol.x, q)
        d = np.array([x[names.index(f"d{i}")] for i in (1, 2, 3)])
        for i in (1, 2, 3):
            thA, thB, di, tip = numpy_levers(q[i - 1], L)
            got = [x[names.index(f"thetaA{i}")], x[names.index(f"thetaB{i}")], d[i - 1]]
            np.testing.assert_allclose(got, [thA, thB, di], rtol=1e-9, atol=1e-18)
            e, n = np.eye(3)[i - 1], np.eye(3)[i % 3]  # the limb's plane: -e_i (s) and e_(i+1) (v)
            T = -tip[0] * e + tip[1] * n
            got = [out[f"tip{i}_{k}"] for k in "xyz"]
            np.testing.assert_allclose(got, T, rtol=0, atol=1e-15)
        worst = max(worst, float(np.max(np.abs(d - A2 * q) / (A2 * q))))
        ref = cn.forward_kinematics(hm, d / A2, NEWTON)
        assert ref.status == Status.SOLVED, ref.message
        np.testing.assert_allclose(x[:3], ref.x, rtol=0, atol=1e-12)
        R, _P = fm.closure.frame(sol.x, fm.p)
        np.testing.assert_allclose(np.asarray(R, dtype=float), np.eye(3), rtol=0, atol=1e-12)
        ik = cn.inverse_kinematics(fm, x[:3], NEWTON)
        assert ik.status == Status.SOLVED, ik.message
        np.testing.assert_allclose(ik.q, q, rtol=0, atol=1e-15)
    assert 0 < worst < 1e-7  # second order only: the levers' and links' tilt


def test_prc3_levers_mobility():
    info = _info("prc3_levers")
    assert info.mobility == 3
    assert info.gruebler == 3  # nothing overconstrained: the links are distance joints
    assert len(info.loops) == 11  # 3 links per limb, and two legs closing at the platform


# -- the 3-PRS and the RPR -----------------------------------------------------------------------

TWINS = {
    # joints-only file, the hand-written closures the built-in replaced (tests/reference, issue 21),
    # its parameters (the papers'), actuator half-range about home
    "prs3_joints": (prs3_closures, {"b": "47.91 mm", "L": "109.215 mm", "alpha0": "45 deg"}, 2e-3),
    "rpr_joints": (rpr_closures, {"r1": "40 mm", "r2": "80 mm", "P0": "40 mm"}, 2e-3),
}


def _named(model: cn.Model, x, q) -> dict[str, float]:
    """Every pose coordinate and reported joint value by name."""
    out = dict(zip(model.closure.x_names, np.asarray(x, dtype=float)))
    out.update(cn.passive_joints(model, x, q))
    return out


@pytest.mark.parametrize("name", list(TWINS))
def test_joints_only_twin_equals_the_builtin_module(name):
    """FK (the pose and every joint angle the built-in reports, by name), IK and dx/dq to 1e-12;
    FK -> IK round trip.  The joint angles are the file's joint coordinates (a tree joint's) or
    its cut joints' reported values: alpha_i, beta_*i (prs3, eq 22-33), theta_a** (rpr, eq 13)."""
    hand, params, half = TWINS[name]
    fm, hm = _file_model(name), hand.reference_model(params)
    assert list(fm.closure.q_names) == list(hm.closure.q_names)
    assert fm.closure.task == hm.closure.task
    idx = [fm.closure.x_names.index(n) for n in hm.closure.x_names]
    _close(np.asarray(fm.x_home)[idx], hm.x_home, 1e-15)
    _close(fm.q_home, hm.q_home, 1e-15)
    rng = np.random.default_rng(21)
    for q in hm.q_home + rng.uniform(-half, half, (8, hm.closure.nq)):
        a, b = cn.forward_kinematics(hm, q, NEWTON), cn.forward_kinematics(fm, q, NEWTON)
        assert a.status == b.status == Status.SOLVED, (a.message, b.message)
        A, B = _named(hm, a.x, q), _named(fm, b.x, q)
        assert set(A) <= set(B), sorted(set(A) - set(B))
        _close([B[k] for k in A], list(A.values()))
        Ja = np.asarray(hm.closure.jacobian(a.x, q, hm.p))
        Jb = np.asarray(fm.closure.jacobian(b.x, q, fm.p))
        task = [hm.closure.x_names.index(t) for t in hm.closure.task]
        _close(Jb[idx][task], Ja[task])  # dx/dq of the task
        _close(Jb[idx], Ja)
        if name == "rpr_joints":  # the joints keep o' on the paper's line and R = Ry Rx (eq 2)
            _close([B["u"], B["v"], B["gamma"]], [0.0, 0.0, 0.0], 1e-14)
        t = hm.task_of(a.x)
        ia, ib = cn.inverse_kinematics(hm, t, NEWTON), cn.inverse_kinematics(fm, t, NEWTON)
        assert ia.status == ib.status == Status.SOLVED, (ia.message, ib.message)
        _close(ib.q, ia.q)
        _close(np.asarray(ib.x)[idx], ia.x)
        _close(ib.q, q)
