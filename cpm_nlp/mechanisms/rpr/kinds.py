"""Problem kinds of the RPR compliant mechanism (rpr-2rpu-upr-zhang-2022.md):

* ``rpr_screw_jacobian`` -- eq 7-13 by screw theory beside the AD Jacobians;
* ``rpr_twists`` -- displacement twists of the platform per actuator (eq 45);
* ``rpr_transmission_map`` -- η over the (s, t) triangle (Fig. 4), plot-ready;
* ``synthesis`` (the shared kind, via the add-on's ``synthesis``) -- maximise η under eq 22 (eq 19-26);
* ``rpr_joint_design`` -- the R and U flexure joints (eq 27-32, Table 1);
* ``rpr_compliance`` -- the pseudo-rigid-body compliance model (eq 33-44).

Every kind applies to the ``rpr`` mechanism only (:meth:`supports`), the mechanism of the file
problems/mechanisms/rpr.yaml, and runs on its closures (pose, passive joints, Jacobians).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from typing import Any

import numpy as np

from ...analysis import flexure
from ...core.errors import InputError
from ...core.kind import ProblemKind, require_ipopt
from ...core.kinematics import forward_kinematics, inverse_kinematics
from ...core.model import Model
from ...core.options import Option
from ...core.outputs import Output, Values, declared_result, matrix
from ...core.result import STATUS_TEXT, Result, SolverInfo, Status
from ...core.schema import Record
from ...core.solver import SolverConfig
from ...kinds.kinematic import Jacobian, _model_info
from . import compliance as rpr_compliance
from . import design as rpr_design
from . import screws as rpr_screws

MM = 1e-3


class RprKind(ProblemKind):
    """A problem kind that applies to the RPR mechanism only."""

    def supports(self, model: Model) -> str | None:
        return None if model.name == "rpr" else "it is specific to the RPR mechanism (type rpr)"


def _pose_options(model: Model) -> list[Option]:
    """The pose (theta, alpha, P) of the file's closure, each defaulting to the initial pose."""
    return [
        Option(c.name, c.kind, c.description + " (default: the initial pose)", default=None) for c in model.closure.x
    ]


def _pose(model: Model, inputs: Mapping[str, Any]) -> np.ndarray:
    return np.array(
        [model.x_home[i] if inputs.get(c.name) is None else inputs[c.name] for i, c in enumerate(model.closure.x)]
    )


def _matrix(a: np.ndarray) -> list:
    return np.asarray(a, dtype=float).tolist()


def _finish(
    kind: str,
    model: Model,
    status: Status,
    values: dict,
    dims: dict,
    units: dict | None = None,
    solver: SolverInfo | None = None,
    message: str = "",
) -> Result:
    """The result of an RPR kind: each value declared by its dimension (``dims``), with its
    own unit text from ``units`` where the dimension's SI unit does not say it."""
    if not status.ok:
        values = {}
    texts = units or {}
    return declared_result(
        kind,
        status,
        [_output(k, dims[k], texts.get(k)) for k in values],
        values,
        solver=solver,
        message=message or STATUS_TEXT[status],
        model=_model_info(model),
    )


def _output(name: str, dimension: str, unit: str | None) -> Output:
    """An output of an RPR kind: a matrix or a flag has no unit unless its text is given."""
    if unit is None and dimension in ("matrix", "bool"):
        unit = ""
    return Output(name, dimension, dimension if dimension in ("matrix", "text") else "value", unit=unit)


def _check_material(mat: Any, path: tuple) -> flexure.Material:
    mat = flexure.material(mat, path)
    if mat.nu is None or mat.yield_strength is None:
        raise InputError(f"material '{mat.name}' needs nu and yield_strength (eq 32 and the shear modulus)", path=path)
    return mat


def _material_option() -> Any:
    """``material``: a name or inline, with nu and yield strength (eq 32 and the shear modulus)."""
    node = flexure.material_node("material", "the joints' material, with nu and yield_strength", "Al 7075-T6")
    return dataclasses.replace(node, convert=_check_material)


# -- eq 7-13 --------------------------------------------------------------------------------------


def _agreement_output(name: str, difference: str) -> Output:
    """The largest entry of a difference of two matrices (0 within rounding)."""
    return Output(
        name, "dimensionless", unit=f"max |{difference}| (0 where within rounding: 1e-12 of the largest entry)"
    )


