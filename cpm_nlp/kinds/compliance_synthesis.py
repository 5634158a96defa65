"""The ``compliance_synthesis`` problem kind: hinge dimensions and link sections that optimise
a stiffness, stress or frequency measure under requirements on stiffness, stress, frequency and
stroke (`cpm_nlp.analysis.compliance_synthesis`; IPOPT, exact derivatives through the compliance
model).  Every hinge kind's inputs (hinges, material, masses, links, k_actuator) are those of
`cpm_nlp.kinds.compliance`."""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from typing import Any

import numpy as np
import scipy.linalg

from ..analysis import compliance as cm
from ..analysis.compliance_synthesis import ROUND_OFF, ComplianceSynthesisNLP, Requirements, Variable, beam_section
from ..analysis.compliance_values import compliance_output, diagonal_output
from ..analysis.hinge_chains import six_axis_model
from ..analysis.hinge_models import HINGE_MODELS, has_chains
from ..analysis.hinge_types import DIM_OPTIONS, check_leaf_fillet
from ..analysis.link_masses import LinkSection, link_bodies
from ..core.errors import InputError, suggest
from ..core.kind import ProblemKind, broadcast, require_ipopt, task_options, task_values
from ..core.kinematics import inverse_kinematics
from ..core.model import Model
from ..core.options import Option
from ..core.outputs import Output, Values, declared_result, text
from ..core.result import Result, SolverInfo, Status
from ..core.schema import MappingOf, Quantity, Record
from ..core.solver import SolverConfig
from .compliance import _k_q_output
from .frequencies import _coordinate_masses, _links_node, masses_node
from .hinge_inputs import bodies_option, hinge_options, k_actuator_option
from .kinematic import _model_info

#: the measures an objective may name, beyond the compliance of each pose coordinate
MEASURES = {
    "compliance_direction": "the compliance u^T C u along inputs.direction (a unit vector of pose coordinates)",
    "f1": "the first natural frequency (kinematic hinge model, the masses and links given)",
    "stress": "the largest hinge stress over the corners of the required stroke and the poses given",
    "input_stiffness": "the largest diagonal entry of the input stiffness K_q (what the actuators push against)",
}

#: the section dimensions a link's design may vary
LINK_KEYS = ("width", "height", "d")


def _range(name: str, what: str) -> Option:
    return Option(name, "length", f"bounds [low, high] of {what}", default=None, shape="range", lower=0.0, strict=True)


def _design_node() -> MappingOf:
    return MappingOf(
        "design",
        "the hinge dimensions to vary, per hinge group: group -> {t: [low, high], r: ..., w: ...} (the dimensions "
        "of its type; a designed hinge takes its stiffness from its type's formula)",
        Record(
            "<group>",
            "the dimensions of one hinge group and their bounds",
            tuple(_range(d, f"the hinge's {o.description}") for d, o in DIM_OPTIONS.items()),
            what="hinge dimension",
            sparse=True,
        ),
        key_what="hinge group",
        default=None,
    )


def _link_design_node() -> MappingOf:
    return MappingOf(
        "link_design",
        "the link sections to vary: label of inputs.links -> {width: [low, high], height: ..., d: ...}",
        Record(
            "<link>",
            "the section dimensions of one link and their bounds",
            tuple(_range(k, f"the link section's {k}") for k in LINK_KEYS),
            what="section dimension",
            sparse=True,
        ),
        key_what="link",
        default=None,
    )


def _objective_node(model: Model) -> Record:
    names = (*(f"compliance_{x.name}" for x in model.closure.x), *MEASURES)
    text_ = "; ".join(f"{k}: {v}" for k, v in MEASURES.items())
    return Record(
        "objective",
        f"minimize or maximize one measure: compliance_<pose coordinate> (a diagonal entry of C at home); {text_}",
        (
            Option("minimize", "choice", "the measure to minimize", default=None, choices=names),
            Option("maximize", "choice", "the measure to maximize", default=None, choices=names),
        ),
        what="objective key",
        sparse=True,
    )


