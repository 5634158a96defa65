"""The 3-PRS written once (issue 21, item 5): the registered ``prs3`` is the mechanism file
problems/mechanisms/prs3.yaml, its closures generated from the legs; the hand-written
closures it replaced (tests/reference/prs3_closures.py, derived from prs3-ruiz.md eq 2-35)
are the independent reference it is checked against here.

* FK, IK, passive joints and the Jacobians dx/dq (whole pose and task) at 20 seeded random
  poses of the paper's working range (section 4: z +-2 mm, psi and theta +-0.2 deg), to
  1e-12 (absolute, on values of order 1 in SI: metres, radians, and the Jacobians' scale);
* the branch indicators' signs on the working branch and on the other assembly branches
  (a leg on eq 20's other root, and the mirror image of the stage below its base);
* what users see: parameters (bounds exclusive, as the hand-written module declared them),
  limit families and their descriptions, the paper's hinges, derived values and the drawing.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import cpm_nlp as cn
from cpm_nlp.mechanisms import registry
from tests.reference import assert_same_kinematics
from tests.reference import prs3_closures as ref

NEWTON = cn.SolverConfig(method="newton")
TOL = 1e-12
PAPER = {"b": "47.91 mm", "L": "109.215 mm", "alpha0": "45 deg"}
#: the paper's stage, and two others (the file is generated for every parameter value)
PARAMETER_SETS = [
    PAPER,
    {"b": "30 mm", "L": "80 mm", "alpha0": "35 deg"},
    {"b": "60 mm", "L": "150 mm", "alpha0": "60 deg"},
]


def _models(params):
    return cn.build_model("prs3", params), ref.reference_model(params)


def _close(a, b, tol=TOL):
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    scale = max(1.0, float(np.max(np.abs(b))))
    np.testing.assert_allclose(a, b, rtol=0, atol=tol * scale)


def _poses(model, n=20, seed=21):
    """n task poses (pz, psi, theta) in the paper's range: z +-2 mm about home, tilts +-0.2 deg."""
    rng = np.random.default_rng(seed)
    tilt = math.radians(0.2)
    pz0 = model.derived["pz0"]
    return np.column_stack(
        [pz0 + rng.uniform(-2e-3, 2e-3, n), rng.uniform(-tilt, tilt, n), rng.uniform(-tilt, tilt, n)]
    )


def test_the_registered_prs3_is_the_file():
    mech = registry.mechanism_type("prs3")
    assert mech.origin.kind == "file" and mech.origin.path.endswith("prs3.yaml")
    assert "prs3" in registry.BUILTIN_FILES and "prs3" not in registry.BUILTIN
    with pytest.raises(ModuleNotFoundError):
        __import__("cpm_nlp.mechanisms.prs3")
    # the old name of the file twin names the same mechanism (old scripts, old problem files)
    assert registry.mechanism_type("prs3_file") is mech
    assert "prs3_file" not in registry.mechanism_names()


def test_the_name_resolves_to_the_file_without_reading_the_others(monkeypatch):
    """Issue 23 (start-up): a built-in file's name is its file; the plugins and the other
    shipped files are not discovered (nor their YAML parsed) to resolve it."""
    read = []
    # listing the shipped files is what reading the others would take
    monkeypatch.setattr(registry.described, "shipped_files", lambda: read.append("listed") or [])
    fresh = registry._Registry()
    mech = fresh.lookup("prs3")
    assert mech is not None and mech.name == "prs3" and mech.origin.path.endswith("prs3.yaml")
    assert fresh._specs is None and read == []
    assert fresh.lookup("prs3_file") is mech  # the old name: the discovery runs, and maps it
    assert fresh.lookup("prs3_nonesuch") is None


@pytest.mark.parametrize("params", PARAMETER_SETS, ids=["paper", "small", "steep"])
def test_fk_ik_passive_and_jacobians_equal_the_reference(params):
    fm, rm = _models(params)
    assert (fm.closure.x_names, fm.closure.q_names) == (rm.closure.x_names, rm.closure.q_names)
    assert fm.closure.passive_names == rm.closure.passive_names
    assert fm.closure.task == rm.closure.task and fm.closure.offsets == rm.closure.offsets
    for k in ("a", "pz0"):
        assert fm.derived[k] == pytest.approx(rm.derived[k], rel=1e-15)
    assert fm.characteristic_length == rm.characteristic_length
    _close(fm.x_home, rm.x_home)
    _close(fm.q_home, rm.q_home)
    assert_same_kinematics(fm, rm, _poses(rm))


