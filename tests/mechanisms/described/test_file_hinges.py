"""Hinges declared by a mechanism file (its ``stiffness:`` section, issue 12).

The file twin of the 3-PRS (problems/mechanisms/prs3.yaml) declares the hinges and
material of the built-in prs3's STIFFNESS, so the compliance kinds need no
``inputs.hinges`` on it and give the built-in's results; a bad hinge in a mechanism
file is an error when the mechanism loads, naming the file and the key path.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

import cpm_nlp as cn
from cpm_nlp.analysis import compliance as cm
from cpm_nlp.mechanisms import described
from cpm_nlp.problems.file import load_problem, solve

ROOT = Path(__file__).resolve().parents[3]
PROBLEMS = ROOT / "problems"
MECH_TEXT = (
    (PROBLEMS / "mechanisms" / "prs3.yaml")
    .read_text()
    .replace("\nname: prs3\n", "\nname: prs3_hinged\n")
    .split("examples:")[0]
)
PROBLEM = """problem: actuator_forces
mechanism:
  file: m.yaml
  parameters: {b: 47.91 mm, L: 109.215 mm, alpha0: 45 deg}
inputs: {s1: 0.935 mm, s2: 0.935 mm, s3: 0.935 mm, stress_limit: true}
"""


def test_file_declares_the_hinges_of_the_reference():
    """The hinges, material and source of prs3-ruiz.md sections 4-5 in the mechanism file
    (the built-in prs3) equal the hand-written module's STIFFNESS, kept in
    tests/reference/prs3_closures.py."""
    from tests.reference import prs3_closures

    reference = prs3_closures.STIFFNESS
    mech = described.load_file(PROBLEMS / "mechanisms" / "prs3.yaml")
    assert cn.mechanism_type("prs3") is mech
    stiffness = mech.part(cn.JointStiffness)
    assert stiffness is not None and set(stiffness.hinges) == set(reference.hinges)
    for name, spec in reference.hinges.items():
        assert stiffness.hinges[name] == spec, name
    assert stiffness.material == reference.material
    assert stiffness.source == reference.source
    assert "prs3_file_table2_forces.yaml" in " ".join(mech.problem_files)
    # the same hinge set (stiffness over the joint vector) on both models
    params = {"b": "47.91 mm", "L": "109.215 mm", "alpha0": "45 deg"}
    hf = cm.hinge_set(cn.build_model("prs3", params), None)
    hb = cm.hinge_set(prs3_closures.reference_model(params), None)
    assert hf.names == hb.names
    assert list(hf.k) == list(hb.k)


def test_file_twin_table2_forces_equal_the_builtin():
    """prs3_file_table2_forces.yaml (the mechanism named by its file) gives the results of
    prs3_table2_forces.yaml (named by its type, prs3): the same mechanism, by two routes."""
    ref = solve(load_problem(PROBLEMS / "prs3_table2_forces.yaml"))
    res = solve(load_problem(PROBLEMS / "prs3_file_table2_forces.yaml"))
    assert ref.ok and res.ok
    for name in ("F1", "F2", "F3", "stress_max", "dz_at_allowable"):
        assert res.values[name] == pytest.approx(ref.values[name], rel=1e-9, abs=0), name
    assert load_problem(PROBLEMS / "prs3_file_table2_forces.yaml").reproduce is None


def _files(tmp_path, old: str = "", new: str = "") -> Path:
    assert old in MECH_TEXT
    (tmp_path / "m.yaml").write_text(MECH_TEXT.replace(old, new, 1))
    f = tmp_path / "p.yaml"
    f.write_text(PROBLEM)
    return f


def _load_error(tmp_path, old: str, new: str) -> str:
    _files(tmp_path, old, new)
    with pytest.raises(cn.InputError) as info:
        described.load_file(tmp_path / "m.yaml")
    return str(info.value)


BAD = [
    # (replace, with, the key path, words of the message)
    ("      t: 2 mm", "      t: 17 mm", "stiffness.hinges.revolute.t", "impossible circular notch"),
    ("      l: 5 mm", "      l: -5 mm", "stiffness.hinges.spherical.l", "> 0 mm"),
    ("      joints: alpha  ", "      joints: alfa  ", "stiffness.hinges.revolute.joints.bend", "did you mean 'alpha'"),
    (
        "      type: circular_notch",
        "      tpye: circular_notch",
        "stiffness.hinges.revolute.tpye",
        "did you mean 'type'",
    ),
    ("      type: filleted_rod", "      type: filleted_road", "stiffness.hinges.spherical.type", "did you mean"),
    (
        "  material: {name: Al 7075 (prs3-ruiz), E",
        "  material: {name: Al 7075 (prs3-ruiz), Young: 1, E",
        "stiffness.material",
        "Young",
    ),
    ("  hinges:", "  hinge:", "stiffness", "did you mean 'hinges'"),
]


@pytest.mark.parametrize("old,new,key,words", BAD)
def test_bad_hinge_in_a_mechanism_file_is_an_error_at_load(tmp_path, old, new, key, words):
    msg = _load_error(tmp_path, old, new)
    assert str(tmp_path / "m.yaml") in msg and key in msg and words in msg, msg


def test_unknown_material_name(tmp_path):
    text = MECH_TEXT.split("  material: {")[0] + "  material: Al 7057-T6\n"
    (tmp_path / "m.yaml").write_text(text)
    with pytest.raises(cn.InputError) as info:
        described.load_file(tmp_path / "m.yaml")
    assert "stiffness.material" in str(info.value) and "did you mean 'Al 7075-T6'" in str(info.value)


def _cli(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "cpm_nlp", *args], capture_output=True, text=True, cwd=ROOT)


def _exits_2(f: Path, *needles: str) -> str:
    r = _cli("solve", str(f))
    out = r.stdout + r.stderr
    assert r.returncode == 2, out
    assert "Traceback" not in out and len(out.strip().splitlines()) == 1, out
    for n in (str(f), *needles):
        assert n in out, out
    return out


@pytest.mark.parametrize("case", [0, 1, 2, 3])
def test_bad_hinge_in_a_mechanism_file_exits_2(tmp_path, case):
    old, new, key, words = BAD[case]
    f = _files(tmp_path, old, new)
    _exits_2(f, str(tmp_path / "m.yaml"), key, words)


def test_stress_limit_with_a_material_without_yield_strength_exits_2(tmp_path):
    f = _files(
        tmp_path,
        "yield_strength: 503 MPa,\n             allowable: 400 MPa}",
        "}",
    )
    # without a stress limit the material is enough (stiffness only)
    res = solve(load_problem(f, ["inputs.stress_limit=false"]))
    assert res.ok
    _exits_2(f, str(tmp_path / "m.yaml"), "stiffness.material", "yield strength")


def test_load_in_the_wrong_dimension_exits_2(tmp_path):
    f = _files(tmp_path)
    f.write_text(PROBLEM.replace("stress_limit: true}", "load: {pz: 1 N*m}}"))
    _exits_2(f, "inputs.load.pz", "is not a force")
    f.write_text(PROBLEM.replace("stress_limit: true}", "load: {psi: 1 N}}"))
    _exits_2(f, "inputs.load.psi", "is not a moment")


def test_inline_description_declares_its_hinges():
    """``mechanism: {description: ...}`` carries its stiffness section too, checked at load."""
    import yaml

    desc = yaml.safe_load(MECH_TEXT.replace("name: prs3_hinged", "name: prs3_inline"))
    data = yaml.safe_load(PROBLEM)
    data["mechanism"] = {"description": desc, "parameters": data["mechanism"]["parameters"]}
    data["inputs"]["stress_limit"] = False
    res = solve(cn.problem_from_dict(data))
    ref = solve(load_problem(PROBLEMS / "prs3_table2_forces.yaml"))
    assert res.values["F1"] == pytest.approx(ref.values["F1"], rel=1e-9)
    desc["stiffness"]["hinges"]["revolute"]["r"] = "0.5 mm"
    with pytest.raises(cn.InputError, match=r"^mechanism\.description\.stiffness\.hinges\.revolute\.t: impossible"):
        cn.problem_from_dict(data)