def _compliance_max_node(model: Model) -> Record:
    c = model.closure
    return Record(
        "compliance_max",
        "the largest allowed diagonal entry of the output compliance C at home, per pose coordinate",
        tuple(
            Quantity(
                x.name,
                f"largest C_{x.name}",
                kinds=(diagonal_output(x).dimension,),
                default=None,
                positive=True,
                si=True,
            )
            for x in c.x
        ),
        what="pose coordinate",
        sparse=True,
        default={},
    )


def _stroke_node(model: Model) -> Record:
    c = model.closure
    return Record(
        "stroke",
        "the required stroke: task coordinate -> [low, high] motion from home; the hinge stresses at every corner "
        "of this box must stay below the allowable stress (the stress-limited range covers it)",
        tuple(
            Option(c.x[i].name, c.x[i].kind, f"motion of {c.x[i].name} from home", default=None, shape="range")
            for i in c.task_index
        ),
        what="task coordinate",
        sparse=True,
        default={},
    )


class ComplianceSynthesis(ProblemKind):
    name = "compliance_synthesis"
    parts = (cm.JointStiffness,)
    #: the output compliance C and the input stiffness K_q of the design, as heat maps
    plots = ("matrices",)
    description = (
        "hinge dimensions (t, r, w per hinge group) and link sections that minimize or maximize a compliance, "
        "stress, input-stiffness or frequency measure under stiffness, stress, frequency and stroke requirements "
        "(kinematic hinge model; IPOPT with exact derivatives; the optimum re-evaluated by the forward analysis)"
    )

    def input_options(self, model: Model) -> list[Option]:
        ka = k_actuator_option(model)
        return [
            *hinge_options(),
            bodies_option(),
            _design_node(),
            _links_node(),
            _link_design_node(),
            masses_node(model),
            ka,
            _objective_node(model),
            _compliance_max_node(model),
            Option(
                "hinge_axes",
                "choice",
                "the hinge model of the output compliance C: 'kinematic' (each hinge about the axes the kinematics "
                "moves; C = J (K_q + K_a)^-1 J^T) or 'all' (every flexure a six-axis spring, at home: also with the "
                "actuators held, the parasitic compliance); stresses, K_q and f1 are the kinematic model's",
                default="kinematic",
                choices=("kinematic", "all"),
            ),
            Record(
                "direction",
                "a direction in the pose coordinates (components, normalized; all on lengths or all on angles) for "
                "compliance_direction and compliance_direction_max",
                tuple(
                    Option(x.name, "dimensionless", f"component along {x.name}", default=None) for x in model.closure.x
                ),
                what="pose coordinate",
                sparse=True,
                default={},
            ),
            Quantity(
                "compliance_direction_max",
                "the largest allowed compliance u^T C u along the direction",
                kinds=("compliance", "rotational_compliance"),
                default=None,
                positive=True,
                si=True,
            ),
            Quantity(
                "input_stiffness_max",
                "the largest allowed diagonal entry of K_q (each actuator's input stiffness)",
                kinds=("stiffness", "rotational_stiffness"),
                default=None,
                positive=True,
                si=True,
            ),
            Option(
                "frequency_min", "frequency", "the smallest allowed first natural frequency", None, 0.0, strict=True
            ),
            _stroke_node(model),
            Record(
                "poses",
                "further poses where every hinge must stay below the allowable stress: task coordinates (or their "
                "offsets from home), each a value or a list (lists of equal length); those not given at home",
                tuple(task_options(model, "grid")),
                what="task coordinate",
                sparse=True,
                default={},
            ),
            Option("sigma_allow", "stress", "allowable stress (default: the hinge material's)", None, 0.0, strict=True),
            Option("safety_factor", "dimensionless", "divides the allowable stress", default=1.0, lower=1.0),
            Option("stress_check", "choice", "the stress checked", default="nominal", choices=("nominal", "peak")),
        ]

    def check_solver(self, solver: SolverConfig) -> None:
        require_ipopt(solver, self.name)

    def resolve(self, inputs: dict[str, Any], model: Model, path: tuple) -> None:  # noqa: C901 - one check per input
        """The hinges, the design variables (checked against the hinges' types), the requirements."""
        hs = cm.hinge_set(model, inputs["hinges"], inputs["material"], None, path, inputs.get("bodies"))
        inputs["hinge_set"] = hs
        if hs.bodies and inputs["hinge_axes"] != "all":
            raise InputError(
                f"flexible bodies ({', '.join(b.name for b in hs.bodies)}) enter the six-axis hinge model's "
                "compliance only; give hinge_axes: all",
                path=path + ("hinge_axes",),
            )
        design = inputs["design"] or {}
        groups = {h.group: h for h in hs.hinges}
        variables: list[Variable] = []
        for g, dims in design.items():
            if g not in groups:
                raise InputError(
                    f"no hinge group {g!r}; the hinges: {', '.join(groups)}",
                    path=path + ("design", g),
                    suggestions=suggest(g, list(groups)),
                )
            h = groups[g]
            if h.kind is None or h.material is None or h.material.E is None:
                raise InputError(
                    f"hinge {g} needs a flexure type and a material with E to be designed", path=path + ("design", g)
                )
            for d, rng in dims.items():
                if rng is None:
                    continue
                if d not in h.dims:
                    raise InputError(
                        f"hinge type {h.kind} has no dimension {d} (it takes {', '.join(h.dims)})",
                        path=path + ("design", g, d),
                    )
                lo, hi = float(rng[0]), float(rng[1])
                if not hi > lo:
                    raise InputError(f"expected [low, high] with high > low, got {rng}", path=path + ("design", g, d))
                variables.append(Variable(f"{d}_{g}", g, d, lo, hi))
            if h.kind == "leaf_spring" and h.dims.get("h") is not None:  # h/r within the K_t fit at the bounds
                span = {d: (h.dims[d], h.dims[d]) if dims.get(d) is None else tuple(dims[d]) for d in ("r", "h")}
                for r, sh in ((span["r"][1], span["h"][0]), (span["r"][0], span["h"][1])):
                    check_leaf_fillet({"r": float(r), "h": float(sh)}, path + ("design", g))
        mat = next((h.material for h in hs.hinges if h.material is not None), None)
        inputs["M_x"], inputs["M_q"] = _coordinate_masses(inputs["masses"] or {}, model, mat, path)
        inputs["links_resolved"] = None
        if inputs["links"]:
            if not has_chains(model):
                raise InputError(f"links need the legs of {model.name} as serial chains", path=path + ("links",))
            sm = HINGE_MODELS["all"].prepare(model, hs, path + ("links",), True).six_axis
            bodies = []
            for label, spec in inputs["links"].items():
                for b in link_bodies(sm, {label: spec}, mat.density if mat else None, path + ("links",)):
                    bodies.append((label, b))
            inputs["links_resolved"] = (sm, bodies)
        inputs["flexible"] = _flexible_links(inputs, hs, path)
        for label, dims in (inputs["link_design"] or {}).items():
            spec = (inputs["links"] or {}).get(label)
            if spec is None or spec.get("section") is None or spec.get("mass") is not None:
                raise InputError(
                    f"link_design.{label} needs a link of that label in inputs.links given by its section (no mass)",
                    path=path + ("link_design", label),
                )
            sec = spec["section"]
            for k, rng in dims.items():
                if rng is None:
                    continue
                if getattr(sec, k) is None:
                    raise InputError(f"the section of link {label} has no {k}", path=path + ("link_design", label, k))
                variables.append(Variable(f"{k}_{label}", label, k, float(rng[0]), float(rng[1]), link=True))
        if not variables:
            raise InputError("expected design: at least one hinge dimension (or link_design) to vary", path=path)
        inputs["variables"] = variables
        self._requirements(inputs, model, hs, path)

    def _requirements(self, inputs: dict[str, Any], model: Model, hs: cm.HingeSet, path: tuple) -> None:
        c = model.closure
        obj = inputs["objective"] or {}
        if (obj.get("minimize") is None) == (obj.get("maximize") is None):
            raise InputError(
                "expected objective: {minimize: <measure>} or {maximize: <measure>}", path=path + ("objective",)
            )
        sense, measure = (1, obj["minimize"]) if obj.get("minimize") else (-1, obj["maximize"])
        if sense < 0 and measure in ("stress", "input_stiffness"):
            raise InputError(
                f"{measure} is a largest value over hinges or actuators: it can be minimized, not maximized",
                path=path + ("objective", "maximize"),
            )
        direction = self._direction(inputs, model, measure, path)
        needs_ka = measure.startswith("compliance_") or inputs["compliance_max"] or direction is not None
        six = _six_axis_chosen(inputs, model, hs, path)
        if needs_ka and inputs["k_actuator"] is None and not six:
            raise InputError(
                "the output compliance with the actuators held is zero in the kinematic hinge model; give k_actuator "
                "(a stiffness, or 0 N/m for the actuator forces held)",
                path=path + ("k_actuator",),
            )
        freq = measure == "f1" or inputs["frequency_min"] is not None
        if freq and not (np.any(inputs["M_x"]) or np.any(inputs["M_q"]) or inputs["links_resolved"]):
            raise InputError("a frequency needs masses (or links)", path=path + ("masses",))
        if freq and inputs["k_actuator"] is None:
            raise InputError(
                "a frequency with the actuators held has no motion; give k_actuator", path=path + ("k_actuator",)
            )
        stroke = {k: v for k, v in (inputs["stroke"] or {}).items() if v is not None}
        poses = _with_home({k: v for k, v in (inputs["poses"] or {}).items() if v is not None}, model)
        inputs["poses"] = poses
        if poses:
            broadcast(task_values(poses, model, path + ("poses",)), list(c.task), path + ("poses",))
        if measure == "stress" and not (stroke or poses):
            raise InputError(
                "the stress objective needs the required stroke (inputs.stroke) or poses (inputs.poses)",
                path=path + ("stroke",),
            )
        sigma = None
        if stroke or poses:
            sigma = cm.allowable(hs, inputs["sigma_allow"], inputs["safety_factor"], path)
        inputs["stroke_box"] = stroke
        inputs["requirements"] = Requirements(
            (sense, measure),
            {c.x_names.index(k): v for k, v in (inputs["compliance_max"] or {}).items() if v is not None},
            inputs["input_stiffness_max"],
            inputs["frequency_min"],
            (),
            sigma,
            inputs["stress_check"] == "peak",
            direction,
            inputs["compliance_direction_max"],
            six,
        )

    @staticmethod
    def _direction(inputs: dict[str, Any], model: Model, measure: str, path: tuple) -> np.ndarray | None:
        """The unit direction u of ``direction`` (None when neither the objective nor a requirement needs it)."""
        c = model.closure
        given = {k: v for k, v in (inputs["direction"] or {}).items() if v}
        wanted = measure == "compliance_direction" or inputs["compliance_direction_max"] is not None
        if not wanted:
            return None
        if not given:
            raise InputError(
                "compliance_direction needs inputs.direction: pose coordinate -> component", path=path + ("direction",)
            )
        kinds = {c.x[c.x_names.index(k)].kind for k in given}
        if len(kinds) > 1:
            raise InputError(
                "a direction mixes lengths and angles, whose compliances have different units; give one kind",
                path=path + ("direction",),
            )
        u = np.array([float(given.get(n, 0.0)) for n in c.x_names])
        return u / np.linalg.norm(u)

    def run(self, model: Model, inputs: Mapping[str, Any], solver: SolverConfig) -> Result:
        require_ipopt(solver, self.name)
        c = model.closure
        req: Requirements = inputs["requirements"]
        out = Values()
        corners, message = self._corners(model, inputs["stroke_box"], solver)
        if not message:
            given, message = self._poses(model, inputs["poses"], solver)
            corners += given
        if message:
            return self._result(model, Status.INFEASIBLE, out, SolverInfo("ipopt"), message)
        req = Requirements(**{**req.__dict__, "stress_poses": corners})
        hs: cm.HingeSet = inputs["hinge_set"]
        nlp = ComplianceSynthesisNLP(
            model,
            hs,
            inputs["variables"],
            req,
            inputs["k_actuator"],
            inputs["M_x"],
            inputs["M_q"],
            inputs["links_resolved"],
            inputs["flexible"],
        )
        y0 = np.array([_start(v, hs, inputs) for v in inputs["variables"]])
        res = nlp.solve(y0)
        info = SolverInfo("ipopt", res.iterations, res.seconds)
        if not res.success:
            status = Status.INFEASIBLE if res.infeasible else Status.NOT_CONVERGED
            why = "the requirements cannot all be met within the bounds" if res.infeasible else "no optimum found"
            return self._result(model, status, out, info, f"{why} (IPOPT: {res.message}); no design is reported")
        for v in inputs["variables"]:
            out.add(Output(v.name, "length"), res.design[v.name])
        m = res.measures
        if "C" in m:
            out.add(compliance_output(c), m["C"].tolist())
            out.add_all((diagonal_output(x), float(m["C"][i, i])) for i, x in enumerate(c.x))
        out.add(_k_q_output(c), m["K_q"].tolist())
        if "compliance_direction" in m:
            out.add(Output("C_direction", _direction_dimension(model, req)), float(m["compliance_direction"]))
        out.add(Output("f1", "frequency"), m["f1"])  # None without masses or with the actuators held
        if "stress" in m:
            out.add(Output("stress_max", "stress"), float(m["stress"]))
            out.add(Output("sigma_allow", "stress"), req.sigma_allow)
        sense, measure = req.objective
        out.add(text("objective"), f"{'minimize' if sense > 0 else 'maximize'} {measure}")
        active = [k.name for k in res.constraints if k.active]
        out.add(text("active_constraints"), ", ".join(active) or "none")
        out.add(text("constraints"), "; ".join(k.text() for k in res.constraints))
        # floored at round-off: the digits below it differ between BLAS kernels
        out.add(Output("kkt_residual", "dimensionless"), max(res.kkt_residual, ROUND_OFF))
        deviation = self._recheck(model, inputs, res, corners)
        out.add(Output("recheck_deviation", "dimensionless"), max(deviation, ROUND_OFF))
        status, msg = (
            Status.SOLVED,
            f"IPOPT: {res.message}, {res.iterations} iterations; active: {', '.join(active) or 'none'}",
        )
        if not deviation <= 1e-6:
            status = Status.NOT_CONVERGED
            msg = f"the forward analysis of the design differs from the NLP's model by {deviation:.3g} (relative)"
        return self._result(model, status, out, info, msg)

    @staticmethod
    def _corners(model: Model, box: Mapping[str, Any], solver: SolverConfig) -> tuple[list, str]:
        """The poses (x, q) at the corners of the stroke box about home (IK), or why one is not reachable."""
        if not box:
            return [], ""
        c = model.closure
        t0 = model.task_of(model.x_home)
        names = [c.x[i].name for i in c.task_index]
        keys = list(box)
        out = []
        for corner in range(2 ** len(keys)):
            t = t0.copy()
            for b, k in enumerate(keys):
                t[names.index(k)] += box[k][(corner >> b) & 1]
            sol = inverse_kinematics(model, t, solver)
            if not sol.ok:
                where = ", ".join(f"{k} {box[k][(corner >> b) & 1]:+.6g}" for b, k in enumerate(keys))
                return [], f"the required stroke is not reachable: the corner ({where}) from home: {sol.status.value}"
            out.append((f"stroke corner {corner + 1}", sol.x, sol.q))
        return out, ""

    @staticmethod
    def _poses(model: Model, poses: Mapping[str, Any], solver: SolverConfig) -> tuple[list, str]:
        """The poses given (task coordinates, lists of equal length) by IK: (label, x, q)."""
        if not poses:
            return [], ""
        ts, _ = broadcast(task_values(poses, model, ("inputs", "poses")), list(model.closure.task), ("inputs", "poses"))
        out = []
        for k, t in enumerate(ts):
            sol = inverse_kinematics(model, t, solver)
            if not sol.ok:
                return [], f"pose {k + 1} of inputs.poses is not reachable: {sol.status.value}"
            out.append((f"pose {k + 1}", sol.x, sol.q))
        return out, ""

    @staticmethod
    def _recheck(model: Model, inputs: Mapping[str, Any], res: Any, corners: list) -> float:
        """The largest relative difference between the NLP's measures at the optimum and the forward
        analysis of the same design (`static_point`, `output_compliance`, the hinges' stresses)."""
        hs2 = designed_hinges(model, inputs, res.design)
        sp = cm.static_point(model, hs2, model.x_home, model.q_home)
        m = res.measures
        dev = [_rel(sp.K_q, m["K_q"])]
        ka = inputs["k_actuator"]
        if "C" in m:
            C = _six_axis_home(model, hs2, ka) if inputs["hinge_axes"] == "all" else cm.output_compliance(sp, ka)
            dev.append(_rel(C, m["C"]))
            u = inputs["requirements"].direction
            if u is not None:
                dev.append(_rel(np.array([u @ C @ u]), np.array([m["compliance_direction"]])))
        if "stress" in m:
            peak = inputs["stress_check"] == "peak"
            worst = max(hs2.checked(cm.static_point(model, hs2, x, q).stresses, peak) or 0.0 for _, x, q in corners)
            dev.append(_rel(np.array([worst]), np.array([float(m["stress"])])))
        if m["f1"] is not None:
            lam = scipy.linalg.eigh(sp.K_q + np.diag(ka), m["M"], eigvals_only=True)[0]
            dev.append(_rel(np.array([math.sqrt(max(lam, 0.0)) / (2 * math.pi)]), np.array([m["f1"]])))
        return float(max(dev))

    def _result(self, model: Model, status: Status, out: Values, info: SolverInfo, message: str) -> Result:
        return declared_result(
            self.name, status, out.outputs, out.values, solver=info, message=message, model=_model_info(model)
        )

    def outputs(self, model: Model) -> list[Output]:
        c = model.closure
        design = [Output("{name}", "length", per="design variable: <dimension>_<hinge group or link>")]
        return [
            *design,
            compliance_output(c),
            *(diagonal_output(x) for x in c.x),
            _k_q_output(c),
            Output("C_direction", "compliance", unit="m/N or rad/(N*m): along inputs.direction"),
            Output("f1", "frequency"),
            Output("stress_max", "stress"),
            Output("sigma_allow", "stress"),
            text("objective"),
            text("active_constraints"),
            text("constraints"),
            Output("kkt_residual", "dimensionless"),
            Output("recheck_deviation", "dimensionless"),
        ]


