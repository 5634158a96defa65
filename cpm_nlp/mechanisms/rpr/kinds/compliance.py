"""``rpr_compliance``: the pseudo-rigid-body compliance model of the RPR (eq 33-44,
rpr-2rpu-upr-zhang-2022.md)."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from ....core.errors import InputError
from ....core.kinematics import inverse_kinematics
from ....core.model import Model
from ....core.options import Option
from ....core.outputs import Output
from ....core.result import Result, SolverInfo, Status
from ....core.schema import Record
from ....core.solver import SolverConfig
from ....core.units import result_unit
from .. import compliance as rpr_compliance
from .common import RprKind, _declare, _finish, _material_option, _matrix, _pose, _pose_options
from .joint_design import _joint_dims, _joints_option

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
    Option(
        "model",
        "choice",
        "prb: the pseudo-rigid-body rotation and stretch of Fig. 8 (c_r = 12 L/(E w t^3), c_t = L/(E w t)); beam: "
        "the leaf as a Timoshenko beam (its compliance at its centre; also reports the transverse compliance c_s "
        "that eq 33-36 leave out)",
        default="prb",
        choices=("prb", "beam"),
    ),
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
            return _finish(self, model, sol.status, {}, message=sol.message)
        amp = inputs["amplifier"]
        c_s = None
        if amp["leaf"] is not None:
            leaf = amp["leaf"]
            dims = (leaf["length"], leaf["thickness"], leaf["width"])
            if leaf["model"] == "beam":
                mat.require("nu", ("inputs", "material"), "the leaf as a Timoshenko beam")
                c_r, c_t, c_s = rpr_compliance.leaf_beam_compliances(mat, *dims)
            else:
                c_r, c_t = rpr_compliance.leaf_compliances(mat, *dims)
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
            "c_s": c_s,
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
        return _finish(
            self,
            model,
            Status.SOLVED,
            values,
            SolverInfo("closed_form"),
            "compliance at the pose solved by closed-form IK",
        )

    def outputs(self, model: Model) -> list[Output]:
        """The amplifier's and the joints' compliance and stiffness, the amplifier's matrix (eq 33),
        the Jacobians, K' (eq 40), C (eq 43), C_in (eq 44) and the amplification."""
        passive = ", ".join(model.closure.passive_names)
        dims = {
            "c_r": "rotational_compliance",
            "c_t": "compliance",
            "c_s": "compliance",
            "k_R": "rotational_stiffness",
            "k_U": "rotational_stiffness",
            **dict.fromkeys(("A11", "A12", "A21", "A22"), "compliance"),
            "K_J": "rotational_stiffness",
            **dict.fromkeys(("G", "G_p", "K_prime", "C", "C_in"), "matrix"),
            "amp": "dimensionless",
            "amp_free": "dimensionless",
        }
        units = {
            "K_J": f"{result_unit('rotational_stiffness')}, order {passive}",
            "G": "rows theta, alpha [rad], P [m] per l1 l2 l3 [m]",
            "G_p": f"rows {passive} [rad] per l1 l2 l3 [m]",
            "K_prime": "N/m (eq 40)",
            "C": "rows theta [rad/N], alpha [rad/N], P [m/N]; columns input forces 1, 2, 3 (eq 43)",
            "C_in": "m/N (eq 44)",
            "amp": "D_out/D_in per leg under the mechanism's load",
            "amp_free": "l1/l2, the unloaded amplification",
        }
        return _declare(dims, units)
