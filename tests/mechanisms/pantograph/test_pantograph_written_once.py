"""The pantograph written once (issue 21, item 5): the registered ``pantograph`` is the mechanism
file problems/mechanisms/pantograph.yaml (bodies and joints only; its two loops found from the
graph) with the add-on cpm_nlp/mechanisms/pantograph/addon.py (the paper's limits of eq 31, the
closed-form workspace of eq 17-29, the cuboid of eq 32-34, the synthesis of eq 35-38).  The
hand-written closures it replaced (tests/reference/pantograph_closures.py, eq 1-8 of
pantograph-3d-elgammal-2016.md by hand) are the independent reference it is checked against.

* FK, IK, the passive hinge angle psi and the Jacobians dx/dq (task and the reference's pose
  coordinates) and dq/dt at 20 seeded poses around home, for 3 parameter sets, to 1e-12 (absolute,
  on values of order 1 in SI); the file's other coordinates are what the paper says they are
  (the second U's turn is phi, the parallelogram's angles are psi, eq 17; the sliders are q; the
  S joint at C turns about z only: its other two angles are 0);
* the AD Jacobian of the file against central differences of the reference's closed-form IK,
  and the file's FK against its own IK;
* the paper's limits on the file's coordinates and its derived values (Mx, My, Mz, omega, eq
  9-16) equal the module's, for the limits given directly, by a hinge (eq 31), theta and stroke
  counted from home;
* the add-on's parts, the alias, and the file's size (issue 21's target: at most 60 lines).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import cpm_nlp as cn
from cpm_nlp.core.mechanism import Addon, MechanismDeclarationError, with_addon
from cpm_nlp.core.result import Status
from cpm_nlp.mechanisms import registry
from cpm_nlp.mechanisms.pantograph import addon, analysis
from tests.conftest import PROBLEMS
from tests.reference import close
from tests.reference import pantograph_closures as ref

NEWTON = cn.SolverConfig(method="newton")
FILE = PROBLEMS / "mechanisms" / "pantograph.yaml"
#: the paper's section 5 (a = 20 mm, b = 50 mm), the synthesis optimum of section 6 and a short b
PARAMETER_SETS = [ref.PAPER, {"a": "10 mm", "b": "56.948 mm"}, {"a": "25 mm", "b": "15 mm"}]
#: section 5's printed limits
PAPER_LIMITS = {"psi_min": "1.49 rad", "psi_max": "1.65 rad", "phi_max": "0.0795 rad"}
#: the limits of problems/pantograph_forward_kinematics.yaml (the poses below stay inside)
WIDE_LIMITS = {"psi_min": "45 deg", "psi_max": "135 deg", "phi_max": "45 deg"}
#: the Jacobians' tolerance (relative to max(1, |J|))
JAC_TOL = 1e-12
#: the reference's pose coordinates
REF_X = ("px", "py", "pz", "theta1", "theta2", "phi")


def _poses(model: cn.Model, n: int = 20, seed: int = 21) -> np.ndarray:
    """n end-effector positions from actuators around home (|AB| within 25 % of home, mild
    angles), by eq 9-10 in closed form (p = (Mx dx, -My dy, -Mz dz), Mx = 1 + b/a, My = Mz = b/a)."""
    a, b = model.parameters["a"], model.parameters["b"]
    rng = np.random.default_rng(seed)
    r = math.sqrt(2) * a * (1 + 0.25 * rng.uniform(-1, 1, n))
    phi, m = rng.uniform(-0.3, 0.3, n), rng.uniform(-0.3, 0.3, n)
    q = np.column_stack([r * np.cos(m) * np.cos(phi), -r * np.sin(m), r * np.cos(m) * np.sin(phi)])
    return q * np.array([1 + b / a, -b / a, -b / a])


def _assert_same_pantograph(fm: cn.Model, rm: cn.Model, poses: np.ndarray) -> None:
    """As tests.reference.assert_same_kinematics, on the reference's six pose coordinates of the
    file's twelve; the file's other six are phi, psi, psi and q (the paper's eq 17)."""
    names = list(fm.closure.x_names)
    idx = [names.index(n) for n in REF_X]
    for t in poses:
        ia, ib = cn.inverse_kinematics(rm, t), cn.inverse_kinematics(fm, t)
        assert ia.status is ib.status is Status.SOLVED, (ia.message, ib.message)
        close(ib.x[idx], ia.x)
        close(ib.q, ia.q)
        close(ib.passive[:1], ia.passive)  # psi; then the S joint's two other angles at C, zero
        close(ib.passive[1:], [0.0, 0.0])
        fa, fb = cn.forward_kinematics(rm, ia.q, NEWTON), cn.forward_kinematics(fm, ia.q, NEWTON)
        assert fa.status is fb.status is Status.SOLVED, (fa.message, fb.message)
        close(fb.x[idx], fa.x)
        close(fb.x[:3], t, 1e-11)  # FK(IK(t)) = t
        psi = math.pi - (fa.x[3] - fa.x[4])  # eq 17
        close([fb.x[names.index(n)] for n in ("phiB", "psiD", "psiB")], [fa.x[5], psi, psi])
        close([fb.x[names.index(n)] for n in ("xB", "yA", "zA")], ia.q)
        pa, pb = cn.passive_joints(rm, fa.x, ia.q), cn.passive_joints(fm, fb.x, ia.q)
        assert list(pa) == ["psi"] and list(pb) == ["psi", "psiCx", "psiCy"]
        close(pb["psi"], pa["psi"])
        close([pb["psiCx"], pb["psiCy"]], [0.0, 0.0])  # the plane of L3 is that of L1
        ja, jb = cn.jacobians(rm, fa.x, ia.q), cn.jacobians(fm, fb.x, ia.q)
        close(jb.J[idx], ja.J, JAC_TOL)  # dx/dq of the reference's coordinates
        close(jb.J_task, ja.J_task, JAC_TOL)  # dt/dq
        close(jb.J_inv, ja.J_inv, JAC_TOL)  # dq/dt


# -- the registry ---------------------------------------------------------------------------------


def test_the_registered_pantograph_is_the_file_with_its_addon():
    mech = registry.mechanism_type("pantograph")
    assert mech.origin.kind == "file" and mech.origin.path.endswith("pantograph.yaml")
    assert registry.BUILTIN_FILES["pantograph"] == "pantograph.yaml" and "pantograph" not in registry.BUILTIN
    assert registry.ADDONS["pantograph"] == "cpm_nlp.mechanisms.pantograph.addon:ADDON"
    with pytest.raises(ModuleNotFoundError):
        __import__("cpm_nlp.mechanisms.pantograph.kinematics")
    with pytest.raises(ModuleNotFoundError, match="pantograph.yaml"):
        __import__("cpm_nlp.pantograph")
    # the add-on's parts, and the file's own
    assert mech.part(cn.SynthesisFormulation) is addon.ADDON.parts[0] and mech.part(cn.CuboidExtras) is addon.CUBOID
    assert mech.part(cn.PaperMembership).test is analysis.paper_membership
    assert mech.check_limits is analysis.check_limits
    assert mech.geometry is not None and mech.kinds == {}
    assert registry.mechanism_type("pantograph_file") is mech
    assert "pantograph_file" not in registry.mechanism_names()


def test_the_file_is_joints_only_and_at_most_60_lines():
    """Issue 21's target: the pantograph in at most 60 lines of joints-only YAML (its closed-form
    IK, the paper, the limits' descriptions and the problem files included)."""
    text = FILE.read_text()
    assert len(text.splitlines()) <= 60
    data = cn.mechanisms.described.read_yaml(FILE)
    assert "closures" not in data and "passive" not in data and "actuators" not in data
    assert data["name"] == "pantograph" and "joints" in data and "bodies" in data


def test_a_file_of_the_same_text_is_the_built_in(tmp_path):
    """The shipped file by path (pantograph_file_forward_kinematics.yaml) or an unchanged copy
    gets the built-in with its add-on; a changed copy of the same name is refused."""
    text = FILE.read_text()
    shipped = cn.load_problem(PROBLEMS / "pantograph_file_forward_kinematics.yaml")
    assert shipped.model.mechanism is registry.mechanism_type("pantograph")
    (tmp_path / "pantograph.yaml").write_text(text)
    problem = {
        "problem": "inverse_kinematics",
        "mechanism": {"file": "pantograph.yaml", "parameters": ref.PAPER, "limits": PAPER_LIMITS},
        "inputs": {"px": "100 mm", "py": "1 mm", "pz": "0 mm"},
    }
    model = cn.problem_from_dict(problem, base_dir=tmp_path).model
    assert model.mechanism is registry.mechanism_type("pantograph") and model.limits["psi"] == (1.49, 1.65)
    (tmp_path / "pantograph.yaml").write_text(text.replace("title: 3D", "title: A 3D"))
    with pytest.raises(cn.InputError, match="differs from it; rename it"):
        cn.problem_from_dict(problem, base_dir=tmp_path)


def test_the_addon_may_not_repeat_the_file():
    mech = registry.mechanism_type("pantograph")
    with pytest.raises(MechanismDeclarationError, match="repeats what the file declares .*check_limits"):
        with_addon(mech, Addon(check_limits=addon.ADDON.check_limits))
    for part in addon.ADDON.parts:  # the synthesis, the cuboid and the paper's membership
        with pytest.raises(MechanismDeclarationError, match=f"repeats what the file declares .*{part.capability}"):
            with_addon(mech, Addon(parts=(part,)))
    assert [p.capability for p in addon.ADDON.parts] == ["synthesis", "cuboid", "paper_membership"]


def test_the_addons_limits_replace_the_family_of_their_name():
    """The file's family theta (theta1, theta2 absolute) is the add-on's theta (counted from home,
    as the module had it); the file's other families stay (psi, phi as ranges of the joints)."""
    names = [o.name for o in registry.mechanism_type("pantograph").limits]
    assert names.count("theta") == 1 and {"psi", "phi", "dx", "psi_min", "phi_max", "stroke", "hinge"} <= set(names)
    theta = {o.name: o for o in registry.mechanism_type("pantograph").limits}["theta"]
    assert theta == {o.name: o for o in ref.LIMITS}["theta"]


# -- the kinematics equal the reference's ---------------------------------------------------------


@pytest.mark.parametrize("params", PARAMETER_SETS, ids=["section5", "section6", "short_b"])
def test_fk_ik_passive_and_jacobians_equal_the_reference(params):
    fm, rm = cn.build_model("pantograph", params, WIDE_LIMITS), ref.reference_model(params, WIDE_LIMITS)
    idx = [fm.closure.x_names.index(n) for n in REF_X]
    assert fm.closure.q_names == rm.closure.q_names == ["dx", "dy", "dz"]
    assert rm.closure.passive_names == ["psi"] and fm.closure.passive_names == ["psi", "psiCx", "psiCy"]
    assert fm.closure.task == rm.closure.task
    assert fm.parameters == rm.parameters
    close(fm.x_home[idx], rm.x_home)
    close(fm.q_home, rm.q_home)
    # Mx, My, Mz, omega from the AD Jacobian of each model's loops (eq 9-16), and the limits
    assert set(rm.derived) <= set(fm.derived)
    for k, v in rm.derived.items():
        assert fm.derived[k] == (pytest.approx(v, rel=1e-12) if v is not None else None), k
    assert fm.limits == rm.limits
    _assert_same_pantograph(fm, rm, _poses(rm))


@pytest.mark.parametrize(
    "limits",
    [
        {},
        PAPER_LIMITS,
        {"psi_min": "80 deg"},
        {"hinge": "cantilever_notch", "l": "5 mm", "t": "0.1 mm", "material": "polypropylene"},
        {"hinge": "circular_notch", "t": "1 mm", "r": "1 mm", "material": "Ti-6Al-4V", "stroke": ["-70 um", "70 um"]},
        {**PAPER_LIMITS, "theta": ["-0.1", "0.1"]},
    ],
    ids=["none", "printed", "psi_min", "eq31_cantilever", "eq38_stroke", "theta"],
)
def test_the_papers_limits_on_the_files_coordinates_equal_the_modules(limits):
    """Eq 31 (psi = pi/2 -+ delta_max, phi_max = delta_max), theta and stroke about home: the
    model's limits and derived values are the module's, by name."""
    fm, rm = cn.build_model("pantograph", ref.PAPER, limits), ref.reference_model(ref.PAPER, limits)
    assert fm.limits.keys() == rm.limits.keys()
    for k in rm.limits:
        close(fm.limits[k], rm.limits[k])
    for k, v in rm.derived.items():
        assert fm.derived[k] == (pytest.approx(v, rel=1e-12) if v is not None else None), k
        assert fm.dimensions[k] == rm.dimensions[k], k


def test_jacobian_against_central_differences_of_the_reference_ik():
    """dq/dt and dt/dq of the file's loops (AD) against central differences of the reference's
    closed-form IK (eq 9-10, an independent derivation), and the file's FK against its IK."""
    fm, rm = (
        cn.build_model("pantograph", {"a": "15 mm", "b": "40 mm"}),
        ref.reference_model({"a": "15 mm", "b": "40 mm"}),
    )
    h = 1e-8
    for t in _poses(rm, n=5, seed=7):
        ik = cn.inverse_kinematics(fm, t)
        rep = cn.jacobians(fm, ik.x, ik.q)
        fd = np.column_stack(
            [
                (np.asarray(rm.closure.ik(t + h * e, rm.p)[1]) - np.asarray(rm.closure.ik(t - h * e, rm.p)[1])).ravel()
                / (2 * h)
                for e in np.eye(3)
            ]
        )
        np.testing.assert_allclose(rep.J_inv, fd, rtol=0, atol=1e-6 * np.abs(fd).max())
        np.testing.assert_allclose(rep.J_task @ fd, np.eye(3), rtol=0, atol=1e-6)
        # eq 13: J = diag(Mx, -My, -Mz) everywhere
        np.testing.assert_allclose(rep.J_task, np.diag([1 + 40 / 15, -40 / 15, -40 / 15]), rtol=0, atol=1e-12)
        fk = cn.forward_kinematics(fm, ik.q, NEWTON)
        assert fk.status is Status.SOLVED, fk.message
        np.testing.assert_allclose(fk.x, ik.x, rtol=0, atol=1e-12)


def test_the_synthesis_magnification_is_the_closed_form():
    """The synthesis's Mx, My, Mz (symbolic in a, b, from the file's IK and AD Jacobian) are eq 9-10."""
    import casadi as ca

    a, b = ca.SX.sym("a"), ca.SX.sym("b")
    fn = ca.Function(
        "M",
        [a, b],
        list(analysis.magnification_symbolic(registry.closure_of(registry.mechanism_type("pantograph")), a, b)),
    )
    for av, bv in ((0.02, 0.05), (0.01, 0.056948), (0.03, 0.01)):
        got = [float(v) for v in fn(av, bv)]
        np.testing.assert_allclose(got, [1 + bv / av, bv / av, bv / av], rtol=1e-12)


def test_a_family_and_the_papers_limit_of_one_joint_are_refused():
    with pytest.raises(cn.InputError, match=r"either psi .* or psi_min"):
        cn.build_model("pantograph", ref.PAPER, {"psi": ["1.4", "1.7"], "psi_min": "1.49"})
    with pytest.raises(cn.InputError, match=r"either phi .* or hinge"):
        cn.build_model(
            "pantograph",
            ref.PAPER,
            {
                "phi": ["-0.1", "0.1"],
                "hinge": "cantilever_notch",
                "l": "5 mm",
                "t": "0.1 mm",
                "material": "polypropylene",
            },
        )
    with pytest.raises(cn.InputError, match=r"either dx .* or stroke"):
        cn.build_model("pantograph", ref.PAPER, {"dx": ["0", "0.03"], "stroke": ["-1e-4", "1e-4"]})
    # a family of the file alone limits its joint (problems/pantograph_file_forward_kinematics.yaml)
    m = cn.build_model("pantograph", ref.PAPER, {"psi": ["45 deg", "135 deg"]})
    close(m.limits["psi"], [math.pi / 4, 3 * math.pi / 4])
