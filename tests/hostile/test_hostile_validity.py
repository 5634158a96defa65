"""Hostile inputs of issue 19, "bad input accepted, and results outside their model given
without a word": bounds with low > high, a coordinate name declared twice and an S joint
with dependent axes are refused (exit 2, one line naming the key, nothing written); a notch
hinge thicker than its width, the 3-PRS revolute notch, a 1 MN load, a stress above yield
and a pose near a singularity are solved with warnings, in the JSON and in the printed
output, never as if they were clean."""

from __future__ import annotations

import json
import shutil
import time
from pathlib import Path

import pytest

from cpm_nlp.core.result import Result, ResultWarning, Status
from cpm_nlp.plot.figures import from_result
from tests.conftest import run_cli
from tests.hostile.test_hostile import HANG_S, assert_refused, dump, snapshot

ROOT = Path(__file__).resolve().parents[2]
PROBLEMS = ROOT / "problems"
MECHANISMS = PROBLEMS / "mechanisms"


@pytest.fixture
def work(tmp_path):
    """A folder with the shipped mechanism files (to edit) beside the problem files."""
    shutil.copytree(MECHANISMS, tmp_path / "mechanisms")
    return tmp_path


def _refused(work: Path, problem: Path, key: str) -> str:
    before = snapshot(work)
    t0 = time.perf_counter()
    out = work / "out.json"
    run = run_cli("solve", str(problem), "-o", str(out))
    elapsed = time.perf_counter() - t0
    line = assert_refused(run, problem.name, key)
    assert snapshot(work) == before  # nothing written, nothing changed
    assert not out.exists()
    assert elapsed < HANG_S, elapsed
    return line


def _mechanism_problem(work: Path, mech: str, edit: tuple[str, str], problem: str) -> Path:
    text = (work / "mechanisms" / mech).read_text()
    assert edit[0] in text
    text = text.replace("\nname: prs3\n", "\nname: bad_prs3\n")  # a changed copy of a built-in's file: its own name
    (work / "mechanisms" / f"bad_{mech}").write_text(text.replace(edit[0], edit[1]))
    data = (PROBLEMS / problem).read_text().replace(f"mechanisms/{mech}", f"mechanisms/bad_{mech}")
    target = work / "p.yaml"
    target.write_text(data)
    return target


# -- refusals -----------------------------------------------------------------------------------


def test_parameter_bounds_with_low_above_high_are_refused(work):
    p = _mechanism_problem(
        work,
        "delta.yaml",
        ("default: 100 mm, bounds: [0 m, 10 m]", "default: 100 mm, bounds: [10 m, 0 m]"),
        "delta_forward_kinematics.yaml",
    )
    line = _refused(work, p, "parameters.rb.bounds")
    assert "low < high" in line and "bad_delta.yaml" in line


def test_platform_bounds_with_low_above_high_are_refused(work):
    p = _mechanism_problem(work, "prs3.yaml", ("pz: [0, 2*L]", "pz: [2*L, 0]"), "prs3_file_forward_kinematics.yaml")
    line = _refused(work, p, "platform.bounds.pz")
    assert "low < high" in line


def test_a_coordinate_name_declared_twice_is_refused(work):
    """Every copy of the repeated leg names its revolute "alpha": one value would be lost."""
    p = _mechanism_problem(
        work, "prs3.yaml", ('coordinates: ["alpha{i}"]', 'coordinates: ["alpha"]'), "prs3_file_forward_kinematics.yaml"
    )
    line = _refused(work, p, "legs[0].joints[1].coordinates")
    assert "'alpha' is declared twice" in line


def test_an_s_joint_with_three_parallel_axes_is_refused(work):
    old = "axes: [[0, -1, 0], [sin(alpha0), 0, cos(alpha0)], [-cos(alpha0), 0, sin(alpha0)]]"
    p = _mechanism_problem(
        work, "prs3.yaml", (old, "axes: [[0, 0, 1], [0, 0, 1], [0, 0, 1]]"), "prs3_file_forward_kinematics.yaml"
    )
    line = _refused(work, p, "legs[0].joints[2].axes")
    assert "independent axes" in line


def test_an_s_joint_whose_axes_become_dependent_with_the_parameters_is_refused(work):
    old = "axes: [[0, -1, 0], [sin(alpha0), 0, cos(alpha0)], [-cos(alpha0), 0, sin(alpha0)]]"
    new = "axes: [[0, -1, 0], [sin(alpha0), 0, cos(alpha0)], [sin(alpha0), 0, cos(alpha0)]]"
    p = _mechanism_problem(work, "prs3.yaml", (old, new), "prs3_file_forward_kinematics.yaml")
    line = _refused(work, p, "legs[0].joints[2].axes")
    assert "linearly dependent" in line


def test_problem_bounds_with_low_above_high_are_refused(tmp_path):
    data = {
        "problem": "forward_kinematics",
        "mechanism": {
            "type": "prs3",
            "parameters": {"b": "47.91 mm", "L": "109.215 mm"},
            "limits": {"s": ["10 m", "0 m"]},
        },
        "inputs": {"s1": "0 mm", "s2": "0 mm", "s3": "0 mm"},
    }
    p = tmp_path / "p.yaml"
    p.write_text(dump(data))
    _refused(tmp_path, p, "mechanism.limits.s")


