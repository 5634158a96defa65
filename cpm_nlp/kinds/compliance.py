"""Problem kinds of compliance, stiffness and strength, for any mechanism whose
joints carry hinges (declared by the mechanism's part ``stiffness``, a
[`JointStiffness`][cpm_nlp.analysis.compliance.JointStiffness], or given under
``inputs.hinges``); the method is `cpm_nlp.analysis.compliance`.

* ``actuator_forces`` -- the actuator forces, input stiffness K_q and hinge
  stresses along a motion (actuator inputs, or poses through IK), and the motion
  at which the first hinge reaches the allowable stress;
* ``platform_compliance`` -- the 6x6 (nx x nx) output compliance at a pose and the
  compliant forward kinematics under a load;
* ``natural_frequencies`` (`cpm_nlp.kinds.frequencies`) -- frequencies and mode shapes,
  linearized Lagrange at a pose, from masses and inertias on the coordinates and the hinge
  stiffness.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from types import MappingProxyType
from typing import Any

import numpy as np
import scipy.optimize

from ..analysis import compliance as cm
from ..analysis.compliance_values import (
    compliance_output,
    coordinate_list,
    diagonal_output,
    force_output,
    peak_outputs,
    point_warnings,
    stress_groups,
    stress_outputs,
    stress_values,
)
from ..analysis.hinge_chains import LegChains
from ..analysis.hinge_models import (
    HINGE_MODELS,
    Prepared,
    default_hinge_model,
    hinge_model_text,
    six_axis_point,
)
from ..core.errors import InputError
from ..core.kind import (
    ProblemKind,
    actuator_options,
    broadcast,
    check_actuator_limits,
    given,
    task_options,
    task_values,
)
from ..core.kinematics import PoseSolution, forward_kinematics, inverse_kinematics
from ..core.model import Model
from ..core.options import Option
from ..core.outputs import Output, Values, declared_result, matrix, text, vector
from ..core.result import STATUS_TEXT, Result, SolverInfo, Status, poses_solver_info, worst_status
from ..core.solver import SolverConfig
from ..core.units import result_unit
from .hinge_inputs import bodies_option, hinge_options, k_actuator_option, load_option
from .kinematic import _model_info, _pose_outputs, _pose_values


def _pose_inputs(model: Model) -> list[Option]:
    return task_options(model, "grid") + actuator_options(model, "grid")


def _solve_poses(model: Model, inputs: Mapping[str, Any], solver: SolverConfig) -> tuple[list[PoseSolution], bool]:
    c = model.closure
    if given(inputs, c.q_names):
        qs, batch = broadcast([inputs[n] for n in c.q_names], c.q_names, ("inputs",))
        return [forward_kinematics(model, q, solver) for q in qs], batch
    ts, batch = broadcast(task_values(inputs, model, ("inputs",)), list(c.task), ("inputs",))
    return [inverse_kinematics(model, t, solver) for t in ts], batch


def _check_pose_inputs(model: Model, inputs: Mapping[str, Any], path: tuple, required: bool = True) -> None:
    c = model.closure
    pose_keys = given(inputs, [o.name for o in task_options(model, "grid")])
    act_keys = given(inputs, c.q_names)
    if pose_keys and act_keys:
        raise InputError(
            f"give either the pose ({', '.join(pose_keys)}) or the actuators ({', '.join(act_keys)}), not both",
            path=path,
        )
    if act_keys:
        if len(act_keys) != c.nq:
            raise InputError(f"give every actuator: {', '.join(c.q_names)}", path=path)
        check_actuator_limits(model, inputs, path)
        broadcast([inputs[n] for n in c.q_names], c.q_names, path)
    elif pose_keys or required:
        broadcast(task_values(inputs, model, path), list(c.task), path)


def _commanded_pose(model: Model, inputs: Mapping[str, Any], solver: SolverConfig) -> PoseSolution:
    """The one pose a scalar kind works at: the given actuators or pose, else home."""
    c = model.closure
    if given(inputs, c.q_names) or given(inputs, [o.name for o in task_options(model, "scalar")]):
        return _solve_poses(model, inputs, solver)[0][0]
    return inverse_kinematics(model, model.task_of(model.x_home), solver)


def _summary(sols: list[PoseSolution], batch: bool) -> tuple[Status, str, list[Status] | None]:
    statuses = [s.status for s in sols]
    bad = [(k, s) for k, s in enumerate(sols) if not s.ok]
    if not bad:
        return Status.SOLVED, f"{len(sols)} pose(s) solved", statuses if batch else None
    k, s = bad[0]
    msg = f"{len(bad)} of {len(sols)} poses not solved; first, point {k}: {STATUS_TEXT[s.status]}" + (
        f" ({s.message})" if s.message else ""
    )
    return worst_status(statuses), msg, statuses if batch else None


class _HingeKind(ProblemKind):
    """Shared input handling: pose or actuator inputs, hinges, material, load."""

    #: the mechanism's declared hinges, the defaults of ``inputs.hinges`` (read by
    #: `hinge_set`)
    parts = (cm.JointStiffness,)

    def supports(self, model: Model) -> str | None:
        c = model.closure
        if c.nx == 0:  # pragma: no cover - every closure has a pose
            return "it has no pose coordinates"
        return None

    def extra_options(self, model: Model) -> list[Option]:
        return []

    def input_options(self, model: Model) -> list[Option]:
        return _pose_inputs(model) + hinge_options() + [bodies_option(), load_option(model)] + self.extra_options(model)

    def resolve(self, inputs: dict[str, Any], model: Model, path: tuple) -> None:
        """The hinges (the mechanism's merged with ``hinges`` and ``material``)."""
        inputs["hinge_set"] = cm.hinge_set(
            model, inputs["hinges"], inputs["material"], inputs.get("sigma_allow"), path, inputs.get("bodies")
        )


#: the stiffness of a hinge group's formula about each of its axes: on an angle coordinate, on a length
K_FORMULA: Mapping[str, Output] = MappingProxyType(
    {
        kind: Output("k_formula_{group}_{axis}", dimension, per=f"hinge group with a flexure type, and axis on {on}")
        for kind, dimension, on in (("angle", "rotational_stiffness", "an angle"), ("length", "stiffness", "a length"))
    }
)


def _formula_stiffness(model: Model, hs: cm.HingeSet) -> Values:
    """The stiffness of each hinge group's formula about each of its axes (a group once)."""
    c = model.closure
    coords = [*c.x, *c.q, *c.passive_coords]
    out, seen = Values(), set()
    for h in hs.hinges:
        if h.group in seen:
            continue
        seen.add(h.group)
        for a, kf in h.k_formula.items():
            family = K_FORMULA["angle" if coords[h.axes[a]].kind == "angle" else "length"]
            out.add(family.member(group=h.group, axis=a), kf)
    return out


def _declared_hinges(kind: ProblemKind, model: Model) -> cm.HingeSet | None:
    """The mechanism's own hinges (its part ``stiffness``), as a problem without ``inputs.hinges``
    has them: the hinge groups a result names unless the problem adds others (None: none declared)."""
    return cm.hinge_set(model, None) if kind.part(model, cm.JointStiffness) is not None else None


def _stress_outputs(hs: cm.HingeSet | None, suffix: str = "") -> list[Output]:
    """The largest stress, that of each of the mechanism's hinge groups, and the family of all
    groups: the nominal stresses, then the peak stresses K_t × nominal and each group's K_t."""
    groups = stress_groups(hs) if hs is not None else ()
    out: list[Output] = []
    largest, family = stress_outputs(suffix)
    peak_largest, peak_family, kt_family = peak_outputs(suffix)
    for one, fam in ((largest, family), (peak_largest, peak_family)):
        out += [one, *(fam.member(group=g) for g in groups), fam]
    return [*out, *(kt_family.member(group=g) for g in groups), kt_family]


def _k_q_output(c: Any) -> Output:
    stiffness = f"{result_unit('stiffness')} or {result_unit('rotational_stiffness')}"
    return matrix("K_q", f"{stiffness} (rows and columns {', '.join(c.q_names)})")


def _hinge_result(
    kind: str,
    model: Model,
    status: Status,
    out: Values,
    info: SolverInfo,
    message: str,
    statuses: list[Status] | None = None,
) -> Result:
    return declared_result(
        kind,
        status,
        out.outputs,
        out.values,
        solver=info,
        message=message,
        statuses=statuses,
        model=_model_info(model),
    )


#: the largest nominal stress in the flexible bodies' beams
BEAM_STRESS = Output("beam_stress_max", "stress", when="bodies")


class ActuatorForces(_HingeKind):
    name = "actuator_forces"
    description = (
        "actuator forces (gradient of the hinge strain energy, AD through the kinematics, plus a platform load), "
        "input stiffness K_q and hinge stresses along a motion; the motion where the first hinge reaches sigma_allow"
    )
    plots = ("forces",)

    def extra_options(self, model: Model) -> list[Option]:
        return [
            Option(
                "stress_limit",
                "bool",
                "also find the motion (along the ray from home through the last point) at which the first hinge "
                "reaches the allowable stress, on the nonlinear kinematics, and its linear extrapolation",
                default=False,
            ),
            Option(
                "sigma_allow",
                "stress",
                "allowable stress (default: the hinge material's allowable, else its yield strength / safety_factor)",
                default=None,
                lower=0.0,
                strict=True,
            ),
            Option("safety_factor", "dimensionless", "divides the allowable stress", default=1.0, lower=1.0),
            Option(
                "hinge_axes",
                "choice",
                "the hinge model: 'kinematic' (the pseudo-rigid-body energy method on the kinematics) or 'all' (every "
                "hinge a six-axis spring on the legs' chains, the equilibrium at each input); default: kinematic, or "
                "all with flexible bodies",
                default=None,
                choices=tuple(HINGE_MODELS),
            ),
            Option(
                "stress_check",
                "choice",
                "the stress the stress limit checks: nominal (at the thinnest section, as the papers do) or peak "
                "(K_t x nominal, the hinges' stress-concentration factors)",
                default="nominal",
                choices=("nominal", "peak"),
            ),
        ]

    def check_inputs(self, inputs: dict[str, Any], model: Model, path: tuple) -> None:
        _check_pose_inputs(model, inputs, path)
        if inputs["stress_limit"]:
            hs = inputs["hinge_set"]
            if not any(h.kind is not None for h in hs.hinges):
                raise InputError(
                    "a stress limit needs hinges with a flexure type and dimensions (the stiffness alone gives "
                    "no stress)",
                    path=path + ("stress_limit",),
                )
            inputs["sigma"] = cm.allowable(hs, inputs.get("sigma_allow"), inputs["safety_factor"], path)

    def resolve(self, inputs: dict[str, Any], model: Model, path: tuple) -> None:
        """The hinges, and with flexible bodies the six-axis model that carries them."""
        super().resolve(inputs, model, path)
        hs = inputs["hinge_set"]
        chosen = inputs.get("hinge_axes")
        if chosen is None:  # the energy method on the kinematics, unless flexible bodies need the six-axis model
            chosen = "all" if hs.bodies else "kinematic"
        at = path + ("hinge_axes" if inputs.get("hinge_axes") is not None else "bodies",)
        prepared = HINGE_MODELS[chosen].prepare(model, hs, at, True)
        inputs["six_axis"] = prepared if chosen == "all" else None

    @staticmethod
    def _point(model: Model, inputs: Mapping[str, Any], sol: PoseSolution) -> tuple[Any, dict] | None:
        """Forces, K_q, stresses and energy at a solved pose: the energy method on the kinematics,
        or, with flexible bodies, the six-axis model's equilibrium at the pose's actuators."""
        hs: cm.HingeSet = inputs["hinge_set"]
        if inputs.get("six_axis") is None:
            return cm.static_point(model, hs, sol.x, sol.q, inputs["load"]), {}
        return six_axis_point(inputs["six_axis"].six_axis, model, sol.x, sol.q, inputs["load"])

    def run(self, model: Model, inputs: Mapping[str, Any], solver: SolverConfig) -> Result:
        c = model.closure
        hs: cm.HingeSet = inputs["hinge_set"]
        sols, batch = _solve_poses(model, inputs, solver)
        got = [self._point(model, inputs, s) if s.ok else None for s in sols]
        points = [None if g is None else g[0] for g in got]
        status, message, statuses = _summary(sols, batch)
        if any(s.ok and g is None for s, g in zip(sols, got)):
            status, message = Status.NOT_CONVERGED, "the six-axis model with flexible bodies found no equilibrium"

        def per_point(col: list) -> Any:
            return col if batch else col[0]

        out = Values(_pose_outputs(model), _pose_values(model, sols, batch))
        if inputs.get("six_axis") is not None:  # the pose of the flexible mechanism, not the rigid one
            flex = [None if sp is None else sp.x for sp in points]
            flexed = [_Flexed(s, s.x if x is None else x) for s, x in zip(sols, flex)]
            out = Values(_pose_outputs(model), _pose_values(model, flexed, batch))
            if hs.bodies:
                beam_stress = [None if g is None else max(g[1].values(), default=None) for g in got]
                out.add(BEAM_STRESS, per_point(beam_stress))
            names = ", ".join(b.name for b in hs.bodies)
            message += "; six-axis hinges" + (f", flexible bodies {names} (beams)" if names else "")
        for j, q in enumerate(c.q):
            out.add(force_output(f"F{j + 1}", q), per_point([None if sp is None else float(sp.F[j]) for sp in points]))
        out.extend(stress_values(hs, points, batch))
        out.add(_k_q_output(c), per_point([None if sp is None else sp.K_q.tolist() for sp in points]))
        out.add(Output("energy", "energy"), per_point([None if sp is None else sp.energy for sp in points]))
        out.extend(_formula_stiffness(model, hs))
        if inputs["stress_limit"]:
            last = sols[-1]
            limit, limit_message = (
                self._limit(model, hs, inputs, last, solver)
                if last.ok
                else (Values(), "no stress limit: the last point was not solved")
            )
            out.extend(limit)
            message += "; " + limit_message
        info = poses_solver_info(sols, solver.name)
        res = _hinge_result(self.name, model, status, out, info, message, statuses)
        return res.warn(*point_warnings(hs, points, inputs.get("sigma", inputs.get("sigma_allow"))))

    def _limit(
        self, model: Model, hs: cm.HingeSet, inputs: Mapping[str, Any], end: PoseSolution, solver: SolverConfig
    ) -> tuple[Values, str]:
        """The scale λ of the ray home -> end at which the largest stress reaches σ_allow."""
        sigma = inputs["sigma"]
        ray = _Ray(model, end, bool(given(inputs, model.closure.q_names)), solver)
        if inputs.get("six_axis") is not None:
            flexed = self._point(model, inputs, end)
            if flexed is not None:
                ray.t_linear_end = model.task_of(flexed[0].x)

        def excess(lam: float) -> float:
            sol = ray.pose(lam)
            if not sol.ok:
                raise _OutOfReach(lam, sol)
            got = self._point(model, inputs, sol)
            if got is None:
                raise _OutOfReach(lam, sol)
            sp = got[0]
            return (hs.checked(sp.stresses, inputs["stress_check"] == "peak") or 0.0) - sigma

        s_end = excess(1.0) + sigma
        lam_lin = sigma / s_end if s_end > 0 else None
        try:
            lam = self._root(excess, sigma, s_end, inputs, hs)
        except _OutOfReach as exc:
            return (
                Values(),
                f"the motion leaves the reachable poses (scale {exc.lam:g}: {exc.sol.status.value}) before a hinge "
                f"reaches sigma_allow",
            )
        if lam is None:
            return Values(), "the stresses never reach sigma_allow along this motion"
        at = ray.pose(lam)
        if inputs.get("six_axis") is not None:  # the flexible mechanism's pose there
            at = _Flexed(at, self._point(model, inputs, at)[0].x)
        values = _limit_values(model, ray, at, lam, lam_lin, sigma)
        which = "peak" if inputs["stress_check"] == "peak" else "nominal"
        return values, (
            f"first hinge at sigma_allow = {sigma / 1e6:.6g} MPa ({which} stress) at scale {lam:.6g} of the motion"
        )

    def _root(
        self, excess: Any, sigma: float, s_end: float, inputs: Mapping[str, Any], hs: cm.HingeSet
    ) -> float | None:
        """The root of ``excess`` on the ray: bracketed from [0, 1] by doubling, then Brent's
        method; None when the stresses never reach σ_allow."""
        s_start = excess(0.0) + sigma
        if s_start >= sigma:  # no root to bracket: the motion starts at or above the allowable stress
            raise InputError(
                f"the allowable stress {sigma:.6g} Pa is already reached at the start of the motion (home: "
                f"largest hinge stress {s_start:.6g} Pa, {s_end:.6g} Pa at its end); give a larger "
                "sigma_allow" + (" or a smaller load" if np.any(inputs["load"]) else ""),
                path=self._sigma_path(inputs, hs),
            )
        lam_hi = 1.0
        while excess(lam_hi) < 0:
            lam_hi *= 2.0
            if lam_hi > 1e6:
                return None
        return scipy.optimize.brentq(excess, 0.0 if lam_hi == 1.0 else lam_hi / 2, lam_hi, xtol=1e-12, rtol=1e-12)

    @staticmethod
    def _sigma_path(inputs: Mapping[str, Any], hs: cm.HingeSet) -> tuple:
        """Where the allowable stress was given: inputs.sigma_allow, else the hinge material."""
        if inputs.get("sigma_allow") is not None:
            return ("inputs", "sigma_allow")
        for h in hs.hinges:
            if h.material is not None and h.material.name in hs.material_at:
                return hs.material_at[h.material.name][0]
        return ("inputs", "sigma_allow")

    def outputs(self, model: Model) -> list[Output]:
        """The pose, the actuator forces, the stresses, K_q, the energy, the formula stiffness of
        each hinge group (the mechanism's, and the families of a problem's own), the stress limit."""
        c = model.closure
        hs = _declared_hinges(self, model)
        formula = _formula_stiffness(model, hs).outputs if hs is not None else []
        return [
            *_pose_outputs(model),
            *(force_output(f"F{j + 1}", q) for j, q in enumerate(c.q)),
            *_stress_outputs(hs),
            _k_q_output(c),
            Output("energy", "energy"),
            *formula,
            *K_FORMULA.values(),
            *_limit_outputs(model),
            BEAM_STRESS,
        ]


@dataclasses.dataclass(frozen=True)
class _Flexed:
    """A solved rigid pose with the pose of the flexible mechanism at its actuators."""

    rigid: PoseSolution
    x: np.ndarray

    def __getattr__(self, name: str) -> Any:
        return getattr(self.rigid, name)


class _OutOfReach(Exception):
    def __init__(self, lam: float, sol: PoseSolution) -> None:
        super().__init__(f"scale {lam}")
        self.lam, self.sol = lam, sol


class _Ray:
    """The motion from home towards a pose, scaled by λ: by the actuators (forward
    kinematics) or by the task coordinates (inverse kinematics)."""

    def __init__(self, model: Model, end: PoseSolution, by_actuators: bool, solver: SolverConfig) -> None:
        self.model, self.end, self.by_actuators, self.solver = model, end, by_actuators, solver
        self.t_home, self.t_end = model.task_of(model.x_home), model.task_of(end.x)
        #: the task at the motion's end that the linear extrapolation scales (the flexible mechanism's
        #: pose there, with flexible bodies)
        self.t_linear_end = self.t_end

    def pose(self, lam: float) -> PoseSolution:
        m = self.model
        if self.by_actuators:
            return forward_kinematics(m, m.q_home + lam * (self.end.q - m.q_home), self.solver)
        return inverse_kinematics(m, self.t_home + lam * (self.t_end - self.t_home), self.solver)


def _limit_outputs(model: Model) -> list[Output]:
    """σ_allow, the scale of the motion where the first hinge reaches it and the pose and
    actuators there, each also by linear extrapolation (the actuators not)."""
    c = model.closure
    out = [
        Output("sigma_allow", "stress"),
        Output("scale_at_allowable", "dimensionless"),
        Output("scale_at_allowable_linear", "dimensionless"),
    ]
    for i in c.task_index:
        out += [Output(f"{c.x[i].name}_at_allowable{s}", c.x[i].kind) for s in ("", "_linear")]
    for off, target in c.offsets.items():
        out += [Output(f"{off}_at_allowable{s}", c.x[c.x_names.index(target)].kind) for s in ("", "_linear")]
    return out + [Output(f"{qn}_at_allowable", c.q[j].kind) for j, qn in enumerate(c.q_names)]


def _limit_values(
    model: Model, ray: _Ray, sol: PoseSolution, lam: float, lam_lin: float | None, sigma: float
) -> Values:
    """The pose and actuators where the first hinge reaches σ_allow, and their linear extrapolation."""
    c = model.closure
    values: list[Any] = [sigma, lam, lam_lin]
    linear = {}
    for k, i in enumerate(c.task_index):
        linear[i] = ray.t_home[k] + lam_lin * (ray.t_linear_end[k] - ray.t_home[k])
        values += [float(sol.x[i]), float(linear[i])]
    for target in c.offsets.values():
        i = c.x_names.index(target)
        values += [float(sol.x[i] - model.x_home[i]), float(linear[i]) - float(model.x_home[i])]
    values += [float(v) for v in sol.q]
    return Values().add_all(zip(_limit_outputs(model), values, strict=True))


class PlatformCompliance(_HingeKind):
    name = "platform_compliance"
    #: the hinges, and the legs as serial chains for the six-axis hinge model (``hinge_axes: all``)
    parts = (cm.JointStiffness, LegChains)
    description = (
        "output compliance C = J (K_q + K_a)^-1 J^T at a pose and the compliant forward kinematics under a load "
        "(minimum potential energy on the loop closures, IPOPT): deflection, linear deflection C f, hinge stresses"
    )
    plots = ("ellipsoid",)

    def extra_options(self, model: Model) -> list[Option]:
        return [
            k_actuator_option(model),
            Option("hinge_axes", "choice", hinge_model_text(), default=None, choices=tuple(HINGE_MODELS)),
        ]

    def input_options(self, model: Model) -> list[Option]:
        return (
            task_options(model, "scalar")
            + actuator_options(model, "scalar")
            + super().input_options(model)[len(_pose_inputs(model)) :]
        )

    def resolve(self, inputs: dict[str, Any], model: Model, path: tuple) -> None:
        """The hinges, and the six-axis hinge model where ``hinge_axes`` asks for it (or by default can)."""
        super().resolve(inputs, model, path)
        chosen = inputs.get("hinge_axes")
        hinges = HINGE_MODELS[chosen] if chosen is not None else default_hinge_model(model)
        inputs["hinge_model"] = hinges.prepare(model, inputs["hinge_set"], path + ("hinge_axes",), chosen is not None)

    def check_inputs(self, inputs: dict[str, Any], model: Model, path: tuple) -> None:
        _check_pose_inputs(model, inputs, path, required=False)

    def run(self, model: Model, inputs: Mapping[str, Any], solver: SolverConfig) -> Result:
        sol = _commanded_pose(model, inputs, solver)
        out = Values(_pose_outputs(model), _pose_values(model, [sol], False))
        info = poses_solver_info([sol], solver.name)
        if not sol.ok:
            return _hinge_result(self.name, model, sol.status, out, info, sol.message)
        hinges: Prepared = inputs["hinge_model"]
        got = hinges.solve(model, inputs["hinge_set"], sol, inputs["load"], inputs["k_actuator"], info)
        res = _hinge_result(self.name, model, got.status, out.extend(got.values), got.solver, got.message)
        return res.warn(*got.warnings)

    def outputs(self, model: Model) -> list[Output]:
        c = model.closure
        xs, qs = coordinate_list(c.x), coordinate_list(c.q)
        return [
            *_pose_outputs(model),
            compliance_output(c),
            vector("deflection_linear", xs),
            vector("deflection", xs),
            vector("q_loaded", qs),
            *_stress_outputs(_declared_hinges(self, model), "_loaded"),
            *(diagonal_output(x) for x in c.x),
            *(Output(f"d_{x.name}", x.kind) for x in c.x),
            text("hinge_model"),
            Output("stress_max_unloaded", "stress"),
            Output("stress_peak_max_unloaded", "stress"),
            *(force_output(f"F{j + 1}_loaded", q) for j, q in enumerate(c.q)),
        ]
