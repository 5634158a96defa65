"""The graph of a bodies-and-joints file: its joints resolved to CasADi, the spanning tree grown
from the ground (actuated joints first, then the joints whose values are task coordinates, then
in file order; a ``distance`` joint never), each body's parent in it, and the loops the joints
left out close (the fundamental cycles of the tree: a cycle basis)."""

from __future__ import annotations

from dataclasses import dataclass, field

import casadi as ca

from ...core.errors import InputError
from .spec import Joint

#: each body's parent in the tree and the joint to it (None: the ground)
Parents = dict[str, "tuple[str, GraphJoint] | None"]


@dataclass
class GraphJoint:
    """A joint of the graph resolved to CasADi."""

    spec: Joint
    type: str
    a: str  # the proximal body
    b: str  # the distal body
    pa: ca.SX  # its point on a (a's frame = the world at the drawing)
    pb: ca.SX  # its point on b
    axis: ca.SX | None = None
    axes: list = field(default_factory=list)
    tree: bool = False
    reversed: bool = False  # in the tree, b is the parent of a
    values: list = field(default_factory=list)  # displacements from the drawing, one per dof
    names: tuple = ()
    loop: int = 0  # the loop it closes (cut joints), 1-based
    length: ca.SX | None = None
    homes: list = field(default_factory=list)  # its coordinates' values in the drawing (tree joints)
    drive: ca.SX | None = None  # an actuated joint's displacement from the drawing, gain (q - q_home)

    @property
    def name(self) -> str:
        return str(self.spec.name)


def spanning_tree(gjoints: list[GraphJoint], bodies: list[str], ground: str, task: set[str]) -> Parents:
    """Grow the tree from the ground: actuated joints first, then the joints whose values are
    task coordinates, then in file order (a distance joint never); the joints left out close
    one loop each (numbered in file order).  Each body's parent in the tree."""
    root = {b: b for b in bodies}

    def find(b: str) -> str:
        while root[b] != b:
            root[b] = root[root[b]]
            b = root[b]
        return b

    def rank(k: int) -> tuple:
        j = gjoints[k].spec
        return (j.type != "pose", j.actuated is None, not task & set(j.coordinates), k)

    for k in sorted(range(len(gjoints)), key=rank):
        g = gjoints[k]
        if g.type == "distance":
            continue
        ra, rb = find(g.a), find(g.b)
        if ra != rb:
            root[ra] = rb
            g.tree = True
        elif g.spec.actuated is not None:
            raise InputError(
                f"the actuated joint {g.name} closes a loop of actuated joints only (they form a cycle)",
                path=g.spec.path + ("actuated",),
            )
    parent = _orient(gjoints, bodies, ground)
    loop = 0
    for g in gjoints:
        if not g.tree:
            loop += 1
            g.loop = loop
    return parent


def _orient(gjoints: list[GraphJoint], bodies: list[str], ground: str) -> Parents:
    """Each body's parent in the tree (breadth first from the ground), and each tree joint's direction."""
    parent: Parents = {ground: None}
    frontier = [ground]
    while frontier:
        nxt = []
        for body in frontier:
            for g in gjoints:
                if not g.tree or body not in (g.a, g.b):
                    continue
                other = g.b if body == g.a else g.a
                if other in parent:
                    continue
                g.reversed = other == g.a
                parent[other] = (body, g)
                nxt.append(other)
        frontier = nxt
    loose = [b for b in bodies if b not in parent]
    if loose:
        raise InputError(
            f"the bodies {', '.join(loose)} are not joined to the ground by joints (a distance joint "
            "is a rod between two bodies, not a joint that carries one)",
            path=("bodies", loose[0]),
            hint="join every body to another by a P, R, C, U or S joint",
        )
    return parent


def path_to_ground(parent: Parents, body: str) -> list[str]:
    out = [body]
    while parent[out[-1]] is not None:
        out.append(parent[out[-1]][0])  # type: ignore[index]
    return out


def loop_bodies(parent: Parents, g: GraphJoint) -> list[str]:
    """The bodies around the loop a cut joint closes: a -> ... -> common ancestor -> ... -> b."""
    pa, pb = path_to_ground(parent, g.a), path_to_ground(parent, g.b)
    common = next(x for x in pa if x in pb)
    return pa[: pa.index(common) + 1] + list(reversed(pb[: pb.index(common)]))
