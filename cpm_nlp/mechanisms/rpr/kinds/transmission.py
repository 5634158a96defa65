"""``rpr_transmission_map``: η over the (s, t) triangle (Fig. 4), plot-ready; the bound on η and
the design values that ``synthesis`` shares (rpr-2rpu-upr-zhang-2022.md, eq 19-26)."""

from __future__ import annotations

import math
from collections.abc import Mapping
from types import MappingProxyType
from typing import Any

import numpy as np

from ....core.errors import InputError
from ....core.model import Model
from ....core.options import Option
from ....core.outputs import Output
from ....core.result import Result, Status
from ....core.solver import SolverConfig
from .. import design as rpr_design
from .common import RprKind, _declare, _finish

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


#: the file's own design (r1, r2, P0) in the design plane, as both kinds report it
DESIGN_NAMES = ("l1_design", "l2_design", "l3_design", "s_design", "t_design", "eta_design", "design_in_space")


#: the dimensions of `DESIGN_NAMES`
DESIGN_DIMENSIONS = MappingProxyType({k: ("bool" if k == "design_in_space" else "dimensionless") for k in DESIGN_NAMES})


def _design_values(model: Model, eta_max: str) -> dict:
    r1, r2, P0 = (model.parameters[k] for k in ("r1", "r2", "P0"))
    D, l1, l2, l3 = rpr_design.normalize(r1, r2, P0)
    s, t = rpr_design.to_plane(l1, l2, l3)
    eta = rpr_design.eta(r1, r2, P0, eta_max)
    in_space = rpr_design.design_space_violation(l1, l2, l3) is None
    return dict(zip(DESIGN_NAMES, (l1, l2, l3, s, t, eta, in_space), strict=True))


#: the map over the (s, t) grid, its best and worst points, and the file's own design
MAP_OUTPUTS = _declare(
    {
        "s": "dimensionless",
        "t": "dimensionless",
        "eta": "matrix",
        "in_region": "matrix",
        "eta_best": "dimensionless",
        "s_best": "dimensionless",
        "t_best": "dimensionless",
        "eta_worst": "dimensionless",
        "points_inside": "dimensionless",
        "region_fraction": "dimensionless",
        "eta_region": "dimensionless",  # the bound of in_region, as the problem gave it
        **DESIGN_DIMENSIONS,
        "design_in_region": "bool",
    },
    {"eta": "rows t, columns s; null outside eq 22", "in_region": "eta >= eta_region; null outside eq 22"},
)


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
        if not inside.any():
            return _finish(
                self, model, Status.INFEASIBLE, {}, message="no grid point lies in the design space of eq 22"
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
                "eta_region": float(inputs["eta_region"]),  # the bound of in_region (a map states it)
            }
        )
        design = _design_values(model, mode)
        design["design_in_region"] = bool(design["eta_design"] >= inputs["eta_region"])
        values.update(design)
        return _finish(
            self, model, Status.SOLVED, values, message=f"{int(inside.sum())} of {E.size} grid points inside eq 22"
        )

    def outputs(self, model: Model) -> list[Output]:
        return list(MAP_OUTPUTS)
