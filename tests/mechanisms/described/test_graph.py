"""Mechanism files of bodies and joints (issue 21, items 1-3): the spanning tree and its loops,
mobility by rank beside Grübler-Kutzbach, outputs at any point, the reference configuration
assembled from a rough drawing -- each against a closed form written here in numpy (the
circle intersection of a four-bar, the RSSR's input-output equation, Bennett's relation), not
against the code's own output.  The corpus files (Jansen, Watt II, Bennett) are pinned to their
sources in tests/corpus/test_corpus.py; every generic kind runs on them in test_conformance.py.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import yaml

import cpm_nlp as cn
from cpm_nlp.core.result import Status
from cpm_nlp.mechanisms.described import from_dict, load_file

HERE = Path(__file__).resolve().parents[2]
GRAPH = HERE / "data" / "graph"
CORPUS = HERE / "corpus"
NEWTON = cn.SolverConfig("newton")
MM, DEG = 1e-3, math.pi / 180


def _model(path: Path, parameters: dict | None = None):
    mech = load_file(path)
    return mech.model(mech.closure(), parameters or {}, {}, ())


def _wrap(a):
    return (np.asarray(a) + math.pi) % (2 * math.pi) - math.pi


def _read(path: Path) -> dict:
    return yaml.safe_load(path.read_text(encoding="utf-8"))


# -- the four-bar: a rough drawing, assembled ---------------------------------------------------


def _fourbar(theta: float, a=0.020, b=0.060, c=0.045, d=0.050) -> tuple[float, np.ndarray]:
    """numpy: the rocker pin B = the intersection of the circles (A, b) and (B0, c) on the
    side of the assembled drawing (B left of A -> B0), and the rocker angle psi of B0 -> B."""
    A = a * np.array([math.cos(theta), math.sin(theta)])
    B0 = np.array([d, 0.0])
    v = B0 - A
    dist = math.hypot(*v)
    e = (b * b - c * c + dist * dist) / (2 * dist)
    h = math.sqrt(b * b - e * e)
    B = A + e * v / dist + h * np.array([-v[1], v[0]]) / dist
    return math.atan2(B[1] - B0[1], B[0] - B0[0]), B


def test_fourbar_rough_drawing_assembles_and_fk_is_the_circle_intersection():
    """The drawing puts the rocker upright and the coupler's end off it (1 mm and more); the
    reference configuration is assembled (theta = 90 deg) and FK over a full crank turn gives
    the rocker angle and its pin B of the closed form to 1e-12."""
    model = _model(GRAPH / "fourbar.yaml")
    c = model.closure
    assert tuple(c.task) == ("psi",) and tuple(c.q_names) == ("theta",)
    psi, B = _fourbar(math.pi / 2)
    k = c.x_names.index("psi")
    assert model.x_home[k] == pytest.approx(psi, abs=1e-12)
    assert not abs(psi - math.pi / 2) < 1e-3  # the drawing was rough: assembly moved the rocker
    out = [p.name for p in c.passive_coords].index("B_x")
    for deg in range(0, 360, 20):
        fk = cn.forward_kinematics(model, [deg * DEG], NEWTON)
        assert fk.status == Status.SOLVED, (deg, fk.message)
        psi, B = _fourbar(deg * DEG)
        assert _wrap(fk.x[k] - psi) == pytest.approx(0.0, abs=1e-12)
        np.testing.assert_allclose(fk.passive[out : out + 2], B, rtol=0, atol=1e-12)


def test_fourbar_any_parameter_reassembles_and_fk_against_ik():
    """--set on every parameter: the reference configuration is assembled again from the same
    drawing (no closed-form home written in the file), FK equals the closed form with the new
    lengths, and IK of the FK pose returns the crank angle."""
    lengths = {"a": 0.018, "b": 0.064, "c": 0.047, "d": 0.052}
    model = _model(GRAPH / "fourbar.yaml", lengths)
    k = model.closure.x_names.index("psi")
    fk = cn.forward_kinematics(model, [40 * DEG], NEWTON)
    assert fk.status == Status.SOLVED, fk.message
    assert _wrap(fk.x[k] - _fourbar(40 * DEG, **lengths)[0]) == pytest.approx(0.0, abs=1e-12)
    ik = cn.inverse_kinematics(model, [fk.x[k]])
    assert ik.status == Status.SOLVED, ik.message
    fk2 = cn.forward_kinematics(model, ik.q, NEWTON)  # psi takes each value at two crank angles
    assert _wrap(fk2.x[k] - fk.x[k]) == pytest.approx(0.0, abs=1e-10)


def test_fourbar_that_cannot_close_says_so():
    """A coupler too short to reach the rocker: the assembly fails with the loop's residual
    named, an input error (never a pose)."""
    with pytest.raises(cn.InputError, match=r"does not assemble from the drawing.*loop 1"):
        _model(GRAPH / "fourbar.yaml", {"b": 0.010})


def test_fourbar_other_assembly_mode_is_another_branch():
    """The loop's indicator (its block determinant) is positive on the drawn assembly mode and
    negative on the crossed one (the circle intersection on the other side)."""
    model = _model(GRAPH / "fourbar.yaml")
    c = model.closure
    fk = cn.forward_kinematics(model, [60 * DEG], NEWTON)
    g = np.asarray(c.branch(fk.x, fk.q, model.p)).ravel()
    assert c.branch_names == ("loop1",) and g[0] > 0
    modes = cn.assembly_modes(model, [60 * DEG], NEWTON, starts=400)
    signs = sorted(float(np.sign(m.branch[0])) for m in modes.modes)
    assert signs == [-1.0, 1.0], signs  # open and crossed, one indicator sign each


# -- the RSSR: a spatial loop closed by a distance joint ------------------------------------------


def _rssr_phi(theta: float) -> float:
    """numpy (as tests/corpus/test_corpus.py): A = Rot(n, theta) (0, 0.5, 0), n = (1, 0, 1)/sqrt 2;
    B = (1, 0, 0) + Rot(z, phi) (0, 1, 0); |B - A| = |(1, 1, 0) - (0, 0.5, 0)|: the root of
    P cos(phi) + Q sin(phi) = R, the root of the drawing's mode (phi = 0 at theta = 0)."""
    n = np.array([1.0, 0.0, 1.0]) / math.sqrt(2)
    a0 = np.array([0.0, 0.5, 0.0])
    A = a0 * math.cos(theta) + np.cross(n, a0) * math.sin(theta) + n * (n @ a0) * (1 - math.cos(theta))
    w = A - np.array([1.0, 0.0, 0.0])
    P, Q, R = 2 * w[1], -2 * w[0], w @ w + 1.0 - 1.25
    base, half = math.atan2(Q, P), math.acos(R / math.hypot(P, Q))
    return float(_wrap(base - half))


