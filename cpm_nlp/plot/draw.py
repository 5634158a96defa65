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

from ..core.canonical import canonical_eigh
from ..core.errors import InputError
from ..core.units import DIMENSIONS, to_display
from ..io.atomic import check_output_path, replace_atomically

#: file types :func:`save` writes (.html: an interactive Plotly figure, :mod:`cpm_nlp.plot.interactive`)
FIGURE_FORMATS = (".png", ".svg", ".pdf", ".html")
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


def unit_text(unit: str) -> str:
    """A unit for a label, powers in mathtext: ``mm^3`` -> mm³ (``$\\mathrm{mm}^{3}$``)."""
    if "^" not in unit:
        return unit
    text = re.sub(r"[A-Za-zµ]+", lambda m: r"\mathrm{" + m.group() + "}", unit)
    text = re.sub(r"\^(-?\d+)", r"^{\1}", text).replace("*", r"\cdot ")
    return f"${text}$"


def axis_label(name: str, unit: str) -> str:
    return f"{pretty(name)} ({unit_text(unit)})" if unit else pretty(name)


def value_text(v: float, digits: int = 5) -> str:
    """A value to read: ``digits`` significant digits, more where rounding would
    make it look like a round number it is not (0.99999999991 is not "1")."""
    text = f"{v:.{digits}g}"
    shown = float(text)
    if shown != v and shown == round(shown):
        text = f"{v:.12g}"
    return text


# -- saving -----------------------------------------------------------------------------------


def check_figure_path(path: str | os.PathLike, option: str = "-o", inputs: Sequence[str | os.PathLike] = ()) -> None:
    """Fail early (an :class:`InputError`) if a figure cannot be written there
    (or would replace one of ``inputs``)."""
    if Path(path).suffix.lower() not in FIGURE_FORMATS:
        raise InputError(
            f"expected a figure file ending in {', '.join(FIGURE_FORMATS)}, got {str(path)!r}", path=(option,)
        )
    check_output_path(str(path), inputs, option=option)


def require_backend(path: str | os.PathLike) -> None:
    """The plotting library a figure file needs is installed (an :class:`InputError` saying
    which extra installs it if not): Plotly for .html, Matplotlib for the others."""
    from ..core.extras import require

    if Path(path).suffix.lower() == ".html":
        require("plotly", "plot", "interactive (.html) plots")
    else:
        require("matplotlib", "plot", "plotting")


def save(fig: Any, path: str | os.PathLike, option: str = "-o", inputs: Sequence[str | os.PathLike] = ()) -> None:
    """Write a figure (format from the suffix) all at once; .html: a Plotly figure,
    self-contained (plotly.js embedded: it opens without a network)."""
    fmt = Path(path).suffix.lower().lstrip(".")
    if fmt == "html":
        replace_atomically(
            path,
            lambda tmp: fig.write_html(tmp, include_plotlyjs=True, full_html=True),
            suffix=".html",
            inputs=inputs,
            option=option,
        )
        return
    replace_atomically(
        path, lambda tmp: fig.savefig(tmp, format=fmt, dpi=150), suffix=f".{fmt}", inputs=inputs, option=option
    )


# -- (a) workspace -------------------------------------------------------------------------------


@dataclass
class BoundarySlice:
    """A plane slice of the workspace for :func:`workspace_figure`: membership of
    a grid in the plane of task axes ``axes`` (i, j) with the third at ``at`` (SI).

    x, y: the grid lines (SI) along axes i and j; inside: (len(y), len(x)):
    bools, or the signed margin of the membership test (> 0 inside), whose
    zero level places the boundary between the grid lines.
    """

    axes: tuple[int, int]
    x: Any
    y: Any
    inside: Any
    at: float
    #: the boundary as polylines (K x 2, SI) placed more finely than the grid's contour
    #: (e.g. bisected onto it), drawn instead of the contour
    lines: Any = None


def _slice_lines(sl: BoundarySlice) -> list[np.ndarray]:
    """The boundary of the reachable part of a slice: polylines (K x 2, SI) of the 0.5 level."""
    from contourpy import contour_generator

    if sl.lines is not None:
        return [np.asarray(line, dtype=float).reshape(-1, 2) for line in sl.lines]
    raw = np.asarray(sl.inside)
    level = 0.5 if raw.dtype == bool else 0.0
    z = raw.astype(float)
    finite = z[np.isfinite(z)]
    if not finite.size:
        return []
    # a point that does not assemble (margin -inf or nan) is outside, below every finite margin
    low = min(float(finite.min()), level) - (float(np.ptp(finite)) or 1.0)
    z = np.where(np.isfinite(z), z, np.where(z == np.inf, float(finite.max()), low))
    if z.min() >= level or z.max() <= level:
        return []
    gen = contour_generator(np.asarray(sl.x, dtype=float), np.asarray(sl.y, dtype=float), z)
    return [np.asarray(line) for line in gen.lines(level)]


def _box_corners(lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    return np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])


_BOX_FACES = ([0, 1, 3, 2], [4, 5, 7, 6], [0, 1, 5, 4], [2, 3, 7, 6], [0, 2, 6, 4], [1, 3, 7, 5])
_BOX_EDGES = ((0, 1), (1, 3), (3, 2), (2, 0), (4, 5), (5, 7), (7, 6), (6, 4), (0, 4), (1, 5), (2, 6), (3, 7))
#: colours of further boxes (a paper's formulation beside ours)
_OTHER_BOXES = ("tab:purple", "tab:orange", "tab:green")


def _box_sizes(lo: np.ndarray, hi: np.ndarray, scales: Sequence[tuple[float, str]]) -> str:
    units = {s[1] for s in scales}
    if len(units) == 1:
        return " × ".join(_number(d) for d in hi - lo) + f" {units.pop()}".rstrip()
    return " × ".join(f"{_number(d)} {u}".rstrip() for d, (_, u) in zip(hi - lo, scales))


