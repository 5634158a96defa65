"""Declared outputs of a problem kind, and the [`Result`][cpm_nlp.core.result.Result] built from them.

A kind declares each value it returns once, as an [`Output`][cpm_nlp.core.result.Output] (name, dimension,
role); `declared_result` then writes the result's units and dimensions from
that declaration, so that no kind writes a unit by hand (issue 22, item 2).  The unit
of a physical dimension is `result_unit`'s; an output with
no SI unit (a matrix, a list of coordinates, a text) carries a text saying what it
holds (`matrix`, `vector`, `text`).
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

from .result import ROLES, Entry, Output, Result, ResultWarning, SolverInfo, Status
from .units import DIMENSIONS, size_dimension

__all__ = (
    "BINDING_UNIT",
    "ROLES",
    "Entry",
    "Output",
    "Values",
    "declared_for",
    "declared_result",
    "matrix",
    "output_names",
    "outputs_of",
    "size",
    "text",
    "vector",
)


#: the unit of a margin (dimension "si"): that of whichever quantity binds (a length, an angle, a stress ...)
BINDING_UNIT = "SI unit of the binding quantity"


def outputs_of(dims: Mapping[str, str], *, named: bool = True) -> list[Output]:
    """Outputs of the given dimensions, in their order (a matrix's and a text's role said by
    their dimension, every other one a value).  An output of no physical dimension (a text,
    a matrix) writes its dimension's name as its unit, or with ``named=False`` no unit; a
    margin (dimension "si") is in the unit of whichever quantity binds (`BINDING_UNIT`)."""
    return [
        Output(
            n,
            d,
            d if d in ("matrix", "text") else "value",
            unit=BINDING_UNIT if d == "si" else None if named or d in DIMENSIONS else "",
        )
        for n, d in dims.items()
    ]


def size(name: str, kinds: Iterable[str]) -> Output:
    """The size of a box whose sides are coordinates of ``kinds`` (an area, a volume, a
    length times an angle ...): dimension and unit by `size_dimension`."""
    dimension, unit = size_dimension(kinds)
    return Output(name, dimension, unit=unit)


def matrix(name: str, unit: str) -> Output:
    """A matrix output; ``unit`` says its rows and columns (and their units)."""
    return Output(name, "matrix", "matrix", unit=unit)


def vector(name: str, unit: str) -> Output:
    """A list of values of several coordinates; ``unit`` names them and their units."""
    return Output(name, "vector", unit=unit)


def text(name: str, unit: str = "") -> Output:
    """A text (a name, a verdict, a note): no unit."""
    return Output(name, "text", "text", unit=unit)


@dataclass
class Values:
    """Values with their declarations, gathered in the order computed (what
    `declared_result` takes): a kind adds each value with its [`Output`][cpm_nlp.core.result.Output]."""

    outputs: list[Output] = field(default_factory=list)
    values: dict[str, Any] = field(default_factory=dict)

    def add(self, output: Output, value: Any) -> Values:
        """Declare ``output`` and set its value."""
        self.outputs.append(output)
        self.values[output.name] = value
        return self

    def add_all(self, pairs: Iterable[tuple[Output, Any]]) -> Values:
        for output, value in pairs:
            self.add(output, value)
        return self

    def declare(self, outputs: Iterable[Output]) -> Values:
        """Declare outputs whose values come later (or never)."""
        self.outputs.extend(outputs)
        return self

    def extend(self, other: Values) -> Values:
        self.outputs.extend(other.outputs)
        self.values.update(other.values)
        return self


def output_names(outputs: Sequence[Output]) -> list[str]:
    return [o.name for o in outputs]


def declared_for(kind: str, declared: Sequence[Output], names: Iterable[str]) -> list[Output]:
    """The declarations of ``names``, in the declared order, from a kind's declared outputs (a
    result built from them holds what the kind declares, nothing else); a name the kind
    does not declare is a programming error (ValueError), as [`Result`][cpm_nlp.core.result.Result] refuses it."""
    wanted = set(names)
    undeclared = sorted(wanted - {o.name for o in declared if not o.family})
    if undeclared:
        raise ValueError(f"{kind}: value(s) the kind does not declare: {', '.join(map(str, undeclared))}")
    return [o for o in declared if not o.family and o.name in wanted]


def declared_result(
    kind: str,
    status: Status,
    outputs: Sequence[Output],
    values: Mapping[str, Any],
    *,
    solver: SolverInfo | None = None,
    message: str = "",
    statuses: list[Status] | None = None,
    model: Mapping[str, Any] | None = None,
    warnings: Sequence[ResultWarning] = (),
) -> Result:
    """A result whose units and dimensions are those ``outputs`` declare, in their order;
    every value is of a declared output."""
    return Result(
        kind,
        status,
        outputs,
        values,
        solver=solver,
        message=message,
        statuses=statuses,
        model=model,
        warnings=warnings,
    )