class ScrewJacobian(RprKind, Jacobian):
    name = "rpr_screw_jacobian"
    plots = ("jacobian", "matrices")
    description = "RPR Jacobian J, G and passive rates G_p by screw theory (eq 7-13) beside the AD Jacobians"

    def run(self, model: Model, inputs: Mapping[str, Any], solver: SolverConfig) -> Result:
        res = super().run(model, inputs, solver)
        if not res.ok:
            return res
        x = np.array([res.values[n] for n in model.closure.x_names])
        st = rpr_screws.screw_jacobian(model, x)
        G_p_ad = rpr_compliance.passive_rates(model, x)[1]
        J_ad = np.array(res.values["J_inv"])
        passive = ", ".join(model.closure.passive_names)
        extra = (
            Values()
            .add(matrix("S_t", "columns theta, alpha, P; rows wx wy wz [rad] vx vy vz [m] at o'"), _matrix(st.S_t))
            .add(matrix("J_a", "eq 9"), _matrix(st.J_a))
            .add(matrix("J_b", "eq 9"), _matrix(st.J_b))
            .add(
                matrix("J_st", "rows l1 l2 l3 per columns theta, alpha [rad], P [m] (eq 10; = J_inv by AD)"),
                _matrix(st.J),
            )
            .add(
                matrix("G_st", "rows theta, alpha [rad], P [m] per columns l1 l2 l3 [m] (eq 11; = J by AD)"),
                _matrix(st.G),
            )
            .add(matrix("G_p", f"rows {passive} [rad] per l1 l2 l3 [m] (eq 13)"), _matrix(st.G_p))
            .add(matrix("G_p_ad", "as G_p, by AD of the passive joint angles"), _matrix(G_p_ad))
            .add(_agreement_output("dJ", "J_st - J_inv"), _agreement(st.J, J_ad))
            .add(_agreement_output("dG_p", "G_p - G_p_ad"), _agreement(st.G_p, G_p_ad))
        )
        return res.declare(extra.outputs).set(extra.values)

    def output_names(self, model: Model) -> list[str]:
        return super().output_names(model) + ["S_t", "J_a", "J_b", "J_st", "G_st", "G_p", "G_p_ad", "dJ", "dG_p"]


# -- section 5.1 ------------------------------------------------------------------------------------


class Twists(RprKind):
    name = "rpr_twists"
    plots = ("twists", "matrices")
    description = "displacement twists of the RPR platform for a small displacement of each actuator (eq 45)"

    def input_options(self, model: Model) -> list[Option]:
        return _pose_options(model) + [
            Option(
                "d",
                "length",
                "displacement applied to each actuator in turn (section 5.1: 10 µm)",
                default=10e-6,
                lower=0.0,
                upper=1e-3,
                strict=True,
            ),
            Option(
                "reference",
                "choice",
                "point the translational rows refer to: o' (the platform centre), o (the fixed origin) or 'point'",
                default="o_prime",
                choices=rpr_screws.REFERENCES,
            ),
            Option(
                "point",
                "length",
                "the reference point [x, y, z] in the fixed frame (reference: point)",
                default=None,
                shape="list",
                max_len=3,
            ),
            Option(
                "convention",
                "choice",
                "velocity: the velocity of the reference point; eq45: each "
                "rotation's moment with the position vector from the axis to the reference (how eq 45 and 47 "
                "are printed)",
                default="velocity",
                choices=rpr_screws.CONVENTIONS,
            ),
        ]

    def check_inputs(self, inputs: dict[str, Any], model: Model, path: tuple) -> None:
        point = inputs.get("point")
        if inputs["reference"] == "point" and (point is None or len(point) != 3):
            raise InputError("reference 'point' needs 'point' with three coordinates [x, y, z]", path=path + ("point",))
        if inputs["reference"] != "point" and point is not None:
            raise InputError(
                f"'point' is used only with reference: point (reference is '{inputs['reference']}')",
                path=path + ("point",),
            )

    def run(self, model: Model, inputs: Mapping[str, Any], solver: SolverConfig) -> Result:
        x0 = _pose(model, inputs)
        sol = inverse_kinematics(model, x0, solver)
        if not sol.ok:
            return _finish(self.name, model, sol.status, {}, {}, message=sol.message)
        c = rpr_screws.reference_point(model, sol.x, inputs["reference"], inputs.get("point"))
        S = rpr_screws.twist_basis(model, sol.x, c, inputs["convention"])
        G = rpr_screws.screw_jacobian(model, sol.x).G
        d = inputs["d"]
        T = S @ G * d  # one column per actuator
        fk_cols, iters, status, msg = [], 0, Status.SOLVED, ""
        for k in range(3):
            q = sol.q.copy()
            q[k] += d
            fk = forward_kinematics(model, q, solver, guess=sol.x)
            iters += fk.iterations
            if not fk.ok:
                status, msg = fk.status, f"FK with l{k + 1} + d: {fk.message}"
                break
            fk_cols.append(S @ (fk.x - sol.x))
        if not status.ok:
            return _finish(self.name, model, status, {}, {}, message=msg)
        T_fk = np.column_stack(fk_cols)
        values = {
            "T": _matrix(T),
            "T_fk": _matrix(T_fk),
            "dT_fk": float(np.max(np.abs(T_fk - T))),
            "reference_point": c.tolist(),
            "theta": float(sol.x[0]),
            "alpha": float(sol.x[1]),
            "P": float(sol.x[2]),
        }
        dims = {
            "T": "matrix",
            "T_fk": "matrix",
            "dT_fk": "dimensionless",
            "reference_point": "length",
            "theta": "angle",
            "alpha": "angle",
            "P": "length",
        }
        rows = "rows wx, wy, wz [rad], vx, vy, vz [m]; columns actuators 1, 2, 3"
        units = {
            "T": f"{rows} ({inputs['convention']} convention, linear G d)",
            "T_fk": f"{rows}, S_t times the exact FK pose change",
            "dT_fk": "max |T_fk - T|",
        }
        return _finish(
            self.name,
            model,
            Status.SOLVED,
            values,
            dims,
            units,
            SolverInfo(solver.name, iters),
            f"twists for d = {d:.3g} m on each actuator, {inputs['convention']} convention",
        )

    def output_names(self, model: Model) -> list[str]:
        return ["T", "T_fk", "dT_fk", "reference_point", "theta", "alpha", "P"]


