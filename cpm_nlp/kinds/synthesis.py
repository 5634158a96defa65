"""The ``synthesis`` problem kind: dimensional synthesis of a mechanism.

Every paper states its own synthesis (design variables, objective,
constraints), so the kind dispatches to the mechanism: a mechanism that
supports it registers its formulation, an instance of a
[`SynthesisFormulation`][cpm_nlp.kinds.synthesis.SynthesisFormulation]
subclass, among its parts (``Mechanism.parts``; the part ``synthesis``).  The kind itself only
looks the formulation up and hands it the validated model, inputs and solver.

A mechanism that declares none gets the generic formulation,
`CuboidSynthesis`: the largest inscribed cuboid per unit of a declared
footprint, with the chosen parameters as unknowns of the cuboid NLP
(`cpm_nlp.analysis.synthesis`).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, ClassVar

from ..analysis.synthesis import cuboid_synthesis
from ..analysis.workspace import check_grid_sizes, check_per_edge_option
from ..core.errors import InputError, suggest
from ..core.kind import ProblemKind, require_ipopt
from ..core.mechanism import Part
from ..core.model import Model
from ..core.multistart import start_options
from ..core.options import Option
from ..core.outputs import Output, declared_result, output_names, outputs_of, size
from ..core.result import Result, SolverInfo, Status
from ..core.schema import Either, ListOf, Record
from ..core.solver import SolverConfig


class SynthesisFormulation(ProblemKind, Part):
    """A mechanism's synthesis problem (the paper's), as the synthesis kind uses it:
    a problem kind of its own (inputs, validation, run, outputs) that the
    ``synthesis`` kind looks up by the mechanism (the part ``synthesis``: an instance,
    in ``Mechanism.parts``) and hands the problem to."""

    name = "synthesis"
    capability: ClassVar[str] = "synthesis"


def _declared(model: Model) -> dict[str, Option]:
    """The declared parameter options of a model's mechanism (by name)."""
    return {o.name: o for o in model.mechanism.parameters} if model.mechanism is not None else {}


def _dim(model: Model, name: str) -> str:
    opt = _declared(model).get(name)
    return opt.kind if opt is not None else model.dimensions.get(name, "dimensionless")


def _known_parameter(model: Model) -> Any:
    """A validator: the name of a parameter of the model (else "unknown parameter", with a "did you mean")."""
    names = model.closure.parameters

    def check(name: Any, path: tuple) -> None:
        if name not in names:
            raise InputError(
                f"unknown parameter {name!r}; expected one of: {', '.join(names)}",
                path=path,
                suggestions=suggest(str(name), names),
            )

    return check


def _design_option(model: Model) -> Either:
    """``design``: the parameters to vary, by name (within their declared bounds) or name -> [low, high]."""
    declared = _declared(model)
    names = model.closure.parameters

    def declared_bounds(chosen: list, path: tuple) -> dict[str, tuple[float, float]]:
        out = {}
        for k, name in enumerate(chosen):
            opt = declared.get(name)
            lo, hi = (opt.lower, opt.upper) if opt is not None else (None, None)
            if lo is None or hi is None:
                raise InputError(
                    f"parameter {name} declares no finite bounds; give them: design: {{{name}: [low, high]}}",
                    path=path + (k,),
                )
            out[name] = (float(lo), float(hi))
        return out

    def ranges() -> tuple:
        out = []
        for name in names:
            opt = declared.get(name)
            kind = opt.kind if opt is not None else _dim(model, name)
            bounds = {"lower": opt.lower, "upper": opt.upper} if opt is not None else {}
            out.append(Option(name, kind, f"bounds of {name}", default=None, shape="range", **bounds))
        return tuple(out)

    def non_empty(value: Any, path: tuple) -> None:
        if not value or any(v is None for v in value.values()):
            raise InputError(f"{mismatch}, got {value!r}", path=path)

    mismatch = "expected a non-empty list of parameter names or a mapping name -> [low, high]"
    return Either(
        "design",
        "the parameters to vary: a list of names, which vary within their declared bounds, or a mapping "
        "name -> [low, high]; e.g. design: {L: [90 mm, 130 mm]}",
        (
            ListOf(
                "design",
                "parameter names",
                Option("parameter", "str", "a parameter of the mechanism", check=_known_parameter(model)),
                convert=declared_bounds,
            ),
            Record("design", "name -> [low, high]", ranges(), what="parameter", sparse=True, check=non_empty),
        ),
        mismatch=mismatch,
        essential=True,
        missing=f"; parameters of {model.name}: {', '.join(names)}",
    )


def _footprint_option(model: Model) -> Record:
    """``footprint``: parameter -> exponent; the footprint is the product of the parameters' powers."""
    return Record(
        "footprint",
        "footprint = product of parameter powers, parameter -> exponent, e.g. {b: 2} (default: none)",
        tuple(
            Option(n, "dimensionless", f"exponent of {n}", default=None, lower=-10.0, upper=10.0)
            for n in model.closure.parameters
        ),
        default={},
        what="parameter",
        sparse=True,
        convert=lambda value, _path: {k: e for k, e in value.items() if e is not None},
        mismatch="expected a mapping parameter -> exponent (footprint = product of parameter powers, e.g. {b: 2})",
    )