def _six_axis_chosen(inputs: Mapping[str, Any], model: Model, hs: cm.HingeSet, path: tuple) -> bool:
    """Whether C is the six-axis model's (``hinge_axes: all``), checked to place every hinge."""
    if inputs["hinge_axes"] != "all":
        return False
    if not has_chains(model):
        raise InputError(f"hinge_axes: all needs the legs of {model.name} as chains", path=path + ("hinge_axes",))
    HINGE_MODELS["all"].prepare(model, hs, path + ("hinge_axes",), True)  # every hinge placed, else bad input
    return True


def _six_axis_home(model: Model, hs: cm.HingeSet, ka: np.ndarray | None) -> np.ndarray:
    """The six-axis hinge model's C at home, as platform_compliance (hinge_axes: all) computes it."""
    sm = six_axis_model(model, hs)
    c = model.closure
    _, z, lam, _ = sm.newton(sm.start(model.x_home, model.q_home), np.zeros(c.nx), model.q_home, None, None)
    return sm.compliance(z, lam, ka, None if ka is None else np.zeros(c.nq))


def _direction_dimension(model: Model, req: Requirements) -> str:
    i = int(np.flatnonzero(req.direction)[0])
    return diagonal_output(model.closure.x[i]).dimension


def _with_home(poses: dict[str, Any], model: Model) -> dict[str, Any]:
    """The poses given, the task coordinates not given (nor their offsets) at their home value."""
    if not poses:
        return poses
    c = model.closure
    out = dict(poses)
    for i in c.task_index:
        name = c.x[i].name
        if name not in out and not any(o in out for o, target in c.offsets.items() if target == name):
            out[name] = float(model.x_home[i])
    return out


