"""cpm-nlp import: a URDF and its Extended URDF sidecar as a mechanism file of bodies and joints.

The fixtures (tests/data/import/) are written for these tests, in the layout of the public
examples of Gepetto/example-parallel-robots (robots/5bar_linkage/robot.urdf + robot.yaml: a 6d
closure between two dummy links; robots/5bar_linkage_iso3d: a 3d closure between two links on
fixed joints).  The expected drawing is derived here by hand from each fixture's stated
geometry (crank angles and link lengths), not from the importer's frame arithmetic.
"""

from __future__ import annotations

import builtins
import math
from pathlib import Path

import numpy as np
import pytest
import yaml

import cpm_nlp as cn
from cpm_nlp.core.errors import InputError
from cpm_nlp.core.result import Status
from cpm_nlp.io.import_urdf import import_urdf
from cpm_nlp.mechanisms.described import load_file

DATA = Path(__file__).resolve().parents[1] / "data" / "import"
FIVE, FIVE_SIDE = str(DATA / "five_bar.urdf"), str(DATA / "five_bar.yaml")
FOUR, FOUR_SIDE = str(DATA / "four_bar.urdf"), str(DATA / "four_bar.yaml")

# five_bar.urdf (its header): A1, A2 = (-/+0.05, 0), cranks 0.1 at 120 and 60 deg, distal 0.15
FIVE_D, FIVE_L1, FIVE_L2 = 0.1, 0.1, 0.15
# four_bar.urdf (its header): O = (0, 0), D = (0.06, 0); crank a at 60 deg, coupler b, rocker c;
# the tracer at (0.035, 0.02) in the coupler's frame (x along the coupler)
FOUR_A, FOUR_B, FOUR_C, FOUR_D, FOUR_TH2 = 0.02, 0.07, 0.05, 0.06, math.radians(60)
TRACER = np.array([0.035, 0.02])


def five_bar_drawing(q1: float = 0.0, q2: float = 0.0) -> dict[str, np.ndarray]:
    """The five-bar by hand: crank angles 120 deg + q1 and 60 deg + q2, P the upper
    intersection of the two circles of radius l2 about the elbows."""
    a1, a2 = np.array([-FIVE_D / 2, 0.0]), np.array([FIVE_D / 2, 0.0])
    c1 = a1 + FIVE_L1 * np.array([math.cos(2 * math.pi / 3 + q1), math.sin(2 * math.pi / 3 + q1)])
    c2 = a2 + FIVE_L1 * np.array([math.cos(math.pi / 3 + q2), math.sin(math.pi / 3 + q2)])
    m, half = (c1 + c2) / 2, np.linalg.norm(c2 - c1) / 2
    u = (c2 - c1) / (2 * half)
    p = m + math.sqrt(FIVE_L2**2 - half**2) * np.array([-u[1], u[0]])  # left of c1 -> c2: above
    return {"A1": a1, "A2": a2, "C1": c1, "C2": c2, "P": p}


def four_bar_drawing(q: float = 0.0) -> dict[str, np.ndarray]:
    """The four-bar by hand: crank at 60 deg + q, the open assembly (C left of B -> D)."""
    o, d = np.zeros(2), np.array([FOUR_D, 0.0])
    b = FOUR_A * np.array([math.cos(FOUR_TH2 + q), math.sin(FOUR_TH2 + q)])
    dist = np.linalg.norm(d - b)
    e = (d - b) / dist
    x = (FOUR_B**2 - FOUR_C**2 + dist**2) / (2 * dist)
    c = b + x * e + math.sqrt(FOUR_B**2 - x**2) * np.array([-e[1], e[0]])
    th3 = math.atan2(c[1] - b[1], c[0] - b[0])
    th4 = math.atan2(c[1] - d[1], c[0] - d[0])
    rot = np.array([[math.cos(th3), -math.sin(th3)], [math.sin(th3), math.cos(th3)]])
    return {"O": o, "D": d, "B": b, "C": c, "T": b + rot @ TRACER, "th3": th3, "th4": th4}


def load(text: str) -> dict:
    return yaml.safe_load(text)


def point(data: dict, body: str, name: str) -> np.ndarray:
    """A body's point: its own coordinates, else the drawing's."""
    raw = data["bodies"][body]
    own = raw["points"].get(name) if isinstance(raw, dict) else None
    if isinstance(raw, list):
        assert name in raw
    else:
        assert name in raw["points"]
    return np.array(own if own is not None else data["points"][name], dtype=float)


# -- what is written ---------------------------------------------------------------------------


