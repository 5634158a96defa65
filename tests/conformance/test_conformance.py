"""Conformance of every registered mechanism: the built-in ones, plugins, and
mechanisms described in files.  A new mechanism gets these checks by being
registered; no test code is written for it.

For each mechanism, on a model from its first shipped problem file (or its
default parameters):

* the home pose assembles (Φ = 0) and lies on the designated branch (g > 0);
* FK(IK(t)) = t on random poses around home (IK in closed form when the
  mechanism has one, else solved);
* the AD Jacobians Φ_x, Φ_q and J against central differences;
* batch FK against single solves (same status, same pose);
* export round trip: the exported CasADi files and the C library give the
  in-process results;
* every shipped example of the mechanism is of a kind that supports it, and solves.
"""

from __future__ import annotations

import os
import shutil
from pathlib import Path

import numpy as np
import pytest

import cpm_nlp as cn
from cpm_nlp.analysis import compliance as cm
from cpm_nlp.analysis import workspace as W
from cpm_nlp.core.result import Status
from cpm_nlp.problems.shipped import shipped_problems_dir
from tests import conformance_cases as cc
from tests.conftest import PROBLEMS, central_difference

GCC = shutil.which("gcc")
ROOT_MECHANISMS = Path(__file__).resolve().parents[2] / "problems" / "mechanisms"


def _example_files(mech: cn.Mechanism) -> list[Path]:
    return [Path(f) if Path(f).is_absolute() else shipped_problems_dir() / f for f in mech.problem_files]


@pytest.fixture(scope="module", params=cn.mechanism_names())
def mechanism(request) -> cn.Mechanism:
    return cn.mechanism_type(request.param)


@pytest.fixture(scope="module")
def model(mechanism) -> cn.Model:
    files = _example_files(mechanism)
    if files:
        return cn.load_problem(files[0]).model
    return cn.build_model(mechanism.name)


def _random_actuators(model: cn.Model, n: int, seed: int) -> np.ndarray:
    """Actuator values of the working range: inside the declared strokes (their middle 80 %),
    else within 0.5 % of the characteristic length (or 5 mrad) of home."""
    rng = np.random.default_rng(seed)
    length = max(model.characteristic_length, 1e-3)
    lo, hi = [], []
    for k, coord in enumerate(model.closure.q):
        lim = model.limit_of(coord)
        if lim is not None:
            mid, half = (lim[0] + lim[1]) / 2, 0.4 * (lim[1] - lim[0])
            lo.append(mid - half)
            hi.append(mid + half)
        else:
            step = 0.005 * length if coord.kind == "length" else 5e-3
            lo.append(model.q_home[k] - step)
            hi.append(model.q_home[k] + step)
    return rng.uniform(lo, hi, (n, model.closure.nq))


def _working_poses(model: cn.Model, n: int, seed: int) -> list[cn.PoseSolution]:
    """Solved FK poses of random actuator values of the working range."""
    newton = cn.SolverConfig("newton")
    sols = [cn.forward_kinematics(model, q, newton) for q in _random_actuators(model, n, seed)]
    return [s for s in sols if s.status == Status.SOLVED]


def test_declaration_is_valid(mechanism):
    cn.Mechanism.__post_init__(mechanism)  # validates again: types of every part
    assert mechanism.title and mechanism.parameters is not None


def test_home_assembles_on_its_branch(model):
    c = model.closure
    res = np.asarray(c.phi(model.x_home, model.q_home, model.p)).ravel()
    assert np.max(np.abs(res)) < 1e-12
    if c.branch is not None:
        g = np.asarray(c.branch(model.x_home, model.q_home, model.p)).ravel()
        assert np.all(g > 0), f"home pose off the designated branch: g = {g}"
    status, message, _ = cn.assess(model, model.x_home, model.q_home, 1e-9)
    assert status == Status.SOLVED, message


