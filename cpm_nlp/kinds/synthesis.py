"""The ``synthesis`` problem kind: dimensional synthesis of a mechanism.

Every paper states its own synthesis (design variables, objective,
constraints), so the kind dispatches to the mechanism: a mechanism that
supports it declares its formulation, a :class:`SynthesisFormulation`
subclass, as the capability ``Mechanism.synthesis``.  The kind itself only looks the formulation
up and hands it the validated model, inputs and solver.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from ..core.kind import ProblemKind, require_ipopt
from ..core.model import Model
from ..core.options import Option
from ..core.result import Result
from ..core.solver import SolverConfig


class SynthesisFormulation(ProblemKind):
    """A mechanism's synthesis problem (the paper's), as the synthesis kind uses it:
    a problem kind of its own (inputs, validation, run, outputs) that the
    ``synthesis`` kind looks up by the mechanism and hands the problem to."""

    name = "synthesis"


def formulation(model: Model) -> SynthesisFormulation | None:
    """The synthesis formulation of a model's mechanism, or None."""
    mech = model.mechanism
    if mech is None or mech.synthesis is None:
        return None
    return mech.synthesis()


class Synthesis(ProblemKind):
    name = "synthesis"
    plots = ("comparison", "design")
    description = "dimensional synthesis by the mechanism's own formulation (IPOPT, multi-start)"

    def supports(self, model: Model) -> str | None:
        if formulation(model) is None:
            return f"the mechanism '{model.name}' declares no synthesis formulation (Mechanism.synthesis)"
        return None

    def input_options(self, model: Model) -> list[Option]:
        return formulation(model).input_options(model)

    def parse_inputs(self, raw: Any, model: Model, path: tuple = ("inputs",)) -> dict[str, Any]:
        return formulation(model).parse_inputs(raw, model, path)

    def check_solver(self, solver: SolverConfig) -> None:
        require_ipopt(solver, self.name)

    def run(self, model: Model, inputs: Mapping[str, Any], solver: SolverConfig) -> Result:
        require_ipopt(solver, self.name)
        return formulation(model).run(model, inputs, solver)

    def output_names(self, model: Model) -> list[str]:
        return formulation(model).output_names(model)
