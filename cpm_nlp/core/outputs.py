"""Declared outputs of a problem kind, and the :class:`~cpm_nlp.core.result.Result` built from them.

A kind declares each value it returns once, as an :class:`Output` (name, dimension,
role); :func:`declared_result` then writes the result's units and dimensions from
that declaration, so that no kind writes a unit by hand (issue 22, item 2).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

from .result import Result, ResultWarning, SolverInfo, Status
from .units import result_unit

#: what an output is: one number per point ("value"), a number relative to another
#: output ("reference", ``refers_to`` names it), a matrix whose rows and columns the
#: unit text describes ("matrix"), a free text ("text")
ROLES = ("value", "reference", "matrix", "text")


@dataclass(frozen=True)
class Output:
    """One value a kind returns.

    name: its name in the result (the papers' symbol); dimension: "length", "angle" ...
    (or "matrix", "text" for what has no SI unit); role: one of :data:`ROLES`;
    refers_to: the output a "reference" is taken from (x0 of an offset dx); unit: the
    unit text where the dimension's SI unit does not say it (a matrix's rows and columns).
    """

    name: str
    dimension: str
    role: str = "value"
    refers_to: str = ""
    unit: str | None = None

    def __post_init__(self) -> None:
        if self.role not in ROLES:
            raise ValueError(f"output {self.name!r}: role must be one of {', '.join(ROLES)}, got {self.role!r}")
        if (self.role == "reference") != bool(self.refers_to):
            raise ValueError(f"output {self.name!r}: a 'reference' output, and only it, names what it refers_to")

    @property
    def si(self) -> str:
        """The unit the result writes (:func:`~cpm_nlp.core.units.result_unit` unless given)."""
        return self.unit if self.unit is not None else result_unit(self.dimension)


def outputs_of(dims: Mapping[str, str]) -> list[Output]:
    """Outputs of the given dimensions, in their order (a matrix's and a text's role said by
    their dimension, every other one a value)."""
    return [Output(n, d, d if d in ("matrix", "text") else "value") for n, d in dims.items()]


def output_names(outputs: Sequence[Output]) -> list[str]:
    return [o.name for o in outputs]


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
    """A result whose units and dimensions are those ``outputs`` declare, in their order."""
    seen: set[str] = set()
    for o in outputs:
        if o.name in seen:
            raise ValueError(f"{kind}: output {o.name!r} is declared twice")
        seen.add(o.name)
    return Result(
        kind,
        status,
        dict(values),
        {o.name: o.si for o in outputs},
        {o.name: o.dimension for o in outputs},
        solver or SolverInfo("none"),
        message,
        statuses,
        dict(model or {}),
        list(warnings),
    )
