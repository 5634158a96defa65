"""The assembly-mode search a user can trust (issue 20): solved when it ran, modes
merged on SE(3), the region without user bounds, per-mode residual and status,
the completeness estimate from the counts, the round trip on random 6-6
platforms, the shipped 6-UPS file against the hand-written closure, the 3-PRS
modes told apart by the declared branch; FK by continuation from home and
reduced angles; named branch indicators and the ``branch:`` section."""

import math

import numpy as np
import pytest

import cpm_nlp as cn
from cpm_nlp.analysis import assembly
from cpm_nlp.analysis.assembly import assembly_modes, completeness
from cpm_nlp.core.errors import InputError
from cpm_nlp.core.kinematics import PoseSolution
from cpm_nlp.core.result import Status
from cpm_nlp.core.solver import SolverConfig
from cpm_nlp.mechanisms.described import from_dict, load_file
from cpm_nlp.problems.file import problem_from_dict, solve
from tests import gallery_closures as gc
from tests import watt_six_bar as watt
from tests.analysis.test_mode_certificate import four_bar
from tests.conftest import PAPER_PRS3, ROOT
from tests.random_platforms import Platform66, contains

UPS6 = ROOT / "problems" / "mechanisms" / "ups6.yaml"
#: the shipped problems/ups6_forward_kinematics.yaml inputs (la1..la3, lb1..lb3), m
UPS6_Q = np.array([226, 223, 224, 225, 222, 224.5]) * 1e-3


def _ups6():
    mech = load_file(UPS6)
    return mech.model(mech.closure(), {}, {}, ())


def _rz(t):
    return np.array([[math.cos(t), -math.sin(t), 0], [math.sin(t), math.cos(t), 0], [0, 0, 1]])


def _ry(t):
    return np.array([[math.cos(t), 0, math.sin(t)], [0, 1, 0], [-math.sin(t), 0, math.cos(t)]])


def _rx(t):
    return np.array([[1, 0, 0], [0, math.cos(t), -math.sin(t)], [0, math.sin(t), math.cos(t)]])


def _frame(x):
    return _rz(x[5]) @ _ry(x[4]) @ _rx(x[3]), np.asarray(x[:3])


def test_ups6_file_and_its_closure_agree():
    """The shipped 6-UPS file and the hand-written closure with the same geometry (its legs
    ordered around the hexagon: a1, b1, a2, b2, a3, b3) find the same modes, 8 (4 above the
    base, their mirror images below), each a pose with the given leg lengths.  Before: the file
    found 1 (its IPOPT box of +-60 deg was the search region, and Newton on |v| - l converged
    from 25 % of the starts)."""
    model = _ups6()
    found = assembly_modes(model, UPS6_Q, starts=2000)
    g = gc.stewart_model(ra=0.15, rp=0.1, half_a=math.radians(10), half_p=math.radians(10), h0=0.2)
    ref = assembly_modes(g, UPS6_Q[[0, 3, 1, 4, 2, 5]], starts=2000)
    assert found.count == ref.count == 8
    for md in found.modes:
        R, p = _frame(md.x)
        assert any(np.max(np.abs(R - _frame(r.x)[0])) < 1e-8 and np.max(np.abs(p - r.x[:3])) < 1e-9 for r in ref.modes)
        assert md.residual < 1e-12
    assert found.converged > 0.9 * found.starts
    assert sum(md.designated for md in found.modes) == 1 and found.modes[0].designated


def test_no_aliasing_every_rotation_once():
    """theta in (-pi, pi] gives every rotation two angle triples; modes are merged on the
    rotation matrix, so each rotation is reported once (before: 80 modes for 40)."""
    model = _ups6()
    found = assembly_modes(model, UPS6_Q, starts=1500, seed=3)
    mats = [np.r_[_frame(md.x)[0].ravel(), md.x[:3]] for md in found.modes]
    for i in range(len(mats)):
        for j in range(i):
            assert np.max(np.abs(mats[i] - mats[j])) > 1e-6
    for md in found.modes:
        assert np.all(np.abs(md.x[3:]) <= math.pi)


