"""The drawing of a URDF: every link's frame in the world as a function of the joint values, and
the joint values that close the sidecar's loops (Levenberg-Marquardt from the zero configuration)."""

from __future__ import annotations

from typing import Any

import casadi as ca
import numpy as np

from ...core.joints import JOINT_TYPES
from ...core.screws import axis_rotation
from .read import UrdfJoint

#: Gauss-Newton steps of the assembly, and the residual it reaches (times the drawing's size)
ASSEMBLY_STEPS, ASSEMBLY_TOL = 500, 1e-12


def _dof(kind: str) -> int:
    """A URDF joint's degrees of freedom: those of the joint table (R, P, S, U), none when fixed."""
    return 0 if kind == "fixed" else JOINT_TYPES[kind].dof


def _rot(axis: Any, angle: Any) -> ca.SX:
    """Rodrigues: the rotation by ``angle`` about the unit ``axis`` (`axis_rotation`)."""
    return ca.SX(axis_rotation(ca.SX(ca.DM(np.asarray(axis, dtype=float).reshape(3, 1))), angle))


def _motion(j: UrdfJoint, v: ca.SX) -> ca.SX:
    """The child's frame in the joint frame for the joint values ``v`` (4x4)."""
    m = ca.SX.eye(4)
    e = np.eye(3)
    if j.kind == "R":
        m[:3, :3] = _rot(j.axis, v[0])
    elif j.kind == "P":
        m[:3, 3] = ca.DM(j.axis) * v[0]
    elif j.kind == "S":
        m[:3, :3] = _rot(e[0], v[0]) @ _rot(e[1], v[1]) @ _rot(e[2], v[2])
    elif j.kind == "U":
        m[:3, :3] = _rot(e[j.u_axes[0]], v[0]) @ _rot(e[j.u_axes[1]], v[1])
    return m


def link_frames(order: list[str], parent_joint: dict[str, UrdfJoint]) -> tuple[ca.Function, dict[str, tuple[int, int]]]:
    """Every link's frame in the world (4x4, column-major, one after another in ``order``) as a
    function of the joint values, and each joint's slice of those values."""
    slots, n = {}, 0
    for lk in order[1:]:
        j = parent_joint[lk]
        slots[j.name] = (n, n + _dof(j.kind))
        n += _dof(j.kind)
    q = ca.SX.sym("q", n)
    frame = {order[0]: ca.SX.eye(4)}
    for lk in order[1:]:
        j = parent_joint[lk]
        frame[lk] = frame[j.parent] @ ca.DM(j.origin) @ _motion(j, q[slots[j.name][0] : slots[j.name][1]])
    out = ca.vertcat(*[ca.reshape(frame[lk], 16, 1) for lk in order])
    return ca.Function("urdf_frames", [q], [out], ["q"], ["frames"]), slots


def world_frames(frames: ca.Function, values: np.ndarray, order: list[str]) -> dict[str, np.ndarray]:
    flat = np.asarray(frames(values)).ravel()
    return {lk: flat[16 * k : 16 * k + 16].reshape(4, 4, order="F") for k, lk in enumerate(order)}


def assemble(
    frames: ca.Function, order: list[str], pairs: list[tuple[str, str, str]], held: list[int], scale: float
) -> tuple[np.ndarray, str]:
    """Joint values that close the loops, from the URDF's zero configuration: a 3d closure brings
    the two frames' origins together, a 6d closure the frames.  Levenberg-Marquardt steps with
    CasADi's AD Jacobian (redundant rows are fine), first with the ``held`` (actuated) joints at
    0, then, if that fails, with them free too.  If the loops do not close, the zero
    configuration, and a note that says by how much they stay open."""
    q = ca.SX.sym("q", frames.size1_in(0))
    flat = frames(q)
    index = {lk: k for k, lk in enumerate(order)}

    def frame(lk: str) -> ca.SX:
        return ca.reshape(flat[16 * index[lk] : 16 * index[lk] + 16], 4, 4)

    rows = []
    for la, lb, kind in pairs:
        ta, tb = frame(la), frame(lb)
        rows.append(ta[:3, 3] - tb[:3, 3])
        if kind == "6d":  # the whole rotation matrices: zero at the same frame only (not at a half turn)
            rows.append(ca.reshape(ta[:3, :3] - tb[:3, :3], 9, 1) * scale)
    fn = ca.Function("urdf_loops", [q], [ca.vertcat(*rows), ca.jacobian(ca.vertcat(*rows), q)], ["q"], ["r", "J"])
    tol = ASSEMBLY_TOL * scale
    start = float(np.max(np.abs(np.asarray(fn(np.zeros(q.size1()))[0]))))
    if start <= tol:
        return np.zeros(q.size1()), ""
    left = start
    for fixed in (set(held), set()):
        free = [k for k in range(q.size1()) if k not in fixed]
        if not free:
            continue
        values, reached = _levenberg_marquardt(fn, q.size1(), free, tol)
        if reached <= tol:
            return values, ""
        left = min(left, reached)
    return np.zeros(q.size1()), (
        f"the loops do not close from the URDF's zero configuration (largest closure residual {start:.3g}, "
        f"at best {left:.3g}): the drawing is the zero configuration"
    )


def _levenberg_marquardt(fn: ca.Function, n: int, free: list[int], tol: float) -> tuple[np.ndarray, float]:
    """Minimise |r(q)|^2 over the ``free`` values from q = 0; the values and the largest |r|."""
    values = np.zeros(n)
    r, jac = (np.asarray(v) for v in fn(values))
    r = r.ravel()
    cost, lam = float(r @ r), 1e-3
    for _step in range(ASSEMBLY_STEPS):
        if float(np.max(np.abs(r))) <= tol:
            break
        j = jac[:, free]
        g = j.T @ j
        step = np.linalg.solve(g + lam * (np.diag(np.diag(g)) + 1e-12 * np.eye(len(free))), -j.T @ r)
        longest = float(np.max(np.abs(step)))
        if longest > 0.5:  # at most half a radian (or half a metre) a step
            step *= 0.5 / longest
        trial = values.copy()
        trial[free] += step
        r2, jac2 = (np.asarray(v) for v in fn(trial))
        r2 = r2.ravel()
        if float(r2 @ r2) < cost:
            values, r, jac, cost, lam = trial, r2, jac2, float(r2 @ r2), max(lam / 3, 1e-12)
        else:
            lam *= 4
            if lam > 1e12:
                break
    return values, float(np.max(np.abs(r)))
