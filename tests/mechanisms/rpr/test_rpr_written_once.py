"""The RPR written once (issue 21, item 5): the registered ``rpr`` is the mechanism file
problems/mechanisms/rpr.yaml (its closures generated from the legs, its passive joints and
closed-form IK written in it) with the add-on cpm_nlp/mechanisms/rpr/addon.py (the paper's kinds
and its synthesis formulation).  The hand-written closures it replaced
(tests/reference/rpr_closures.py, derived from rpr-2rpu-upr-zhang-2022.md eq 2-13) are the
independent reference it is checked against here.

* FK, IK, passive joints and the Jacobians dx/dq (whole pose and task, and dq/dt) at 20 seeded
  random poses (|theta|, |alpha| up to 0.3 rad, P within 20 % of P0) for the paper's three
  designs (eq 26, 47, 49), to 1e-12 (absolute, on values of order 1 in SI);
* the AD Jacobians of the file against central differences of the reference's IK and passive
  angles, and FK against IK;
* the residuals: the file's leg equation is (|A_iB_i|^2 - l_i^2)/(2 P0), the reference's
  |A_iB_i| - l_i; the rows of Phi_x and Phi_q differ by l_i/P0 at a solution (the only outputs
  that changed in the move: rpr_jacobian.yaml's Phi_x, Phi_q, det_Phi_x, det_Phi_y);
* the branch indicators' signs on the working branch and on its mirror image below the base;
* the add-on's formulations on the file's closures equal them on the reference's, and the
  compliance result of problems/rpr_compliance.yaml equals the one the hand-written module gave
  before the move (recorded at commit 2a9c063: consistency, not a published figure);
* what users see: parameters (bounds exclusive), limit families, derived D, passive joints,
  the paper, the problem files, the Table 1 hinges.
"""

from __future__ import annotations

import numpy as np
import pytest

import cpm_nlp as cn
from cpm_nlp.analysis.compliance import JointStiffness
from cpm_nlp.core.mechanism import Addon, MechanismDeclarationError, with_addon
from cpm_nlp.core.result import Status
from cpm_nlp.mechanisms import registry
from cpm_nlp.mechanisms.rpr import addon, kinds
from cpm_nlp.mechanisms.rpr import compliance as rc
from tests.conftest import PROBLEMS
from tests.reference import assert_same_kinematics, close
from tests.reference import rpr_closures as ref

#: the paper's designs: eq 26 (the chosen one), eq 47 (l = 1, 1, 1) and eq 49 (l = 1.5, 0.75, 0.75)
PARAMETER_SETS = [
    ref.PAPER,
    {"r1": "40 mm", "r2": "40 mm", "P0": "40 mm"},
    {"r1": "60 mm", "r2": "30 mm", "P0": "30 mm"},
]
#: what problems/rpr_compliance.yaml gave with the hand-written module (commit 2a9c063,
#: `cpm-nlp solve problems/rpr_compliance.yaml -o`), recorded before the move
COMPLIANCE_BEFORE = {
    "C": [
        [-1.6517113452198622e-05, 3.474158572722716e-23, 1.6517113452198622e-05],
        [-8.28087950235179e-06, 1.6561759004703573e-05, -8.280879502351788e-06],
        [6.857234998860523e-07, 2.3253139697909294e-08, 6.857234998860523e-07],
    ],
    "C_in": [
        [1.3464180967329007e-07, 2.3248296302846204e-09, 2.5033746434266985e-09],
        [2.3248296302846208e-09, 1.3482035468643214e-07, 2.3248296302846208e-09],
        [2.503374643426698e-09, 2.3248296302846208e-09, 1.3464180967329007e-07],
    ],
    "K_prime": [
        [2618.175187147421, -1258.0961693445945, -1360.079017802827],
        [-1258.0961693445945, 2516.192338689189, -1258.0961693445945],
        [-1360.079017802827, -1258.0961693445945, 2618.175187147421],
    ],
}


def _poses(model, n=20, seed=21):
    """n task poses (theta, alpha, P): tilts up to 0.3 rad, P within 20 % of P0."""
    rng = np.random.default_rng(seed)
    P0 = model.parameters["P0"]
    return np.column_stack([rng.uniform(-0.3, 0.3, n), rng.uniform(-0.3, 0.3, n), P0 * rng.uniform(0.8, 1.2, n)])


def _central(f, x, h):
    return np.column_stack([(f(x + h * e) - f(x - h * e)) / (2 * h) for e in np.eye(len(x))])


