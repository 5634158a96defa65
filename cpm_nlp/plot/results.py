"""The results a plot reads: a JSON result (``cpm-nlp solve -o``, or a
[`Result`][cpm_nlp.core.result.Result]) or a sweep results file, read into
`ResultData`; the options of a plot; and the small readers of values every
plot type shares.
"""

from __future__ import annotations

import json
import os
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..core.errors import InputError
from ..core.result import ResultWarning
from ..core.units import DIMENSIONS
from ..io.inputs import MAX_RESULTS_BYTES, read_input_text
from ..io.results import FORMATS, read_results
from ..mechanisms.provenance import recorded_closure, recorded_mechanism, recorded_model

#: sweep statuses of points outside the design space (drawn apart from points that did not solve)
OUTSIDE = ("infeasible", "invalid_input")

_BY_SI = {d.si: name for name, d in DIMENSIONS.items() if name != "dimensionless"}


class NotApplicable(InputError):
    """This plot type does not fit the result (the message says why)."""


class NothingSolved(InputError):
    """The result has no solved point: there is nothing to draw."""


@dataclass
class PlotOptions:
    """value: the quantity of a map or curves; x, y: the map's axes (names of
    swept keys or values); best: mark the "max" or "min" of a map."""

    value: str | None = None
    x: str | None = None
    y: str | None = None
    best: str | None = None
    #: an interactive Plotly figure (``.html``) of the 3-D view, not a Matplotlib one
    interactive: bool = False


@dataclass
class ResultData:
    """A result to plot.

    Attributes
    ----------
    problem
        the problem kind;
    sweep
        True for a sweep results file, whose ``values`` are its columns (lists, one entry per
        point) and ``parameters`` its swept keys;
    dimensions
        of every value ("length", "angle" ...).
    """

    source: str
    problem: str
    values: dict[str, Any]
    dimensions: dict[str, str]
    statuses: list[str] | None = None
    model: dict[str, Any] = field(default_factory=dict)
    sweep: bool = False
    status: str = "solved"  # of the whole result
    live: Any = None  # the Model solved, when at hand (solve --plot): lets a plot sample its workspace
    parameters: list[dict[str, Any]] = field(default_factory=list)
    recorded: list[str] = field(default_factory=list)  # value columns of a sweep
    units: dict[str, str] = field(
        default_factory=dict
    )  # as the result writes them (matrices: what rows and columns are)
    #: published figures to draw beside the values: (value expression "dz[2]", published SI, label)
    published: list[tuple[str, float, str]] = field(default_factory=list)
    #: the result's warnings (`ResultWarning`), read back from its JSON
    warnings: list[Any] = field(default_factory=list)
    #: where the mechanism came from, as the result records it (``origin``; None in older results)
    origin: Any = None
    #: the problem solved, when at hand (solve --plot): lets a plot solve it along a motion
    #: (the forces of one pose drawn as a curve from home through it)
    solved_problem: Any = None

    @property
    def kind(self) -> str:
        return "sweep" if self.sweep else self.problem

    @property
    def ok(self) -> np.ndarray | None:
        return None if self.statuses is None else np.array([s == "solved" for s in self.statuses])


def _dimension_of_unit(unit: Any) -> str | None:
    if unit == "":
        return "dimensionless"
    return _BY_SI.get(unit) if isinstance(unit, str) else None


def from_result(result: Any, source: str = "") -> ResultData:
    """A [`Result`][cpm_nlp.core.result.Result] or its JSON dict."""
    d = result if isinstance(result, Mapping) or not hasattr(result, "to_dict") else result.to_dict()
    if not isinstance(d, Mapping) or not isinstance(d.get("values"), Mapping) or not isinstance(d.get("problem"), str):
        raise InputError("expected a cpm-nlp result (JSON with problem, status, values, units)", file=source or None)
    dims = {k: dim for k, u in (d.get("units") or {}).items() if (dim := _dimension_of_unit(u))}
    return ResultData(
        source,
        d["problem"],
        dict(d["values"]),
        dims,
        d.get("statuses"),
        dict(d.get("model") or {}),
        status=str(d.get("status")),
        units={k: str(u) for k, u in (d.get("units") or {}).items()},
        warnings=[ResultWarning.from_dict(w) for w in d.get("warnings") or [] if isinstance(d.get("warnings"), list)],
        origin=d.get("origin"),
    )


def from_solved(result: Any, problem: Any) -> ResultData:
    """A result with the problem that gave it (``cpm-nlp solve FILE --plot``): the model
    at hand, the published figures of its ``reproduce`` section (drawn beside the values)."""
    data = from_result(result)
    data.live = problem.model
    data.solved_problem = problem
    if problem.reproduce is not None:
        data.published = [
            (row.value, row.published, f"published ({row.source})")
            for row in problem.reproduce.rows
            if row.value and row.published is not None
        ]
    return data


