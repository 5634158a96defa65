"""Closed-form forward kinematics of a planar graph of bodies and joints, decomposed into dyads
(issue 23, item 5).

Once the actuators are set, a planar linkage of R and P joints (and rods, ``distance`` joints) is
solved in closed form where it decomposes into Assur groups of class II -- dyads -- each placed by
bodies already placed (the ground first, then the actuated joints' bodies), as Pyslvs and pylinkage
assemble a linkage.  A body's pose is its rotation (cos, sin) and translation from the drawing (the
graph's body frames are the world at the drawing, `graph`); derived here:

* **actuated joint** (R or P) to a placed body: its value is the actuator's, the body follows;
* **RRR** -- bodies b1, b2 pinned (R) to placed bodies at A and B and to each other at C, or one
  body pinned at A with a rod (``distance``) from its point C to a placed point B: C is the
  intersection of the circles |C - A| = r1, |C - B| = r2 (r1, r2 the bodies' own lengths, the rod's):
  e = B - A, a = (r1² - r2² + |e|²)/(2|e|²), h² = r1²/|e|² - a², C = A + a e + s √h² e⊥;
* **RRP** -- b1 pinned at A, b2 sliding on a placed body (P, axis u) and pinned to b1 at C, or one
  body sliding with a rod from C to a placed point A: C = P0 + v d on the slide's line (d its world
  direction) and |C - A| = r: v = -d·(P0 - A) + s √(disc), disc = (d·(P0 - A))² - |P0 - A|² + r²;
* **RPR** -- b1 pinned at A, b2 pinned at B, the two sliding on each other (P, axis u; both turn
  by the same angle θ): R(θ)(w + v u) = B - A with w the drawing's offset between the pins across
  the slide, so v = -w·u + s √(|B - A|² - (w·n)²) (n ⊥ u) and θ the angle from w + v u to B - A.

Each dyad has two assemblies; its sign s is the reference configuration's (the graph's assembled
reference, with the parameters' defaults, as the graph's branch indicators are signed:
`branches.graph_indicators`).
``disc`` (the least over the dyads, negative where one does not assemble) and ``side`` (the least of
each dyad's side at the guess x0 times its sign: positive where x0 is on the assembly taken) let the
FK kernel (`cpm_nlp.core.kernels.fk_kernel`) leave any other pose to Newton.  The pose
coordinates follow from the bodies' poses: a tree R joint's value is its home plus the turn between
its bodies, each body's turn the one nearest its turn at the guess x0 (as Newton from x0 finds it),
a body driven by an actuated R joint turning with it exactly (a crank keeps its whole turns), a
tree P joint's the slide between its points, the platform's coordinates by their rows (linear in
them).  A graph that decomposes only in part (a class III group after some dyads) gets a seed
instead (`Decomposition.seed`): the dyads' closed form places the bodies it can, and Newton,
started there, moves only the rest (the placed coordinates' rows are already solved, and Φ_x is
block-triangular in them); Newton's status stands.  A spatial or overconstrained graph, or one
whose platform is placed by its coordinates, gets neither.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import casadi as ca
import numpy as np

#: a body's pose in the plane: (cos, sin) of its turn from the drawing and its translation
Pose = tuple[ca.SX, ca.SX, ca.SX]


def _rot(pose: Pose, v: ca.SX) -> ca.SX:
    c, s, _t = pose
    return ca.vertcat(c * v[0] - s * v[1], s * v[0] + c * v[1])


def _world(pose: Pose, p: ca.SX) -> ca.SX:
    return _rot(pose, p[:2]) + pose[2]


def _perp(v: ca.SX) -> ca.SX:
    return ca.vertcat(-v[1], v[0])


def _cross(a: ca.SX, b: ca.SX) -> ca.SX:
    return a[0] * b[1] - a[1] * b[0]


def _from_points(d1: ca.SX, d2: ca.SX, w1: ca.SX, w2: ca.SX) -> Pose:
    """The pose that takes the drawing's points d1, d2 of a body to w1, w2 (|w2 - w1| = |d2 - d1|)."""
    d, w = d2[:2] - d1[:2], w2 - w1
    n2 = ca.dot(d, d)
    c, s = ca.dot(d, w) / n2, _cross(d, w) / n2
    return c, s, w1 - ca.vertcat(c * d1[0] - s * d1[1], s * d1[0] + c * d1[1])