def test_five_bar_bodies_joints_and_drawing():
    imported = import_urdf(FIVE, FIVE_SIDE)
    data = load(imported.text)
    assert imported.planar and data["platform"]["planar"] is True
    assert data["name"] == "five_bar"
    # the dummy links welded by the 6d closure are gone: one R joint between the distal links
    assert set(data["bodies"]) == {"ground", "crank1", "crank2", "distal1", "distal2"}
    joints = {j["name"]: j for j in data["joints"]}
    assert {n: (j["type"], tuple(j["between"])) for n, j in joints.items()} == {
        "mot1": ("planar_R", ("ground", "crank1")),
        "free1": ("planar_R", ("crank1", "distal1")),
        "closedloop1_A": ("planar_R", ("distal1", "distal2")),
        "mot2": ("planar_R", ("ground", "crank2")),
        "free2": ("planar_R", ("crank2", "distal2")),
    }
    assert joints["mot1"]["actuated"] == "mot1" and joints["mot2"]["actuated"] == "mot2"
    assert "actuated" not in joints["free1"] and joints["free1"]["coordinates"] == ["free1"]
    assert joints["mot1"]["range"] == [-3.14, 3.14]  # the URDF's limit, axis +n: not flipped
    # the plane is the URDF's y-z plane (every axis along x); the 0.01 layer offset is dropped
    hand = five_bar_drawing()
    expect = {
        ("ground", "P_mot1"): hand["A1"],
        ("ground", "P_mot2"): hand["A2"],
        ("crank1", "P_mot1"): hand["A1"],
        ("crank1", "P_free1"): hand["C1"],
        ("crank2", "P_free2"): hand["C2"],
        ("distal1", "P_free1"): hand["C1"],
        ("distal1", "P_closedloop1_A"): hand["P"],
        ("distal1", "P_effector"): hand["P"],
        ("distal2", "P_closedloop1_A"): hand["P"],
        ("distal2", "P_free2"): hand["C2"],
    }
    for (body, name), value in expect.items():
        np.testing.assert_allclose(point(data, body, name), value, rtol=0, atol=1e-12, err_msg=f"{body}.{name}")
    assert data["platform"]["body"] == "distal1" and data["platform"]["point"] == "P_effector"
    assert data["platform"]["task"] == ["x", "y"]
    np.testing.assert_allclose([data["platform"]["home"]["x"], data["platform"]["home"]["y"]], hand["P"], atol=1e-12)
    # free2's URDF axis is -x: its angle in the plane is minus the URDF's, and the header says so
    assert any("free2" in n and "-n" in n for n in imported.notes)
    assert "# Planar: every R axis is n = [1.0, 0, 0]" in imported.text


def test_four_bar_bodies_joints_and_drawing():
    imported = import_urdf(FOUR, FOUR_SIDE, platform="tracer")
    data = load(imported.text)
    assert imported.planar
    # world and base (a fixed joint) are one body, the ground; coupler_end, tracer on the coupler
    assert set(data["bodies"]) == {"ground", "crank_link", "coupler", "rocker"}
    joints = {j["name"]: j for j in data["joints"]}
    assert {n: (j["type"], tuple(j["between"])) for n, j in joints.items()} == {
        "crank": ("planar_R", ("ground", "crank_link")),
        "coupler_pin": ("planar_R", ("crank_link", "coupler")),
        "rocker_pivot": ("planar_R", ("ground", "rocker")),
        "coupler_end": ("planar_R", ("coupler", "rocker")),  # the 3d closure: S, planar_R in the plane
    }
    assert joints["crank"]["actuated"] == "crank"
    assert joints["rocker_pivot"]["range"] == [-1.0, 1.0]
    hand = four_bar_drawing()
    expect = {
        ("ground", "P_crank"): hand["O"],
        ("ground", "P_rocker_pivot"): hand["D"],
        ("crank_link", "P_coupler_pin"): hand["B"],
        ("coupler", "P_coupler_pin"): hand["B"],
        ("coupler", "P_coupler_end"): hand["C"],
        ("rocker", "P_coupler_end"): hand["C"],
        ("coupler", "P_tracer"): hand["T"],
    }
    for (body, name), value in expect.items():
        np.testing.assert_allclose(point(data, body, name), value, rtol=0, atol=1e-12, err_msg=f"{body}.{name}")
    assert data["platform"]["body"] == "coupler" and data["platform"]["task"] == ["phi"]
    assert data["platform"]["home"]["phi"] == 0


def test_numbers_are_written_exactly():
    """Every coordinate is written with repr: the file reads back the very floats computed."""
    imported = import_urdf(FOUR, FOUR_SIDE, platform="tracer")
    data = load(imported.text)
    for body, own in imported.bodies.items():
        for name, value in own.items():
            if value is not None:
                assert data["bodies"][body]["points"][name] == value
    for v in data["points"].values():
        assert all(isinstance(x, (int, float)) for x in v)


def test_spatial_file_keeps_axes_and_the_spherical_closure():
    imported = import_urdf(FOUR, FOUR_SIDE, platform="tracer", planar=False, task=["phi"])
    data = load(imported.text)
    assert not imported.planar and "planar" not in data["platform"]
    joints = {j["name"]: j for j in data["joints"]}
    assert joints["crank"]["type"] == "R" and joints["crank"]["axis"] == [0, 0, 1.0]
    assert joints["coupler_end"]["type"] == "S" and "axis" not in joints["coupler_end"]
    hand = four_bar_drawing()
    np.testing.assert_allclose(data["points"]["P_coupler_end"], [*hand["C"], 0.0], atol=1e-12)


def test_actuated_joints_from_the_option():
    data = load(import_urdf(FOUR, FOUR_SIDE, platform="tracer", actuated=["rocker_pivot"]).text)
    joints = {j["name"]: j for j in data["joints"]}
    assert joints["rocker_pivot"]["actuated"] == "rocker_pivot"
    assert "actuated" not in joints["crank"] and joints["crank"]["coordinates"] == ["crank"]


def test_names_are_made_valid_and_said(tmp_path):
    text = (DATA / "four_bar.urdf").read_text().replace('"coupler"', '"coupler link"')
    text = text.replace('name="crank"', 'name="2-crank"').replace('"world"', '"on"')
    path = tmp_path / "names.urdf"
    path.write_text(text)
    imported = import_urdf(str(path), FOUR_SIDE, actuated=["2-crank"], platform="tracer")
    data = load(imported.text)
    assert "coupler_link" in data["bodies"]
    assert [j["name"] for j in data["joints"]][0] == "n_2_crank"
    assert any("'2-crank' -> n_2_crank" in n for n in imported.notes)