def from_table(table: Any) -> ResultData:
    """A sweep results file read by `cpm_nlp.io.results.read_results`."""
    meta = table.meta
    names = ["point", *(p["key"] for p in table.parameters), "status", "message", "seconds", "warnings"]
    names += table.values
    values = {n: table.column(n) for n in names}
    dims = {p["key"]: p["dimension"] for p in table.parameters if p.get("dimension")}
    dims.update(meta.get("dimensions") or {})
    for n, u in (meta.get("units") or {}).items():
        if n not in dims and (dim := _dimension_of_unit(u)):
            dims[n] = dim
    model = {"type": meta.get("mechanism")}
    return ResultData(
        table.path,
        str(meta.get("problem")),
        values,
        dims,
        statuses=[str(s) for s in table.column("status")],
        model=model,
        sweep=True,
        parameters=table.parameters,
        recorded=table.values,
    )


def load(path: str | os.PathLike) -> ResultData:
    """Read a JSON result (``cpm-nlp solve -o``) or a sweep results file."""
    p = Path(path)
    if p.suffix.lower() in FORMATS:
        return from_table(read_results(p))
    text = read_input_text(p, MAX_RESULTS_BYTES)
    try:
        data = json.loads(text)
    except ValueError:
        raise InputError(
            "expected a JSON result written by 'cpm-nlp solve -o' or a sweep results file (.parquet, .csv)",
            file=str(path),
        ) from None
    return from_result(data, str(path))


# -- helpers ------------------------------------------------------------------------------------


def result_closure(data: ResultData) -> Any:
    """The symbolic mechanism of the result (names of its coordinates)."""
    return recorded_closure(result_mechanism(data)) if data.live is None else data.live.closure


def result_mechanism(data: ResultData) -> Any:
    """The mechanism of the result: the one its ``origin`` records (a mechanism file only
    if it is unchanged at its path, see `cpm_nlp.mechanisms.provenance`), else the
    registered type ``model.type`` (a result written before results recorded their origin)."""
    if data.live is not None and data.live.mechanism is not None:
        return data.live.mechanism
    name = data.model.get("type")
    if not name and data.origin is None:
        raise NotApplicable("the result does not name its mechanism (model.type)")
    return recorded_mechanism(data.origin, name, data.source or None)


def mechanism_title(data: ResultData) -> str:
    """The mechanism's title for a figure ("3-PRS compliant stage (Ruiz et al.)"), else its type name."""
    try:
        return str(result_mechanism(data).title)
    except (InputError, AttributeError):
        return str(data.model.get("type") or data.problem)


def figure_title(data: ResultData, what: str = "") -> str:
    """A figure's title: the mechanism's title over what is drawn (``what``; default: the
    problem kind in words, "inscribed cuboid"), never an internal name."""
    return f"{mechanism_title(data)}\n{what or problem_words(data)}"


def problem_words(data: ResultData) -> str:
    """The result's problem kind in words ("rpr transmission map")."""
    return str(data.problem).replace("_", " ")


def result_model(data: ResultData, parameters: Mapping[str, Any] | None = None, with_limits: bool = False) -> Any:
    """A model of the result's mechanism (`result_mechanism`) from ``parameters``
    (default: the ones the result records), without registering it; ``with_limits``: with the
    joint limits the result records too (its workspace is then the one solved)."""
    mech = result_mechanism(data)
    if parameters is None:
        parameters = {o.name: data.model[o.name] for o in mech.parameters if data.model.get(o.name) is not None}
    limits = None
    if with_limits:
        limits = {o.name: data.model[o.name] for o in mech.limits if data.model.get(o.name) is not None}
    return recorded_model(mech, parameters, limits=limits)


def value_list(data: ResultData, name: str) -> list | None:
    v = data.values.get(name)
    return v if isinstance(v, list) else None


def pose_name(data: ResultData, closure: Any, coord: str) -> str:
    """A coordinate, by its offset from home where the result has it (dz for pz)."""
    for off, target in closure.offsets.items():
        if target == coord and off in data.values:
            return off
    return coord


def require_lists(data: ResultData, names: list[str], what: str) -> None:
    missing = [n for n in names if value_list(data, n) is None]
    if missing:
        raise NotApplicable(
            f"{what} needs per-point lists of {', '.join(missing)} (solve a batch, without an outputs selection)"
        )


def dimension_of(data: ResultData, name: str) -> str | None:
    return data.dimensions.get(name)
