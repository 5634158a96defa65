"""The certificate that a mode search missed no real mode in its region (issue 20, item 2,
stretch): interval branch and bound on the closures (cpm_nlp/analysis/mode_certificate.py).
Certified on small systems, against the closed form where there is one; never certified when a
mode is missing; honestly not proven on a 6-6 platform.  Its time is measured by
benchmarks/bench_assembly_modes.py (no timing is asserted here)."""

import math

import numpy as np

from cpm_nlp.analysis.assembly import assembly_modes
from cpm_nlp.analysis.mode_certificate import certify_modes
from cpm_nlp.mechanisms.described import from_dict, load_file
from cpm_nlp.problems.file import problem_from_dict, solve
from tests.conftest import ROOT
from tests.dietmaier import LENGTHS
from tests.dietmaier import model as dietmaier_model

MECHANISMS = ROOT / "problems" / "mechanisms"


def four_bar():
    """Freudenstein's four-bar (crank a2 = 1, coupler a3 = 3.5, rocker a4 = 3, ground g = 4),
    closed by two expressions (also tests/analysis/test_mode_search.py's)."""
    desc = {
        "name": "four_bar_certificate",
        "parameters": {
            k: {"dimension": "length", "default": f"{v} m"} for k, v in (("a2", 1), ("a3", 3.5), ("a4", 3), ("g", 4))
        },
        "platform": {
            "coordinates": {"theta3": "angle", "theta4": "angle"},
            "position": "[0*g, 0*g, 0*g]",
            "rotation": [],
            "task": ["theta4"],
        },
        "actuators": {"theta2": {"dimension": "angle", "home": 0}},
        "closures": [
            "a2*cos(theta2) + a3*cos(theta3) - a4*cos(theta4) - g",
            "a2*sin(theta2) + a3*sin(theta3) - a4*sin(theta4)",
        ],
    }
    cx = 1 + (3.5**2 - 3**2 + 9) / 6  # home: theta2 = 0, the coupler's and the rocker's circles
    cy = math.sqrt(3.5**2 - (cx - 1) ** 2)
    desc["platform"]["home"] = {"theta3": math.atan2(cy, cx - 1), "theta4": math.atan2(cy, cx - 4)}
    mech = from_dict(desc)
    return mech.model(mech.closure(), {}, {}, ())


def file_model(name):
    mech = load_file(MECHANISMS / f"{name}.yaml")
    return mech.model(mech.closure(), {}, {}, ())


def test_four_bar_certified_two_modes_as_the_closed_form():
    """Crank at 70 deg: the closed form has two assembly modes (two circle intersections); the
    search finds 2 and the certificate proves there is no other in (-pi, pi]^2."""
    model = four_bar()
    found = assembly_modes(model, [math.radians(70)], starts=300)
    assert found.count == 2
    cert = certify_modes(model, found)
    assert cert.certified and cert.open == 0 and cert.reason == ""
    assert cert.settled >= 2 and cert.excluded > 0


def test_a_missing_mode_is_never_certified_away():
    model = four_bar()
    found = assembly_modes(model, [math.radians(70)], starts=300)
    found.modes = found.modes[:1]
    cert = certify_modes(model, found, max_boxes=20_000)
    assert not cert.certified and cert.open > 0 and cert.reason


def test_five_bar_and_3rrr_certified():
    for name, dq in (("five_bar", 0.1), ("rrr3", 0.0)):
        model = file_model(name)
        found = assembly_modes(model, model.q_home + dq, starts=2000)
        cert = certify_modes(model, found)
        assert cert.certified, (name, cert)
        for md in found.modes:
            assert np.max(np.abs(np.asarray(model.closure.fk_residual(md.x, np.r_[md.q, model.p])))) < 1e-12


def test_problem_kind_reports_the_certificate():
    data = {
        "problem": "forward_kinematics",
        "mechanism": {"file": str(MECHANISMS / "five_bar.yaml")},
        "inputs": {"q1": "118 deg", "q2": "63 deg", "assembly_modes": "all", "mode_starts": 500},
    }
    data["inputs"]["mode_certificate"] = True
    res = solve(problem_from_dict(data))
    cert = res.values["mode_certificate"]
    assert cert["certified"] and cert["boxes"] > 0
    assert "certificate: no other real mode in the region" in res.values["mode_search"]


def test_6_6_platform_not_proven_within_a_budget():
    """Dietmaier's platform: 6 coordinates, three angles over a full turn; the certificate does
    not finish (the benchmark: 200 000 sub-boxes in about 30 s, none settled) and says so."""
    model = dietmaier_model()
    found = assembly_modes(model, LENGTHS, starts=500)
    cert = certify_modes(model, found, max_boxes=2000)
    assert not cert.certified and "budget of 2000 sub-boxes" in cert.reason
