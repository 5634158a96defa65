"""Actuator forces and hinge stresses along a motion, from arrays: two panels (forces,
stresses) against the actuator displacement (or the input that varies), with the
allowable stress, the point where the first hinge reaches it, and published points.

Equal curves (the three actuators of a symmetric stage pushed equally) are drawn so
that each is seen: distinct dashes, markers of distinct shapes and sizes, at staggered
samples, and a note in the panel's title.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..core.errors import InputError
from .style import as_floats, display_unit, figure_class, unit_text, wrap

#: (dashes, marker) of the curves in a group of equal ones, in drawing order: the first
#: solid under the others, the next dashed and dotted over it (its gaps show the first)
_STYLES = (("-", "o"), ((0, (5, 3)), "s"), ((0, (1, 2)), "^"), ((0, (6, 2, 1, 2)), "v"), ((0, (2, 2)), "D"))
#: marker sizes (points) in drawing order: a smaller marker over a larger one leaves both seen
_SIZES = (8.0, 5.5, 3.5, 2.5, 2.0)
#: the published points and the limit point
_PUBLISHED = {"marker": "D", "ms": 8, "mfc": "none", "mec": "tab:red", "mew": 1.6, "ls": "none", "zorder": 6}
_LIMIT = {"marker": "*", "ms": 13, "color": "k", "mfc": "gold", "ls": "none", "zorder": 7}


@dataclass
class Quantity:
    """One curve: its legend text and SI values (one per abscissa point; NaN: not solved)."""

    label: str
    values: Any


@dataclass
class ForcePanel:
    """One panel: what it shows (``name``, the axis label's words), the dimension, its curves,
    published points (x SI, value SI, legend text), and horizontal limit lines (value SI, text)."""

    name: str
    dimension: str
    curves: Sequence[Quantity]
    points: Sequence[tuple[float, float, str]] = ()
    lines: Sequence[tuple[float, str]] = ()
    marks: Sequence[tuple[float, float, str]] = field(default_factory=list)


def equal_groups(curves: Sequence[Quantity]) -> list[list[int]]:
    """Indices of curves with equal values (to 1e-9 of the largest), in order."""
    arrays = [as_floats(c.values) for c in curves]
    scale = max((float(np.nanmax(np.abs(a))) for a in arrays if np.isfinite(a).any()), default=1.0) or 1.0
    groups: list[list[int]] = []
    for k, a in enumerate(arrays):
        for g in groups:
            if np.allclose(arrays[g[0]], a, rtol=0, atol=1e-9 * scale, equal_nan=True):
                g.append(k)
                break
        else:
            groups.append([k])
    return groups


def _draw_curves(ax: Any, xs: np.ndarray, curves: Sequence[Quantity], fy: float) -> str:
    """The curves, equal ones drawn to be seen; returns the note naming the equal ones."""
    notes = []
    n = len(xs)
    for group in equal_groups(curves):
        step = max(len(group) * 2, n // 8) if n > 3 * len(group) else 1
        for rank, k in enumerate(group):
            dashes, marker = _STYLES[rank % len(_STYLES)]
            ys = as_floats(curves[k].values) * fy
            ax.plot(
                xs,
                ys,
                ls=dashes,
                lw=1.6 if rank == 0 else 1.3,
                marker=marker,
                ms=_SIZES[rank % len(_SIZES)] if len(group) > 1 else 4.0,
                markevery=(rank * 2 % step if step > 1 else 0, step) if step > 1 else None,
                color=f"C{k % 10}",
                label=curves[k].label,
                zorder=3 + rank,
            )
        if len(group) > 1:
            notes.append(" = ".join(curves[k].label for k in group))
    return "; ".join(f"{text}: the curves coincide" for text in notes)


def _draw_panel(ax: Any, xs: np.ndarray, fx: float, xlabel: str, panel: ForcePanel) -> None:
    values = [as_floats(c.values) for c in panel.curves]
    both = np.concatenate([*values, np.array([p[1] for p in panel.points] + [v for v, _ in panel.lines])])
    fy, unit = display_unit(panel.dimension, both)
    note = _draw_curves(ax, xs * fx, panel.curves, fy)
    for value, text in panel.lines:
        ax.axhline(value * fy, color="tab:red", ls="--", lw=1.2, label=text, zorder=2)
    by_label: dict[str, list[tuple[float, float]]] = {}
    for x, y, text in panel.points:
        if (x, y) not in by_label.setdefault(text, []):
            by_label[text].append((x, y))
    for text, pts in by_label.items():
        px, py = np.array(pts, dtype=float).T
        ax.plot(px * fx, py * fy, label=text, **_PUBLISHED)
    for x, y, text in panel.marks:
        ax.plot([x * fx], [y * fy], label=text, **_LIMIT)
    ax.set_ylabel(f"{panel.name} ({unit_text(unit)})" if unit else panel.name)
    ax.set_xlabel(xlabel)
    ax.set_xlim(left=min(0.0, float(np.nanmin(xs * fx))))
    ax.set_ylim(bottom=min(0.0, float(np.nanmin(both * fy))))
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize="x-small", loc="upper left")
    if note:
        ax.set_title(wrap(note, 60), fontsize="small")


def forces_figure(
    x: Any,
    xlabel: str,
    xdimension: str | None,
    panels: Sequence[ForcePanel],
    *,
    title: str = "",
    subtitle: str = "",
) -> Any:
    """The panels side by side against ``x`` (SI; ``xdimension`` its dimension,
    ``xlabel`` the axis' words without the unit)."""
    Figure = figure_class()
    xs = as_floats(x)
    if not panels or not np.isfinite(xs).any():
        raise InputError("nothing to plot (no solved point)")
    fx, ux = display_unit(xdimension, xs) if xdimension else (1.0, "")
    label = f"{xlabel} ({unit_text(ux)})" if ux else xlabel
    fig = Figure(figsize=(5.2 * len(panels), 4.6), layout="constrained")
    for k, panel in enumerate(panels):
        _draw_panel(fig.add_subplot(1, len(panels), k + 1), xs, fx, label, panel)
    if title:
        fig.suptitle(title + (f"\n{wrap(subtitle, 130)}" if subtitle else ""), fontsize="medium")
    return fig


def readable_group(group: str) -> str:
    """``revolute`` -> "revolute hinges" (the legend of a hinge group's stress)."""
    words = group.replace("_", " ")
    return words if "hinge" in words or "joint" in words else f"{words} hinges"


def published_by_value(
    published: Sequence[tuple[str, float, str]], at: Mapping[int | None, float]
) -> dict[str, list[tuple[float, float, str]]]:
    """Published values of the result's values, as (x SI, value SI, label) per value name:
    ``"F1"`` at the one pose (``at[None]``), ``"F1[2]"`` at the third point (``at[2]``)."""
    import re

    out: dict[str, list[tuple[float, float, str]]] = {}
    for expr, value, text in published:
        m = re.fullmatch(r"(\w+)(?:\[(\d+)\])?", str(expr))
        if m is None:
            continue
        key = None if m.group(2) is None else int(m.group(2))
        if key in at:
            out.setdefault(m.group(1), []).append((float(at[key]), float(value), text))
    return out