# -- eq 14-26 ---------------------------------------------------------------------------------------


def _eta_max_option() -> Option:
    return Option(
        "eta_max",
        "choice",
        "|S_T ∘ S_O|max: distance from B1 to the axis of S_O (the paper) or the "
        "speed of B1, sqrt(d² + h²) (Wang et al. 2010)",
        default="distance",
        choices=rpr_design.ETA_MAX_MODES,
    )


def _design_values(model: Model, eta_max: str) -> tuple[dict, dict]:
    r1, r2, P0 = (model.parameters[k] for k in ("r1", "r2", "P0"))
    D, l1, l2, l3 = rpr_design.normalize(r1, r2, P0)
    s, t = rpr_design.to_plane(l1, l2, l3)
    values = {
        "l1_design": l1,
        "l2_design": l2,
        "l3_design": l3,
        "s_design": s,
        "t_design": t,
        "eta_design": rpr_design.eta(r1, r2, P0, eta_max),
        "design_in_space": rpr_design.design_space_violation(l1, l2, l3) is None,
    }
    dims = {k: ("bool" if k == "design_in_space" else "dimensionless") for k in values}
    return values, dims


class TransmissionMap(RprKind):
    name = "rpr_transmission_map"
    description = "output transmission index eta over a grid of the (s, t) design triangle (eq 19-23, Fig. 4)"
    plots = ("map",)
    map_axes = ("s", "t", "eta")  # rpr-2rpu-upr-zhang-2022.md, Fig. 4

    def input_options(self, model: Model) -> list[Option]:
        return [
            Option("s", "dimensionless", "values of s = l2 (eq 23)", shape="grid"),
            Option("t", "dimensionless", "values of t = (l3 - l1)/sqrt(3) (eq 23)", shape="grid"),
            Option(
                "eta_region",
                "dimensionless",
                "the optimum region is where eta >= this value",
                default=0.99,
                lower=0.0,
                upper=1.0,
            ),
            _eta_max_option(),
        ]

    def check_inputs(self, inputs: dict[str, Any], model: Model, path: tuple) -> None:
        for key in ("s", "t"):
            if not isinstance(inputs[key], list):
                inputs[key] = [inputs[key]]
        n = len(inputs["s"]) * len(inputs["t"])
        if n > 250_000:
            raise InputError(f"the grid has {n} points; expected at most 250000", path=path)

    def run(self, model: Model, inputs: Mapping[str, Any], solver: SolverConfig) -> Result:
        s, t = np.array(inputs["s"]), np.array(inputs["t"])
        mode = inputs["eta_max"]
        E = rpr_design.transmission_map(s, t, mode)
        inside = np.isfinite(E)
        region = E >= inputs["eta_region"]
        values: dict[str, Any] = {
            "s": s.tolist(),
            "t": t.tolist(),
            "eta": [[None if not math.isfinite(v) else float(v) for v in row] for row in E],
            "in_region": [
                [None if not ok else bool(v) for ok, v in zip(irow, rrow)] for irow, rrow in zip(inside, region)
            ],
        }
        dims = {"s": "dimensionless", "t": "dimensionless", "eta": "matrix", "in_region": "matrix"}
        if not inside.any():
            return _finish(
                self.name, model, Status.INFEASIBLE, {}, {}, message="no grid point lies in the design space of eq 22"
            )
        k = np.nanargmax(E)
        i, j = np.unravel_index(k, E.shape)
        values.update(
            {
                "eta_best": float(E[i, j]),
                "s_best": float(s[j]),
                "t_best": float(t[i]),
                "eta_worst": float(np.nanmin(E)),
                "points_inside": int(inside.sum()),
                "region_fraction": float(region[inside].mean()),
            }
        )
        design, ddims = _design_values(model, mode)
        design["design_in_region"] = bool(design["eta_design"] >= inputs["eta_region"])
        ddims["design_in_region"] = "bool"
        values.update(design)
        dims.update(
            {
                "eta_best": "dimensionless",
                "s_best": "dimensionless",
                "t_best": "dimensionless",
                "eta_worst": "dimensionless",
                "points_inside": "dimensionless",
                "region_fraction": "dimensionless",
                **ddims,
            }
        )
        units = {"eta": "rows t, columns s; null outside eq 22", "in_region": "eta >= eta_region; null outside eq 22"}
        return _finish(
            self.name,
            model,
            Status.SOLVED,
            values,
            dims,
            units,
            message=f"{int(inside.sum())} of {E.size} grid points inside eq 22",
        )

    def output_names(self, model: Model) -> list[str]:
        return [
            "s",
            "t",
            "eta",
            "in_region",
            "eta_best",
            "s_best",
            "t_best",
            "eta_worst",
            "points_inside",
            "region_fraction",
            "l1_design",
            "l2_design",
            "l3_design",
            "s_design",
            "t_design",
            "eta_design",
            "design_in_space",
            "design_in_region",
        ]


