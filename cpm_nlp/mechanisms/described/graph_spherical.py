"""Closed-form forward kinematics of a spatial graph of R joints, decomposed into spherical dyads
(issue 23, item 5: the spherical analogue of `graph_dyads`).

Once the actuators are set, bodies are placed from the ground by their actuated R joints, and by
**spherical dyads**: two free bodies b1, b2, joined by an R joint (axis c), each joined by an R
joint to a placed body (k1 by the axis a1, k2 by a2), the three axes meeting at one point O.  Each
body turns about its joint to the placed body, so the world direction C of the joint between them
keeps its arcs to the two known axes A = R_k1 a1, B = R_k2 a2: C·A = a1·c = cos α1 and
C·B = a2·c = cos α2 -- C is where two cones meet (a spherical triangle A, B, C with two sides
known: the spherical law of cosines), derived here:

    C = x A + y B + s z (A × B),  x = (cos α1 - cos α2 cos γ)/sin² γ,
    y = (cos α2 - cos α1 cos γ)/sin² γ,  z² = disc / sin² γ,
    disc = 1 - x² - y² - 2 x y cos γ,  cos γ = A·B,

two assemblies (the branch sign s, the reference configuration's: the sign of C·(A × B) there).
Each body's rotation follows from C: R_b1 = R_k1 Rot(a1, θ1), θ1 the turn about a1 that takes c
to R_k1ᵀ C (its cosine and sine from the parts of c and R_k1ᵀ C across a1), its translation
the one that keeps its joint point on k1's.  The planar dyads' `graph_dyads.Decomposition` does
the same in the plane; the FK kernel uses both alike (`core.kernels.closed_fk_kernel`).

Detected from the graph, not assumed: a pair is a spherical dyad when, **at the drawing with the
parameters' defaults**, the axes a1 and c on b1 meet (their lines' distance), a2 and c on b2 meet,
the two meeting points agree along c, and the two placed bodies put them at one world point O --
each within `CONCURRENT_TOL` of the drawing's size.  The same measure, symbolic in the parameters
and the actuators, is checked **on the parameters in use** at every pose: where it exceeds the
tolerance (a design whose axes no longer meet) ``disc`` is negative and the pose is left to
Newton.  A dyad whose two known axes are parallel (sin γ = 0) gives a non-finite pose, also left
to Newton.  The pose coordinates follow from the bodies' rotations: a tree R joint's value is its
home plus the turn between its bodies about its axis (the one nearest x0, as Newton from x0 finds
it; an actuated joint's exactly its actuator's); the platform's coordinates, where its rows are
linear in them, by one Newton step on those rows.  A graph that decomposes only in part, or whose
platform rows are not linear, gets a seed (`Decomposition.seed`'s analogue): Newton, started
there, moves only what is left.  A planar graph is `graph_dyads`'; a graph with other joints than
R is left to Newton where the dyads do not reach.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import casadi as ca
import numpy as np

from .graph_dyads import joints_to_placed, point_on, reference_signs, with_signs
from .motions import rot

#: how near the axes of a spherical dyad must meet, relative to the drawing's size (detection at
#: the defaults, and the check at every pose on the parameters in use)
CONCURRENT_TOL = 1e-9

#: a body's pose: its rotation from the drawing and its translation (a point p at R p + t)
Pose3 = tuple[ca.SX, ca.SX]


def _world(pose: Pose3, p: ca.SX) -> ca.SX:
    return pose[0] @ p + pose[1]


def _rodrigues(k: ca.SX, c: ca.SX, s: ca.SX) -> ca.SX:
    """R = c I + s [k]x + (1 - c) k kᵀ (k a unit axis, c² + s² = 1)."""
    K = ca.skew(k)
    return c * ca.SX.eye(3) + s * K + (1 - c) * (k @ k.T)


def _wrap(z: ca.SX) -> ca.SX:
    """z brought into [-π, π)."""
    return z - 2 * np.pi * ca.floor((z + np.pi) / (2 * np.pi))


def _line_meet(p1: ca.SX, u1: ca.SX, p2: ca.SX, u2: ca.SX) -> tuple[ca.SX, ca.SX]:
    """The distance between the lines p1 + t u1 and p2 + t u2 (unit u1, u2, not parallel) and the
    point of the first nearest the second."""
    n = ca.cross(u1, u2)
    n2 = ca.dot(n, n)
    d = p2 - p1
    dist = ca.fabs(ca.dot(d, n)) / ca.sqrt(n2)
    t1 = ca.dot(ca.cross(d, u2), n) / n2
    return dist, p1 + t1 * u1


@dataclass
class SphericalDyad:
    """A solved spherical dyad: the bodies it places, its discriminant (with the concurrency
    check folded in), its concurrency measure, and the side of its assembly at a pose x."""

    bodies: tuple[str, str]
    disc: ca.SX
    concurrency: ca.SX  # the axes' distance from one point, relative to the drawing's size
    symbol: ca.SX
    side_x: ca.SX = None  # type: ignore[assignment]
    sign: float = 1.0


class SphericalDecomposition:
    """The spherical dyads of a spatial graph of R joints (``gen``: its `GraphGenerator`, built),
    placed in order from the ground."""

    def __init__(self, gen: Any, q: ca.SX) -> None:
        self.gen, self.q = gen, q
        self.placed: dict[str, Pose3] = {gen.ground: (ca.SX.eye(3), ca.SX.zeros(3))}
        self.dyads: list[SphericalDyad] = []
        self.joints = [g for g in gen.gjoints if g.type == "R"]
        self.complete = self._decompose() and len(self.joints) == len(gen.gjoints)

    def _point_on(self, g: Any, body: str) -> ca.SX:
        return point_on(g, body)

    def _decompose(self) -> bool:
        bodies = [b.name for b in self.gen.d.bodies]
        while len(self.placed) < len(bodies):
            if not (self._actuated() or self._pair()):
                return False
        return True

    def _to_placed(self, b: str) -> list:
        """The undriven R joints between an unplaced body b and placed ones: (joint, placed body)."""
        return joints_to_placed(self.joints, self.placed, b, undriven=True)

    def _actuated(self) -> bool:
        """A body joined to a placed one by an actuated R joint: it turns by the actuator about the axis."""
        for g in self.joints:
            if g.drive is None or (g.a in self.placed) == (g.b in self.placed):
                continue
            known, new = (g.a, g.b) if g.a in self.placed else (g.b, g.a)
            K = self.placed[known]
            sign = 1 if new == g.b else -1  # the joint's value turns b relative to a
            R = K[0] @ rot(g.axis, sign * g.drive)
            self.placed[new] = (R, _world(K, self._point_on(g, known)) - R @ self._point_on(g, new))
            return True
        return False

    def _pair(self) -> bool:
        """Two free bodies joined by an R joint, each joined by an R joint to a placed body, the
        three axes meeting at one point (at the drawing, with the defaults)."""
        free = [b.name for b in self.gen.d.bodies if b.name not in self.placed]
        for g in self.joints:
            if g.a not in free or g.b not in free or g.drive is not None:
                continue
            b1, b2 = g.a, g.b
            for h1, k1 in self._to_placed(b1):
                for h2, k2 in self._to_placed(b2):
                    if self._spherical(g, b1, h1, k1, b2, h2, k2):
                        return True
        return False

    def _concurrency(self, g: Any, b1: str, h1: Any, k1: str, b2: str, h2: Any, k2: str) -> tuple:
        """How far the three axes are from meeting at one point (relative to the drawing's size),
        symbolic in q and p, and the world point O where they meet (through k1)."""
        c = g.axis
        d1, O1 = _line_meet(self._point_on(h1, b1), h1.axis, self._point_on(g, b1), c)
        d2, O2 = _line_meet(self._point_on(h2, b2), h2.axis, self._point_on(g, b2), c)
        # the meeting points, along c, at the same offset from the joint's point on each body
        delta = ca.dot(self._point_on(g, b2) - O2, c) - ca.dot(self._point_on(g, b1) - O1, c)
        K1, K2 = self.placed[k1], self.placed[k2]
        O1w = _world(K1, self._point_on(h1, k1)) + K1[0] @ (O1 - self._point_on(h1, b1))
        O2w = _world(K2, self._point_on(h2, k2)) + K2[0] @ (O2 - self._point_on(h2, b2))
        worst = ca.fmax(ca.fmax(d1, d2), ca.fmax(ca.fabs(delta), ca.norm_2(O1w - O2w)))
        return worst / self.gen.scale, O1w

    def _spherical(self, g: Any, b1: str, h1: Any, k1: str, b2: str, h2: Any, k2: str) -> bool:
        gen = self.gen
        a1, a2, c = h1.axis, h2.axis, g.axis
        # non-degenerate: each body's two axes apart (else its turn about a1 is not fixed by C)
        sin2 = ca.fmin(ca.dot(ca.cross(a1, c), ca.cross(a1, c)), ca.dot(ca.cross(a2, c), ca.cross(a2, c)))
        conc, _O = self._concurrency(g, b1, h1, k1, b2, h2, k2)
        f = ca.Function("spherical_dyad_check", [gen.p, self.q], [conc, sin2], ["p", "q"], ["concurrency", "sin2"])
        ref = gen.assembler
        v_conc, v_sin2 = (float(v) for v in f(gen.p_default, np.asarray(ref.q_ref, float)))
        if not (np.isfinite(v_conc) and v_conc <= CONCURRENT_TOL and v_sin2 > 1e-12):
            return False
        K1, K2 = self.placed[k1], self.placed[k2]
        A, B = K1[0] @ a1, K2[0] @ a2
        cg = ca.dot(A, B)
        ca1, ca2 = ca.dot(a1, c), ca.dot(a2, c)  # cos α1, cos α2: the arcs each body keeps
        den = 1 - cg**2
        x = (ca1 - ca2 * cg) / den
        y = (ca2 - ca1 * cg) / den
        disc = 1 - x**2 - y**2 - 2 * x * y * cg
        s = ca.SX.sym("s")  # the reference's sign, set once known (`_parts`)
        C = x * A + y * B + s * ca.sqrt(ca.fmax(disc, 0) / den) * ca.cross(A, B)
        self.placed[b1] = self._turned(K1, h1, k1, b1, c, C)
        self.placed[b2] = self._turned(K2, h2, k2, b2, c, C)
        ok = ca.if_else(conc <= CONCURRENT_TOL, disc, -1)
        dyad = SphericalDyad((b1, b2), ok, conc, s)
        pose = gen.pose
        Ax, Bx, Cx = pose[k1][0] @ a1, pose[k2][0] @ a2, pose[b1][0] @ c
        dyad.side_x = ca.dot(ca.cross(Ax, Bx), Cx)
        self.dyads.append(dyad)
        return True

    def _turned(self, K: Pose3, h: Any, k: str, b: str, c: ca.SX, C: ca.SX) -> Pose3:
        """The pose of b, turned about its joint h to the placed body k so that its axis c lands on
        the world direction C: R_b = R_k Rot(a, θ) with Rot(a, θ) c = R_kᵀ C."""
        a = h.axis
        u = c - ca.dot(a, c) * a
        t = K[0].T @ C
        v = t - ca.dot(a, t) * a
        n2 = ca.dot(u, u)
        cth, sth = ca.dot(u, v) / n2, ca.dot(a, ca.cross(u, v)) / n2
        R = K[0] @ _rodrigues(a, cth, sth)
        return R, _world(K, self._point_on(h, k)) - R @ self._point_on(h, b)

    # -- the pose coordinates ---------------------------------------------------------------------
    def _coordinates(self, x0: ca.SX) -> tuple[ca.SX, bool] | None:
        """The pose coordinates from the bodies' poses (x0's where a body is not placed) and whether
        every one is in closed form (None: a platform row it cannot take)."""
        gen = self.gen
        where = {n: k for k, n in enumerate(gen.x_names)}
        x: list = [None] * len(gen.x_names)
        exact = True
        for g in gen.gjoints:
            if not g.tree or g.type == "pose":
                continue
            for name in g.names:
                k = where[name]
                if g.type == "R" and g.drive is not None:
                    x[k] = g.homes[0] + g.drive
                elif g.type == "R" and g.a in self.placed and g.b in self.placed:
                    M = self.placed[g.a][0].T @ self.placed[g.b][0]
                    sin = ca.dot(g.axis, ca.vertcat(M[2, 1] - M[1, 2], M[0, 2] - M[2, 0], M[1, 0] - M[0, 1])) / 2
                    turn = ca.atan2(sin, (ca.trace(M) - 1) / 2)
                    x[k] = x0[k] + _wrap(g.homes[0] + turn - x0[k])
                else:
                    x[k] = x0[k]
                    exact = False
        rest = [k for k in range(len(x)) if x[k] is None]
        if rest and not self._platform(x, x0, rest):
            for k in rest:
                x[k] = x0[k]
            exact = False
        return ca.vertcat(*x), exact

    def _platform(self, x: list, x0: ca.SX, rest: list) -> bool:
        """The platform's coordinates (``rest``, filled into x) where their rows are linear in them:
        one Newton step from the guess solves them (False: they are not)."""
        gen = self.gen
        rows = ca.vertcat(*[r for r, _name in gen.platform_rows]) if gen.platform_rows else ca.SX(0, 1)
        xr = ca.vertcat(*[gen.x[k] for k in rest])
        if rows.numel() != len(rest):
            return False
        J = ca.jacobian(rows, xr)
        if ca.depends_on(J, xr):
            return False
        full = ca.vertcat(*[x0[k] if x[k] is None else x[k] for k in range(len(x))])
        f = ca.Function("platform_rows", [gen.x, gen.p], [rows, J], ["x", "p"], ["rows", "J"])
        r, Jv = f(full, gen.p)
        z = ca.vertcat(*[x0[k] for k in rest]) - ca.solve(Jv, r)
        for i, k in enumerate(rest):
            x[k] = z[i]
        return True

    def parts(self, x_ref: np.ndarray, q_ref: np.ndarray, p_ref: np.ndarray) -> tuple | None:
        """(x0, x, disc, side, exact): the dyads placed, each with its reference sign (None: a
        dyad is singular at the reference)."""
        gen = self.gen
        x0 = ca.SX.sym("x0", gen.x.numel())
        if not reference_signs(self.dyads, gen, self.q, (x_ref, q_ref, p_ref)):
            return None
        coords = self._coordinates(x0)
        if coords is None:
            return None
        x, exact = coords
        return (x0, *with_signs(self.dyads, gen, x, x0), exact)


def spherical_closed_form(gen: Any, q: ca.SX) -> tuple[ca.Function | None, ca.Function | None]:
    """(``fk_closed``, ``fk_seed``) of a spatial graph: the closed-form FK where its R joints
    decompose into actuated joints and spherical dyads, else the seed of the dyads it has (both
    None: no spherical dyad, or the platform is placed by its coordinates)."""
    if gen.d.platform.planar or gen.d.platform.placed:
        return None, None
    dec = SphericalDecomposition(gen, q)
    if not dec.dyads:
        return None, None
    a = gen.assembler
    parts = dec.parts(np.asarray(a.x_ref, float), np.asarray(a.q_ref, float), np.asarray(a.defaults, float))
    if parts is None:
        return None, None
    x0, x, disc, side, exact = parts
    names = ", ".join(f"RRR ({', '.join(dy.bodies)})" for dy in dec.dyads)
    if dec.complete and exact:
        gen.closed_form_summary = f"forward kinematics in closed form: {len(dec.dyads)} spherical dyad(s), {names}"
        outs = ca.cse([x, disc, side])
        fn = ca.Function("fk_closed", [q, x0, gen.p], outs, ["q", "x0", "p"], ["x", "disc", "side"])
        return fn, None
    finite = ca.sum1(ca.fabs(x) < ca.inf) == x.numel()  # false for inf and NaN
    ok = ca.logic_and(ca.logic_and(disc >= 0, side > 0), finite)
    guess = ca.cse(ca.if_else(ok, x, x0))
    rest = [b.name for b in gen.d.bodies if b.name not in dec.placed]
    gen.closed_form_summary = (
        f"forward kinematics partly in closed form: {len(dec.dyads)} spherical dyad(s), {names}; "
        f"Newton places {', '.join(rest) or 'the platform coordinates'}"
    )
    return None, ca.Function("fk_seed", [q, x0, gen.p], [guess], ["q", "x0", "p"], ["x0_seed"])


__all__ = ["CONCURRENT_TOL", "SphericalDecomposition", "spherical_closed_form"]
