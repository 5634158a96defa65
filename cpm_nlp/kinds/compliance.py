"""Problem kinds of compliance, stiffness and strength, for any mechanism whose
joints carry hinges (declared by the mechanism's part ``stiffness``, a
:class:`~cpm_nlp.analysis.compliance.JointStiffness`, or given under
``inputs.hinges``); the method is :mod:`cpm_nlp.analysis.compliance`.

* ``actuator_forces`` -- the actuator forces, input stiffness K_q and hinge
  stresses along a motion (actuator inputs, or poses through IK), and the motion
  at which the first hinge reaches the allowable stress;
* ``platform_compliance`` -- the 6x6 (nx x nx) output compliance at a pose and the
  compliant forward kinematics under a load;
* ``natural_frequencies`` -- frequencies and mode shapes, linearized Lagrange at
  a pose, from masses and inertias on the coordinates and the hinge stiffness.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np
import scipy.optimize

from ..analysis import compliance as cm
from ..analysis import validity
from ..analysis.dynamics import parse_inertia, parse_mass
from ..analysis.hinge_chains import LegChains, SixAxisModel
from ..analysis.hinge_models import HINGE_MODELS, default_hinge_model, hinge_model_text
from ..core.canonical import canonical_eigh, degenerate_note, multiplicities
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
from ..core.result import STATUS_TEXT, Result, SolverInfo, Status, worst_status
from ..core.schema import Record
from ..core.solver import SolverConfig
from ..core.units import result_unit
from .hinge_inputs import hinge_options, k_actuator_option, load_option, mass_node
from .kinematic import _model_info, _pose_names, _pose_values


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
    #: :func:`~cpm_nlp.analysis.compliance.hinge_set`)
    parts = (cm.JointStiffness,)

    def supports(self, model: Model) -> str | None:
        c = model.closure
        if c.nx == 0:  # pragma: no cover - every closure has a pose
            return "it has no pose coordinates"
        return None

    def extra_options(self, model: Model) -> list[Option]:
        return []

    def input_options(self, model: Model) -> list[Option]:
        return _pose_inputs(model) + hinge_options() + [load_option(model)] + self.extra_options(model)

    def resolve(self, inputs: dict[str, Any], model: Model, path: tuple) -> None:
        """The hinges (the mechanism's merged with ``hinges`` and ``material``)."""
        inputs["hinge_set"] = cm.hinge_set(model, inputs["hinges"], inputs["material"], inputs.get("sigma_allow"), path)


def _stress_values(hs: cm.HingeSet, points: list[cm.StaticPoint | None], batch: bool) -> tuple[dict, dict]:
    groups = sorted({h.group for h in hs.hinges if h.kind is not None})
    values: dict[str, Any] = {}
    dims: dict[str, str] = {}
    cols: dict[str, list] = {"stress_max": []}
    cols.update({f"stress_{g}": [] for g in groups})
    for sp in points:
        if sp is None:
            for v in cols.values():
                v.append(None)
            continue
        cols["stress_max"].append(sp.stress_max)
        for g in groups:
            vals = [s for h, s in zip(hs.hinges, sp.stresses.values()) if h.group == g and s is not None]
            cols[f"stress_{g}"].append(max(vals) if vals else None)
    for k, v in cols.items():
        values[k] = v if batch else v[0]
        dims[k] = "stress"
    return values, dims


def _point_warnings(hs: cm.HingeSet, points: list[cm.StaticPoint | None], sigma: float | None = None) -> list:
    """The hinges' geometry, stresses and deflections at the solved points (:mod:`~cpm_nlp.analysis.validity`)."""
    pts = [
        None if sp is None else (sp.stresses, validity.hinge_deflections(hs.hinges, sp.theta, hs.theta0))
        for sp in points
    ]
    return validity.hinge_warnings(hs.hinges, pts, sigma)


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

    def run(self, model: Model, inputs: Mapping[str, Any], solver: SolverConfig) -> Result:
        c = model.closure
        hs: cm.HingeSet = inputs["hinge_set"]
        f = inputs["load"]
        sols, batch = _solve_poses(model, inputs, solver)
        points = [cm.static_point(model, hs, s.x, s.q, f) if s.ok else None for s in sols]
        status, message, statuses = _summary(sols, batch)
        names, dims = _pose_names(model)
        values = _pose_values(model, sols, batch)
        units = {n: result_unit(dims[n]) for n in names}
        for j in range(c.nq):
            col = [None if sp is None else float(sp.F[j]) for sp in points]
            values[f"F{j + 1}"] = col if batch else col[0]
            dims[f"F{j + 1}"] = "force" if c.q[j].kind == "length" else "moment"
            units[f"F{j + 1}"] = "N" if c.q[j].kind == "length" else "N*m"
        sv, sd = _stress_values(hs, points, batch)
        values.update(sv)
        dims.update(sd)
        units.update({k: "Pa" for k in sd})
        kq = [None if sp is None else sp.K_q.tolist() for sp in points]
        energy = [None if sp is None else sp.energy for sp in points]
        values.update(K_q=kq if batch else kq[0], energy=energy if batch else energy[0])
        dims.update(K_q="matrix", energy="energy")
        units.update(K_q=f"N/m or N*m/rad (rows and columns {', '.join(c.q_names)})", energy="J")
        seen: set[str] = set()
        for h in hs.hinges:
            if h.group in seen:
                continue
            seen.add(h.group)
            for a, kf in h.k_formula.items():
                kind = [model.closure.x, model.closure.q, model.closure.passive_coords]
                coord = (list(kind[0]) + list(kind[1]) + list(kind[2]))[h.axes[a]]
                values[f"k_formula_{h.group}_{a}"] = kf
                dims[f"k_formula_{h.group}_{a}"] = "rotational_stiffness" if coord.kind == "angle" else "stiffness"
                units[f"k_formula_{h.group}_{a}"] = "N*m/rad" if coord.kind == "angle" else "N/m"
        if inputs["stress_limit"]:
            last = sols[-1]
            lim_values, lim_dims, lim_msg = (
                self._limit(model, hs, inputs, last, solver)
                if last.ok
                else ({}, {}, "no stress limit: the last point was not solved")
            )
            values.update(lim_values)
            dims.update(lim_dims)
            units.update({k: result_unit(d) for k, d in lim_dims.items()})
            message += "; " + lim_msg
        info = SolverInfo(
            "+".join(sorted({s.solver for s in sols if s.solver})) or solver.name,
            sum(s.iterations for s in sols),
            sum(s.seconds for s in sols),
        )
        res = Result(self.name, status, values, units, dims, info, message, statuses, _model_info(model))
        return res.warn(*_point_warnings(hs, points, inputs.get("sigma", inputs.get("sigma_allow"))))

    def _limit(self, model: Model, hs: cm.HingeSet, inputs: Mapping[str, Any], end: PoseSolution, solver):  # noqa: C901 - bracket, root, then one value family per coordinate kind
        """The scale λ of the ray home -> end at which the largest stress reaches σ_allow."""
        c = model.closure
        sigma = inputs["sigma"]
        by_actuators = bool(given(inputs, c.q_names))
        t_home, t_end = model.task_of(model.x_home), model.task_of(end.x)

        def pose(lam: float) -> PoseSolution:
            if by_actuators:
                return forward_kinematics(model, model.q_home + lam * (end.q - model.q_home), solver)
            return inverse_kinematics(model, t_home + lam * (t_end - t_home), solver)

        def excess(lam: float) -> float:
            sol = pose(lam)
            if not sol.ok:
                raise _OutOfReach(lam, sol)
            sp = cm.static_point(model, hs, sol.x, sol.q, inputs["load"])
            return (sp.stress_max or 0.0) - sigma

        s_end = excess(1.0) + sigma
        lam_lin = sigma / s_end if s_end > 0 else None
        lam_hi = 1.0
        try:
            s_start = excess(0.0) + sigma
            if s_start >= sigma:  # no root to bracket: the motion starts at or above the allowable stress
                raise InputError(
                    f"the allowable stress {sigma:.6g} Pa is already reached at the start of the motion (home: "
                    f"largest hinge stress {s_start:.6g} Pa, {s_end:.6g} Pa at its end); give a larger "
                    "sigma_allow" + (" or a smaller load" if np.any(inputs["load"]) else ""),
                    path=self._sigma_path(inputs, hs),
                )
            while excess(lam_hi) < 0:
                lam_hi *= 2.0
                if lam_hi > 1e6:
                    return {}, {}, "the stresses never reach sigma_allow along this motion"
            lam = scipy.optimize.brentq(excess, 0.0 if lam_hi == 1.0 else lam_hi / 2, lam_hi, xtol=1e-12, rtol=1e-12)
        except _OutOfReach as exc:
            return (
                {},
                {},
                f"the motion leaves the reachable poses (scale {exc.lam:g}: {exc.sol.status.value}) before a hinge "
                f"reaches sigma_allow",
            )
        sol = pose(lam)
        values: dict[str, Any] = {"sigma_allow": sigma, "scale_at_allowable": lam, "scale_at_allowable_linear": lam_lin}
        dims: dict[str, str] = {"sigma_allow": "stress", "scale_at_allowable": "dimensionless"}
        dims["scale_at_allowable_linear"] = "dimensionless"
        for k, i in enumerate(c.task_index):
            name = c.x[i].name
            values[f"{name}_at_allowable"] = float(sol.x[i])
            values[f"{name}_at_allowable_linear"] = float(t_home[k] + lam_lin * (t_end[k] - t_home[k]))
            dims[f"{name}_at_allowable"] = dims[f"{name}_at_allowable_linear"] = c.x[i].kind
        for off, target in c.offsets.items():
            i = c.x_names.index(target)
            values[f"{off}_at_allowable"] = float(sol.x[i] - model.x_home[i])
            values[f"{off}_at_allowable_linear"] = values[f"{target}_at_allowable_linear"] - float(model.x_home[i])
            dims[f"{off}_at_allowable"] = dims[f"{off}_at_allowable_linear"] = c.x[i].kind
        for j, qn in enumerate(c.q_names):
            values[f"{qn}_at_allowable"] = float(sol.q[j])
            dims[f"{qn}_at_allowable"] = c.q[j].kind
        return values, dims, f"first hinge at sigma_allow = {sigma / 1e6:.6g} MPa at scale {lam:.6g} of the motion"

    @staticmethod
    def _sigma_path(inputs: Mapping[str, Any], hs: cm.HingeSet) -> tuple:
        """Where the allowable stress was given: inputs.sigma_allow, else the hinge material."""
        if inputs.get("sigma_allow") is not None:
            return ("inputs", "sigma_allow")
        for h in hs.hinges:
            if h.material is not None and h.material.name in hs.material_at:
                return hs.material_at[h.material.name][0]
        return ("inputs", "sigma_allow")

    def output_names(self, model: Model) -> list[str]:
        c = model.closure
        names = _pose_names(model)[0] + [f"F{j + 1}" for j in range(c.nq)] + ["stress_max", "K_q", "energy"]
        names += ["sigma_allow", "scale_at_allowable", "scale_at_allowable_linear"]
        for i in c.task_index:
            names += [f"{c.x[i].name}_at_allowable", f"{c.x[i].name}_at_allowable_linear"]
        for off in c.offsets:
            names += [f"{off}_at_allowable", f"{off}_at_allowable_linear"]
        names += [f"{q}_at_allowable" for q in c.q_names]
        decl = self.part(model, cm.JointStiffness)
        if decl is not None:
            names += [f"stress_{g}" for g in decl.records]
            for g, spec in decl.records.items():  # stiffness from the hinge formula, where a geometry is given
                if spec.type:
                    joints = spec.joints
                    names += [f"k_formula_{g}_{a}" for a in (joints if isinstance(joints, Mapping) else ("bend",))]
        return names


class _OutOfReach(Exception):
    def __init__(self, lam: float, sol: PoseSolution) -> None:
        super().__init__(f"scale {lam}")
        self.lam, self.sol = lam, sol


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
        six, fallback = hinges.six_axis(model, inputs["hinge_set"], path + ("hinge_axes",), chosen is not None)
        inputs["six_axis"] = six
        if fallback:
            inputs["fallback"] = fallback

    def check_inputs(self, inputs: dict[str, Any], model: Model, path: tuple) -> None:
        _check_pose_inputs(model, inputs, path, required=False)

    def run(self, model: Model, inputs: Mapping[str, Any], solver: SolverConfig) -> Result:  # noqa: C901 - one branch per hinge model and outcome
        c = model.closure
        hs: cm.HingeSet = inputs["hinge_set"]
        f, ka = inputs["load"], inputs["k_actuator"]
        sol = _commanded_pose(model, inputs, solver)
        names, dims = _pose_names(model)
        units = {n: result_unit(dims[n]) for n in names}
        values = _pose_values(model, [sol], False)
        info = SolverInfo(sol.solver or solver.name, sol.iterations, sol.seconds)
        if not sol.ok:
            return Result(self.name, sol.status, values, units, dims, info, sol.message, None, _model_info(model))
        note = inputs.get("fallback", "")
        if inputs["six_axis"] is not None:
            res = self._run_six_axis(model, inputs, sol, (values, units, dims, info))
            if res is not None:
                return res
            note = (
                "; the six-axis hinge model is singular here (a motion of the legs' chains meets no hinge, "
                "e.g. a leg's spin between two spherical joints), so the default fell back to hinge_axes: kinematic"
            )
        values["hinge_model"], dims["hinge_model"], units["hinge_model"] = "kinematic", "text", ""
        sp = cm.static_point(model, hs, sol.x, sol.q)
        try:
            C = cm.output_compliance(sp, ka)
        except np.linalg.LinAlgError:
            msg = (
                "K_q + K_a is singular: the hinges and actuators leave a motion without stiffness "
                "(give a positive k_actuator, or more hinges)"
            )
            return Result(self.name, Status.SINGULAR, values, units, dims, info, msg, None, _model_info(model))
        lin = C @ f
        loaded = cm.compliant_fk(model, hs, sol.x, sol.q, sp.F, f, ka)
        xs = ", ".join(f"{x.name} [{result_unit(x.kind)}]" for x in c.x)
        values.update(C=C.tolist(), deflection_linear=lin.tolist())
        dims.update(C="matrix", deflection_linear="vector")
        units.update(C=f"rows and columns {xs}; m/N, rad/(N*m) and mixed", deflection_linear=xs)
        for i, x in enumerate(c.x):
            values[f"C_{x.name}"] = float(C[i, i])
            dims[f"C_{x.name}"] = "compliance" if x.kind == "length" else "rotational_compliance"
            units[f"C_{x.name}"] = "m/N" if x.kind == "length" else "rad/(N*m)"
        status, message = Status.SOLVED, "compliant forward kinematics by IPOPT (" + loaded.message + ")"
        if not np.any(f):
            message = "no load: the output compliance only"
        if loaded.ok:
            d = loaded.x - sol.x
            values["deflection"] = d.tolist()
            dims["deflection"] = "vector"
            units["deflection"] = xs
            for i, x in enumerate(c.x):
                values[f"d_{x.name}"] = float(d[i])
                dims[f"d_{x.name}"] = x.kind
                units[f"d_{x.name}"] = result_unit(x.kind)
            spl = cm.static_point(model, hs, loaded.x, loaded.q)
            sv, sd = _stress_values(hs, [spl], False)
            values.update({k + "_loaded": v for k, v in sv.items()})
            dims.update({k + "_loaded": v for k, v in sd.items()})
            units.update({k + "_loaded": "Pa" for k in sd})
            values["q_loaded"] = loaded.q.tolist()
            dims["q_loaded"] = "vector"
            units["q_loaded"] = ", ".join(f"{q.name} [{result_unit(q.kind)}]" for q in c.q)
        else:
            status = Status.NOT_CONVERGED
        if ka is None:
            message += "; actuators rigidly held: a pseudo-rigid-body model with rigid links does not deflect"
        message += note
        info = SolverInfo("ipopt", sol.iterations + loaded.iterations, sol.seconds)
        res = Result(self.name, status, values, units, dims, info, message, None, _model_info(model))
        if not loaded.ok:
            return res.warn(*validity.hinge_geometry_warnings(hs.hinges))
        res.warn(*_point_warnings(hs, [spl]))
        return res.warn(*validity.linear_range_warnings(d, lin, c.x_names, [x.kind for x in c.x]))

    def _run_six_axis(self, model: Model, inputs: Mapping[str, Any], sol: PoseSolution, parts: tuple) -> Result | None:  # noqa: C901 - unloaded, linearized, loaded, then one value family each
        """The six-axis hinge model: the unloaded equilibrium at the commanded actuators, the
        output compliance there, and the loaded pose by IPOPT."""
        values, units, dims, info = parts
        c = model.closure
        sm: SixAxisModel = inputs["six_axis"]
        f, ka = inputs["load"], inputs["k_actuator"]
        xs = ", ".join(f"{x.name} [{result_unit(x.kind)}]" for x in c.x)
        try:
            z0 = sm.start(sol.x, sol.q)
            ok, z_u, lam_u, it_u = sm.newton(z0, np.zeros(c.nx), sol.q, None, None)
            if not ok:
                msg = "six-axis hinge model: no unloaded equilibrium at the commanded actuators (Newton on the KKT)"
                return Result(self.name, Status.NOT_CONVERGED, values, units, dims, info, msg, None, _model_info(model))
            Fc = sm.actuator_reactions(z_u, lam_u, np.zeros(c.nx))
            C = sm.compliance(z_u, lam_u, ka, None if ka is None else Fc)
        except np.linalg.LinAlgError:
            if inputs.get("hinge_axes") is None:
                return None  # the default: the caller falls back to the kinematic model
            msg = (
                "the six-axis hinge model's stiffness is singular: a motion of the legs' chains meets no hinge and "
                "no actuator (e.g. a leg's spin between two spherical joints; give a positive k_actuator, more "
                "hinges, or hinge_axes: kinematic)"
            )
            return Result(self.name, Status.SINGULAR, values, units, dims, info, msg, None, _model_info(model))
        values.update(C=C.tolist(), deflection_linear=(C @ f).tolist(), hinge_model="all")
        dims.update(C="matrix", deflection_linear="vector", hinge_model="text")
        units.update(C=f"rows and columns {xs}; m/N, rad/(N*m) and mixed", deflection_linear=xs, hinge_model="")
        for i, x in enumerate(c.x):
            values[f"C_{x.name}"] = float(C[i, i])
            dims[f"C_{x.name}"] = "compliance" if x.kind == "length" else "rotational_compliance"
            units[f"C_{x.name}"] = "m/N" if x.kind == "length" else "rad/(N*m)"
        unloaded = sm.stresses(z_u)
        values["stress_max_unloaded"] = max((v for v in unloaded.values() if v is not None), default=None)
        dims["stress_max_unloaded"], units["stress_max_unloaded"] = "stress", "Pa"
        six = ", ".join(sm.six_axis_hinges) or "none"
        note = f"six-axis hinges: {six}; {sm.chains.note}"
        if not np.any(f):
            info = SolverInfo("newton-kkt", sol.iterations + it_u, sol.seconds)
            msg = f"no load: the output compliance only ({note})"
            res = Result(self.name, Status.SOLVED, values, units, dims, info, msg, None, _model_info(model))
            return res.warn(*_six_axis_warnings(sm, [z_u]))
        ok, z_l, lam_l, it_l, st = sm.ipopt(z_u, f, sol.q, ka, None if ka is None else Fc)
        info = SolverInfo("ipopt", sol.iterations + it_u + it_l, sol.seconds)
        if not ok:
            msg = f"six-axis compliant forward kinematics by IPOPT did not converge ({st})"
            return Result(self.name, Status.NOT_CONVERGED, values, units, dims, info, msg, None, _model_info(model))
        d = z_l[: c.nx] - z_u[: c.nx]
        values["deflection"] = d.tolist()
        dims["deflection"], units["deflection"] = "vector", xs
        for i, x in enumerate(c.x):
            values[f"d_{x.name}"] = float(d[i])
            dims[f"d_{x.name}"] = x.kind
            units[f"d_{x.name}"] = result_unit(x.kind)
        q_l = z_l[c.nx : c.nx + c.nq]
        values["q_loaded"] = q_l.tolist()
        dims["q_loaded"] = "vector"
        units["q_loaded"] = ", ".join(f"{q.name} [{result_unit(q.kind)}]" for q in c.q)
        loaded = sm.stresses(z_l)
        values["stress_max_loaded"] = max((v for v in loaded.values() if v is not None), default=None)
        dims["stress_max_loaded"], units["stress_max_loaded"] = "stress", "Pa"
        if ka is None:
            F = sm.actuator_reactions(z_l, lam_l, f)
            for j, q in enumerate(c.q):
                values[f"F{j + 1}_loaded"] = float(F[j])
                dims[f"F{j + 1}_loaded"] = "force" if q.kind == "length" else "moment"
                units[f"F{j + 1}_loaded"] = "N" if q.kind == "length" else "N*m"
        msg = f"compliant forward kinematics by IPOPT ({st}, {it_l} iterations); {note}"
        res = Result(self.name, Status.SOLVED, values, units, dims, info, msg, None, _model_info(model))
        res.warn(*_six_axis_warnings(sm, [z_l]))
        return res.warn(*validity.linear_range_warnings(d, C @ f, c.x_names, [x.kind for x in c.x]))

    def output_names(self, model: Model) -> list[str]:
        c = model.closure
        names = _pose_names(model)[0] + ["C", "deflection_linear", "deflection", "q_loaded", "stress_max_loaded"]
        names += [f"C_{x.name}" for x in c.x] + [f"d_{x.name}" for x in c.x]
        names += ["hinge_model", "stress_max_unloaded"] + [f"F{j + 1}_loaded" for j in range(c.nq)]
        return names


def _six_axis_warnings(sm: SixAxisModel, zs: list[np.ndarray]) -> list:
    """Geometry, stresses and deflections of the six-axis model's hinges at the equilibria ``zs``."""
    pts = [(sm.stresses(z), validity.six_axis_deflections(sm.frames, z)) for z in zs]
    return validity.hinge_warnings(sm.hs.hinges, pts)


class NaturalFrequencies(_HingeKind):
    name = "natural_frequencies"
    description = (
        "natural frequencies and mode shapes at a pose: linearized Lagrange with M = J^T M_x J + M_q from masses "
        "and inertias on the coordinates and K = K_q, the hinge energy's Hessian along the loop closures"
    )
    plots = ("modes",)

    def input_options(self, model: Model) -> list[Option]:
        opts = task_options(model, "scalar") + actuator_options(model, "scalar") + hinge_options()
        c = model.closure
        names = c.x_names + c.q_names
        coords = (*c.x, *c.q)
        text = "expected masses: a mapping of coordinate -> mass or inertia over " + ", ".join(names)

        def non_empty(value: Any, path: tuple) -> None:
            if not value:
                raise InputError(text, path=path)

        opts.append(
            Record(
                "masses",
                "mass (on a length coordinate: '12 g', or a block {length, width, height} of the material) or "
                "inertia (on an angle coordinate: kg*m^2, or a block {length, width, height, about: x|y|z} of the "
                "material turning about its own axis through its centre) per pose or actuator coordinate: "
                + ", ".join(names),
                tuple(mass_node(co.name, co.description, co.kind == "angle") for co in coords),
                what="coordinate",
                sparse=True,
                mismatch=text,
                check=non_empty,
            )
        )
        return opts

    def resolve(self, inputs: dict[str, Any], model: Model, path: tuple) -> None:
        """The hinges, and the mass matrices M_x, M_q of the masses (a block's of the hinge material)."""
        super().resolve(inputs, model, path)
        c = model.closure
        hs: cm.HingeSet = inputs["hinge_set"]
        mat = next((h.material for h in hs.hinges if h.material is not None), None)
        density, name = (mat.density, mat.name) if mat else (None, "?")
        mx, mq = np.zeros(c.nx), np.zeros(c.nq)
        for key, value in inputs["masses"].items():
            if value is None:
                continue
            where = path + ("masses", key)
            if key in c.x_names:
                kind = c.x[c.x_names.index(key)].kind
            else:
                kind = c.q[c.q_names.index(key)].kind
            if kind == "length":
                m = parse_mass(value, density, name, where)
            else:
                m = parse_inertia(value, density, name, where)
            if key in c.x_names:
                mx[c.x_names.index(key)] = m
            else:
                mq[c.q_names.index(key)] = m
        inputs["M_x"], inputs["M_q"] = mx, mq

    def check_inputs(self, inputs: dict[str, Any], model: Model, path: tuple) -> None:
        _check_pose_inputs(model, inputs, path, required=False)

    def run(self, model: Model, inputs: Mapping[str, Any], solver: SolverConfig) -> Result:
        c = model.closure
        hs: cm.HingeSet = inputs["hinge_set"]
        sol = _commanded_pose(model, inputs, solver)
        names, dims = _pose_names(model)
        units = {n: result_unit(dims[n]) for n in names}
        values = _pose_values(model, [sol], False)
        info = SolverInfo(sol.solver or solver.name, sol.iterations, sol.seconds)
        if not sol.ok:
            return Result(self.name, sol.status, values, units, dims, info, sol.message, None, _model_info(model))
        sp = cm.static_point(model, hs, sol.x, sol.q)
        M = sp.J.T @ np.diag(inputs["M_x"]) @ sp.J + np.diag(inputs["M_q"])
        K = 0.5 * (sp.K_q + sp.K_q.T)
        try:  # canonical modes: the same on every BLAS kernel (docs/site/guide/compliance.md)
            lam, modes, clusters = canonical_eigh(K, M, T=sp.J)  # read in the pose coordinates
        except np.linalg.LinAlgError:
            return Result(
                self.name,
                Status.SINGULAR,
                values,
                units,
                dims,
                info,
                "the mass matrix J^T M_x J + M_q is singular: give masses that move every actuated direction",
                None,
                _model_info(model),
            )
        freq = np.sqrt(np.clip(lam, 0.0, None)) / (2 * np.pi)
        for k in range(c.nq):
            values[f"f{k + 1}"] = float(freq[k])
            dims[f"f{k + 1}"] = "frequency"
            units[f"f{k + 1}"] = "Hz"
        shapes = (sp.J @ modes).T
        values.update(M=M.tolist(), K=K.tolist(), modes_q=modes.T.tolist(), modes_x=shapes.tolist())
        values["multiplicity"] = multiplicities(clusters)
        dims.update(M="matrix", K="matrix", modes_q="matrix", modes_x="matrix", multiplicity="vector")
        units.update(
            M=f"kg or kg*m^2 (generalized coordinates {', '.join(c.q_names)})",
            K="N/m or N*m/rad",
            modes_q=f"rows: modes; columns {', '.join(c.q_names)} (M-normalized, canonical in the pose coordinates)",
            modes_x=f"rows: modes; columns {', '.join(c.x_names)} (J times modes_q)",
            multiplicity="per mode: how many frequencies equal its own (1: a simple frequency)",
        )
        msg = "frequencies from |K_q - (2 pi f)^2 M| = 0 at the pose"
        repeated = [idx for idx in clusters if len(idx) > 1]
        if repeated:
            msg += "; " + "; ".join(degenerate_note(idx) for idx in repeated)
        res = Result(self.name, Status.SOLVED, values, units, dims, info, msg, None, _model_info(model))
        return res.warn(*_point_warnings(hs, [sp]))

    def output_names(self, model: Model) -> list[str]:
        c = model.closure
        names = _pose_names(model)[0] + [f"f{k + 1}" for k in range(c.nq)]
        return names + ["M", "K", "modes_q", "modes_x", "multiplicity"]