def _indicators(model, x, q):
    c = model.closure
    return dict(zip(c.branch_names, np.asarray(c.branch(x, q, model.p), dtype=float).ravel()))


def _compare_signs(fm, rm, x, q):
    """The file's indicators against the reference's: leg i's working mode (file legi.R2, the
    R joint after the slider) is the reference's leg{i}.inward (l_i0 . s_i0); the declared
    above_base (pz) is the reference's legs rising (l_i0 . z, all three); the aspects agree."""
    g, h = _indicators(fm, x, q), _indicators(rm, x, q)
    for i in (1, 2, 3):
        assert np.sign(g[f"leg{i}.R2"]) == np.sign(h[f"leg{i}.inward"]), (i, g, h)
    rising = [h[f"leg{i}.rising"] for i in (1, 2, 3)]
    assert np.sign(g["above_base"]) == np.sign(min(rising)) == np.sign(max(rising)), (g, h)
    assert np.sign(g["aspect"]) == np.sign(h["aspect"]), (g, h)
    assert all(v > 0 for v in g.values()) == all(v > 0 for v in h.values())
    return g, h


def test_branch_indicator_signs_agree_on_both_assembly_branches():
    fm, rm = _models(PAPER)
    flipped = mirrored = 0
    for t in _poses(rm):
        ik = cn.inverse_kinematics(rm, t)
        x, q = ik.x, ik.q
        g, _ = _compare_signs(fm, rm, x, q)  # the working branch: every indicator positive
        assert all(v > 0 for v in g.values())
        # the other root of eq 20 for one leg: the leg leans outward, the same platform pose
        for i in range(3):
            R = np.array(ref.rotation(x[3], x[4], x[5]), dtype=float)
            B = x[:3] + R @ np.array(ref.PB_m(i, rm.p[0]), dtype=float).ravel()
            AB = B - np.array(ref.OA(i, rm.derived["a"]), dtype=float).ravel()
            s0 = np.array(ref.s0(i), dtype=float).ravel()
            k = s0 @ AB
            q2 = q.copy()
            q2[i] = k + math.sqrt(k**2 - AB @ AB + rm.p[1] ** 2)  # eq 20, the + root
            assert np.max(np.abs(cn.residual(rm, x, q2))) < 1e-15
            g, h = _compare_signs(fm, rm, x, q2)
            assert g[f"leg{i + 1}.R2"] < 0 and h[f"leg{i + 1}.inward"] < 0
            flipped += 1
        # the mirror image below the base (z -> -z: psi, theta change sign, phi does not)
        xm = np.array([x[0], x[1], -x[2], -x[3], -x[4], x[5]])
        assert np.max(np.abs(cn.residual(rm, xm, q))) < 1e-15
        g, h = _compare_signs(fm, rm, xm, q)
        assert g["above_base"] < 0 and max(h[f"leg{i}.rising"] for i in (1, 2, 3)) < 0
        mirrored += 1
    assert (flipped, mirrored) == (60, 20)


def test_what_users_see_is_what_the_module_declared():
    """Parameters (names, dimensions, defaults, exclusive bounds, descriptions), limit
    families with their descriptions, the hinges, material and source of section 5."""
    mech = registry.mechanism_type("prs3")
    assert mech.title == ref.MECHANISM.title and mech.paper == ref.MECHANISM.paper
    assert mech.parameters == ref.PARAMETERS
    limits = {o.name: o for o in mech.limits}
    for o in ref.LIMITS:
        assert limits[o.name] == o
    # the file also offers one actuator's stroke alone (generated for every file)
    assert set(limits) - {o.name for o in ref.LIMITS} == {"s1", "s2", "s3"}
    assert mech.part(cn.JointStiffness) == ref.STIFFNESS
    assert mech.part(cn.LegChains) is not None and mech.geometry is not None
    names = [str(p) for p in mech.problem_files]
    assert any(n.endswith("prs3_forward_kinematics.yaml") for n in names)
    assert any(n.endswith("prs3_file_table2_forces.yaml") for n in names)


def test_strict_bounds_refuse_their_ends():
    for name, value in (("b", "0 mm"), ("L", "0 mm"), ("alpha0", "90 deg"), ("alpha0", "0 deg")):
        with pytest.raises(cn.InputError, match=r"in \(0"):
            cn.build_model("prs3", {**PAPER, name: value})
