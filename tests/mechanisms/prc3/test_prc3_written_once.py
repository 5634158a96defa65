"""The 3-PRC written once (issue 21, item 5): the registered ``prc3`` is the mechanism file
problems/mechanisms/prc3.yaml (its closures generated from the legs) with the add-on
cpm_nlp/mechanisms/prc3/addon.py (the paper's kind ``amplifier``, the Lagrange model of eq
28-41, the hinge check of eq 28, the parameters only the dynamics uses).  The hand-written
closures it replaced (tests/reference/prc3_closures.py, derived from prc3-li-2018.md eq 2-10)
are the independent reference it is checked against here.

* FK, IK, passive joints and the Jacobians dx/dq (whole pose and task, and dq/dt) at 20
  seeded random poses of the paper's workspace (eq 26-27: |x|, |y|, |z| up to A2 q_max =
  131.6 um), to 1e-12 (absolute, on values of order 1 in SI);
* the branch indicators' signs on eq 8's root and on the other root of each leg;
* the dynamics result of problems/prc3_dynamics.yaml equals the one the hand-written module
  gave before the move (recorded at commit cac0e1a: consistency, not a published figure);
* what users see: parameters (bounds exclusive), limit families, the add-on's parts.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import cpm_nlp as cn
from cpm_nlp.analysis.dynamics import DynamicsModel
from cpm_nlp.core.mechanism import Addon, MechanismDeclarationError, with_addon
from cpm_nlp.core.result import Status
from cpm_nlp.kinds.workspace import PaperMembership
from cpm_nlp.mechanisms import registry
from cpm_nlp.mechanisms.prc3 import addon, dynamics
from tests.conftest import PROBLEMS
from tests.reference import assert_same_kinematics
from tests.reference import prc3_closures as ref

NEWTON = cn.SolverConfig(method="newton")
TOL = 1e-12
#: Table 1's lengths, and two other amplifiers and legs (the file is generated for any value)
PARAMETER_SETS = [
    ref.PAPER,
    {"L1": "8 mm", "L2": "20 mm", "L3": "10 mm", "L4": "24 mm", "L7": "50 mm"},
    {"L1": "12 mm", "L2": "30 mm", "L3": "7 mm", "L4": "35 mm", "L7": "100 mm"},
]
#: the values problems/prc3_dynamics.yaml gave with the hand-written module (commit cac0e1a,
#: `cpm-nlp solve problems/prc3_dynamics.yaml --json`), recorded before the move
DYNAMICS_BEFORE = {
    "f1": 107.34757215006091,
    "f2": 107.34757215006091,
    "f3": 107.34757215006091,
    "k": 3.3646082797681003,
    "M_e": 5.513887443541859,
    "K_e": 2508430.5786666344,
    "G_e": 12.337854891118422,
    "f": 107.34757215006091,
    "f_printed": 96.50150839022355,
}


def _close(a, b, tol=TOL):
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    scale = max(1.0, float(np.max(np.abs(b))))
    np.testing.assert_allclose(a, b, rtol=0, atol=tol * scale)


def _poses(model, n=20, seed=21):
    """n platform positions in the paper's workspace: each coordinate within A2 q_max = A2 15 um
    of home (eq 26-27: p = -A2 q for 0 <= q <= 15 um), both signs."""
    reach = model.derived["A2"] * 15e-6
    return np.random.default_rng(seed).uniform(-reach, reach, (n, 3))


def test_the_registered_prc3_is_the_file_with_its_addon():
    mech = registry.mechanism_type("prc3")
    assert mech.origin.kind == "file" and mech.origin.path.endswith("prc3.yaml")
    assert registry.BUILTIN_FILES["prc3"] == "prc3.yaml" and "prc3" not in registry.BUILTIN
    assert registry.ADDONS["prc3"] == "cpm_nlp.mechanisms.prc3.addon:ADDON"
    with pytest.raises(ModuleNotFoundError):
        __import__("cpm_nlp.mechanisms.prc3.kinematics")
    with pytest.raises(ModuleNotFoundError, match="prc3.yaml"):
        __import__("cpm_nlp.prc3")
    # the add-on's parts, and only those, beside the file's
    assert set(mech.kinds) == {"amplifier"} and mech.kinds["amplifier"] is addon.ADDON.kinds["amplifier"]
    dm = mech.part(DynamicsModel)
    assert isinstance(dm, DynamicsModel) and dm.parameters == dynamics.DYNAMIC_PARAMETERS
    assert mech.check_parameters is addon.check_parameters
    assert mech.geometry is not None  # the file's drawing
    # the old name of the file twin names the same mechanism (old scripts, old problem files)
    assert registry.mechanism_type("prc3_file") is mech
    assert "prc3_file" not in registry.mechanism_names()


def test_the_name_resolves_to_the_file_without_reading_the_others(monkeypatch):
    read = []
    # listing the shipped files is what reading the others would take
    monkeypatch.setattr(registry.described, "shipped_files", lambda: read.append("listed") or [])
    fresh = registry._Registry()
    mech = fresh.lookup("prc3")
    assert mech is not None and mech.name == "prc3" and "amplifier" in mech.kinds
    assert fresh._specs is None and read == []


def test_a_file_of_the_same_text_is_the_built_in(tmp_path):
    """A problem naming the shipped file, or an unchanged copy of it, gets the built-in with its
    add-on; a changed copy of the same name is refused."""
    text = (PROBLEMS / "mechanisms" / "prc3.yaml").read_text()
    shipped = cn.load_problem(PROBLEMS / "prc3_file_forward_kinematics.yaml")
    assert shipped.model.mechanism is registry.mechanism_type("prc3")
    (tmp_path / "prc3.yaml").write_text(text)
    problem = {"problem": "amplifier", "mechanism": {"file": "prc3.yaml", "parameters": ref.PAPER}, "inputs": {}}
    assert cn.problem_from_dict(problem, base_dir=tmp_path).model.mechanism is registry.mechanism_type("prc3")
    (tmp_path / "prc3.yaml").write_text(text.replace("title: 3-PRC", "title: A 3-PRC"))
    with pytest.raises(cn.InputError, match="differs from it; rename it"):
        cn.problem_from_dict(problem, base_dir=tmp_path)


def test_the_addon_may_not_repeat_the_file():
    mech = registry.mechanism_type("prc3")
    with pytest.raises(MechanismDeclarationError, match="repeats what the file declares .*amplifier"):
        with_addon(mech, Addon(kinds=addon.ADDON.kinds))
    with pytest.raises(MechanismDeclarationError, match="repeats what the file declares .*L5"):
        with_addon(mech, Addon(parameters=addon.PARAMETERS))
    with pytest.raises(MechanismDeclarationError, match="repeats what the file declares .*check_parameters"):
        with_addon(mech, Addon(check_parameters=addon.check_parameters))
    with pytest.raises(MechanismDeclarationError, match="expected an Addon"):
        with_addon(mech, {"kinds": {}})


def test_an_addon_gives_the_parts_the_file_does_not():
    """Every part an add-on may carry reaches the mechanism (the file has none of these)."""
    mech = registry.mechanism_type("prs3")

    def check(limits, path):
        return None

    def member(model, points):
        return points, {}

    extended = with_addon(mech, Addon(check_limits=check, parts=(PaperMembership(member),)))
    assert extended.check_limits is check and extended.part(PaperMembership).test is member
    assert extended.closure is mech.closure and extended.kinds == mech.kinds


@pytest.mark.parametrize("params", PARAMETER_SETS, ids=["table1", "short", "long"])
def test_fk_ik_passive_and_jacobians_equal_the_reference(params):
    fm, rm = cn.build_model("prc3", params), ref.reference_model(params)
    assert (fm.closure.x_names, fm.closure.q_names) == (rm.closure.x_names, rm.closure.q_names)
    assert fm.closure.passive_names == rm.closure.passive_names
    assert fm.closure.task == rm.closure.task
    assert fm.derived == pytest.approx(rm.derived, rel=1e-15)
    _close(fm.x_home, rm.x_home)
    _close(fm.q_home, rm.q_home)
    _close(fm.x_lower, rm.x_lower)
    _close(fm.x_upper, rm.x_upper)
    assert_same_kinematics(fm, rm, _poses(rm), task_is_pose=True)


def test_jacobian_against_central_differences_and_eq21():
    """dq/dx of the file's closures against central differences of the reference's IK, and
    against eq 21 evaluated on eq 8's root (J / A2, ref.jacobian_eq21)."""
    fm, rm = cn.build_model("prc3", ref.PAPER), ref.reference_model()
    A2, l = rm.derived["A2"], rm.parameters["L7"]
    for t in _poses(rm, n=5, seed=7):
        ik = cn.inverse_kinematics(fm, t)
        J_inv = cn.jacobians(fm, ik.x, ik.q).J_inv
        h = 1e-9
        fd = np.column_stack(
            [
                (np.asarray(rm.closure.ik(t + h * e, rm.p)[1]) - np.asarray(rm.closure.ik(t - h * e, rm.p)[1])).ravel()
                / (2 * h)
                for e in np.eye(3)
            ]
        )
        np.testing.assert_allclose(J_inv, fd, rtol=0, atol=1e-6 * np.abs(fd).max())
        np.testing.assert_allclose(J_inv, ref.jacobian_eq21(ik.x, A2 * ik.q, l) / A2, rtol=0, atol=1e-12)


