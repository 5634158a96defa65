"""The ``assembly_modes`` plot type: every assembly mode a forward-kinematics mode search
found (``assembly_modes: all``), the mechanism drawn in each, one panel per mode."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from .draw_mechanism import mechanism_axes
from .pose import geometry_of, model_for
from .results import NotApplicable, PlotOptions, ResultData, mechanism_title
from .style import display_unit, figure_class, legend_below, pretty

#: panels per row
COLUMNS = 3


def assembly_modes_plot(data: ResultData, options: PlotOptions) -> Any:
    """The mechanism in each assembly mode of the result (its ``modes_<x>`` lists) at the
    actuator inputs of its problem, the designated branch's mode marked."""
    if data.sweep or options.interactive:
        raise NotApplicable("'assembly_modes' draws the modes of one forward kinematics result, to .png, .svg, .pdf")
    model = model_for(data)
    c = model.closure
    cols = [data.values.get(f"modes_{n}") for n in c.x_names]
    if not all(isinstance(v, list) and v for v in cols):
        raise NotApplicable("'assembly_modes' needs the modes of a mode search (inputs.assembly_modes: all)")
    q = _inputs(data, c)
    geometry = geometry_of(model)
    X = np.array(cols, dtype=float).T
    designated = data.values.get("modes_designated") or [False] * len(X)
    n = len(X)
    Figure = figure_class()
    ncols = min(n, COLUMNS)
    nrows = math.ceil(n / ncols)
    fig = Figure(figsize=(4.4 * ncols, 4.2 * nrows + 1.2), layout="constrained")
    first = None
    for k, x in enumerate(X):
        title = f"mode {k + 1}: " + _pose_text(c, x) + (" (designated branch)" if designated[k] else "")
        ax = mechanism_axes(fig, (nrows, ncols, k + 1), geometry(model, x, q), title=title, label_points=False)
        first = first or ax
    _same_limits(fig.axes)
    drawing = geometry(model, X[0], q)
    on = sum(bool(d) for d in designated)
    legend_below(fig, first, drawing.note)
    inputs = ", ".join(_value_text(c.q[j].kind, c.q_names[j], q[j]) for j in range(c.nq))
    fig.suptitle(
        f"Assembly modes of the {mechanism_title(data)} at {inputs}:\n{n} found, {on} on the designated branch"
    )
    return fig


def _same_limits(axes: list) -> None:
    """One view for every panel of a planar mechanism (modes compared at a glance)."""
    flat = [ax for ax in axes if not hasattr(ax, "zaxis")]
    if len(flat) < 2:
        return
    x0 = min(ax.get_xlim()[0] for ax in flat)
    x1 = max(ax.get_xlim()[1] for ax in flat)
    y0 = min(ax.get_ylim()[0] for ax in flat)
    y1 = max(ax.get_ylim()[1] for ax in flat)
    for ax in flat:
        ax.set_aspect("equal", adjustable="box")
        ax.set_xlim(x0, x1)
        ax.set_ylim(y0, y1)


def _inputs(data: ResultData, c: Any) -> np.ndarray:
    """The actuator inputs the modes share: the result's, else its problem's."""
    got = [data.values.get(n) for n in c.q_names]
    if all(isinstance(v, (int, float)) for v in got):
        return np.array(got, dtype=float)
    problem = data.solved_problem
    if problem is not None and all(isinstance(problem.inputs.get(n), (int, float)) for n in c.q_names):
        return np.array([problem.inputs[n] for n in c.q_names], dtype=float)
    raise NotApplicable(
        "the actuator inputs of the modes are not in the result: plot it with 'cpm-nlp solve FILE --plot'"
    )


def _value_text(kind: str, name: str, v: float) -> str:
    f, unit = display_unit(kind, [v])
    return f"{pretty(name)} = {v * f:.4g} {unit}".rstrip()


def _pose_text(c: Any, x: np.ndarray) -> str:
    return ", ".join(_value_text(c.x[i].kind, c.x[i].name, x[i]) for i in c.task_index)
