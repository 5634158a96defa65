"""The table of joint types (cpm_nlp/core/joints.py) against independent facts.

* Each type's degrees of freedom are the rank of its elementary motions' twists at a generic
  configuration (product of exponentials, computed here in numpy), and the textbook counts
  (Lynch & Park, Modern Robotics, 2017, Table 2.1: revolute, prismatic 1; cylindrical,
  universal 2; spherical 3); a planar type's motions stay in the plane, a spatial-only one's
  do not.
* The reader accepts exactly the table's types and names the nearest for any other; the
  generator takes exactly a planar or a spatial type in a planar or a spatial mechanism.
* Every letter can be drawn; every hinge type named is one of the flexure library's, and every
  hinge the shipped files put at a joint is one the table allows there.
"""

from __future__ import annotations

from pathlib import Path

import casadi as ca
import numpy as np
import pytest
import yaml

import cpm_nlp as cn
from cpm_nlp.analysis import compliance, hinge_types
from cpm_nlp.core.chains import JOINT_DOF
from cpm_nlp.core.joints import JOINT_LETTERS, JOINT_TYPES, LETTER_NAMES, joint_type, joint_types
from cpm_nlp.mechanisms import described
from cpm_nlp.mechanisms.described import builder, generate, motions, read_joint, spec
from cpm_nlp.plot import draw_mechanism, interactive

ROOT = Path(__file__).resolve().parents[2]
MECH = ROOT / "problems" / "mechanisms"

#: textbook degrees of freedom (Modern Robotics Table 2.1; a distance joint carries no coordinate)
TEXTBOOK_DOF = {"P": 1, "R": 1, "C": 2, "U": 2, "S": 3, "planar_R": 1, "planar_P": 1, "distance": 0}


def _skew(w):
    return np.array([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]])


def _exp(kind, axis, at, theta):
    """The rigid motion (R, p) of a rotation by theta about ``axis`` through ``at``, or a slide
    by theta along ``axis`` (Rodrigues)."""
    if kind == "P":
        return np.eye(3), theta * axis
    K = _skew(axis)
    R = np.eye(3) + np.sin(theta) * K + (1 - np.cos(theta)) * K @ K
    return R, at - R @ at


def _twist(kind, axis, at):
    """The unit twist (omega; v) of a rotation about ``axis`` through ``at``, or a slide along it."""
    if kind == "P":
        return np.concatenate([np.zeros(3), axis])
    return np.concatenate([axis, np.cross(at, axis)])


def _adjoint(R, p):
    return np.block([[R, np.zeros((3, 3))], [_skew(p) @ R, R]])


def _unit(v):
    return v / np.linalg.norm(v)


def _spatial_twists(t, rng, planar):
    """The joint's spatial twists at a generic configuration: twist k carried by the motions before it."""
    at = rng.normal(size=3)
    if planar:
        at[2] = 0.0
        axis = np.array([0.0, 0.0, 1.0]) if t.axis == "z" else _unit(np.append(rng.normal(size=2), 0.0))
    else:
        axis = _unit(rng.normal(size=3))
    axes = [_unit(rng.normal(size=3)) for _ in range(t.n_axes)]
    R, p = np.eye(3), np.zeros(3)
    cols = []
    for kind, source in t.motion:
        a = axis if source == "axis" else axes[source]
        cols.append(_adjoint(R, p) @ _twist(kind, a, at))
        Rk, pk = _exp(kind, a, at, rng.uniform(0.3, 1.2))
        R, p = R @ Rk, R @ pk + p
    return np.array(cols).T.reshape(6, -1)


@pytest.mark.parametrize("name", list(JOINT_TYPES))
def test_dof_is_the_rank_of_the_elementary_twists(name):
    t = JOINT_TYPES[name]
    rng = np.random.default_rng(7)
    xi = _spatial_twists(t, rng, planar=t.planar and not t.spatial)
    rank = np.linalg.matrix_rank(xi, tol=1e-9) if xi.size else 0
    assert rank == t.dof == TEXTBOOK_DOF[name]
    assert len(t.dims) == t.dof
    for (kind, _source), dim in zip(t.motion, t.dims):
        assert dim == {"R": "angle", "P": "length"}[kind]
    if t.planar and not t.spatial:  # a planar joint moves in the plane: omega along z, v in the plane
        assert np.allclose(xi[[0, 1, 5]], 0.0, atol=1e-12)
    elif t.dof:  # a spatial-only joint leaves it (that is why a planar mechanism refuses it)
        assert not np.allclose(xi[[0, 1, 5]], 0.0, atol=1e-6)


def test_motions_and_axes():
    for name, t in JOINT_TYPES.items():
        sources = [s for _kind, s in t.motion]
        # every motion takes its axis from 'axis' or from 'axes', never both kinds and all 'axes' used
        assert t.n_axes == len([s for s in sources if s != "axis"])
        assert (t.axis is not None) == ("axis" in sources), name
        assert len(t.default_axes) in (0, t.n_axes)
        assert t.actuable == (t.dof == 1), name  # one displacement to drive
        assert t.twin is None or (JOINT_TYPES[t.twin].twin == name and JOINT_TYPES[t.twin].motion == t.motion)
        assert not t.point or t.sphere  # a point joint turns about its point
    assert [n for n, t in JOINT_TYPES.items() if t.point] == ["S", "planar_R"]
    assert JOINT_DOF == {"P": 1, "R": 1, "C": 2, "U": 2, "S": 3}  # the chains: spatial joints with coordinates