def test_branch_indicator_signs_agree_on_both_roots():
    """The file's indicator of leg i (limb{i}.S2) has the sign of the reference's g_i (the leg
    along +e_i from slider to platform, eq 8's root) on the working root and on the other."""
    fm, rm = cn.build_model("prc3", ref.PAPER), ref.reference_model()
    l, A2 = rm.parameters["L7"], rm.derived["A2"]
    flipped = 0
    for t in _poses(rm):
        ik = cn.inverse_kinematics(rm, t)
        g = np.asarray(fm.closure.branch(ik.x, ik.q, fm.p), dtype=float).ravel()
        h = np.asarray(rm.closure.branch(ik.x, ik.q, rm.p), dtype=float).ravel()
        assert (g > 0).all() and (h > 0).all()
        for i in range(3):
            q2 = ik.q.copy()
            rad = l**2 - t[(i + 1) % 3] ** 2 - t[(i + 2) % 3] ** 2
            q2[i] = (-t[i] - l - math.sqrt(rad)) / A2  # eq 7's other root
            assert np.max(np.abs(cn.residual(rm, ik.x, q2))) < 1e-15
            g = np.asarray(fm.closure.branch(ik.x, q2, fm.p), dtype=float).ravel()
            h = np.asarray(rm.closure.branch(ik.x, q2, rm.p), dtype=float).ravel()
            assert np.sign(g[:3]).tolist() == np.sign(h).tolist() and g[i] < 0
            flipped += 1
    assert flipped == 60