def _wrap(z: ca.SX) -> ca.SX:
    """z brought into [-π, π)."""
    return z - 2 * np.pi * ca.floor((z + np.pi) / (2 * np.pi))


@dataclass
class Dyad:
    """A solved dyad: its kind, the bodies it places, its discriminant and the symbolic side of its
    assembly, as placed (``side``, in q and p) and at any pose x (``side_x``, through the graph's
    body poses)."""

    kind: str
    bodies: tuple[str, ...]
    disc: ca.SX
    symbol: ca.SX  # the branch sign, a symbol until the reference's is known (:meth:`Decomposition.function`)
    side_x: ca.SX = None  # type: ignore[assignment]
    sign: float = 1.0


class Decomposition:
    """The dyads of a planar graph (``gen``: its `GraphGenerator`, built), placed in
    order from the ground; `function` is its ``fk_closed``."""

    def __init__(self, gen: Any, q: ca.SX) -> None:
        self.gen, self.q = gen, q
        self.placed: dict[str, Pose] = {gen.ground: (ca.SX(1), ca.SX(0), ca.SX.zeros(2))}
        self.dyads: list[Dyad] = []
        self.joints = [g for g in gen.gjoints if g.type in ("planar_R", "planar_P", "distance")]
        self.complete = len(self.joints) == len(gen.gjoints) and self._decompose()
        #: tree coordinates the placed bodies give (a partial decomposition: the others' stay x0's)
        self.partial = not self.complete

    # -- the graph's own expressions at a pose x (for the reference's signs and the guess's side) --
    def _wx(self, body: str, point: ca.SX) -> ca.SX:
        return self.gen.world(body, point)[:2]

    def _axis_x(self, body: str, u: ca.SX) -> ca.SX:
        return (self.gen.pose[body][0] @ u)[:2]

    # -- the decomposition ------------------------------------------------------------------------
    def _decompose(self) -> bool:
        bodies = [b.name for b in self.gen.d.bodies]
        while len(self.placed) < len(bodies):
            if not (self._actuated() or self._single() or self._pair()):
                return False
        return True

    def _to_placed(self, b: str) -> list:
        """The joints between an unplaced body b and placed ones: (joint, placed body)."""
        return joints_to_placed(self.joints, self.placed, b)

    def _point_on(self, g: Any, body: str) -> ca.SX:
        return point_on(g, body)

    def _actuated(self) -> bool:
        for g in self.joints:
            if g.drive is None or (g.a in self.placed) == (g.b in self.placed):
                continue
            known, new = (g.a, g.b) if g.a in self.placed else (g.b, g.a)
            K = self.placed[known]
            sign = 1 if new == g.b else -1  # the joint's value turns (moves) b relative to a
            if g.type == "planar_R":
                th = sign * g.drive
                c, s = ca.cos(th), ca.sin(th)
                cb, sb = K[0] * c - K[1] * s, K[1] * c + K[0] * s
            else:
                cb, sb = K[0], K[1]
            pose_new = (cb, sb, ca.SX.zeros(2))
            at = _world(K, self._point_on(g, known))
            if g.type == "planar_P":
                at = at + sign * g.drive * _rot(K, g.axis[:2])
            self.placed[new] = (cb, sb, at - _rot(pose_new, self._point_on(g, new)))
            return True
        return False

    def _single(self) -> bool:
        """One body placed by two joints to placed bodies: a pin and a rod (RRR), a slide and a rod (RRP)."""
        for body in [b.name for b in self.gen.d.bodies if b.name not in self.placed]:
            links = self._to_placed(body)
            pins = [(g, k) for g, k in links if g.type == "planar_R" and g.drive is None]
            slides = [(g, k) for g, k in links if g.type == "planar_P" and g.drive is None]
            rods = [(g, k) for g, k in links if g.type == "distance"]
            if pins and rods:
                (gp, kp), (gr, kr) = pins[0], rods[0]
                A_d = self._point_on(gp, body)
                C_d = self._point_on(gr, body)
                A = _world(self.placed[kp], self._point_on(gp, kp))
                B = _world(self.placed[kr], self._point_on(gr, kr))
                r1 = ca.norm_2(C_d[:2] - A_d[:2])
                C, dyad = self._circles(A, r1, B, gr.length, (body,))
                dyad.side_x = self._circles_side_x(
                    self._wx(kp, self._point_on(gp, kp)), self._wx(kr, self._point_on(gr, kr)), self._wx(body, C_d)
                )
                self.placed[body] = _from_points(A_d, C_d, A, C)
                self.dyads.append(dyad)
                return True
            if slides and rods:
                (gs, ks), (gr, kr) = slides[0], rods[0]
                C_d = self._point_on(gr, body)
                A = _world(self.placed[kr], self._point_on(gr, kr))
                C, pose, dyad = self._slide_circle(gs, ks, body, C_d, A, gr.length)
                A_x = self._wx(kr, self._point_on(gr, kr))
                dyad.side_x = ca.dot(self._line_x(gs, ks, body), self._wx(body, C_d) - A_x)
                self.placed[body] = pose
                self.dyads.append(dyad)
                return True
        return False

    def _pair(self) -> bool:
        """Two bodies, each pinned (or slid) to a placed body, joined to each other (RRR, RRP, RPR)."""
        free = [b.name for b in self.gen.d.bodies if b.name not in self.placed]
        for g in self.joints:
            if g.a not in free or g.b not in free or g.type == "distance":
                continue
            b1, b2 = g.a, g.b
            l1 = [(h, k) for h, k in self._to_placed(b1) if h.drive is None and h.type != "distance"]
            l2 = [(h, k) for h, k in self._to_placed(b2) if h.drive is None and h.type != "distance"]
            if not l1 or not l2:
                continue
            (h1, k1), (h2, k2) = l1[0], l2[0]
            kinds = (h1.type, g.type, h2.type)
            if kinds == ("planar_R", "planar_R", "planar_R"):
                self._rrr(g, b1, h1, k1, b2, h2, k2)
            elif kinds == ("planar_R", "planar_R", "planar_P"):
                self._rrp(g, b1, h1, k1, b2, h2, k2)
            elif kinds == ("planar_P", "planar_R", "planar_R"):
                self._rrp(g, b2, h2, k2, b1, h1, k1)
            elif kinds == ("planar_R", "planar_P", "planar_R"):
                self._rpr(g, b1, h1, k1, b2, h2, k2)
            else:
                continue
            return True
        return False

    # -- the dyads --------------------------------------------------------------------------------
    def _circles(self, A: ca.SX, r1: ca.SX, B: ca.SX, r2: ca.SX, bodies: tuple) -> tuple[ca.SX, Dyad]:
        e = B - A
        d2 = ca.dot(e, e)
        a = (r1**2 - r2**2 + d2) / (2 * d2)
        h2 = r1**2 / d2 - a**2
        s = ca.SX.sym("s")  # the reference's sign, set once known (:meth:`function`)
        C = A + a * e + s * ca.sqrt(ca.fmax(h2, 0)) * _perp(e)
        return C, Dyad("RRR", bodies, h2, s)

    @staticmethod
    def _circles_side_x(A: ca.SX, B: ca.SX, C: ca.SX) -> ca.SX:
        return ca.dot(_perp(B - A), C - A)

    def _rrr(self, g: Any, b1: str, h1: Any, k1: str, b2: str, h2: Any, k2: str) -> None:
        A1_d, C1_d = self._point_on(h1, b1), self._point_on(g, b1)
        A2_d, C2_d = self._point_on(h2, b2), self._point_on(g, b2)
        A = _world(self.placed[k1], self._point_on(h1, k1))
        B = _world(self.placed[k2], self._point_on(h2, k2))
        r1, r2 = ca.norm_2(C1_d[:2] - A1_d[:2]), ca.norm_2(C2_d[:2] - A2_d[:2])
        C, dyad = self._circles(A, r1, B, r2, (b1, b2))
        dyad.side_x = self._circles_side_x(
            self._wx(k1, self._point_on(h1, k1)), self._wx(k2, self._point_on(h2, k2)), self._wx(b1, C1_d)
        )
        self.placed[b1] = _from_points(A1_d, C1_d, A, C)
        self.placed[b2] = _from_points(A2_d, C2_d, B, C)
        self.dyads.append(dyad)

    def _line(self, gs: Any, ks: str, body: str, C_d: ca.SX) -> tuple[ca.SX, ca.SX, ca.SX]:
        """The world line on which the point C_d of a body sliding on the placed body ks moves:
        C = P0 + v d, with v the slide's value from the drawing (its direction d, the joint's axis
        as ks carries it, sign: v moves the distal body along +u)."""
        K = self.placed[ks]
        sign = 1 if body == gs.b else -1
        d = sign * _rot(K, gs.axis[:2])
        # at v = 0 the body is at its drawing relative to ks: C at ks's pose of (C_d + pin offset)
        off = self._point_on(gs, ks)[:2] - self._point_on(gs, body)[:2]
        P0 = _world(K, C_d[:2] + off)
        return P0, d, sign * gs.axis[:2]

    def _line_x(self, gs: Any, ks: str, body: str) -> ca.SX:
        """The slide's direction d at a pose x (the graph's expressions)."""
        return (1 if body == gs.b else -1) * self._axis_x(ks, gs.axis)

    def _slide_circle(self, gs: Any, ks: str, body: str, C_d: ca.SX, A: ca.SX, r: ca.SX) -> tuple:
        """A body sliding on ks whose point C_d lies at r from the world point A: the line and the circle."""
        P0, d, _u = self._line(gs, ks, body, C_d)
        m = ca.dot(d, P0 - A)
        disc = m**2 - ca.dot(P0 - A, P0 - A) + r**2
        s = ca.SX.sym("s")
        v = -m + s * ca.sqrt(ca.fmax(disc, 0))
        C = P0 + v * d
        K = self.placed[ks]
        pose = (K[0], K[1], C - _rot(K, C_d[:2]))
        # the side: d·(C - A) = v + m = s √disc
        return C, pose, Dyad("RRP", (body,), disc, s)

    def _rrp(self, g: Any, b1: str, h1: Any, k1: str, b2: str, h2: Any, k2: str) -> None:
        """b1 pinned (h1) at A to k1, b2 sliding (h2) on k2, the two pinned (g) at C."""
        A1_d, C1_d = self._point_on(h1, b1), self._point_on(g, b1)
        C2_d = self._point_on(g, b2)
        A = _world(self.placed[k1], self._point_on(h1, k1))
        r1 = ca.norm_2(C1_d[:2] - A1_d[:2])
        C, pose2, dyad = self._slide_circle(h2, k2, b2, C2_d, A, r1)
        dyad.bodies = (b1, b2)
        dyad.side_x = ca.dot(self._line_x(h2, k2, b2), self._wx(b2, C2_d) - self._wx(k1, self._point_on(h1, k1)))
        self.placed[b2] = pose2
        self.placed[b1] = _from_points(A1_d, C1_d, A, C)
        self.dyads.append(dyad)

    def _rpr(self, g: Any, b1: str, h1: Any, k1: str, b2: str, h2: Any, k2: str) -> None:
        """b1 pinned (h1) at A to k1, b2 pinned (h2) at B to k2, b2 sliding on b1 (g, axis u)."""
        A_d, B_d = self._point_on(h1, b1), self._point_on(h2, b2)
        A = _world(self.placed[k1], self._point_on(h1, k1))
        B = _world(self.placed[k2], self._point_on(h2, k2))
        sign = 1 if b2 == g.b else -1
        u = sign * g.axis[:2]
        # b2 = b1 moved by v u across the slide: B = A + R(θ)(w + v u), with
        # w = (g's point on b1 - A_d) - (g's point on b2 - B_d)
        w = (self._point_on(g, b1)[:2] - A_d[:2]) - (self._point_on(g, b2)[:2] - B_d[:2])
        D = B - A
        m = ca.dot(w, u)
        n = _cross(u, w)
        disc = ca.dot(D, D) - n**2
        s = ca.SX.sym("s")
        v = -m + s * ca.sqrt(ca.fmax(disc, 0))
        z = w + v * u  # in the drawing, taken by R(θ) onto D
        nz = ca.dot(z, z)
        c, sn = ca.dot(z, D) / nz, _cross(z, D) / nz
        rot1 = (c, sn, ca.SX.zeros(2))
        self.placed[b1] = (c, sn, A - _rot(rot1, A_d[:2]))
        self.placed[b2] = (c, sn, B - _rot(rot1, B_d[:2]))
        dyad = Dyad("RPR", (b1, b2), disc, s)
        # the side: (R u)·(B - A) = w·u + v
        u_x = sign * self._axis_x(b1, g.axis)
        dyad.side_x = ca.dot(u_x, self._wx(k2, self._point_on(h2, k2)) - self._wx(k1, self._point_on(h1, k1)))
        self.dyads.append(dyad)

    # -- the pose coordinates ---------------------------------------------------------------------
    def _turns(self, x0: ca.SX) -> dict[str, ca.SX]:
        """Each body's turn from the drawing, a whole number of turns chosen: a body an actuated R
        joint places turns with it exactly (a crank keeps its angle, turns and all); any other
        placed body takes the turn nearest its turn at x0 (as Newton from x0 would), a body left
        unplaced its turn at x0."""
        gen = self.gen
        at_x0 = {b: ca.substitute(ca.SX(gen.angle[b]), gen.x, x0) for b in gen.angle}
        turns = {gen.ground: ca.SX(0)}
        grown = True
        while grown:  # parents first, down the spanning tree
            grown = False
            for child, link in gen.parent.items():
                if child in turns or link is None or link[0] not in turns:
                    continue
                parent, g = link
                if child not in self.placed:
                    turns[child] = at_x0[child]
                elif g.drive is not None and g.type == "planar_R":
                    turns[child] = turns[parent] + (g.drive if child == g.b else -g.drive)
                else:
                    c, s, _t = self.placed[child]
                    turns[child] = at_x0[child] + _wrap(ca.atan2(s, c) - at_x0[child])
                grown = True
        return turns

    def _coordinates(self, x0: ca.SX) -> ca.SX | None:
        """The pose coordinates from the bodies' poses and turns (`_turns`) (None: a
        coordinate it cannot give); a partial decomposition keeps x0's where the bodies are not placed."""
        gen = self.gen
        where = {n: k for k, n in enumerate(gen.x_names)}
        x = [None] * len(gen.x_names)
        turns = self._turns(x0)
        for g in self.joints:
            if not g.tree or g.type == "distance":
                continue
            k = where[g.names[0]]
            home = g.homes[0]
            if g.type == "planar_R":  # its value moves b's turn from a's (graph.poses)
                x[k] = home + g.drive if g.drive is not None else home + turns[g.b] - turns[g.a]
                continue
            if g.a not in self.placed or g.b not in self.placed:
                x[k] = x0[k]
                continue
            if g.drive is not None:
                x[k] = home + g.drive
                continue
            Pa, Pb = self.placed[g.a], self.placed[g.b]
            # b's point pb onto a's pa, moved by v along the axis as a carries it
            offset = _world(Pb, g.pb) - _world(Pa, g.pa)
            x[k] = home + ca.dot(_rot(Pa, g.axis[:2]), offset)
        rest = [k for k in range(len(x)) if x[k] is None]
        if rest and not self._platform(x, x0, rest):
            return None
        return ca.vertcat(*x)

    def _platform(self, x: list, x0: ca.SX, rest: list) -> bool:
        """The platform's coordinates (``rest``, filled into x): their rows are linear in them, so one
        Newton step from the guess solves them (False: they are not)."""
        gen = self.gen
        tree = [k for k in range(len(x)) if k not in rest]
        rows = ca.vertcat(*[r for r, _name in gen.platform_rows])
        xr = ca.vertcat(*[gen.x[k] for k in rest])
        if rows.numel() != len(rest):
            return False
        J = ca.jacobian(rows, xr)
        if ca.depends_on(J, xr):
            return False
        z0 = ca.vertcat(*[x0[k] for k in rest])
        f = ca.Function("platform_rows", [gen.x, gen.p], [rows, J])
        full = ca.SX.zeros(len(x))
        for k in tree:
            full[k] = x[k]
        for k in rest:
            full[k] = x0[k]
        r, Jv = f(full, gen.p)
        z = z0 - ca.solve(Jv, r)
        for i, k in enumerate(rest):
            x[k] = z[i]
        return True

    def function(self, x_ref: np.ndarray, q_ref: np.ndarray, p_ref: np.ndarray) -> ca.Function | None:
        """``fk_closed(q, x0, p) -> (x, disc, side)``, each dyad's sign that of the reference
        configuration (x_ref, q_ref) with the parameters p_ref (None: a dyad is singular there)."""
        parts = self._parts(x_ref, q_ref, p_ref)
        if parts is None:
            return None
        x0, x, disc, side = parts
        outs = ca.cse([x, disc, side])
        return ca.Function("fk_closed", [self.q, x0, self.gen.p], outs, ["q", "x0", "p"], ["x", "disc", "side"])

    def seed(self, x_ref: np.ndarray, q_ref: np.ndarray, p_ref: np.ndarray) -> ca.Function | None:
        """``fk_seed(q, x0, p) -> x0'``: a partial decomposition's guess for Newton -- the placed
        bodies' coordinates in closed form, the others x0's -- where every placed dyad assembles
        and x0 is on the side of each one's assembly, else x0 itself (None: a dyad is singular at
        the reference, or a platform coordinate it cannot give)."""
        parts = self._parts(x_ref, q_ref, p_ref)
        if parts is None:
            return None
        x0, x, disc, side = parts
        finite = ca.sum1(ca.fabs(x) < ca.inf) == x.numel()  # false for inf and NaN
        ok = ca.logic_and(ca.logic_and(disc >= 0, side > 0), finite)
        guess = ca.cse(ca.if_else(ok, x, x0))
        return ca.Function("fk_seed", [self.q, x0, self.gen.p], [guess], ["q", "x0", "p"], ["x0_seed"])

    def _parts(self, x_ref: np.ndarray, q_ref: np.ndarray, p_ref: np.ndarray) -> tuple | None:
        """(x0, x, disc, side) of the dyads placed, each its reference sign (None: see `function`)."""
        gen = self.gen
        x0 = ca.SX.sym("x0", gen.x.numel())
        if not reference_signs(self.dyads, gen, self.q, (x_ref, q_ref, p_ref)):
            return None
        x = self._coordinates(x0)
        if x is None:
            return None
        return (x0, *with_signs(self.dyads, gen, x, x0))