def test_letters_and_the_drawings():
    assert {n: t.letter for n, t in JOINT_TYPES.items()} == {
        "P": "P",
        "R": "R",
        "C": "C",
        "U": "U",
        "S": "S",
        "planar_R": "R",
        "planar_P": "P",
        "distance": "S",  # an S-S strut
    }
    drawn = (draw_mechanism.JOINT_MARKER, LETTER_NAMES, interactive._JOINT_SYMBOL)
    assert set(JOINT_LETTERS) == set(drawn[0]) == set(drawn[1]) == set(drawn[2])
    assert motions.LETTER == {n: t.letter for n, t in JOINT_TYPES.items()}
    # a planar file's type of each joint (the URDF writer's planar layout reads it)
    assert {n: t.in_plane for n, t in JOINT_TYPES.items()} == {
        "P": "planar_P",
        "R": "planar_R",
        "C": None,
        "U": None,
        "S": "planar_R",  # a point joint: it turns about z in the plane
        "planar_R": "planar_R",
        "planar_P": "planar_P",
        "distance": "distance",
    }
    for t in JOINT_TYPES.values():
        assert t.in_plane is None or (JOINT_TYPES[t.in_plane].planar and JOINT_TYPES[t.in_plane].letter in "RPS")


def test_generate_aliases_are_the_table():
    """The names other modules import from motions.py are the table's."""
    assert motions.POINT_JOINTS == {"S", "planar_R"}
    assert motions.SPHERE_JOINTS == {"U", "S", "planar_R"}
    assert motions.JOINT_DIMS == {
        "P": "length",
        "planar_P": "length",
        "R": "angle",
        "planar_R": "angle",
        "U": "angle",
        "S": "angle",
    }


def test_the_reader_accepts_exactly_the_table():
    for name in JOINT_TYPES:
        assert read_joint.read_joint({"type": name, "at": [0, 0, 0]}, ("legs", 0, "joints", 0), {}).type == name
    for bad, near in (("planar_r", "planar_R"), ("distanse", "distance"), ("r", "R"), ("sphere", None)):
        with pytest.raises(cn.InputError) as info:
            read_joint.read_joint({"type": bad, "at": [0, 0, 0]}, ("legs", 0, "joints", 1), {})
        msg = str(info.value)
        assert "legs[0].joints[1].type" in msg and "expected one of: " + ", ".join(JOINT_TYPES) in msg, msg
        if near:
            assert f"did you mean '{near}'" in msg, msg
    for bad in (None, ["R"], 3):  # missing or not a name
        with pytest.raises(cn.InputError, match="unknown joint type"):
            joint_type(bad, ("type",))
    assert "one of " + ", ".join(JOINT_TYPES) == read_joint.JOINT_KEYS["type"]


def test_the_generator_takes_the_planar_or_the_spatial_types(tmp_path):
    assert joint_types(True) == ("planar_R", "planar_P", "distance")
    assert joint_types(False) == ("P", "R", "C", "U", "S", "distance")
    text = (MECH / "five_bar.yaml").read_text().replace("name: five_bar", "name: five_bad").split("examples:")[0]
    for spatial in ("R", "S"):
        f = tmp_path / f"{spatial}.yaml"
        f.write_text(
            text.replace("{type: planar_R, at: [-cx, cy], coordinates: [e1]}", f"{{type: {spatial}, at: [-cx, cy]}}")
        )
        with pytest.raises(cn.InputError) as info:
            described.load_file(f)
        msg = str(info.value)
        assert "a planar mechanism takes planar_R, planar_P, distance joints" in msg, msg
        assert ("did you mean 'planar_R'" in msg) == (spatial == "R"), msg


def test_hinge_names_are_the_flexure_librarys():
    library = set(hinge_types.HINGE_TABLE)
    assert set(compliance.HINGE_TYPES) | set(hinge_types.LIMIT_TYPES) == library
    for name, t in JOINT_TYPES.items():
        assert set(t.hinges) <= library, name
        if t.hinges:  # the library's hinges bend and twist: a joint that carries one turns
            assert any(kind == "R" for kind, _source in t.motion), name
    used = {h for t in JOINT_TYPES.values() for h in t.hinges}
    assert used == library  # every hinge of the library can sit somewhere
    for name, h in hinge_types.HINGE_TABLE.items():  # the table reads its places from the joint types
        assert h.name == name and h.joints == tuple(j for j, t in JOINT_TYPES.items() if name in t.hinges)
        assert h.stiffness is not None or h.rotation is not None, name  # it gives something
        assert (h.stiffness is None) == (h.six_axis is None) == (h.stress is None), name
        assert (h.source != "") == (h.stiffness is not None) and (h.limit_source != "") == (h.rotation is not None)
        assert all(o.kind == "length" for o in h.parameters), name