def test_the_registered_rpr_is_the_file_with_its_addon():
    mech = registry.mechanism_type("rpr")
    assert mech.origin.kind == "file" and mech.origin.path.endswith("rpr.yaml")
    assert registry.BUILTIN_FILES["rpr"] == "rpr.yaml" and "rpr" not in registry.BUILTIN
    assert registry.ADDONS["rpr"] == "cpm_nlp.mechanisms.rpr.addon:ADDON"
    with pytest.raises(ModuleNotFoundError):
        __import__("cpm_nlp.mechanisms.rpr.kinematics")
    with pytest.raises(ModuleNotFoundError, match="rpr.yaml"):
        __import__("cpm_nlp.rpr")
    # the add-on's parts, and only those, beside the file's
    assert (
        set(mech.kinds)
        == set(addon.ADDON.kinds)
        == {
            "rpr_screw_jacobian",
            "rpr_twists",
            "rpr_transmission_map",
            "rpr_joint_design",
            "rpr_compliance",
        }
    )
    assert mech.kinds["rpr_twists"] is kinds.Twists and isinstance(mech.part(cn.SynthesisFormulation), kinds.Synthesis)
    assert mech.geometry is not None and mech.part(cn.DynamicsModel) is None  # the file's drawing
    # the old name of the file twin names the same mechanism (old scripts, old problem files)
    assert registry.mechanism_type("rpr_file") is mech
    assert "rpr_file" not in registry.mechanism_names()
    assert cn.load_problem(PROBLEMS / "rpr_file_forward_kinematics.yaml").model.mechanism is mech


def test_the_name_resolves_to_the_file_without_reading_the_others(monkeypatch):
    read = []
    # listing the shipped files is what reading the others would take
    monkeypatch.setattr(registry.described, "shipped_files", lambda: read.append("listed") or [])
    fresh = registry._Registry()
    mech = fresh.lookup("rpr")
    assert mech is not None and mech.name == "rpr" and "rpr_twists" in mech.kinds
    assert fresh._specs is None and read == []


def test_the_addon_may_not_repeat_the_file():
    mech = registry.mechanism_type("rpr")
    with pytest.raises(MechanismDeclarationError, match="repeats what the file declares .*rpr_twists"):
        with_addon(mech, Addon(kinds={"rpr_twists": kinds.Twists}))
    with pytest.raises(MechanismDeclarationError, match="repeats what the file declares .*synthesis"):
        with_addon(mech, Addon(parts=(addon.RprSynthesis(),)))
    with pytest.raises(MechanismDeclarationError, match="repeats what the file declares .*stiffness"):
        with_addon(mech, Addon(parts=(mech.part(JointStiffness),)))  # the file declares the Table 1 hinges


@pytest.mark.parametrize("params", PARAMETER_SETS, ids=["eq26", "eq47", "eq49"])
def test_fk_ik_passive_and_jacobians_equal_the_reference(params):
    fm, rm = cn.build_model("rpr", params), ref.reference_model(params)
    assert (fm.closure.x_names, fm.closure.q_names) == (rm.closure.x_names, rm.closure.q_names)
    assert fm.closure.passive_names == rm.closure.passive_names
    assert fm.closure.task == rm.closure.task
    assert fm.derived == pytest.approx(rm.derived, rel=1e-15)
    assert fm.characteristic_length == pytest.approx(rm.characteristic_length, rel=1e-15)
    for a, b in ((fm.x_home, rm.x_home), (fm.q_home, rm.q_home), (fm.x_lower, rm.x_lower), (fm.x_upper, rm.x_upper)):
        close(a, b)
    assert_same_kinematics(fm, rm, _poses(rm), task_is_pose=True)


@pytest.mark.parametrize("params", PARAMETER_SETS, ids=["eq26", "eq47", "eq49"])
def test_closed_form_ik_and_passive_functions_equal_the_reference(params):
    """The file's ik and passive functions themselves (not through a solve), to 1e-12."""
    fm, rm = cn.build_model("rpr", params), ref.reference_model(params)
    for t in _poses(rm):
        xf, qf, reach_f = (np.asarray(v, dtype=float).ravel() for v in fm.closure.ik(t, fm.p))
        xr, qr, reach_r = (np.asarray(v, dtype=float).ravel() for v in rm.closure.ik(t, rm.p))
        close(xf, xr)
        close(qf, qr)
        close(reach_f, reach_r)
        close(np.asarray(fm.closure.passive(t, qr, fm.p)), np.asarray(rm.closure.passive(t, qr, rm.p)))