def test_nothing_but_the_two_named_files_is_opened(monkeypatch):
    """four_bar.urdf names /etc/passwd as a mesh: only the URDF and the sidecar are opened."""
    opened = []
    real_open = builtins.open

    def spy(file, *args, **kwargs):
        opened.append(str(file))
        return real_open(file, *args, **kwargs)

    monkeypatch.setattr(builtins, "open", spy)
    import_urdf(FOUR, FOUR_SIDE, platform="tracer")
    assert sorted(opened) == sorted([FOUR, FOUR_SIDE])


# -- bad and hostile input ---------------------------------------------------------------------


@pytest.mark.parametrize(
    ("name", "where", "what"),
    [
        ("hostile_entities.urdf", "robot", "<!DOCTYPE>"),
        ("hostile_external.urdf", "robot", "<!DOCTYPE>"),
        ("missing_parent.urdf", "joint[mot1].parent.link", "did you mean 'base_link'"),
        ("cycle.urdf", "joint[", "cycle: b -> c -> a -> b"),
        ("unknown_type.urdf", "joint[mot1].type", "did you mean 'revolute'"),
        ("xacro_include.urdf", "robot.include", "macro or an include"),
    ],
)
def test_hostile_urdf_is_refused_naming_the_file_and_element(name, where, what):
    path = str(DATA / name)
    with pytest.raises(InputError) as info:
        import_urdf(path)
    message = str(info.value)
    assert message.startswith(path + ": " + where), message
    assert what in message


@pytest.mark.parametrize(
    ("name", "where", "what"),
    [
        ("bad_frame.yaml", "closed_loop[0][1]", "did you mean 'closedloop1_B'"),
        ("bad_type.yaml", "type[0]", "expected '6d'"),
    ],
)
def test_bad_sidecar_is_refused_naming_its_key_path(name, where, what):
    path = str(DATA / name)
    with pytest.raises(InputError) as info:
        import_urdf(FIVE, path)
    assert str(info.value).startswith(f"{path}: {where}: ")
    assert what in str(info.value)


ROBOT = """<?xml version="1.0"?>
<robot name="r">
  <link name="base"/><link name="a"/><link name="b"/>
  {joints}
</robot>
"""


@pytest.mark.parametrize(
    ("joints", "where", "what"),
    [
        (
            '<joint name="j1" type="revolute"><parent link="base"/><child link="a"/></joint>'
            '<joint name="j2" type="revolute"><parent link="b"/><child link="a"/></joint>'
            '<joint name="j3" type="revolute"><parent link="base"/><child link="b"/></joint>',
            "joint[j2].child.link",
            "child of two joints",
        ),
        (
            '<joint name="j1" type="revolute"><origin xyz="0 nan 0"/><parent link="base"/><child link="a"/></joint>',
            "joint[j1].origin.xyz",
            "3 finite numbers",
        ),
        (
            '<joint name="j1" type="floating"><parent link="base"/><child link="a"/></joint>',
            "joint[j1].type",
            "unsupported joint type 'floating'",
        ),
        (
            '<joint name="j1" type="revolute"><parent link="base"/><child link="a"/><axis xyz="0 0 0"/></joint>',
            "joint[j1].axis.xyz",
            "nonzero axis",
        ),
        (
            '<joint name="j1" type="revolute"><parent link="base"/><child link="a"/><mimic joint="j2"/></joint>',
            "joint[j1].mimic",
            "mimic",
        ),
        (
            '<joint name="j1" type="revolute"><parent link="base"/><child link="a"/></joint>',
            "robot",
            "not one tree: base, b have no parent joint",
        ),
        ("<joint name='j1' type='revolute'><parent link='base'/>", "", "malformed XML: line"),
    ],
)
def test_bad_urdf_elements(tmp_path, joints, where, what):
    path = tmp_path / "r.urdf"
    path.write_text(ROBOT.format(joints=joints))
    with pytest.raises(InputError) as info:
        import_urdf(str(path))
    message = str(info.value)
    assert message.startswith(f"{path}: {where}" if where else f"{path}: "), message
    assert what in message


def test_a_large_file_is_refused_before_it_is_read(tmp_path):
    path = tmp_path / "big.urdf"
    with open(path, "wb") as fh:
        fh.truncate(2 << 20)  # sparse: 2 MiB of nothing
    with pytest.raises(InputError, match="the limit is 1 MiB"):
        import_urdf(str(path))


def test_sidecar_errors(tmp_path):
    side = tmp_path / "robot.yaml"
    side.write_text("closed_loops: [[closedloop1_A, closedloop1_B]]\n")
    with pytest.raises(
        InputError, match=r"closed_loops: unknown Extended URDF sidecar key .*did you mean .closed_loop."
    ):
        import_urdf(FIVE, str(side))
    side.write_text("closed_loop: [[closedloop1_A, closedloop1_B]]\ntype: [6d]\nname_mot: [mot3]\n")
    with pytest.raises(InputError, match=r"name_mot\[0\]: no joint of the URDF is named 'mot3'; did you mean"):
        import_urdf(FIVE, str(side))
    side.write_text("closed_loop: [[closedloop1_A, closedloop1_B]]\ntype: [6d]\n")
    with pytest.raises(InputError, match="no actuated joint"):
        import_urdf(FIVE, str(side))
    side.write_text("closed_loop: [[free1, effector_frame]]\ntype: [3d]\nname_mot: [mot1, mot2]\n")
    with pytest.raises(InputError, match=r"closed_loop\[0\]: the frames .* are on one rigid body"):
        import_urdf(FIVE, str(side))


