"""Figures designers read, from plain arrays (Matplotlib, headless).

Every function takes SI numbers and the dimension of each axis ("length",
"angle", ...), converts them for display (lengths to m, mm, µm or nm
following their size, angles to degrees) and returns a
``matplotlib.figure.Figure`` (no pyplot, no global state, no display: the
Agg and SVG renderers write files).  :func:`save` writes PNG, SVG or PDF
atomically.

* :func:`workspace_figure` -- a reachable workspace as a 3-D point cloud with
  its inscribed cuboid, and the three projections (pantograph paper,
  Fig. 9-14);
* :func:`design_map_figure` -- a value over two design parameters, on a grid
  or on scattered points of any domain, e.g. the RPR (s, t) triangle (RPR
  paper, Fig. 4);
* :func:`panels_figure` -- curves against one abscissa, one panel per
  quantity: the 3-PRS joint requirements over the studied poses (3-PRS
  paper, Fig. 6-7), outputs against an input displacement (pantograph
  paper, Fig. 20-22), a value against one swept parameter.

:mod:`cpm_nlp.plot.figures` chooses and feeds these from results.
"""

from __future__ import annotations

import math
import os
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..core.errors import InputError
from ..core.units import DIMENSIONS, to_display
from ..io.atomic import check_output_path, replace_atomically

#: file types :func:`save` writes
FIGURE_FORMATS = (".png", ".svg", ".pdf")
_LENGTHS = (("m", 1.0), ("mm", 1e-3), ("µm", 1e-6), ("nm", 1e-9))
_GREEK = (
    "alpha",
    "beta",
    "gamma",
    "delta",
    "epsilon",
    "zeta",
    "eta",
    "theta",
    "kappa",
    "lambda",
    "mu",
    "nu",
    "xi",
    "rho",
    "sigma",
    "tau",
    "phi",
    "chi",
    "psi",
    "omega",
)


def _figure_class() -> Any:
    from ..core.extras import require

    require("matplotlib", "plot", "plotting")
    from matplotlib.figure import Figure

    return Figure


# -- units and labels ---------------------------------------------------------------------------


def display_unit(dimension: str | None, values: Any = ()) -> tuple[float, str]:
    """``(factor, unit)`` to show SI values of a dimension: shown = SI * factor.

    Lengths take the largest of m, mm, µm, nm that keeps the largest value
    at or above 1; other dimensions their display unit (angles: deg).
    """
    if dimension == "length":
        arr = np.abs(np.asarray(values, dtype=float).ravel())
        arr = arr[np.isfinite(arr)]
        peak = float(arr.max()) if arr.size else 0.0
        if peak == 0.0:
            return 1e3, "mm"
        for unit, size in _LENGTHS:
            if peak >= size * (1 - 1e-9):
                return 1.0 / size, unit
        return 1e9, "nm"
    if dimension in DIMENSIONS and dimension != "dimensionless":
        factor, unit = to_display(1.0, dimension)
        return factor, unit
    return 1.0, ""


def pretty(name: str) -> str:
    """A symbol for axis labels: ``beta_m1`` -> β_m1, ``dalpha`` -> Δα,
    ``dz`` -> d_z, ``s_max`` -> s_max (Matplotlib mathtext); long plain words
    stay as they are."""
    name = str(name).rsplit(".", 1)[-1]
    head, _, tail = name.partition("_")
    delta = ""
    if len(head) > 1 and head[0] == "d" and head[1:].rstrip("0123456789") in _GREEK:
        delta, head = r"\Delta ", head[1:]  # a change of an angle (dalpha: alpha - alpha at home)
    elif len(head) == 2 and head[0] == "d" and head[1] in "xyz":
        head, tail = "d", "_".join(p for p in (head[1], tail) if p)  # d_z: a displacement along z
    m = re.fullmatch(r"([A-Za-z]+?)(\d*)", head)
    if m is None:
        return name
    letters, digits = m.groups()
    if letters.lower() in _GREEK:
        symbol = "\\" + letters
    elif len(letters) <= 2:
        symbol = letters
    else:
        return name
    sub = ",".join(p for p in (digits, *tail.split("_")) if p)
    return f"${delta}{symbol}" + (f"_{{{sub}}}" if sub else "") + "$"


def _number(v: float) -> str:
    """3 significant digits, without an exponent for values up to 10^5."""
    return f"{v:.0f}" if 1e3 <= abs(v) < 1e5 else f"{v:.3g}"


