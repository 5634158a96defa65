"""The closed-form inverse kinematics of a mechanism file (its ``ik`` section): the dependent
coordinates and the actuators as expressions of the task coordinates, and ``reach``."""

from __future__ import annotations

import casadi as ca

from ...core.errors import InputError
from . import expr as ex
from .builder import ClosureBuilder


def closed_form_ik(gen: ClosureBuilder) -> ca.Function | None:  # noqa: C901 - one check per part of the ik section
    ik = gen.d.ik
    if ik is None:
        return None
    pf = gen.d.platform
    t = ca.SX.sym("t", len(pf.task))
    env = dict(gen.env)
    for k, name in enumerate(pf.task):
        env[name] = ex.Value(t[k], ex.DIMENSION_OF[pf.coordinates[name]])
    for name in pf.fixed:
        env[name] = gen.xenv[name]
    for name, text in ik.let.items():
        gen.bind(env, name, gen.value(text, ("ik", "let", name), env), ("ik", "let", name))
    xs = []
    for name in gen.x_names:
        if name in pf.task:
            xs.append(env[name].sx)
        elif name in ik.pose:
            dim = gen.x_coords[gen.x_names.index(name)].kind
            xs.append(gen.scalar(ik.pose[name], ("ik", "pose", name), env, dim))
        else:
            raise InputError(
                f"missing the dependent coordinate {name!r} (an expression of the task coordinates)",
                path=("ik", "pose"),
            )
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
