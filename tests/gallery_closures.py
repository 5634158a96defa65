"""The gallery mechanisms as hand-written LoopClosures (CasADi), so that the
generic machinery (FK, IK, Jacobians, all assembly modes, synthesis) can be
exercised on them now; tests/mechanisms/described/test_gallery.py checks each against the
independent numpy references of tests/gallery_reference.py (which share no
code with this file).  Parameters are SI; default values are those of the
references.

Each ``*_closure()`` returns a LoopClosure and ``*_model(**params)`` a Model.
"""

from __future__ import annotations

import math

import casadi as ca
import numpy as np

from cpm_nlp.core.model import Coordinate, LoopClosure, Model

TWO_PI = 2.0 * math.pi
LEGS = (0.0, TWO_PI / 3.0, 2.0 * TWO_PI / 3.0)


def _fn(name, ins, outs, names_in, names_out) -> ca.Function:
    return ca.Function(name, ins, outs, names_in, names_out)


def _rx(t):
    return ca.vertcat(ca.horzcat(1, 0, 0), ca.horzcat(0, ca.cos(t), -ca.sin(t)), ca.horzcat(0, ca.sin(t), ca.cos(t)))


def _ry(t):
    return ca.vertcat(ca.horzcat(ca.cos(t), 0, ca.sin(t)), ca.horzcat(0, 1, 0), ca.horzcat(-ca.sin(t), 0, ca.cos(t)))


def _rz(t):
    return ca.vertcat(ca.horzcat(ca.cos(t), -ca.sin(t), 0), ca.horzcat(ca.sin(t), ca.cos(t), 0), ca.horzcat(0, 0, 1))


def _cross2(a, b):
    return a[0] * b[1] - a[1] * b[0]


def _dyad(v, l1, l2, sign):
    """First-link angle of an RR dyad reaching offset v, and the reach margin 1 - c²."""
    r = ca.sqrt(ca.dot(v, v))
    c = (r**2 + l1**2 - l2**2) / (2 * l1 * r)
    return ca.atan2(v[1], v[0]) + sign * ca.acos(ca.fmin(ca.fmax(c, -1), 1)), 1 - c**2


def _model(closure: LoopClosure, defaults: dict, overrides: dict, limits=None, lc: float = 1.0) -> Model:
    params = {**defaults, **overrides}
    return Model(closure, {n: params[n] for n in closure.parameters}, limits=limits or {}, characteristic_length=lc)


# -- planar five-bar ------------------------------------------------------------------------------

FIVE_BAR = {"d": 0.2, "l1": 0.25, "l2": 0.3, "sigma1": 1.0, "sigma2": -1.0, "kappa": 1.0}


def five_bar_closure() -> LoopClosure:
    """x = (px, py), q = (theta1, theta2); p = (d, l1, l2, sigma1, sigma2, kappa):
    the signs σi choose the working mode (the elbow of each leg), κ the
    assembly mode; branch indicators: each elbow on its σ side, and P on the
    κ side of B1 -> B2 (κ = +1: to the left)."""
    x, q, p = ca.SX.sym("x", 2), ca.SX.sym("q", 2), ca.SX.sym("p", 6)
    d, l1, l2, s1, s2, kappa = (p[i] for i in range(6))

    def parts(x, q):
        A = [ca.vertcat(-d / 2, 0), ca.vertcat(d / 2, 0)]
        B = [A[i] + l1 * ca.vertcat(ca.cos(q[i]), ca.sin(q[i])) for i in range(2)]
        return A, B

    A, B = parts(x, q)
    res = ca.vertcat(*[(ca.sumsqr(x - B[i]) - l2**2) / (2 * l2) for i in range(2)])
    phi = _fn("phi", [x, q, p], [res], ["x", "q", "p"], ["phi"])
    g = [-s * _cross2(B[i] - A[i], x - B[i]) / (l1 * l2) for i, s in enumerate((s1, s2))]
    g.append(kappa * _cross2(B[1] - B[0], x - B[0]) / l2**2)
    branch = _fn("branch", [x, q, p], [ca.vertcat(*g)], ["x", "q", "p"], ["g"])
    t = ca.SX.sym("t", 2)
    th1, r1 = _dyad(t - ca.vertcat(-d / 2, 0), l1, l2, s1)
    th2, r2 = _dyad(t - ca.vertcat(d / 2, 0), l1, l2, s2)
    ik = _fn("ik", [t, p], [t, ca.vertcat(th1, th2), ca.fmin(r1, r2)], ["t", "p"], ["x", "q", "reach"])

    def home(pv):
        t0 = np.array([0.0, 0.6 * (pv[1] + pv[2])])
        return t0, np.asarray(ik(t0, pv)[1]).ravel()

    def bounds(pv):
        r = pv[0] + pv[1] + pv[2]
        return np.array([-r, -r]), np.array([r, r])

    return LoopClosure(
        "five_bar",
        x=(Coordinate("px", "length", "end point, x"), Coordinate("py", "length", "end point, y")),
        q=tuple(Coordinate(f"theta{i}", "angle", f"actuated base joint {i}", "theta") for i in (1, 2)),
        parameters=("d", "l1", "l2", "sigma1", "sigma2", "kappa"),
        phi=phi,
        task=("px", "py"),
        ik=ik,
        branch=branch,
        home=home,
        bounds=bounds,
    )