def _file_joints():
    """mechanism file name -> (description, coordinate or family -> joint type), of every shipped file."""
    out = {}
    for f in sorted(MECH.glob("*.yaml")):
        d = described.read_description(f)
        types = {}
        for leg in d.legs:
            for j in leg.joints:
                for c in j.coordinates:
                    types[c] = types[builder.family(c)] = j.type
        out[f.name] = (d, types)
    return out


def _at(where, hinges, types):
    """(where, hinge type, joint type) of hinge declarations ``name -> {joints, type}``."""
    for name, h in hinges.items():
        targets = h["joints"].values() if isinstance(h["joints"], dict) else [h["joints"]]
        for c in targets:  # a hinge on a passive expression (no joint of the file): no joint type
            yield f"{where} {name}", h["type"], types.get(c)


def _declared_hinges():
    """(where, hinge type, joint type) of every hinge the shipped files put at a joint: a joint's
    ``flexure``, a mechanism file's ``stiffness.hinges``, a problem file's ``inputs.hinges`` on a
    mechanism file."""
    files = _file_joints()
    for name, (d, types) in files.items():
        for leg in d.legs:
            yield from ((name, j.flexure.values["hinge"], j.type) for j in leg.joints if j.flexure is not None)
        if d.stiffness is not None:
            yield from _at(name, d.stiffness.hinges, types)
    for f in sorted((ROOT / "problems").glob("*.yaml")):
        data = yaml.safe_load(f.read_text())
        mech, hinges = data.get("mechanism"), (data.get("inputs") or {}).get("hinges")
        if isinstance(mech, dict) and "file" in mech and hinges:
            yield from _at(f.name, hinges, files[Path(mech["file"]).name][1])


def test_the_hinges_the_files_declare_sit_where_the_table_allows():
    seen, on_expressions = set(), set()
    for where, hinge, jt in _declared_hinges():
        if jt is None:
            on_expressions.add(where)
            continue
        assert hinge in JOINT_TYPES[jt].hinges, f"{where}: a {hinge} hinge at a {jt} joint"
        seen.add((hinge, jt))
    # the RPR file's R and U flexures sit on its passive angles (eq 13), written as expressions
    # beside S-P-S legs: the table cannot check them (tests/corpus/rpr_joints.yaml has the joints)
    assert on_expressions == {"rpr.yaml R", "rpr.yaml U"}
    # prs3 (notch at R, with the papers' formula; filleted rod at S), the five-bar and the 3-RRR
    # (notches at planar R)
    assert {("circular_notch_paros_weisbord", "R"), ("filleted_rod", "S"), ("circular_notch", "planar_R")} <= seen


def test_the_guide_table_is_the_table():
    """docs/site/guide/mechanism-files.md lists every joint type as the table has it."""
    text = (ROOT / "docs" / "site" / "guide" / "mechanism-files.md").read_text()
    rows = [[c.strip() for c in line.strip().strip("|").split("|")] for line in text.splitlines()]
    rows = [r for r in rows if len(r) == 6 and r[0].startswith("`") and r[0].strip("`") in JOINT_TYPES]
    assert [r[0].strip("`") for r in rows] == list(JOINT_TYPES)
    words = {0: "none", 1: "1", 2: "2", 3: "3"}
    for name, coords, _axes, where, actuated, hinges in rows:
        t = JOINT_TYPES[name.strip("`")]
        if len(set(t.dims)) <= 1:
            assert coords.startswith(words[t.dof]) and (not t.dof or t.dims[0] in coords), (name, coords)
        else:
            assert coords == ", ".join(t.dims), (name, coords)
        assert where == ("both" if t.planar and t.spatial else "planar" if t.planar else "spatial"), name
        assert actuated == ("yes" if t.actuable else "no"), name
        listed = [h.split(" (")[0] for h in hinges.split(", ")] if hinges != "none" else []
        assert listed == list(t.hinges), name


def test_home_values_take_each_coordinates_dimension():
    """A C joint's home is (angle, length), as its motions say; the generator checks each."""
    gen = generate.Generator(described.read_description(MECH / "prs3.yaml"))
    gen.platform()
    eye = ca.SX.eye(3)
    ok = spec.Joint("C", at=[0, 0, 0], axis=[0, 0, 1], home=("10 deg", "1 mm"), path=("legs", 0, "joints", 0))
    home = [float(ca.DM(h)) for h in gen.resolve(ok, gen.env, eye).home]
    np.testing.assert_allclose(home, [np.radians(10), 1e-3], rtol=1e-15)
    bad = spec.Joint("C", at=[0, 0, 0], axis=[0, 0, 1], home=("1 mm", 0), path=("legs", 0, "joints", 0))
    with pytest.raises(cn.InputError, match=r"legs\[0\]\.joints\[0\]\.home\[0\]: expected an angle"):
        gen.resolve(bad, gen.env, eye)