def designed_hinges(model: Model, inputs: Mapping[str, Any], design: Mapping[str, float]) -> cm.HingeSet:
    """The hinge set of the problem with the designed dimensions (their stiffness from the
    formula): what an ordinary forward problem with these hinges solves."""
    raw = dict(inputs["hinges"] or {})
    for v in inputs["variables"]:
        if v.link:
            continue
        entry = dict(raw.get(v.owner) or {})
        entry[v.key] = float(design[v.name])  # a bare SI number
        entry["k"] = None
        raw[v.owner] = entry
    hs = cm.hinge_set(model, raw, inputs["material"], None, bodies=inputs.get("bodies"))
    flexible = inputs.get("flexible") or {}
    if flexible:  # a flexible link takes its link's section, with the designed dimensions
        bodies = []
        for b in hs.bodies:
            if b.name in flexible:
                label, sec = flexible[b.name]
                given = {k: design.get(f"{k}_{label}", getattr(sec, k)) for k in LINK_KEYS}
                section = beam_section(LinkSection(given["width"], given["height"], given["d"]), b.beam.section)
                b = dataclasses.replace(b, beam=dataclasses.replace(b.beam, section=section))
            bodies.append(b)
        hs.bodies = bodies
    return hs


def _flexible_links(inputs: Mapping[str, Any], hs: cm.HingeSet, path: tuple) -> dict[str, tuple[str, LinkSection]]:
    """Flexible body name -> (label, section) of the link of ``links`` it is (a link given by its
    section, between the same two joints): its section is the beam's, so a link design changes
    the beam's stiffness too.  The body's declared section must be that section."""
    if not inputs["links_resolved"] or not hs.bodies:
        return {}
    sm, bodies = inputs["links_resolved"]
    flexible = sm.flexible_links()
    out: dict[str, tuple[str, LinkSection]] = {}
    for label, b in bodies:
        name = flexible.get((b.leg, b.joint))
        sec = inputs["links"][label].get("section")
        if name is None or sec is None:
            continue
        body = next(x for x in hs.bodies if x.name == name)
        declared = body.beam.section
        link = beam_section(sec, declared)
        same = declared.kind == link.kind and all(
            math.isclose(float(declared.values[k]), float(link.values[k]), rel_tol=1e-12)
            for k in ("b", "h", "d")
            if k in link.values
        )
        if not same:
            raise InputError(
                f"link {label} is the flexible body {name}, whose section must be the link's: {link.kind} "
                + ", ".join(f"{k} = {float(v) * 1e3:g} mm" for k, v in link.values.items() if k != "kappa")
                + " (width along the first joint's axis is the beam's b, height its h); the body gives "
                + f"{declared.kind} "
                + ", ".join(f"{k} = {float(v) * 1e3:g} mm" for k, v in declared.values.items() if k != "kappa"),
                path=path + ("links", label, "section"),
            )
        if out.get(name, (label,))[0] != label:
            raise InputError(f"flexible body {name} is two links, {out[name][0]} and {label}", path=path + ("links",))
        out[name] = (label, sec)
    return out


def _start(v: Variable, hs: cm.HingeSet, inputs: Mapping[str, Any]) -> float:
    """The scaled start of a variable: its value in the problem, clipped into its bounds, else mid-range."""
    if v.link:
        sec = inputs["links"][v.owner]["section"]
        value = getattr(sec, v.key)
    else:
        value = next(h.dims.get(v.key) for h in hs.hinges if h.group == v.owner)
    if value is None:
        return 0.5
    return float(np.clip((value - v.lower) / (v.upper - v.lower), 0.05, 0.95))


def _rel(a: np.ndarray, b: np.ndarray) -> float:
    a, b = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    return float(np.max(np.abs(a - b)) / max(float(np.max(np.abs(b))), 1e-300))
