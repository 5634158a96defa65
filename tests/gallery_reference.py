"""Independent references for the gallery of classic parallel mechanisms.

numpy only (no CasADi, nothing of cpm_nlp): closed-form or textbook forward
and inverse kinematics, written from the sources cited beside each, so that
hand-written LoopClosures (tests/gallery_closures.py) and mechanism files can
be checked against something they do not share code with.  Where a source
gives no closed form, the reference solves its own equations by a plain
Newton iteration with a finite-difference Jacobian (:func:`newton`).

Conventions (SI, radians):

* rotations: ``rot_x``, ``rot_y``, ``rot_z`` are the elementary rotations;
  the 3-RPS and 3-PRS use R = Ry(θ) Rx(ψ) Rz(φ) (prs3-ruiz.md eq 4), the
  6-UPS R = Rz(φ) Ry(θ) Rx(ψ) (roll-pitch-yaw);
* every ``ik_*`` returns the actuator values, every ``fk_*`` the pose; a
  pose that cannot be assembled raises :class:`Unreachable`.

Each mechanism has ``selftest_*``, run by tests/mechanisms/described/test_gallery.py:
round trips FK(IK(t)) = t, known poses, and the closure equations at the
returned poses.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

TWO_PI = 2.0 * math.pi
LEG_ANGLES = (0.0, TWO_PI / 3.0, 2.0 * TWO_PI / 3.0)


class Unreachable(ValueError):
    """The pose (or actuator vector) cannot be assembled."""


def rot_x(t: float) -> np.ndarray:
    c, s = math.cos(t), math.sin(t)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def rot_y(t: float) -> np.ndarray:
    c, s = math.cos(t), math.sin(t)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def rot_z(t: float) -> np.ndarray:
    c, s = math.cos(t), math.sin(t)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def newton(f, x0, tol: float = 1e-13, max_iter: int = 60, h: float = 1e-7) -> np.ndarray:
    """Plain Newton on f(x) = 0 with a central-difference Jacobian; raises
    :class:`Unreachable` when it does not converge."""
    x = np.array(x0, dtype=float)
    for _ in range(max_iter):
        r = np.asarray(f(x), dtype=float)
        if np.max(np.abs(r)) < tol:
            return x
        J = np.empty((r.size, x.size))
        for k in range(x.size):
            e = np.zeros_like(x)
            e[k] = h
            J[:, k] = (np.asarray(f(x + e)) - np.asarray(f(x - e))) / (2 * h)
        x = x - np.linalg.lstsq(J, r, rcond=None)[0]
    r = np.asarray(f(x), dtype=float)
    if np.max(np.abs(r)) < 1e3 * tol:
        return x
    raise Unreachable(f"Newton did not converge (max |f| = {np.max(np.abs(r)):.3g})")


def elbow_angle(v: np.ndarray, l1: float, l2: float, sign: float) -> float:
    """Angle of the first link of a planar RR dyad from its base to a point at
    offset v (law of cosines; sign +1 / -1 picks the elbow):

        θ = atan2(v_y, v_x) + sign * acos((|v|² + l1² - l2²) / (2 l1 |v|)).
    """
    r = math.hypot(v[0], v[1])
    c = (r * r + l1 * l1 - l2 * l2) / (2 * l1 * r)
    if not -1.0 <= c <= 1.0:
        raise Unreachable(f"the dyad cannot reach a point at distance {r:.6g} (l1 = {l1}, l2 = {l2})")
    return math.atan2(v[1], v[0]) + sign * math.acos(c)


def circle_intersections(c1: np.ndarray, c2: np.ndarray, r: float) -> tuple[np.ndarray, np.ndarray]:
    """The two points at distance r from both c1 and c2 (planar): M ± h n with
    M the midpoint, h = sqrt(r² - |c2 - c1|²/4), n the left normal of c2 - c1.
    The first is to the left of c1 -> c2."""
    d = c2 - c1
    dist = float(np.hypot(*d))
    h2 = r * r - dist * dist / 4.0
    if h2 < 0 or dist == 0:
        raise Unreachable("the circles do not meet")
    n = np.array([-d[1], d[0]]) / dist
    m = (c1 + c2) / 2.0
    h = math.sqrt(h2)
    return m + h * n, m - h * n


# -- planar five-bar (2-RRRRR) --------------------------------------------------------------------


@dataclass(frozen=True)
class FiveBar:
    """Planar five-bar: base joints A1 = (-d/2, 0), A2 = (d/2, 0), actuated
    angles θ1, θ2 of the proximal links l1 (from the x axis), distal links l2
    meeting at the end point P = (x, y).

    Source: Liu, Wang, Pritschow 2006 ("On the optimal kinematic design of the
    PRRRP 2-DoF parallel mechanism"), and Merlet, *Parallel Robots* (2nd ed.,
    2006), §4.2 (planar 2-dof mechanisms).  IK: each leg is an RR dyad, the law
    of cosines (:func:`elbow_angle`), σi = ±1 per leg: the four working modes.
    FK: B_i = A_i + l1 (cos θi, sin θi), P on both circles of radius l2 about
    B_i (:func:`circle_intersections`): two assembly modes, "up" (left of B1 -> B2)
    and "down".
    """

    d: float = 0.2
    l1: float = 0.25
    l2: float = 0.3

    def base(self) -> tuple[np.ndarray, np.ndarray]:
        return np.array([-self.d / 2, 0.0]), np.array([self.d / 2, 0.0])

    def ik(self, p, signs=(1.0, -1.0)) -> np.ndarray:
        """θ1, θ2 for the end point p; signs (σ1, σ2) choose the working mode
        ((+1, -1): both elbows outwards, the usual one)."""
        a1, a2 = self.base()
        p = np.asarray(p, dtype=float)
        return np.array(
            [elbow_angle(p - a1, self.l1, self.l2, signs[0]), elbow_angle(p - a2, self.l1, self.l2, signs[1])]
        )

    def elbows(self, theta) -> tuple[np.ndarray, np.ndarray]:
        a1, a2 = self.base()
        return (
            a1 + self.l1 * np.array([math.cos(theta[0]), math.sin(theta[0])]),
            a2 + self.l1 * np.array([math.cos(theta[1]), math.sin(theta[1])]),
        )

    def fk(self, theta) -> tuple[np.ndarray, np.ndarray]:
        """Both assembly modes (up, down) of the end point."""
        b1, b2 = self.elbows(theta)
        return circle_intersections(b1, b2, self.l2)

    def jacobian(self, p, theta) -> np.ndarray:
        """dP/dθ from A dP = B dθ, differentiating |P - B_i|² = l2²:
        (P - B_i)·dP = (P - B_i)·(dB_i/dθi) dθi."""
        b = self.elbows(theta)
        A = np.array([p - b[0], p - b[1]])
        db = [self.l1 * np.array([-math.sin(t), math.cos(t)]) for t in theta]
        B = np.diag([float(A[0] @ db[0]), float(A[1] @ db[1])])
        return np.linalg.solve(A, B)

    def residual(self, p, theta) -> np.ndarray:
        return np.array([np.hypot(*(p - b)) - self.l2 for b in self.elbows(theta)])


def selftest_five_bar() -> None:
    m = FiveBar()
    p = np.array([0.03, 0.35])
    for s1 in (1.0, -1.0):
        for s2 in (1.0, -1.0):
            th = m.ik(p, (s1, s2))
            assert np.max(np.abs(m.residual(p, th))) < 1e-14
            up, down = m.fk(th)
            assert min(np.linalg.norm(up - p), np.linalg.norm(down - p)) < 1e-12
    # symmetric pose: the elbows-out working mode is mirror symmetric, θ2 = π - θ1
    th = m.ik([0.0, 0.35])
    assert abs(th[1] - (math.pi - th[0])) < 1e-14
    # Jacobian against central differences of the FK (up mode)
    th = m.ik(p)
    J = m.jacobian(p, th)
    h = 1e-7
    for k in range(2):
        e = np.zeros(2)
        e[k] = h
        num = (m.fk(th + e)[0] - m.fk(th - e)[0]) / (2 * h)
        assert np.allclose(J[:, k], num, atol=1e-7)


# -- Delta robot (Clavel) ------------------------------------------------------------------------


@dataclass(frozen=True)
class Delta:
    """Clavel's Delta robot: three arms of length ``la`` driven by revolute
    actuators on a base triangle (joint axes at radius ``rb``, legs at 0°, 120°,
    240°), forearms of length ``lb`` (parallelograms: the platform only
    translates), platform joints at radius ``rp``.  P = (x, y, z), z < 0 below
    the base.  θi = 0 is a horizontal arm, positive downwards.

    Source: R. Clavel, *Conception d'un robot parallèle rapide à 4 degrés de
    liberté*, EPFL thesis 1991; the closed forms as in R. L. Williams II,
    "The Delta Parallel Robot: Kinematics Solutions" (Ohio University, 2016).
    Derivation (leg i in its own frame, rotated by -γi about z, P' = (x', y', z)):
    elbow J = (rb + la cos θ, 0, -la sin θ); forearm end P' + (rp, 0, 0);
    |P' + (rp, 0, 0) - J|² = lb² is E cos θ + F sin θ + G = 0 with
    X = x' + rp - rb, E = -2 la X, F = 2 la z, G = X² + y'² + z² + la² - lb²;
    with t = tan(θ/2): (G - E) t² + 2 F t + (G + E) = 0, so
    t = (-F - sqrt(E² + F² - G²)) / (G - E) (the knee-out root).
    FK: the three spheres of radius lb about J_i - rp u_i meet in two points
    (trilateration); the robot hangs below, the lower one.
    """

    rb: float = 0.1
    rp: float = 0.03
    la: float = 0.1
    lb: float = 0.25

    def ik(self, p) -> np.ndarray:
        th = []
        for g in LEG_ANGLES:
            xl, yl, z = rot_z(-g) @ np.asarray(p, dtype=float)
            X = xl + self.rp - self.rb
            E, F = -2 * self.la * X, 2 * self.la * z
            G = X * X + yl * yl + z * z + self.la**2 - self.lb**2
            disc = E * E + F * F - G * G
            if disc < 0:
                raise Unreachable("a forearm cannot reach its platform joint")
            t = (-F - math.sqrt(disc)) / (G - E)
            th.append(2 * math.atan(t))
        return np.array(th)

    def sphere_centres(self, theta) -> list[np.ndarray]:
        out = []
        for g, t in zip(LEG_ANGLES, theta):
            local = np.array([self.rb + self.la * math.cos(t) - self.rp, 0.0, -self.la * math.sin(t)])
            out.append(rot_z(g) @ local)
        return out

    def fk(self, theta) -> np.ndarray:
        """The lower intersection of the three spheres (trilateration)."""
        c1, c2, c3 = self.sphere_centres(theta)
        ex = (c2 - c1) / np.linalg.norm(c2 - c1)
        i = ex @ (c3 - c1)
        ey = c3 - c1 - i * ex
        ey /= np.linalg.norm(ey)
        ez = np.cross(ex, ey)
        d = np.linalg.norm(c2 - c1)
        j = ey @ (c3 - c1)
        r = self.lb
        x = d / 2
        y = (i * i + j * j) / (2 * j) - i * x / j
        z2 = r * r - x * x - y * y
        if z2 < 0:
            raise Unreachable("the forearms cannot meet")
        sols = [c1 + x * ex + y * ey + s * math.sqrt(z2) * ez for s in (1.0, -1.0)]
        return min(sols, key=lambda s: s[2])

    def residual(self, p, theta) -> np.ndarray:
        return np.array([np.linalg.norm(np.asarray(p) - c) - self.lb for c in self.sphere_centres(theta)])


def selftest_delta() -> None:
    m = Delta()
    # known pose: with θ = 0 (arms horizontal) the platform hangs at z = -sqrt(lb² - (rb + la - rp)²)
    p0 = m.fk(np.zeros(3))
    assert np.allclose(p0[:2], 0.0, atol=1e-14)
    assert abs(p0[2] + math.sqrt(m.lb**2 - (m.rb + m.la - m.rp) ** 2)) < 1e-14
    assert np.allclose(m.ik(p0), 0.0, atol=1e-12)
    rng = np.random.default_rng(3)
    for _ in range(20):
        p = p0 + rng.uniform(-0.04, 0.04, 3)
        th = m.ik(p)
        assert np.max(np.abs(m.residual(p, th))) < 1e-14
        assert np.allclose(m.fk(th), p, atol=1e-12)


# -- 3-RPS (Lee and Shah) ------------------------------------------------------------------------


def tilt_parasitics(psi: float, theta: float, rp: float) -> tuple[float, float, float]:
    """(φ, px, py) of a platform whose three joints at radius rp (legs at 0°,
    120°, 240°) stay in the vertical planes through the z axis and their leg:
    prs3-ruiz.md eq 13-15 (R = Ry(θ) Rx(ψ) Rz(φ)); the same constraint holds for
    the 3-RPS (Lee and Shah 1988, eq 6-8)."""
    phi = math.atan(math.sin(psi) * math.sin(theta) / (math.cos(psi) + math.cos(theta)))
    cps, sps, cth, sth = math.cos(psi), math.sin(psi), math.cos(theta), math.sin(theta)
    px = rp / 2 * (cth * math.cos(phi) + sps * sth * math.sin(phi) - cps * math.cos(phi))
    py = -rp * math.cos(psi) * math.sin(phi)
    return phi, px, py


def rotation_yxz(psi: float, theta: float, phi: float) -> np.ndarray:
    """R = Ry(θ) Rx(ψ) Rz(φ) (prs3-ruiz.md eq 4)."""
    return rot_y(theta) @ rot_x(psi) @ rot_z(phi)


@dataclass(frozen=True)
class RPS3:
    """3-RPS: revolute joints A_i on the base at radius ra (axes tangential),
    prismatic legs of length q_i (actuated), spherical joints B_i on the
    platform at radius rp; legs at 0°, 120°, 240°.  Each leg stays in the
    vertical plane through the z axis and A_i.  Pose (px, py, pz, ψ, θ, φ),
    task (pz, ψ, θ).

    Source: K.-M. Lee and D. K. Shah, "Kinematic analysis of a three-degrees-
    of-freedom in-parallel actuated manipulator", IEEE J. Robotics and
    Automation 4(3), 1988: IK in closed form (the parasitic motions from the
    leg-plane constraints, :func:`tilt_parasitics`, then q_i = |B_i - A_i|);
    FK by Newton on the six equations (Lee and Shah solve it numerically too).
    """

    ra: float = 0.1
    rp: float = 0.06

    def joints(self, x) -> list[np.ndarray]:
        R = rotation_yxz(x[3], x[4], x[5])
        return [np.asarray(x[:3]) + R @ (self.rp * np.array([math.cos(g), math.sin(g), 0.0])) for g in LEG_ANGLES]

    def base(self) -> list[np.ndarray]:
        return [self.ra * np.array([math.cos(g), math.sin(g), 0.0]) for g in LEG_ANGLES]

    def pose(self, t) -> np.ndarray:
        pz, psi, theta = t
        phi, px, py = tilt_parasitics(psi, theta, self.rp)
        return np.array([px, py, pz, psi, theta, phi])

    def ik(self, t) -> np.ndarray:
        x = self.pose(t)
        return np.array([np.linalg.norm(b - a) for a, b in zip(self.base(), self.joints(x))])

    def equations(self, x, q) -> np.ndarray:
        out = [np.linalg.norm(b - a) - qi for a, b, qi in zip(self.base(), self.joints(x), q)]
        out += [b @ np.array([-math.sin(g), math.cos(g), 0.0]) for g, b in zip(LEG_ANGLES, self.joints(x))]
        return np.array(out)

    def fk(self, q, guess) -> np.ndarray:
        return newton(lambda x: self.equations(x, q), guess)


def selftest_rps3() -> None:
    m = RPS3()
    t = np.array([0.12, 0.05, -0.08])
    x = m.pose(t)
    q = m.ik(t)
    assert np.max(np.abs(m.equations(x, q))) < 1e-15  # the parasitic formulas keep B_i in the leg planes
    home = m.pose([0.12, 0.0, 0.0])
    assert np.allclose(home[[0, 1, 3, 4, 5]], 0.0)
    assert np.allclose(m.ik([0.12, 0, 0]), math.hypot(0.12, m.ra - m.rp))  # known pose: level platform
    assert np.allclose(m.fk(q, home), x, atol=1e-12)


# -- planar 3-RRR --------------------------------------------------------------------------------


@dataclass(frozen=True)
class RRR3:
    """Planar 3-RRR: actuated base joints A_i on a circle of radius ra (at 90°,
    210°, 330°), proximal links l1, distal links l2, platform joints C_i at
    radius rp on the platform (same angles, rotated by φ); pose (x, y, φ).

    Source: C. Gosselin and J. Angeles, "The optimum kinematic design of a
    planar three-degree-of-freedom parallel manipulator", ASME J. Mech. Trans.
    Autom. Des. 110, 1988; Merlet, *Parallel Robots* §4.3.  IK: each leg an RR
    dyad (:func:`elbow_angle`, σi = ±1: eight working modes).  FK: up to six
    assembly modes (a sextic); here Newton on the three closures (round trip).
    """

    ra: float = 0.3
    rp: float = 0.08
    l1: float = 0.2
    l2: float = 0.2
    angles: tuple[float, float, float] = (math.pi / 2, math.pi / 2 + TWO_PI / 3, math.pi / 2 + 2 * TWO_PI / 3)

    def base(self) -> list[np.ndarray]:
        return [self.ra * np.array([math.cos(g), math.sin(g)]) for g in self.angles]

    def platform(self, x) -> list[np.ndarray]:
        return [np.asarray(x[:2]) + self.rp * np.array([math.cos(g + x[2]), math.sin(g + x[2])]) for g in self.angles]

    def ik(self, x, signs=(1.0, 1.0, 1.0)) -> np.ndarray:
        return np.array(
            [elbow_angle(c - a, self.l1, self.l2, s) for a, c, s in zip(self.base(), self.platform(x), signs)]
        )

    def equations(self, x, theta) -> np.ndarray:
        out = []
        for a, c, t in zip(self.base(), self.platform(x), theta):
            b = a + self.l1 * np.array([math.cos(t), math.sin(t)])
            out.append(np.hypot(*(c - b)) - self.l2)
        return np.array(out)

    def fk(self, theta, guess) -> np.ndarray:
        return newton(lambda x: self.equations(x, theta), guess)


def selftest_rrr3() -> None:
    m = RRR3()
    x = np.array([0.01, -0.02, 0.1])
    for signs in ((1, 1, 1), (-1, -1, -1), (1, -1, 1)):
        th = m.ik(x, signs)
        assert np.max(np.abs(m.equations(x, th))) < 1e-15
        assert np.allclose(m.fk(th, x + 0.003), x, atol=1e-12)
    # known pose: centred and unrotated, the legs are symmetric (θ_i - angle_i equal for all legs)
    th = m.ik([0.0, 0.0, 0.0])
    rel = (th - np.array(m.angles) + math.pi) % TWO_PI - math.pi
    assert np.allclose(rel, rel[0], atol=1e-14)


# -- 6-UPS Stewart-Gough platform ---------------------------------------------------------------


def _hexagon(radius: float, centre_deg: tuple[float, ...], half_deg: float) -> np.ndarray:
    pts = []
    for c in centre_deg:
        for s in (-1.0, 1.0):
            a = math.radians(c + s * half_deg)
            pts.append([radius * math.cos(a), radius * math.sin(a), 0.0])
    return np.array(pts)


@dataclass(frozen=True)
class Stewart:
    """6-UPS Stewart-Gough platform: base joints a_i at radius ra (pairs about
    0°, 120°, 240°, ± half_a), platform joints b_i at radius rp (pairs about
    60°, 180°, 300°, ± half_p, leg i joining a_i to the nearest b), leg lengths
    l_i actuated.  Pose (px, py, pz, ψ, θ, φ), R = Rz(φ) Ry(θ) Rx(ψ).

    Source: D. Stewart 1965; Merlet, *Parallel Robots* §4.1 and §5.1: IK
    l_i = |P + R b_i - a_i| (closed form); FK has up to 40 complex solutions
    (Husty 1996, Dietmaier 1998: 40 real ones exist); here Newton on the
    leg lengths (round trip).
    """

    ra: float = 0.2
    rp: float = 0.12
    half_a: float = 10.0
    half_p: float = 10.0

    def base(self) -> np.ndarray:
        return _hexagon(self.ra, (0.0, 120.0, 240.0), self.half_a)

    def platform_points(self) -> np.ndarray:
        pts = _hexagon(self.rp, (60.0, 180.0, 300.0), self.half_p)
        return np.roll(pts, 1, axis=0)  # b_0 pairs with a_0 (nearest neighbours across the hexagons)

    def rotation(self, x) -> np.ndarray:
        return rot_z(x[5]) @ rot_y(x[4]) @ rot_x(x[3])

    def ik(self, x) -> np.ndarray:
        R = self.rotation(x)
        P = np.asarray(x[:3], dtype=float)
        return np.linalg.norm(P + self.platform_points() @ R.T - self.base(), axis=1)

    def fk(self, lengths, guess) -> np.ndarray:
        return newton(lambda x: self.ik(x) - lengths, guess)


def selftest_stewart() -> None:
    m = Stewart()
    x = np.array([0.005, -0.01, 0.25, 0.05, -0.03, 0.08])
    lengths = m.ik(x)
    home = np.array([0, 0, 0.25, 0, 0, 0])
    assert np.allclose(m.fk(lengths, home), x, atol=1e-12)
    # known pose: a level, centred platform has six equal legs (3-fold and mirror symmetry)
    l0 = m.ik(home)
    assert np.allclose(l0, l0[0], atol=1e-15)
    # yaw about the axis by φ keeps the legs pairwise equal (mirror symmetry breaks, 3-fold stays)
    ly = m.ik([0, 0, 0.25, 0, 0, 0.1])
    assert np.allclose(ly[0::2], ly[0], atol=1e-15) and np.allclose(ly[1::2], ly[1], atol=1e-15)


# -- 3-PRS with as-built geometry (prs3-ruiz.md Table 3) ----------------------------------------


def dms(deg: int, minutes: int, seconds: float, sign: float = 1.0) -> float:
    """An angle in degrees, minutes, seconds (Table 3's notation), in radians."""
    return sign * math.radians(deg + minutes / 60.0 + seconds / 3600.0)


@dataclass(frozen=True)
class AsBuiltPRS3:
    """3-PRS (prs3-ruiz.md) with per-leg geometry: guide angles γ_i, base
    heights h_i (offset of the slider line above the nominal actuator plane),
    base tilts (ψc_i about x, θc_i about y) that tilt the guide direction and
    the revolute axis, and actuator zero offsets e_i along the guide.

    The nominal model is the paper's (section 4; a = b + L cos α0): with every
    deviation zero this reference equals eq 13-15 and eq 20.  Per leg:

        A_i = (a + e_i) (cos γ_i, sin γ_i, 0) + (0, 0, h_i)
        s_i0 = R_i (-cos γ_i, -sin γ_i, 0),   m_i = R_i (sin γ_i, -cos γ_i, 0),   R_i = Ry(θc_i) Rx(ψc_i)
        C_i = A_i + s_i s_i0                       (eq A.2)
        B_i = P + R b (cos β_i, sin β_i, 0)        (eq 5-6, platform joints at the nominal 0°, 120°, 240°)
        |B_i - C_i| = L,   (B_i - C_i) · m_i = 0   (eq 35 and the leg plane, eq 7-9)

    IK for the task (pz, ψ, θ): px, py, φ from the three leg-plane equations
    by Newton (no closed form once the planes are not through the axis), then
    s_i = k - sqrt(k² - |AB|² + L²) with k = s_i0 · AB restricted to the leg
    plane (eq 20, minus root).  FK: Newton on the six equations.
    """

    b: float = 47.91e-3
    L: float = 109.215e-3
    alpha0: float = math.pi / 4
    gamma: tuple[float, float, float] = LEG_ANGLES
    heights: tuple[float, float, float] = (0.0, 0.0, 0.0)
    tilts_psi: tuple[float, float, float] = (0.0, 0.0, 0.0)
    tilts_theta: tuple[float, float, float] = (0.0, 0.0, 0.0)
    offsets: tuple[float, float, float] = (0.0, 0.0, 0.0)
    platform_angles: tuple[float, float, float] = field(default=LEG_ANGLES)

    @property
    def a(self) -> float:
        return self.b + self.L * math.cos(self.alpha0)

    def leg(self, i: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(A_i, s_i0, m_i)."""
        g = self.gamma[i]
        Ri = rot_y(self.tilts_theta[i]) @ rot_x(self.tilts_psi[i])
        A = (self.a + self.offsets[i]) * np.array([math.cos(g), math.sin(g), 0.0]) + np.array([0, 0, self.heights[i]])
        return A, Ri @ np.array([-math.cos(g), -math.sin(g), 0.0]), Ri @ np.array([math.sin(g), -math.cos(g), 0.0])

    def joints(self, x) -> list[np.ndarray]:
        R = rotation_yxz(x[3], x[4], x[5])
        return [
            np.asarray(x[:3]) + R @ (self.b * np.array([math.cos(g), math.sin(g), 0.0])) for g in self.platform_angles
        ]

    def equations(self, x, s) -> np.ndarray:
        legs, planes = [], []
        for i, B in enumerate(self.joints(x)):
            A, s0, m = self.leg(i)
            d = B - (A + s[i] * s0)
            legs.append(np.linalg.norm(d) - self.L)
            planes.append(d @ m)
        return np.array(legs + planes)

    def ik(self, t, guess=None) -> tuple[np.ndarray, np.ndarray]:
        """(x, s) for the task (pz, ψ, θ)."""
        pz, psi, theta = t
        phi0, px0, py0 = tilt_parasitics(psi, theta, self.b)
        g0 = np.array([px0, py0, phi0]) if guess is None else np.asarray(guess, dtype=float)

        def planes(v):
            x = np.array([v[0], v[1], pz, psi, theta, v[2]])
            return np.array([(B - self.leg(i)[0]) @ self.leg(i)[2] for i, B in enumerate(self.joints(x))])

        v = newton(planes, g0)
        x = np.array([v[0], v[1], pz, psi, theta, v[2]])
        s = []
        for i, B in enumerate(self.joints(x)):
            A, s0, _m = self.leg(i)
            AB = B - A
            k = s0 @ AB
            disc = k * k - AB @ AB + self.L**2
            if disc < 0:
                raise Unreachable(f"leg {i + 1} cannot reach its platform joint")
            s.append(k - math.sqrt(disc))
        return x, np.array(s)

    def fk(self, s, guess) -> np.ndarray:
        return newton(lambda x: self.equations(x, s), guess)

    def home(self) -> np.ndarray:
        return np.array([0.0, 0.0, self.L * math.sin(self.alpha0), 0.0, 0.0, 0.0])


def table3() -> AsBuiltPRS3:
    """The prototype of prs3-ruiz.md Table 3 (section 6.1), read as follows:

    * guides: the measured angles between OA1-OA2 (120° - 0°5'24") and OA2-OA3
      (120° - 0°1'12") place guides 2 and 3 with guide 1 at 0°; the third
      angle (OA3-OA1, 120° + 0°3'0") does not close the circle with the other
      two (their sum is 359°56'24"), so it is not used: γ3 follows as
      240° - 0°6'36" (OA3-OA1 = 120° + 0°6'36");
    * bases C1-C3: height errors -0.080, -0.343, +0.338 mm (h_i, offsets of the
      slider lines from the nominal plane) and tilt errors ψ (about x) and θ
      (about y) of each base, which tilt its guide and revolute axis;
    * actuators: the plane A_i errors +0.069, +0.069, +0.265 mm, read as
      offsets of the actuator zero positions A_i along the outward radial
      direction (e_i; Table 3 gives no sign convention).
    The leg and platform errors of Table 3 are results of the assembly (heights
    of the assembled prototype), not parameters, and are not used.
    """
    g2 = math.radians(120.0) + dms(0, 5, 24, -1.0)
    g3 = g2 + math.radians(120.0) + dms(0, 1, 12, -1.0)
    return AsBuiltPRS3(
        gamma=(0.0, g2, g3),
        heights=(-0.080e-3, -0.343e-3, 0.338e-3),
        tilts_psi=(dms(0, 0, 3, -1.0), dms(0, 23, 49), dms(0, 17, 34)),
        tilts_theta=(dms(0, 0, 10, -1.0), dms(0, 9, 21, -1.0), dms(0, 15, 25)),
        offsets=(0.069e-3, 0.069e-3, 0.265e-3),
    )


def prs3_nominal_ik(t, b=47.91e-3, L=109.215e-3, alpha0=math.pi / 4) -> tuple[np.ndarray, np.ndarray]:
    """The paper's closed-form IK: x from eq 13-15, s from eq 20 (minus root)."""
    pz, psi, theta = t
    phi, px, py = tilt_parasitics(psi, theta, b)
    x = np.array([px, py, pz, psi, theta, phi])
    a = b + L * math.cos(alpha0)
    R = rotation_yxz(psi, theta, phi)
    s = []
    for g in LEG_ANGLES:
        u = np.array([math.cos(g), math.sin(g), 0.0])
        AB = np.array([px, py, pz]) + R @ (b * u) - a * u  # eq 16
        k = -u @ AB
        s.append(k - math.sqrt(k * k - AB @ AB + L * L))  # eq 20
    return x, np.array(s)


def selftest_prs3_as_built() -> None:
    t = np.array([77.3e-3, 0.01, -0.015])
    x0, s0 = prs3_nominal_ik(t)
    xn, sn = AsBuiltPRS3().ik(t)  # no deviations: the paper's closed form
    assert np.allclose(xn, x0, atol=1e-14) and np.allclose(sn, s0, atol=1e-14)
    m = table3()
    x, s = m.ik(t)
    assert np.max(np.abs(m.equations(x, s))) < 1e-14
    assert np.allclose(m.fk(s, m.home()), x, atol=1e-12)
    # the as-built geometry moves the actuators by the order of the deviations (a fraction of a mm)
    assert 1e-5 < np.max(np.abs(s - s0)) < 2e-3