class Synthesis(RprKind):
    name = "synthesis"
    description = "dimensional synthesis of the RPR: maximise eta (eq 19) under eq 22 by IPOPT multi-start"

    def input_options(self, model: Model) -> list[Option]:
        return [
            Option(
                "l_min",
                "dimensionless",
                "smallest admissible normalized parameter (eq 22 only asks l_i > 0, and eta -> 1 as l3 -> 0)",
                default=0.1,
                lower=0.0,
                upper=1.0,
                strict=True,
            ),
            Option("l1", "dimensionless", "fix l1 = r1/D (eq 21)", default=None, lower=0.0, upper=3.0, strict=True),
            Option("l2", "dimensionless", "fix l2 = r2/D (eq 21)", default=None, lower=0.0, upper=3.0, strict=True),
            Option("l3", "dimensionless", "fix l3 = P/D (eq 21)", default=None, lower=0.0, upper=3.0, strict=True),
            Option(
                "starts", "int", "number of IPOPT starts (Halton points of the triangle)", default=8, lower=1, upper=200
            ),
            _eta_max_option(),
        ]

    def check_inputs(self, inputs: dict[str, Any], model: Model, path: tuple) -> None:
        fixed = {k: inputs[k] for k in ("l1", "l2", "l3") if inputs.get(k) is not None}
        if len(fixed) == 3:
            rpr_design.check_design_space(fixed["l1"], fixed["l2"], fixed["l3"], path)
        elif len(fixed) == 2:
            (a, va), (b, vb) = fixed.items()
            rest = ({"l1", "l2", "l3"} - set(fixed)).pop()
            ls = dict(fixed)
            ls[rest] = 3.0 - va - vb
            rpr_design.check_design_space(ls["l1"], ls["l2"], ls["l3"], path + (b,))

    def check_solver(self, solver: SolverConfig) -> None:
        require_ipopt(solver, self.name)

    def run(self, model: Model, inputs: Mapping[str, Any], solver: SolverConfig) -> Result:
        fixed = {k: inputs[k] for k in ("l1", "l2", "l3") if inputs.get(k) is not None}
        mode = inputs["eta_max"]
        res = rpr_design.synthesis(
            model, solver, l_min=inputs["l_min"], fixed=fixed, starts=inputs["starts"], eta_max=mode
        )
        info = SolverInfo("ipopt", res.iterations, res.seconds)
        if not res.status.ok:
            return _finish(self.name, model, res.status, {}, {}, solver=info, message=res.message)
        l1, l2, l3 = res.l
        s, t = rpr_design.to_plane(l1, l2, l3)
        D = model.derived["D"]
        values = {
            "l1": l1,
            "l2": l2,
            "l3": l3,
            "s": s,
            "t": t,
            "eta": res.eta,
            "D": D,
            "r1": l1 * D,
            "r2": l2 * D,
            "P": l3 * D,
            "starts": res.starts,
            "converged": res.converged,
            "at_best": res.at_best,
            "optima": [list(o) for o in res.optima],
        }
        dims = {k: "dimensionless" for k in values}
        dims.update({"D": "length", "r1": "length", "r2": "length", "P": "length", "optima": "matrix"})
        design, ddims = _design_values(model, mode)
        values.update(design)
        dims.update(ddims)
        units = {"optima": "rows l1, l2, l3, eta of each distinct local optimum, best first"}
        return _finish(self.name, model, Status.SOLVED, values, dims, units, info, res.message)

    def output_names(self, model: Model) -> list[str]:
        return [
            "l1",
            "l2",
            "l3",
            "s",
            "t",
            "eta",
            "D",
            "r1",
            "r2",
            "P",
            "starts",
            "converged",
            "at_best",
            "optima",
            "l1_design",
            "l2_design",
            "l3_design",
            "s_design",
            "t_design",
            "eta_design",
            "design_in_space",
        ]


