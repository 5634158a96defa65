"""Closed-form forward kinematics of a planar RRR dyad (issue 23, item 5).

A planar legs file whose platform is a point (two position coordinates, no rotation) held by
two legs that each end in a link c_i -> B_i eliminated at a revolute (planar R at c_i, known once
the actuators are set): Φ is then two circle rows, |B_i(x) - c_i(q)| = r_i, with B_i(x) = x + d_i
(d_i constant in x).  The pose is the intersection of the circles of centres o_i = c_i - d_i and
radii r_i (derived here; the textbook circle-circle intersection, as Pyslvs and pylinkage assemble
an RRR dyad):

    e = o2 - o1,  D² = e·e,  a = (r1² - r2² + D²) / (2 D²),  h² = r1²/D² - a²,
    x = o1 + a e + s √h² e⊥,  e⊥ = (-e_y, e_x),

with the branch sign s = sign(e⊥·(x - o1)) at the reference configuration (the file's assembly
mode), an expression of the parameters.  h² < 0: the circles do not meet (the pose is out of
reach); a guess x0 with s e⊥·(x0 - o1) <= 0 lies in the other assembly (Newton from it seeks that
one).  The kernel (`cpm_nlp.core.kernels.fk_kernel`) then leaves the pose to Newton, whose
status it reports, so the closed form never answers with a number for a pose it cannot assemble.

An actuated P between two point joints (an R-P-R leg: |B - c| = r + s) is a circle of radius
r + s(q): the same intersection.  Files of bodies and joints have their own decomposition into
dyads (RRR, RRP, RPR; `graph_dyads`).
"""

from __future__ import annotations

import casadi as ca

from .builder import ClosureBuilder


def closed_form_fk(gen: ClosureBuilder, q: ca.SX, circles: list[tuple[int, ca.SX, ca.SX, ca.SX]]) -> ca.Function | None:
    """``fk_closed(q, x0, p) -> (x, disc, side)`` of a two-circle closure (None: Φ is not one).

    circles: each planar circle row of Φ as (row, c, B, r): the row's position, the centre c(q, p),
    the platform point B(x, p) and the radius r(q, p) (planar: the first two components).  disc:
    h², negative where the circles do not meet; side: s e⊥·(x0 - o1), positive where the guess x0
    is on the side of the centres' line of the file's assembly."""
    x = gen.x
    if not gen.d.platform.planar or x.numel() != 2 or len(gen.rows) != 2 or len(circles) != 2:
        return None
    if sorted(row for row, *_ in circles) != [0, 1]:
        return None
    centres = []
    for _row, c, B, r in circles:
        d = B[:2] - x  # B = x + d with d constant in x: the platform does not turn
        if ca.depends_on(d, x) or ca.depends_on(c, x) or ca.depends_on(r, x):
            return None
        centres.append((c[:2] - d, r))
    (o1, r1), (o2, r2) = centres
    e = o2 - o1
    d2 = ca.dot(e, e)
    a = (r1**2 - r2**2 + d2) / (2 * d2)
    h2 = r1**2 / d2 - a**2
    perp = ca.vertcat(-e[1], e[0])
    # the branch sign at the reference configuration (q_home, x_home): the file's assembly mode
    q_home = ca.vertcat(*gen.q_home)
    home = ca.Function("dyad_home_side", [q, x, gen.p], [ca.dot(perp, x - o1)], ["q", "x", "p"], ["side"])
    s = ca.sign(home(q_home, gen.x_home, gen.p))
    pose = o1 + a * e + s * ca.sqrt(ca.fmax(h2, 0)) * perp
    x0 = ca.SX.sym("x0", x.numel())
    side = s * ca.dot(perp, x0 - o1)
    outs = ca.cse([pose, h2, side])
    return ca.Function("fk_closed", [q, x0, gen.p], outs, ["q", "x0", "p"], ["x", "disc", "side"])


__all__ = ["closed_form_fk"]
