"""YAML problem files.

One schema family for every problem kind::

    problem: forward_kinematics        # the question (cpm-nlp describe lists the kinds)
    description: free text
    mechanism:
      type: prs3                       # cpm-nlp describe lists the types
      parameters: {b: 47.91 mm, L: 109.215 mm, alpha0: 45 deg}
      limits: {s: [-3 mm, 3 mm]}       # optional joint limits
    inputs: {s1: 1 mm, s2: 0.5 mm, s3: -0.3 mm}   # a large batch: {data: poses.csv} (cpm_nlp.io.datafile)
    solver: newton                     # a preset under configs/, or a mapping:
    #   {preset: ..., method: ipopt|newton, options: {ipopt.tol: 1e-12}, tolerance: 1e-10}
    outputs: {values: [pz, psi, theta]}  # optional selection
    reproduce: {paper: ..., rows: [...]} # optional published figures
    sweep: {parameters: {...}}           # optional design sweep (cpm_nlp.sweep.run)

Every error names the file and the key path and says what was expected.
"""

from __future__ import annotations

import os
import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ..core.errors import InputError, suggest, unknown_key_error
from ..core.finite import check_numbers
from ..core.kind import ProblemKind
from ..core.model import Model
from ..core.origin import Origin
from ..core.result import Result, finite_status
from ..core.solver import SolverConfig
from ..io.datafile import data_file_of, merge_data_file
from ..io.inputs import display_name, input_dir
from ..mechanisms.provenance import section_origin
from ..mechanisms.registry import SECTION_KEYS, section_model
from .overrides import apply_overrides
from .reader import read_yaml
from .registry import problem_kind
from .solver_section import parse_solver

TOP_LEVEL = {
    "problem": "the problem kind",
    "description": "free text",
    "mechanism": "mechanism type, parameters and limits",
    "inputs": "the inputs of the problem kind",
    "solver": "a preset name or {preset, method, options, tolerance}",
    "outputs": "optional {values: [names]} selection",
    "reproduce": "published figures the file reproduces",
    "sweep": "values to sweep (cpm-nlp sweep)",
}


@dataclass
class Problem:
    """A validated problem: ready to [`solve`][cpm_nlp.problems.file.solve]."""

    kind: ProblemKind
    model: Model
    inputs: dict[str, Any]
    solver: SolverConfig
    outputs: list[str] | None = None
    reproduce: Any = None
    file: str | None = None
    description: str = ""
    data: dict[str, Any] = field(default_factory=dict)
    sweep: Any = None  # a cpm_nlp.sweep.run.SweepSpec when the file has a sweep section
    #: where the mechanism came from (recorded in the result)
    origin: Origin | None = None


def problem_from_dict(data: Any, *, file: str | None = None, base_dir: Path | None = None) -> Problem:
    """Validate a parsed problem mapping into a [`Problem`][cpm_nlp.problems.file.Problem]."""
    try:
        return _problem_from_dict(data, file, base_dir)
    except InputError as exc:
        raise exc.at(file=file) from None


def _problem_from_dict(data: Any, file: str | None, base_dir: Path | None) -> Problem:
    """One step per section of the file, in the order its messages are given."""
    _check_top_level(data)
    kind = problem_kind(data["problem"])
    model, origin = _mechanism_section(data.get("mechanism"), base_dir)
    reason = kind.supports(model)
    if reason:
        raise InputError(
            f"problem kind '{kind.name}' does not apply to mechanism '{model.name}': {reason}", path=("problem",)
        )
    raw_inputs = data.get("inputs")
    if data_file_of(raw_inputs):  # a large batch from a data file beside the problem file
        raw_inputs = merge_data_file(raw_inputs, kind.input_options(model), base_dir)
    inputs = kind.parse_inputs(raw_inputs, model, ("inputs",))
    solver = parse_solver(data.get("solver"), base_dir)
    kind.check_solver(solver)
    outputs = _parse_outputs(data.get("outputs"), kind.output_names(model))
    description = data.get("description") or ""
    if not isinstance(description, str):
        raise InputError(f"expected free text, got {description!r}", path=("description",))
    reproduce = None
    if data.get("reproduce") is not None:  # the sections a file may lack are parsed by modules loaded for them
        from .published import parse_reproduce

        reproduce = parse_reproduce(data["reproduce"], ("reproduce",))
        _check_reproduced_values(data["reproduce"], reproduce, outputs or kind.output_names(model))
    sweep = None
    if data.get("sweep") is not None:
        from .sweep_section import parse_sweep

        sweep = parse_sweep(data["sweep"], data, kind, model, base_dir)
    return Problem(kind, model, inputs, solver, outputs, reproduce, file, description, data, sweep, origin)


