"""The ``compliance_synthesis`` kind (cpm_nlp.analysis.compliance_synthesis; issue 25 item 5).

* the optimum satisfies the KKT conditions, and the constraints it reports active are at
  their bounds (and the inactive ones below, with zero multipliers);
* the design re-evaluated by the ordinary forward kinds (platform_compliance,
  actuator_forces, natural_frequencies) gives the same stiffness, stress and frequency;
* the NLP's AD derivatives equal central differences of the forward analysis;
* an infeasible requirement returns status infeasible, exit 1 and no design numbers;
* bad input is named (exit 2)."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from cpm_nlp.analysis import compliance as cm
from cpm_nlp.analysis.compliance_synthesis import ComplianceSynthesisNLP, Requirements
from cpm_nlp.core.errors import InputError
from cpm_nlp.kinds.compliance_synthesis import ComplianceSynthesis, _six_axis_home, designed_hinges
from cpm_nlp.problems.file import load_problem, problem_from_dict, solve

ROOT = Path(__file__).resolve().parents[2]
PRS3_FILE = ROOT / "problems" / "prs3_compliance_synthesis.yaml"
RRR3_FILE = ROOT / "problems" / "rrr3_compliance_synthesis.yaml"


def _nlp(problem):
    """The NLP of a loaded problem, as the kind builds it, with its stroke corners."""
    inputs = problem.inputs
    corners, msg = ComplianceSynthesis._corners(problem.model, inputs["stroke_box"], problem.solver)
    assert not msg
    req = Requirements(**{**inputs["requirements"].__dict__, "stress_poses": corners})
    nlp = ComplianceSynthesisNLP(
        problem.model,
        inputs["hinge_set"],
        inputs["variables"],
        req,
        inputs["k_actuator"],
        inputs["M_x"],
        inputs["M_q"],
        inputs["links_resolved"],
    )
    return nlp, corners


#: the shipped files, and the 3-RRR's smallest peak stress (an epigraph objective) under a stiffness requirement
#: (450 um/N: the stiffest x the stroke allows is 417.9 um/N with the 3-D-fitted circular_notch default)
CASES = {
    "prs3": (PRS3_FILE, []),
    "rrr3": (RRR3_FILE, []),
    "rrr3_min_stress": (RRR3_FILE, ["inputs.objective={minimize: stress}", "inputs.compliance_max={x: 450 um/N}"]),
    # the lateral (parasitic) compliance of the six-axis model with the sliders held, a requirement
    "prs3_six_axis": (
        PRS3_FILE,
        [
            "inputs.hinge_axes=all",
            "inputs.k_actuator=rigid",
            "inputs.compliance_max={px: 8 um/N}",
            "inputs.objective={minimize: input_stiffness}",
        ],
    ),
}


@pytest.fixture(scope="module", params=sorted(CASES))
def solved(request):
    problem = load_problem(*CASES[request.param])
    nlp, corners = _nlp(problem)
    y0 = np.full(len(problem.inputs["variables"]), 0.5)
    out = nlp.solve(y0)
    assert out.success, out.message
    return problem, nlp, corners, out


def test_the_optimum_satisfies_the_kkt_conditions(solved):
    """Stationarity of the Lagrangian ∇f + J_gᵀ λ_g + λ_x = 0 (AD gradients at IPOPT's solution
    and multipliers), dual feasibility (g <= 1: λ_g >= 0; a variable at its upper bound: λ_x >= 0,
    at its lower: <= 0) and complementarity (λ × slack = 0)."""
    problem, nlp, _, out = solved
    _, g, grad_f, jac = (np.asarray(a, dtype=float) for a in nlp.nlp_fn(out.w, out.p))
    grad_L = grad_f.ravel() + jac.T @ out.lam_g + out.lam_x
    assert np.max(np.abs(grad_L)) < 1e-8 * max(1.0, np.max(np.abs(grad_f)))
    _, _, _, ubg = nlp.bounds()
    lam = out.lam_g[nlp.n_eq :]
    slack = ubg[nlp.n_eq :] - g.ravel()[nlp.n_eq :]
    assert np.all(lam >= -1e-9) and np.all(slack >= -1e-9)
    np.testing.assert_allclose(lam * slack, 0.0, atol=1e-8)
    nv = len(out.y)
    lam_y = out.lam_x[:nv]
    assert np.all(lam_y[out.y >= 1 - 1e-6] >= -1e-9) and np.all(lam_y[out.y <= 1e-6] <= 1e-9)
    np.testing.assert_allclose(lam_y * np.minimum(out.y, 1 - out.y), 0.0, atol=1e-8)


def test_reported_active_constraints_are_at_their_bounds(solved):
    problem, nlp, _, out = solved
    active = [c for c in out.constraints if c.active]
    if problem.inputs["requirements"].objective[1] == "stress":  # a stiffness requirement binds the stress
        assert [c.name for c in active][:1] == ["C_x"]
    assert active, "a design on no constraint would be unbounded"
    for c in out.constraints:
        if c.interval:
            continue
        if c.sense == "<=":
            assert c.value <= c.bound * (1 + 1e-7)
        else:
            assert c.value >= c.bound * (1 - 1e-7)
        if c.active:
            assert c.value == pytest.approx(c.bound, rel=1e-5)
        elif c.name != "f1":
            assert c.value < c.bound * (1 - 1e-6)


def _forward(problem, design, kind, inputs):
    """An ordinary problem of ``kind`` on the synthesized hinges (their k from the formula)."""
    raw = dict(problem.inputs["hinges"] or {})
    for v in problem.inputs["variables"]:
        if v.link:
            continue
        entry = dict(raw.get(v.owner) or {})
        entry[v.key], entry["k"] = float(design[v.name]), None
        raw[v.owner] = entry
    data = {"problem": kind, "mechanism": problem.data["mechanism"], "inputs": {"hinges": raw, **inputs}}
    if problem.inputs["material"] is not None:
        data["inputs"]["material"] = problem.data["inputs"]["material"]
    res = solve(problem_from_dict(data, base_dir=ROOT / "problems"))
    assert res.ok, res.message
    return res.values


def test_the_design_solved_as_forward_problems_gives_the_same_figures():
    """The 3-PRS optimum: its frequency by natural_frequencies (the same masses and links), its
    compliance by platform_compliance (kinematic hinges, k_actuator 0), and the stresses at the
    stroke's corners by actuator_forces, whose stress-limited motion towards the binding corner
    ends at that corner (scale 1)."""
    problem = load_problem(PRS3_FILE)
    res = solve(problem)
    assert res.ok, res.message
    v = res.values
    design = {x.name: v[x.name] for x in problem.inputs["variables"]}
    data_in = problem.data["inputs"]
    nf = _forward(
        problem,
        design,
        "natural_frequencies",
        {"masses": data_in["masses"], "links": data_in["links"], "k_actuator": "0 N/m"},
    )
    assert nf["f1"] == pytest.approx(v["f1"], rel=1e-9)
    pc = _forward(problem, design, "platform_compliance", {"hinge_axes": "kinematic", "k_actuator": "0 N/m"})
    np.testing.assert_allclose(pc["C"], v["C"], rtol=1e-9, atol=1e-12 * np.abs(v["C"]).max())
    # every corner of z +-2 mm, psi, theta +-0.2 deg
    dz, ang = 2e-3, np.radians(0.2)
    corners = [(a, b, c) for a in (-dz, dz) for b in (-ang, ang) for c in (-ang, ang)]
    pose = {"dz": [c[0] for c in corners], "psi": [c[1] for c in corners], "theta": [c[2] for c in corners]}
    af = _forward(problem, design, "actuator_forces", pose)
    assert max(af["stress_max"]) == pytest.approx(v["stress_max"], rel=1e-9)
    assert v["stress_max"] == pytest.approx(400e6, rel=1e-7)  # the stroke binds the design
    # the stress limit found along the motion towards a binding corner (corner 6: z -2 mm,
    # psi +0.2 deg, theta -0.2 deg ... by the bit order of the box) is that corner
    binding = [c for c in v["active_constraints"].split(", ") if c.startswith("stress")]
    corner = int(binding[0].rsplit(" ", 1)[1]) - 1
    keys = ["dz", "psi", "theta"]
    box = {"dz": (-dz, dz), "psi": (-ang, ang), "theta": (-ang, ang)}
    at = {k: box[k][(corner >> b) & 1] for b, k in enumerate(keys)}
    lim = _forward(problem, design, "actuator_forces", {**at, "stress_limit": True, "sigma_allow": "400 MPa"})
    assert lim["scale_at_allowable"] == pytest.approx(1.0, rel=1e-6)


def test_ad_derivatives_equal_central_differences_of_the_forward_analysis(solved):
    """∂g/∂y of the NLP (AD through the hinge formulas' quadrature) against central differences
    of the forward analysis: the hinge set rebuilt from the perturbed dimensions, K_q and the
    stresses by static_point, C by output_compliance."""
    problem, nlp, corners, out = solved
    inputs, model = problem.inputs, problem.model
    w0, par = nlp.start(out.y)
    _, g, grad_f, jac = (np.asarray(a, dtype=float) for a in nlp.nlp_fn(w0, par))
    nv = len(inputs["variables"])

    def forward(y):
        design = {v.name: v.value(y[i]) for i, v in enumerate(inputs["variables"])}
        hs = designed_hinges(model, inputs, design)
        sp = cm.static_point(model, hs, model.x_home, model.q_home)
        vals = []
        for name, _, bound in nlp.g_info:
            if name.startswith("C_"):
                i = model.closure.x_names.index(name[2:])
                if inputs["hinge_axes"] == "all":
                    C = _six_axis_home(model, hs, inputs["k_actuator"])
                else:
                    C = cm.output_compliance(sp, inputs["k_actuator"])
                vals.append(C[i, i] / bound)
            elif name.startswith("stress"):
                hinge, where = name.split()[1], name.split(" at ", 1)[1]
                x, q = next((x, q) for label, x, q in corners if label == where)
                st = cm.static_point(model, hs, x, q).stresses
                if inputs["stress_check"] == "peak":
                    st = hs.peaks(st)
                vals.append(st[hinge] / bound)
            elif name.startswith("t/(2r)"):
                group = name.split()[-1]
                h = next(h for h in hs.hinges if h.group == group)
                vals.append(h.dims["t"] / (2 * h.dims["r"]))
            else:  # K_q[q]
                j = model.closure.q_names.index(name[4:-1])
                vals.append(sp.K_q[j, j] / bound)
        sense, measure = inputs["requirements"].objective
        if measure.startswith("compliance_"):  # the objective, scaled as the NLP scales it
            i = model.closure.x_names.index(measure[len("compliance_") :])
            vals.append(sense * cm.output_compliance(sp, inputs["k_actuator"])[i, i] / par[0])
        return np.array(vals)

    objective = inputs["requirements"].objective[1].startswith("compliance_")  # f1, stress: not f itself
    g_ineq = g.ravel()[nlp.n_eq : nlp.n_eq + nlp.n_ineq]
    ad = jac[nlp.n_eq : nlp.n_eq + nlp.n_ineq, :nv]
    if objective:
        f0 = np.asarray(nlp.nlp_fn(w0, par)[0], dtype=float).ravel()
        g_ineq = np.concatenate([g_ineq, f0])
        ad = np.vstack([ad, grad_f.ravel()[:nv]])
    np.testing.assert_allclose(forward(out.y), g_ineq, rtol=1e-9, atol=1e-12)
    h = 1e-6
    fd = np.column_stack([(forward(out.y + h * e) - forward(out.y - h * e)) / (2 * h) for e in np.eye(nv)])
    # per row (a constraint or the objective), to 2e-5 of its largest derivative
    scale = np.maximum(np.abs(fd).max(axis=1, keepdims=True), 1e-300)
    assert np.all(np.abs(ad - fd) <= 2e-5 * scale + 1e-9 * np.abs(fd).max()), np.abs(ad - fd) / scale


def _cli(path, *sets):
    cmd = [sys.executable, "-m", "cpm_nlp", "solve", str(path), "--json"]
    for s in sets:
        cmd += ["--set", s]
    return subprocess.run(cmd, capture_output=True, text=True, cwd=ROOT)


def test_an_infeasible_requirement_returns_infeasible_and_no_design():
    """A +-5 mm stroke of the 3-RRR cannot be met at 400 MPa within the bounds: status
    infeasible, exit 1, and not a single design number in the result."""
    out = _cli(RRR3_FILE, "inputs.stroke.x=[-5 mm, 5 mm]")
    assert out.returncode == 1, out.stderr
    res = json.loads(out.stdout)
    assert res["status"] == "infeasible"
    assert not any(k in res["values"] for k in ("t_elbow", "r_elbow", "w_elbow", "C_x", "f1"))
    assert "no design is reported" in res["message"]


def test_an_unreachable_stroke_is_infeasible():
    out = _cli(RRR3_FILE, "inputs.stroke.x=[-500 mm, 500 mm]")
    assert out.returncode == 1
    res = json.loads(out.stdout)
    assert res["status"] == "infeasible" and "not reachable" in res["message"] and not res["values"]


def _problem(**inputs):
    base = {
        "design": {"elbow": {"t": ["0.3 mm", "3 mm"]}},
        "hinges": {"elbow": {"joints": "e", "type": "circular_notch", "t": "1 mm", "r": "5 mm", "w": "12 mm"}},
        "material": {"name": "Al", "E": "72 GPa", "nu": 0.33, "allowable": "400 MPa"},
        "k_actuator": "10 N*m/rad",
        "objective": {"minimize": "compliance_x"},
    }
    base.update(inputs)
    base = {k: v for k, v in base.items() if v is not None}
    return {
        "problem": "compliance_synthesis",
        "mechanism": {"file": str(ROOT / "problems/mechanisms/rrr3.yaml")},
        "inputs": base,
    }


@pytest.mark.parametrize(
    ("inputs", "path", "words"),
    [
        ({"design": {"elbo": {"t": ["1 mm", "2 mm"]}}}, ("inputs", "design", "elbo"), "no hinge group"),
        ({"design": {"elbow": {"d": ["1 mm", "2 mm"]}}}, ("inputs", "design", "elbow", "d"), "no dimension d"),
        ({"design": {"elbow": {"t": ["2 mm", "1 mm"]}}}, ("inputs", "design", "elbow", "t"), "low < high"),
        ({"objective": {}}, ("inputs", "objective"), "minimize"),
        ({"k_actuator": "rigid"}, ("inputs", "k_actuator"), "compliance with the actuators held"),
        ({"objective": {"maximize": "f1"}}, ("inputs", "masses"), "needs masses"),
        ({"objective": {"minimize": "stress"}}, ("inputs", "stroke"), "required stroke"),
        ({"objective": {"minimize": "compliance_direction"}}, ("inputs", "direction"), "needs inputs.direction"),
        ({"objective": {"maximize": "stress"}}, ("inputs", "objective", "maximize"), "not maximized"),
        (
            {"objective": {"minimize": "compliance_direction"}, "direction": {"x": 1, "phi": 1}},
            ("inputs", "direction"),
            "mixes lengths and angles",
        ),
    ],
)
def test_bad_synthesis_input_is_named(inputs, path, words):
    with pytest.raises(InputError) as err:
        problem_from_dict(_problem(**inputs))
    assert err.value.path == path, err.value.message
    assert words in err.value.message


def test_link_sections_as_design_variables():
    """The legs' section as design variables for the highest f1: lighter legs raise it, so the
    section ends on its lower bounds (multipliers of a lower bound: negative); the design's f1 is
    natural_frequencies' with 6 x 6 mm legs and the same hinges."""
    problem = load_problem(PRS3_FILE, ["inputs.link_design={legs: {width: [6 mm, 14 mm], height: [6 mm, 14 mm]}}"])
    res = solve(problem)
    assert res.ok, res.message
    v = res.values
    assert v["width_legs"] == pytest.approx(6e-3, rel=1e-7) and v["height_legs"] == pytest.approx(6e-3, rel=1e-7)
    assert "width_legs" in v["active_constraints"].split(", ")
    design = {x.name: v[x.name] for x in problem.inputs["variables"] if not x.link}
    data_in = problem.data["inputs"]
    links = {"legs": {**data_in["links"]["legs"], "section": {"width": "6 mm", "height": "6 mm"}}}
    nf = _forward(
        problem, design, "natural_frequencies", {"masses": data_in["masses"], "links": links, "k_actuator": "0 N/m"}
    )
    assert nf["f1"] == pytest.approx(v["f1"], rel=1e-9)
    heavy = solve(load_problem(PRS3_FILE))
    assert v["f1"] > heavy.values["f1"]


def test_stress_over_given_poses_is_actuator_forces_stress():
    """Stresses over a set of poses (inputs.poses, the others at home) instead of a stroke box: the
    binding pose's peak stress is actuator_forces' at that pose on the designed hinges."""
    problem = load_problem(RRR3_FILE, ["inputs.stroke={}", "inputs.poses={x: [4 mm, 0 mm], y: [0 mm, -4 mm]}"])
    res = solve(problem)
    assert res.ok, res.message
    v = res.values
    assert "stress elbow1 at pose 1" in v["active_constraints"]
    design = {x.name: v[x.name] for x in problem.inputs["variables"]}
    af = _forward(problem, design, "actuator_forces", {"x": [4e-3, 0.0], "y": [0.0, -4e-3], "phi": [0.0, 0.0]})
    assert max(af["stress_peak_max"]) == pytest.approx(400e6, rel=1e-7)
    assert af["stress_peak_max"][0] == pytest.approx(v["stress_max"], rel=1e-9)


def test_compliance_along_a_direction_is_the_forward_compliance():
    """A requirement on u^T C u along a direction (x + 2y, normalized) that binds (the most
    compliant x design under it): the value is
    platform_compliance's C read along u at the design."""
    problem = load_problem(
        RRR3_FILE,
        [
            "inputs.direction={x: 1, y: 2}",
            "inputs.compliance_direction_max=500 um/N",
            "inputs.objective={maximize: compliance_x}",
        ],
    )
    res = solve(problem)
    assert res.ok, res.message
    v = res.values
    assert "C along the direction" in v["active_constraints"]
    assert v["C_direction"] == pytest.approx(500e-6, rel=1e-7)
    design = {x.name: v[x.name] for x in problem.inputs["variables"]}
    pc = _forward(problem, design, "platform_compliance", {"k_actuator": "10 N*m/rad"})
    u = np.array([1.0, 2.0, 0.0]) / np.sqrt(5.0)
    assert u @ np.array(pc["C"]) @ u == pytest.approx(v["C_direction"], rel=1e-9)


def test_six_axis_compliance_of_the_design_is_platform_compliances():
    """With hinge_axes: all the lateral compliance with the sliders held binds at 8 um/N, and
    platform_compliance (hinge_axes: all, sliders held) on the designed hinges gives that C."""
    problem = load_problem(PRS3_FILE, list(CASES["prs3_six_axis"][1]))
    res = solve(problem)
    assert res.ok, res.message
    v = res.values
    assert "C_px" in v["active_constraints"].split(", ") and v["C_px"] == pytest.approx(8e-6, rel=1e-7)
    design = {x.name: v[x.name] for x in problem.inputs["variables"]}
    pc = _forward(problem, design, "platform_compliance", {"hinge_axes": "all", "k_actuator": "rigid"})
    assert pc["hinge_model"] == "all"
    np.testing.assert_allclose(pc["C"], v["C"], rtol=1e-7, atol=1e-7 * np.abs(v["C"]).max())
