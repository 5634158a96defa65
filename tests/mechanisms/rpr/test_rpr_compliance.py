"""Flexure-joint design (eq 27-32, Table 1) and the pseudo-rigid-body compliance
model (eq 33-44, eq 55, 58) of the RPR compliant mechanism."""

import math
from pathlib import Path

import numpy as np
import pytest

import cpm_nlp as cn
from cpm_nlp.analysis import flexure
from cpm_nlp.analysis import flexure_compliance as fc
from cpm_nlp.mechanisms.rpr import compliance as rc
from cpm_nlp.mechanisms.rpr import screws as rpr

ROOT = Path(__file__).resolve().parents[3]
AL = flexure.MATERIALS["Al 7075-T6"]
SPEC = rc.JointSpec(AL, SF=2.0, theta_des=math.radians(2), box=12e-3, t_min=0.3e-3, couple_arm=1.0)
TABLE1 = {"R": (4e-3, 0.4e-3, 12e-3), "U": (1e-3, 0.4e-3, 12e-3)}


@pytest.fixture(scope="module")
def model():
    return cn.build_model("rpr", {"r1": "40 mm", "r2": "80 mm", "P0": "40 mm"})


def test_eq_27_work_of_the_leg_wrenches_gives_the_terms_of_eq_30_and_31(model):
    W = rc.design_wrenches(model, couple_arm=1.0)
    L = 0.04  # |A1B1| at the initial pose
    ev = rc.evaluate_joint("R", SPEC, W["R"], TABLE1["R"])
    c = ev["compliances"]
    assert ev["f"] == pytest.approx(c["cr_tx"] + c["cr_ty"] + L**2 * c["cr_mx"] + c["cr_mz"], rel=1e-12)  # eq 30
    ev = rc.evaluate_joint("U", SPEC, W["U"], TABLE1["U"])
    c = ev["compliances"]
    assert ev["f"] == pytest.approx(c["cu_tx"] + c["cu_ty"] + c["cu_mz"], rel=1e-12)  # eq 31
    # the couple is scaled by couple_arm: its work by couple_arm^2
    W2 = rc.design_wrenches(model, couple_arm=0.5)
    ev2 = rc.evaluate_joint("U", SPEC, W2["U"], TABLE1["U"])
    assert ev2["f"] == pytest.approx(c["cu_tx"] + c["cu_ty"] + 0.25 * c["cu_mz"], rel=1e-12)


def test_table_1_against_eq_32():
    # R: r/t = 10 allows 2.01 deg with SF = 2 (feasible); U: r/t = 2.5 allows 0.50 deg (not)
    W = rc.design_wrenches(cn.build_model("rpr", {"r1": "40 mm", "r2": "80 mm", "P0": "40 mm"}), 1.0)
    r = rc.evaluate_joint("R", SPEC, W["R"], TABLE1["R"])
    u = rc.evaluate_joint("U", SPEC, W["U"], TABLE1["U"])
    assert r["feasible"] and math.degrees(r["theta_max"]) == pytest.approx(2.0098, abs=1e-4)
    assert not u["feasible"] and math.degrees(u["theta_max"]) == pytest.approx(0.50244, abs=1e-4)
    assert math.degrees(fc.rotation_limit_eq32(AL.E, 0.4e-3, 1e-3, AL.yield_strength, 1.0)) < 2.0


def test_joint_design_meets_every_constraint_and_beats_table_1(model):
    W = rc.design_wrenches(model, 1.0)
    for joint in ("R", "U"):
        d = rc.joint_design(model, joint, SPEC, cn.SolverConfig(), starts=4)
        assert d.status is cn.Status.SOLVED and d.converged == 4 and d.at_best == 4, d.message
        ev = rc.evaluate_joint(joint, SPEC, W[joint], d.dims)
        assert all(v >= -1e-12 for v in ev["margins"].values()), ev["margins"]
        assert d.theta_max == pytest.approx(SPEC.theta_des, rel=1e-8)  # eq 32 binds
        if joint == "R":
            assert d.dims[2] == pytest.approx(12e-3)  # b at the box
            assert d.dims[1] + 2 * d.dims[0] == pytest.approx(12e-3)  # the block holds the notch
            assert d.f < rc.evaluate_joint("R", SPEC, W["R"], TABLE1["R"])["f"]
        else:
            assert d.dims[0] == pytest.approx(3e-3)  # two notches fill the box: 4 r = 12 mm
            assert d.dims[2] == pytest.approx(12e-3)
        # no feasible neighbour is better (local optimality by sampling)
        rng = np.random.default_rng(3)
        for _ in range(20):
            trial = np.array(d.dims) * (1 + 0.02 * rng.normal(size=3))
            e = rc.evaluate_joint(joint, SPEC, W[joint], trial)
            if e["feasible"]:
                assert e["f"] >= d.f * (1 - 1e-9)