def _check_top_level(data: Any) -> None:
    """A mapping of the top-level keys, with finite numbers only and a problem kind."""
    if not isinstance(data, dict):
        kind = "an empty file" if data is None else f"{type(data).__name__} {data!r}"[:80]
        raise InputError(f"expected a mapping with keys {', '.join(TOP_LEVEL)}; got {kind}")
    check_numbers(data)  # no inf, NaN or 1500-digit integer anywhere, before anything is built
    for key in data:
        if key not in TOP_LEVEL:
            raise unknown_key_error(str(key), TOP_LEVEL, (), "top-level key")
    if data.get("problem") is None:
        raise InputError("missing required key 'problem' (the problem kind, e.g. forward_kinematics)")


def _mechanism_section(mech: Any, base_dir: Path | None) -> tuple[Model, Origin | None]:
    """The model of the ``mechanism`` section, and where its mechanism comes from."""
    if not isinstance(mech, Mapping):
        raise InputError(
            "expected a mapping with keys type, parameters, limits"
            + ("" if mech is not None else " (the key is missing)"),
            path=("mechanism",),
        )
    for key in mech:
        if key not in SECTION_KEYS:
            raise unknown_key_error(str(key), SECTION_KEYS, ("mechanism",), "mechanism key")
    model = section_model(mech, base_dir)
    origin = section_origin(mech, base_dir, model)
    return model, origin


def _check_reproduced_values(raw: Any, spec: Any, names: list[str]) -> None:
    """Every compared value is one the problem gives (a typo is bad input, not a failed row)."""
    for i, fig in enumerate(spec.rows):
        name = (fig.value or "").split("[")[0]
        if name and name not in names:
            where = ("reproduce", "rows", i, "value") if isinstance(raw.get("rows"), list) else ("reproduce",)
            raise InputError(
                f"unknown value '{name}'; this problem gives: {', '.join(names)}",
                path=where,
                suggestions=suggest(name, names),
            )


def _parse_outputs(raw: Any, names: list[str]) -> list[str] | None:
    if raw is None:
        return None
    path = ("outputs",)
    if not isinstance(raw, Mapping):
        raise InputError(f"expected a mapping {{values: [names]}}, got {raw!r}", path=path)
    for key in raw:
        if key != "values":
            raise unknown_key_error(str(key), ["values"], path, "outputs key")
    values = raw.get("values")
    if values is None:
        return None
    if not isinstance(values, list) or not all(isinstance(v, str) for v in values) or not values:
        raise InputError(f"expected a non-empty list of value names, got {values!r}", path=path + ("values",))
    for i, v in enumerate(values):
        if v not in names:
            raise InputError(
                f"unknown value '{v}'; this problem gives: {', '.join(names)}",
                path=path + ("values", i),
                suggestions=suggest(v, names),
            )
    return list(values)


def load_problem(path: str | os.PathLike, overrides: Sequence[str] = ()) -> Problem:
    """Read, override (``--set``) and validate a problem file.  ``path`` may be
    ``-`` (standard input) or a pipe (``<(cat p.yaml)``); the relative paths in
    such a file are resolved against the working directory."""
    file = display_name(path)
    data = read_yaml(path, allow_pipe=True)
    try:
        data = apply_overrides(data, overrides)
    except InputError as exc:
        raise exc.at(file=file) from None
    return problem_from_dict(data, file=file, base_dir=input_dir(path))


def solve(problem: Problem) -> Result:
    """Run a validated problem; the result carries its status (never raises
    for a failed solve)."""
    t0 = time.perf_counter()
    try:
        result = problem.kind.run(problem.model, problem.inputs, problem.solver)
    except InputError as exc:  # an input found wrong only while solving (e.g. an allowable stress)
        raise exc.at(file=problem.file) from None
    if result.solver.seconds == 0.0:  # a kind that does not time itself: the whole run, truthfully
        result.solver.seconds = time.perf_counter() - t0
    if result.origin is None:
        result.origin = problem.origin
    result = finite_status(result)  # a NaN or an inf is a failed status, never an answer
    if problem.outputs is not None:
        result.keep(problem.outputs)
    return result