def test_option_errors():
    with pytest.raises(InputError, match=r"--actuated: the joint 'effector_frame' is fixed"):
        import_urdf(FIVE, FIVE_SIDE, actuated=["effector_frame"])
    with pytest.raises(
        InputError, match=r"--task\[1\]: unknown task coordinate 'w'; expected one of: x, y, phi, free1"
    ):
        import_urdf(FIVE, FIVE_SIDE, task=["x", "w"])
    with pytest.raises(InputError, match=r"--task: expected 2 different task coordinates"):
        import_urdf(FIVE, FIVE_SIDE, task=["x"])
    with pytest.raises(InputError, match=r"--task: which task coordinates for 1 actuated joint"):
        import_urdf(FOUR, FOUR_SIDE, platform="tracer", planar=False)
    with pytest.raises(InputError, match=r"--platform: no joint or link of the URDF is named 'tracr'"):
        import_urdf(FOUR, FOUR_SIDE, platform="tracr")
    with pytest.raises(InputError, match=r"four_bar.urdf: robot: which body is the platform"):
        import_urdf(FOUR, FOUR_SIDE)
    with pytest.raises(InputError, match=r"--name: expected a mechanism name"):
        import_urdf(FIVE, FIVE_SIDE, name="five bar")


# -- the command line --------------------------------------------------------------------------


def test_cli_writes_the_file(cli, tmp_path):
    out = tmp_path / "five.yaml"
    run = cli("import", FIVE, "--sidecar", FIVE_SIDE, "-o", str(out), "--name", "five_bar_urdf")
    assert run.code == 0, run.err
    assert run.out == f"{out}: 5 bodies, 5 joints (planar) from {FIVE}\n"
    assert out.read_text() == import_urdf(FIVE, FIVE_SIDE, name="five_bar_urdf").text
    assert not [p for p in tmp_path.iterdir() if p.name != "five.yaml"]  # no temporary left


def test_cli_prints_without_output(cli):
    run = cli("import", FOUR, "--sidecar", FOUR_SIDE, "--platform", "tracer", "--actuated", "crank")
    assert run.code == 0, run.err
    assert run.out == import_urdf(FOUR, FOUR_SIDE, platform="tracer", actuated=["crank"]).text


def test_cli_bad_input_exits_2_and_writes_nothing(cli, tmp_path):
    out = tmp_path / "x.yaml"
    for argv in (
        ("import", str(DATA / "hostile_entities.urdf"), "-o", str(out)),
        ("import", FIVE, "--sidecar", str(DATA / "bad_type.yaml"), "-o", str(out)),
        ("import", FIVE, "--sidecar", FIVE_SIDE, "--task", "x,", "-o", str(out)),
        ("import", str(tmp_path / "missing.urdf"), "-o", str(out)),
    ):
        run = cli(*argv)
        assert run.code == 2, (argv, run.err)
        assert run.err.startswith("error: ") and run.err.count("\n") == 1 and "Traceback" not in run.err
    assert not out.exists()


def test_cli_refuses_to_overwrite_an_input(cli, tmp_path):
    urdf, side = tmp_path / "r.urdf", tmp_path / "r.yaml"
    urdf.write_bytes(Path(FIVE).read_bytes())
    side.write_bytes(Path(FIVE_SIDE).read_bytes())
    for target in (urdf, side):
        before = target.read_bytes()
        run = cli("import", str(urdf), "--sidecar", str(side), "-o", str(target))
        assert run.code == 2 and "refusing to overwrite it" in run.err
        assert target.read_bytes() == before


# -- the imported files load, and their kinematics is the linkage's -------------------------------

NEWTON = cn.SolverConfig("newton")
#: FK of the imported models on CasADi's virtual machine: each import is a closure of its own,
#: whose kernel would be compiled for a few poses (most of these tests' time, issue 23); the
#: backends' agreement is tests/core/test_batch.py's
MAP = "map"


def _model(tmp_path, text: str):
    path = tmp_path / "imported.yaml"
    path.write_text(text)
    mech = load_file(path)
    return mech.model(mech.closure(), {}, {}, ())


@pytest.mark.parametrize("q", [(0.0, 0.0), (0.3, -0.2), (-0.4, 0.5), (0.8, 0.6)])
def test_imported_five_bar_forward_kinematics_is_the_closed_form(tmp_path, q):
    """FK of the imported file (2 degrees of freedom, task x, y: the effector P) against the
    two-circle construction of five_bar_drawing (numpy) to 1e-9 m; the plane's angles are the
    URDF's (mot1, mot2 turn about +x, the plane's normal)."""
    model = _model(tmp_path, import_urdf(FIVE, FIVE_SIDE).text)
    assert model.closure.nq == 2 and list(model.closure.x_names[:2]) == ["x", "y"]
    fk = cn.forward_kinematics(model, list(q), NEWTON, backend=MAP)
    assert fk.status == Status.SOLVED, fk.message
    np.testing.assert_allclose(fk.x[:2], five_bar_drawing(*q)["P"], rtol=0, atol=1e-9)
    ik = cn.inverse_kinematics(model, list(fk.x[:2]))  # FK against IK: the actuators come back
    assert ik.status == Status.SOLVED, ik.message
    np.testing.assert_allclose(ik.q, q, rtol=0, atol=1e-9)


