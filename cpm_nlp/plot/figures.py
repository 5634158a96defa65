"""Which figure a result makes.

A result is the JSON of ``cpm-nlp solve -o`` (or a [`Result`][cpm_nlp.core.result.Result])
or a sweep results file; `load` reads either into `ResultData`
(`cpm_nlp.plot.results`).  The figure is chosen from the result's problem kind
(its ``plots``, see [`ProblemKind`][cpm_nlp.core.kind.ProblemKind]: the first plot type
that applies to the values wins) or named (``--type``).

Extending: a plot type is a `PlotType` in the
registry (`cpm_nlp.plot.registry`: built-in, a mechanism's add-on, or a plugin
of the entry-point group ``cpm_nlp.plots``), its function taking ``(data, options)``
and returning a Matplotlib figure made from arrays (the ``draw_*`` modules), or
raising `NotApplicable`; a problem kind lists its plot types in its ``plots``
attribute.  A kind needs no plotting code of its own when its values use the names
the built-in plot types read (SI values, units in the result):

* ``workspace`` -- a point cloud: ``cloud_<t>`` for each task coordinate t
  (the ``workspace`` kind), or ``points`` (N x 3); a cuboid: ``<t>_min`` and
  ``<t>_max`` (the ``inscribed_cuboid`` kind), or ``cuboid_lower`` and
  ``cuboid_upper``; a batch of poses (FK, IK) gives its task coordinates.  A
  cuboid without a cloud (``inscribed_cuboid``) is drawn in a cloud sampled
  from the model when the model is at hand (``cpm-nlp solve FILE --plot``);
* ``map`` -- the kind's ``map_axes`` name (x, y, value): x and y: x and y
  lists and the value either a list of the same length or a matrix
  (rows y, columns x; ``null`` outside the design space); optional
  ``in_region`` (same shape: outlined; ``<value>_region``: the bound the value
  reaches there, stated in the legend), ``<x>_best``/``<y>_best`` and
  ``<x>_design``/``<y>_design`` (marked), ``domain`` (vertices, outlined).
  A sweep maps a value over its two swept parameters.
"""

from __future__ import annotations

from dataclasses import replace
from typing import Any

from ..core.errors import InputError, suggest
from ..problems.registry import kind_names, problem_kind
from .plot_type import PlotType
from .registry import REGISTRY, interactive_names, plot_type_names
from .results import (
    NotApplicable,
    NothingSolved,
    PlotOptions,
    ResultData,
    from_result,
    from_table,
    load,
)

__all__ = [
    "NotApplicable",
    "NothingSolved",
    "PlotOptions",
    "ResultData",
    "check_plot_type",
    "figure",
    "from_result",
    "from_table",
    "load",
]

#: plot types that may draw a sweep results file, the default first
SWEEP_PLOTS = ("map", "lines", "workspace")


def figure(
    data: ResultData, plot_type: str | None = None, options: PlotOptions | None = None, interactive: bool = False
) -> tuple[Any, str]:
    """The figure of a result: ``(figure, plot type)``; ``interactive``: a Plotly
    figure (for ``.html``) of a 3-D plot type (declared ``interactive``).  Raises
    `NothingSolved` for a result without a solved point."""
    options = replace(
        options or PlotOptions(), interactive=interactive or (options is not None and options.interactive)
    )
    ok = data.ok
    if (ok is not None and not ok.any()) or (ok is None and data.status != "solved"):
        raise NothingSolved(f"no point of {data.source or 'the result'} is solved; there is nothing to plot")
    if plot_type is not None:
        check_plot_type(plot_type)
        return _draw(_plot_for(data, plot_type), data, options), plot_type
    candidates = SWEEP_PLOTS if data.sweep else _kind_plots(data.problem)
    if not candidates:
        known = [n for n in kind_names() if problem_kind(n).plots]
        raise NotApplicable(f"no plot is known for a {data.kind} result; known: {', '.join(known + ['sweep'])}")
    reasons = []
    for name in candidates:
        try:
            return _draw(_plot_for(data, name), data, options), name
        except NotApplicable as exc:
            reasons.append(f"{name}: {exc.message}")
    raise NotApplicable("no plot fits this result (" + "; ".join(reasons) + ")")


def check_plot_type(plot_type: str | None) -> None:
    """An [`InputError`][cpm_nlp.core.errors.InputError] (``--type``, with "did you mean") unless ``plot_type``
    is None or a registered plot type (checked before anything is solved)."""
    if plot_type is None or REGISTRY.has(plot_type):
        return
    names = plot_type_names()
    if plot_type not in names:
        raise InputError(
            f"unknown plot type {plot_type!r}; expected one of: {', '.join(sorted(names))}",
            path=("--type",),
            suggestions=suggest(plot_type, names),
        )


def _mechanism(data: ResultData) -> str | None:
    name = data.model.get("type")
    return name if isinstance(name, str) and name else None


def _plot_for(data: ResultData, name: str) -> PlotType:
    """The plot type ``name`` for this result: a mechanism's own plot only for that
    mechanism's results, a plot declaring its kinds only for results of those kinds."""
    plot = REGISTRY.get(name, _mechanism(data))
    if plot is None:
        owners = REGISTRY.owners(name)
        whose = " or ".join(owners) if owners else "another mechanism"
        raise NotApplicable(
            f"'{name}' is a plot of the {whose} mechanism (its paper's own); "
            f"this result is of {_mechanism(data) or 'a mechanism it does not name'}"
        )
    if not plot.fits(data.kind):
        raise NotApplicable(f"'{name}' draws results of {', '.join(plot.kinds)}; this is a {data.kind} result")
    return plot


def _draw(plot: PlotType, data: ResultData, options: PlotOptions) -> Any:
    if options.interactive and not plot.interactive:
        raise NotApplicable(
            f"an interactive (.html) figure is drawn for the 3-D plots "
            f"({', '.join(interactive_names(_mechanism(data)))}); '{plot.name}' is drawn to .png, .svg or .pdf"
        )
    return plot.function(data, options)


def _kind_plots(name: str) -> tuple[str, ...]:
    """The plot types of a problem kind (none for a kind unknown here)."""
    return problem_kind(name).plots if name in kind_names() else ()
