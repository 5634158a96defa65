"""The mobility of a graph of bodies and joints: the loop rows independent at the reference
configuration (the rank of the loops' Jacobian, in file order), the degrees of freedom they
leave, Grübler-Kutzbach counted beside them, and the message when they do not match the
actuators (naming the joints the free motions move)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ...core.joints import JOINT_TYPES
from ...core.model import Coordinate
from .graph_tree import GraphJoint

#: the freedom a distance joint (a rod with a spherical joint at each end) leaves between the
#: two bodies it joins, spatial and planar (Grübler-Kutzbach); other joints: their dof (the table)
ROD_FREEDOM = {False: 5, True: 2}
#: a row is independent of the rows kept before it when its part outside their span is at least
#: this share of its norm (the rank test at the reference configuration, in file order)
RANK_TOL = 1e-8


@dataclass
class GraphInfo:
    """What ``describe`` shows of a graph: bodies, tree and cut joints, loops, mobility."""

    bodies: list[str]
    ground: str
    joints: list[tuple[str, str, str, str, bool, bool, int]]  # name, type, a, b, actuated, tree, loop
    loops: list[tuple[int, str, list[str]]]  # number, the joint closing it, the bodies around it
    gruebler: int
    mobility: int
    dropped: list[tuple[int, str]]  # (loop, row name) of the rows that repeat others at the reference


def independent_rows(J: np.ndarray) -> list[int]:
    """The rows of J independent of the rows before them (Gram-Schmidt in row order, `RANK_TOL`)."""
    keep, basis = [], np.zeros((0, J.shape[1]))
    for k in range(J.shape[0]):
        row = J[k]
        n = np.linalg.norm(row)
        if n == 0:
            continue
        rest = row - basis.T @ (basis @ row) if basis.size else row
        if np.linalg.norm(rest) > RANK_TOL * n:
            keep.append(k)
            basis = np.vstack([basis, rest / np.linalg.norm(rest)])
    return keep


def gruebler(gjoints: Sequence[GraphJoint], nbodies: int, planar: bool) -> int:
    """Grübler-Kutzbach: λ (bodies - 1) - Σ (λ - f), λ = 3 planar, 6 spatial; f a joint's freedom."""
    lam = 3 if planar else 6
    freedom = [
        ROD_FREEDOM[planar] if g.type == "distance" else len(g.names) if g.type == "pose" else JOINT_TYPES[g.type].dof
        for g in gjoints
    ]
    return lam * (nbodies - 1) - sum(lam - f for f in freedom)


def mobility_message(info: GraphInfo, q_coords: Sequence[Coordinate], J_ref: np.ndarray, tree_names: list[str]) -> str:
    """Why the loops' degrees of freedom do not match the actuators (J_ref: the loops' Jacobian
    in the tree coordinates ``tree_names`` at the reference configuration)."""
    nq = len(q_coords)
    text = (
        f"wrong mobility: the loops' Jacobian at the reference configuration gives {info.mobility} degree(s) "
        f"of freedom (Grübler-Kutzbach: {info.gruebler}), and {nq} joint(s) are actuated "
        f"({', '.join(c.name for c in q_coords)})"
    )
    if info.mobility > nq:
        moving = _moving(J_ref, tree_names)
        return text + f"; the free motions move {', '.join(moving)}: actuate more joints, or join those bodies"
    return text + "; actuate fewer joints (an actuated joint is locked against the others)"


def _moving(J_ref: np.ndarray, tree_names: list[str]) -> list[str]:
    """The joints the free motions move: the rows of the whole null space (not one basis vector)."""
    _u, sv, vt = np.linalg.svd(J_ref) if J_ref.size else (None, np.zeros(0), np.eye(len(tree_names)))
    rank = int(np.sum(sv > RANK_TOL * max(float(sv[0]) if sv.size else 1.0, 1e-300)))
    share = np.linalg.norm(vt[rank:], axis=0)
    return [n for n, v in zip(tree_names, share) if v > 1e-6 * max(float(np.max(share)), 1e-300)]
