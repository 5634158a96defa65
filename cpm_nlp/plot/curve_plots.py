"""The ``requirements`` and ``io`` plot types: joint requirements over the
studied poses, outputs against the input that varies.
"""

from __future__ import annotations

import re
from typing import Any

import numpy as np

from ..core.errors import InputError, suggest
from ..core.kinematics import passive_joints
from .draw_panels import Panel, panels_figure
from .results import (
    NotApplicable,
    PlotOptions,
    ResultData,
    dimension_of,
    figure_title,
    mechanism_title,
    pose_name,
    problem_words,
    require_lists,
    result_closure,
    result_model,
)
from .style import as_floats, display_unit


def _families(coords: Any) -> dict[str, list[Any]]:
    out: dict[str, list[Any]] = {}
    for c in coords:
        out.setdefault(c.group, []).append(c)
    return out


def requirements_plot(data: ResultData, _options: PlotOptions) -> Any:
    """The joint requirements over the studied poses: platform motions and
    actuator displacements (first row, 3-PRS paper Fig. 6), passive joint
    rotations, relative to home where home is not zero (Fig. 7)."""
    if data.sweep:
        raise NotApplicable("'requirements' plots one joint_requirements result, not a sweep")
    c = result_closure(data)
    task = [pose_name(data, c, t) for t in c.task]
    names = task + c.q_names + c.passive_names
    require_lists(data, names, "the requirements plot")
    n = len(data.values[task[0]])
    panels = [
        Panel(t, dimension_of(data, t) or c.x[c.x_names.index(x)].kind, {t: data.values[t]})
        for t, x in zip(task, c.task)
    ]
    for fam, coords in _families(c.q).items():
        series = {q.name: data.values[q.name] for q in coords}
        panels.append(Panel(fam, coords[0].kind, series, annotate_range=True, levels=_published_range(data, fam)))
    home: dict[str, float] = {}
    if c.passive is not None:
        try:
            model = result_model(data, {p: data.model[p] for p in c.parameters})
            home = passive_joints(model, model.x_home, model.q_home)
        except (InputError, KeyError):
            home = {}
    for fam, coords in _families(c.passive_coords).items():
        shift = {j.name: home.get(j.name, 0.0) for j in coords}
        relative = any(abs(v) > 1e-12 for v in shift.values())
        series = {
            ("d" if relative else "") + j.name: [None if v is None else v - shift[j.name] for v in data.values[j.name]]
            for j in coords
        }
        name = ("d" if relative else "") + fam
        panels.append(Panel(name, coords[0].kind, series, annotate_range=True, levels=_published_range(data, name)))
    return panels_figure(
        list(range(1, n + 1)),
        panels,
        xname="studied pose (number)",
        title=f"Joint requirements over {n} studied poses: {mechanism_title(data)}",
        ncols=len(task) + len(_families(c.q)),
        joined=False,  # the poses are cases of a grid, not a path: no line joins them
    )


def _published_range(data: ResultData, family: str) -> list[tuple[float, str]]:
    """The published ends of a family's range (``<family>_min``, ``<family>_max`` of the
    problem's reproduce rows), as levels to draw."""
    ends = (f"{family}_min", f"{family}_max")
    return [(float(v), label.replace("published", "published range", 1)) for e, v, label in data.published if e in ends]


def io_plot(data: ResultData, options: PlotOptions) -> Any:
    """Outputs against the input that varies, one panel per output (pantograph
    paper, Fig. 20-22): pose coordinates against an actuator for FK, actuators
    and dependent coordinates against a task coordinate for IK."""
    if data.sweep:
        raise NotApplicable("'io' plots one batch result; for a sweep use 'lines'")
    c = result_closure(data)
    if data.problem == "inverse_kinematics":
        inputs = [pose_name(data, c, t) for t in c.task]
        outputs = c.q_names + [pose_name(data, c, c.x_names[i]) for i in c.dep_index]
    else:
        inputs = c.q_names
        outputs = [pose_name(data, c, x) for x in c.x_names]
    if options.value:
        if options.value not in data.values:
            raise InputError(
                f"unknown value {options.value!r}", path=("--value",), suggestions=suggest(options.value, data.values)
            )
        outputs = [options.value]
    require_lists(data, inputs + outputs, "an output/input plot")
    cols = {n: np.array([np.nan if v is None else v for v in data.values[n]], dtype=float) for n in inputs}
    spread = {n: np.nanmax(v) - np.nanmin(v) if np.isfinite(v).any() else 0.0 for n, v in cols.items()}
    x = max(inputs, key=lambda n: spread[n])
    if spread[x] <= 0:
        raise NotApplicable("no input varies over the batch")
    same = [n for n in inputs if np.allclose(cols[n], cols[x], equal_nan=True)]
    xname = " = ".join(same)
    order = np.argsort(cols[x])
    outputs = [o for o in outputs if o not in same]
    flat = [o for o in outputs if _constant(data.values[o])] if len(outputs) > 1 else []
    refs = _published_points(data, cols[x])
    panels = []
    for o in outputs:
        if o in flat:
            continue
        series = {o + " (this model)" if o in refs else o: [data.values[o][i] for i in order]}
        panels.append(Panel(o, dimension_of(data, o), series, points=refs.get(o, ())))
    if not panels:
        raise NotApplicable("every output is constant over the batch")
    title = figure_title(data, f"{problem_words(data)}: outputs against {xname}")
    if flat:
        title += "\nconstant over the batch: " + ", ".join(_constant_text(data, o) for o in flat)
    return panels_figure(cols[x][order], panels, xname=xname, xdimension=dimension_of(data, x), title=title)


def _constant(values: list) -> bool:
    arr = as_floats(values)
    arr = arr[np.isfinite(arr)]
    return bool(arr.size) and float(np.ptp(arr)) <= 1e-9 * max(float(np.abs(arr).max()), 1e-300)


def _constant_text(data: ResultData, name: str) -> str:
    arr = as_floats(data.values[name])
    v = float(arr[np.isfinite(arr)][0])
    f, unit = display_unit(dimension_of(data, name), [v])
    return f"{name} = {v * f:.4g} {unit}".rstrip()


def _published_points(data: ResultData, x: np.ndarray) -> dict[str, list[tuple[float, float, str]]]:
    """Published values of single points of the batch ("dz[1]": dz at the second
    input), as (input, published value, label) per output name."""
    out: dict[str, list[tuple[float, float, str]]] = {}
    for expr, value, label in data.published:
        m = re.fullmatch(r"(\w+)\[(\d+)\]", expr)
        if m is None or int(m.group(2)) >= len(x):
            continue
        out.setdefault(m.group(1), []).append((float(x[int(m.group(2))]), float(value), label))
    return out
