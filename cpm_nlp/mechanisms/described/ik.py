"""The closed-form inverse kinematics of a mechanism file (its ``ik`` section): the dependent
coordinates and the actuators as expressions of the task coordinates, and ``reach``."""

from __future__ import annotations

import casadi as ca

from ...core.errors import InputError
from . import expr as ex
from .builder import ClosureBuilder
from .spec import ClosedFormIK


def closed_form_ik(gen: ClosureBuilder) -> ca.Function | None:
    """``ik(t, p) -> (x, q, reach)`` from the ``ik`` section (None: the file has none)."""
    ik = gen.d.ik
    if ik is None:
        return None
    t = ca.SX.sym("t", len(gen.d.platform.task))
    env = _task_env(gen, t)
    for name, text in ik.let.items():
        gen.bind(env, name, gen.value(text, ("ik", "let", name), env), ("ik", "let", name))
    xs = [_pose(gen, ik, env, name) for name in gen.x_names]
    qs = []
    for c in gen.q_coords:
        if c.name not in ik.actuators:
            raise InputError(f"missing the actuator {c.name!r}", path=("ik", "actuators"))
        qs.append(gen.scalar(ik.actuators[c.name], ("ik", "actuators", c.name), env, c.kind))
    if ik.reach is None:
        raise InputError("missing 'reach': an expression < 0 where the pose cannot be assembled", path=("ik",))
    reach = gen.scalar(ik.reach, ("ik", "reach"), env)
    return ca.Function(
        "ik", [t, gen.p], ca.cse([ca.vertcat(*xs), ca.vertcat(*qs), reach]), ["t", "p"], ["x", "q", "reach"]
    )


def _task_env(gen: ClosureBuilder, t: ca.SX) -> dict[str, ex.Value]:
    """The parameters and derived values, the task coordinates (the symbols t) and the fixed ones."""
    pf = gen.d.platform
    env = dict(gen.env)
    for k, name in enumerate(pf.task):
        env[name] = ex.Value(t[k], ex.DIMENSION_OF[pf.coordinates[name]])
    for name in pf.fixed:
        env[name] = gen.xenv[name]
    return env


def _pose(gen: ClosureBuilder, ik: ClosedFormIK, env: dict[str, ex.Value], name: str) -> ca.SX:
    """A pose coordinate: a task coordinate's symbol, or a dependent one's expression (``ik.pose``)."""
    if name in gen.d.platform.task:
        return env[name].sx
    if name not in ik.pose:
        raise InputError(
            f"missing the dependent coordinate {name!r} (an expression of the task coordinates)", path=("ik", "pose")
        )
    dim = gen.x_coords[gen.x_names.index(name)].kind
    return gen.scalar(ik.pose[name], ("ik", "pose", name), env, dim)