def test_without_a_frame_angles_alias():
    """The hand-written closure without its frame: the coordinates are compared (angles
    wrapped) and two triples of one rotation stay two modes: why the frame is used."""
    c = gc.stewart_closure()
    c.frame = None
    g = gc.stewart_model(closure=c, ra=0.15, rp=0.1, half_a=math.radians(10), half_p=math.radians(10), h0=0.2)
    found = assembly_modes(g, UPS6_Q[[0, 3, 1, 4, 2, 5]], starts=2000)
    assert found.count > 8 and found.details["merged_on"].startswith("coordinates")


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_round_trip_random_6_6_platforms(seed):
    """A random 6-6 platform, a random pose, its leg lengths: the default search (12 000 starts)
    finds that pose, and every mode it reports has those leg lengths (numpy IK).  The rate over
    40 platforms is measured by benchmarks/bench_assembly_modes.py."""
    platform = Platform66(seed)
    model = platform.model()
    pose = platform.random_pose(np.random.default_rng(1000 + seed))
    lengths = platform.lengths(pose)
    found = assembly_modes(model, lengths, seed=seed)
    assert contains(found, platform, pose)
    for md in found.modes:
        assert np.max(np.abs(platform.lengths(md.x) - lengths)) < 1e-10
    assert found.completeness.complete


def test_search_region_needs_no_bounds_and_is_reported():
    model = _ups6()
    region = assembly.search_region(model)
    assert [s for s in region.source[3:]] == ["full turn"] * 3
    assert np.allclose(region.lower[3:], -math.pi) and np.allclose(region.upper[3:], math.pi)
    assert np.all(region.upper[:3] - region.lower[:3] >= 2 * UPS6_Q.max())
    assert "psi in (-180, 180] deg (full turn)" in region.describe()


def test_freudenstein_four_bar_both_modes_without_bounds():
    """Freudenstein's four-bar (crank a2 = 1, coupler a3 = 3.5, rocker a4 = 3, ground g = 4):
    both assembly modes (open and crossed) without any bounds, against the closed form (the
    two intersections of the coupler's and the rocker's circles)."""
    model = four_bar()  # the same four-bar, written once (tests/analysis/test_mode_certificate.py)
    t2 = math.radians(70)
    B = np.array([math.cos(t2), math.sin(t2)])
    O4 = np.array([4.0, 0])
    d = np.linalg.norm(O4 - B)
    a = (3.5**2 - 3**2 + d**2) / (2 * d)
    h = math.sqrt(3.5**2 - a**2)
    e = (O4 - B) / d
    expected = []
    for s in (1, -1):
        C = B + a * e + s * h * np.array([-e[1], e[0]])
        expected.append([math.atan2(*(C - B)[::-1]), math.atan2(*(C - O4)[::-1])])
    found = assembly_modes(model, [t2], starts=300)
    assert found.count == 2
    got = np.array([md.x for md in found.modes])
    for ex in expected:
        assert np.min(np.max(np.abs((got - ex + math.pi) % (2 * math.pi) - math.pi), axis=1)) < 1e-10


def test_prs3_declared_branch_tells_the_modes_apart(prs3):
    """3-PRS: the modes with a leg folded down (alpha ~ 10 deg) and the platform tilted
    ~45 deg keep the legs' signs but lie across a forward singularity: the aspect indicator
    is negative there, so only the working mode is designated (before: all 4)."""
    s = np.array([1e-3, 0.5e-3, -0.3e-3])
    found = assembly_modes(prs3, s, starts=2000)
    assert found.count >= 4  # above the base: the working mode and three tilted; with the full turn also below
    assert [md.designated for md in found.modes] == [True] + [False] * (found.count - 1)
    tilted = [md for md in found.modes[1:] if md.x[2] > 0]
    assert len(tilted) == 3
    for md in found.modes[1:]:
        assert md.status is Status.WRONG_BRANCH and "<= 0" in md.message
    for md in tilted:
        assert "aspect = -" in md.message and np.max(np.degrees(np.abs(md.x[3:5]))) > 30