def test_fk_of_ik_returns_the_pose(model):
    """t from FK of random actuators; IK(t) gives the actuators back, FK(IK(t)) = t."""
    newton = cn.SolverConfig("newton")
    poses = _working_poses(model, 20, seed=1)
    assert len(poses) >= 10, f"only {len(poses)} of 20 random actuator vectors of the working range solved"
    for pose in poses:
        t = model.task_of(pose.x)
        ik = cn.inverse_kinematics(model, t, newton)
        assert ik.status == Status.SOLVED, ik.message
        np.testing.assert_allclose(ik.q, pose.q, rtol=0, atol=1e-10 * max(1.0, float(np.max(np.abs(pose.q)))))
        fk = cn.forward_kinematics(model, ik.q, newton)
        assert fk.status == Status.SOLVED, fk.message
        np.testing.assert_allclose(model.task_of(fk.x), t, rtol=0, atol=1e-10 * max(1.0, float(np.max(np.abs(t)))))


def test_ad_jacobians_against_central_differences(model):
    c = model.closure
    pose = _working_poses(model, 3, seed=2)[0]
    x, q, p = pose.x, pose.q, model.p
    phi = lambda xx, qq: np.asarray(c.phi(xx, qq, p)).ravel()  # noqa: E731
    h = 1e-7
    for ad, fd in (
        (c.phi_x(x, q, p), central_difference(lambda xx: phi(xx, q), x, h)),
        (c.phi_q(x, q, p), central_difference(lambda qq: phi(x, qq), q, h)),
    ):
        np.testing.assert_allclose(np.asarray(ad), fd, rtol=1e-5, atol=1e-6)
    # J = dx/dq along the closure: central differences of FK itself
    fk = lambda qq: cn.forward_kinematics(model, qq, cn.SolverConfig("newton"), guess=x).x  # noqa: E731
    J = np.asarray(c.jacobian(x, q, p))
    hq = 1e-7 * max(1.0, float(np.max(np.abs(q))))
    np.testing.assert_allclose(J, central_difference(fk, q, hq), rtol=1e-4, atol=1e-6)


def test_batch_equals_single_solves(model):
    newton = cn.SolverConfig("newton")
    qs = _random_actuators(model, 12, seed=3)
    batch = cn.batch_forward_kinematics(model, qs, newton)
    for i, q in enumerate(qs):
        single = cn.forward_kinematics(model, q, newton)
        assert batch.statuses[i] == single.status
        if single.status == Status.SOLVED:
            np.testing.assert_allclose(batch.x[i], single.x, rtol=0, atol=1e-12)