def _few_ticks(ax: Any, three_d: bool) -> None:
    """At most four ticks per 3-D axis (long labels of a short range overlap otherwise)."""
    from matplotlib.ticker import MaxNLocator

    axes = (ax.xaxis, ax.yaxis, ax.zaxis) if three_d else (ax.xaxis, ax.yaxis)
    for axis in axes:
        axis.set_major_locator(MaxNLocator(4 if three_d else 6))


def workspace_figure(  # noqa: C901 - one branch per optional layer (cloud, boxes, boundary slices)
    points: Any,
    *,
    cuboid: tuple[Sequence[float], Sequence[float]] | None = None,
    names: Sequence[str] = ("x", "y", "z"),
    dimensions: Sequence[str | None] = ("length", "length", "length"),
    title: str = "",
    points_label: str = "reachable points",
    cuboid_label: str = "maximal inscribed cuboid",
    boxes: Sequence[tuple[Sequence[float], Sequence[float], str]] = (),
    slices: Sequence[BoundarySlice] = (),
    hull: Any = None,
    slices_label: str = "workspace boundary (slices through the box centre)",
) -> Any:
    """A point cloud (N x 3, SI) in 3-D and its three projections, with an
    optional cuboid ``(lower corner, upper corner)`` drawn in, further
    ``boxes`` (lower, upper, label: e.g. a paper's formulation, dashed),
    boundary ``slices`` (the workspace's boundary in a plane through the box,
    drawn in the projection of that plane and in 3-D) and the convex ``hull``
    of given points (K x 3, SI; e.g. the vertices of an actuator workspace)."""
    Figure = _figure_class()
    from matplotlib.patches import Rectangle
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    pts = np.asarray(points, dtype=float).reshape(-1, 3)
    pts = pts[np.all(np.isfinite(pts), axis=1)]
    if not len(pts) and cuboid is None and hull is None:
        raise InputError("no finite points to plot")
    box = None if cuboid is None else np.array([np.asarray(c, dtype=float).ravel()[:3] for c in cuboid])
    others = [(np.asarray(lo, dtype=float), np.asarray(hi, dtype=float), label) for lo, hi, label in boxes]
    hull_pts = None if hull is None else np.asarray(hull, dtype=float).reshape(-1, 3)
    parts = [pts] + ([] if box is None else [box]) + [np.vstack([lo, hi]) for lo, hi, _ in others]
    parts += [] if hull_pts is None else [hull_pts]
    for sl in slices:
        i, j = sl.axes
        grid = np.zeros((4, 3))
        grid[:, i] = [min(sl.x), max(sl.x)] * 2
        grid[:, j] = [min(sl.y), max(sl.y), max(sl.y), min(sl.y)]
        grid[:, 3 - i - j] = sl.at
        parts.append(grid)
    both = np.vstack(parts)
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
    if len(P):
        ax.scatter(
            P[:, 0], P[:, 1], P[:, 2], s=size, c=P[:, 2], cmap="viridis", alpha=0.5, label=f"{points_label} ({len(P)})"
        )
    ax.set_xlabel(labels[0])
    ax.set_ylabel(labels[1])
    ax.set_zlabel(labels[2])
    _few_ticks(ax, True)
    if hull_pts is not None:
        from scipy.spatial import ConvexHull

        H = hull_pts * f
        faces = ConvexHull(H).simplices
        ax.add_collection3d(
            Poly3DCollection([H[fc] for fc in faces], facecolor="tab:blue", edgecolor="none", alpha=0.15)
        )
        ax.scatter(H[:, 0], H[:, 1], H[:, 2], color="tab:blue", s=12)
        ax.plot([], [], color="tab:blue", lw=6, alpha=0.3, label=f"workspace: hull of {len(H)} vertices")
    lines_by_slice = [(sl, _slice_lines(sl)) for sl in slices]
    drawn_boundary = False
    for sl, lines in lines_by_slice:
        i, j = sl.axes
        k = 3 - i - j
        for line in lines:
            xyz = np.zeros((len(line), 3))
            xyz[:, i], xyz[:, j], xyz[:, k] = line[:, 0], line[:, 1], sl.at
            xyz = xyz * f
            ax.plot(xyz[:, 0], xyz[:, 1], xyz[:, 2], color="k", lw=1.2, label=None if drawn_boundary else "_b")
            drawn_boundary = True
    if drawn_boundary:
        ax.plot([], [], color="k", lw=1.2, label=slices_label)
    B = None
    if box is not None:
        B = box * f
        lo, hi = B.min(axis=0), B.max(axis=0)
        corners = _box_corners(lo, hi)
        ax.add_collection3d(
            Poly3DCollection([corners[fc] for fc in _BOX_FACES], facecolor="tab:red", edgecolor="darkred", alpha=0.25)
        )
        ax.plot([], [], color="tab:red", lw=6, alpha=0.4, label=f"{cuboid_label} ({_box_sizes(lo, hi, scales)})")
    for (olo, ohi, olabel), colour in zip(others, _OTHER_BOXES):
        lo, hi = np.minimum(olo, ohi) * f, np.maximum(olo, ohi) * f
        corners = _box_corners(lo, hi)
        for a, b in _BOX_EDGES:
            ax.plot(*corners[[a, b]].T, color=colour, lw=1.8, ls="--")
        ax.plot([], [], color=colour, lw=1.8, ls="--", label=f"{olabel} ({_box_sizes(lo, hi, scales)})")
    handles = [h for h, lab in zip(*ax.get_legend_handles_labels()) if not lab.startswith("_")]
    if handles:
        fig.legend(handles=handles, loc="outside lower center", ncols=min(2, len(handles)), fontsize="small")
    for n, (i, j) in enumerate(((0, 1), (0, 2), (1, 2))):
        a2 = fig.add_subplot(2, 2, n + 2)
        if len(P):
            a2.scatter(P[:, i], P[:, j], s=size, color="tab:blue", alpha=0.3, lw=0)
        if hull_pts is not None:
            from scipy.spatial import ConvexHull

            H2 = (hull_pts * f)[:, [i, j]]
            try:
                loop = H2[ConvexHull(H2).vertices]
                a2.fill(loop[:, 0], loop[:, 1], color="tab:blue", alpha=0.15)
                a2.plot(*np.vstack([loop, loop[:1]]).T, color="tab:blue", lw=1)
            except (ValueError, RuntimeError):  # a flat projection: the points alone
                a2.plot(H2[:, 0], H2[:, 1], "o", color="tab:blue")
        for sl, lines in lines_by_slice:
            if set(sl.axes) == {i, j}:
                swap = sl.axes != (i, j)
                for line in lines:
                    u, v = (line[:, 1], line[:, 0]) if swap else (line[:, 0], line[:, 1])
                    a2.plot(u * f[i], v * f[j], color="k", lw=1.2)
                k = 3 - i - j
                at = sl.at * f[k]
                at = 0.0 if abs(at) < 1e-9 * max(np.ptp(both[:, k] * f[k]), 1e-300) else at
                a2.set_title(
                    f"boundary at {pretty(names[k])} = {_number(at)} {scales[k][1]}".rstrip(), fontsize="small"
                )
        if B is not None:
            lo, hi = B.min(axis=0), B.max(axis=0)
            a2.add_patch(Rectangle((lo[i], lo[j]), hi[i] - lo[i], hi[j] - lo[j], fill=False, edgecolor="tab:red", lw=2))
        for (olo, ohi, _), colour in zip(others, _OTHER_BOXES):
            lo, hi = np.minimum(olo, ohi) * f, np.maximum(olo, ohi) * f
            a2.add_patch(
                Rectangle((lo[i], lo[j]), hi[i] - lo[i], hi[j] - lo[j], fill=False, edgecolor=colour, lw=1.8, ls="--")
            )
        a2.set_xlabel(labels[i])
        a2.set_ylabel(labels[j])
        a2.grid(True, alpha=0.3)
        a2.autoscale_view()
    if title:
        fig.suptitle(title)
    return fig


