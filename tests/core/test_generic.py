"""Export, embedding and batches work for any LoopClosure: a two-bar planar
mechanism with no closed-form IK, no passive joints, no branch indicator and
no dependent pose coordinates exercises the generic paths."""

import shutil
import subprocess

import casadi as ca
import numpy as np
import pytest

import cpm_nlp as cn
from cpm_nlp.core.model import Coordinate, LoopClosure, Model
from cpm_nlp.core.result import Status

NEWTON = cn.SolverConfig("newton")


def two_bar() -> LoopClosure:
    """Point P = (px, py) held by two telescopic legs of lengths l1, l2 from
    A1 = (0, 0) and A2 = (d, 0); the working assembly has py > 0."""
    x, q, p = ca.SX.sym("x", 2), ca.SX.sym("q", 2), ca.SX.sym("p", 1)
    d = p[0]
    phi = ca.vertcat((x[0] ** 2 + x[1] ** 2 - q[0] ** 2) / (2 * d), ((x[0] - d) ** 2 + x[1] ** 2 - q[1] ** 2) / (2 * d))
    return LoopClosure(
        "twobar",
        x=(Coordinate("px", "length"), Coordinate("py", "length")),
        q=(Coordinate("l1", "length", family="l"), Coordinate("l2", "length", family="l")),
        parameters=("d",),
        phi=ca.Function("phi", [x, q, p], [phi], ["x", "q", "p"], ["phi"]),
        task=("px", "py"),
        home=lambda pv: (np.array([pv[0] / 2, pv[0]]), np.full(2, np.hypot(pv[0] / 2, pv[0]))),
        bounds=lambda pv: (np.array([-2 * pv[0], 0.0]), np.array([3 * pv[0], 3 * pv[0]])),
    )


@pytest.fixture(scope="module")
def model():
    return Model(two_bar(), {"d": 0.1}, limits={"l": (0.05, 0.2)})


def test_single_and_batch_fk_ik(model):
    rng = np.random.default_rng(41)
    lengths = rng.uniform(0.08, 0.16, (200, 2))
    res = cn.batch_forward_kinematics(model, lengths)
    assert res.passive.shape == (200, 0) and res.solver == "fast_newton"
    for k in range(0, 200, 20):
        single = cn.forward_kinematics(model, lengths[k], NEWTON)
        assert res.statuses[k] is single.status
        if single.ok:
            np.testing.assert_allclose(res.x[k], single.x, atol=1e-14)
    ok = res.ok
    ik = cn.batch_inverse_kinematics(model, res.x[ok])  # no closed form: Newton on Φ for q
    assert ik.ok.all() and ik.solver == "fast_newton"
    np.testing.assert_allclose(ik.q, lengths[ok], atol=1e-13)
    far = cn.batch_forward_kinematics(model, [[0.01, 0.3]])  # the legs cannot meet
    assert far.statuses == [Status.NOT_CONVERGED]
    limited = cn.batch_inverse_kinematics(model, [[0.05, 0.3]])  # needs l1 > 0.2
    assert limited.statuses == [Status.OUTSIDE_JOINT_LIMITS] and "l1 = " in limited.message(0)


def test_functions_and_jacobians(model):
    fns = cn.functions(model)
    assert fns.passive is None and fns.ik.name_in() == ["t", "y0"]
    out = fns.fk(q=[0.12, 0.11], x0=fns.x_home)
    assert int(out["status"]) == 0
    jac = cn.batch_jacobians(model, np.asarray(out["x"]).T, [[0.12, 0.11]])
    rep = cn.jacobians(model, np.asarray(out["x"]).ravel(), [0.12, 0.11])
    np.testing.assert_allclose(jac.J[0], rep.J, rtol=1e-14)


@pytest.mark.skipif(shutil.which("gcc") is None, reason="gcc is not installed")
def test_export_c_compiles(model, tmp_path):
    data = cn.export_kinematics(model, tmp_path / "c", fmt="c")
    assert data["mechanism"]["title"] is None and [f["name"] for f in data["functions"]] == [
        "twobar_fk",
        "twobar_ik",
        "twobar_jacobian",
    ]
    assert data["functions"][1]["inputs"][1]["elements"] == ["l1", "l2"]  # y0: no dependent pose coordinates
    subprocess.run(
        ["gcc", "-O2", "-shared", "-fPIC", str(tmp_path / "c" / "twobar_kinematics.c"), "-o", str(tmp_path / "t.so")],
        check=True,
    )


def test_structurally_singular_mechanism_is_singular():
    """Φ independent of one pose coordinate (a broken mechanism module): the
    pose checks still build and call every pose singular."""
    x, q, p = ca.SX.sym("x", 2), ca.SX.sym("q", 2), ca.SX.sym("p", 1)
    closure = LoopClosure(
        "degenerate",
        x=(Coordinate("u", "length"), Coordinate("v", "length")),
        q=(Coordinate("a", "length"), Coordinate("b", "length")),
        parameters=("d",),
        phi=ca.Function("phi", [x, q, p], [ca.vertcat(x[0] - q[0], p[0] * (x[0] - q[1]))], ["x", "q", "p"], ["phi"]),
        task=("u", "v"),
        home=lambda pv: (np.zeros(2), np.zeros(2)),
        bounds=lambda pv: (np.full(2, -1.0), np.full(2, 1.0)),
    )
    model = Model(closure, {"d": 1.0})
    status, message, details = cn.assess(model, [0.1, 0.0], [0.1, 0.1], 1e-10)
    assert status is Status.SINGULAR and details["cond_phi_x"] == np.inf
