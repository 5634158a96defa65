"""Problem kinds: what question a problem file asks about a mechanism.

A problem kind declares its inputs (as `Option` s,
which may depend on the mechanism), validates them, and runs an algorithm on
a [`Model`][cpm_nlp.core.model.Model] with a [`SolverConfig`][cpm_nlp.core.solver.SolverConfig],
returning a [`Result`][cpm_nlp.core.result.Result].  Problem, method (the algorithm
modules) and solver stay separate.

The generic kinds live in `cpm_nlp.kinds`; a mechanism declares its own
kinds (``Mechanism.kinds``); `cpm_nlp.problems.registry` finds them all.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from .errors import InputError
from .mechanism import P, Part
from .model import Coordinate, Model
from .options import Option, validate_mapping
from .result import Output, Result
from .solver import SolverConfig
from .units import format_quantity


class ProblemKind:
    """Base class of problem kinds.

    Subclasses set ``name`` and ``description`` and implement
    [`input_options`][cpm_nlp.core.kind.ProblemKind.input_options], `run` and
    [`outputs`][cpm_nlp.core.kind.ProblemKind.outputs]; they may
    override [`resolve`][cpm_nlp.core.kind.ProblemKind.resolve] for values derived from several inputs (the hinges of
    ``hinges`` and ``material``) and [`check_inputs`][cpm_nlp.core.kind.ProblemKind.check_inputs] for rules that involve
    several inputs.  The inputs are parsed once, here, by their declaration
    (options and the nested nodes of `cpm_nlp.core.schema`): no kind parses
    an input by hand.
    """

    name = ""
    description = ""
    #: plot types that may draw a result of this kind, the default first (see `cpm_nlp.plot.figures`)
    plots: tuple[str, ...] = ()
    #: (x, y, value) names of the values a design map of a result shows (plot type "map")
    map_axes: tuple[str, str, str] | None = None
    #: the mechanism parts this kind reads (`Part` types,
    #: declared with the kind), each through `part`
    parts: tuple[type[Part], ...] = ()

    def part(self, model: Model, kind: type[P]) -> P | None:
        """The part of type ``kind`` of the model's mechanism (None without one, or for a
        model built by hand); ``kind`` must be one this kind declares in `parts`."""
        if kind not in self.parts:
            raise TypeError(f"problem kind {self.name!r} reads {kind.__name__} but does not declare it in parts")
        return model.mechanism.part(kind) if model.mechanism is not None else None

    def input_options(self, model: Model) -> list[Option]:
        """The declared inputs: `Option` s and nodes of `cpm_nlp.core.schema`."""
        raise NotImplementedError

    def parse_inputs(self, raw: Any, model: Model, path: tuple = ("inputs",)) -> dict[str, Any]:
        """The one parse of a kind's inputs: validated by their declaration, then
        [`resolve`][cpm_nlp.core.kind.ProblemKind.resolve] and
        [`check_inputs`][cpm_nlp.core.kind.ProblemKind.check_inputs]."""
        inputs = validate_mapping(raw, self.input_options(model), path, what="input")
        self.resolve(inputs, model, path)
        self.check_inputs(inputs, model, path)
        return inputs

    def resolve(self, inputs: dict[str, Any], model: Model, path: tuple) -> None:
        """Add the values derived from several parsed inputs to ``inputs``; raise
        [`InputError`][cpm_nlp.core.errors.InputError]."""

    def check_inputs(self, inputs: dict[str, Any], model: Model, path: tuple) -> None:
        """Cross-input validation; raise [`InputError`][cpm_nlp.core.errors.InputError]."""

    def run(self, model: Model, inputs: Mapping[str, Any], solver: SolverConfig) -> Result:
        raise NotImplementedError

    def outputs(self, model: Model) -> list[Output]:
        """The declared outputs on ``model``: name, dimension, role (and the unit text of
        what has no SI unit), every value the kind may return, in order; its results are
        built from them (`declared_result`).  Values whose
        names depend on the inputs (one per hinge group of the problem's hinges) are a
        family (``Output(..., per=...)``), of which a result holds members."""
        raise NotImplementedError

    def output_names(self, model: Model) -> list[str]:
        """The names of [`outputs`][cpm_nlp.core.kind.ProblemKind.outputs] that a result has by default: not a family's
        (its members
        depend on the inputs), nor one that only an input asks for (``Output.when``)."""
        return [o.name for o in self.outputs(model) if not o.family and not o.when]

    def supports(self, model: Model) -> str | None:
        """None if the kind applies to this model, else the reason it does not."""
        return None

    def check_solver(self, solver: SolverConfig) -> None:
        """Raise [`InputError`][cpm_nlp.core.errors.InputError] if the kind cannot use this solver
        configuration (e.g. an optimisation needs IPOPT)."""


# -- helpers shared by the kinematic kinds ------------------------------------------


def task_options(model: Model, shape: str) -> list[Option]:
    """Inputs naming the task coordinates (and their offsets from home)."""
    c = model.closure
    out = []
    for i in c.task_index:
        coord = c.x[i]
        out.append(Option(coord.name, coord.kind, coord.description, default=None, shape=shape))
    for off, target in c.offsets.items():
        coord = c.x[c.x_names.index(target)]
        out.append(Option(off, coord.kind, f"{target} relative to the home pose", default=None, shape=shape))
    return out


def actuator_options(model: Model, shape: str) -> list[Option]:
    return [Option(q.name, q.kind, q.description, default=None, shape=shape) for q in model.closure.q]


def given(inputs: Mapping[str, Any], names: Sequence[str]) -> list[str]:
    return [n for n in names if inputs.get(n) is not None]


def task_values(inputs: Mapping[str, Any], model: Model, path: tuple) -> list[Any]:
    """The task coordinates from the inputs, offsets resolved; one entry per
    task coordinate (a scalar or a list, as given)."""
    c = model.closure
    out = []
    for i in c.task_index:
        name = c.x[i].name
        alts = [o for o, target in c.offsets.items() if target == name]
        have = given(inputs, [name] + alts)
        if len(have) > 1:
            raise InputError(f"give only one of {', '.join(repr(h) for h in have)}", path=path)
        if not have:
            either = " or ".join(repr(n) for n in [name] + alts)
            raise InputError(f"missing input {either} ({c.x[i].description})", path=path)
        value = inputs[have[0]]
        home = float(model.x_home[i])
        if have[0] != name:
            value = [v + home for v in value] if isinstance(value, list) else value + home
        out.append(value)
    return out


def check_actuator_limits(model: Model, inputs: Mapping[str, Any], path: tuple) -> None:
    """Actuator inputs must lie within the declared stroke (an input error)."""
    for coord in model.closure.q:
        lim = model.limit_of(coord)
        value = inputs.get(coord.name)
        if lim is None or value is None:
            continue
        values = value if isinstance(value, list) else [value]
        for k, v in enumerate(values):
            if not lim[0] <= v <= lim[1]:
                where = path + ((coord.name, k) if isinstance(value, list) else (coord.name,))
                hint = None
                if abs(v) > 100 * max(abs(lim[0]), abs(lim[1])):
                    hint = "a bare number is read in SI; write the unit, e.g. '1.5 mm'"
                raise InputError(
                    f"actuator displacement {format_quantity(v, coord.kind)} is out of reach: expected a value "
                    f"within the stroke [{format_quantity(lim[0], coord.kind)}, "
                    f"{format_quantity(lim[1], coord.kind)}] declared at mechanism.limits.{coord.group}",
                    path=where,
                    hint=hint,
                )


def broadcast(columns: Sequence[Any], names: Sequence[str], path: tuple) -> tuple[np.ndarray, bool]:
    """Align scalar/list inputs into an (N, k) array; lists must share a length."""
    lengths = {len(v) for v in columns if isinstance(v, list)}
    batch = bool(lengths)
    if len(lengths) > 1:
        detail = ", ".join(f"{n}: {len(v)}" for n, v in zip(names, columns) if isinstance(v, list))
        raise InputError(f"lists of inputs must have the same length (got {detail})", path=path)
    n = lengths.pop() if lengths else 1
    arr = np.empty((n, len(columns)))
    for j, v in enumerate(columns):  # column-wise: a data file's 100 000 rows at numpy's speed
        arr[:, j] = v
    return arr, batch


def require_ipopt(solver: SolverConfig, kind: str) -> None:
    """Optimisation kinds (cuboid, synthesis) need IPOPT, not a rootfinder."""
    if solver.method != "ipopt":
        raise InputError(
            f"problem kind '{kind}' solves an optimisation problem and needs method ipopt, got '{solver.method}'",
            path=("solver", "method"),
        )


def coordinate_dims(coords: Sequence[Coordinate]) -> dict[str, str]:
    return {c.name: c.kind for c in coords}
