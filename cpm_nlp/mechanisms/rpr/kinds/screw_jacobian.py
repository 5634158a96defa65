"""``rpr_screw_jacobian``: eq 7-13 by screw theory beside the AD Jacobians (rpr-2rpu-upr-zhang-2022.md)."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from ....core.model import Model
from ....core.outputs import Output, Values, matrix
from ....core.result import Result
from ....core.solver import SolverConfig
from ....kinds.kinematic import Jacobian
from .. import compliance as rpr_compliance
from .. import screws as rpr_screws
from .common import RprKind, _matrix

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
        values = (
            _matrix(st.S_t),
            _matrix(st.J_a),
            _matrix(st.J_b),
            _matrix(st.J),
            _matrix(st.G),
            _matrix(st.G_p),
            _matrix(G_p_ad),
            _agreement(st.J, J_ad),
            _agreement(st.G_p, G_p_ad),
        )
        extra = Values().add_all(zip(_screw_outputs(model), values, strict=True))
        return res.declare(extra.outputs).set(extra.values)

    def outputs(self, model: Model) -> list[Output]:
        """The AD Jacobians (`Jacobian`), then eq 7-13 by screw theory."""
        return super().outputs(model) + _screw_outputs(model)


def _screw_outputs(model: Model) -> list[Output]:
    """S_t, J_a, J_b (eq 7-9), J and G (eq 10-11), G_p (eq 13) and G_p by AD, and how far the screw
    and the AD matrices differ."""
    passive = ", ".join(model.closure.passive_names)
    return [
        matrix("S_t", "columns theta, alpha, P; rows wx wy wz [rad] vx vy vz [m] at o'"),
        matrix("J_a", "eq 9"),
        matrix("J_b", "eq 9"),
        matrix("J_st", "rows l1 l2 l3 per columns theta, alpha [rad], P [m] (eq 10; = J_inv by AD)"),
        matrix("G_st", "rows theta, alpha [rad], P [m] per columns l1 l2 l3 [m] (eq 11; = J by AD)"),
        matrix("G_p", f"rows {passive} [rad] per l1 l2 l3 [m] (eq 13)"),
        matrix("G_p_ad", "as G_p, by AD of the passive joint angles"),
        _agreement_output("dJ", "J_st - J_inv"),
        _agreement_output("dG_p", "G_p - G_p_ad"),
    ]


#: two computations of one matrix agree "within rounding" below this fraction of its largest entry
AGREEMENT_RESOLUTION = 1e-12


def _agreement(a: np.ndarray, b: np.ndarray) -> float:
    """max |a - b|, or 0 where it is within rounding (AGREEMENT_RESOLUTION of the largest entry):
    the rounding itself depends on the BLAS kernel, and a result must be the same on every machine."""
    d = float(np.max(np.abs(a - b)))
    scale = max(float(np.max(np.abs(a))), float(np.max(np.abs(b))), 1.0)
    return 0.0 if d <= AGREEMENT_RESOLUTION * scale else d