def test_eq_36_amplifier_matrices_and_the_exchanged_arms():
    A = rc.amplifier_matrices(l1=16e-3, l2=1.6e-3, c_r=0.2, c_t=3e-9)
    assert A["A21"][0, 0] / A["A11"][0, 0] == pytest.approx(10.0)  # amplification l1/l2
    assert A["A22"][1, 1] == pytest.approx((16e-3**2 * 0.2 + 4 * 3e-9) / 4)
    assert np.allclose(A["A12"], A["A21"])


def test_compliance_model_structure(model):
    kR, kU = 3.0, 6.0
    out = rc.compliance_model(
        model, model.x_home, l1=16e-3, l2=1.6e-3, c_r=0.2, c_t=3e-9, k_J=rc.stiffness_order(model, kR, kU)
    )
    G, G_p, K = out["G"], out["G_p"], out["K_prime"]
    assert np.allclose(G, rpr.screw_jacobian(model, model.x_home).G)
    assert np.allclose(G_p, rpr.screw_jacobian(model, model.x_home).G_p)
    assert np.allclose(K, K.T) and np.all(np.linalg.eigvalsh(K) > -1e-9)
    # at the initial pose only the theta and alpha rotations of the joints work (eq 39-40)
    g_t, g_a = G[0], G[1]
    K_hand = (2 * kR + kU) * np.outer(g_t, g_t) + (kR + 2 * kU) * np.outer(g_a, g_a)
    assert np.allclose(K, K_hand)
    assert np.allclose(out["C"], G @ np.linalg.solve(np.eye(3) + out["A22"] @ K, out["A21"]))  # eq 43
    assert np.allclose(out["C_in"], out["C_in"].T)
    # without joint stiffness the amplifiers run free: C = A21 G, C_in = A11
    free = rc.compliance_model(model, model.x_home, l1=16e-3, l2=1.6e-3, c_r=0.2, c_t=3e-9, k_J=np.zeros(9))
    assert np.allclose(free["C"], free["A21"][0, 0] * G)
    assert np.allclose(free["C_in"], free["A11"])
    assert np.allclose(free["amp"], 10.0)


def test_compliance_of_the_shipped_assumptions_against_eq_55_and_58(model):
    kR = 1 / fc.circular_notch_compliances(AL.E, AL.G, 12e-3, 0.4e-3, 4e-3)["rz"]
    kU = 1 / fc.circular_notch_compliances(AL.E, AL.G, 12e-3, 0.4e-3, 1e-3)["rz"]
    c_r, c_t = rc.leaf_compliances(AL, 1e-3, 0.4e-3, 12e-3)
    out = rc.compliance_model(
        model, model.x_home, l1=16e-3, l2=1.6e-3, c_r=c_r, c_t=c_t, k_J=rc.stiffness_order(model, kR, kU)
    )
    C, C_in = out["C"], out["C_in"]
    # eq 55 (the paper's theory) and eq 58, within the 15 % of problems/rpr_compliance.yaml
    assert C[0, 0] == pytest.approx(-1.8704e-5, rel=0.15)
    assert C[1, 0] == pytest.approx(-9.1276e-6, rel=0.15)
    assert C[2, 0] == pytest.approx(7.4223e-7, rel=0.15)
    assert C_in[0, 0] == pytest.approx(1.4083e-7, rel=0.15)
    assert C_in[1, 1] == pytest.approx(1.2084e-7, rel=0.15)
    # mirror symmetry of legs 1 and 3: opposite tilts, equal alpha and P
    assert C[0, 2] == pytest.approx(-C[0, 0]) and C[1, 2] == pytest.approx(C[1, 0])
    assert C[0, 1] == pytest.approx(0.0, abs=1e-20)