def test_ad_jacobians_against_central_differences_and_fk_against_ik():
    """dq/dt of the file's closures against central differences of the reference's IK, the
    file's passive-angle derivatives (the add-on's, rc.passive_jacobian) against those of the
    reference's passive angles, and FK (Newton, from home) back to the IK pose."""
    fm, rm = cn.build_model("rpr", ref.PAPER), ref.reference_model()
    h = 1e-7
    for t in _poses(rm, n=6, seed=7):
        ik = cn.inverse_kinematics(fm, t)
        assert ik.status is Status.SOLVED
        J_inv = cn.jacobians(fm, ik.x, ik.q).J_inv

        def legs(x):
            return np.asarray(rm.closure.ik(x, rm.p)[1], dtype=float).ravel()

        def passive(x):
            return np.asarray(rm.closure.passive(x, legs(x), rm.p), dtype=float).ravel()

        fd = _central(legs, t, h)
        np.testing.assert_allclose(J_inv, fd, rtol=0, atol=1e-7 * np.abs(fd).max())
        dj_dx, dj_dq = (np.asarray(v) for v in rc.passive_jacobian(fm.closure)(t, ik.q, fm.p))
        fd = _central(passive, t, h)
        np.testing.assert_allclose(dj_dx, fd, rtol=0, atol=1e-7 * np.abs(fd).max())
        assert not dj_dq.any()  # the passive angles are functions of the pose
        fk = cn.forward_kinematics(fm, ik.q, cn.SolverConfig("newton"))
        assert fk.status is Status.SOLVED
        close(fk.x, t, 1e-11)


def test_the_residuals_differ_by_a_row_scale_only():
    """The file's leg equation (|A_iB_i|^2 - l_i^2)/(2 P0) is the reference's |A_iB_i| - l_i
    times (|A_iB_i| + l_i)/(2 P0): equal at home, and every row of Phi_x and Phi_q scaled by
    l_i/P0 at a solution.  Poses, Jacobians and passive joints do not depend on the scale
    (tested above); the jacobian kind's Phi_x, Phi_q and their determinants do."""
    fm, rm = cn.build_model("rpr", ref.PAPER), ref.reference_model()
    P0 = rm.parameters["P0"]
    close(fm.closure.phi_x(rm.x_home, rm.q_home, fm.p), rm.closure.phi_x(rm.x_home, rm.q_home, rm.p))
    for t in _poses(rm, n=5, seed=3):
        ik = cn.inverse_kinematics(rm, t)
        scale = np.diag(ik.q / P0)
        for f in ("phi_x", "phi_q"):
            a = np.asarray(getattr(fm.closure, f)(ik.x, ik.q, fm.p))
            b = np.asarray(getattr(rm.closure, f)(ik.x, ik.q, rm.p))
            close(a, scale @ b)


def test_branch_indicator_signs_agree_on_the_mirror_assembly():
    """On the working branch every indicator of both is positive; the mirror image below the
    base, (-theta, -alpha, -P), closes eq 6 with the same leg lengths, and there the reference's
    P and B_i heights and the file's P and legs' S1 indicators (the cosine of leg i to z) are all
    negative: both report it as the wrong branch."""
    fm, rm = cn.build_model("rpr", ref.PAPER), ref.reference_model()
    names = list(fm.closure.branch_names)
    sided = [names.index(n) for n in ("P", "leg1.S1", "leg2.S1", "leg3.S1")]
    for t in _poses(rm):
        ik = cn.inverse_kinematics(rm, t)
        g = np.asarray(fm.closure.branch(ik.x, ik.q, fm.p), dtype=float).ravel()
        h = np.asarray(rm.closure.branch(ik.x, ik.q, rm.p), dtype=float).ravel()
        assert (g > 0).all() and (h > 0).all()
        mirror = -ik.x
        assert np.max(np.abs(cn.residual(rm, mirror, ik.q))) < 1e-15
        g = np.asarray(fm.closure.branch(mirror, ik.q, fm.p), dtype=float).ravel()
        h = np.asarray(rm.closure.branch(mirror, ik.q, rm.p), dtype=float).ravel()
        assert (h < 0).all() and (g[sided] < 0).all()
        a, b = cn.inverse_kinematics(rm, mirror), cn.inverse_kinematics(fm, mirror)
        assert a.status is b.status is Status.WRONG_BRANCH


def test_the_addon_formulations_on_the_file_equal_them_on_the_reference():
    """G and G_p (eq 11, 13), K' (eq 40) and the compliance model (eq 33-44) of the add-on, run
    on the file's closures and on the reference's: equal to 1e-12."""
    fm, rm = cn.build_model("rpr", ref.PAPER), ref.reference_model()
    for t in _poses(rm, n=4, seed=5):
        for a, b in zip(rc.passive_rates(fm, t), rc.passive_rates(rm, t)):
            close(a, b)
        k_f, k_r = rc.stiffness_order(fm, 12.0, 3.0), rc.stiffness_order(rm, 12.0, 3.0)
        assert k_f.tolist() == k_r.tolist() == [12.0, 3.0, 3.0, 3.0, 3.0, 12.0, 12.0, 3.0, 3.0]
        out_f = rc.compliance_model(fm, t, l1=16e-3, l2=1.6e-3, c_r=0.2, c_t=3e-9, k_J=k_f)
        out_r = rc.compliance_model(rm, t, l1=16e-3, l2=1.6e-3, c_r=0.2, c_t=3e-9, k_J=k_r)
        for key in ("G", "G_p", "K_prime", "C", "C_in"):
            np.testing.assert_allclose(out_f[key], out_r[key], rtol=1e-12, atol=1e-12 * np.abs(out_r[key]).max())


