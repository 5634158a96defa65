"""``rpr_joint_design``: the R and U flexure joints (eq 27-32, Table 1, rpr-2rpu-upr-zhang-2022.md)."""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

from ....core.errors import InputError
from ....core.kind import require_ipopt
from ....core.model import Model
from ....core.options import Option
from ....core.outputs import Output
from ....core.result import Result, SolverInfo, Status
from ....core.schema import Record
from ....core.solver import SolverConfig
from ....core.units import result_unit
from .. import compliance as rpr_compliance
from .common import MM, RprKind, _declare, _finish, _material_option

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
        iters, seconds, messages, status = 0, 0.0, [], Status.SOLVED
        for joint in rpr_compliance.JOINTS:
            d = rpr_compliance.joint_design(model, joint, spec, solver, inputs["starts"])
            iters += d.iterations
            seconds += d.seconds
            messages.append(f"{joint}: {d.message}")
            if not d.status.ok:
                status = d.status
                continue
            values.update({f"{n}_{joint}": v for n, v in zip(rpr_compliance.VARIABLES[joint], d.dims)})
            if joint == "R":
                values["h_R"] = d.dims[1] + 2 * d.dims[0]  # the smallest block holding the notch
            values[f"f_{joint}"] = d.f
            values[f"theta_max_{joint}"] = d.theta_max
            values[f"k_{joint}"] = 1.0 / d.working
            values.update(d.compliances)
            for joint_c, geometry in inputs["compare"].items():
                if joint_c != joint:
                    continue
                ev = rpr_compliance.evaluate_joint(joint, spec, wrenches[joint], _joint_dims(joint, geometry))
                values[f"f_{joint}_compare"] = ev["f"]
                values[f"theta_max_{joint}_compare"] = ev["theta_max"]
                values[f"feasible_{joint}_compare"] = ev["feasible"]
                values[f"f_ratio_{joint}"] = ev["f"] / d.f
        return _finish(self, model, status, values, SolverInfo("ipopt", iters, seconds), "; ".join(messages))

    def outputs(self, model: Model) -> list[Output]:
        """Per joint (R, U): the optimal notch, f (eq 27), the rotation capability, the working
        stiffness, the diagonal compliances (eq 28-29) and those of a compared joint."""
        dims: dict[str, str] = {}
        units: dict[str, str] = {}
        for joint in rpr_compliance.JOINTS:
            dims.update({f"{n}_{joint}": "length" for n in rpr_compliance.VARIABLES[joint]})
            dims.update({"h_R": "length"} if joint == "R" else {})
            dims.update({f"f_{joint}": "dimensionless", f"theta_max_{joint}": "angle"})
            dims[f"k_{joint}"] = "rotational_stiffness"
            units[f"f_{joint}"] = units[f"f_{joint}_compare"] = "J per unit wrench (eq 27)"
            for n in rpr_compliance.COMPLIANCE_NAMES:  # eq 28-29: a translation per force, a rotation per moment
                name = f"c{joint.lower()}_{n}"
                dims[name] = "compliance" if n.startswith("t") else "rotational_compliance"
                units[name] = f"{result_unit(dims[name])}, joint frame (z along the leg)"
            dims.update({f"f_{joint}_compare": "dimensionless", f"theta_max_{joint}_compare": "angle"})
            dims.update({f"feasible_{joint}_compare": "bool", f"f_ratio_{joint}": "dimensionless"})
        return _declare(dims, units)