# -- warnings -----------------------------------------------------------------------------------


def _solve(problem: Path, *sets: str) -> tuple[dict, str]:
    """(the JSON result, the printed output) of one problem; exit 0 (solved, with warnings)."""
    args = [a for s in sets for a in ("--set", s)]
    js = run_cli("solve", str(problem), "--json", *args)
    assert js.code == 0, js.err
    printed = run_cli("solve", str(problem), *args)
    assert printed.code == 0, printed.err
    assert "Traceback" not in js.err + printed.err
    return json.loads(js.out), printed.out


def _assert_warned(result: dict, printed: str, code: str) -> list[dict]:
    found = [w for w in result["warnings"] if w["code"] == code]
    assert found, result["warnings"]
    assert result["status"] == "solved"
    n = len(result["warnings"])
    assert f"solved, with {n} warning" in printed  # the status line does not read as clean
    for w in found:
        assert f"warning: {w['message']}" in printed
    return found


def test_a_notch_hinge_thicker_than_its_width_is_flagged():
    result, printed = _solve(
        PROBLEMS / "prs3_table2_forces.yaml", "inputs.hinges.revolute.t=9 mm", "inputs.hinges.revolute.w=5 mm"
    )
    found = _assert_warned(result, printed, "hinge_geometry")
    assert any(w["where"] == "hinge revolute: t > w" and w["value"] == pytest.approx(9e-3) for w in found)


def test_the_3prs_revolute_notch_deeper_than_wide_is_flagged_and_reproduce_keeps_working():
    """t + 2r = 18 mm > w = 10 mm: the torsion formula is used outside its range (a warning,
    so the paper's own hinge is still solved)."""
    result, printed = _solve(PROBLEMS / "prs3_table2_forces.yaml")
    found = _assert_warned(result, printed, "hinge_geometry")
    assert found[0]["where"] == "hinge revolute: t + 2r > w"
    assert found[0]["value"] == pytest.approx(18e-3) and found[0]["limit"] == pytest.approx(10e-3)
    run = run_cli("reproduce", str(PROBLEMS / "prs3_table2_forces.yaml"))
    assert run.code == 0, run.out + run.err


def test_a_1_mn_load_is_flagged():
    """The six-axis compliance problem under 1 MN: far beyond yield, the formulas' deflection
    range and the linear range; solved, never as if it were clean."""
    result, printed = _solve(PROBLEMS / "prs3_cutting_force.yaml", "inputs.load.px=1 MN")
    codes = {w["code"] for w in result["warnings"]}
    assert {"stress_above_yield", "deflection_beyond_formula", "beyond_linear_range"} <= codes
    for code in ("stress_above_yield", "deflection_beyond_formula", "beyond_linear_range"):
        _assert_warned(result, printed, code)
    stress = next(w for w in result["warnings"] if w["code"] == "stress_above_yield")
    assert stress["value"] > stress["limit"] == pytest.approx(503e6)


def test_the_shipped_1_n_load_has_no_load_warning():
    result, _ = _solve(PROBLEMS / "prs3_cutting_force.yaml")
    assert {w["code"] for w in result["warnings"]} == {"hinge_geometry"}


def test_a_stress_above_yield_is_flagged():
    """Table 2's third column, 2.865 mm: the model's revolute stress is 538 MPa > 503 MPa."""
    result, printed = _solve(
        PROBLEMS / "prs3_table2_forces.yaml", "inputs.s1=2.865 mm", "inputs.s2=2.865 mm", "inputs.s3=2.865 mm"
    )
    (w,) = _assert_warned(result, printed, "stress_above_yield")
    assert w["where"] == "hinge revolute" and w["value"] > w["limit"] == pytest.approx(503e6)


def test_a_pose_near_a_singularity_is_flagged(tmp_path):
    shutil.copytree(MECHANISMS, tmp_path / "mechanisms")
    p = tmp_path / "ik.yaml"
    p.write_text(
        dump(
            {
                "problem": "inverse_kinematics",
                "mechanism": {"file": "mechanisms/rrr3.yaml"},
                "inputs": {"x": "0 mm", "y": "0 mm", "phi": "28.955 deg"},
            }
        )
    )
    result, printed = _solve(p)
    (w,) = _assert_warned(result, printed, "near_singular")
    assert w["value"] > w["limit"] == 1e6
    clean, printed_clean = _solve(p, "inputs.phi=0 deg")
    assert clean["warnings"] == [] and "warning" not in printed_clean


def test_warnings_survive_the_json_round_trip(tmp_path):
    out = tmp_path / "r.json"
    run = run_cli("solve", str(PROBLEMS / "prs3_table2_forces.yaml"), "-o", str(out), "-q")
    assert run.code == 0, run.err
    data = json.loads(out.read_text())
    back = from_result(data, str(out))
    assert [w.code for w in back.warnings] == [w["code"] for w in data["warnings"]] == ["hinge_geometry"]
    assert isinstance(back.warnings[0], ResultWarning)


def test_a_clean_result_has_an_empty_warnings_list():
    r = Result("forward_kinematics", Status.SOLVED)
    assert r.to_dict()["warnings"] == []
    r.warn(ResultWarning("near_singular", "m", "Phi_x", 1e7, 1e6), ResultWarning("near_singular", "m", "Phi_x"))
    assert len(r.warnings) == 1  # one per code and place
