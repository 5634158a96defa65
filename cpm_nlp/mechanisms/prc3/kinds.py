"""The 3-PRC's own problem kind: ``amplifier``, the ratios of its lever
amplifier (A1, A2) and the output d = A2 q for given inputs (Li et al. 2018, eq 1-2)."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from ...core.kind import ProblemKind, actuator_options, broadcast, check_actuator_limits, given
from ...core.model import Model
from ...core.options import Option
from ...core.outputs import Output
from ...core.result import Result
from ...core.solver import SolverConfig
from ...kinds.analysis import closed_form_result

# -- amplifier (eq 1-2) ------------------------------------------------------------------------------------


class Amplifier(ProblemKind):
    name = "amplifier"
    plots = ("amplifier",)
    description = "lever amplifier ratios A1, A2 (prc3 eq 1) and the output d = A2 q for given inputs (eq 2)"

    def supports(self, model: Model) -> str | None:
        return None if "A2" in model.derived else "it has no lever amplifier (no ratio A2)"

    def input_options(self, model: Model) -> list[Option]:
        return actuator_options(model, "grid")

    def check_inputs(self, inputs: dict[str, Any], model: Model, path: tuple) -> None:
        check_actuator_limits(model, inputs, path)
        names = given(inputs, model.closure.q_names)
        broadcast([inputs[n] for n in names], names, path)

    def run(self, model: Model, inputs: Mapping[str, Any], solver: SolverConfig) -> Result:
        A2 = model.derived["A2"]
        values: dict[str, Any] = {"A1": model.derived["A1"], "A2": A2}
        for k, name in enumerate(model.closure.q_names):
            q = inputs.get(name)
            if q is None:
                continue
            values[name] = q
            values[f"d{k + 1}"] = [A2 * v for v in q] if isinstance(q, list) else A2 * q  # eq 2
        declared = {o.name: o for o in self.outputs(model)}
        return closed_form_result(
            self.name,
            model,
            values,
            [declared[n] for n in values],
            message="A1 = L2/L1, A2 = L2 L4/(L1 L3) (eq 1); d = A2 q",
        )

    def outputs(self, model: Model) -> list[Output]:
        """The ratios (eq 1), the actuator inputs and the outputs d = A2 q (eq 2), lengths."""
        q = model.closure.q_names
        return [
            Output("A1", "dimensionless"),
            Output("A2", "dimensionless"),
            *(Output(n, "length") for n in q),
            *(Output(f"d{k + 1}", "length") for k in range(len(q))),
        ]