def axis_label(name: str, unit: str) -> str:
    return f"{pretty(name)} ({unit})" if unit else pretty(name)


# -- saving -----------------------------------------------------------------------------------


def check_figure_path(path: str | os.PathLike, option: str = "-o", inputs: Sequence[str | os.PathLike] = ()) -> None:
    """Fail early (an :class:`InputError`) if a figure cannot be written there
    (or would replace one of ``inputs``)."""
    if Path(path).suffix.lower() not in FIGURE_FORMATS:
        raise InputError(
            f"expected a figure file ending in {', '.join(FIGURE_FORMATS)}, got {str(path)!r}", path=(option,)
        )
    check_output_path(str(path), inputs, option=option)


def save(fig: Any, path: str | os.PathLike, option: str = "-o", inputs: Sequence[str | os.PathLike] = ()) -> None:
    """Write a figure (format from the suffix) all at once."""
    fmt = Path(path).suffix.lower().lstrip(".")
    replace_atomically(
        path, lambda tmp: fig.savefig(tmp, format=fmt, dpi=150), suffix=f".{fmt}", inputs=inputs, option=option
    )


# -- (a) workspace -------------------------------------------------------------------------------


def workspace_figure(
    points: Any,
    *,
    cuboid: tuple[Sequence[float], Sequence[float]] | None = None,
    names: Sequence[str] = ("x", "y", "z"),
    dimensions: Sequence[str | None] = ("length", "length", "length"),
    title: str = "",
    points_label: str = "reachable points",
    cuboid_label: str = "maximal inscribed cuboid",
) -> Any:
    """A point cloud (N x 3, SI) in 3-D and its three projections, with an
    optional cuboid ``(lower corner, upper corner)`` drawn in."""
    Figure = _figure_class()
    from matplotlib.patches import Rectangle
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    pts = np.asarray(points, dtype=float).reshape(-1, 3)
    pts = pts[np.all(np.isfinite(pts), axis=1)]
    if not len(pts) and cuboid is None:
        raise InputError("no finite points to plot")
    box = None if cuboid is None else np.array([np.asarray(c, dtype=float).ravel()[:3] for c in cuboid])
    both = pts if box is None else np.vstack([pts, box])
    # one unit per dimension, so that three lengths are read on one scale
    scales = [
        display_unit(dimensions[i], both[:, [j for j in range(3) if dimensions[j] == dimensions[i]]]) for i in range(3)
    ]
    f = np.array([s[0] for s in scales])
    P = pts * f
    labels = [axis_label(n, s[1]) for n, s in zip(names, scales)]
    fig = Figure(figsize=(11, 9), layout="constrained")
    ax = fig.add_subplot(2, 2, 1, projection="3d")
    size = float(np.clip(3000 / max(len(P), 1), 2, 25))
    ax.scatter(
        P[:, 0], P[:, 1], P[:, 2], s=size, c=P[:, 2], cmap="viridis", alpha=0.6, label=f"{points_label} ({len(P)})"
    )
    ax.set_xlabel(labels[0])
    ax.set_ylabel(labels[1])
    ax.set_zlabel(labels[2])
    B = None
    if box is not None:
        B = box * f
        lo, hi = B.min(axis=0), B.max(axis=0)
        corners = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])
        faces = [[0, 1, 3, 2], [4, 5, 7, 6], [0, 1, 5, 4], [2, 3, 7, 6], [0, 2, 6, 4], [1, 3, 7, 5]]
        ax.add_collection3d(
            Poly3DCollection([corners[fc] for fc in faces], facecolor="tab:red", edgecolor="darkred", alpha=0.25)
        )
        units = {s[1] for s in scales}
        if len(units) == 1:
            sizes = " × ".join(_number(d) for d in hi - lo) + f" {units.pop()}".rstrip()
        else:
            sizes = " × ".join(f"{_number(d)} {u}".rstrip() for d, (_, u) in zip(hi - lo, scales))
        ax.plot([], [], color="tab:red", lw=6, alpha=0.4, label=f"{cuboid_label} ({sizes})")
    ax.legend(loc="upper left", fontsize="small")
    for k, (i, j) in enumerate(((0, 1), (0, 2), (1, 2))):
        a2 = fig.add_subplot(2, 2, k + 2)
        a2.scatter(P[:, i], P[:, j], s=size, color="tab:blue", alpha=0.4)
        if B is not None:
            lo, hi = B.min(axis=0), B.max(axis=0)
            a2.add_patch(Rectangle((lo[i], lo[j]), hi[i] - lo[i], hi[j] - lo[j], fill=False, edgecolor="tab:red", lw=2))
        a2.set_xlabel(labels[i])
        a2.set_ylabel(labels[j])
        a2.grid(True, alpha=0.3)
    if title:
        fig.suptitle(title)
    return fig


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