# -- eq 27-32 ---------------------------------------------------------------------------------------

_JOINT_GEOMETRY = {
    "R": (
        Option("r", "length", "notch radius", lower=0.0, upper=1.0, strict=True),
        Option("t", "length", "thinnest section", lower=0.0, upper=1.0, strict=True),
        Option("b", "length", "width (along the rotation axis)", lower=0.0, upper=1.0, strict=True),
        Option(
            "h", "length", "block height (not used by the notch model)", default=None, lower=0.0, upper=1.0, strict=True
        ),
    ),
    "U": (
        Option("r", "length", "notch radius", lower=0.0, upper=1.0, strict=True),
        Option("t", "length", "thinnest section", lower=0.0, upper=1.0, strict=True),
        Option("h", "length", "side of the square rod (width of both notches)", lower=0.0, upper=1.0, strict=True),
    ),
}


def _joints_option(name: str, description: str) -> Record:
    """Circular-notch R and U joints by their dimensions ({R: {r, t, b}, U: {r, t, h}}); only those given."""
    return Record(
        name,
        description,
        tuple(
            Record(j, f"the {j} joint's notch", _JOINT_GEOMETRY[j], default=None, what="joint dimension")
            for j in rpr_compliance.JOINTS
        ),
        default=None,
        sparse=True,
        mismatch="expected a mapping {R: {r, t, b}, U: {r, t, h}}",
        unknown="unknown joint {key}; expected R or U",
        convert=lambda value, _path: {j: g for j, g in (value or {}).items() if g is not None},
    )


def _joint_dims(joint: str, geometry: Mapping[str, Any]) -> tuple[float, float, float]:
    return (geometry["r"], geometry["t"], geometry["b" if joint == "R" else "h"])