@pytest.mark.parametrize(
    "q",
    [
        0.0,
        0.5,
        -0.7,
        1.0,
        2.0,
        3.0,
        -2.0,
        -3.0,  # the rocker a whole turn off from home: its limit is checked on the same pose
    ],
)
def test_imported_four_bar_forward_kinematics_is_the_closed_form(tmp_path, q):
    """FK of the imported four-bar (1 degree of freedom, task phi: the coupler's turn from the
    drawing; x, y: the tracer) against the circle intersection of four_bar_drawing to 1e-9."""
    model = _model(tmp_path, import_urdf(FOUR, FOUR_SIDE, platform="tracer").text)
    hand, drawn = four_bar_drawing(q), four_bar_drawing()
    assert abs(hand["th4"] - drawn["th4"]) < 1.0  # inside the rocker's URDF limit [-1, 1]
    fk = cn.forward_kinematics(model, [q], NEWTON, backend=MAP)
    assert fk.status == Status.SOLVED, fk.message
    x = dict(zip(model.closure.x_names, fk.x))
    np.testing.assert_allclose([x["x"], x["y"]], hand["T"], rtol=0, atol=1e-9)
    assert x["phi"] == pytest.approx(hand["th3"] - drawn["th3"], abs=1e-9)
    assert x["rocker_pivot"] == pytest.approx(hand["th4"] - drawn["th4"], abs=1e-9)


def test_imported_four_bar_as_a_spatial_file(tmp_path):
    """--spatial: R joints with their axes and the 3d closure an S joint; the mobility by rank
    is still 1 (Grübler-Kutzbach says 0), and FK is the planar closed form, z = 0."""
    text = import_urdf(FOUR, FOUR_SIDE, platform="tracer", planar=False, task=["phi"]).text
    model = _model(tmp_path, text)
    for q in (0.5, -0.7):
        fk = cn.forward_kinematics(model, [q], NEWTON, backend=MAP)
        assert fk.status == Status.SOLVED, fk.message
        x = dict(zip(model.closure.x_names, fk.x))
        hand, drawn = four_bar_drawing(q), four_bar_drawing()
        np.testing.assert_allclose([x["x"], x["y"], x["z"]], [*hand["T"], 0.0], rtol=0, atol=1e-9)
        assert x["phi"] == pytest.approx(hand["th3"] - drawn["th3"], abs=1e-9)


# a slider-crank, written here: crank a = 0.03 at 30 deg about z, rod b = 0.08 (its end and the
# slider, a prismatic joint along x from the base, joined by a 3d closure), slider limit +-0.05
SC_A, SC_B, SC_TH0 = 0.03, 0.08, math.radians(30)
SC_PHI0 = -math.asin(SC_A * math.sin(SC_TH0) / SC_B)
SC_S0 = SC_A * math.cos(SC_TH0) + SC_B * math.cos(SC_PHI0)
SLIDER_CRANK = f"""<?xml version="1.0"?>
<robot name="slider_crank">
  <link name="base"/><link name="crank_link"/><link name="rod"/><link name="rod_end"/><link name="slider"/>
  <joint name="crank" type="continuous">
    <origin rpy="0 0 {SC_TH0!r}"/><parent link="base"/><child link="crank_link"/><axis xyz="0 0 1"/>
  </joint>
  <joint name="rod_pin" type="continuous">
    <origin xyz="{SC_A!r} 0 0" rpy="0 0 {SC_PHI0 - SC_TH0!r}"/><parent link="crank_link"/><child link="rod"/>
    <axis xyz="0 0 1"/>
  </joint>
  <joint name="rod_end_frame" type="fixed">
    <origin xyz="{SC_B!r} 0 0"/><parent link="rod"/><child link="rod_end"/>
  </joint>
  <joint name="slide" type="prismatic">
    <origin xyz="{SC_S0!r} 0 0"/><parent link="base"/><child link="slider"/><axis xyz="1 0 0"/>
    <limit lower="-0.05" upper="0.05" effort="1" velocity="1"/>
  </joint>
</robot>
"""


def _slider_crank(tmp_path):
    urdf, side = tmp_path / "sc.urdf", tmp_path / "sc.yaml"
    urdf.write_text(SLIDER_CRANK)
    side.write_text("closed_loop: [[rod_end, slider]]\ntype: [3d]\nname_mot: [crank]\n")
    return import_urdf(str(urdf), str(side), platform="slider", task=["x"])


def test_imported_slider_crank_prismatic_joint(tmp_path):
    """A prismatic joint: planar_P along the URDF axis, its limit its range, at its frame's origin."""
    data = load(_slider_crank(tmp_path).text)
    slide = next(j for j in data["joints"] if j["name"] == "slide")
    assert slide["type"] == "planar_P" and slide["axis"] == [1.0, 0] and slide["range"] == [-0.05, 0.05]
    assert slide["between"] == ["ground", "slider"]
    np.testing.assert_allclose(data["points"]["P_slide"], [SC_S0, 0.0], rtol=0, atol=1e-15)
    np.testing.assert_allclose(point(data, "rod", "P_rod_end"), [SC_S0, 0.0], rtol=0, atol=1e-12)


