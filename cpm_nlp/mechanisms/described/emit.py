"""The CasADi Functions of a generated closure (Φ, the branch indicators, the platform's
frame, the reported joint values, the reference configuration, the pose bounds, the drawing's
points), with common subexpressions merged."""

from __future__ import annotations

import math
from typing import Any

import casadi as ca

from .builder import ClosureBuilder
from .ik import closed_form_ik


def closure_functions(gen: ClosureBuilder, q: ca.SX) -> dict[str, Any]:
    x, p = gen.x, gen.p
    io = ["x", "q", "p"]
    # common subexpressions merged (ca.cse: each distinct operation on the same operands once;
    # the values are the same to the bit): the legs share the platform's rotation and its
    # sines and cosines, each indicator the squared norm of its leg's closure
    phi = ca.Function("phi", [x, q, p], [ca.cse(ca.vertcat(*[r[0] for r in gen.rows]))], io, ["phi"])
    g = ca.cse(ca.vertcat(*[b[0] for b in gen.branch]))
    branch = ca.Function("branch", [x, q, p], [g], io, ["g"]) if gen.branch else None
    frame = ca.Function("frame", [x, p], ca.cse([gen.R, gen.P]), ["x", "p"], ["R", "position"])
    passive = None
    if gen.reported:
        j = ca.cse(ca.vertcat(*[r.value for r in gen.reported]))
        passive = ca.Function("passive", [x, q, p], [j], io, ["j"])
    home = ca.Function("home", [p], [gen.x_home, ca.vertcat(*gen.q_home)], ["p"], ["x", "q"])
    radius = ca.mmax(ca.vertcat(*gen.platform_radius)) if gen.platform_radius else ca.SX(0)
    if gen.d.characteristic_length is not None:
        radius = gen.scalar(gen.d.characteristic_length, ("characteristic_length",), gen.env, "length")
    lo, hi = pose_bounds(gen, radius)
    req = ca.vertcat(*[r[0] for r in gen.requirements]) if gen.requirements else ca.SX(0, 1)
    extras = ca.Function(
        "described_values",
        [p],
        [lo, hi, radius, ca.vertcat(*[dv[1] for dv in gen.derived]) if gen.derived else ca.SX(0, 1), req],
        ["p"],
        ["lower", "upper", "length", "derived", "requirements"],
    )
    points = [v for _leg, joints in gen.drawn for _t, v, _a, _s in joints] + [gen.P]
    drawing = ca.Function("drawing_points", [x, q, p], [ca.horzcat(*points)], io, ["points"])
    return {
        "drawing": drawing,
        "drawing_legs": [(name, [(t, a, sl) for t, _v, a, sl in joints]) for name, joints in gen.drawn],
        "phi": phi,
        "branch": branch,
        "branch_names": [b[1] for b in gen.branch],
        "branch_descriptions": [b[2] for b in gen.branch],
        "frame": frame,
        "passive": passive,
        "home": home,
        "extras": extras,
        "ik": closed_form_ik(gen),
        "row_names": [r[1] for r in gen.rows],
        "requirements": [(r[1], r[2]) for r in gen.requirements],
    }


def pose_bounds(gen: ClosureBuilder, radius: ca.SX) -> tuple[ca.SX, ca.SX]:
    pf = gen.d.platform
    lo, hi = [], []
    span = 2 * ca.fmax(radius, ca.norm_2(gen.P_home))
    for k, coord in enumerate(gen.x_coords):
        name, dim = coord.name, coord.kind
        if name in pf.bounds:
            a, b = pf.bounds[name]
            lo.append(gen.scalar(a, ("platform", "bounds", name, 0), gen.env, dim))
            hi.append(gen.scalar(b, ("platform", "bounds", name, 1), gen.env, dim))
        elif dim == "angle":
            # a passive joint of a graph turns up to a half turn either way from the drawing
            half = math.pi / 3 if name in pf.coordinates else math.pi if gen.d.is_graph else math.pi / 2
            lo.append(gen.x_home[k] - half)
            hi.append(gen.x_home[k] + half)
        else:
            lo.append(gen.x_home[k] - span)
            hi.append(gen.x_home[k] + span)
    return ca.vertcat(*lo), ca.vertcat(*hi)
