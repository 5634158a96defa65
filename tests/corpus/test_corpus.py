"""The external corpus (issue 20, item 6): published mechanisms that nobody in this project
designed, each written as a mechanism file (tests/corpus/<name>.yaml) from its source's
numbers, loaded as a user would (``cn.load_problem`` on the problem files in
tests/corpus/problems/, ``load_file`` for the Python API), and compared with

* the values the source prints, with the source and the tolerance (and its reason) beside
  each: Williams's Delta examples, Pyslvs's own test values;
* an independent model written here in numpy from the source's geometry (closed forms or
  chained circle intersections, nothing of cpm_nlp), where the source prints no output: these
  are labelled "derived here", never "published";
* FK against IK (the IK of the FK pose returns the actuators), and the assembly modes of
  ``assembly_modes: all`` against the numpy model's.

tests/corpus/README.md lists each mechanism, its source and what is pinned.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import cpm_nlp as cn
from cpm_nlp.core.result import Status
from cpm_nlp.mechanisms.described import load_file

CORPUS = Path(__file__).resolve().parent
PROBLEMS = CORPUS / "problems"
NEWTON = cn.SolverConfig("newton")
MM = 1e-3
DEG = math.pi / 180


def _model(name: str, parameters: dict | None = None):
    mech = load_file(CORPUS / f"{name}.yaml")
    return mech.model(mech.closure(), parameters or {}, {}, ())


def _solve(problem: str, *overrides: str):
    result = cn.solve(cn.load_problem(PROBLEMS / problem, list(overrides)))
    assert result.status == Status.SOLVED, result.message
    return result.values


def _wrap(a):
    return (np.asarray(a) + math.pi) % (2 * math.pi) - math.pi


def _fk_ik_round_trip(model, q, tol_q, *, unique=True):
    """FK of q, then IK of the FK pose's task coordinates: the actuators come back
    (``unique``), or -- for a one-dof crank linkage whose output takes each value at two crank
    angles -- the IK's actuators give, by FK, the same task coordinates and the IK's pose."""
    fk = cn.forward_kinematics(model, q, NEWTON)
    assert fk.status == Status.SOLVED, fk.message
    t = np.asarray(fk.x)[model.closure.task_index]
    ik = cn.inverse_kinematics(model, t)
    assert ik.status == Status.SOLVED, ik.message
    if unique:
        np.testing.assert_allclose(_wrap(np.asarray(ik.q) - np.asarray(q)), 0.0, atol=tol_q)
    else:
        back = cn.forward_kinematics(model, ik.q, NEWTON, guess=ik.x)
        assert back.status == Status.SOLVED, back.message
        np.testing.assert_allclose(_wrap(np.asarray(back.x) - np.asarray(ik.x)), 0.0, atol=tol_q)
        np.testing.assert_allclose(_wrap(np.asarray(back.x)[model.closure.task_index] - t), 0.0, atol=tol_q)
    return fk


def _passive_index(model, name):
    return [c.name for c in model.closure.passive_coords].index(name)


def _circle(c1, r1, c2, r2, side):
    """The intersection of the circles (c1, r1) and (c2, r2) left (side +1) or right (-1) of c1 -> c2."""
    c1, c2 = np.asarray(c1, float), np.asarray(c2, float)
    d = c2 - c1
    dist = math.hypot(*d)
    a = (r1 * r1 - r2 * r2 + dist * dist) / (2 * dist)
    h = math.sqrt(r1 * r1 - a * a)
    return c1 + a * d / dist + side * h * np.array([-d[1], d[0]]) / dist


def _cross(a, b):
    return a[0] * b[1] - a[1] * b[0]


# -- Delta robot: R. L. Williams II, "The Delta Parallel Robot: Kinematics Solutions", 2016 ------
# ABB FlexPicker IRB 360-1/1600: sB = 0.567, sP = 0.076, L = 0.524, l = 1.244 m (p. 4 and p. 16)

SB, SP, L_UP, L_LOW = 0.567, 0.076, 0.524, 1.244
WB, UP = math.sqrt(3) / 6 * SB, math.sqrt(3) / 3 * SP
#: legs 1, 2, 3 radial at -90, 30, 150 deg (Williams p. 10: B_1 = (0, -wB, 0))
DELTA_LEGS = (-math.pi / 2, math.pi / 6, 5 * math.pi / 6)


def _williams_ipk(p):
    """Williams's IPK (p. 13-14) in numpy: per leg E cos(theta) + F sin(theta) + G = 0 (the
    knee point at wB + L (cos theta, -sin theta) along the leg's radial e_i, the platform vertex
    P + uP e_i, |knee - vertex| = l); the root of the "kinked out" knee is the one with the
    knee outside the base circle at these poses (the larger cos)."""
    out = []
    for g in DELTA_LEGS:
        e = np.array([math.cos(g), math.sin(g), 0.0])
        w = np.asarray(p, float) + (UP - WB) * e
        E, F, G = -2 * L_UP * (w @ e), 2 * L_UP * w[2], w @ w + L_UP**2 - L_LOW**2
        r, base = math.hypot(E, F), math.atan2(F, E)
        roots = [base + math.acos(-G / r), base - math.acos(-G / r)]
        out.append(max(roots, key=math.cos))
    return np.array(_wrap(out))


@pytest.fixture(scope="module")
def delta():
    return _model("delta_williams")


def test_delta_williams_ipk_snapshots():
    """Williams p. 16, IPK snapshot examples ("the preferred kinked out solution"):
    P = (0, 0, -0.9) m -> (-20.5, -20.5, -20.5) deg and P = (0.3, 0.5, -1.1) m -> (47.5, -11.6,
    21.4) deg, printed to 0.1 deg: tolerance 0.05 deg, the rounding of the print.  Measured:
    0.047 deg and 0.032 deg.  The same angles from Williams's E cos + F sin + G = 0 in numpy to
    1e-9 rad.  (The PDF's text layer drops the minus signs; the signs are read from the
    z < 0 platform below the base and match this closed form.)"""
    general = _solve("delta_williams_ik.yaml")
    nominal = _solve("delta_williams_ik.yaml", "inputs.x=0 m", "inputs.y=0 m", "inputs.z=-0.9 m")
    for values, p, printed in (
        (nominal, (0.0, 0.0, -0.9), (-20.5, -20.5, -20.5)),
        (general, (0.3, 0.5, -1.1), (47.5, -11.6, 21.4)),
    ):
        q = np.array([values[f"theta{i}"] for i in (1, 2, 3)])
        np.testing.assert_allclose(q / DEG, printed, rtol=0, atol=0.05)
        np.testing.assert_allclose(q, _williams_ipk(p), rtol=0, atol=1e-9)


def test_delta_williams_fpk_snapshots(delta):
    """Williams p. 19, FPK snapshot examples: Theta = (10, 20, 30) deg -> P = (0.108, -0.180,
    -1.244) m, printed to 1 mm: tolerance 0.5 mm, the rounding (measured 0.14, 0.35, 0.46 mm).
    Theta = 0 -> P = (0, 0, -1.065) m: the exact value with the table's dimensions is
    -1.064452 m (z0 = -sqrt(l^2 - (wB + L - uP)^2), the same in an independent implementation,
    Pieces98/Deltarobot_Kinematics's README: -1064.4517 mm), 0.55 mm from the print, beyond the
    0.5 mm rounding of a correctly rounded -1.0645 (it looks rounded twice, -1.06445 -> -1.0645
    -> -1.065): asserted as that deviation, at most 0.6 mm, and the value itself against the
    closed form to 1e-12 m."""
    general = _solve("delta_williams_fk.yaml")
    np.testing.assert_allclose([general["x"], general["y"], general["z"]], [0.108, -0.180, -1.244], rtol=0, atol=0.5e-3)
    nominal = cn.forward_kinematics(delta, [0.0, 0.0, 0.0], NEWTON)
    assert nominal.status == Status.SOLVED
    z0 = -math.sqrt(L_LOW**2 - (WB + L_UP - UP) ** 2)
    np.testing.assert_allclose(nominal.x, [0.0, 0.0, z0], rtol=0, atol=1e-12)
    assert abs(nominal.x[2] - (-1.065)) <= 0.6e-3


def test_delta_williams_fk_against_numpy_ipk_and_round_trip(delta):
    """Random arm angles: FK on the file, then Williams's IPK in numpy returns them (1e-9 rad:
    the FK pose carries Newton's tolerance); and the tool's IK of the FK pose returns them."""
    rng = np.random.default_rng(20)
    for _ in range(6):
        q = rng.uniform(-30 * DEG, 60 * DEG, 3)
        fk = _fk_ik_round_trip(delta, q, 1e-9)
        np.testing.assert_allclose(_williams_ipk(fk.x), q, rtol=0, atol=1e-9)


# -- linear Delta: Williams 2016, the Delta Maker 3D printer (pp. 24-25, 36-39) -----------------

SB_L, SP_L, L_ROD = 0.246, 0.127, 0.264
#: the vertical P joints B_i and the platform vertices P_i (Williams p. 24)
LIN_B = [(-SB_L / 2, -math.sqrt(3) / 6 * SB_L), (SB_L / 2, -math.sqrt(3) / 6 * SB_L), (0.0, math.sqrt(3) / 3 * SB_L)]
LIN_P = [(-SP_L / 2, -math.sqrt(3) / 6 * SP_L), (SP_L / 2, -math.sqrt(3) / 6 * SP_L), (0.0, math.sqrt(3) / 3 * SP_L)]


def _linear_delta_ipk(p):
    """Williams's prismatic IPK in numpy: the carriage B_i - L_i z is at distance l from the
    vertex P + P_i; the "lower solution" (the carriage above the platform):
    L_i = -z - sqrt(l^2 - |P_xy + P_i - B_i|^2)."""
    x, y, z = p
    return np.array(
        [-z - math.sqrt(L_ROD**2 - (x + pi[0] - bi[0]) ** 2 - (y + pi[1] - bi[1]) ** 2) for bi, pi in zip(LIN_B, LIN_P)]
    )


def test_delta_linear_williams_ipk_snapshots():
    """Williams p. 36, prismatic IPK snapshots ("the preferred lower solution"): P = (0, 0,
    -0.5) m -> L = (0.2451, 0.2451, 0.2451) m and P = (0.03, 0.05, -0.40) m -> L = (0.1664,
    0.1516, 0.1384) m, printed to 0.1 mm: tolerance 0.05 mm, the rounding (measured 0.003 mm
    at most).  The same lengths from the closed form in numpy to 1e-12 m."""
    general = _solve("delta_linear_williams_ik.yaml")
    nominal = _solve("delta_linear_williams_ik.yaml", "inputs.x=0 m", "inputs.y=0 m", "inputs.z=-0.5 m")
    for values, p, printed in (
        (nominal, (0.0, 0.0, -0.5), (0.2451, 0.2451, 0.2451)),
        (general, (0.03, 0.05, -0.40), (0.1664, 0.1516, 0.1384)),
    ):
        lengths = np.array([values[f"L{i}"] for i in (1, 2, 3)])
        np.testing.assert_allclose(lengths, printed, rtol=0, atol=0.05e-3)
        np.testing.assert_allclose(lengths, _linear_delta_ipk(p), rtol=0, atol=1e-12)


def test_delta_linear_williams_fpk_snapshots():
    """Williams pp. 38-39, prismatic FPK snapshots ("the admissible lower solution"):
    L = (0.2, 0.2, 0.2) m -> P = (0, 0, -0.4549) m; L = (0.14, 0.15, 0.16) m -> z = -0.4012 m
    and, for x and y, the magnitudes 0.0363 and 0.0215 m (the PDF's text layer drops the minus
    signs and scrambles the order of this vector: only the magnitudes are pinned, as a set;
    the closed form gives x = -0.02153, y = -0.03633).  Printed to 0.1 mm: tolerance 0.05 mm.
    FK against Williams's IPK in numpy (1e-12 m) and against the tool's IK."""
    general = _solve("delta_linear_williams_fk.yaml")
    p = np.array([general["x"], general["y"], general["z"]])
    assert p[2] == pytest.approx(-0.4012, abs=0.05e-3)
    np.testing.assert_allclose(np.sort(np.abs(p[:2])), [0.0215, 0.0363], rtol=0, atol=0.05e-3)
    np.testing.assert_allclose(_linear_delta_ipk(p), [0.14, 0.15, 0.16], rtol=0, atol=1e-12)
    model = _model("delta_linear_williams")
    nominal = _fk_ik_round_trip(model, [0.2, 0.2, 0.2], 1e-12)
    np.testing.assert_allclose(nominal.x, [0.0, 0.0, -0.4549], rtol=0, atol=0.05e-3)
    _fk_ik_round_trip(model, [0.14, 0.15, 0.16], 1e-12)


# -- five-bar: a public five-bar robot project's tests (b = 0.125 m, l = 0.205 m) --------------

#: the four working modes (w1, w2) at P = (0, 0.3) m and the source's (q1, q2), test_inverse
FIVE_BAR_MODES = {
    (1, 1): (0.52040625, 1.30998849),
    (-1, 1): (1.83160416, 1.30998849),
    (-1, -1): (1.83160416, 2.6211864),
    (1, -1): (0.52040625, 2.6211864),
}


def _five_bar_ik(p, w1, w2, b=0.125, l=0.205):
    """The law of cosines per leg (numpy): q_i = atan2(P - A_i) - w_i acos(|P - A_i| / (2 l))."""
    out = []
    for a, w in (((-b, 0.0), w1), ((b, 0.0), w2)):
        v = np.asarray(p, float) - np.asarray(a)
        out.append(math.atan2(v[1], v[0]) - w * math.acos(math.hypot(*v) / (2 * l)))
    return np.array(out)


@pytest.mark.parametrize(("w1", "w2"), list(FIVE_BAR_MODES))
def test_five_bar_four_working_modes(w1, w2):
    """The source's test_inverse: the four working modes at P = (0, 0.3) m, printed to 1e-8
    rad: tolerance 5e-9 rad, the rounding (pytest.approx's default there is relative 1e-6).
    Each mode by the file's closed-form IK and by the IK solved on the generated closures
    (method solve); the numpy law of cosines to 1e-12 rad."""
    overrides = (f"mechanism.parameters.w1={w1}", f"mechanism.parameters.w2={w2}")
    values = _solve("five_bar_working_modes_ik.yaml", *overrides)
    q = np.array([values["q1"], values["q2"]])
    np.testing.assert_allclose(q, FIVE_BAR_MODES[(w1, w2)], rtol=0, atol=5e-9)
    np.testing.assert_allclose(q, _five_bar_ik((0.0, 0.3), w1, w2), rtol=0, atol=1e-12)
    model = _model("five_bar_working_modes", {"w1": w1, "w2": w2})
    solved = cn.inverse_kinematics(model, [0.0, 0.3], method="solve")
    assert solved.status == Status.SOLVED, solved.message
    np.testing.assert_allclose(_wrap(np.asarray(solved.q) - q), 0.0, atol=1e-9)
    rng = np.random.default_rng(7)
    for _ in range(4):
        qr = np.asarray(FIVE_BAR_MODES[(w1, w2)]) + rng.uniform(-0.05, 0.05, 2)
        fk = _fk_ik_round_trip(model, qr, 1e-9)
        np.testing.assert_allclose(_five_bar_ik(fk.x, w1, w2), qr, rtol=0, atol=1e-9)


def test_five_bar_assembly_modes_of_the_minus_plus_joints():
    """The source's test_forward and test_forward_ass_2: the -+ joints (1.83160416,
    1.30998849) rad give P = (0, 0.3) m in the first assembly mode and
    (-1.98021962e-17, 9.61346135e-02) m in the second (their tolerance 1e-5; printed to 1e-11 m,
    computed from the same rounded joints): `assembly_modes: all` finds exactly these two,
    to 1e-9 m (the rounded joints move P by about 4e-10 m from (0, 0.3))."""
    values = _solve("five_bar_working_modes_fk.yaml")
    assert values["modes"] == 2
    modes = np.array([values["modes_x"], values["modes_y"]]).T
    np.testing.assert_allclose(modes[0], (0.0, 0.3), rtol=0, atol=1e-9)
    np.testing.assert_allclose(modes[1], (-1.98021962e-17, 9.61346135e-02), rtol=0, atol=1e-9)
    assert values["modes_designated"] == [True, False]


# -- Jansen's linkage: Pyslvs, example "Jansen's linkage (Single)", test/test_core.py -----------

JANSEN = {
    0: (0.0, 0.0),
    1: (9.61, 11.52),
    2: (-38.0, -7.8),
    3: (-35.24, 33.61),
    4: (-77.75, -2.54),
    5: (-20.1, -42.79),
    6: (-56.05, -35.42),
    7: (-22.22, -91.74),
}


def _rigid(p, a, b, target, pa, pb):
    """The point `target` of the rigid body through a and b (coordinates p), the body moved to pa, pb."""
    u = (p[b] - p[a]) / np.linalg.norm(p[b] - p[a])
    v = np.array([-u[1], u[0]])
    w = p[target] - p[a]
    U = (pb - pa) / np.linalg.norm(pb - pa)
    return pa + (w @ u) * U + (w @ v) * np.array([-U[1], U[0]])


def _jansen_foot(angle, crank=None):
    """Pyslvs's construction in numpy: the crank pin, then each dyad's circle intersection on
    the side it has in the initial configuration (how Pyslvs picks it), the ternary links rigid."""
    p = {k: np.array(v) for k, v in JANSEN.items()}
    d = lambda a, b: float(np.linalg.norm(p[a] - p[b]))  # noqa: E731
    side = lambda c1, q, c2: math.copysign(1.0, _cross(p[c2] - p[c1], p[q] - p[c1]))  # noqa: E731
    r1 = crank or d(0, 1)
    p1 = r1 * np.array([math.cos(angle), math.sin(angle)])
    p3 = _circle(p1, d(1, 3), p[2], d(2, 3), side(1, 3, 2))
    p5 = _circle(p1, d(1, 5), p[2], d(2, 5), side(1, 5, 2))
    p4 = _rigid(p, 2, 3, 4, p[2], p3)
    p6 = _circle(p4, d(4, 6), p5, d(5, 6), side(4, 6, 5))
    return _rigid(p, 5, 6, 7, p5, p6)


@pytest.mark.parametrize(
    ("angle", "crank", "printed"),
    [
        (0.0, None, (-43.170055, -91.753226)),  # test_solving and test_solving_bfgs
        (45.0, None, (-24.406394, -91.789596)),  # test_solving_bfgs, set_inputs 45
        (45.0, 16.0, (-24.117994, -91.198072)),  # test_solving_bfgs, set_data L1 = 16
    ],
)
def test_jansen_pyslvs_foot_positions(angle, crank, printed):
    """Pyslvs test/test_core.py pins the foot P7 with assertAlmostEqual(places=6) on values
    printed to 6 decimals (Pyslvs's length unit, here mm): tolerance 5e-7 mm, the rounding.
    The crank length 16 is set through dr1 = 16 - |P0 P1| (the other links kept, as
    Pyslvs's set_data does).  The numpy construction gives the same to 1e-9 mm."""
    overrides = [f"inputs.theta={angle!r} deg"]
    if crank is not None:
        overrides.append(f"mechanism.parameters.dr1={crank - math.hypot(*JANSEN[1])!r} mm")
    values = _solve("jansen_pyslvs_fk.yaml", *overrides)
    foot = np.array([values["foot_x"], values["foot_y"]]) / MM
    np.testing.assert_allclose(foot, printed, rtol=0, atol=5e-7)
    np.testing.assert_allclose(foot, _jansen_foot(angle * DEG, crank), rtol=0, atol=1e-9)


def test_jansen_pyslvs_fk_path_and_round_trip():
    """A full crank turn in 30 deg steps (FK from home each time, not continued by the test):
    the foot is the numpy construction's to 1e-9 mm.  FK against IK: the IK of the rocker angle
    a5 gives a crank angle whose FK is the IK's pose with that a5 (a5 takes each value at two
    crank angles, as any output of a crank: the IK from home may return the other one)."""
    model = _model("jansen_pyslvs")
    idx = _passive_index(model, "foot_x")
    for deg in range(0, 360, 30):
        fk = cn.forward_kinematics(model, [deg * DEG], NEWTON)
        assert fk.status == Status.SOLVED, (deg, fk.message)
        foot = np.array(fk.passive[idx : idx + 2]) / MM
        np.testing.assert_allclose(foot, _jansen_foot(deg * DEG), rtol=0, atol=1e-9)
    for deg in (20.0, 45.0, 80.0):
        _fk_ik_round_trip(model, [deg * DEG], 1e-8, unique=False)


# -- six-bar with a slider: Pyslvs, example "Crank slider (RP joint)", test/test_core.py --------

SLIDER = {
    0: (-67.38, 36.13),
    1: (-68.925, 55.925),
    2: (11.88, 0.0),
    3: (50.775, 24.7908),
    4: (74.375, 7.625),
    5: (95.1972, 52.8805),
}


def _slider_output(angle):
    """numpy: the crank pin, the slider on y = 0 right of it (as initially), J3 on the side of
    J2 -> J4 it has initially, J5 rigid on L3 (J2, J3)."""
    p = {k: np.array(v) for k, v in SLIDER.items()}
    d = lambda a, b: float(np.linalg.norm(p[a] - p[b]))  # noqa: E731
    p1 = p[0] + d(0, 1) * np.array([math.cos(angle), math.sin(angle)])
    p2 = np.array([p1[0] + math.sqrt(d(1, 2) ** 2 - p1[1] ** 2), 0.0])
    side = math.copysign(1.0, _cross(p[4] - p[2], p[3] - p[2]))
    p3 = _circle(p2, d(2, 3), p[4], d(3, 4), side)
    return _rigid(p, 2, 3, 5, p2, p3)


def test_crank_slider_sixbar_pyslvs_printed_value():
    """Pyslvs test/test_core.py, test_solving: crank at 0 deg -> J5 = (103.801126, 78.393173),
    assertAlmostEqual(places=6): tolerance 5e-7 mm, the rounding of the printed value.  The
    crank is 94.5 deg from the file's reference configuration (see the file's `branch:`)."""
    values = _solve("crank_slider_sixbar_pyslvs_fk.yaml")
    j5 = np.array([values["j5x"], values["j5y"]]) / MM
    np.testing.assert_allclose(j5, (103.801126, 78.393173), rtol=0, atol=5e-7)
    np.testing.assert_allclose(j5, _slider_output(0.0), rtol=0, atol=1e-9)


def test_crank_slider_sixbar_pyslvs_path_and_round_trip():
    """Crank angles over a full turn (J5 against numpy to 1e-9 mm); FK against IK (task: the
    slider position x) at crank angles near the reference (80 to 110 deg)."""
    model = _model("crank_slider_sixbar_pyslvs")
    idx = _passive_index(model, "j5x")
    for deg in range(0, 360, 45):
        fk = cn.forward_kinematics(model, [deg * DEG], NEWTON)
        assert fk.status == Status.SOLVED, (deg, fk.message)
        np.testing.assert_allclose(np.array(fk.passive[idx : idx + 2]) / MM, _slider_output(deg * DEG), atol=1e-9)
    for deg in (80.0, 95.0, 110.0):
        _fk_ik_round_trip(model, [deg * DEG], 1e-8)


# -- four-bar: Pyslvs example "Crank rocker"; Freudenstein 1955 --------------------------------

FB_A = math.hypot(12.92, 32.53)  # crank
FB_B = math.hypot(73.28 - 12.92, 67.97 - 32.53)  # coupler
FB_C = math.hypot(73.28 - 90.0, 67.97)  # rocker
FB_D = 90.0  # ground


def _freudenstein(theta2):
    """Both roots theta4 of Freudenstein's equation (1955),
    K1 cos(t4) - K2 cos(t2) + K3 = cos(t2 - t4), K1 = d/a, K2 = d/c,
    K3 = (a^2 - b^2 + c^2 + d^2)/(2 a c): with A cos(t4) + B sin(t4) = C,
    A = K1 - cos(t2), B = -sin(t2), C = K2 cos(t2) - K3."""
    a, b, c, d = FB_A, FB_B, FB_C, FB_D
    K1, K2, K3 = d / a, d / c, (a * a - b * b + c * c + d * d) / (2 * a * c)
    A, B, C = K1 - math.cos(theta2), -math.sin(theta2), K2 * math.cos(theta2) - K3
    base, half = math.atan2(B, A), math.acos(C / math.hypot(A, B))
    return _wrap([base + half, base - half])


def _fourbar_open(theta2, roots):
    """The root with the rocker pin P2 left of P1 -> P4 (the initial configuration's assembly)."""
    p1 = FB_A * np.array([math.cos(theta2), math.sin(theta2)])
    p4 = np.array([FB_D, 0.0])
    return [t4 for t4 in roots if _cross(p4 - p1, p4 + FB_C * np.array([math.cos(t4), math.sin(t4)]) - p1) > 0][0]


def test_fourbar_pyslvs_assembly_modes_against_freudenstein():
    """`assembly_modes: all` at theta2 = 40 deg: the two modes (open, crossed) are the two
    roots of Freudenstein's equation (numpy, derived here: Pyslvs prints no angles for this
    example), to 1e-9 rad; the designated one is the open assembly of the initial
    configuration."""
    values = _solve("fourbar_pyslvs_modes.yaml")
    roots = _freudenstein(40 * DEG)
    assert values["modes"] == 2
    got = np.sort(_wrap(values["modes_theta4"]))
    np.testing.assert_allclose(got, np.sort(roots), rtol=0, atol=1e-9)
    assert values["modes_designated"] == [True, False]
    assert values["theta4"] == pytest.approx(_fourbar_open(40 * DEG, roots), abs=1e-9)


def test_fourbar_pyslvs_full_turn_and_round_trip():
    """The crank-rocker's crank turns fully: FK at every 30 deg is the open root of
    Freudenstein's equation (1e-9 rad); IK of theta4 returns the crank near home."""
    model = _model("fourbar_pyslvs")
    for deg in range(0, 360, 30):
        fk = cn.forward_kinematics(model, [deg * DEG], NEWTON)
        assert fk.status == Status.SOLVED, (deg, fk.message)
        assert _wrap(fk.x[0] - _fourbar_open(deg * DEG, _freudenstein(deg * DEG))) == pytest.approx(0.0, abs=1e-9)
    for deg in (50.0, 68.0, 90.0):
        _fk_ik_round_trip(model, [deg * DEG], 1e-8)


# -- Watt II six-bar: Pyslvs, example "Watt II" ------------------------------------------------

WATT = {
    1: (-5.3333, 36.0),
    2: (42.6667, 48.3333),
    3: (60.0, 1.3333),
    4: (79.0, 71.3333),
    5: (113.6667, 36.0),
    6: (87.0, -17.0),
}


def _watt_modes(theta1):
    """numpy: the four modes (each four-bar's circle intersection on either side): the angles
    (a2, a3, a4, a5) and whether each side is the initial configuration's."""
    p = {k: np.array(v) for k, v in WATT.items()}
    p[0] = np.zeros(2)
    d = lambda a, b: float(np.linalg.norm(p[a] - p[b]))  # noqa: E731
    ang = lambda v: math.atan2(v[1], v[0])  # noqa: E731
    s2 = math.copysign(1.0, _cross(p[3] - p[1], p[2] - p[1]))
    s5 = math.copysign(1.0, _cross(p[6] - p[4], p[5] - p[4]))
    p1 = d(0, 1) * np.array([math.cos(theta1), math.sin(theta1)])
    out = []
    for side2 in (s2, -s2):
        p2 = _circle(p1, d(1, 2), p[3], d(2, 3), side2)
        p4 = _rigid(p, 3, 2, 4, p[3], p2)
        for side5 in (s5, -s5):
            p5 = _circle(p4, d(4, 5), p[6], d(5, 6), side5)
            out.append(
                (np.array([ang(p2 - p1), ang(p2 - p[3]), ang(p5 - p4), ang(p5 - p[6])]), side2 == s2 and side5 == s5)
            )
    return out


def test_watt2_pyslvs_four_assembly_modes():
    """`assembly_modes: all` with the crank at 120 deg: the four modes of the numpy model
    (derived here: Pyslvs prints no output for this example), each to 1e-9 rad, the designated
    one on both four-bars' initial assembly."""
    values = _solve("watt2_pyslvs_modes.yaml")
    assert values["modes"] == 4
    # the file is bodies and joints: a5 is the output rocker's angle (its platform coordinate),
    # P2 the first four-bar's coupler point (an output); the numpy model's a2, a3 give P2
    found = np.array(
        [[values["modes_a5"][m], values["modes_P2_x"][m] / MM, values["modes_P2_y"][m] / MM] for m in range(4)]
    )
    for want, initial in _watt_modes(120 * DEG):
        p2 = np.array(WATT[3]) + math.dist(WATT[2], WATT[3]) * np.array([math.cos(want[1]), math.sin(want[1])])
        hit = [
            m for m in range(4) if abs(_wrap(found[m, 0] - want[3])) < 1e-9 and np.allclose(found[m, 1:], p2, atol=1e-9)
        ]
        assert len(hit) == 1, want
        assert values["modes_designated"][hit[0]] == initial


def test_watt2_pyslvs_path_and_round_trip():
    """The crank over a full turn in 45 deg steps: the output rocker a5 is the numpy model's
    (initial sides) to 1e-9 rad; IK of a5 returns the crank near home (98 deg)."""
    model = _model("watt2_pyslvs")
    for deg in range(0, 360, 45):
        fk = cn.forward_kinematics(model, [deg * DEG], NEWTON)
        assert fk.status == Status.SOLVED, (deg, fk.message)
        want = next(a for a, initial in _watt_modes(deg * DEG) if initial)
        assert _wrap(fk.x[0] - want[3]) == pytest.approx(0.0, abs=1e-9)  # a5, the output rocker
        k = _passive_index(model, "P2_x")
        p2 = np.array(WATT[3]) + math.dist(WATT[2], WATT[3]) * np.array([math.cos(want[1]), math.sin(want[1])])
        np.testing.assert_allclose(np.array(fk.passive[k : k + 2]) / MM, p2, rtol=0, atol=1e-9)
    for deg in (80.0, 100.0, 120.0):
        _fk_ik_round_trip(model, [deg * DEG], 1e-8)


# -- spatial RSSR: linkR test configuration RSSR_3d --------------------------------------------


def _rssr_outputs(theta):
    """numpy: the input crank's sphere A = Rot(n, theta) (0, 0.5, 0), n = (1, 0, 1)/sqrt 2
    through the origin (Rodrigues); the output's B = (1, 0, 0) + (-sin phi, cos phi, 0);
    |B - A| = l = |(1, 1, 0) - (0, 0.5, 0)|; with w = A - (1, 0, 0):
    P cos(phi) + Q sin(phi) = R, P = 2 w_y, Q = -2 w_x, R = 1 + |w|^2 - l^2: both roots."""
    n = np.array([1.0, 0.0, 1.0]) / math.sqrt(2)
    a0 = np.array([0.0, 0.5, 0.0])
    A = a0 * math.cos(theta) + np.cross(n, a0) * math.sin(theta) + n * (n @ a0) * (1 - math.cos(theta))
    w = A - np.array([1.0, 0.0, 0.0])
    l2 = 1.0**2 + 0.5**2
    P, Q, R = 2 * w[1], -2 * w[0], w @ w + 1.0 - l2
    base, half = math.atan2(Q, P), math.acos(R / math.hypot(P, Q))
    return _wrap([base + half, base - half])


def test_rssr_linkr_two_assembly_modes():
    """`assembly_modes: all` at theta = 60 deg: the two roots of the RSSR input-output
    equation (numpy, derived here from linkR's geometry; linkR pins no output), 1e-9 rad."""
    values = _solve("rssr_linkr_fk.yaml")
    assert values["modes"] == 2
    np.testing.assert_allclose(np.sort(_wrap(values["modes_phi"])), np.sort(_rssr_outputs(60 * DEG)), atol=1e-9)
    assert values["modes_designated"] == [True, False]


def test_rssr_linkr_path_and_round_trip():
    """FK over input angles from -90 to 90 deg: phi is one of the input-output equation's
    roots (the one on the designated branch), to 1e-9 rad; FK against IK (phi takes each value
    at two input angles: the IK's input gives, by FK, the IK's pose)."""
    model = _model("rssr_linkr")
    for deg in range(-90, 91, 30):
        fk = cn.forward_kinematics(model, [deg * DEG], NEWTON)
        assert fk.status == Status.SOLVED, (deg, fk.message)
        roots = _rssr_outputs(deg * DEG)
        assert min(abs(_wrap(fk.x[0] - r)) for r in roots) < 1e-9
        _fk_ik_round_trip(model, [deg * DEG], 1e-8, unique=False)


# -- planar 3-RRR: ARTE's example 3RRR (A. Gil, A Robotics Toolbox for Education) -------------

ARTE_L, ARTE_A, ARTE_B, ARTE_H = 3.0, 1.0, 1.0, 0.5
ARTE_BASE = np.array([[0.0, 0.0], [ARTE_L, 0.0], [ARTE_L / 2, ARTE_L]])


def _arte_platform(x, y, phi):
    p = np.array([x, y])
    return [
        p,
        p + ARTE_H * np.array([math.cos(phi), math.sin(phi)]),
        p + ARTE_H * np.array([math.cos(phi + math.pi / 3), math.sin(phi + math.pi / 3)]),
    ]


def _arte_ik(pose, w=(1, 1, 1)):
    """The law of cosines per arm (numpy): q_i = atan2(C_i - A_i) + w_i acos((a^2 + r^2 - b^2) / (2 a r))."""
    out = []
    for a_i, c_i, w_i in zip(ARTE_BASE, _arte_platform(*pose), w):
        v = c_i - a_i
        r = math.hypot(*v)
        out.append(math.atan2(v[1], v[0]) + w_i * math.acos((ARTE_A**2 + r * r - ARTE_B**2) / (2 * ARTE_A * r)))
    return np.array(out)


def _arte_fk_all(q, n=20001):
    """Every real FK solution (numpy, derived here): for each phi of a fine grid, P is on the
    circle (elbow D1, b) and on the circle (D2 - h u(phi), b) -- two intersections, each a
    branch -- and the residual |C3 - D3| - b of arm 3 changes sign at a solution, refined by
    bisection; the same elimination as ARTE's polynomial in tan(phi/2)."""
    d = ARTE_BASE + ARTE_A * np.c_[np.cos(q), np.sin(q)]

    def point(phi, side):
        u = np.array([math.cos(phi), math.sin(phi)])
        c2 = d[1] - ARTE_H * u
        v = c2 - d[0]
        dist = math.hypot(*v)
        h2 = ARTE_B**2 - (dist / 2) ** 2
        if h2 < 0:
            return None
        return d[0] + v / 2 + side * math.sqrt(h2) * np.array([-v[1], v[0]]) / dist

    def residual(phi, side):
        p = point(phi, side)
        if p is None:
            return math.nan
        c3 = p + ARTE_H * np.array([math.cos(phi + math.pi / 3), math.sin(phi + math.pi / 3)])
        return math.hypot(*(c3 - d[2])) - ARTE_B

    grid = np.linspace(-math.pi, math.pi, n)
    out = []
    for side in (1.0, -1.0):
        f = np.array([residual(g, side) for g in grid])
        for k in np.flatnonzero(np.isfinite(f[:-1]) & np.isfinite(f[1:]) & (f[:-1] * f[1:] < 0)):
            lo, hi = grid[k], grid[k + 1]
            for _ in range(60):
                mid = (lo + hi) / 2
                if residual(lo, side) * residual(mid, side) <= 0:
                    hi = mid
                else:
                    lo = mid
            phi = (lo + hi) / 2
            out.append((*point(phi, side), phi))
    return np.array(out)


def test_rrr3_arte_ik_against_the_law_of_cosines():
    """IK solved on the generated closures (the file has no closed form) at poses around the
    reference: the law of cosines in numpy (elbows w = +1), 1e-9 rad; FK against IK."""
    model = _model("rrr3_arte")
    for pose in ((1.25, 1.0, 0.0), (1.5, 1.2, 0.2), (1.1, 0.9, -0.15), (1.4, 0.8, 0.1)):
        ik = cn.inverse_kinematics(model, pose)
        assert ik.status == Status.SOLVED, ik.message
        np.testing.assert_allclose(_wrap(np.asarray(ik.q) - _arte_ik(pose)), 0.0, atol=1e-9)
        _fk_ik_round_trip(model, ik.q, 1e-9)


def test_rrr3_arte_assembly_modes_against_a_scan():
    """`assembly_modes: all` for the actuators of P = (1.75, 0.9) m, phi = -0.1 rad: the same
    real solutions as the numpy scan (2 with this geometry: the arms' reach, a + b = 2 m,
    against a base of 3 m, leaves little room), each to 1e-8.  The designated one is the pose:
    the law of cosines returns the actuators from it (1e-9 rad), and it is (1.75, 0.9, -0.1)
    to 1e-7 (the problem file gives the actuators to 1e-9 rad: 5e-10 rad of rounding, times
    |dx/dq| up to about 30 here, moves the pose by 1.6e-8)."""
    values = _solve("rrr3_arte_modes.yaml")
    q = np.array([values[k] for k in ("q1", "q2", "q3")])
    want = _arte_fk_all(q)
    assert values["modes"] == len(want) == 2
    found = np.array([values["modes_x"], values["modes_y"], values["modes_phi"]]).T
    for w in want:
        assert min(np.max(np.abs(np.r_[f[:2] - w[:2], _wrap(f[2] - w[2])])) for f in found) < 1e-8
    np.testing.assert_allclose(_wrap(_arte_ik(found[0]) - q), 0.0, atol=1e-9)
    np.testing.assert_allclose(found[0], (1.75, 0.9, -0.1), rtol=0, atol=1e-7)


# -- every corpus file: the AD Jacobian against central differences of FK ----------------------


@pytest.mark.parametrize("name", sorted(p.stem for p in CORPUS.glob("*.yaml")))
def test_corpus_jacobian_against_central_differences(name):
    """J = -Phi_x^-1 Phi_q (AD) at a pose near home equals the central differences of FK
    (step 1e-6 of the actuators' unit, truncation O(h^2)): relative 1e-6 of max |J|.  Near home:
    the actuators 1e-3 of their unit away (1 mm, 1 mrad); Dietmaier's platform has |dx/dq| up to
    60 at its home, so that 1 cm on every leg is a pose Newton from home does not reach."""
    model = _model(name)
    q = np.asarray(model.q_home, float) + 1e-3
    fk = cn.forward_kinematics(model, q, NEWTON)
    assert fk.status == Status.SOLVED, fk.message
    J = np.asarray(cn.jacobians(model, fk.x, fk.q).J)
    h = 1e-6
    fd = np.empty_like(J)
    for k in range(q.size):
        e = np.zeros_like(q)
        e[k] = h
        plus = cn.forward_kinematics(model, q + e, NEWTON, guess=fk.x)
        minus = cn.forward_kinematics(model, q - e, NEWTON, guess=fk.x)
        fd[:, k] = (np.asarray(plus.x) - np.asarray(minus.x)) / (2 * h)
    np.testing.assert_allclose(J, fd, rtol=0, atol=1e-6 * np.max(np.abs(J)))


# -- generated branch indicators: mode invariants over a full crank turn (issue 20, item 5) --------


def _branch(model, x, q):
    g = np.asarray(model.closure.branch(np.asarray(x, float), np.asarray(q, float), model.p)).ravel()
    return dict(zip(model.closure.branch_names, g.tolist()))


def test_fourbar_pyslvs_indicators_over_a_full_turn():
    """Without a `branch:` override the generated indicators (chain.R2: the coupler-rocker
    dyad's assembly mode; aspect) are positive at every 15 deg of a full crank turn on the open
    assembly (numpy: Freudenstein's root with P2 left of P1 -> P4) and negative on the crossed
    one; chain.R2 has the sign of the triangle (P1, P2, P4)'s orientation there.  Before the
    fix the old indicator (the coupler's cosine to its reference direction) was -0.255 at
    0 deg, -0.998 at -60 deg and -0.428 at 180 deg, on the open assembly."""
    model = _model("fourbar_pyslvs")
    assert model.closure.branch_names == ("chain.R2", "aspect")
    for deg in range(0, 360, 15):
        t2 = deg * DEG
        roots = _freudenstein(t2)
        open_ = _fourbar_open(t2, roots)
        crossed = next(r for r in roots if abs(_wrap(r - open_)) > 1e-6)
        p1 = FB_A * np.array([math.cos(t2), math.sin(t2)])
        for t4, sign in ((open_, 1.0), (crossed, -1.0)):
            p2 = np.array([FB_D, 0.0]) + FB_C * np.array([math.cos(t4), math.sin(t4)])
            assert math.copysign(1.0, _cross(p2 - p1, np.array([FB_D, 0.0]) - p2)) == -sign  # the mode, numpy
            g = _branch(model, [t4], [t2])
            assert all(v * sign > 0 for v in g.values()), (deg, sign, g)
    for deg in (0.0, -60.0, 180.0):  # the brief's poses: FK solves on the open assembly
        fk = cn.forward_kinematics(model, [deg * DEG], NEWTON)
        assert fk.status == Status.SOLVED, fk.message
        assert _wrap(fk.x[0] - _fourbar_open(deg * DEG, _freudenstein(deg * DEG))) == pytest.approx(0.0, abs=1e-9)


def _rssr_mode(theta, phi):
    """numpy: the sign of dg/dphi, g = |B(phi) - A(theta)|^2 - l^2 (the RSSR's two assembly
    modes meet where it vanishes)."""
    n = np.array([1.0, 0.0, 1.0]) / math.sqrt(2)
    a0 = np.array([0.0, 0.5, 0.0])
    A = a0 * math.cos(theta) + np.cross(n, a0) * math.sin(theta) + n * (n @ a0) * (1 - math.cos(theta))
    B = np.array([1.0 - math.sin(phi), math.cos(phi), 0.0])
    return math.copysign(1.0, 2 * (B - A) @ np.array([-math.cos(phi), -math.sin(phi), 0.0]))


def test_rssr_linkr_indicators_over_a_full_turn():
    """The generated indicators (coupler.S2: the coupler-output sub-chain's assembly mode;
    aspect) are positive over a full input turn (every 15 deg) on the root with the sign of
    dg/dphi of home (numpy) and negative on the other root.  The old indicator was -0.223 at
    theta = -90 deg on the designated mode."""
    model = _model("rssr_linkr")
    assert model.closure.branch_names == ("coupler.S2", "aspect")
    home = _rssr_mode(0.0, 0.0)
    for deg in range(-180, 180, 15):
        for phi in _rssr_outputs(deg * DEG):
            sign = _rssr_mode(deg * DEG, phi) * home
            g = _branch(model, [phi], [deg * DEG])
            assert all(v * sign > 0 for v in g.values()), (deg, phi, g)
    fk = cn.forward_kinematics(model, [-90 * DEG], NEWTON)
    assert fk.status == Status.SOLVED, fk.message


def _slider_pose(angle, right, side):
    """numpy: the pose (x, y, phi, s) of L3 in metres and radians, the slider right (or left)
    of the crank pin, J3 on the initial (or the other) side of J2 -> J4 (phi None: the rocker
    does not reach L3 there)."""
    p = {k: np.array(v) for k, v in SLIDER.items()}
    d = lambda a, b: float(np.linalg.norm(p[a] - p[b]))  # noqa: E731
    p1 = p[0] + d(0, 1) * np.array([math.cos(angle), math.sin(angle)])
    p2 = np.array([p1[0] + (1 if right else -1) * math.sqrt(d(1, 2) ** 2 - p1[1] ** 2), 0.0])
    s0 = math.copysign(1.0, _cross(p[4] - p[2], p[3] - p[2]))
    try:
        p3 = _circle(p2, d(2, 3), p[4], d(3, 4), s0 if side else -s0)
    except ValueError:
        return np.array([p2[0] * MM, 0.0, 0.0, (p2[0] - p[2][0]) * MM]), None
    ang = lambda v: math.atan2(v[1], v[0])  # noqa: E731
    phi = ang(p3 - p2) - ang(p[3] - p[2])
    return np.array([p2[0] * MM, 0.0, phi, (p2[0] - p[2][0]) * MM]), phi


def test_crank_slider_sixbar_pyslvs_indicators_over_a_full_turn():
    """The generated indicators: crank.R2 (the rod and slider: positive with the slider right
    of the crank pin, as in Pyslvs), rocker.R1 (L3 and the rocker: positive with J3 on the
    initial side of J2 -> J4), aspect (their product): at every 15 deg of a full turn each has
    the sign of its own mode in the numpy model.  With the slider left of the crank pin the
    rocker never reaches L3 (this geometry), so there crank.R2 is checked on the rod-slider
    sub-chain alone (its rows closed; it does not depend on phi).  The old indicator of the
    rod was -0.302 at 0 deg on the designated mode."""
    model = _model("crank_slider_sixbar_pyslvs")
    assert model.closure.branch_names == ("crank.R2", "rocker.R1", "aspect")
    for deg in range(0, 360, 15):
        q = [deg * DEG]
        for side in (True, False):
            x, phi = _slider_pose(deg * DEG, True, side)
            assert phi is not None
            assert np.max(np.abs(cn.residual(model, x, q))) < 1e-12
            g = _branch(model, x, q)
            want = 1 if side else -1
            assert g["crank.R2"] > 0 and math.copysign(1, g["rocker.R1"]) == want, (deg, g)
            assert math.copysign(1, g["aspect"]) == want
        x, phi = _slider_pose(deg * DEG, False, True)
        assert phi is None
        closed = np.abs(cn.residual(model, x, q)) < 1e-12
        assert closed.sum() == 3, deg  # the rod and the slider's two rows; not the rocker's
        assert _branch(model, x, q)["crank.R2"] < 0, deg