@pytest.mark.parametrize("q", [0.0, 0.6, -1.2, 1.8])  # at 2.5 the slider is past its URDF limit 0.05
def test_imported_slider_crank_forward_kinematics(tmp_path, q):
    """FK of the slider's x is a cos(th) + sqrt(b^2 - (a sin(th))^2), th = 30 deg + q (by hand), to 1e-9 m."""
    model = _model(tmp_path, _slider_crank(tmp_path).text)
    fk = cn.forward_kinematics(model, [q], NEWTON, backend=MAP)
    th = SC_TH0 + q
    s = SC_A * math.cos(th) + math.sqrt(SC_B**2 - (SC_A * math.sin(th)) ** 2)
    assert fk.status == Status.SOLVED, fk.message
    x = dict(zip(model.closure.x_names, fk.x))
    assert x["x"] == pytest.approx(s, abs=1e-9) and x["slide"] == pytest.approx(s - SC_S0, abs=1e-9)


def test_sidecar_joint_types(tmp_path):
    """joint_name/joint_type: SPHERICAL is an S joint -- the rocker, now between two S joints, is a
    rod: a distance joint ground-coupler of the rocker's length c (by hand); UJOINT_ZX a U joint
    about the joint frame's z then x axis, in world directions (the coupler's frame is turned by
    theta3 about z: x -> (cos theta3, sin theta3, 0)), and the file is spatial."""
    side = tmp_path / "robot.yaml"
    side.write_text(Path(FOUR_SIDE).read_text() + "joint_name: [rocker_pivot]\njoint_type: [SPHERICAL]\n")
    imported = import_urdf(FOUR, str(side), platform="tracer")
    data = load(imported.text)
    assert data["platform"]["planar"] is True and "rocker" not in data["bodies"]
    rod = data["joints"][-1]
    assert rod["type"] == "distance" and rod["between"] == ["ground", "coupler"]
    assert (rod["at"], rod["to"]) == ("P_rocker_pivot", "P_coupler_end")
    assert rod["length"] == pytest.approx(FOUR_C, abs=1e-15)
    assert any("'rocker' is a rod between joint 'rocker_pivot'" in n for n in imported.notes)
    fk = cn.forward_kinematics(_model(tmp_path, imported.text), [0.5], NEWTON, backend=MAP)  # still the four-bar
    assert fk.status == Status.SOLVED, fk.message
    np.testing.assert_allclose(fk.x[:2], four_bar_drawing(0.5)["T"], rtol=0, atol=1e-9)
    side.write_text(Path(FOUR_SIDE).read_text() + "joint_name: [coupler_pin]\njoint_type: [UJOINT_ZX]\n")
    imported = import_urdf(FOUR, str(side), platform="tracer", task=["phi"])
    assert not imported.planar
    pin = next(j for j in load(imported.text)["joints"] if j["name"] == "coupler_pin")
    th3 = four_bar_drawing()["th3"]
    assert pin["type"] == "U" and "axis" not in pin
    np.testing.assert_allclose(pin["axes"], [[0, 0, 1], [math.cos(th3), math.sin(th3), 0]], rtol=0, atol=1e-12)
    side.write_text(Path(FOUR_SIDE).read_text() + "joint_name: [crank]\njoint_type: [SPHERE]\n")
    with pytest.raises(InputError, match=r"joint_type\[0\]: unknown joint type 'SPHERE'.*did you mean 'SPHERICAL'"):
        import_urdf(FOUR, str(side), platform="tracer")


def test_a_6d_closure_to_the_ground_welds_the_body_to_the_ground(tmp_path):
    """The ground is never welded onto another body: [rocker_end, base] welds the rocker to the
    ground, its drawing moved so that the frame rocker_end is base's (C onto the origin), and
    the rocker's pivot, now inside one body, is left out (each said so)."""
    side = tmp_path / "robot.yaml"
    side.write_text("closed_loop: [[coupler_end, rocker_end], [rocker_end, base]]\ntype: [3d, 6d]\nname_mot: [crank]\n")
    imported = import_urdf(FOUR, str(side), platform="tracer")
    data = load(imported.text)
    assert set(data["bodies"]) == {"ground", "crank_link", "coupler"}
    assert [j["name"] for j in data["joints"]] == ["crank", "coupler_pin", "coupler_end"]
    assert data["joints"][2]["between"] == ["coupler", "ground"]
    np.testing.assert_allclose(point(data, "ground", "P_coupler_end"), [0.0, 0.0], rtol=0, atol=1e-12)
    np.testing.assert_allclose(point(data, "coupler", "P_coupler_end"), four_bar_drawing()["C"], rtol=0, atol=1e-12)
    assert any(
        "'rocker' is welded to 'ground' (the frames are 0.0873 m and 75.2 deg apart" in n for n in imported.notes
    )
    assert any("'rocker_pivot' is locked by the weld" in n for n in imported.notes)


def test_too_many_elements_are_refused(tmp_path):
    path = tmp_path / "flat.urdf"
    path.write_text('<robot name="r">' + "<a/>" * 60_000 + "</robot>")
    with pytest.raises(InputError, match="robot: more than 50000 XML elements"):
        import_urdf(str(path))


# delta.urdf (its header): base radius R, platform radius r, crank L, rod l, parallelogram half
# width w, arms at 0, 120, 240 deg, cranks 20 deg below the horizontal at joint value 0
DELTA, DELTA_SIDE = str(DATA / "delta.urdf"), str(DATA / "delta.yaml")
DR, DRP, DL, DLR, DW, DTH0 = 0.1, 0.03, 0.1, 0.25, 0.02, math.radians(20)