def test_compliances_carry_their_dimensions():
    """Issue 22: c_r (eq 35: a rotation per moment) and c_t (a stretch per force) and the
    amplifier's A11..A22 (eq 36: displacements per force) are compliances, not dimensionless
    numbers; pint agrees that each unit is the reciprocal of its stiffness's and of the
    quantities it relates (independent of core.units' own tables)."""
    import pint

    from cpm_nlp.core.units import DIMENSIONS

    ureg = pint.UnitRegistry()
    for name, per in (("rotational_compliance", "rad/(N*m)"), ("compliance", "m/N")):
        assert ureg(DIMENSIONS[name].si).dimensionality == ureg(per).dimensionality
    stiff = {"rotational_compliance": "rotational_stiffness", "compliance": "stiffness"}
    for name, k in stiff.items():
        assert (ureg(DIMENSIONS[name].si) * ureg(DIMENSIONS[k].si)).dimensionless
    res = cn.solve(cn.load_problem(ROOT / "problems" / "rpr_compliance.yaml"))
    assert res.ok, res.message
    assert (res.dimensions["c_r"], res.units["c_r"]) == ("rotational_compliance", "rad/(N*m)")
    assert (res.dimensions["c_t"], res.units["c_t"]) == ("compliance", "m/N")
    assert {res.dimensions[a] for a in ("A11", "A12", "A21", "A22")} == {"compliance"}
    # c_r = 1/k_r of the leaf hinge: the product with a rotational stiffness is a number
    product = ureg.Quantity(res.values["c_r"], res.units["c_r"]) * ureg.Quantity(1.0, "N*m/rad")
    assert product.dimensionless
    # the joints' diagonal compliances (eq 28-29): a translation per force, a rotation per moment
    joints = problem_kind_outputs("rpr_joint_design")
    assert joints["cr_tx"].dimension == "compliance" and joints["cu_mz"].dimension == "rotational_compliance"
    assert joints["cr_mx"].si.startswith("rad/(N*m)") and joints["cr_tx"].si.startswith("m/N")


def problem_kind_outputs(kind: str) -> dict:
    from cpm_nlp.problems.describe import reference_model

    model, _ = reference_model("rpr")
    return {o.name: o for o in cn.problem_kind(kind).outputs(model)}


def test_the_leaf_as_a_beam_against_eq_55_and_58():
    """The amplifier's leaf hinge as a Timoshenko beam (leaf model: beam): its rotation and
    stretch at the centre are the PRB's 12 L/(E w t^3) and L/(E w t) (Fig. 8), so C and C_in are
    those of eq 33-44 (the eq 55, 58 model); it adds the transverse compliance the bridge model
    leaves out, checked against L^3/(12 E I) + L/(kappa G A) written out (Cowper's kappa)."""
    import json
    import subprocess
    import sys

    length, t, w = 1e-3, 0.4e-3, 12e-3  # the shipped leaf (problems/rpr_compliance.yaml)
    c_r, c_t, c_s = rc.leaf_beam_compliances(AL, length, t, w)
    E, nu = AL.E, AL.nu
    G, inertia, area = E / (2 * (1 + nu)), w * t**3 / 12, w * t
    assert c_r == pytest.approx(12 * length / (E * w * t**3), rel=1e-12)
    assert c_t == pytest.approx(length / (E * w * t), rel=1e-12)
    kappa = 10 * (1 + nu) / (12 + 11 * nu)
    assert c_s == pytest.approx(length**3 / (12 * E * inertia) + length / (kappa * G * area), rel=1e-12)
    path = str(ROOT / "problems/rpr_compliance.yaml")
    runs = [
        json.loads(
            subprocess.run(
                [sys.executable, "-m", "cpm_nlp", "solve", path, "--json", *extra], capture_output=True, text=True
            ).stdout
        )["values"]
        for extra in ([], ["--set", "inputs.amplifier.leaf.model=beam"])
    ]
    prb, beam = runs
    np.testing.assert_allclose(beam["C"], prb["C"], rtol=1e-12, atol=1e-20)
    np.testing.assert_allclose(beam["C_in"], prb["C_in"], rtol=1e-12, atol=1e-22)
    assert prb["c_s"] is None and beam["c_s"] == pytest.approx(c_s, rel=1e-9)
    # what the bridge model leaves out: 9.4 times the stretch, a fifth of C_in
    assert beam["c_s"] / beam["c_t"] == pytest.approx(9.376, rel=1e-3)


def test_the_shipped_leaf_beam_file_is_the_prb_file_with_the_beam():
    """problems/rpr_compliance_leaf_beam.yaml: the inputs of problems/rpr_compliance.yaml with
    leaf model: beam; C and C_in equal that file's (the eq 55, 58 model, to 1e-12), and c_s is
    the Timoshenko transverse compliance of its leaf, 2.724e-8 m/N (the value
    leaf_beam_compliances gives, checked written out above)."""
    prb = cn.solve(cn.load_problem(ROOT / "problems" / "rpr_compliance.yaml"))
    beam = cn.solve(cn.load_problem(ROOT / "problems" / "rpr_compliance_leaf_beam.yaml"))
    assert prb.ok and beam.ok, (prb.message, beam.message)
    np.testing.assert_allclose(beam.values["C"], prb.values["C"], rtol=1e-12, atol=1e-20)
    np.testing.assert_allclose(beam.values["C_in"], prb.values["C_in"], rtol=1e-12, atol=1e-22)
    assert beam.values["c_s"] == pytest.approx(rc.leaf_beam_compliances(AL, 1e-3, 0.4e-3, 12e-3)[2], rel=1e-12)
    assert beam.values["c_s"] == pytest.approx(2.724e-8, rel=1e-3)
    assert prb.values["c_s"] is None