class JointDesign(RprKind):
    name = "rpr_joint_design"
    plots = ("comparison",)
    description = "optimal R and U flexure joints of the RPR (eq 27-32, Table 1) by IPOPT multi-start"

    def input_options(self, model: Model) -> list[Option]:
        return [
            Option("SF", "dimensionless", "safety factor of eq 32 (not given by the paper)", lower=1.0, upper=100.0),
            Option(
                "theta_des",
                "angle",
                "rotation each joint must allow (eq 32: 2 deg)",
                default=math.radians(2),
                lower=0.0,
                upper=math.pi / 4,
                strict=True,
            ),
            Option(
                "box",
                "length",
                "size box of a joint (section 3.1: 12 mm)",
                default=12 * MM,
                lower=0.0,
                upper=1.0,
                strict=True,
            ),
            Option(
                "t_min",
                "length",
                "thinnest admissible section (section 3.1: 0.3 mm)",
                default=0.3 * MM,
                lower=0.0,
                upper=1.0,
                strict=True,
            ),
            Option(
                "couple_arm",
                "length",
                "length that makes the unit couple of eq 27 a work per unit force (1 m: eq 27 in SI units)",
                default=1.0,
                lower=0.0,
                upper=100.0,
                strict=True,
            ),
            Option(
                "rotation_limit",
                "choice",
                "eq32 (as printed) or notch (circular-notch stress limit)",
                default="eq32",
                choices=rpr_compliance.ROTATION_LIMITS,
            ),
            Option("starts", "int", "number of IPOPT starts per joint", default=6, lower=1, upper=100),
            _material_option(),
            _joints_option("compare", "joints to evaluate beside the optimum: {R: {r, t, b}, U: {r, t, h}}"),
        ]

    def check_inputs(self, inputs: dict[str, Any], model: Model, path: tuple) -> None:
        if not inputs["t_min"] < inputs["box"] / 4:
            raise InputError(
                f"expected t_min below a quarter of the box (a notch and its two cuts must fit), got t_min = "
                f"{inputs['t_min'] * 1e3:g} mm, box = {inputs['box'] * 1e3:g} mm",
                path=path + ("t_min",),
            )

    def check_solver(self, solver: SolverConfig) -> None:
        require_ipopt(solver, self.name)

    def run(self, model: Model, inputs: Mapping[str, Any], solver: SolverConfig) -> Result:
        spec = rpr_compliance.JointSpec(
            inputs["material"],
            inputs["SF"],
            inputs["theta_des"],
            inputs["box"],
            inputs["t_min"],
            inputs["couple_arm"],
            inputs["rotation_limit"],
        )
        wrenches = rpr_compliance.design_wrenches(model, spec.couple_arm)
        values: dict[str, Any] = {}
        dims: dict[str, str] = {}
        iters, seconds, messages, status = 0, 0.0, [], Status.SOLVED
        for joint in rpr_compliance.JOINTS:
            d = rpr_compliance.joint_design(model, joint, spec, solver, inputs["starts"])
            iters += d.iterations
            seconds += d.seconds
            messages.append(f"{joint}: {d.message}")
            if not d.status.ok:
                status = d.status
                continue
            names = rpr_compliance.VARIABLES[joint]
            for n, v in zip(names, d.dims):
                values[f"{n}_{joint}"] = v
                dims[f"{n}_{joint}"] = "length"
            if joint == "R":
                values["h_R"] = d.dims[1] + 2 * d.dims[0]  # the smallest block holding the notch
                dims["h_R"] = "length"
            values[f"f_{joint}"] = d.f
            values[f"theta_max_{joint}"] = d.theta_max
            values[f"k_{joint}"] = 1.0 / d.working
            dims.update(
                {f"f_{joint}": "dimensionless", f"theta_max_{joint}": "angle", f"k_{joint}": "rotational_stiffness"}
            )
            for k, v in d.compliances.items():
                values[k] = v
                dims[k] = "dimensionless"
            for joint_c, geometry in inputs["compare"].items():
                if joint_c != joint:
                    continue
                ev = rpr_compliance.evaluate_joint(joint, spec, wrenches[joint], _joint_dims(joint, geometry))
                values[f"f_{joint}_compare"] = ev["f"]
                values[f"theta_max_{joint}_compare"] = ev["theta_max"]
                values[f"feasible_{joint}_compare"] = ev["feasible"]
                values[f"f_ratio_{joint}"] = ev["f"] / d.f
                dims.update(
                    {
                        f"f_{joint}_compare": "dimensionless",
                        f"theta_max_{joint}_compare": "angle",
                        f"feasible_{joint}_compare": "bool",
                        f"f_ratio_{joint}": "dimensionless",
                    }
                )
        units = {
            k: ("m/N" if k[3] == "t" else "rad/(N m)") + ", joint frame (z along the leg)"
            for k in values
            if k.startswith(("cr_", "cu_"))
        }
        units.update({"f_R": "J per unit wrench (eq 27)", "f_U": "J per unit wrench (eq 27)"})
        return _finish(
            self.name, model, status, values, dims, units, SolverInfo("ipopt", iters, seconds), "; ".join(messages)
        )

    def output_names(self, model: Model) -> list[str]:
        names = []
        for joint in rpr_compliance.JOINTS:
            names += [f"{n}_{joint}" for n in rpr_compliance.VARIABLES[joint]]
            names += (["h_R"] if joint == "R" else []) + [f"f_{joint}", f"theta_max_{joint}", f"k_{joint}"]
            names += [f"c{joint.lower()}_{n}" for n in rpr_compliance.COMPLIANCE_NAMES]
            names += [
                f"f_{joint}_compare",
                f"theta_max_{joint}_compare",
                f"feasible_{joint}_compare",
                f"f_ratio_{joint}",
            ]
        return names


