"""A design map from arrays: a value over two design parameters, on a grid or
on scattered points of any domain, e.g. the RPR (s, t) triangle (RPR paper, Fig. 4).
"""

from __future__ import annotations

from collections.abc import Sequence
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


def design_map_figure(  # noqa: C901 - one branch per optional layer of the map
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
    from matplotlib.path import Path as MplPath
    from matplotlib.tri import Triangulation

    x = np.asarray(x, dtype=float).ravel()
    y = np.asarray(y, dtype=float).ravel()
    z = as_floats(np.asarray(z, dtype=object).ravel())
    if not (len(x) == len(y) == len(z)):
        raise InputError(f"x, y and the value must have one entry per point (got {len(x)}, {len(y)}, {len(z)})")
    good = np.isfinite(z) & np.isfinite(x) & np.isfinite(y)
    if ok is not None:
        good &= np.asarray(ok, dtype=bool).ravel()
    if not good.any():
        raise InputError(f"no point has a value of {names[2]} to plot (no point solved)")
    away = np.zeros(len(x), bool) if outside is None else np.asarray(outside, dtype=bool).ravel() & ~good
    (fx, ux_), (fy, uy_), (fz, uz_) = (
        display_unit(dimensions[0], x[np.isfinite(x)]),
        display_unit(dimensions[1], y[np.isfinite(y)]),
        display_unit(dimensions[2], z[good]),
    )
    X, Y, Z = x * fx, y * fy, z * fz
    poly = None if domain is None else np.asarray(domain, dtype=float).reshape(-1, 2) * [fx, fy]
    inside_region = None if region is None else np.array([bool(v) for v in np.asarray(region, dtype=object).ravel()])
    fig = Figure(figsize=(8, 6.5), layout="constrained")
    ax = fig.add_subplot(1, 1, 1)
    grid = _grid_index(x, y)
    mappable = None
    levels: Any = 8
    norm = None
    zpos = Z[good]
    if zpos.min() > 0 and zpos.max() / zpos.min() > 1000:  # values over decades: a log scale shows them all
        from matplotlib.colors import LogNorm

        norm = LogNorm(zpos.min(), zpos.max())
        levels = np.geomspace(zpos.min(), zpos.max(), 9)[1:-1]
    if grid is not None:
        ux, uy, ix, iy = grid
        cells = np.full((len(uy), len(ux)), np.nan)
        cells[iy[good], ix[good]] = Z[good]
        masked = np.ma.masked_invalid(cells)
        mappable = ax.pcolormesh(
            cell_edges(ux * fx), cell_edges(uy * fy), masked, cmap="viridis", shading="flat", norm=norm
        )
        if np.count_nonzero(np.isfinite(cells)) >= 4 and np.nanmax(cells) > np.nanmin(cells):
            cs = ax.contour(ux * fx, uy * fy, masked, levels=levels, colors="k", linewidths=0.6, alpha=0.7)
            ax.clabel(cs, fontsize="x-small", fmt="%.3g")
        if inside_region is not None and inside_region.any():
            mask = np.zeros_like(cells)
            mask[iy, ix] = inside_region.astype(float)
            ax.contour(ux * fx, uy * fy, mask, levels=[0.5], colors="tab:red", linewidths=2)
    else:
        try:
            # points outside the design space stay out of the triangulation (its hull is then the
            # domain's, if convex); points that did not solve make holes
            use = ~away
            tri = Triangulation(X[use], Y[use])
            corners = tri.triangles
            bad = ~good[use][corners].all(axis=1)
            bad |= _slivers(X[use], Y[use], corners)
            if poly is not None:
                centroids = np.c_[X[use][corners].mean(axis=1), Y[use][corners].mean(axis=1)]
                bad |= ~MplPath(poly).contains_points(centroids, radius=1e-9)
            tri.set_mask(bad)
            if bad.all():
                raise ValueError("every triangle has a point that did not solve")
            Zf = np.where(good, Z, np.nanmean(Z[good]))[use]
            mappable = ax.tripcolor(tri, Zf, cmap="viridis", shading="gouraud", norm=norm)
            if np.ptp(Z[good]) > 0:
                cs = ax.tricontour(tri, Zf, levels=levels, colors="k", linewidths=0.6, alpha=0.7)
                ax.clabel(cs, fontsize="x-small", fmt="%.3g")
            if inside_region is not None and inside_region[use].any():
                ax.tricontour(tri, inside_region[use].astype(float), levels=[0.5], colors="tab:red", linewidths=2)
        except (ValueError, RuntimeError):  # too few or collinear points: colour the points themselves
            mappable = None
        if mappable is None:
            mappable = ax.scatter(X[good], Y[good], c=Z[good], cmap="viridis", s=30, norm=norm)
        elif good.sum() <= 2000:
            ax.plot(X[good], Y[good], ".", color="k", ms=1.5, alpha=0.5)
    fig.colorbar(
        mappable,
        ax=ax,
        pad=0.01,
        fraction=0.05,
        label=axis_label(names[2], uz_) + (", log scale" if norm is not None else ""),
    )
    if inside_region is not None and inside_region.any():
        ax.plot([], [], color="tab:red", lw=2, label=region_label)
    if away.any():  # few: dotted; many (a grid around the domain): the blank says it
        shown = (X[away], Y[away]) if away.sum() <= 400 else ([], [])
        ax.plot(
            *shown,
            "s" if away.sum() > 400 else ".",
            color="0.8",
            ms=2 if away.sum() <= 400 else 6,
            label=f"outside the design space ({int(away.sum())}{'' if away.sum() <= 400 else ', blank'})",
        )
    failed = ~good & ~away
    if failed.any():
        ax.plot(X[failed], Y[failed], "x", color="0.45", ms=5, label=f"not solved ({int(failed.sum())})")
    if poly is not None:
        closed = np.vstack([poly, poly[:1]])
        ax.plot(closed[:, 0], closed[:, 1], "--", color="k", lw=1.2, label="design domain")
    styles = ({"marker": "o", "mfc": "white"}, {"marker": "D", "mfc": "tab:orange"}, {"marker": "s", "mfc": "tab:cyan"})
    for (mx, my, label), style in zip(marks, styles):
        if mx is not None and my is not None:
            ax.plot(mx * fx, my * fy, ls="none", mec="k", ms=9, mew=1.5, label=label, **style)
    if best in ("max", "min"):
        idx = np.flatnonzero(good)
        k = idx[np.argmax(Z[idx])] if best == "max" else idx[np.argmin(Z[idx])]
        ax.plot(
            X[k],
            Y[k],
            "*",
            color="tab:red",
            ms=16,
            mec="k",
            label=f"{best} {value_text(Z[k])} {unit_text(uz_)}".strip(),
        )
        ax.annotate(
            f"({X[k]:.4g}, {Y[k]:.4g})", (X[k], Y[k]), textcoords="offset points", xytext=(8, 8), fontsize="small"
        )
    ax.set_xlabel(axis_label(names[0], ux_))
    ax.set_ylabel(axis_label(names[1], uy_))
    handles = ax.get_legend_handles_labels()[0]
    if handles:  # below the map, never over it
        fig.legend(loc="outside lower center", ncols=min(3, len(handles)), fontsize="small")
    ax.set_title((title + "\n" if title else "") + f"{pretty(names[2])} over {pretty(names[0])} and {pretty(names[1])}")
    return fig