def test_kind_solved_when_the_search_ran_even_if_the_designated_fk_fails(monkeypatch):
    """The search that ran is solved (exit 0); the designated FK's failure is its own status."""
    failed = PoseSolution(Status.NOT_CONVERGED, message="Newton stopped (test)")
    monkeypatch.setattr(assembly, "forward_kinematics", lambda *a, **k: failed)
    data = {
        "problem": "forward_kinematics",
        "mechanism": {"file": str(UPS6)},
        "inputs": {f"l{n}": f"{v * 1e3} mm" for n, v in zip(["a1", "a2", "a3", "b1", "b2", "b3"], UPS6_Q)},
    }
    data["inputs"].update(assembly_modes="all", mode_starts=500)
    res = solve(problem_from_dict(data))
    assert res.status is Status.SOLVED and res.values["modes"] == 8
    assert res.values["designated_status"] == "not_converged" and res.values["px"] is None
    assert "designated pose (the ordinary FK): not_converged" in res.message


def test_kind_reports_region_residuals_statuses_and_completeness():
    data = {
        "problem": "forward_kinematics",
        "mechanism": {"type": "prs3", "parameters": PAPER_PRS3},
        "inputs": {"s1": "1 mm", "s2": "0.5 mm", "s3": "-0.3 mm", "assembly_modes": "all", "mode_starts": 1000},
    }
    res = solve(problem_from_dict(data))
    v = res.values
    assert res.ok and len(v["modes_residual"]) == len(v["modes_status"]) == v["modes"]
    assert max(v["modes_residual"]) < 1e-12 and v["modes_status"][0] == "solved"
    assert set(v["mode_region"]) == set(cn.build_model("prs3", PAPER_PRS3).closure.x_names)
    assert v["mode_region"]["psi"]["source"] == "full turn"
    assert "search region: px in" in v["mode_search"]
    assert v["mode_completeness"]["hits"] == sum(v["modes_basin"])
    assert "aspect" in v["branch_names"]  # (the file's declared above_base follows it)


def test_completeness_estimate_and_its_caveats():
    """Chao1: f1^2 / (2 f2) unseen modes; without doubletons f1 (f1 - 1) / 2; complete only
    without rare modes.  The two caveats differ, and the incomplete one says how many starts."""
    done = completeness([500, 300, 120, 80], 1000)
    assert done.complete and done.unseen == 0 and "Chao1 estimates no unseen mode" in done.note
    part = completeness([900, 50, 2, 1, 1, 1], 1000)
    assert not part.complete and part.singletons == 3 and part.doubletons == 1
    assert part.unseen == pytest.approx(9 / 2) and part.estimate == pytest.approx(10.5)
    assert part.rare == [2, 3, 4, 5] and part.new_mode_probability == pytest.approx(3 / 955)
    # a 99 % chance of reaching a basin of 1/1000: ceil(ln 0.01 / ln(1 - 0.001)) starts
    assert part.starts_needed == math.ceil(math.log(0.01) / math.log(1 - 0.001)) == 4603
    assert "probably incomplete" in part.note and "4603 starts" in part.note and part.note != done.note
    single = completeness([1], 10)
    assert not single.complete and single.unseen == 0.0


def test_fk_continues_from_home_where_newton_jumps_branch():
    """Watt II six-bar, crank at 168 deg: Newton from home lands off the designated branch
    (transmission2 < 0); the continuation from home reaches the pose on it, equal to the numpy
    path following (tests/watt_six_bar.py) to 1e-12."""
    model = watt.model()
    t2 = math.radians(168)
    plain = cn.forward_kinematics(model, [t2], SolverConfig("newton"), continuation=False)
    assert plain.status is Status.WRONG_BRANCH and "transmission2" in plain.message
    for solver in (SolverConfig("newton"), SolverConfig()):
        sol = cn.forward_kinematics(model, [t2], solver)
        assert sol.ok, sol.message
        ref = (watt.path(t2) + math.pi) % (2 * math.pi) - math.pi
        assert np.max(np.abs(sol.x - ref)) < 1e-12
        assert np.max(np.abs(watt.closures(sol.x, t2))) < 1e-12