def graph_closed_form(gen: Any, q: ca.SX) -> tuple[ca.Function | None, ca.Function | None]:
    """(``fk_closed``, ``fk_seed``) of a planar graph: the closed-form FK where it decomposes into
    dyads, else the seed of the dyads it has (both None: none, or the graph is overconstrained or
    spatial, or its platform is placed by its coordinates)."""
    if not gen.d.platform.planar or gen.normal_form or gen.d.platform.placed:
        return None, None
    dec = Decomposition(gen, q)
    if not dec.dyads or len(dec.joints) != len(gen.gjoints):
        return None, None
    a = gen.assembler
    ref = (np.asarray(a.x_ref, float), np.asarray(a.q_ref, float), np.asarray(a.defaults, float))
    dyads = ", ".join(f"{dy.kind} ({', '.join(dy.bodies)})" for dy in dec.dyads)
    if dec.complete:
        fn = dec.function(*ref)
        if fn is not None:
            gen.closed_form_summary = f"forward kinematics in closed form: {len(dec.dyads)} dyad(s), {dyads}"
        return fn, None
    seed = dec.seed(*ref)
    if seed is not None:
        rest = [b.name for b in gen.d.bodies if b.name not in dec.placed]
        gen.closed_form_summary = (
            f"forward kinematics partly in closed form: {len(dec.dyads)} dyad(s), {dyads}; "
            f"Newton places {', '.join(rest)}"
        )
    return None, seed