# -- eq 33-44 ---------------------------------------------------------------------------------------

_AMPLIFIER = (
    Option(
        "l1",
        "length",
        "arm of the output force f_y (eq 33; 16 mm, see rpr_compliance)",
        lower=0.0,
        upper=1.0,
        strict=True,
    ),
    Option("l2", "length", "arm of the input force f_x (eq 33; 1.6 mm)", lower=0.0, upper=1.0, strict=True),
    Option(
        "k_r",
        "rotational_stiffness",
        "stiffness 1/c_r of a leaf hinge's PRB rotation",
        default=None,
        lower=0.0,
        strict=True,
    ),
    Option("k_t", "stiffness", "stiffness 1/c_t of a leaf hinge's stretch", default=None, lower=0.0, strict=True),
)
_LEAF = (
    Option("length", "length", "leaf length", lower=0.0, upper=1.0, strict=True),
    Option("thickness", "length", "leaf thickness", lower=0.0, upper=1.0, strict=True),
    Option("width", "length", "leaf width", lower=0.0, upper=1.0, strict=True),
)


def _leaf_or_stiffness(amp: Mapping[str, Any], path: tuple) -> None:
    """The amplifier's hinges: by the leaf's dimensions, or by both stiffnesses k_r and k_t."""
    given = [k for k in ("k_r", "k_t") if amp[k] is not None]
    if amp["leaf"] is not None and given:
        raise InputError("give either leaf or k_r and k_t, not both", path=path)
    if amp["leaf"] is None and len(given) != 2:
        raise InputError("expected leaf: {length, thickness, width} or both k_r and k_t", path=path)


