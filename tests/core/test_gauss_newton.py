"""The full FK of overconstrained graphs (normal equations) by Gauss-Newton first (issue 23).

:func:`cpm_nlp.core.kernels.full_fk_kernel` of a closure solved through normal equations runs
:func:`~cpm_nlp.core.kernels.gauss_newton_fk_kernel` (unrolled steps on every closure equation,
first derivatives only) and, where it does not settle a pose as solved, Newton on the normal
equations exactly as before (:func:`~cpm_nlp.core.kernels.newton_fk_kernel`).  Checked here, on
the shipped pantograph file, the Bennett linkage and the RPR of joints: a pose Gauss-Newton does
not settle has Newton's outputs exactly; a pose both solve has Newton's pose (1e-12); a pose only
Gauss-Newton solves holds every closure equation and comes back through the IK (the pantograph's
closed form, Bennett's relation in numpy).  Consistency checks, no published figures.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import cpm_nlp as cn
from cpm_nlp.core.batch import evaluate
from cpm_nlp.core.kernels import full_fk_kernel, gauss_newton_fk_kernel, newton_fk_kernel, shared_values
from cpm_nlp.mechanisms.described import load_file

CORPUS = Path(__file__).resolve().parents[1] / "corpus"
NEWTON = cn.SolverConfig("newton")


def _model(name: str) -> cn.Model:
    if name == "pantograph_file":  # the paper's R hinges at C and F: overconstrained (the shipped file has S there)
        name = "pantograph_joints"
    mech = load_file(CORPUS / f"{name}.yaml")
    params = {"r1": "40 mm", "r2": "80 mm", "P0": "40 mm"} if name == "rpr_joints" else {}
    params = {"a": "20 mm", "b": "50 mm"} if name == "pantograph_joints" else params
    return mech.model(mech.closure(), params, {}, ())


def _inputs(model: cn.Model, half_length: float, half_angle: float, n: int, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    half = np.array([half_length if c.kind == "length" else half_angle for c in model.closure.q])
    return model.q_home + rng.uniform(-1, 1, (n, len(half))) * half


def _run(kern, model, q):
    args = [q, np.tile(model.x_home, (len(q), 1)), *shared_values(kern, model, NEWTON.tolerance)]
    return dict(zip(kern.outputs, evaluate(kern.function, args)))


def _wrapped(c, d):
    d = np.array(d, dtype=float)
    for k, coord in enumerate(c.x):
        if coord.kind == "angle":
            d[:, k] = (d[:, k] + math.pi) % (2 * math.pi) - math.pi
    return d


@pytest.mark.parametrize(
    ("name", "half_length", "half_angle"),
    [
        ("pantograph_file", 2e-3, 0.0),
        ("pantograph_file", 2e-2, 0.0),
        ("bennett", 0.0, 0.3),
        ("rpr_joints", 2e-3, 0.05),
    ],
)
def test_gauss_newton_first_then_newton_as_before(name, half_length, half_angle):
    model = _model(name)
    c = model.closure
    assert c.loops is not None  # normal equations
    q = _inputs(model, half_length, half_angle, 300, seed=230)
    full = _run(full_fk_kernel(c, NEWTON), model, q)
    newton = _run(newton_fk_kernel(c, NEWTON), model, q)
    gn = _run(gauss_newton_fk_kernel(c, NEWTON), model, q)
    settled = gn["status"].ravel() == 0
    if half_length <= 2e-3 and half_angle <= 0.05 or name == "bennett":
        assert settled.mean() > 0.9, settled.mean()
    # not settled by Gauss-Newton: Newton's answer, every output
    for key in full:
        np.testing.assert_array_equal(full[key][~settled], newton[key][~settled], err_msg=key)
    np.testing.assert_array_equal(full["status"][settled], 0)
    np.testing.assert_array_equal(full["x"][settled], gn["x"][settled])
    both = settled & (newton["status"].ravel() == 0)
    assert both.sum() >= 50
    np.testing.assert_allclose(_wrapped(c, full["x"][both] - newton["x"][both]), 0, atol=1e-12)
    for i in np.flatnonzero(settled):  # every closure equation holds, Newton solved the pose or not
        assert np.max(np.abs(np.asarray(c.loops(full["x"][i], q[i], model.p)))) <= 1e-14
    if c.ik is not None:  # FK against IK: the task coordinates' IK gives back q
        for i in np.flatnonzero(settled & (newton["status"].ravel() != 0))[:20]:
            ik = cn.inverse_kinematics(model, full["x"][i][c.task_index])
            np.testing.assert_allclose(ik.q, q[i], rtol=0, atol=1e-12)


def _bennett_phi2(theta1: float, alpha: float = math.radians(30), beta: float = math.radians(60)) -> float:
    """Bennett's relation (tests/corpus/bennett.yaml): tan(theta1/2) tan(phi2/2) =
    sin((beta + alpha)/2) / sin((beta - alpha)/2), solved for phi2 (numpy)."""
    k = math.sin((beta + alpha) / 2) / math.sin((beta - alpha) / 2)
    return 2 * math.atan(k / math.tan(theta1 / 2))


def test_bennett_fk_by_gauss_newton_follows_bennetts_relation():
    """Bennett's linkage has no closed-form IK: its FK is the full path.  Gauss-Newton settles
    inputs within 0.3 rad of home and the coupler angle follows Bennett's relation to 1e-11 rad."""
    model = _model("bennett")
    c = model.closure
    q = _inputs(model, 0.0, 0.3, 50, seed=231)
    gn = _run(gauss_newton_fk_kernel(c, NEWTON), model, q)
    settled = gn["status"].ravel() == 0
    assert settled.all()
    k = c.x_names.index("phi2")
    for i in range(len(q)):
        d = gn["x"][i][k] - _bennett_phi2(float(q[i][0]))
        assert (d + math.pi) % (2 * math.pi) - math.pi == pytest.approx(0.0, abs=1e-11)