def test_rssr_distance_joint_closes_the_loop():
    """The RSSR with its coupler a distance joint: mobility 1 by rank and by Grübler-Kutzbach
    (6*2 - 5 - 1 - 5), FK over a half turn equals the input-output equation's root to 1e-12."""
    model = _model(GRAPH / "rssr.yaml")
    k = model.closure.x_names.index("phi")
    for deg in range(-90, 91, 15):
        fk = cn.forward_kinematics(model, [deg * DEG], NEWTON)
        assert fk.status == Status.SOLVED, (deg, fk.message)
        assert _wrap(fk.x[k] - _rssr_phi(deg * DEG)) == pytest.approx(0.0, abs=1e-12)


# -- Bennett: overconstrained, one degree of freedom ----------------------------------------------


def _bennett_phi2(theta1: float, alpha=30 * DEG, beta=60 * DEG) -> float:
    """Bennett's relation tan(theta1/2) tan(phi2/2) = sin((beta + alpha)/2) / sin((beta - alpha)/2)."""
    k = math.sin((beta + alpha) / 2) / math.sin((beta - alpha) / 2)
    return 2 * math.atan(k / math.tan(theta1 / 2))


def test_bennett_loads_by_rank_and_follows_bennetts_relation():
    """Grübler-Kutzbach gives -2; the rank of the loop's Jacobian gives 1, so it loads; FK along
    a whole crank turn (each solve from the last) and from home at any input follows Bennett's
    relation to 1e-11 rad, with every loop equation (not only the normal equations) holding."""
    model = _model(CORPUS / "bennett.yaml")
    c = model.closure
    assert c.loops is not None  # the overconstrained form: each closure equation is checked
    k = c.x_names.index("phi2")
    x = None
    for deg in range(100, 460, 10):
        fk = cn.forward_kinematics(model, [deg * DEG], NEWTON, guess=x)
        assert fk.status == Status.SOLVED, (deg, fk.message)
        x = fk.x
        assert _wrap(fk.x[k] - _bennett_phi2(deg * DEG)) == pytest.approx(0.0, abs=1e-11)
        assert np.max(np.abs(np.asarray(c.loops(fk.x, fk.q, model.p)))) < 1e-12
    for deg in (200, 250, 300):
        fk = cn.forward_kinematics(model, [deg * DEG], NEWTON)
        assert fk.status == Status.SOLVED, (deg, fk.message)
        assert _wrap(fk.x[k] - _bennett_phi2(deg * DEG)) == pytest.approx(0.0, abs=1e-11)


def test_bennett_describe_names_the_disagreement(capsys):
    """describe says both counts and names the overconstrained loop."""
    from cpm_nlp.cli.main import main

    assert main(["describe", str(CORPUS / "bennett.yaml")]) == 0
    text = capsys.readouterr().out
    assert "1 degree(s) of freedom; Grübler-Kutzbach: -2" in text
    assert "the two disagree" in text and "loop 1 (3 of 5)" in text
    assert "loop 1, closed by J4: L3 - L2 - L1 - ground" in text


