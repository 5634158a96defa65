"""``rpr_screw_jacobian``: eq 7-13 by screw theory beside the AD Jacobians (rpr-2rpu-upr-zhang-2022.md)."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from ....core.model import Model
from ....core.result import Result
from ....core.solver import SolverConfig
from ....kinds.kinematic import Jacobian
from .. import compliance as rpr_compliance
from .. import screws as rpr_screws
from .common import RprKind, _matrix

# -- eq 7-13 --------------------------------------------------------------------------------------


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
        extra = {
            "S_t": _matrix(st.S_t),
            "J_a": _matrix(st.J_a),
            "J_b": _matrix(st.J_b),
            "J_st": _matrix(st.J),
            "G_st": _matrix(st.G),
            "G_p": _matrix(st.G_p),
            "G_p_ad": _matrix(G_p_ad),
            "dJ": _agreement(st.J, J_ad),
            "dG_p": _agreement(st.G_p, G_p_ad),
        }
        res.values.update(extra)
        res.units.update(
            {
                "S_t": "columns theta, alpha, P; rows wx wy wz [rad] vx vy vz [m] at o'",
                "J_a": "eq 9",
                "J_b": "eq 9",
                "J_st": "rows l1 l2 l3 per columns theta, alpha [rad], P [m] (eq 10; = J_inv by AD)",
                "G_st": "rows theta, alpha [rad], P [m] per columns l1 l2 l3 [m] (eq 11; = J by AD)",
                "G_p": "rows " + ", ".join(model.closure.passive_names) + " [rad] per l1 l2 l3 [m] (eq 13)",
                "G_p_ad": "as G_p, by AD of the passive joint angles",
                "dJ": "max |J_st - J_inv| (0 where within rounding: 1e-12 of the largest entry)",
                "dG_p": "max |G_p - G_p_ad| (0 where within rounding: 1e-12 of the largest entry)",
            }
        )
        res.dimensions.update({k: ("dimensionless" if k.startswith("d") else "matrix") for k in extra})
        return res

    def output_names(self, model: Model) -> list[str]:
        return super().output_names(model) + ["S_t", "J_a", "J_b", "J_st", "G_st", "G_p", "G_p_ad", "dJ", "dG_p"]


#: two computations of one matrix agree "within rounding" below this fraction of its largest entry
AGREEMENT_RESOLUTION = 1e-12


def _agreement(a: np.ndarray, b: np.ndarray) -> float:
    """max |a - b|, or 0 where it is within rounding (AGREEMENT_RESOLUTION of the largest entry):
    the rounding itself depends on the BLAS kernel, and a result must be the same on every machine."""
    d = float(np.max(np.abs(a - b)))
    scale = max(float(np.max(np.abs(a))), float(np.max(np.abs(b))), 1.0)
    return 0.0 if d <= AGREEMENT_RESOLUTION * scale else d