def five_bar_model(closure: LoopClosure | None = None, limits=None, **params) -> Model:
    return _model(closure or five_bar_closure(), FIVE_BAR, params, limits, lc=FIVE_BAR["l1"])


# -- Delta robot ----------------------------------------------------------------------------------

DELTA = {"rb": 0.1, "rp": 0.03, "la": 0.1, "lb": 0.25}


def delta_closure() -> LoopClosure:
    """x = (px, py, pz), q = (theta1..3) (arm angles, positive down); p = (rb, rp,
    la, lb).  Forearms as distance constraints (the parallelograms keep the
    platform level).  Branch: knee out on every leg, platform below the base."""
    x, q, p = ca.SX.sym("x", 3), ca.SX.sym("q", 3), ca.SX.sym("p", 4)
    rb, rp, la, lb = (p[i] for i in range(4))
    res, g = [], []
    for i, gam in enumerate(LEGS):
        local = _rz(-gam) @ x  # the leg's frame
        J = ca.vertcat(rb + la * ca.cos(q[i]), 0, -la * ca.sin(q[i]))
        f = local + ca.vertcat(rp, 0, 0) - J
        res.append((ca.sumsqr(f) - lb**2) / (2 * lb))
        g.append((-ca.sin(q[i]) * f[0] - ca.cos(q[i]) * f[2]) / (la * lb))  # (arm x forearm) . y_leg
    g.append(-x[2] / lb)
    phi = _fn("phi", [x, q, p], [ca.vertcat(*res)], ["x", "q", "p"], ["phi"])
    branch = _fn("branch", [x, q, p], [ca.vertcat(*g)], ["x", "q", "p"], ["g"])
    t = ca.SX.sym("t", 3)
    th, reach = [], []
    for gam in LEGS:
        local = _rz(-gam) @ t
        X = local[0] + rp - rb
        E, F = -2 * la * X, 2 * la * local[2]
        G = X**2 + local[1] ** 2 + local[2] ** 2 + la**2 - lb**2
        disc = E**2 + F**2 - G**2
        th.append(2 * ca.atan((-F - ca.sqrt(ca.fmax(disc, 0))) / (G - E)))
        reach.append(disc / (4 * la**2 * lb**2))
    ik = _fn("ik", [t, p], [t, ca.vertcat(*th), ca.mmin(ca.vertcat(*reach))], ["t", "p"], ["x", "q", "reach"])

    def home(pv):
        rb_, rp_, la_, lb_ = pv
        return np.array([0.0, 0.0, -math.sqrt(lb_**2 - (rb_ + la_ - rp_) ** 2)]), np.zeros(3)

    def bounds(pv):
        r = pv[2] + pv[3]
        return np.array([-r, -r, -r]), np.array([r, r, r])

    return LoopClosure(
        "delta",
        x=tuple(Coordinate(n, "length", f"platform centre, {n[1]}") for n in ("px", "py", "pz")),
        q=tuple(Coordinate(f"theta{i}", "angle", f"arm {i}, down from horizontal", "theta") for i in (1, 2, 3)),
        parameters=("rb", "rp", "la", "lb"),
        phi=phi,
        task=("px", "py", "pz"),
        ik=ik,
        branch=branch,
        home=home,
        bounds=bounds,
    )


