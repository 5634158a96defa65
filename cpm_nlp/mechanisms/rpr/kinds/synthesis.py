"""``synthesis`` of the RPR (the shared kind, via the add-on's ``synthesis``): maximise η under
eq 22 (eq 19-26, rpr-2rpu-upr-zhang-2022.md)."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from ....core.kind import require_ipopt
from ....core.model import Model
from ....core.options import Option
from ....core.outputs import Output
from ....core.result import Result, SolverInfo, Status
from ....core.solver import SolverConfig
from .. import design as rpr_design
from .common import RprKind, _declare, _finish
from .transmission import DESIGN_DIMENSIONS, _design_values, _eta_max_option

#: the optimum (normalized and in length), the starts, every distinct local optimum, and the file's own design
SYNTHESIS_OUTPUTS = _declare(
    {
        **dict.fromkeys(("l1", "l2", "l3", "s", "t", "eta"), "dimensionless"),
        **dict.fromkeys(("D", "r1", "r2", "P"), "length"),
        **dict.fromkeys(("starts", "converged", "at_best"), "dimensionless"),
        "optima": "matrix",
        **DESIGN_DIMENSIONS,
    },
    {"optima": "rows l1, l2, l3, eta of each distinct local optimum, best first"},
)


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
            return _finish(self, model, res.status, {}, solver=info, message=res.message)
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
        values.update(_design_values(model, mode))
        return _finish(self, model, Status.SOLVED, values, info, res.message)

    def outputs(self, model: Model) -> list[Output]:
        return list(SYNTHESIS_OUTPUTS)