__all__ = ["Decomposition", "graph_closed_form"]


def reference_signs(dyads: list[Any], gen: Any, q: Any, ref: tuple) -> bool:
    """Each dyad's branch sign (``dy.sign``, +-1) from its side indicator ``dy.side_x`` at the
    reference ``ref = (x, q, p)``; False where a dyad is singular there (its side zero or not
    finite): no closed form.  Shared by the planar and the spherical dyads."""
    for dy in dyads:
        f = ca.Function("dyad_side", [gen.x, q, gen.p], [dy.side_x], ["x", "q", "p"], ["side"])
        v = float(f(*ref))
        if not np.isfinite(v) or v == 0.0:
            return False
        dy.sign = 1.0 if v > 0 else -1.0
    return True


def with_signs(dyads: list[Any], gen: Any, x: Any, x0: Any) -> tuple[Any, Any, Any]:
    """(x, disc, side): the placed coordinates ``x`` with each dyad's sign symbol replaced by its
    reference sign, the smallest discriminant (>= 0: every dyad assembles) and the smallest
    signed side at the guess ``x0`` (> 0: the guess lies on the reference branches)."""
    syms = ca.vertcat(*[dy.symbol for dy in dyads])
    sv = ca.DM([dy.sign for dy in dyads])
    x = ca.substitute(x, syms, sv)
    disc = ca.mmin(ca.vertcat(*[ca.substitute(dy.disc, syms, sv) for dy in dyads]))
    side = ca.mmin(ca.vertcat(*[dy.sign * ca.substitute(dy.side_x, gen.x, x0) for dy in dyads]))
    return x, disc, side


def point_on(g: Any, body: str) -> ca.SX:
    """The point of joint ``g`` on ``body`` (one of its two bodies), in that body's frame."""
    return g.pa if body == g.a else g.pb


def joints_to_placed(joints: list[Any], placed: Mapping[str, Any], b: str, undriven: bool = False) -> list:
    """The joints between an unplaced body ``b`` and placed ones, as (joint, placed body);
    ``undriven``: only the joints no actuator drives.  Shared by the planar and the spherical
    decompositions."""
    out = []
    for g in joints:
        if undriven and g.drive is not None:
            continue
        if g.a == b and g.b in placed:
            out.append((g, g.b))
        elif g.b == b and g.a in placed:
            out.append((g, g.a))
    return out