def delta_model(closure: LoopClosure | None = None, limits=None, **params) -> Model:
    return _model(closure or delta_closure(), DELTA, params, limits)


# -- 3-RPS ---------------------------------------------------------------------------------------

RPS3 = {"ra": 0.1, "rp": 0.06, "h0": 0.12}
SIX = (
    Coordinate("px", "length", "platform centre, x (parasitic)"),
    Coordinate("py", "length", "platform centre, y (parasitic)"),
    Coordinate("pz", "length", "platform centre, z"),
    Coordinate("psi", "angle", "rotation about x"),
    Coordinate("theta", "angle", "rotation about y"),
    Coordinate("phi", "angle", "rotation about z (parasitic)"),
)


def _yxz(psi, theta, phi):
    return _ry(theta) @ _rx(psi) @ _rz(phi)


def _parasitic(psi, theta, r):
    phi = ca.atan(ca.sin(psi) * ca.sin(theta) / (ca.cos(psi) + ca.cos(theta)))
    px = r / 2 * (ca.cos(theta) * ca.cos(phi) + ca.sin(psi) * ca.sin(theta) * ca.sin(phi) - ca.cos(psi) * ca.cos(phi))
    py = -r * ca.cos(psi) * ca.sin(phi)
    return phi, px, py


def rps3_closure() -> LoopClosure:
    """x = (px, py, pz, psi, theta, phi), R = Ry Rx Rz; q = leg lengths l1..3;
    p = (ra, rp, h0).  Passive: each revolute joint's angle from the radial
    direction to the leg.  Branch: platform above, every leg leaning inwards."""
    x, q, p = ca.SX.sym("x", 6), ca.SX.sym("q", 3), ca.SX.sym("p", 3)
    ra, rp = p[0], p[1]

    def legs(x):
        R = _yxz(x[3], x[4], x[5])
        out = []
        for g in LEGS:
            u = ca.DM([math.cos(g), math.sin(g), 0])
            out.append((ra * u, x[:3] + R @ (rp * u), u, ca.DM([-math.sin(g), math.cos(g), 0])))
        return out

    L = legs(x)
    res = [(ca.sumsqr(B - A) - q[i] ** 2) / (2 * ra) for i, (A, B, _u, _t) in enumerate(L)]
    res += [ca.dot(B, t) for _A, B, _u, t in L]
    phi = _fn("phi", [x, q, p], [ca.vertcat(*res)], ["x", "q", "p"], ["phi"])
    alpha = [ca.atan2(B[2] - A[2], ca.dot(B - A, u)) for A, B, u, _t in L]
    passive = _fn("passive", [x, q, p], [ca.vertcat(*alpha)], ["x", "q", "p"], ["j"])
    g = [x[2] / ra] + [ca.dot(A - B, u) / ra for A, B, u, _t in L]
    branch = _fn("branch", [x, q, p], [ca.vertcat(*g)], ["x", "q", "p"], ["g"])
    t = ca.SX.sym("t", 3)
    ph, px, py = _parasitic(t[1], t[2], rp)
    xt = ca.vertcat(px, py, t[0], t[1], t[2], ph)
    lengths = ca.vertcat(*[ca.norm_2(B - A) for A, B, _u, _t in legs(xt)])
    ik = _fn("ik", [t, p], [xt, lengths, ca.SX(1)], ["t", "p"], ["x", "q", "reach"])

    def home(pv):
        x0 = np.array([0, 0, pv[2], 0, 0, 0.0])
        return x0, np.asarray(ik([pv[2], 0, 0], pv)[1]).ravel()

    def bounds(pv):
        r = pv[0] + pv[1]
        lim = math.pi / 3
        return np.array([-r, -r, 0.0, -lim, -lim, -lim]), np.array([r, r, 3 * pv[2], lim, lim, lim])

    return LoopClosure(
        "rps3",
        x=SIX,
        q=tuple(Coordinate(f"l{i}", "length", f"leg {i} length", "l") for i in (1, 2, 3)),
        parameters=("ra", "rp", "h0"),
        phi=phi,
        task=("pz", "psi", "theta"),
        ik=ik,
        passive=passive,
        passive_coords=tuple(Coordinate(f"alpha{i}", "angle", f"revolute joint {i}", "alpha") for i in (1, 2, 3)),
        branch=branch,
        home=home,
        bounds=bounds,
    )