def _edges(u: np.ndarray) -> np.ndarray:
    mid = (u[1:] + u[:-1]) / 2
    return np.r_[u[0] - (mid[0] - u[0]), mid, u[-1] + (u[-1] - mid[-1])]


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
    Figure = _figure_class()
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
        mappable = ax.pcolormesh(_edges(ux * fx), _edges(uy * fy), masked, cmap="viridis", shading="flat", norm=norm)
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
    fig.colorbar(mappable, ax=ax, label=axis_label(names[2], uz_) + (", log scale" if norm is not None else ""))
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
        ax.plot(X[k], Y[k], "*", color="tab:red", ms=16, mec="k", label=f"{best} {Z[k]:.5g} {uz_}".strip())
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


# -- (c), (d) curves in panels ----------------------------------------------------------------------


@dataclass
class Panel:
    """One panel of :func:`panels_figure`: curves of one quantity.

    series: label -> values (SI, one per abscissa point; None/NaN = not
    solved, a gap); annotate_range: write the range of the values in the
    panel's title (for requirements).
    """

    name: str
    dimension: str | None
    series: Mapping[str, Any] = field(default_factory=dict)
    annotate_range: bool = False
    title: str = ""


#: SI values smaller than this are rounding noise of an exact zero (residuals are
#: accepted at 1e-10): shown as 0, not blown up to 1e-20 nm
NUMERICAL_ZERO = 1e-13


def as_floats(values: Any) -> np.ndarray:
    """SI values (None: not solved) as floats, NaN for None, rounding noise of zero as 0."""
    arr = np.asarray([np.nan if v is None else v for v in values], dtype=float)
    return np.where(np.abs(arr) < NUMERICAL_ZERO, 0.0, arr)


def panels_figure(
    x: Any,
    panels: Sequence[Panel],
    *,
    xname: str = "pose",
    xdimension: str | None = None,
    title: str = "",
    ncols: int | None = None,
    markers: bool = True,
) -> Any:
    """Curves against one abscissa ``x`` (SI), one panel per quantity.

    ``xdimension`` None means a count (e.g. the number of a studied pose)."""
    Figure = _figure_class()
    if not panels:
        raise InputError("nothing to plot (no quantity given)")
    xs = as_floats(x)
    fx, ux = display_unit(xdimension, xs) if xdimension else (1.0, "")
    n = len(panels)
    ncols = ncols or min(n, 3 if n in (3, 5, 6, 9) else 4)
    nrows = math.ceil(n / ncols)
    fig = Figure(figsize=(4.2 * ncols, 3.3 * nrows + 0.5), layout="constrained")
    drawn = 0
    for k, panel in enumerate(panels):
        ax = fig.add_subplot(nrows, ncols, k + 1)
        ys_all = [as_floats(v) for v in panel.series.values()]
        both = np.concatenate(ys_all) if ys_all else np.array([])
        fy, uy = display_unit(panel.dimension, both)
        for label, ys in zip(panel.series, ys_all):
            if len(ys) != len(xs):
                raise InputError(f"{label}: expected {len(xs)} values (one per point), got {len(ys)}")
            ax.plot(xs * fx, ys * fy, marker="o" if markers else None, ms=3, lw=1.2, label=pretty(label))
            drawn += int(np.isfinite(ys).any())
        ax.set_ylabel(axis_label(panel.name, uy))
        ax.set_xlabel(axis_label(xname, ux) if xdimension else xname)
        ax.grid(True, alpha=0.3)
        if len(panel.series) > 1:
            ax.legend(fontsize="x-small", ncol=min(3, len(panel.series)))
        finite = both[np.isfinite(both)] * fy
        text = panel.title
        if panel.annotate_range and finite.size:
            text = (text + "\n" if text else "") + f"{finite.min():.3g} … {finite.max():.3g} {uy}".strip()
        if text:
            ax.set_title(text, fontsize="small")
    if not drawn:
        raise InputError("no point has a value to plot (no point solved)")
    if title:
        fig.suptitle(title)
    return fig


