"""The legs of a described mechanism as serial chains (`Chains`),
the ``chains`` capability the six-axis hinge model needs.

The description already gives each leg as a chain at the reference
configuration; here its joints are evaluated at a model's parameters.  Spatial
legs of P, R, C, U and S joints are supported; a planar mechanism or a
``distance`` joint has no chains (the capability is then absent).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

import casadi as ca
import numpy as np

from ...core.chains import JOINT_DOF, ChainJoint, Chains, LegChain

if TYPE_CHECKING:
    from .generate import Generator

#: each leg's name and its joints as (type, elementary motions, coordinates, actuator or None)
Layout = list[tuple[str, list[tuple[str, list[str], tuple[str, ...], str | None]]]]


def supported(gen: Generator) -> bool:
    """Whether every leg is a spatial chain of P, R, C, U and S joints."""
    if gen.d.platform.planar or not gen.leg_joints:
        return False
    return all(j.type in JOINT_DOF for _leg, joints in gen.leg_joints for j in joints)


def _names(j: Any) -> tuple[str, ...]:
    dof = JOINT_DOF[j.type]
    names = tuple(j.spec.coordinates) or tuple(j.names)
    return names if len(names) == dof else ("",) * dof


def chain_parts(gen: Generator) -> tuple[ca.Function, ca.Function, ca.Function, Layout]:
    """What `chains_maker` needs of a built generator: the chains' geometry (a CasADi function
    of the parameters), the platform's frame, the reference configuration and the layout."""
    from .motions import elementary_motions

    q = ca.vertcat(*gen.q_syms)
    outs: list[Any] = []
    layout: Layout = []
    for leg, joints in gen.leg_joints:
        rows = []
        for j in joints:
            motions = elementary_motions(j)
            kinds, axes = [m[0] for m in motions], [m[1] for m in motions]
            outs.append(j.at)
            outs.append(ca.horzcat(*axes))
            gain = ca.SX(0)
            if j.spec.actuated is not None and j.value is not None:
                gain = ca.sum1(ca.jacobian(j.value, q).T)
            outs.append(gain)
            rows.append((j.type, kinds, _names(j), j.spec.actuated))
        layout.append((leg.name, rows))
    geom = ca.Function("chain_geometry", [gen.p], outs)
    frame = ca.Function("platform_frame_p", [gen.x, gen.p], [gen.P, gen.R], ["x", "p"], ["P", "R"])
    refs = ca.Function("chain_reference", [gen.p], [gen.x_home, ca.vertcat(*gen.q_home)])
    return geom, frame, refs, layout


def chains_function(gen: Generator):
    """``(model) -> Chains`` for a built generator."""
    return chains_maker(*chain_parts(gen))


def chains_maker(geom: ca.Function, frame: ca.Function, refs: ca.Function, layout: Layout):
    """``(model) -> Chains`` from `chain_parts` (the chains' geometry is evaluated once per model)."""
    nx = frame.size1_in(0)

    def make(model: Any) -> Chains:
        p = np.asarray(model.p, dtype=float)
        vals = [np.asarray(v, dtype=float) for v in geom(p)] if geom.n_out() else []
        legs = []
        k = 0
        for name, rows in layout:
            built = []
            for _j, kinds, names, actuated in rows:
                at, axes, gain = vals[k].ravel(), vals[k + 1].reshape(3, -1), float(vals[k + 2].ravel()[0])
                k += 3
                built.append((at, axes, kinds, names, actuated, gain))
            locs = [b[0] for b in built]
            joints = []
            for n, (at, axes, kinds, names, actuated, gain) in enumerate(built):
                joints.append(
                    ChainJoint(
                        type=rows[n][0],
                        at=at,
                        axes=axes / np.linalg.norm(axes, axis=0),
                        motions=tuple(kinds),
                        coordinates=names,
                        actuated=actuated,
                        gain=gain if actuated else 1.0,
                        link=_link(locs, n),
                    )
                )
            legs.append(LegChain(name, tuple(joints), locs[-1]))
        xs = ca.SX.sym("x", nx)
        P, R = frame(xs, p)
        platform = ca.Function("platform_frame", [xs], [P, R], ["x"], ["P", "R"])
        x_ref, q_ref = (np.asarray(v, dtype=float).ravel() for v in refs(p))
        note = "links and the platform are rigid bodies; the hinges are six-axis springs at their joints"
        return Chains(tuple(legs), platform, x_ref, q_ref, note)

    return make


def _link(locs: list[np.ndarray], n: int) -> np.ndarray | None:
    """The unit direction from joint n to the first later joint elsewhere, else from
    the last earlier joint elsewhere to joint n."""
    for m in list(range(n + 1, len(locs))) + list(range(n - 1, -1, -1)):
        d = locs[m] - locs[n] if m > n else locs[n] - locs[m]
        if np.linalg.norm(d) > 1e-12:
            return d / np.linalg.norm(d)
    return None


__all__ = ["Layout", "chain_parts", "chains_function", "chains_maker", "supported"]
