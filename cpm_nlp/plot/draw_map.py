"""A design map from arrays: a value over two design parameters, on a grid or
on scattered points of any domain, e.g. the RPR (s, t) triangle (RPR paper, Fig. 4).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..core.errors import InputError
from .style import (
    as_floats,
    axis_label,
    cell_edges,
    display_unit,
    figure_class,
    pretty,
    unit_text,
    value_text,
)

# -- (b) design map ----------------------------------------------------------------------------------


def _grid_index(x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray] | None:
    """(unique x, unique y, ix, iy) if the points are a full grid, each node once."""
    ux, ix = np.unique(x, return_inverse=True)
    uy, iy = np.unique(y, return_inverse=True)
    if len(ux) < 2 or len(uy) < 2 or len(ux) * len(uy) != len(x):
        return None
    if len(set(zip(ix.tolist(), iy.tolist()))) != len(x):
        return None
    return ux, uy, ix, iy


def _slivers(x: np.ndarray, y: np.ndarray, corners: np.ndarray, factor: float = 10.0) -> np.ndarray:
    """Triangles with an edge much longer than the typical one (in axis-relative
    units): they bridge a concave part of the domain, not the sample."""
    span = np.array([np.ptp(x) or 1.0, np.ptp(y) or 1.0])
    p = np.c_[x, y] / span
    edges = np.stack([np.linalg.norm(p[corners[:, i]] - p[corners[:, (i + 1) % 3]], axis=1) for i in range(3)], 1)
    longest = edges.max(axis=1)
    return longest > factor * np.median(edges)


@dataclass
class _Layers:
    """What the layers of one design map share: the axes, the points in display units, which
    solved (``good``), which lie outside the design space (``away``), the region, the domain
    and the colour scale."""

    ax: Any
    X: np.ndarray
    Y: np.ndarray
    Z: np.ndarray
    good: np.ndarray
    away: np.ndarray
    region: np.ndarray | None
    poly: np.ndarray | None
    norm: Any
    levels: Any
    #: the grid's cells outside the design space are drawn (else their points, as dots)
    blank_drawn: bool = False
    #: the region's outline (polylines, display units)
    outline: tuple = ()


#: colour of the points or cells outside the design space (the legend's swatch is the same)
OUTSIDE_COLOUR = "0.86"


def _colour_scale(zpos: np.ndarray) -> tuple[Any, Any]:
    """The colour norm and contour levels: logarithmic for values over decades, else linear;
    the levels round numbers inside the values' range (`contour_levels`)."""
    lo, hi = float(zpos.min()), float(zpos.max())
    if lo > 0 and hi / lo > 1000:  # values over decades: a log scale shows them all
        from matplotlib.colors import LogNorm

        return LogNorm(lo, hi), contour_levels(lo, hi, log=True)
    return None, contour_levels(lo, hi)


def contour_levels(lo: float, hi: float, log: bool = False) -> np.ndarray:
    """Round contour levels strictly inside (lo, hi), as Matplotlib's tickers choose them:
    1-2-5 steps of each decade on a log scale (every decade alone where that gives more than
    nine), about eight 1-2-2.5-5 steps on a linear one."""
    from matplotlib.ticker import LogLocator, MaxNLocator

    if hi <= lo:
        return np.array([])
    if log:
        for subs in ((1.0, 2.0, 5.0), (1.0,)):
            levels = LogLocator(base=10.0, subs=subs).tick_values(lo, hi)
            levels = levels[(levels > lo) & (levels < hi)]
            if len(levels) <= 9:
                break
        return levels
    levels = MaxNLocator(nbins=8, steps=[1, 2, 2.5, 5, 10]).tick_values(lo, hi)
    levels[np.abs(levels) < 1e-9 * (hi - lo)] = 0.0  # the level 0, not its rounding noise
    return levels[(levels > lo) & (levels < hi)]


def level_format(levels: Any) -> Any:
    """A formatter of contour levels: the fewest significant digits that write every level
    exactly ("0.15", "2000", "2.305", "1e-05"), so that round levels read round and close
    ones stay apart."""
    levels = np.asarray(levels, dtype=float)
    for digits in range(1, 13):
        if all(abs(float(f"{v:.{digits}g}") - v) <= 1e-9 * abs(v) for v in levels):
            break

    def text(v: float) -> str:
        if 1 <= abs(v) < 1e6:  # no exponent: "30", "2000", "2.305"
            return f"{v:.{max(0, digits - 1 - int(np.floor(np.log10(abs(v)))))}f}"
        return f"{v:.{digits}g}"

    return text