class Compliance(RprKind):
    name = "rpr_compliance"
    plots = ("matrices",)
    description = "pseudo-rigid-body compliance C and input compliance C_in of the RPR (eq 33-44)"

    def input_options(self, model: Model) -> list[Option]:
        return _pose_options(model) + [
            Option(
                "k_R",
                "rotational_stiffness",
                "stiffness of every R joint's rotation (instead of joints.R)",
                default=None,
                lower=0.0,
                strict=True,
            ),
            Option(
                "k_U",
                "rotational_stiffness",
                "stiffness of every U joint axis (instead of joints.U)",
                default=None,
                lower=0.0,
                strict=True,
            ),
            _material_option(),
            Record(
                "amplifier",
                "the displacement amplifier: {l1, l2, leaf: {length, thickness, width}} or {l1, l2, k_r, k_t}",
                (*_AMPLIFIER, Record("leaf", "the leaf hinges", _LEAF, default=None, what="leaf dimension")),
                what="amplifier key",
                check=_leaf_or_stiffness,
            ),
            _joints_option("joints", "the R and U joints by their dimensions: {R: {r, t, b}, U: {r, t, h}}"),
        ]

    def check_inputs(self, inputs: dict[str, Any], model: Model, path: tuple) -> None:
        for joint in rpr_compliance.JOINTS:
            has_k = inputs[f"k_{joint}"] is not None
            has_geometry = joint in inputs["joints"]
            if has_k == has_geometry:
                raise InputError(f"give either joints.{joint} (its dimensions) or k_{joint} (its stiffness)", path=path)

    def run(self, model: Model, inputs: Mapping[str, Any], solver: SolverConfig) -> Result:
        mat = inputs["material"]
        x0 = _pose(model, inputs)
        sol = inverse_kinematics(model, x0, solver)
        if not sol.ok:
            return _finish(self.name, model, sol.status, {}, {}, message=sol.message)
        amp = inputs["amplifier"]
        if amp["leaf"] is not None:
            leaf = amp["leaf"]
            c_r, c_t = rpr_compliance.leaf_compliances(mat, leaf["length"], leaf["thickness"], leaf["width"])
        else:
            c_r, c_t = 1.0 / amp["k_r"], 1.0 / amp["k_t"]
        k = {}
        for joint in rpr_compliance.JOINTS:
            if inputs[f"k_{joint}"] is not None:
                k[joint] = inputs[f"k_{joint}"]
            else:
                dims = _joint_dims(joint, inputs["joints"][joint])
                k[joint] = 1.0 / float(rpr_compliance.working_compliance(joint, mat.E, mat.G, dims))
        out = rpr_compliance.compliance_model(
            model,
            sol.x,
            l1=amp["l1"],
            l2=amp["l2"],
            c_r=c_r,
            c_t=c_t,
            k_J=rpr_compliance.stiffness_order(model, k["R"], k["U"]),
        )
        values = {
            "c_r": c_r,
            "c_t": c_t,
            "k_R": k["R"],
            "k_U": k["U"],
            "A11": float(out["A11"][0, 0]),
            "A12": float(out["A12"][0, 0]),
            "A21": float(out["A21"][0, 0]),
            "A22": float(out["A22"][0, 0]),
            "K_J": np.diag(out["K_J"]).tolist(),
            "G": _matrix(out["G"]),
            "G_p": _matrix(out["G_p"]),
            "K_prime": _matrix(out["K_prime"]),
            "C": _matrix(out["C"]),
            "C_in": _matrix(out["C_in"]),
            "amp": out["amp"].tolist(),
            "amp_free": amp["l1"] / amp["l2"],
        }
        dims = {k_: "matrix" for k_ in values}
        dims.update(
            {
                "c_r": "dimensionless",
                "c_t": "dimensionless",
                "k_R": "rotational_stiffness",
                "k_U": "rotational_stiffness",
                "A11": "dimensionless",
                "A12": "dimensionless",
                "A21": "dimensionless",
                "A22": "dimensionless",
                "K_J": "rotational_stiffness",
                "amp": "dimensionless",
                "amp_free": "dimensionless",
            }
        )
        units = {
            "c_r": "rad/(N m)",
            "c_t": "m/N",
            "A11": "m/N",
            "A12": "m/N",
            "A21": "m/N",
            "A22": "m/N",
            "K_J": "N m/rad, order " + ", ".join(model.closure.passive_names),
            "G": "rows theta, alpha [rad], P [m] per l1 l2 l3 [m]",
            "G_p": "rows " + ", ".join(model.closure.passive_names) + " [rad] per l1 l2 l3 [m]",
            "K_prime": "N/m (eq 40)",
            "C": "rows theta [rad/N], alpha [rad/N], P [m/N]; columns input forces 1, 2, 3 (eq 43)",
            "C_in": "m/N (eq 44)",
            "amp": "D_out/D_in per leg under the mechanism's load",
            "amp_free": "l1/l2, the unloaded amplification",
        }
        return _finish(
            self.name,
            model,
            Status.SOLVED,
            values,
            dims,
            units,
            SolverInfo("closed_form"),
            "compliance at the pose solved by closed-form IK",
        )

    def output_names(self, model: Model) -> list[str]:
        return [
            "c_r",
            "c_t",
            "k_R",
            "k_U",
            "A11",
            "A12",
            "A21",
            "A22",
            "K_J",
            "G",
            "G_p",
            "K_prime",
            "C",
            "C_in",
            "amp",
            "amp_free",
        ]


#: two computations of one matrix agree "within rounding" below this fraction of its largest entry
AGREEMENT_RESOLUTION = 1e-12


def _agreement(a: np.ndarray, b: np.ndarray) -> float:
    """max |a - b|, or 0 where it is within rounding (AGREEMENT_RESOLUTION of the largest entry):
    the rounding itself depends on the BLAS kernel, and a result must be the same on every machine."""
    d = float(np.max(np.abs(a - b)))
    scale = max(float(np.max(np.abs(a))), float(np.max(np.abs(b))), 1.0)
    return 0.0 if d <= AGREEMENT_RESOLUTION * scale else d
