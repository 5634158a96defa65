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

import shutil
from pathlib import Path

import numpy as np
import pytest

import cpm_nlp as cn
from cpm_nlp.core.result import Status
from cpm_nlp.problems.shipped import shipped_problems_dir

from .conftest import central_difference

GCC = shutil.which("gcc")


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


def test_every_supported_kind_runs_on_a_shipped_example(mechanism, model):
    examples: dict[str, list[Path]] = {}
    for f in _example_files(mechanism):
        examples.setdefault(cn.load_problem(f).kind.name, []).append(f)
    supported = [k for k in cn.kind_names() if cn.problem_kind(k).supports(model) is None]
    for kind, files in examples.items():
        assert kind in supported, f"{files[0].name}: kind {kind} does not support {mechanism.name}"
        result = cn.solve(cn.load_problem(files[0]))
        assert result.status in (Status.SOLVED,), f"{files[0].name}: {result.status} {result.message}"