def _grid_layer(m: _Layers, grid: tuple, fx: float, fy: float) -> Any:
    """Points on a full grid: cells, contour lines, the region's outline."""
    ux, uy, ix, iy = grid
    cells = np.full((len(uy), len(ux)), np.nan)
    cells[iy[m.good], ix[m.good]] = m.Z[m.good]
    masked = np.ma.masked_invalid(cells)
    mappable = m.ax.pcolormesh(
        cell_edges(ux * fx), cell_edges(uy * fy), masked, cmap="viridis", shading="flat", norm=m.norm
    )
    if np.count_nonzero(np.isfinite(cells)) >= 4 and np.nanmax(cells) > np.nanmin(cells) and len(m.levels):
        cs = m.ax.contour(ux * fx, uy * fy, masked, levels=m.levels, colors="k", linewidths=0.6, alpha=0.7)
        m.ax.clabel(cs, fontsize="x-small", fmt=level_format(m.levels))
    if m.away.any():  # cells outside the design space: one light grey, named in the legend
        from matplotlib.collections import PolyCollection

        ex, ey = cell_edges(ux * fx), cell_edges(uy * fy)
        i, j = ix[m.away], iy[m.away]
        cells_out = np.stack(
            [np.c_[ex[i], ey[j]], np.c_[ex[i + 1], ey[j]], np.c_[ex[i + 1], ey[j + 1]], np.c_[ex[i], ey[j + 1]]], axis=1
        )
        m.ax.add_collection(
            PolyCollection(
                cells_out,
                facecolors=OUTSIDE_COLOUR,
                edgecolors=OUTSIDE_COLOUR,
                linewidths=0.3,
                label=f"outside the design space ({int(m.away.sum())} grid points)",
            )
        )
        m.blank_drawn = True
    if m.region is not None and m.region.any():
        mask = np.zeros_like(cells)
        mask[iy, ix] = m.region.astype(float)
        _outline(m, m.ax.contour(ux * fx, uy * fy, mask, levels=[0.5]))
    return mappable


def _outline(m: _Layers, cs: Any) -> None:
    """Keep the lines of a contour set as the region's outline (drawn as lines, so that the
    legend names what is drawn) and remove the contour set."""
    lines = [poly for path in cs.get_paths() for poly in path.to_polygons(closed_only=False) if len(poly) > 1]
    cs.remove()
    m.outline = tuple(lines)


def _triangulated(m: _Layers) -> Any:
    """Scattered points: a triangulation (points outside the design space stay out of it, its
    hull is then the domain's, if convex; points that did not solve make holes)."""
    from matplotlib.path import Path as MplPath
    from matplotlib.tri import Triangulation

    use = ~m.away
    X, Y = m.X[use], m.Y[use]
    tri = Triangulation(X, Y)
    corners = tri.triangles
    bad = ~m.good[use][corners].all(axis=1)
    bad |= _slivers(X, Y, corners)
    if m.poly is not None:
        centroids = np.c_[X[corners].mean(axis=1), Y[corners].mean(axis=1)]
        bad |= ~MplPath(m.poly).contains_points(centroids, radius=1e-9)
    tri.set_mask(bad)
    if bad.all():
        raise ValueError("every triangle has a point that did not solve")
    Zf = np.where(m.good, m.Z, np.nanmean(m.Z[m.good]))[use]
    mappable = m.ax.tripcolor(tri, Zf, cmap="viridis", shading="gouraud", norm=m.norm)
    if np.ptp(m.Z[m.good]) > 0 and len(m.levels):
        cs = m.ax.tricontour(tri, Zf, levels=m.levels, colors="k", linewidths=0.6, alpha=0.7)
        m.ax.clabel(cs, fontsize="x-small", fmt=level_format(m.levels))
    if m.region is not None and m.region[use].any():
        _outline(m, m.ax.tricontour(tri, m.region[use].astype(float), levels=[0.5]))
    return mappable


def _scattered_layer(m: _Layers) -> Any:
    """Scattered points: triangulated, else (too few or collinear points) the points coloured."""
    good = m.good
    try:
        mappable = _triangulated(m)
    except (ValueError, RuntimeError):  # too few or collinear points: colour the points themselves
        return m.ax.scatter(m.X[good], m.Y[good], c=m.Z[good], cmap="viridis", s=30, norm=m.norm)
    if good.sum() <= 2000:
        m.ax.plot(m.X[good], m.Y[good], ".", color="k", ms=1.5, alpha=0.5)
    return mappable


def _point_layers(m: _Layers, region_label: str) -> None:
    """The region's legend entry, the points outside the design space and those not solved,
    the domain's outline."""
    ax, X, Y = m.ax, m.X, m.Y
    for n, line in enumerate(m.outline):  # the region's outline, named once in the legend
        ax.plot(line[:, 0], line[:, 1], color="tab:red", lw=2, label="_" if n else region_label)
    away = m.away
    if away.any() and not m.blank_drawn:  # scattered points outside: dots (a grid's cells: _grid_layer)
        ax.plot(
            X[away], Y[away], ".", color=OUTSIDE_COLOUR, ms=2, label=f"outside the design space ({int(away.sum())})"
        )
    failed = ~m.good & ~away
    if failed.any():
        ax.plot(X[failed], Y[failed], "x", color="0.45", ms=5, label=f"not solved ({int(failed.sum())})")
    if m.poly is not None:
        closed = np.vstack([m.poly, m.poly[:1]])
        ax.plot(closed[:, 0], closed[:, 1], "--", color="k", lw=1.2, label="design domain")