# -- (d) compliance ellipsoid and mode shapes -------------------------------------------------------


def ellipsoid_figure(C: Any, names: Sequence[str], *, title: str = "") -> Any:
    """The compliance ellipsoid {C f : |f| = 1} of a 2x2 or 3x3 translational
    compliance block C (m/N): the deflections a unit force in any direction
    causes, in 3-D (or 2-D) with its principal axes listed."""
    Figure = _figure_class()
    Cm = np.asarray(C, dtype=float)
    n = Cm.shape[0]
    if n not in (2, 3) or Cm.shape != (n, n):
        raise InputError(f"a compliance ellipsoid needs a 2x2 or 3x3 block, got {Cm.shape}")
    S = 0.5 * (Cm + Cm.T)
    w, V = np.linalg.eigh(S)
    peak = float(np.max(np.abs(w))) if w.size else 0.0
    f, unit = display_unit("length", [peak])
    fig = Figure(figsize=(7, 6), layout="constrained")
    text = ", ".join(f"{_number(abs(v) * f)} {unit}/N" for v in w[::-1])
    if n == 3:
        ax = fig.add_subplot(1, 1, 1, projection="3d")
        u, v = np.meshgrid(np.linspace(0, 2 * np.pi, 40), np.linspace(0, np.pi, 20))
        dirs = np.stack([np.cos(u) * np.sin(v), np.sin(u) * np.sin(v), np.cos(v)], axis=-1)
        pts = dirs @ S.T * f
        ax.plot_surface(pts[..., 0], pts[..., 1], pts[..., 2], alpha=0.35, color="tab:blue")
        for k in range(3):
            a = V[:, k] * w[k] * f
            ax.plot([-a[0], a[0]], [-a[1], a[1]], [-a[2], a[2]], color="tab:red", lw=2)
        ax.set_zlabel(axis_label(names[2], unit + "/N"))
    else:
        ax = fig.add_subplot(1, 1, 1)
        t = np.linspace(0, 2 * np.pi, 200)
        pts = np.stack([np.cos(t), np.sin(t)], axis=-1) @ S.T * f
        ax.plot(pts[:, 0], pts[:, 1], color="tab:blue")
        ax.set_aspect("equal")
        ax.grid(True, alpha=0.3)
    ax.set_xlabel(axis_label(names[0], unit + "/N"))
    ax.set_ylabel(axis_label(names[1], unit + "/N"))
    ax.set_title(f"principal compliances: {text}", fontsize="small")
    if title:
        fig.suptitle(title)
    return fig


def modes_figure(
    points: Any, shapes: Sequence[Any], frequencies: Sequence[float], names: Sequence[str], *, title: str = ""
) -> Any:
    """Mode shapes as arrows: one panel per mode, an arrow at each point (N x 3,
    SI) along its displacement in that mode (N x 3, normalized to the largest)."""
    Figure = _figure_class()
    P = np.asarray(points, dtype=float).reshape(-1, 3)
    f, unit = display_unit("length", P)
    n = len(shapes)
    if n == 0:
        raise InputError("no mode to draw")
    span = float(np.ptp(P, axis=0).max()) if len(P) > 1 else float(np.abs(P).max() or 1.0)
    span = span or 1.0
    fig = Figure(figsize=(4.5 * min(n, 3), 4.2 * math.ceil(n / 3)), layout="constrained")
    for k, (shape, freq) in enumerate(zip(shapes, frequencies)):
        D = np.asarray(shape, dtype=float).reshape(-1, 3)
        peak = float(np.abs(D).max()) or 1.0
        D = D / peak * 0.3 * span
        ax = fig.add_subplot(math.ceil(n / 3), min(n, 3), k + 1, projection="3d")
        ax.scatter(P[:, 0] * f, P[:, 1] * f, P[:, 2] * f, color="k", s=12)
        ax.quiver(P[:, 0] * f, P[:, 1] * f, P[:, 2] * f, D[:, 0] * f, D[:, 1] * f, D[:, 2] * f, color="tab:red")
        ax.set_title(f"mode {k + 1}: {_number(freq)} Hz", fontsize="small")
        ax.set_xlabel(axis_label(names[0], unit))
        ax.set_ylabel(axis_label(names[1], unit))
        ax.set_zlabel(axis_label(names[2], unit))
    if title:
        fig.suptitle(title)
    return fig