def rps3_model(closure: LoopClosure | None = None, limits=None, **params) -> Model:
    return _model(closure or rps3_closure(), RPS3, params, limits, lc=RPS3["rp"])


# -- planar 3-RRR --------------------------------------------------------------------------------

RRR3 = {"ra": 0.3, "rp": 0.08, "l1": 0.2, "l2": 0.2, "sigma1": 1.0, "sigma2": 1.0, "sigma3": 1.0}
RRR3_ANGLES = (math.pi / 2, math.pi / 2 + TWO_PI / 3, math.pi / 2 + 2 * TWO_PI / 3)


def rrr3_closure() -> LoopClosure:
    """x = (px, py, phi), q = (theta1..3); p = (ra, rp, l1, l2, sigma1..3), the σi
    choosing each leg's elbow (eight working modes)."""
    x, q, p = ca.SX.sym("x", 3), ca.SX.sym("q", 3), ca.SX.sym("p", 7)
    ra, rp, l1, l2 = (p[i] for i in range(4))
    sig = [p[4], p[5], p[6]]

    def points(x):
        return [
            (
                ra * ca.DM([math.cos(g), math.sin(g)]),
                x[:2] + rp * ca.vertcat(ca.cos(g + x[2]), ca.sin(g + x[2])),
            )
            for g in RRR3_ANGLES
        ]

    res, g = [], []
    for i, (A, C) in enumerate(points(x)):
        B = A + l1 * ca.vertcat(ca.cos(q[i]), ca.sin(q[i]))
        res.append((ca.sumsqr(C - B) - l2**2) / (2 * l2))
        g.append(-sig[i] * _cross2(B - A, C - B) / (l1 * l2))
    phi = _fn("phi", [x, q, p], [ca.vertcat(*res)], ["x", "q", "p"], ["phi"])
    branch = _fn("branch", [x, q, p], [ca.vertcat(*g)], ["x", "q", "p"], ["g"])
    t = ca.SX.sym("t", 3)
    th, reach = [], []
    for i, (A, C) in enumerate(points(t)):
        a, r = _dyad(C - A, l1, l2, sig[i])
        th.append(a)
        reach.append(r)
    ik = _fn("ik", [t, p], [t, ca.vertcat(*th), ca.mmin(ca.vertcat(*reach))], ["t", "p"], ["x", "q", "reach"])

    def home(pv):
        return np.zeros(3), np.asarray(ik(np.zeros(3), pv)[1]).ravel()

    def bounds(pv):
        return np.array([-pv[0], -pv[0], -math.pi]), np.array([pv[0], pv[0], math.pi])

    return LoopClosure(
        "rrr3",
        x=(
            Coordinate("px", "length", "platform centre, x"),
            Coordinate("py", "length", "platform centre, y"),
            Coordinate("phi", "angle", "platform rotation"),
        ),
        q=tuple(Coordinate(f"theta{i}", "angle", f"actuated base joint {i}", "theta") for i in (1, 2, 3)),
        parameters=("ra", "rp", "l1", "l2", "sigma1", "sigma2", "sigma3"),
        phi=phi,
        task=("px", "py", "phi"),
        ik=ik,
        branch=branch,
        home=home,
        bounds=bounds,
    )