def delta_platform(q) -> np.ndarray:
    """The Delta by hand: crank i at 20 deg + q_i below the horizontal (a positive turn about the
    tangent u_i = (-sin g, cos g, 0) lowers it), and the translating platform's centre P at
    distance l from every C_i = E_i - r e_i (a parallelogram keeps the platform's orientation):
    the lower intersection of three spheres (trilateration)."""
    c = []
    for g, qi in zip((0.0, 2 * math.pi / 3, 4 * math.pi / 3), q):
        e = np.array([math.cos(g), math.sin(g), 0.0])
        th = DTH0 + qi
        c.append(DR * e + DL * (math.cos(th) * e - math.sin(th) * np.array([0.0, 0.0, 1.0])) - DRP * e)
    ex = (c[1] - c[0]) / np.linalg.norm(c[1] - c[0])
    i = float(ex @ (c[2] - c[0]))
    ey = (c[2] - c[0] - i * ex) / np.linalg.norm(c[2] - c[0] - i * ex)
    ez = np.cross(ex, ey)
    d, j = float(np.linalg.norm(c[1] - c[0])), float(ey @ (c[2] - c[0]))
    x = d / 2  # equal radii: (l^2 - l^2 + d^2) / (2 d)
    y = (i * i + j * j) / (2 * j) - i * x / j
    z = math.sqrt(DLR**2 - x * x - y * y)
    p = c[0] + x * ex + y * ey
    return min((p + z * ez, p - z * ez), key=lambda v: v[2])


def test_imported_delta_rods_and_forward_kinematics(tmp_path):
    """A spatial Delta from a URDF whose rods end in SPHERICAL joints and 3d closures: each rod
    between two S joints is a distance joint of length l, but the last one the platform would
    otherwise hang on only, which keeps its body with a U (no spin) and an S; 3 degrees of
    freedom; FK equals the trilateration of delta_platform (numpy) to 1e-9 m, the platform does
    not turn, and IK gives the actuators back."""
    imported = import_urdf(DELTA, DELTA_SIDE, platform="effector")
    data = load(imported.text)
    assert not imported.planar and data["platform"]["task"] == ["x", "y", "z"]
    kinds = [j["type"] for j in data["joints"]]
    assert kinds.count("R") == 3 and kinds.count("distance") == 5 and kinds.count("U") == kinds.count("S") == 1
    for j in data["joints"]:
        if j["type"] == "distance":
            assert j["length"] == pytest.approx(DLR, abs=1e-15)
    elbow = DR + DL * math.cos(DTH0)  # crank 1 (arm at 0 deg): its elbow pins at (elbow, +-w, -L sin 20 deg)
    np.testing.assert_allclose(point(data, "crank1", "P_rod1a"), [elbow, DW, -DL * math.sin(DTH0)], atol=1e-15)
    np.testing.assert_allclose(point(data, "crank1", "P_rod1b"), [elbow, -DW, -DL * math.sin(DTH0)], atol=1e-15)
    np.testing.assert_allclose(point(data, "platform", "P_effector"), delta_platform((0, 0, 0)), rtol=0, atol=1e-15)
    model = _model(tmp_path, imported.text)
    for q in ((0.0, 0.0, 0.0), (0.2, -0.1, 0.3), (-0.3, 0.25, 0.1)):
        fk = cn.forward_kinematics(model, list(q), NEWTON, backend=MAP)
        assert fk.status == Status.SOLVED, fk.message
        x = dict(zip(model.closure.x_names, fk.x))
        np.testing.assert_allclose([x["x"], x["y"], x["z"]], delta_platform(q), rtol=0, atol=1e-9)
        np.testing.assert_allclose([x["psi"], x["theta"], x["phi"]], 0.0, atol=1e-9)
        ik = cn.inverse_kinematics(model, [x["x"], x["y"], x["z"]])
        assert ik.status == Status.SOLVED, ik.message
        np.testing.assert_allclose(ik.q, q, rtol=0, atol=1e-9)


def test_cli_spatial_and_task(cli, tmp_path):
    out = tmp_path / "four.yaml"
    run = cli(
        "import", FOUR, "--sidecar", FOUR_SIDE, "--platform", "tracer", "--spatial", "--task", "phi", "-o", str(out)
    )
    assert run.code == 0, run.err
    assert run.out == f"{out}: 4 bodies, 4 joints (spatial) from {FOUR}\n"
    assert out.read_text() == import_urdf(FOUR, FOUR_SIDE, platform="tracer", planar=False, task=["phi"]).text
    run = cli("import", FOUR, "--sidecar", FOUR_SIDE, "--platform", "tracer", "--spatial", "-o", str(out))
    assert run.code == 2 and "--task: which task coordinates for 1 actuated joint(s)?" in run.err


def test_a_passive_joint_as_the_task(tmp_path):
    """--task rocker_pivot: the four-bar's output angle (Freudenstein's), its change from the
    drawing th4(q) - th4(0) by hand, to 1e-9 rad."""
    model = _model(tmp_path, import_urdf(FOUR, FOUR_SIDE, platform="tracer", task=["rocker_pivot"]).text)
    fk = cn.forward_kinematics(model, [0.5], NEWTON, backend=MAP)
    assert fk.status == Status.SOLVED, fk.message
    x = dict(zip(model.closure.x_names, fk.x))
    assert x["rocker_pivot"] == pytest.approx(four_bar_drawing(0.5)["th4"] - four_bar_drawing()["th4"], abs=1e-9)


