"""Independent references: hand-written closures the package no longer ships (issue 21, item 5),
and the comparison of a mechanism written once (its file) against one of them."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

import cpm_nlp as cn
from cpm_nlp.core.mechanism import Mechanism
from cpm_nlp.core.model import LoopClosure, Model
from cpm_nlp.core.result import Status

#: mechanism name -> its reference closure, one per process (code, not problem data), so that
#: solvers built for one reference model serve all of them, as the registry's closures do
_CLOSURES: dict[str, LoopClosure] = {}


def reference_model_of(
    mechanism: Mechanism, closure: Callable[[], LoopClosure], parameters: dict, limits: dict | None
) -> Model:
    """A model of a reference closure, not registered: built from its declaration directly."""
    c = _CLOSURES.get(mechanism.name)
    if c is None:
        c = _CLOSURES[mechanism.name] = closure()
        c.mechanism = mechanism
    return mechanism.model(c, parameters, limits or {}, ("mechanism",))


#: the comparison's tolerance, relative to max(1, |reference|)
TOL = 1e-12
NEWTON = cn.SolverConfig("newton")


def close(a, b, tol: float = TOL) -> None:
    """|a - b| <= tol * max(1, |b|)."""
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    scale = max(1.0, float(np.max(np.abs(b))))
    np.testing.assert_allclose(a, b, rtol=0, atol=tol * scale)


def assert_same_kinematics(fm: cn.Model, rm: cn.Model, poses: np.ndarray, task_is_pose: bool = False) -> None:
    """At each task pose: IK (x, q, passive joints), FK from the IK's actuators (against the
    reference's FK and against the IK pose; ``task_is_pose``: x is the task pose itself), the
    passive joints by name, and the Jacobians J, J_task, J_inv of the file's model ``fm`` equal
    the reference's ``rm``."""
    for t in poses:
        ia, ib = cn.inverse_kinematics(rm, t), cn.inverse_kinematics(fm, t)
        assert ia.status is ib.status is Status.SOLVED, (ia.message, ib.message)
        close(ib.x, ia.x)
        close(ib.q, ia.q)
        close(ib.passive, ia.passive)
        fa, fb = cn.forward_kinematics(rm, ia.q, NEWTON), cn.forward_kinematics(fm, ia.q, NEWTON)
        assert fa.status is fb.status is Status.SOLVED, (fa.message, fb.message)
        close(fb.x, fa.x)
        close(fb.x, t if task_is_pose else ia.x, 1e-11)  # FK(IK(t)): the IK pose, each model's own solve
        pa, pb = cn.passive_joints(rm, fa.x, ia.q), cn.passive_joints(fm, fb.x, ia.q)
        assert list(pa) == list(pb)
        close(list(pb.values()), list(pa.values()))
        ja, jb = cn.jacobians(rm, fa.x, ia.q), cn.jacobians(fm, fb.x, ia.q)
        for name in ("J", "J_task", "J_inv"):  # dx/dq (whole pose), dt/dq (task), dq/dt
            close(getattr(jb, name), getattr(ja, name))