def rrr3_model(closure: LoopClosure | None = None, limits=None, **params) -> Model:
    return _model(closure or rrr3_closure(), RRR3, params, limits, lc=RRR3["rp"])


# -- 6-UPS Stewart-Gough platform ---------------------------------------------------------------

STEWART = {"ra": 0.2, "rp": 0.12, "half_a": math.radians(10.0), "half_p": math.radians(10.0), "h0": 0.25}


def _hexagon(r, centres, half):
    pts = []
    for c in centres:
        for s in (-1.0, 1.0):
            a = c + s * half
            pts.append(ca.vertcat(r * ca.cos(a), r * ca.sin(a), 0))
    return pts


def stewart_closure() -> LoopClosure:
    """x = (px, py, pz, psi, theta, phi), R = Rz(φ) Ry(θ) Rx(ψ); q = leg lengths
    l1..6; p = (ra, rp, half_a, half_p, h0).  IK in closed form (the leg
    lengths); branch: platform above the base and not upside down (R_zz > 0).
    Search region: ψ, φ in [-π, π], θ in [-π/2, π/2] (every rotation once)."""
    x, q, p = ca.SX.sym("x", 6), ca.SX.sym("q", 6), ca.SX.sym("p", 5)
    ra, rp, half_a, half_p = (p[i] for i in range(4))
    rad = math.pi / 180.0
    A = _hexagon(ra, [0.0, 120 * rad, 240 * rad], half_a)
    Bp = _hexagon(rp, [60 * rad, 180 * rad, 300 * rad], half_p)
    Bp = Bp[-1:] + Bp[:-1]  # b_0 pairs with a_0

    def legs(x):
        R = _rz(x[5]) @ _ry(x[4]) @ _rx(x[3])
        return [x[:3] + R @ Bp[i] - A[i] for i in range(6)], R

    d, R = legs(x)
    res = ca.vertcat(*[(ca.sumsqr(d[i]) - q[i] ** 2) / (2 * ra) for i in range(6)])
    phi = _fn("phi", [x, q, p], [res], ["x", "q", "p"], ["phi"])
    branch = _fn("branch", [x, q, p], [ca.vertcat(x[2] / ra, R[2, 2])], ["x", "q", "p"], ["g"])
    t = ca.SX.sym("t", 6)
    dt, _R = legs(t)
    lengths = ca.vertcat(*[ca.norm_2(v) for v in dt])
    ik = _fn("ik", [t, p], [t, lengths, ca.mmin(lengths) / ra], ["t", "p"], ["x", "q", "reach"])

    def home(pv):
        x0 = np.array([0, 0, pv[4], 0, 0, 0.0])
        return x0, np.asarray(ik(x0, pv)[1]).ravel()

    def bounds(pv):
        r = pv[0] + pv[1]
        return (
            np.array([-r, -r, 0.0, -math.pi, -math.pi / 2, -math.pi]),
            np.array([r, r, 2 * pv[4] + r, math.pi, math.pi / 2, math.pi]),
        )

    xf, pf = ca.SX.sym("x", 6), ca.SX.sym("p", 5)
    frame = _fn("frame", [xf, pf], [_rz(xf[5]) @ _ry(xf[4]) @ _rx(xf[3]), xf[:3]], ["x", "p"], ["R", "position"])
    return LoopClosure(
        "stewart",
        frame=frame,
        x=SIX,
        q=tuple(Coordinate(f"l{i}", "length", f"leg {i} length", "l") for i in range(1, 7)),
        parameters=("ra", "rp", "half_a", "half_p", "h0"),
        phi=phi,
        task=("px", "py", "pz", "psi", "theta", "phi"),
        ik=ik,
        branch=branch,
        home=home,
        bounds=bounds,
    )


def stewart_model(closure: LoopClosure | None = None, limits=None, **params) -> Model:
    return _model(closure or stewart_closure(), STEWART, params, limits, lc=STEWART["rp"])


# -- 3-PRS with per-leg as-built geometry --------------------------------------------------------