class CuboidSynthesis(SynthesisFormulation):
    """The generic synthesis of a mechanism without a paper formulation: the
    parameters named in ``design`` vary within their bounds to maximise the
    inscribed cuboid per unit of ``footprint`` (a product of parameter powers),
    under the model's joint limits; multi-start, the optimum re-checked."""

    description = (
        "generic dimensional synthesis: the parameters as unknowns of the cuboid NLP, maximising the inscribed "
        "cuboid per unit of a footprint (IPOPT, multi-start, optimum re-checked)"
    )

    def input_options(self, model: Model) -> list[Option]:
        return [
            _design_option(model),
            _footprint_option(model),
            *start_options(default=4),
            Option(
                "samples_per_edge",
                "int",
                "sample points per box edge in the NLP (default: 3 for up to 3 task coordinates, fewer above)",
                default=None,
                lower=2,
                upper=7,
            ),
            check_per_edge_option(9),
        ]

    def check_inputs(self, inputs: dict[str, Any], model: Model, path: tuple) -> None:
        check_grid_sizes(model.closure.nq, inputs["samples_per_edge"], inputs["check_per_edge"], path)
        design = inputs["design"]
        for name, e in inputs["footprint"].items():
            low = design[name][0] if name in design else model.parameters[name]
            if e != 0 and not low > 0:
                raise InputError(
                    f"the footprint takes the log of {name}; its lower bound must be positive, got {low:g}",
                    path=path + ("design", name),
                )

    def run(self, model: Model, inputs: Mapping[str, Any], solver: SolverConfig) -> Result:
        rep = cuboid_synthesis(
            model,
            inputs["design"],
            inputs["footprint"],
            solver,
            starts=inputs["starts"],
            seed=inputs["seed"],
            samples_per_edge=inputs["samples_per_edge"],
            check_per_edge=inputs["check_per_edge"],
        )
        outputs = self._outputs(model, inputs)
        values: dict[str, Any] = dict.fromkeys(output_names(outputs))
        c = model.closure
        if rep.found:
            values.update({n: rep.parameters[n] for n in inputs["design"]})
            for k, t in enumerate(c.task):
                values[f"{t}_min"], values[f"{t}_max"] = float(rep.lower[k]), float(rep.upper[k])
            values.update(
                volume=rep.volume,
                footprint=rep.footprint,
                objective=rep.objective,
                check_points=rep.check.points,
                check_outside=rep.check.outside,
                check_margin=rep.check.margin,
                check_binding=rep.check.binding,
                shrink=rep.shrink,
            )
        values.update(starts=rep.starts, starts_converged=rep.converged, starts_agreed=rep.agreed)
        status = Status.SOLVED if rep.found else Status.INFEASIBLE if rep.infeasible else Status.NOT_CONVERGED
        return declared_result(
            "synthesis",
            status,
            outputs,
            values,
            solver=SolverInfo("ipopt", rep.iterations, rep.seconds),
            message=rep.message,
            model={"type": model.name, **dict(model.parameters)},
        )

    def _outputs(self, model: Model, inputs: Mapping[str, Any] | None) -> list[Output]:
        """The design parameters, the box, its volume and check, the multi-start's counts."""
        c = model.closure
        out = outputs_of({n: _dim(model, n) for n in (inputs["design"] if inputs else c.parameters)}, named=False)
        for i in c.task_index:
            out += [Output(f"{c.x[i].name}_min", c.x[i].kind), Output(f"{c.x[i].name}_max", c.x[i].kind)]
        out.append(size("volume", (c.x[i].kind for i in c.task_index)))
        counts = ("starts", "starts_converged", "starts_agreed")
        return out + outputs_of(
            {
                "footprint": "dimensionless",
                "objective": "dimensionless",
                "check_points": "dimensionless",
                "check_outside": "dimensionless",
                "check_margin": "si",
                "check_binding": "text",
                "shrink": "dimensionless",
                **dict.fromkeys(counts, "dimensionless"),
            },
            named=False,
        )

    def outputs(self, model: Model) -> list[Output]:
        return self._outputs(model, None)

    def output_names(self, model: Model, inputs: Mapping[str, Any] | None = None) -> list[str]:
        return output_names(self._outputs(model, inputs))


def formulation(model: Model) -> SynthesisFormulation | None:
    """The synthesis formulation of a model's mechanism: its own (the paper's), else
    the generic `CuboidSynthesis`; None for a model built by hand."""
    mech = model.mechanism
    if mech is None:
        return None
    return mech.part(SynthesisFormulation) or CuboidSynthesis()


class Synthesis(ProblemKind):
    name = "synthesis"
    parts = (SynthesisFormulation,)
    plots = ("comparison", "design")
    description = (
        "dimensional synthesis by the mechanism's own formulation, else the generic one: the largest inscribed "
        "cuboid per unit of footprint (IPOPT, multi-start)"
    )

    def supports(self, model: Model) -> str | None:
        if formulation(model) is None:
            return f"the model '{model.name}' has no mechanism declaration (built by hand)"
        if self.part(model, SynthesisFormulation) is None and not model.closure.parameters:
            return f"the mechanism '{model.name}' has no parameters: there is no dimension to synthesize"
        return None

    def input_options(self, model: Model) -> list[Option]:
        return formulation(model).input_options(model)

    def resolve(self, inputs: dict[str, Any], model: Model, path: tuple) -> None:
        formulation(model).resolve(inputs, model, path)

    def check_inputs(self, inputs: dict[str, Any], model: Model, path: tuple) -> None:
        formulation(model).check_inputs(inputs, model, path)

    def check_solver(self, solver: SolverConfig) -> None:
        require_ipopt(solver, self.name)

    def run(self, model: Model, inputs: Mapping[str, Any], solver: SolverConfig) -> Result:
        require_ipopt(solver, self.name)
        return formulation(model).run(model, inputs, solver)

    def outputs(self, model: Model) -> list[Output]:
        return formulation(model).outputs(model)

    def output_names(self, model: Model) -> list[str]:
        return formulation(model).output_names(model)