def test_bennett_with_its_condition_broken_does_not_assemble():
    """A twist that breaks a/sin(alpha) = b/sin(beta) is not expressible in the file (b is derived);
    a link length set apart is: the linkage then locks and the drawing does not assemble."""
    data = _read(CORPUS / "bennett.yaml")
    data["derived"]["b"] = {"value": "1.05*a*sin(beta)/sin(alpha)", "dimension": "length"}
    with pytest.raises(cn.InputError, match="does not assemble|wrong mobility"):
        mech = from_dict(data)
        mech.model(mech.closure(), {}, {}, ())


# -- the corpus: the Jansen linkage re-assembled, outputs at any point -------------------------


def test_jansen_output_point_and_reassembly():
    """The foot P7 (a point of the ternary link L7) is an output; a crank 2 mm longer (the crank's
    own pin drawn at its length, the other links' at Pyslvs's) assembles in a few steps."""
    model = _model(CORPUS / "jansen_pyslvs.yaml", {"dr1": 0.002})
    names = [p.name for p in model.closure.passive_coords]
    assert names[-2:] == ["foot_x", "foot_y"]
    fk = cn.forward_kinematics(model, [45 * DEG], NEWTON)
    assert fk.status == Status.SOLVED, fk.message


# -- bad input: one clear message each ------------------------------------------------------------


def _bad(change) -> cn.InputError:
    data = _read(GRAPH / "fourbar.yaml")
    change(data)
    with pytest.raises(cn.InputError) as info:
        mech = from_dict(data, file="fourbar.yaml")
        mech.model(mech.closure(), {}, {}, ())
    return info.value


@pytest.mark.parametrize(
    ("change", "path", "words"),
    [
        (lambda d: d["joints"][1].update(between=["crank", "coupler2"]), "joints[1].between[1]", "did you mean"),
        (lambda d: d["joints"][1].update(at="Q"), "joints[1].at", "not a point of 'crank'"),
        (lambda d: d["bodies"].update(base=d["bodies"].pop("ground")), None, None),  # 'base' is a ground too
        (lambda d: d["bodies"].update(frame=d["bodies"].pop("ground")), "bodies", "no ground"),
        # legs and bodies in one file (issue 21): the legs place the platform by its coordinates
        (lambda d: d.update(legs=[{"joints": [{"type": "planar_R", "at": [0, 0]}]}]), "platform", "places its"),
        (lambda d: d.update(actuators={"u": "length"}), "actuators", "not both"),
        (lambda d: d["joints"][0].pop("actuated"), "joints", "no actuators"),
        (lambda d: d["joints"][3].update(actuated="psi2"), "joints", "actuate fewer"),
        (lambda d: d["platform"].update(task=["chi"]), "platform.task[0]", "unknown task coordinate"),
        (lambda d: d["parameters"]["a"].pop("default"), "parameters.a.default", "needs a default"),
        (lambda d: d["joints"][1].update(between=["crank", "crank"]), "joints[1].between", "two different bodies"),
        (lambda d: d.update(outputs={"F": "rocker.Q"}), "outputs.F", "not a point of 'rocker'"),
    ],
)
def test_bad_graph_files_name_the_key(change, path, words):
    if path is None:  # a change that is fine: the ground may be named base
        data = _read(GRAPH / "fourbar.yaml")
        data["bodies"] = {("base" if k == "ground" else k): v for k, v in data["bodies"].items()}
        for j in data["joints"]:
            j["between"] = ["base" if b == "ground" else b for b in j["between"]]
        mech = from_dict(data)
        mech.model(mech.closure(), {}, {}, ())
        return
    exc = _bad(change)
    text = exc.render()
    assert path in text and words in text, text


def test_same_file_same_tree_and_rows():
    """The tree, the loops and the rows kept depend on the file only (file order, a rank test
    with a wide margin): two loads give the same closure, row for row."""
    a, b = (load_file(CORPUS / "jansen_pyslvs.yaml").closure() for _ in range(2))
    assert a.x_names == b.x_names and a.branch_names == b.branch_names
    x = np.linspace(0.1, 0.7, a.nx)
    np.testing.assert_array_equal(np.asarray(a.phi(x, [0.3], [0.0])), np.asarray(b.phi(x, [0.3], [0.0])))


def test_set_override_reaches_a_graph_parameter():
    """`--set mechanism.parameters.dr1=...` on the Jansen problem file: the crank length changes."""
    problem = cn.load_problem(CORPUS / "problems" / "jansen_pyslvs_fk.yaml", ["mechanism.parameters.dr1=1 mm"])
    assert problem.model.parameters["dr1"] == pytest.approx(0.001)