AS_BUILT_PARAMETERS = (
    "b",
    "L",
    "alpha0",
    *(f"gamma{i}" for i in (1, 2, 3)),
    *(f"h{i}" for i in (1, 2, 3)),
    *(f"psi_c{i}" for i in (1, 2, 3)),
    *(f"theta_c{i}" for i in (1, 2, 3)),
    *(f"e{i}" for i in (1, 2, 3)),
)


def prs3_as_built_closure() -> LoopClosure:
    """The 3-PRS of prs3-ruiz.md with per-leg geometry (guide angle γi, base
    height hi, base tilts ψc_i, θc_i, actuator zero offset e_i; see
    tests/gallery_reference.AsBuiltPRS3).  No closed-form IK (the leg planes
    no longer pass through the axis); branch as the built-in prs3: each leg
    leans towards the axis and rises from slider to platform."""
    x, q, p = ca.SX.sym("x", 6), ca.SX.sym("q", 3), ca.SX.sym("p", len(AS_BUILT_PARAMETERS))
    P = dict(zip(AS_BUILT_PARAMETERS, [p[i] for i in range(p.size1())]))
    b, L, alpha0 = P["b"], P["L"], P["alpha0"]
    a = b + L * ca.cos(alpha0)
    R = _yxz(x[3], x[4], x[5])
    res_len, res_plane, g = [], [], []
    for i, beta in enumerate(LEGS, start=1):
        gam = P[f"gamma{i}"]
        Ri = _ry(P[f"theta_c{i}"]) @ _rx(P[f"psi_c{i}"])
        u = ca.vertcat(ca.cos(gam), ca.sin(gam), 0)
        A = (a + P[f"e{i}"]) * u + ca.vertcat(0, 0, P[f"h{i}"])
        s0 = Ri @ (-u)
        m = Ri @ ca.vertcat(ca.sin(gam), -ca.cos(gam), 0)
        B = x[:3] + R @ (b * ca.DM([math.cos(beta), math.sin(beta), 0]))
        dv = B - (A + q[i - 1] * s0)
        res_len.append((ca.sumsqr(dv) - L**2) / (2 * L))
        res_plane.append(ca.dot(dv, m))
        g += [ca.dot(dv, s0) / L, dv[2] / L]
    phi = _fn("phi", [x, q, p], [ca.vertcat(*res_len, *res_plane)], ["x", "q", "p"], ["phi"])
    branch = _fn("branch", [x, q, p], [ca.vertcat(*g)], ["x", "q", "p"], ["g"])

    def home(pv):
        return np.array([0, 0, pv[1] * math.sin(pv[2]), 0, 0, 0.0]), np.zeros(3)

    def bounds(pv):
        lim = math.pi / 3
        return np.array([-pv[1], -pv[1], 0.0, -lim, -lim, -lim]), np.array([pv[1], pv[1], 2 * pv[1], lim, lim, lim])

    return LoopClosure(
        "prs3_as_built",
        x=SIX,
        q=tuple(Coordinate(f"s{i}", "length", f"actuator {i}", "s") for i in (1, 2, 3)),
        parameters=AS_BUILT_PARAMETERS,
        phi=phi,
        task=("pz", "psi", "theta"),
        branch=branch,
        offsets={"dz": "pz"},
        home=home,
        bounds=bounds,
    )


def prs3_as_built_model(reference, closure: LoopClosure | None = None, limits=None) -> Model:
    """The model of a tests/gallery_reference.AsBuiltPRS3 geometry."""
    r = reference
    values = {"b": r.b, "L": r.L, "alpha0": r.alpha0}
    for i in range(3):
        values[f"gamma{i + 1}"] = r.gamma[i]
        values[f"h{i + 1}"] = r.heights[i]
        values[f"psi_c{i + 1}"] = r.tilts_psi[i]
        values[f"theta_c{i + 1}"] = r.tilts_theta[i]
        values[f"e{i + 1}"] = r.offsets[i]
    return Model(closure or prs3_as_built_closure(), values, limits=limits or {}, characteristic_length=r.b)
