"""Curves against one abscissa, one panel per quantity: the joint requirements
over the studied poses (3-PRS paper, Fig. 6-7), outputs against an input
displacement (pantograph paper, Fig. 20-22), a value against one swept parameter.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..core.errors import InputError
from .style import (
    as_floats,
    axis_label,
    display_unit,
    figure_class,
    pretty,
    wrap,
)

# -- (c), (d) curves in panels ----------------------------------------------------------------------


@dataclass
class Panel:
    """One panel of `panels_figure`: curves of one quantity.

    Attributes
    ----------
    series
        label -> values (SI, one per abscissa point; None/NaN = not solved, a gap);
    annotate_range
        write the range of the values in the panel's title (for requirements).
    """

    name: str
    dimension: str | None
    series: Mapping[str, Any] = field(default_factory=dict)
    annotate_range: bool = False
    title: str = ""
    #: published points drawn over the curves: (x SI, value SI, label)
    points: Sequence[tuple[float, float, str]] = ()
    #: published levels drawn across the panel (value SI, label): e.g. a range read off a paper's figure
    levels: Sequence[tuple[float, str]] = ()


#: markers of the series of one panel, in order (points of unrelated cases: told apart by shape too)
_MARKERS = ("o", "s", "^", "v", "D", "P")


def _draw_panel(ax: Any, panel: Panel, xs: np.ndarray, fx: float, xlabel: str, markers: bool, joined: bool) -> int:
    """One panel: its curves (or, not ``joined``, its points: cases without an order between
    them, side by side at each case) and published points and levels, labels, legend and
    title; how many of its curves and point sets have a value to draw."""
    ys_all = [as_floats(v) for v in panel.series.values()]
    both = np.concatenate([*ys_all, np.array([v for v, _ in panel.levels], dtype=float)]) if ys_all else np.array([])
    fy, uy = display_unit(panel.dimension, both)
    drawn = 0
    n = len(panel.series)
    for k, (label, ys) in enumerate(zip(panel.series, ys_all)):
        if len(ys) != len(xs):
            raise InputError(f"{label}: expected {len(xs)} values (one per point), got {len(ys)}")
        if joined:
            ax.plot(xs * fx, ys * fy, marker="o" if markers else None, ms=3, lw=1.2, label=pretty(label))
        else:  # unrelated cases: no line between them; the series of a case side by side
            dodge = (k - (n - 1) / 2) * min(0.6 / max(n, 1), 0.22)
            ax.plot(xs * fx + dodge, ys * fy, ls="none", marker=_MARKERS[k % len(_MARKERS)], ms=4, label=pretty(label))
        drawn += int(np.isfinite(ys).any())
    for n_level, (value, text) in enumerate(panel.levels):
        ax.axhline(value * fy, color="tab:red", ls="--", lw=1.0, label=text if n_level == 0 else "_level")
    if panel.points:
        px_, py_ = np.array([(p[0], p[1]) for p in panel.points]).T
        ax.plot(px_ * fx, py_ * fy, "D", ms=7, mfc="none", mec="tab:red", mew=1.5, label=panel.points[0][2])
        drawn += 1
    ax.set_ylabel(axis_label(panel.name, uy))
    ax.set_xlabel(xlabel)
    ax.grid(True, alpha=0.3)
    if not joined:
        from matplotlib.ticker import MaxNLocator

        ax.xaxis.set_major_locator(MaxNLocator(integer=True))
    entries = len(panel.series) + bool(panel.points) + bool(panel.levels)
    if entries > 1 and joined:
        ax.legend(fontsize="x-small", ncol=min(3, entries))
    elif entries > 1:  # points fill the panel: the legend in a band kept free above them
        lo, hi = ax.get_ylim()
        ax.set_ylim(lo, hi + 0.4 * (hi - lo))
        ax.legend(fontsize="x-small", ncol=min(4, entries), loc="upper center", handletextpad=0.3, columnspacing=0.8)
    text = _panel_title(panel, both[np.isfinite(both)] * fy, uy)
    if text:
        ax.set_title(wrap(text, int(4.2 * 9)), fontsize="small")
    return drawn


def _panel_title(panel: Panel, finite: np.ndarray, unit: str) -> str:
    """The panel's title, with the range of its values where it asks for it."""
    if not (panel.annotate_range and finite.size):
        return panel.title
    return (panel.title + "\n" if panel.title else "") + f"range {finite.min():.3g} … {finite.max():.3g} {unit}".strip()


def panels_figure(
    x: Any,
    panels: Sequence[Panel],
    *,
    xname: str = "pose",
    xdimension: str | None = None,
    title: str = "",
    ncols: int | None = None,
    markers: bool = True,
    joined: bool = True,
) -> Any:
    """Curves against one abscissa ``x`` (SI), one panel per quantity.

    ``xdimension`` None means a count (e.g. the number of a studied pose); ``joined``
    False: the points are unrelated cases (no line joins them, integer ticks)."""
    Figure = figure_class()
    if not panels:
        raise InputError("nothing to plot (no quantity given)")
    xs = as_floats(x)
    fx, ux = display_unit(xdimension, xs) if xdimension else (1.0, "")
    n = len(panels)
    ncols = ncols or min(n, 3 if n in (3, 5, 6, 9) else 4)
    nrows = math.ceil(n / ncols)
    width = max(4.2 * ncols, 6.5)
    fig = Figure(figsize=(width, 3.3 * nrows + 0.5 + 0.25 * title.count("\n")), layout="constrained")
    xlabel = axis_label(xname, ux) if xdimension else xname
    drawn = 0
    for k, panel in enumerate(panels):
        drawn += _draw_panel(fig.add_subplot(nrows, ncols, k + 1), panel, xs, fx, xlabel, markers, joined)
    if not drawn:
        raise InputError("no point has a value to plot (no point solved)")
    if title:
        fig.suptitle("\n".join(wrap(line, int(width * 9)) for line in title.split("\n")))
    return fig