def test_fk_angles_reduced():
    """A guess five turns away: the angles come back in (-pi, pi]."""
    model = watt.model()
    guess = model.x_home + 10 * math.pi
    sol = cn.forward_kinematics(model, [0.3], SolverConfig("newton"), guess=guess)
    assert sol.ok and np.all(np.abs(sol.x) <= math.pi)
    assert np.max(np.abs(watt.closures(sol.x, 0.3))) < 1e-12


# -- branch indicators ----------------------------------------------------------------------------


def _ups6_with_branch(branch):
    import yaml

    data = yaml.safe_load(UPS6.read_text())
    data["name"] = "ups6_branch_test"
    data.pop("examples", None)
    if branch is not None:
        data["branch"] = branch
    mech = from_dict(data)
    return mech.model(mech.closure(), {}, {}, ())


def test_generated_indicators_are_named_after_leg_and_joint():
    c = _ups6().closure
    assert c.branch_names[:2] == ("a1.P2", "a1.U1") and c.branch_names[-1] == "aspect"
    assert c.branch_descriptions[1].startswith("leg a1, joint 1 (U)")


def test_branch_section_selects_adds_removes():
    assert _ups6_with_branch([]).closure.branch is None  # branch: [] removes the generated ones
    m = _ups6_with_branch(["aspect", {"up": "pz"}])
    assert m.closure.branch_names == ("aspect", "up")
    m = _ups6_with_branch({"remove": ["aspect"], "add": ["pz"]})
    assert "aspect" not in m.closure.branch_names and m.closure.branch_names[-1] == "branch[0]"
    m = _ups6_with_branch({"keep": ["a1.U1", "b3.U1"]})
    assert m.closure.branch_names == ("a1.U1", "b3.U1")
    with pytest.raises(InputError, match="no generated branch indicator 'a1.U2'") as err:
        _ups6_with_branch({"remove": ["a1.U2"]})
    assert "a1.U1" in err.value.suggestions


def test_wrong_branch_names_indicator_leg_joint_and_value():
    """A mode below the base: the message names the indicator, its leg and joint, and its value."""
    model = _ups6()
    found = assembly_modes(model, UPS6_Q, starts=1000)
    msgs = [md.message for md in found.modes if md.status is Status.WRONG_BRANCH]
    assert any("a1.U1 = -" in m and "leg a1, joint 1 (U)" in m for m in msgs) or any("aspect = -" in m for m in msgs)
    below = [md for md in found.modes if md.x[2] < 0]
    assert below and all("<= 0" in md.message for md in below)


def test_kernel_checks_see_nan_and_inf():
    """The kernels' finiteness test: a NaN or inf entry is not finite, and the residual of a
    vector holding one is inf (before: v * 0 == 0, which CasADi simplifies to true, so a NaN
    residual entry was skipped by fmax and the residual of [NaN, 1] was 1)."""
    import casadi as ca

    from cpm_nlp.core.conditioning import all_finite as _all_finite
    from cpm_nlp.core.conditioning import robust_max_abs as _robust_max_abs

    for sym in (ca.SX, ca.MX):
        v = sym.sym("v", 2)
        f = ca.Function("f", [v], [_robust_max_abs(v), _all_finite(v)])
        for bad in ([math.nan, 1.0], [1.0, math.inf]):
            residual, finite = (float(o) for o in f(bad))
            assert residual == math.inf and finite == 0
        residual, finite = (float(o) for o in f([1.0, -2.0]))
        assert residual == 2.0 and finite == 1