def workspace_figure_2d(
    points: Any,
    *,
    cuboid: tuple[Sequence[float], Sequence[float]] | None = None,
    names: Sequence[str] = ("x", "y"),
    dimensions: Sequence[str | None] = ("length", "length"),
    title: str = "",
    points_label: str = "reachable points",
    cuboid_label: str = "maximal inscribed rectangle",
    slices: Sequence[BoundarySlice] = (),
    outline: Sequence[Any] = (),
    boundary_label: str = "workspace boundary",
    corners: Any = None,
    note: str = "",
) -> Any:
    """A planar workspace (two task coordinates): the points (N x 2, SI), an optional
    rectangle ``(lower, upper)``, its boundary as the zero level of the membership
    margin of ``slices`` (axes (0, 1)) and/or as given polylines ``outline`` (K x 2, SI,
    e.g. the image of the stroke square's edges), the ``corners`` (K x 2) marked; one
    axes, equal scales where both axes are of one dimension; ``note`` under the legend
    says what the boundary is."""
    Figure = _figure_class()
    from matplotlib.patches import Rectangle

    pts = np.asarray(points, dtype=float).reshape(-1, 2)
    pts = pts[np.all(np.isfinite(pts), axis=1)]
    lines = [np.asarray(line, dtype=float).reshape(-1, 2) for line in outline]
    for sl in slices:
        lines += _slice_lines(sl)
    box = None if cuboid is None else np.array([np.asarray(c, dtype=float).ravel()[:2] for c in cuboid])
    cor = None if corners is None else np.asarray(corners, dtype=float).reshape(-1, 2)
    parts = [pts, *lines] + ([] if box is None else [box]) + ([] if cor is None else [cor])
    both = np.vstack([p for p in parts if len(p)]) if any(len(p) for p in parts) else np.zeros((0, 2))
    if not len(both):
        raise InputError("no finite points to plot")
    same = dimensions[0] == dimensions[1]
    scales = [display_unit(dimensions[i], both if same else both[:, i]) for i in range(2)]
    f = np.array([s[0] for s in scales])
    fig = Figure(figsize=(8, 7.5), layout="constrained")
    ax = fig.add_subplot(1, 1, 1)
    if len(pts):
        P = pts * f
        size = float(np.clip(3000 / max(len(P), 1), 2, 25))
        ax.scatter(P[:, 0], P[:, 1], s=size, color="tab:blue", alpha=0.35, lw=0, label=f"{points_label} ({len(P)})")
    for n, line in enumerate(lines):
        ax.plot(line[:, 0] * f[0], line[:, 1] * f[1], color="k", lw=1.4, label="_" if n else boundary_label)
    if cor is not None:
        ax.plot(cor[:, 0] * f[0], cor[:, 1] * f[1], "s", color="k", ms=6, mfc="white", label="corners (images)")
    if box is not None:
        lo, hi = box.min(axis=0) * f, box.max(axis=0) * f
        ax.add_patch(
            Rectangle(
                (lo[0], lo[1]),
                hi[0] - lo[0],
                hi[1] - lo[1],
                fill=False,
                edgecolor="tab:red",
                lw=2,
                label=f"{cuboid_label} ({_box_sizes(lo, hi, scales)})",
            )
        )
    ax.set_xlabel(axis_label(names[0], scales[0][1]))
    ax.set_ylabel(axis_label(names[1], scales[1][1]))
    ax.grid(True, alpha=0.3)
    if same:
        ax.set_aspect("equal", adjustable="datalim")
    ax.margins(0.05)
    handles = [(h, lab) for h, lab in zip(*ax.get_legend_handles_labels()) if not lab.startswith("_")]
    if handles:
        fig.legend(
            [h for h, _ in handles],
            [lab for _, lab in handles],
            loc="outside lower center",
            ncols=min(2, len(handles)),
            fontsize="small",
            title=_wrap(note, 95) or None,
            title_fontsize="x-small",
        )
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
    #: published points drawn over the curves: (x SI, value SI, label)
    points: Sequence[tuple[float, float, str]] = ()


#: SI values smaller than this are rounding noise of an exact zero (residuals are
#: accepted at 1e-10): shown as 0, not blown up to 1e-20 nm
NUMERICAL_ZERO = 1e-13