def _marks(m: _Layers, marks: Sequence, best: str | None, fx: float, fy: float, unit: str) -> None:
    """The reference designs, and the best point (``best``: "max" or "min")."""
    ax = m.ax
    styles = ({"marker": "o", "mfc": "white"}, {"marker": "D", "mfc": "tab:orange"}, {"marker": "s", "mfc": "tab:cyan"})
    for (mx, my, label), style in zip(marks, styles):
        if mx is not None and my is not None:
            ax.plot(mx * fx, my * fy, ls="none", mec="k", ms=9, mew=1.5, label=label, **style)
    if best not in ("max", "min"):
        return
    X, Y, Z = m.X, m.Y, m.Z
    idx = np.flatnonzero(m.good)
    k = idx[np.argmax(Z[idx])] if best == "max" else idx[np.argmin(Z[idx])]
    ax.plot(
        X[k], Y[k], "*", color="tab:red", ms=16, mec="k", label=f"{best} {value_text(Z[k])} {unit_text(unit)}".strip()
    )
    ax.annotate(f"({X[k]:.4g}, {Y[k]:.4g})", (X[k], Y[k]), textcoords="offset points", xytext=(8, 8), fontsize="small")


def _solved(x: np.ndarray, y: np.ndarray, z: np.ndarray, ok: Any, name: str) -> np.ndarray:
    """Which points have a value (finite, and ``ok`` where given); bad input: none."""
    if not (len(x) == len(y) == len(z)):
        raise InputError(f"x, y and the value must have one entry per point (got {len(x)}, {len(y)}, {len(z)})")
    good = np.isfinite(z) & np.isfinite(x) & np.isfinite(y)
    if ok is not None:
        good &= np.asarray(ok, dtype=bool).ravel()
    if not good.any():
        raise InputError(f"no point has a value of {name} to plot (no point solved)")
    return good


def design_map_figure(
    x: Any,
    y: Any,
    z: Any,
    *,
    names: Sequence[str] = ("x", "y", "value"),
    dimensions: Sequence[str | None] = (None, None, None),
    ok: Any = None,
    outside: Any = None,
    region: Any = None,
    region_label: str = "optimum region",
    domain: Any = None,
    best: str | None = None,
    marks: Sequence[tuple[float, float, str]] = (),
    title: str = "",
) -> Any:
    """A heat map of ``z`` over two parameters with contour lines.

    Points on a full grid are drawn as cells; scattered points (a random
    sample, a triangle) are triangulated.  ``ok`` marks the points that
    solved (default: finite z); the others leave a hole: those in
    ``outside`` (outside the design space) as faint dots, the rest (did not
    solve) as grey crosses.  ``region``: a boolean per point, outlined in red
    (e.g. the RPR optimum region, Fig. 4).  ``domain``: vertices of the design
    domain, outlined, no colour outside it.  ``best``: "max" or "min" marks
    that point; ``marks``: (x, y, label) of reference designs.
    """
    Figure = figure_class()
    x = np.asarray(x, dtype=float).ravel()
    y = np.asarray(y, dtype=float).ravel()
    z = as_floats(np.asarray(z, dtype=object).ravel())
    good = _solved(x, y, z, ok, names[2])
    away = np.zeros(len(x), bool) if outside is None else np.asarray(outside, dtype=bool).ravel() & ~good
    (fx, ux_), (fy, uy_), (fz, uz_) = (
        display_unit(dimensions[0], x[np.isfinite(x)]),
        display_unit(dimensions[1], y[np.isfinite(y)]),
        display_unit(dimensions[2], z[good]),
    )
    fig = Figure(figsize=(8, 6.5), layout="constrained")
    ax = fig.add_subplot(1, 1, 1)
    Z = z * fz
    norm, levels = _colour_scale(Z[good])
    m = _Layers(
        ax,
        x * fx,
        y * fy,
        Z,
        good,
        away,
        None if region is None else np.array([bool(v) for v in np.asarray(region, dtype=object).ravel()]),
        None if domain is None else np.asarray(domain, dtype=float).reshape(-1, 2) * [fx, fy],
        norm,
        levels,
    )
    grid = _grid_index(x, y)
    mappable = _grid_layer(m, grid, fx, fy) if grid is not None else _scattered_layer(m)
    label = axis_label(names[2], uz_) + (", log scale" if norm is not None else "")
    fig.colorbar(mappable, ax=ax, pad=0.01, fraction=0.05, label=label)
    _point_layers(m, region_label)
    _marks(m, marks, best, fx, fy, uz_)
    ax.set_xlabel(axis_label(names[0], ux_))
    ax.set_ylabel(axis_label(names[1], uy_))
    handles = ax.get_legend_handles_labels()[0]
    if handles:  # below the map, never over it
        fig.legend(loc="outside lower center", ncols=min(3, len(handles)), fontsize="small")
    ax.set_title((title + "\n" if title else "") + f"{pretty(names[2])} over {pretty(names[0])} and {pretty(names[1])}")
    return fig