def test_the_dynamics_equals_the_value_before_the_move():
    """problems/prc3_dynamics.yaml (eq 28-41, assumed masses) gives what the hand-written
    module gave (DYNAMICS_BEFORE), now with the platform velocity from the file's closures."""
    res = cn.solve(cn.load_problem(PROBLEMS / "prc3_dynamics.yaml"))
    assert res.status is Status.SOLVED
    for name, before in DYNAMICS_BEFORE.items():
        assert res.values[name] == pytest.approx(before, rel=1e-12), name


def test_the_lagrangian_on_the_file_equals_it_on_the_reference():
    """T and U of eq 28-35 built on the file's closures and on the hand-written ones: equal (the
    only kinematics they use is the closures' Jacobian at home, -A2 I by eq 26)."""
    fm = cn.load_problem(PROBLEMS / "prc3_dynamics.yaml").model
    on_file = fm.mechanism.part(DynamicsModel).lagrangian()
    on_ref = dynamics.lagrangian(ref.reference_model().closure)
    rng = np.random.default_rng(28)
    w = np.concatenate([[71.7e9, 9.81, 6.5e-3, 0.5e-3, 3e-3, 26e-3, 33e-3, 59.5e-3], rng.uniform(1e-3, 0.1, 8)])
    for _ in range(5):
        q, qd = rng.uniform(0, 15e-6, 3), rng.uniform(-1e-3, 1e-3, 3)
        a, b = on_file(q=q, qd=qd, p=fm.p, w=w), on_ref(q=q, qd=qd, p=fm.p, w=w)
        for out in ("T", "U", "k"):
            assert float(a[out]) == pytest.approx(float(b[out]), rel=1e-12, abs=1e-300)


def test_what_users_see_is_what_the_module_declared():
    """Parameters (the file's five, then the add-on's seven, as the module ordered them; bounds
    exclusive), the limit families with their descriptions, the paper and the problem files."""
    mech = registry.mechanism_type("prc3")
    assert mech.title == ref.MECHANISM.title and mech.paper == ref.MECHANISM.paper
    assert mech.parameters == ref.PARAMETERS
    limits = {o.name: o for o in mech.limits}
    for o in ref.LIMITS:
        assert limits[o.name] == o
    assert set(limits) - {o.name for o in ref.LIMITS} == {"q1", "q2", "q3"}  # one input's range alone
    names = [str(p).rsplit("/", 1)[-1] for p in mech.problem_files]
    for f in ("prc3_forward_kinematics", "prc3_amplifier", "prc3_cuboid", "prc3_dynamics", "prc3_file_cuboid"):
        assert f"{f}.yaml" in names
    # the add-on's parameters reach the model (not p); one not given is absent
    model = cn.build_model("prc3", {**ref.PAPER, "L8": "59.5 mm", "r": "3 mm", "t": "0.5 mm"})
    assert model.parameters["L8"] == pytest.approx(59.5e-3) and "L5" not in model.parameters
    assert model.dimensions["L8"] == "length" and list(model.closure.parameters) == list(dynamics.KINEMATIC)


def test_strict_bounds_and_the_hinge_check_refuse_bad_values():
    for name in ("L1", "L7", "L8"):
        with pytest.raises(cn.InputError, match=r"in \(0"):
            cn.build_model("prc3", {**ref.PAPER, name: "0 mm"})
    with pytest.raises(cn.InputError, match=r"mechanism\.parameters\.t"):
        cn.build_model("prc3", {**ref.PAPER, "r": "1 mm", "t": "3 mm"})