def test_an_open_drawing_is_closed_at_import(tmp_path):
    """The rocker drawn 0.3 rad off (the loop open at the URDF's zero): the importer closes the
    loops with the crank held at 0 (Levenberg-Marquardt on the other joints, AD Jacobian), so
    the drawing is the assembled four-bar of four_bar_drawing (by hand), and each joint's
    coordinate stays the URDF's: the rocker's home is -0.3 rad, and its FK value is too."""
    text = Path(FOUR).read_text().replace('rpy="0 0 1.3129882281354577"', 'rpy="0 0 1.6129882281354577"')
    path = tmp_path / "open.urdf"
    path.write_text(text)
    imported = import_urdf(str(path), FOUR_SIDE, platform="tracer")
    data, hand = load(imported.text), four_bar_drawing()
    for body, name, value in (
        ("rocker", "P_coupler_end", "C"),
        ("coupler", "P_coupler_end", "C"),
        ("coupler", "P_tracer", "T"),
    ):
        np.testing.assert_allclose(point(data, body, name), hand[value], rtol=0, atol=1e-12)
    assert "configuration with the loops closed" in imported.text.splitlines()[1]
    joints = {j["name"]: j for j in data["joints"]}
    assert joints["rocker_pivot"]["home"] == pytest.approx(-0.3, abs=1e-12)
    assert "home" not in joints["crank"] and "home" not in joints["coupler_pin"]
    model = _model(tmp_path, imported.text)
    fk = cn.forward_kinematics(model, [0.5], NEWTON, backend=MAP)
    assert fk.status == Status.SOLVED, fk.message
    x = dict(zip(model.closure.x_names, fk.x))
    turn = four_bar_drawing(0.5)["th4"] - hand["th4"]
    assert x["rocker_pivot"] == pytest.approx(turn - 0.3, abs=1e-9)


def test_loops_that_cannot_close_keep_the_zero_configuration(tmp_path):
    """A 6d closure whose frames are 0.01 m apart along the axes of a planar linkage cannot
    close: the drawing stays the zero configuration, and the header says so."""
    text = Path(FIVE).read_text().replace('xyz="0.1 0.11180339887498947 -0.01"', 'xyz="0.1 0.11180339887498947 0"')
    path = tmp_path / "layers.urdf"
    path.write_text(text)
    imported = import_urdf(str(path), FIVE_SIDE)
    assert any(n.startswith("the loops do not close from the URDF's zero configuration") for n in imported.notes)
    np.testing.assert_allclose(point(load(imported.text), "distal2", "P_free2"), five_bar_drawing()["C2"], atol=1e-12)


def _four_bar_with_pin_chain(tmp_path, more_axes: list[str]) -> str:
    """four_bar.urdf with revolutes about ``more_axes`` after the coupler pin's (z), dummy links
    between them, all crossing at the pin (as the Gepetto examples write U and S joints)."""
    old = '<parent link="crank_link"/>\n    <child link="coupler"/>'
    text = Path(FOUR).read_text()
    assert old in text
    text = text.replace(old, '<parent link="crank_link"/>\n    <child link="pin0"/>')
    links = [f"pin{k}" for k in range(len(more_axes))] + ["coupler"]
    extra = "".join(f'  <link name="{lk}"/>\n' for lk in links[:-1])
    for k, axis in enumerate(more_axes):
        extra += (
            f'  <joint name="pin_r{k + 1}" type="continuous"><parent link="{links[k]}"/>'
            f'<child link="{links[k + 1]}"/><axis xyz="{axis}"/></joint>\n'
        )
    path = tmp_path / f"chain{len(more_axes)}.urdf"
    path.write_text(text.replace("</robot>", extra + "</robot>"))
    return str(path)


def test_revolutes_crossing_at_a_point_are_a_u_or_an_s(tmp_path):
    """Two revolutes crossing at the coupler pin (z, then the coupler's x) are one U joint with
    those axes in world directions; three (z, x, y) are one S joint; the dummy links between
    them are gone (the coupler's frame is turned by theta3 about z: x -> (cos, sin, 0))."""
    th3 = four_bar_drawing()["th3"]
    data = load(
        import_urdf(_four_bar_with_pin_chain(tmp_path, ["1 0 0"]), FOUR_SIDE, platform="tracer", task=["phi"]).text
    )
    assert set(data["bodies"]) == {"ground", "crank_link", "coupler", "rocker"}
    pin = next(j for j in data["joints"] if j["name"] == "coupler_pin")
    assert pin["type"] == "U" and pin["between"] == ["crank_link", "coupler"] and pin["at"] == "P_coupler_pin"
    np.testing.assert_allclose(pin["axes"], [[0, 0, 1], [math.cos(th3), math.sin(th3), 0]], rtol=0, atol=1e-12)
    np.testing.assert_allclose(point(data, "coupler", "P_coupler_pin"), [*four_bar_drawing()["B"], 0], atol=1e-12)
    path = _four_bar_with_pin_chain(tmp_path, ["1 0 0", "0 1 0"])
    data = load(import_urdf(path, FOUR_SIDE, platform="tracer", task=["phi"], planar=False).text)
    pin = next(j for j in data["joints"] if j["name"] == "coupler_pin")
    assert pin["type"] == "S" and pin["between"] == ["crank_link", "coupler"]
    assert set(data["bodies"]) == {"ground", "crank_link", "coupler", "rocker"}