def test_the_compliance_equals_the_value_before_the_move():
    res = cn.solve(cn.load_problem(PROBLEMS / "rpr_compliance.yaml"))
    assert res.status is Status.SOLVED
    for name, before in COMPLIANCE_BEFORE.items():
        b = np.asarray(before)
        np.testing.assert_allclose(res.values[name], b, rtol=0, atol=1e-12 * np.abs(b).max(), err_msg=name)


def test_the_twists_fk_columns_are_the_exact_roots():
    """problems/rpr_twists_eq47.yaml's T_fk (S_t times the FK pose change for 10 um on each leg)
    is the exact one: the Newton root of the file's closures and of the reference's (they agree
    to 1e-15).  Before the move IPOPT stopped on the reference's |A_iB_i| - l_i after its first
    step, the linear prediction (T_fk - T = 7.7e-17); the exact columns differ from the linear
    T by the second-order 2.6e-12."""
    from cpm_nlp.mechanisms.rpr import screws

    problem = cn.load_problem(PROBLEMS / "rpr_twists_eq47.yaml")
    res = cn.solve(problem)
    assert res.status is Status.SOLVED
    fm = problem.model
    rm = ref.reference_model(PARAMETER_SETS[1])  # eq 47's design, as the problem file
    x, q = fm.x_home, fm.q_home
    S = screws.twist_basis(fm, x, screws.reference_point(fm, x, "o_prime", None), "eq45")
    newton = cn.SolverConfig("newton")
    for k in range(3):
        qk = q + 10e-6 * np.eye(3)[k]
        a, b = cn.forward_kinematics(fm, qk, newton), cn.forward_kinematics(rm, qk, newton)
        close(a.x, b.x, 1e-15)
        close(np.asarray(res.values["T_fk"])[:, k], S @ (a.x - x), 1e-13)  # IPOPT's root: to its tolerance
    assert 1e-12 < res.values["dT_fk"] < 5e-12


def test_what_users_see_is_what_the_module_declared():
    """Parameters (bounds exclusive), limit families with their descriptions, the pose and the
    passive joints with their families and descriptions, the title, the paper, the problem
    files, derived D (eq 20) and the Table 1 hinges the module declared."""
    mech = registry.mechanism_type("rpr")
    assert mech.title == ref.MECHANISM.title and mech.paper == ref.MECHANISM.paper
    assert mech.parameters == ref.PARAMETERS
    limits = {o.name: o for o in mech.limits}
    for o in ref.LIMITS:
        assert limits[o.name] == o
    assert set(limits) - {o.name for o in ref.LIMITS} == {"l1", "l2", "l3"}  # one leg's stroke alone
    model = cn.build_model("rpr", ref.PAPER)
    assert tuple(model.closure.x) == ref.X and tuple(model.closure.passive_coords) == ref.PASSIVE
    assert model.derived == {"D": pytest.approx(0.16 / 3, rel=1e-15)} and model.dimensions["D"] == "length"
    names = {str(p).rsplit("/", 1)[-1] for p in mech.problem_files}
    for f in ("forward_kinematics", "screw_jacobian", "twists_eq47", "synthesis_fixed_P", "compliance"):
        assert f"rpr_{f}.yaml" in names
    PW = "circular_notch_paros_weisbord"  # the beam integrals of its eq 29
    assert mech.part(JointStiffness) == JointStiffness(
        hinges={
            "R": {"joints": "theta_R", "type": PW, "r": "4 mm", "t": "0.4 mm", "w": "12 mm"},
            "U": {"joints": "theta_U", "type": PW, "r": "1 mm", "t": "0.4 mm", "w": "12 mm"},
        },
        material="Al 7075-T6",
        source="Zhang et al. 2022 Table 1 (joint dimensions) and section 5 (Al-7075)",
    )


def test_strict_bounds_refuse_zero_lengths():
    for name in ("r1", "r2", "P0"):
        with pytest.raises(cn.InputError, match=r"in \(0"):
            cn.build_model("rpr", {**ref.PAPER, name: "0 mm"})
