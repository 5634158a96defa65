"""``compliance_synthesis`` with flexible links (issue 25): a link of ``links`` that is a flexible
body takes the link's section as the beam's, so a link design changes its stiffness (EA, EI, GJ,
κGA in each element's K_e, symbolic) as well as its mass.

* the NLP's C at a design equals the forward six-axis compliance (`platform_compliance`'s) of
  the same hinges and beams, and its AD derivatives equal central differences of that forward
  analysis, for the hinge dimensions and the link section alike;
* the optimum re-evaluated by ``platform_compliance`` with the designed hinges and beams gives
  the same C;
* bad input is named."""

from __future__ import annotations

from pathlib import Path

import casadi as ca
import numpy as np
import pytest

from cpm_nlp.analysis.compliance_synthesis import ComplianceSynthesisNLP, Requirements
from cpm_nlp.core.errors import InputError
from cpm_nlp.kinds.compliance_synthesis import _six_axis_home, designed_hinges
from cpm_nlp.problems.file import load_problem, problem_from_dict, solve

ROOT = Path(__file__).resolve().parents[2]
PRS3_FILE = ROOT / "problems" / "prs3_compliance_synthesis.yaml"
#: the 3-PRS, sliders held, its legs 10 x 10 mm^2 beams (`links.legs` is the same bar): the
#: thinnest revolute notch (the smallest input stiffness) with the lateral compliance at most 6 um/N
FLEXIBLE = [
    "inputs.hinge_axes=all",
    "inputs.k_actuator=rigid",
    "inputs.compliance_max={px: 6 um/N}",
    "inputs.objective={minimize: input_stiffness}",
    "inputs.stroke={}",
    "inputs.link_design={legs: {width: [6 mm, 14 mm], height: [6 mm, 14 mm]}}",
]


def _bodies(n, b="10 mm", h="10 mm"):
    return f"inputs.bodies={{leg: {{between: [alpha, beta_m], section: {{b: {b}, h: {h}}}, elements: {n}}}}}"


def test_ad_derivatives_of_C_with_a_flexible_link_equal_central_differences():
    problem = load_problem(PRS3_FILE, [*FLEXIBLE[:4], FLEXIBLE[5], _bodies(2)])
    inputs, model = problem.inputs, problem.model
    assert inputs["flexible"] == {"leg": ("legs", inputs["links"]["legs"]["section"])}
    req = Requirements(**{**inputs["requirements"].__dict__, "stress_poses": []})
    nlp = ComplianceSynthesisNLP(
        model,
        inputs["hinge_set"],
        inputs["variables"],
        req,
        inputs["k_actuator"],
        inputs["M_x"],
        inputs["M_q"],
        inputs["links_resolved"],
        inputs["flexible"],
    )
    variables = inputs["variables"]
    assert [v.name for v in variables] == ["t_revolute", "r_revolute", "d_spherical", "width_legs", "height_legs"]
    C_fn = ca.Function("C", [nlp.y], [nlp.measures["C"], ca.jacobian(ca.vec(nlp.measures["C"]), nlp.y)])

    def forward(y):
        design = {v.name: float(v.value(y[i])) for i, v in enumerate(variables)}
        return _six_axis_home(model, designed_hinges(model, inputs, design), inputs["k_actuator"])

    y0 = np.array([0.3, 0.6, 0.5, 0.2, 0.7])
    C0, dC = (np.asarray(a, dtype=float) for a in C_fn(y0))
    np.testing.assert_allclose(C0, forward(y0), rtol=1e-8, atol=1e-9 * np.abs(C0).max())
    step = 1e-4  # of the scaled variables: the truncation error ~ step^2
    for i, v in enumerate(variables):
        up, down = y0.copy(), y0.copy()
        up[i] += step
        down[i] -= step
        fd = (forward(up) - forward(down)).ravel(order="F") / (2 * step)
        scale = np.abs(dC[:, i]).max()
        assert scale > 0, v.name  # every variable moves C: the link section through the beams
        assert np.max(np.abs(fd - dC[:, i])) < 2e-6 * scale, v.name


def test_the_optimum_is_platform_compliances_with_the_designed_beams():
    """The design re-evaluated by platform_compliance (six-axis hinges, the legs 14 x 14 mm beams
    at the optimum) gives the NLP's C; the stiffer legs let the notch be thinner than with the
    legs as given (the same requirement, the section fixed)."""
    problem = load_problem(PRS3_FILE, [*FLEXIBLE, "inputs.design={revolute: {t: [0.5 mm, 4 mm]}}", _bodies(1)])
    res = solve(problem)
    assert res.ok, res.message
    v = res.values
    assert "C_px" in v["active_constraints"].split(", ")
    assert v["C_px"] == pytest.approx(6e-6, rel=1e-7)
    assert v["recheck_deviation"] < 1e-8
    w, h = v["width_legs"], v["height_legs"]
    assert w == pytest.approx(14e-3, rel=1e-6) and h == pytest.approx(14e-3, rel=1e-6)  # the stiffest legs
    data = {
        "problem": "platform_compliance",
        "mechanism": problem.data["mechanism"],
        "inputs": {
            "hinge_axes": "all",
            "hinges": {"revolute": {"t": f"{v['t_revolute'] * 1e3!r} mm", "k": None}},
            "bodies": {
                "leg": {
                    "between": ["alpha", "beta_m"],
                    "section": {"b": f"{w * 1e3!r} mm", "h": f"{h * 1e3!r} mm"},
                    "elements": 1,
                }
            },
        },
    }
    forward = solve(problem_from_dict(data, base_dir=ROOT / "problems"))
    assert forward.ok, forward.message
    np.testing.assert_allclose(forward.values["C"], v["C"], rtol=1e-7, atol=1e-9 * np.abs(v["C"]).max())
    fixed = load_problem(PRS3_FILE, [*FLEXIBLE[:5], "inputs.design={revolute: {t: [0.5 mm, 4 mm]}}", _bodies(1)])
    fixed_res = solve(fixed)
    assert fixed_res.ok and fixed_res.values["t_revolute"] > v["t_revolute"]


@pytest.mark.parametrize(
    ("sets", "path", "words"),
    [
        ([*FLEXIBLE, _bodies(1, h="8 mm")], ("inputs", "links", "legs", "section"), "must be the link's"),
        (
            [*FLEXIBLE[2:], "inputs.k_actuator=0 N/m", _bodies(1)],
            ("inputs", "hinge_axes"),
            "hinge_axes: all",
        ),
    ],
)
def test_bad_flexible_link_designs_are_named(sets, path, words):
    with pytest.raises(InputError) as err:
        load_problem(PRS3_FILE, sets)
    assert err.value.path == path and words in err.value.message
