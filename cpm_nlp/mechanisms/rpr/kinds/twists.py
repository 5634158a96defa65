"""``rpr_twists``: displacement twists of the platform per actuator (eq 45, rpr-2rpu-upr-zhang-2022.md)."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from ....core.errors import InputError
from ....core.kinematics import forward_kinematics, inverse_kinematics
from ....core.model import Model
from ....core.options import Option
from ....core.outputs import Output
from ....core.result import Result, SolverInfo, Status
from ....core.solver import SolverConfig
from .. import screws as rpr_screws
from .common import RprKind, _declare, _finish, _matrix, _pose, _pose_options

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
            return _finish(self, model, sol.status, {}, message=sol.message)
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
            return _finish(self, model, status, {}, message=msg)
        T_fk = np.column_stack(fk_cols)
        values = {
            "T": _matrix(T),
            "T_fk": _matrix(T_fk),
            "dT_fk": float(np.max(np.abs(T_fk - T))),
            "reference_point": c.tolist(),
            "convention": inputs["convention"],
            "theta": float(sol.x[0]),
            "alpha": float(sol.x[1]),
            "P": float(sol.x[2]),
        }
        return _finish(
            self,
            model,
            Status.SOLVED,
            values,
            SolverInfo(solver.name, iters),
            f"twists for d = {d:.3g} m on each actuator, {inputs['convention']} convention",
        )

    def outputs(self, model: Model) -> list[Output]:
        """The twists by G d and by the exact FK, their difference, the point they refer to, the
        convention of their moments, and the pose."""
        rows = "rows wx, wy, wz [rad], vx, vy, vz [m]; columns actuators 1, 2, 3"
        return _declare(
            {
                "T": "matrix",
                "T_fk": "matrix",
                "dT_fk": "dimensionless",
                "reference_point": "length",
                "convention": "text",
                **{x.name: x.kind for x in model.closure.x},
            },
            {
                "T": f"{rows} (linear G d; moments in the convention the value 'convention' names)",
                "T_fk": f"{rows}, S_t times the exact FK pose change",
                "dT_fk": "max |T_fk - T|",
                "convention": "",
            },
        )