# -- a spatial platform: the 6-UPS as bodies and joints against its legs file ------------------


def _ups6_graph() -> dict:
    """problems/mechanisms/ups6.yaml (legs) written as 14 bodies and 18 joints, with the file's
    default dimensions in numbers: U at the base (axes normal to the leg), the actuated P along
    the leg, S at the platform."""
    rb, rp, bb, pb, h0 = 0.150, 0.100, 20 * DEG, 20 * DEG, 0.200
    z = np.array([0.0, 0.0, 1.0])

    def rz(v, t):
        c, s = math.cos(t), math.sin(t)
        return [c * v[0] - s * v[1], s * v[0] + c * v[1], v[2]]

    points, bodies, joints = {"O": [0, 0, 0]}, {"ground": ["O"], "platform": []}, []
    for i in range(3):
        turn = 2 * math.pi * i / 3
        for side, sign in (("a", -1.0), ("b", 1.0)):
            n = f"{side}{i + 1}"
            base = np.array(rz([rb * math.cos(bb / 2), sign * rb * math.sin(bb / 2), 0.0], turn))
            top = np.array(
                rz([rp * math.cos(math.pi / 3 - pb / 2), sign * rp * math.sin(math.pi / 3 - pb / 2), h0], turn)
            )
            d = top - base
            u1 = np.cross(z, d) / np.linalg.norm(np.cross(z, d))
            u2 = np.cross(d, u1) / np.linalg.norm(np.cross(d, u1))
            points[f"A{n}"], points[f"B{n}"] = base.tolist(), top.tolist()
            bodies["ground"].append(f"A{n}")
            bodies["platform"].append(f"B{n}")
            bodies[f"cyl_{n}"] = [f"A{n}"]
            bodies[f"rod_{n}"] = [f"A{n}", f"B{n}"]
            joints += [
                {"type": "U", "between": ["ground", f"cyl_{n}"], "at": f"A{n}", "axes": [u1.tolist(), u2.tolist()]},
                {
                    "type": "P",
                    "between": [f"cyl_{n}", f"rod_{n}"],
                    "at": f"A{n}",
                    "axis": d.tolist(),
                    "actuated": f"l{n}",
                    "home": float(np.linalg.norm(d)),
                },
                {"type": "S", "between": [f"rod_{n}", "platform"], "at": f"B{n}"},
            ]
    points["P0"] = [0.0, 0.0, h0]
    bodies["platform"].append("P0")
    return {
        "name": "ups6_graph",
        "points": points,
        "bodies": bodies,
        "joints": joints,
        "platform": {
            "body": "platform",
            "point": "P0",
            "coordinates": {
                "px": "length",
                "py": "length",
                "pz": "length",
                "psi": "angle",
                "theta": "angle",
                "phi": "angle",
            },
            "position": ["px", "py", "pz"],
            "rotation": [["z", "phi"], ["y", "theta"], ["x", "psi"]],
            "task": ["px", "py", "pz", "psi", "theta", "phi"],
            "home": {"pz": h0},
        },
    }


def test_ups6_as_bodies_and_joints_equals_its_legs_file():
    """The Stewart platform written as bodies and joints (five S joints close five loops; the
    platform's six coordinates locate its body through position and rotation rows) against
    the legs file, whose closure the leg generator writes by elimination: FK of 10 seeded
    random leg lengths (+-10 mm) agree to 1e-10, and so does the task Jacobian dx/dq."""
    mech = from_dict(_ups6_graph())
    graph = mech.model(mech.closure(), {}, {}, ())
    legs = cn.build_model("ups6", {})
    c = graph.closure
    assert sorted(c.q_names) == sorted(legs.closure.q_names)
    order = [list(c.q_names).index(n) for n in legs.closure.q_names]  # graph's q in the legs' order
    rows = [c.x_names.index(n) for n in ("px", "py", "pz", "psi", "theta", "phi")]
    rng = np.random.default_rng(7)
    for _ in range(10):
        dq = rng.uniform(-0.01, 0.01, 6)  # in the legs file's order
        qa = np.empty(6)
        qa[order] = legs.q_home + dq
        a = cn.forward_kinematics(graph, qa, NEWTON)
        b = cn.forward_kinematics(legs, legs.q_home + dq, NEWTON)
        assert a.status == b.status == Status.SOLVED, (a.message, b.message)
        np.testing.assert_allclose(np.asarray(a.x)[rows], np.asarray(b.x)[:6], rtol=0, atol=1e-10)
        ja = cn.jacobians(graph, a.x, a.q).J_task[:, order]
        jb = cn.jacobians(legs, b.x, b.q).J_task
        np.testing.assert_allclose(ja, jb, rtol=0, atol=1e-9 * np.max(np.abs(jb)))
