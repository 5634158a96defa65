"""The ``map`` and ``lines`` plot types: a value over two swept parameters (or
the grids of a kind's ``map_axes``), values against one swept parameter.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..core.errors import InputError, suggest
from ..problems.registry import kind_names, problem_kind
from .draw_map import design_map_figure
from .draw_panels import Panel, panels_figure
from .results import (
    OUTSIDE,
    NotApplicable,
    PlotOptions,
    ResultData,
    dimension_of,
    figure_title,
    problem_words,
    value_list,
)
from .style import pretty, value_text

# -- map ---------------------------------------------------------------------------------------------


def _sweep_key(data: ResultData, name: str | None, option: str) -> str:
    """A swept key or value column of a sweep, named in full or by its last part."""
    keys = [p["key"] for p in data.parameters] + list(data.recorded)
    if name in keys:
        return name
    short = [k for k in keys if k.rsplit(".", 1)[-1] == name]
    if len(short) == 1:
        return short[0]
    raise InputError(
        f"unknown column {name!r}; expected one of: {', '.join(keys)}",
        path=(option,),
        suggestions=suggest(str(name), keys),
    )


def _numeric_columns(data: ResultData, names: list[str]) -> list[str]:
    out = []
    for n in names:
        col = data.values.get(n) or []
        if any(v is not None for v in col) and all(
            v is None or (isinstance(v, (int, float)) and not isinstance(v, bool)) for v in col
        ):
            out.append(n)
    return out


def _value_column(data: ResultData, options: PlotOptions) -> str:
    if options.value:
        return _sweep_key(data, options.value, "--value")
    numeric = _numeric_columns(data, data.recorded)
    if not numeric:
        raise NotApplicable("the sweep recorded no numeric value (select scalar values with outputs.values)")
    return numeric[0]


def map_plot(data: ResultData, options: PlotOptions) -> Any:
    """A design map: a value over two swept parameters, or over the two grids
    of a kind's ``map_axes`` (see the module's naming conventions)."""
    if data.sweep:
        return _sweep_map(data, options)
    v = data.values
    axes = _map_axes(data.problem)
    xk, yk, zk = options.x or axes[0], options.y or axes[1], options.value or axes[2]
    if not (xk and yk and zk):
        raise NotApplicable("a map of a single result needs --x, --y and --value naming three of its lists")
    for n, opt in ((xk, "--x"), (yk, "--y"), (zk, "--value")):
        if value_list(data, n) is None:
            raise InputError(
                f"expected the name of a list of the result, got {n!r}",
                path=(opt,),
                suggestions=suggest(n, [k for k in v if value_list(data, k) is not None]),
            )
    x, y, z = v[xk], v[yk], v[zk]
    region = v.get("in_region")
    if z and isinstance(z[0], list):  # a matrix over the grids: rows y, columns x
        if len(z) != len(y) or any(len(row) != len(x) for row in z):
            raise NotApplicable(f"{zk} is not a {len(y)} x {len(x)} matrix over {yk} and {xk}")
        x, y = [xi for _ in y for xi in x], [yi for yi in y for _ in x]
        z = [zij for row in z for zij in row]
        if isinstance(region, list) and region and isinstance(region[0], list):
            region = [rij for row in region for rij in row]
        outside = [zij is None for zij in z]  # null: outside the design space
    else:
        outside = None
    marks = []
    for suffix, label in (("_design", "design (the file)"), ("_best", f"best {pretty(zk)} (the result)")):
        mx, my = v.get(xk + suffix), v.get(yk + suffix)
        if isinstance(mx, (int, float)) and isinstance(my, (int, float)):
            marks.append((mx, my, label))
    return design_map_figure(
        x,
        y,
        z,
        names=(xk, yk, zk),
        dimensions=(
            dimension_of(data, xk),
            dimension_of(data, yk),
            dimension_of(data, zk) if dimension_of(data, zk) != "matrix" else None,
        ),
        outside=outside,
        region=region if isinstance(region, list) and len(region) == len(z) else None,
        region_label=_region_label(zk, v.get(zk + "_region")),
        domain=v.get("domain"),
        best=options.best,
        marks=marks,
        title=figure_title(data),
    )


def _region_label(name: str, bound: Any) -> str:
    """The legend of a map's region: the bound the result gives (``<value>_region``, the
    region being where the value reaches it), e.g. "optimum region: η ≥ 0.99"."""
    if isinstance(bound, (int, float)) and not isinstance(bound, bool):
        return f"optimum region: {pretty(name)} ≥ {value_text(bound)}"
    return "optimum region"


def _sweep_map(data: ResultData, options: PlotOptions) -> Any:
    params = _numeric_columns(data, [p["key"] for p in data.parameters])
    if options.x or options.y:
        xk = _sweep_key(data, options.x or params[0], "--x")
        yk = _sweep_key(data, options.y or next(p for p in params if p != xk), "--y")
    elif len(params) >= 2:
        xk, yk = params[0], params[1]
    else:
        raise NotApplicable(f"a map needs two swept numeric parameters; this sweep has {len(params)}")
    others = [p["key"] for p in data.parameters if p["key"] not in (xk, yk)]
    if others:
        raise NotApplicable(f"a map shows two parameters; this sweep also varies {', '.join(others)}")
    zk = _value_column(data, options)
    bases = {p["key"]: p.get("base") for p in data.parameters}
    return design_map_figure(
        data.values[xk],
        data.values[yk],
        data.values[zk],
        names=(xk, yk, zk),
        dimensions=(dimension_of(data, xk), dimension_of(data, yk), dimension_of(data, zk)),
        ok=data.ok,
        outside=[s in OUTSIDE for s in data.statuses or []] or None,
        best=options.best,
        marks=[(bases.get(xk), bases.get(yk), "base design (the file)")],
        title=figure_title(data, f"sweep of {problem_words(data)}"),
    )


# -- curves ----------------------------------------------------------------------------------------


def lines_plot(data: ResultData, options: PlotOptions) -> Any:
    """Values of a one-parameter sweep against the parameter, one panel each."""
    if not data.sweep:
        raise NotApplicable("'lines' plots a sweep results file")
    params = _numeric_columns(data, [p["key"] for p in data.parameters])
    if len(data.parameters) != 1 or not params:
        raise NotApplicable(f"'lines' needs a sweep of one numeric parameter; this one has {len(data.parameters)}")
    x = params[0]
    names = [_value_column(data, options)] if options.value else _numeric_columns(data, data.recorded)
    if not names:
        raise NotApplicable("the sweep recorded no numeric value")
    order = np.argsort(np.asarray(data.values[x], dtype=float))
    ok = data.ok if data.ok is not None else np.ones(len(order), bool)
    panels = [
        Panel(n, dimension_of(data, n), {n: [data.values[n][i] if ok[i] else None for i in order]}) for n in names
    ]
    xs = [data.values[x][i] for i in order]
    return panels_figure(
        xs,
        panels,
        xname=x,
        xdimension=dimension_of(data, x),
        title=figure_title(data, f"{problem_words(data)}: sweep of {x}"),
    )


def _map_axes(name: str) -> tuple[str | None, str | None, str | None]:
    axes = problem_kind(name).map_axes if name in kind_names() else None
    return axes or (None, None, None)