def as_floats(values: Any) -> np.ndarray:
    """SI values (None: not solved) as floats, NaN for None, rounding noise of zero as 0."""
    arr = np.asarray([np.nan if v is None else v for v in values], dtype=float)
    return np.where(np.abs(arr) < NUMERICAL_ZERO, 0.0, arr)


def panels_figure(  # noqa: C901 - one branch per optional layer of a panel
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
    width = max(4.2 * ncols, 6.5)
    fig = Figure(figsize=(width, 3.3 * nrows + 0.5 + 0.25 * title.count("\n")), layout="constrained")
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
        if panel.points:
            label = panel.points[0][2]
            px_, py_ = np.array([(p[0], p[1]) for p in panel.points]).T
            ax.plot(px_ * fx, py_ * fy, "D", ms=7, mfc="none", mec="tab:red", mew=1.5, label=label)
            drawn += 1
        ax.set_ylabel(axis_label(panel.name, uy))
        ax.set_xlabel(axis_label(xname, ux) if xdimension else xname)
        ax.grid(True, alpha=0.3)
        if len(panel.series) + bool(panel.points) > 1:
            ax.legend(fontsize="x-small", ncol=min(3, len(panel.series) + bool(panel.points)))
        finite = both[np.isfinite(both)] * fy
        text = panel.title
        if panel.annotate_range and finite.size:
            text = (text + "\n" if text else "") + f"{finite.min():.3g} … {finite.max():.3g} {uy}".strip()
        if text:
            ax.set_title(_wrap(text, int(4.2 * 9)), fontsize="small")
    if not drawn:
        raise InputError("no point has a value to plot (no point solved)")
    if title:
        fig.suptitle("\n".join(_wrap(line, int(width * 9)) for line in title.split("\n")))
    return fig


# -- (e) the mechanism at a pose --------------------------------------------------------------------

#: colour and width of each part of a drawing
_PART_STYLE = {
    "base": ("0.45", 1.5),
    "actuator": ("tab:orange", 4.0),
    "link": ("tab:blue", 2.5),
    "leg": ("tab:blue", 2.5),
    "platform": ("tab:green", 2.0),
}
_FACE_COLOUR = {
    "base": "0.75",
    "platform": "tab:green",
    "actuator": "tab:orange",
    "link": "tab:blue",
    "leg": "tab:blue",
}
#: marker of each joint letter (prismatic, revolute, universal, spherical, cylindrical)
_JOINT_MARKER = {"P": "s", "R": "o", "U": "D", "S": "o", "C": "^"}
_JOINT_NAME = {"P": "prismatic", "R": "revolute", "U": "universal", "S": "spherical", "C": "cylindrical"}


@dataclass
class Arrow:
    """An arrow on a mechanism drawing: from ``origin`` (SI point) along ``vector``
    (drawn to the figure's scale), with a legend ``label``."""

    origin: Any
    vector: Any
    label: str = ""
    colour: str = "tab:red"


def draw_mechanism(
    ax: Any,
    drawing: Any,
    *,
    factor: float,
    faint: bool = False,
    label_points: bool = True,
    arrows: Sequence[Arrow] = (),
) -> None:
    """Draw a :class:`~cpm_nlp.core.mechanism.Drawing` (SI) into a 3-D axes,
    shown = SI * factor; ``faint``: a reference pose (thin, grey, no labels)."""
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    pts = {k: np.asarray(v, dtype=float).ravel()[:3] * factor for k, v in drawing.points.items()}
    for part, corners in drawing.faces:
        poly = np.array([pts[c] for c in corners])
        colour = "0.85" if faint else _FACE_COLOUR[part]
        ax.add_collection3d(
            Poly3DCollection(
                [poly], facecolor=colour, edgecolor="0.5" if faint else colour, alpha=0.12 if faint else 0.3
            )
        )
    if not _links_and_joints(ax, drawing, pts, set(), faint, {"depthshade": False}):
        return
    if label_points:
        for p, names in _coincident(pts):
            ax.text(*p, " " + " = ".join(names), fontsize="x-small", color="0.2")
    for arrow in arrows:
        o = np.asarray(arrow.origin, dtype=float) * factor
        v = np.asarray(arrow.vector, dtype=float) * factor
        ax.quiver(*o, *v, color=arrow.colour, lw=2, arrow_length_ratio=0.15, label=arrow.label or "_")


def _links_and_joints(ax: Any, drawing: Any, pts: dict, seen: set[str], faint: bool, joint_style: dict) -> bool:
    """The links of a drawing (one legend entry per part not in ``seen``) and, unless
    ``faint``, its joints (one legend entry per joint type), in 2-D or 3-D axes alike (the
    points ``pts`` have 2 or 3 coordinates); False for a faint drawing (nothing more to draw)."""
    for a, b, part in drawing.segments:
        colour, width = _PART_STYLE[part]
        ends = np.array([pts[a], pts[b]])
        label = "_" if faint or part in seen else part
        seen.add(part)
        style = {"color": "0.7", "lw": 1.0, "ls": "--"} if faint else {"color": colour, "lw": width, "ls": "-"}
        ax.plot(*ends.T, label=label, **style)
    if faint:
        ax.plot([], [], color="0.7", lw=1.0, ls="--", label="home pose")
        return False
    kinds: set[str] = set()
    for name, letter in drawing.joints.items():
        face = "white" if letter == "S" else "k"
        label = "_" if letter in kinds else f"{_JOINT_NAME[letter]} joint ({letter})"
        kinds.add(letter)
        ax.scatter(
            *pts[name], marker=_JOINT_MARKER[letter], s=40, facecolor=face, edgecolor="k", label=label, **joint_style
        )
    return True


def is_planar(*drawings: Any) -> bool:
    """Every point of the drawings in the plane z = 0 (to 1e-9 of their size): a planar
    mechanism, drawn in 2-D."""
    pts = np.array([np.asarray(v, dtype=float).ravel()[:3] for d in drawings for v in d.points.values()])
    if not len(pts) or pts.shape[1] < 3:
        return False
    span = float(np.ptp(pts[:, :2], axis=0).max()) or 1.0
    return bool(np.all(np.abs(pts[:, 2]) <= 1e-9 * span))


def draw_mechanism_2d(
    ax: Any,
    drawing: Any,
    *,
    factor: float,
    faint: bool = False,
    label_points: bool = True,
    arrows: Sequence[Arrow] = (),
) -> None:
    """:func:`draw_mechanism` for a planar mechanism, in a 2-D axes (its plane z = 0)."""
    from matplotlib.patches import Polygon

    pts = {k: np.asarray(v, dtype=float).ravel()[:2] * factor for k, v in drawing.points.items()}
    seen: set[str] = set()
    for part, corners in drawing.faces:
        colour = "0.85" if faint else _FACE_COLOUR[part]
        poly = np.array([pts[c] for c in corners])
        label = "_" if faint or part in seen else part
        seen.add(part)
        ax.add_patch(
            Polygon(
                poly,
                closed=True,
                facecolor=colour,
                edgecolor="0.5" if faint else colour,
                alpha=0.12 if faint else 0.3,
                label=label,
            )
        )
    if not _links_and_joints(ax, drawing, pts, seen, faint, {"zorder": 5}):
        return
    if label_points:
        for p, names in _coincident(pts):
            ax.annotate(
                " = ".join(names), p, xytext=(4, 4), textcoords="offset points", fontsize="x-small", color="0.2"
            )
    for arrow in arrows:
        o = np.asarray(arrow.origin, dtype=float).ravel()[:2] * factor
        v = np.asarray(arrow.vector, dtype=float).ravel()[:2] * factor
        ax.annotate("", o + v, xytext=o, arrowprops={"arrowstyle": "-|>", "color": arrow.colour, "lw": 2}, zorder=6)
        ax.plot([], [], color=arrow.colour, lw=2, label=arrow.label or "_")


def _coincident(pts: Mapping[str, np.ndarray]) -> list[tuple[np.ndarray, list[str]]]:
    """The points grouped where they coincide (one label each: "A1 = C1")."""
    allpts = np.array(list(pts.values())) if pts else np.zeros((0, 3))
    tol = 1e-9 * (float(np.ptp(allpts, axis=0).max()) if len(allpts) > 1 else 1.0)
    groups: list[tuple[np.ndarray, list[str]]] = []
    for name, p in pts.items():
        for q, names in groups:
            if np.linalg.norm(p - q) <= tol:
                names.append(name)
                break
        else:
            groups.append((p, [name]))
    return groups


def equal_aspect(ax: Any, points: np.ndarray) -> None:
    """Equal scales on the three axes of a 3-D axes around ``points`` (shown units)."""
    lo, hi = points.min(axis=0), points.max(axis=0)
    span = float(max(np.max(hi - lo), 1e-300))
    mid = (lo + hi) / 2
    pad = 0.55 * span
    ax.set_xlim(mid[0] - pad, mid[0] + pad)
    ax.set_ylim(mid[1] - pad, mid[1] + pad)
    ax.set_zlim(mid[2] - pad, mid[2] + pad)
    ax.set_box_aspect((1, 1, 1))


def mechanism_axes(
    fig: Any,
    position: Any,
    drawing: Any,
    *,
    home: Any = None,
    arrows: Sequence[Arrow] = (),
    title: str = "",
    label_points: bool = True,
) -> Any:
    """A 3-D axes of ``fig`` (subplot ``position``) with the mechanism drawn at
    its pose (and faintly at ``home``), axes in one length unit, equal scales; a
    planar mechanism (every point in z = 0) in a 2-D axes of its plane."""
    allpts = np.array([np.asarray(v, dtype=float).ravel()[:3] for v in drawing.points.values()])
    if home is not None:
        allpts = np.vstack([allpts, [np.asarray(v, dtype=float).ravel()[:3] for v in home.points.values()]])
    factor, unit = display_unit("length", allpts)
    if is_planar(drawing, *([home] if home is not None else [])):
        ax = fig.add_subplot(*position)
        if home is not None:
            draw_mechanism_2d(ax, home, factor=factor, faint=True)
        draw_mechanism_2d(ax, drawing, factor=factor, arrows=arrows, label_points=label_points)
        ax.set_aspect("equal", adjustable="datalim")
        ax.margins(0.12)
        ax.set_xlabel(f"x ({unit})")
        ax.set_ylabel(f"y ({unit})")
        ax.grid(True, alpha=0.3)
        if title:
            ax.set_title(title, fontsize="small")
        return ax
    ax = fig.add_subplot(*position, projection="3d")
    if home is not None:
        draw_mechanism(ax, home, factor=factor, faint=True)
    draw_mechanism(ax, drawing, factor=factor, arrows=arrows, label_points=label_points)
    shown = allpts * factor
    for arrow in arrows:
        o = np.asarray(arrow.origin, dtype=float) * factor
        shown = np.vstack([shown, o, o + np.asarray(arrow.vector, dtype=float) * factor])
    equal_aspect(ax, shown)
    ax.set_xlabel(f"x ({unit})")
    ax.set_ylabel(f"y ({unit})")
    ax.set_zlabel(f"z ({unit})")
    _few_ticks(ax, True)
    if title:
        ax.set_title(title, fontsize="small")
    return ax


def mechanism_figure(
    drawing: Any, *, home: Any = None, arrows: Sequence[Arrow] = (), title: str = "", note: str = ""
) -> Any:
    """The mechanism at a pose, alone: a 3-D view with its legend and ``note`` below."""
    Figure = _figure_class()
    fig = Figure(figsize=(8, 7.5), layout="constrained")
    ax = mechanism_axes(fig, (1, 1, 1), drawing, home=home, arrows=arrows)
    _legend_below(fig, ax, note)
    if title:
        fig.suptitle(title)
    return fig


def drawing_factor(drawing: Any) -> tuple[float, str]:
    """The length unit :func:`mechanism_axes` shows a drawing in (factor from SI, unit)."""
    allpts = np.array([np.asarray(v, dtype=float).ravel()[:3] for v in drawing.points.values()])
    return display_unit("length", allpts)


def modes_mechanism_figure(
    drawing: Any,
    arrows: Sequence[Sequence[Arrow]],
    frequencies: Sequence[float],
    *,
    title: str = "",
    note: str = "",
) -> Any:
    """Mode shapes on the mechanism: one panel per mode (up to three), the mechanism
    at its pose with an arrow at each of its points along that point's displacement."""
    Figure = _figure_class()
    n = min(len(arrows), 3)
    if n == 0:
        raise InputError("no mode to draw")
    fig = Figure(figsize=(4.6 * n, 5.4), layout="constrained")
    for k in range(n):
        mechanism_axes(
            fig,
            (1, n, k + 1),
            drawing,
            arrows=arrows[k],
            title=f"mode {k + 1}: {_number(frequencies[k])} Hz",
            label_points=False,
        )
    _legend_below(fig, fig.axes[0], note)
    if title:
        fig.suptitle(title)
    return fig


def principal_axes(S: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Principal compliances (ascending) and axes (columns) of a symmetric block S, in
    the canonical form of :func:`cpm_nlp.core.canonical.canonical_eigh`: each axis'
    first significant component positive, and equal compliances (a circle, a sphere)
    with axes along the coordinates in their order, on every BLAS kernel."""
    w, V, _ = canonical_eigh(np.asarray(S, dtype=float))
    return w, V


def _ellipsoid_on(ax: Any, S: np.ndarray, centre: np.ndarray, scale: float) -> None:
    """The ellipsoid {S f : |f| = 1} (or the ellipse of a 2x2 S, in the plane z = centre)
    drawn in shown units at ``centre``, ``scale`` shown units per m/N."""
    n = S.shape[0]
    if not hasattr(ax, "zaxis"):  # a planar mechanism in its plane: the ellipse of the x, y block
        S2 = S[:2, :2]
        t = np.linspace(0, 2 * np.pi, 200)
        pts = np.stack([np.cos(t), np.sin(t)], axis=-1) @ S2.T * scale
        ax.plot(pts[:, 0] + centre[0], pts[:, 1] + centre[1], color="tab:purple", lw=2, zorder=9)
        w, V = principal_axes(S2)
        for k in range(2):
            a = V[:, k] * w[k] * scale
            ax.plot(*np.array([centre[:2] - a, centre[:2] + a]).T, color="tab:purple", lw=3, zorder=10)
        ax.plot([], [], color="tab:purple", lw=3, label="compliance ellipse (scaled)")
        return
    if n == 3:
        u, v = np.meshgrid(np.linspace(0, 2 * np.pi, 40), np.linspace(0, np.pi, 20))
        dirs = np.stack([np.cos(u) * np.sin(v), np.sin(u) * np.sin(v), np.cos(v)], axis=-1)
        pts = dirs @ S.T * scale + centre
        ax.plot_surface(pts[..., 0], pts[..., 1], pts[..., 2], alpha=0.35, color="tab:purple", zorder=9)
    else:
        t = np.linspace(0, 2 * np.pi, 200)
        pts = np.stack([np.cos(t), np.sin(t)], axis=-1) @ S.T * scale
        ax.plot(pts[:, 0] + centre[0], pts[:, 1] + centre[1], np.full_like(t, centre[2]), color="tab:purple", lw=2)
    w, V = principal_axes(S)
    for k in range(n):  # the principal axes: seen even where the ellipsoid is flat
        a = np.zeros(3)
        a[:n] = V[:, k] * w[k] * scale
        ax.plot(*np.array([centre - a, centre + a]).T, color="tab:purple", lw=3, zorder=10)
    ax.computed_zorder = False  # the ellipsoid over the platform's face
    ax.plot([], [], color="tab:purple", lw=3, label="compliance ellipsoid (scaled)")


def _legend_below(fig: Any, ax: Any, note: str = "") -> None:
    note = _wrap(note, 140) if len(note) > 140 else note  # a long note in lines, not past the figure's edges
    handles, labels = ax.get_legend_handles_labels()
    keep = [(h, lab) for h, lab in zip(handles, labels) if not lab.startswith("_")]
    if keep:
        fig.legend(
            [h for h, _ in keep],
            [lab for _, lab in keep],
            loc="outside lower center",
            ncols=min(3, len(keep)),
            fontsize="small",
            title=note or None,
            title_fontsize="x-small",
        )


# -- (f) comparisons and matrices ----------------------------------------------------------------------


@dataclass
class Comparison:
    """One quantity computed here beside a reference (a paper's printed value, a
    reference design): shown as the reference's ratio to ours."""

    name: str
    ours: float
    reference: float
    dimension: str | None = None


def comparison_axes(
    ax: Any, rows: Sequence[Comparison], *, reference_label: str, ours_label: str = "this model"
) -> None:
    """Rows of reference / ours on a log axis (1: agree), each with both values written out."""
    y = np.arange(len(rows))[::-1]
    ratios = []
    for r in rows:
        ratio = r.reference / r.ours if r.ours not in (0, 0.0) and r.ours is not None else np.nan
        ratios.append(ratio if np.isfinite(ratio) and ratio > 0 else np.nan)
    ratios = np.array(ratios)
    ax.axvline(1.0, color="k", lw=1)
    ax.barh(
        y,
        np.nan_to_num(ratios - 1.0),
        left=1.0,
        color=["tab:green" if abs(r - 1) < 0.01 else "tab:orange" for r in np.nan_to_num(ratios, nan=1)],
        height=0.6,
    )
    ax.set_yticks(y, [pretty(r.name) for r in rows])
    for yi, r in zip(y, rows):
        f, unit = display_unit(r.dimension, [r.ours, r.reference])
        ax.annotate(
            f"{ours_label} {_number(r.ours * f)} · {reference_label} {_number(r.reference * f)} "
            f"{unit_text(unit)}".rstrip(),
            (0, yi),
            xycoords=("axes fraction", "data"),
            xytext=(4, 9),
            textcoords="offset points",
            fontsize="x-small",
            va="bottom",
        )
    finite = ratios[np.isfinite(ratios)]
    span = max(float(np.max(np.abs(finite - 1.0))) if finite.size else 0.0, 0.05)
    ax.set_xlim(1.0 - 1.3 * span, 1.0 + 1.3 * span)
    ax.set_ylim(-0.7, len(rows) - 0.1)
    ax.set_xlabel(f"{reference_label} / {ours_label}")
    ax.grid(True, axis="x", alpha=0.3)


def matrix_axes(ax: Any, M: Any, *, title: str = "", rows: Sequence[str] = (), cols: Sequence[str] = ()) -> None:
    """A matrix as a heat map of log10 |entry|, each entry written in."""
    M = np.asarray(M, dtype=float)
    mag = np.log10(np.where(np.abs(M) > 0, np.abs(M), np.nan))
    im = ax.imshow(mag, cmap="Blues", aspect="auto")
    big = float(np.abs(M).max()) if M.size else 0.0
    for (i, j), v in np.ndenumerate(M):
        v = 0.0 if abs(v) <= 1e-12 * big else v  # rounding noise of an exact zero
        dark = np.isfinite(mag[i, j]) and im.norm(mag[i, j]) > 0.6
        ax.text(j, i, f"{v:.3g}", ha="center", va="center", fontsize="x-small", color="white" if dark else "black")
    ax.set_xticks(range(M.shape[1]), [pretty(c) for c in cols] if len(cols) == M.shape[1] else range(1, M.shape[1] + 1))
    ax.set_yticks(range(M.shape[0]), [pretty(r) for r in rows] if len(rows) == M.shape[0] else range(1, M.shape[0] + 1))
    ax.set_title(title, fontsize="small")
    return im


def comparison_figure(
    groups: Sequence[tuple[str, Sequence[Comparison]]], spread: Mapping[str, Any] | None = None, *, title: str = ""
) -> Any:
    """One panel per kind of reference (:func:`comparison_axes`), and the
    multi-start record (starts, converged, agreed; distinct optima) if given."""
    Figure = _figure_class()
    spread = dict(spread or {})
    heights = [max(len(rows), 1) * 0.55 + 1.0 for _, rows in groups]
    extra = 1 if spread else 0
    fig = Figure(figsize=(8, sum(heights) + 2.2 * extra + 0.8), layout="constrained")
    axes = fig.subplots(len(groups) + extra, 1, height_ratios=heights + [2.2] * extra, squeeze=False)[:, 0]
    for ax, (label, rows) in zip(axes, groups):
        comparison_axes(ax, rows, reference_label=label)
        ax.set_title(f"against the {label}", fontsize="small")
    if spread:
        ax = axes[-1]
        optima = spread.pop("optima", None)
        counts = {k: v for k, v in spread.items() if isinstance(v, (int, float))}
        if counts:
            names = list(counts)
            ax.bar(range(len(names)), [counts[n] for n in names], color="tab:blue", width=0.6)
            ax.set_xticks(range(len(names)), [n.replace("_", " ") for n in names], fontsize="small")
            ax.set_ylabel("starts")
        text = "multi-start: " + ", ".join(f"{k.replace('_', ' ')} {v}" for k, v in counts.items())
        if optima:
            text += f"; {len(optima)} distinct optim{'um' if len(optima) == 1 else 'a'}"
        ax.set_title(text, fontsize="small")
    if title:
        fig.suptitle(title)
    return fig


def matrices_figure(mats: Sequence[tuple[str, Any]], units: Mapping[str, str] | None = None, *, title: str = "") -> Any:
    """Matrices as annotated heat maps (:func:`matrix_axes`), the unit text of each below it."""
    Figure = _figure_class()
    units = units or {}
    n = len(mats)
    ncols = min(n, 3)
    nrows = math.ceil(n / ncols)
    fig = Figure(figsize=(4.6 * ncols, 4.0 * nrows + 0.6), layout="constrained")
    for k, (name, M) in enumerate(mats):
        ax = fig.add_subplot(nrows, ncols, k + 1)
        matrix_axes(ax, M, title=pretty(name))
        note = units.get(name, "")
        if note:
            ax.set_xlabel(_wrap(note, 60), fontsize="x-small")
    if title:
        fig.suptitle(title)
    return fig


def _wrap(text: str, width: int) -> str:
    import textwrap

    return "\n".join(textwrap.wrap(text, width)) or text


def dynamics_figure(
    freqs: Any,
    modes: Any,
    coords: Sequence[str],
    groups: Sequence[tuple[str, Sequence[Comparison]]],
    *,
    title: str = "",
) -> Any:
    """Natural frequencies (bars), mode shapes (each normalised to its largest
    entry, one group of bars per mode) and the comparison with printed values."""
    Figure = _figure_class()
    freqs = np.asarray(freqs, dtype=float)
    modes = np.asarray(modes, dtype=float)
    fig = Figure(figsize=(11, 4.2 + (2.0 if groups else 0)), layout="constrained")
    top, bottom = fig.subfigures(2, 1, height_ratios=[4.2, 2.0 * len(groups)]) if groups else (fig, None)
    a1, a2 = top.subplots(1, 2)
    labels = [f"mode {k + 1}" for k in range(len(freqs))]
    a1.bar(labels, freqs, color="tab:blue", width=0.6)
    for k, f in enumerate(freqs):
        a1.annotate(f"{f:.4g} Hz", (k, f), ha="center", va="bottom", fontsize="small")
    a1.set_ylabel("natural frequency (Hz)")
    a1.set_ylim(0, 1.15 * max(freqs.max(), 1e-12))
    width = 0.8 / max(len(freqs), 1)
    for k in range(modes.shape[1]):
        v = modes[:, k] / np.abs(modes[:, k]).max()
        a2.bar(np.arange(len(coords)) + (k - (modes.shape[1] - 1) / 2) * width, v, width, label=f"mode {k + 1}")
    a2.set_xticks(range(len(coords)), [pretty(c) for c in coords])
    a2.axhline(0, color="k", lw=0.8)
    a2.set_ylabel("mode shape (normalised)")
    a2.legend(fontsize="x-small")
    a2.set_title("eigenvectors of K v = ω² M v", fontsize="small")
    if bottom is not None:
        axes = bottom.subplots(len(groups), 1, squeeze=False)[:, 0]
        for ax, (label, rows) in zip(axes, groups):
            comparison_axes(ax, rows, reference_label=label)
    if title:
        fig.suptitle(title)
    return fig


def jacobian_figure(pose: Any, home: Any, got: Any, panels: Sequence[tuple[str, int]], values: Mapping) -> Any:
    """The mechanism at the pose beside cond and manipulability over a slice of
    the workspace (``got`` from the figure module), or beside J_task when there
    is no slice."""
    Figure = _figure_class()
    fig = Figure(figsize=(15, 5.2), layout="constrained")
    ax = mechanism_axes(fig, (1, 3, 1), pose, home=home)
    _legend_below(fig, ax, pose.note)
    if got is None:
        a2 = fig.add_subplot(1, 3, 2)
        matrix_axes(a2, values["J_task"], title="J_task (no workspace slice: the pose is outside)")
        return fig
    gx, gy, cond, manip, names, kinds, t0 = got
    fx, ux = display_unit(kinds[0], gx)
    fy, uy = display_unit(kinds[1], gy)
    for (name, pos), Z in zip(panels, (cond, manip)):
        a = fig.add_subplot(1, 3, pos)
        finite = Z[np.isfinite(Z) & (Z > 0)]
        norm = None
        if finite.size and finite.max() / finite.min() > 20:  # near a singularity: a log scale keeps the rest readable
            from matplotlib.colors import LogNorm

            norm = LogNorm(finite.min(), finite.max())
        mesh = a.pcolormesh(
            _edges(gx * fx), _edges(gy * fy), np.ma.masked_invalid(Z), cmap="viridis", shading="flat", norm=norm
        )
        fig.colorbar(mesh, ax=a, pad=0.01, fraction=0.05, label=name + (", log scale" if norm is not None else ""))
        a.plot(t0[0] * fx, t0[1] * fy, "*", color="tab:red", ms=14, mec="k", label="the pose")
        a.set_xlabel(axis_label(names[0], ux))
        a.set_ylabel(axis_label(names[1], uy))
        if kinds[0] == kinds[1] == "length" and ux == uy:  # a plane of the workspace: equal scales
            a.set_aspect("equal", adjustable="box")
        at = ""
        for k in range(2, len(names)):  # the task coordinates held at the pose (none for a 2-D task)
            fk, uk = display_unit(kinds[k], [t0[k]])
            at += f" at {pretty(names[k])} = {_number(t0[k] * fk)} {uk}"
        a.set_title(f"{name}{at} (blank: outside)".replace("  ", " "), fontsize="small")
        value = values.get(name)
        if isinstance(value, (int, float)):
            a.legend(fontsize="x-small", title=f"{name} = {value:.4g}", title_fontsize="x-small", loc="upper right")
    return fig


# -- (d) compliance ellipsoid and mode shapes -------------------------------------------------------


def ellipsoid_figure(
    C: Any, names: Sequence[str], *, title: str = "", drawing: Any = None, centre: Any = None, note: str = ""
) -> Any:
    """The compliance ellipsoid {C f : |f| = 1} of a 2x2 or 3x3 translational
    compliance block C (m/N): the deflections a unit force in any direction
    causes, in 3-D (or 2-D) with its principal axes listed.  With a ``drawing``
    of the mechanism (and the platform ``centre``, SI), a first panel draws the
    ellipsoid there on the mechanism, scaled to a quarter of its size."""
    Figure = _figure_class()
    Cm = np.asarray(C, dtype=float)
    n = Cm.shape[0]
    if n not in (2, 3) or Cm.shape != (n, n):
        raise InputError(f"a compliance ellipsoid needs a 2x2 or 3x3 block, got {Cm.shape}")
    S = 0.5 * (Cm + Cm.T)
    w, V = principal_axes(S)
    peak = float(np.max(np.abs(w))) if w.size else 0.0
    f, unit = display_unit("length", [peak])
    text = ", ".join(f"{_number(abs(v) * f)} {unit}/N" for v in w[::-1])
    panels = 1 if drawing is None else 2
    fig = Figure(figsize=(7 * panels, 6.5 if drawing is not None else 6), layout="constrained")
    if drawing is not None:
        on = mechanism_axes(fig, (1, 2, 1), drawing)
        df, dunit = drawing_factor(drawing)
        allpts = np.array([np.asarray(v, dtype=float).ravel()[:3] for v in drawing.points.values()])
        span = float(np.ptp(allpts, axis=0).max()) or 1.0
        force = 0.25 * span / (peak or 1.0)
        force = float(10 ** math.floor(math.log10(force)))
        _ellipsoid_on(on, S, np.asarray(centre, dtype=float).ravel()[:3] * df, force * df)
        on.set_title(f"at the platform centre: the deflections under |f| = {force:g} N", fontsize="small")
        _legend_below(fig, on, note)
    if n == 3:
        ax = fig.add_subplot(1, panels, panels, projection="3d")
        u, v = np.meshgrid(np.linspace(0, 2 * np.pi, 40), np.linspace(0, np.pi, 20))
        dirs = np.stack([np.cos(u) * np.sin(v), np.sin(u) * np.sin(v), np.cos(v)], axis=-1)
        pts = dirs @ S.T * f
        ax.plot_surface(pts[..., 0], pts[..., 1], pts[..., 2], alpha=0.35, color="tab:blue")
        for k in range(3):
            a = V[:, k] * w[k] * f
            ax.plot([-a[0], a[0]], [-a[1], a[1]], [-a[2], a[2]], color="tab:red", lw=2)
        ax.set_zlabel(axis_label(names[2], unit + "/N"))
        # equal scales on the three axes, so a flat ellipsoid looks flat (not a sphere)
        lim = 1.05 * peak * f or 1.0
        ax.set_xlim(-lim, lim), ax.set_ylim(-lim, lim), ax.set_zlim(-lim, lim)
        ax.set_box_aspect((1, 1, 1))
    else:
        ax = fig.add_subplot(1, panels, panels)
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