@pytest.mark.parametrize("fmt", ["casadi", pytest.param("c", marks=pytest.mark.skipif(GCC is None, reason="no gcc"))])
def test_export_round_trip(model, fmt, tmp_path):
    cn.export_kinematics(model, tmp_path / fmt, fmt=fmt)
    fns = cn.functions(model)
    t = model.task_of(_working_poses(model, 3, seed=4)[0].x)
    c = model.closure
    # without a closed form the IK is Newton from y0: the home pose, as cn.inverse_kinematics starts
    # (not CasADi's default 0: a U-P-S or R-P-S leg of length 0 is a singular start of its squared equation)
    ik = fns.ik(t=t) if c.ik is not None else fns.ik(t=t, y0=np.r_[model.x_home[c.dep_index], model.q_home])
    assert int(ik["status"]) == 0
    if fmt == "casadi":
        loaded = cn.load_exported(tmp_path / fmt)
        fk_name = next(n for n in loaded if n.endswith("_fk"))
        got = loaded[fk_name](q=ik["q"], x0=model.x_home)
    else:
        import casadi as ca

        lib = next((tmp_path / fmt).glob("*.c"))
        so = tmp_path / "lib.so"
        import subprocess

        subprocess.run([GCC, "-O1", "-shared", "-fPIC", str(lib), "-o", str(so)], check=True)
        fk_name = f"{model.name}_fk"
        got = ca.external(fk_name, str(so))(q=ik["q"], x0=model.x_home)
    want = fns.fk(q=ik["q"], x0=model.x_home)
    np.testing.assert_allclose(np.asarray(got["x"]), np.asarray(want["x"]), rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(np.asarray(got["x"]).ravel(), np.asarray(ik["x"]).ravel(), rtol=0, atol=1e-9)


def test_every_supported_kind_runs_on_a_shipped_example(mechanism, model, shipped_solve):
    examples: dict[str, list[Path]] = {}
    for f in _example_files(mechanism):
        examples.setdefault(cn.load_problem(f).kind.name, []).append(f)
    supported = [k for k in cn.kind_names() if cn.problem_kind(k).supports(model) is None]
    for kind, files in examples.items():
        assert kind in supported, f"{files[0].name}: kind {kind} does not support {mechanism.name}"
        shipped = files[0].parent.resolve() == PROBLEMS.resolve()  # solved once per session (conftest)
        result = shipped_solve(files[0].stem)[1] if shipped else cn.solve(cn.load_problem(files[0]))
        assert result.status in (Status.SOLVED,), f"{files[0].name}: {result.status} {result.message}"


# -- every generic kind on every mechanism (issue 20) -----------------------------------------
#
# For each mechanism (every registered one, and every mechanism file of tests/corpus/) and each
# generic kind: a minimal problem generated from the home pose (tests/conformance_cases.py)
# solves with an honest status, and its result is checked against something independent of
# that kind: FK of IK, central differences, membership, a seeded Monte Carlo, J K^-1 J^T.

CORPUS = Path(__file__).resolve().parents[1] / "corpus"
SUBJECTS = [*cn.mechanism_names(), *(f"corpus/{p.name}" for p in cc.corpus_files(CORPUS))]
NEWTON = cn.SolverConfig("newton")


@pytest.fixture(scope="module", params=SUBJECTS)
def subject(request) -> cc.Subject:
    if request.param.startswith("corpus/"):
        return cc.file_subject(CORPUS / request.param.split("/", 1)[1])
    return cc.shipped_subject(request.param)


@pytest.fixture(scope="module")
def near_home(subject) -> dict[str, np.ndarray]:
    """Three solved poses about home: actuators q (3, nq), task values t, poses x."""
    q = subject.actuators_near_home(3, seed=11)
    sols = [cn.forward_kinematics(subject.model, qq, NEWTON) for qq in q]
    bad = [s for s in sols if s.status != Status.SOLVED]
    assert not bad, f"FK about home: {bad[0].status} {bad[0].message}"
    return {"q": q, "t": np.array([subject.model.task_of(s.x) for s in sols]), "x": np.array([s.x for s in sols])}


def _solve(subject: cc.Subject, kind: str, inputs: dict) -> cn.Result:
    result = cn.solve(subject.problem(kind, inputs))
    assert result.status == Status.SOLVED, f"{subject.name} {kind}: {result.status.value}: {result.message}"
    return result


def _scale(v) -> float:
    return max(1.0, float(np.max(np.abs(v))))


def _fk(subject, near_home) -> None:
    c = subject.model.closure
    res = _solve(subject, "forward_kinematics", cc.inputs_of(subject, "forward_kinematics", near_home))
    X = np.array([res.values[n] for n in c.x_names]).T
    for x, q in zip(X, near_home["q"]):  # the loop closes at the reported pose (Φ = 0)
        assert np.max(np.abs(np.asarray(c.phi(x, q, subject.model.p)))) < 1e-9
    np.testing.assert_allclose(np.array([res.values[n] for n in c.q_names]).T, near_home["q"], rtol=0, atol=1e-15)


def _ik(subject, near_home) -> None:
    """IK(t) gives back the actuators t came from, and FK of those gives t (both kinds)."""
    c = subject.model.closure
    res = _solve(subject, "inverse_kinematics", cc.inputs_of(subject, "inverse_kinematics", near_home))
    Q = np.array([res.values[n] for n in c.q_names]).T
    np.testing.assert_allclose(Q, near_home["q"], rtol=0, atol=1e-9 * _scale(near_home["q"]))
    back = _solve(subject, "forward_kinematics", {n: Q[:, k].tolist() for k, n in enumerate(c.q_names)})
    T = np.array([back.values[n] for n in c.task]).T
    np.testing.assert_allclose(T, near_home["t"], rtol=0, atol=1e-9 * _scale(near_home["t"]))


def _jacobian(subject, near_home) -> None:
    """J = dx/dq (AD) against central differences of FK."""
    res = _solve(subject, "jacobian", cc.inputs_of(subject, "jacobian", near_home))
    J = np.asarray(res.values["J"], dtype=float)
    q0, x0 = near_home["q"][0], near_home["x"][0]
    fk = lambda qq: cn.forward_kinematics(subject.model, qq, NEWTON, guess=x0).x  # noqa: E731
    fd = central_difference(fk, q0, 1e-7 * _scale(q0))
    np.testing.assert_allclose(J, fd, rtol=1e-5, atol=1e-6 * np.max(np.abs(fd)))


def _joint_requirements(subject, near_home) -> None:
    """Every grid point's actuators are its IK; each family's range is the range of its members."""
    c, m = subject.model.closure, subject.model
    res = _solve(subject, "joint_requirements", cc.inputs_of(subject, "joint_requirements", near_home))
    T = np.array([res.values[n] for n in c.task]).T
    assert len(T) == 2 ** len(c.task)
    Q = np.array([res.values[n] for n in c.q_names]).T
    for t, q in zip(T, Q):
        ik = cn.inverse_kinematics(m, t, NEWTON)
        assert ik.status == Status.SOLVED
        np.testing.assert_allclose(q, ik.q, rtol=0, atol=1e-9 * _scale(q))
    for group in {co.group for co in c.q}:
        members = [k for k, co in enumerate(c.q) if co.group == group]
        if f"{group}_min" in res.values:
            assert res.values[f"{group}_min"] == pytest.approx(Q[:, members].min(), abs=1e-12)
            assert res.values[f"{group}_max"] == pytest.approx(Q[:, members].max(), abs=1e-12)


def _workspace(subject, near_home) -> None:
    res = _solve(subject, "workspace", cc.inputs_of(subject, "workspace", near_home))
    assert res.values["status"] == ["inside", "outside"], res.values["binding"]
    assert res.values["count_inside"] == 1


def _membership_volume(model: cn.Model, lower, upper, n: int, seed: int) -> tuple[float, float]:
    """Seeded Monte Carlo of membership in a box: the volume and its standard error."""
    T = lower + (upper - lower) * np.random.default_rng(seed).random((n, lower.size))
    inside = cn.membership(model, T).inside
    box, p = float(np.prod(upper - lower)), inside.mean()
    return box * p, box * np.sqrt(max(p * (1 - p), 1.0 / n) / n)


def _actuator_workspace(subject, near_home) -> None:
    inputs = cc.inputs_of(subject, "actuator_workspace", near_home)
    if not subject.has_strokes:  # the image of the strokes needs strokes: a clear refusal
        with pytest.raises(cn.InputError, match="no stroke is declared"):
            subject.problem("actuator_workspace", inputs)
        return
    res = cn.solve(subject.problem("actuator_workspace", inputs))
    if res.status in (Status.SINGULAR, Status.WRONG_BRANCH) and not subject.generated_strokes:
        _fold_confirmed(subject, res)  # declared strokes across a leg's singularity: honest, and shown
        return
    assert res.status == Status.SOLVED, f"{subject.name}: {res.status.value}: {res.message}"
    lo = np.array([res.values[f"{t}_min"] for t in subject.model.closure.task])
    hi = np.array([res.values[f"{t}_max"] for t in subject.model.closure.task])
    pad = 0.25 * (hi - lo)  # the grid's bounding box misses the bulge of curved faces
    vol, se = _membership_volume(subject.model, lo - pad, hi + pad, 1500, seed=3)
    assert abs(res.values["volume"] - vol) < 4 * se, (res.values["volume"], vol, se)


def _fold_confirmed(subject, res) -> None:
    """Declared strokes that fold (singular) or leave the branch of home (wrong_branch), shown
    independently of the kind's grid: on FK continued from home towards the corners of the
    strokes, det(dt/dq) changes sign, or the branch of home ends (bisected to 2^-30 of the way)
    where det(dt/dq) vanishes (below 1e-4 of its value at home): a leg's own singularity."""
    m = subject.model
    lo, hi = subject.stroke()

    def det(x, q) -> float:
        return float(np.linalg.det(np.asarray(cn.jacobians(m, x, q).J_task)))

    d0 = det(m.x_home, m.q_home)
    ratios = []
    for corner in W.box_corners(lo, hi):
        x, s_ok = m.x_home, 0.0
        for s in np.linspace(0.0, 1.0, 41)[1:]:
            sol = cn.forward_kinematics(m, m.q_home + s * (corner - m.q_home), NEWTON, guess=x)
            if sol.status != Status.SOLVED:
                break
            x, s_ok = sol.x, s
            ratios.append(det(x, sol.q) / d0)
        else:
            continue
        s_bad = s
        for _ in range(30):  # the end of the branch of home on this segment
            mid = 0.5 * (s_ok + s_bad)
            sol = cn.forward_kinematics(m, m.q_home + mid * (corner - m.q_home), NEWTON, guess=x)
            if sol.status == Status.SOLVED:
                x, s_ok = sol.x, mid
                ratios.append(det(x, sol.q) / d0)
            else:
                s_bad = mid
    ratios = np.array(ratios)
    assert res.message and (np.any(ratios < 0) or np.min(np.abs(ratios)) < 1e-4), (res.message, ratios.min())


def _inscribed_cuboid(subject, near_home) -> None:
    res = _solve(subject, "inscribed_cuboid", cc.inputs_of(subject, "inscribed_cuboid", near_home))
    task = subject.model.closure.task
    lo = np.array([res.values[f"{t}_min"] for t in task])
    hi = np.array([res.values[f"{t}_max"] for t in task])
    assert np.all(hi > lo) and res.values["starts"] == 2
    assert res.values["volume"] == pytest.approx(float(np.prod(hi - lo)), rel=1e-12)
    corners = cn.membership(subject.model, W.box_corners(lo, hi))
    assert corners.inside.all(), corners.binding


def _synthesis(subject, near_home) -> None:
    inputs = cc.inputs_of(subject, "synthesis", near_home)
    if inputs is None:  # the mechanism's own formulation: its shipped example runs
        assert any(cn.load_problem(f).kind.name == "synthesis" for f in _example_files(subject.model.mechanism))
        return
    result = cn.solve(subject.problem("synthesis", inputs))
    name = next(iter(inputs["design"]))
    if result.status != Status.SOLVED:  # honest: no number that looks like an answer
        assert result.status in (Status.NOT_CONVERGED, Status.INFEASIBLE) and result.message
        assert result.values[name] is None and result.values["volume"] is None
        return
    low, high = inputs["design"][name]
    assert low - 1e-12 <= result.values[name] <= high + 1e-12
    params = {**(subject.section.get("parameters") or {}), name: result.values[name]}
    section = {**subject.section, "parameters": params}
    designed = cc.subject(subject.name, section, subject.base_dir).model
    task = designed.closure.task
    lo = np.array([result.values[f"{t}_min"] for t in task])
    hi = np.array([result.values[f"{t}_max"] for t in task])
    corners = cn.membership(designed, W.box_corners(lo, hi))
    assert corners.inside.all(), corners.binding


def _actuator_forces(subject, near_home) -> None:
    """F = dU/dq: the forces at q0 against central differences of the energy at q0 +- h."""
    c = subject.model.closure
    res = _solve(subject, "actuator_forces", cc.inputs_of(subject, "actuator_forces", near_home))
    E = np.asarray(res.values["energy"], dtype=float)
    F = np.array([res.values[f"F{j + 1}"][0] for j in range(c.nq)])
    h = cc.central_step(subject)
    fd = (E[1 : 1 + c.nq] - E[1 + c.nq :]) / (2 * h)
    np.testing.assert_allclose(F, fd, rtol=1e-5, atol=1e-7 * max(np.max(np.abs(F)), 1e-9))
    K = np.asarray(res.values["K_q"][0])
    np.testing.assert_allclose(K, K.T, rtol=1e-9, atol=1e-9 * np.max(np.abs(K)))
    if cc.generated_hinges(subject):
        np.testing.assert_allclose(K, cc.SPRING * np.eye(c.nq), rtol=1e-9)


def _stiffness_at(subject, near_home) -> tuple[np.ndarray, np.ndarray]:
    """K_q (actuator_forces) and J (cn.jacobians) at the first pose about home."""
    q0, x0 = near_home["q"][0], near_home["x"][0]
    inputs = {**cc.inputs_of(subject, "actuator_forces", near_home)}
    inputs = {k: (v[0] if k in subject.model.closure.q_names else v) for k, v in inputs.items()}
    K = np.asarray(_solve(subject, "actuator_forces", inputs).values["K_q"])
    return K, np.asarray(cn.jacobians(subject.model, x0, q0).J)


def _platform_compliance(subject, near_home) -> None:
    """Actuator forces held (k_actuator 0), pseudo-rigid-body hinges: C = J K_q^-1 J^T."""
    inputs = {**cc.inputs_of(subject, "platform_compliance", near_home), "hinge_axes": "kinematic"}
    C = np.asarray(_solve(subject, "platform_compliance", inputs).values["C"])
    K, J = _stiffness_at(subject, near_home)
    if C.shape[0] != J.shape[0]:
        J = J[subject.model.closure.task_index]
    want = J @ np.linalg.solve(K, J.T)
    np.testing.assert_allclose(C, want, rtol=1e-7, atol=1e-9 * np.max(np.abs(want)))


def _natural_frequencies(subject, near_home) -> None:
    """M = J_m^T diag(m) J_m (masses on the task coordinates), K = K_q, f from |K - w^2 M| = 0."""
    c = subject.model.closure
    res = _solve(subject, "natural_frequencies", cc.inputs_of(subject, "natural_frequencies", near_home))
    M, K = np.asarray(res.values["M"]), np.asarray(res.values["K"])
    K_q, J = _stiffness_at(subject, near_home)
    masses = cc.masses(subject)
    rows = [c.x_names.index(n) for n in masses]
    Jm = J[rows]
    np.testing.assert_allclose(M, Jm.T @ np.diag(list(masses.values())) @ Jm, rtol=1e-9, atol=1e-12 * np.max(M))
    np.testing.assert_allclose(K, 0.5 * (K_q + K_q.T), rtol=1e-9, atol=1e-9 * np.max(np.abs(K)))
    w2 = np.sort(np.linalg.eigvals(np.linalg.solve(M, K)).real)
    f = [res.values[f"f{k + 1}"] for k in range(c.nq)]
    np.testing.assert_allclose(f, np.sqrt(w2) / (2 * np.pi), rtol=1e-6)


def _compliance_synthesis(subject, near_home) -> None:
    """The thinnest section (t, else d) of the mechanism's first typed hinge group, 20 % about its
    value, for the smallest input stiffness: the optimum sits on the lower bound (the stiffness
    grows with it), re-evaluated by the forward analysis.  Without a typed hinge (generated
    springs) the design is refused, naming the hinge."""
    hs = cm.hinge_set(subject.model, cc.inputs_of(subject, "actuator_forces", near_home).get("hinges"))
    typed = [h for h in hs.hinges if h.kind is not None and h.material is not None and h.material.E is not None]
    objective = {"minimize": "input_stiffness"}
    if not typed:
        group = hs.hinges[0].group
        with pytest.raises(cn.InputError, match="needs a flexure type"):
            subject.problem(
                "compliance_synthesis",
                {"hinges": cc._hinges(subject), "design": {group: {"t": [1e-3, 2e-3]}}, "objective": objective},
            )
        return
    h = typed[0]
    dim = "t" if "t" in h.dims else "d"
    v = h.dims[dim]
    res = _solve(
        subject, "compliance_synthesis", {"design": {h.group: {dim: [0.8 * v, 1.2 * v]}}, "objective": objective}
    )
    assert res.values[f"{dim}_{h.group}"] == pytest.approx(0.8 * v, rel=1e-6)
    assert res.values["recheck_deviation"] < 1e-9 and res.values["kkt_residual"] < 1e-8


def _dynamics(subject, near_home) -> None:
    """The mechanism's Lagrange model: f from |K - w^2 M| = 0 and q_static = -K^-1 G, on the
    parameters of its shipped dynamics example (the dynamics needs more than the kinematics)."""
    examples = [f for f in _example_files(subject.model.mechanism) if cn.load_problem(f).kind.name == "dynamics"]
    inputs = cc.inputs_of(subject, "dynamics", near_home)
    if not examples:
        with pytest.raises(cn.InputError, match="missing parameter"):
            subject.problem("dynamics", inputs)
        return
    section = cn.load_problem(examples[0]).data["mechanism"]
    res = _solve(cc.subject(subject.name, section, examples[0].parent), "dynamics", inputs)
    M, K, G = (np.asarray(res.values[k]) for k in ("M", "K", "G"))
    w2 = np.sort(np.linalg.eigvals(np.linalg.solve(M, K)).real)
    f = [res.values[f"f{k + 1}"] for k in range(len(M))]
    np.testing.assert_allclose(f, np.sqrt(w2) / (2 * np.pi), rtol=1e-7)
    np.testing.assert_allclose(res.values["q_static"], -np.linalg.solve(K, G), rtol=1e-9, atol=1e-15)


CHECKS = {
    "forward_kinematics": _fk,
    "inverse_kinematics": _ik,
    "jacobian": _jacobian,
    "joint_requirements": _joint_requirements,
    "workspace": _workspace,
    "actuator_workspace": _actuator_workspace,
    "inscribed_cuboid": _inscribed_cuboid,
    "synthesis": _synthesis,
    "actuator_forces": _actuator_forces,
    "platform_compliance": _platform_compliance,
    "natural_frequencies": _natural_frequencies,
    "compliance_synthesis": _compliance_synthesis,
    "dynamics": _dynamics,
}


def test_every_generic_kind_is_checked():
    assert sorted(CHECKS) == sorted(cc.GENERIC_KINDS)


#: (corpus file, kind) pairs that take 12 s to 370 s each on the 2-core machine: a cuboid or a
#: synthesis of a mechanism without a closed-form IK, its membership by IPOPT point solves and
#: interval proofs (measured 2026-11-27 at load 2-4: Williams's Delta synthesis 366 s, ARTE's
#: 3-RRR cuboid and synthesis 120 s each, the crank-slider six-bar's 40 s each, Jansen's 13 s and
#: 12 s, the Delta's cuboid 17 s; all passed).  They run with CPM_NLP_SLOW=1, outside the default
#: suite, which must stay within minutes; making them fast is the speed issue's (a Delta without a
#: closed-form IK in seconds).
SLOW = {
    ("delta_williams.yaml", "synthesis"),
    ("delta_williams.yaml", "inscribed_cuboid"),
    ("rrr3_arte.yaml", "inscribed_cuboid"),
    ("rrr3_arte.yaml", "synthesis"),
    ("crank_slider_sixbar_pyslvs.yaml", "inscribed_cuboid"),
    ("crank_slider_sixbar_pyslvs.yaml", "synthesis"),
    ("jansen_pyslvs.yaml", "inscribed_cuboid"),
    ("jansen_pyslvs.yaml", "synthesis"),
    # the 3-PRC with its levers (17 bodies, 23 pose coordinates, no closed-form IK): 117 s and 68 s
    # at load 2-3 (2026-11-27, both passed)
    ("prc3_levers.yaml", "inscribed_cuboid"),
    ("prc3_levers.yaml", "synthesis"),
    # the slowest of the default suite (2026-11-27, at load 5: 75 s, 48 s, 33 s, 26 s, 42 s), each
    # with a faster twin there: Dietmaier's 6-6 beside the gallery's ups6, the 3-PRS with joints
    # only beside its legs file (equal to 1e-12: test_graph_seeds), the pantograph with the paper's
    # R hinges beside the Bennett linkage (both overconstrained: normal equations); CI stays
    # within its 10 minutes
    ("dietmaier_6_6.yaml", "synthesis"),
    ("dietmaier_6_6.yaml", "inscribed_cuboid"),
    ("prs3_joints.yaml", "synthesis"),
    ("prs3_joints.yaml", "inscribed_cuboid"),
    ("pantograph_joints.yaml", "inscribed_cuboid"),
}
#: (corpus file, kind) pairs known to fail, kept as strict xfails so that a fix shows: the
#: declared strokes' grid (3 per actuator here) does not resolve the part that assembles, and
#: actuator_workspace says so (not_converged) instead of a volume: Dietmaier's legs 0.1 m to
#: 2.5 m (1 of 729 grid points assembles; volume 0 against 2170 m^3 in the cells across the
#: border of assembly); ARTE's cranks at -360, 0, +360 deg are one angle, which does not
#: assemble (0 of 27).  A box that partly assembles: tests/analysis/test_actuator_workspace_partial.py.
KNOWN_GAPS = {
    ("dietmaier_6_6.yaml", "actuator_workspace"),
    ("rrr3_arte.yaml", "actuator_workspace"),
}


@pytest.mark.parametrize("kind", cc.GENERIC_KINDS)
def test_generic_kind_on_every_mechanism(request, subject, near_home, kind):
    file = request.node.callspec.params["subject"].removeprefix("corpus/")
    if (file, kind) in SLOW and not os.environ.get("CPM_NLP_SLOW"):
        pytest.skip(f"{file} {kind}: minutes on 2 cores (CPM_NLP_SLOW=1 runs it)")
    if (file, kind) in KNOWN_GAPS:
        request.applymarker(pytest.mark.xfail(strict=True, reason="grid does not resolve the assembling part"))
    reason = cn.problem_kind(kind).supports(subject.model)
    if reason is not None:  # an unsupported pair: a clear reason, and the problem is refused with it
        assert reason.strip()
        with pytest.raises(cn.InputError, match="does not apply"):
            subject.problem(kind, {})
        return
    CHECKS[kind](subject, near_home)


def test_hinge_kinds_without_hinges_say_so(subject):
    """A mechanism that declares no stiffness: the compliance kinds ask for hinges."""
    if not cc.generated_hinges(subject):
        return
    q0 = {n: float(v) for n, v in zip(subject.model.closure.q_names, subject.model.q_home)}
    for kind in ("actuator_forces", "platform_compliance"):
        with pytest.raises(cn.InputError, match="declares no joint stiffness"):
            subject.problem(kind, q0)


def test_corpus_glob_takes_mechanism_files_only(tmp_path):
    """tests/corpus/*.yaml: every mechanism file is a subject (none when the folder is empty
    or absent); a problem file or other YAML beside them is not."""
    assert cc.corpus_files(tmp_path / "absent") == []
    assert cc.corpus_files(tmp_path) == []
    delta = (ROOT_MECHANISMS / "delta.yaml").read_text(encoding="utf-8")
    (tmp_path / "b_delta.yaml").write_text(delta.replace("name: delta", "name: corpus_probe_delta"), encoding="utf-8")
    problem = "problem: forward_kinematics\nmechanism: {type: delta}\n"
    (tmp_path / "a_problem.yaml").write_text(problem, encoding="utf-8")
    (tmp_path / "c_list.yaml").write_text("- 1\n- 2\n", encoding="utf-8")
    (tmp_path / "d_bad.yaml").write_text("name: [unclosed\n", encoding="utf-8")
    five = (ROOT_MECHANISMS / "five_bar.yaml").read_text(encoding="utf-8")
    (tmp_path / "e_five.yaml").write_text(five.replace("name: five_bar", "name: corpus_probe_five"), encoding="utf-8")
    files = cc.corpus_files(tmp_path)
    assert [f.name for f in files] == ["b_delta.yaml", "e_five.yaml"]
    s = cc.file_subject(files[0])
    assert s.model.closure.ik is None and s.has_strokes
    q = s.actuators_near_home(3, seed=11)
    sols = [cn.forward_kinematics(s.model, qq, NEWTON) for qq in q]
    near = {"q": q, "t": np.array([s.model.task_of(p.x) for p in sols]), "x": np.array([p.x for p in sols])}
    for kind in ("forward_kinematics", "inverse_kinematics", "workspace", "jacobian"):
        CHECKS[kind](s, near)
