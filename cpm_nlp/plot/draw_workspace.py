"""A reachable workspace from arrays: a 3-D point cloud with its inscribed
cuboid, further boxes, boundary slices and hull, and the three projections
(pantograph paper, Fig. 9-14); a planar workspace in its plane.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..core.errors import InputError
from .style import (
    axis_label,
    display_unit,
    few_ticks,
    figure_class,
    number,
    pretty,
    wrap,
)

# -- (a) workspace -------------------------------------------------------------------------------


@dataclass
class BoundarySlice:
    """A plane slice of the workspace for `workspace_figure`: membership of
    a grid in the plane of task axes ``axes`` (i, j) with the third at ``at`` (SI).

    Attributes
    ----------
    x, y
        the grid lines (SI) along axes i and j;
    inside
        (len(y), len(x)): bools, or the signed margin of the membership test (> 0 inside), whose
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


def slice_lines(sl: BoundarySlice) -> list[np.ndarray]:
    """The boundary of the reachable part of a slice: polylines (K x 2, SI) of the 0.5 level."""
    from contourpy import contour_generator

    if sl.lines is not None:
        return [np.asarray(line, dtype=float).reshape(-1, 2) for line in sl.lines]
    field = slice_field(sl)
    if field is None:
        return []
    z, level = field
    if z.min() >= level or z.max() <= level:
        return []
    gen = contour_generator(np.asarray(sl.x, dtype=float), np.asarray(sl.y, dtype=float), z)
    return [np.asarray(line) for line in gen.lines(level)]


def slice_field(sl: BoundarySlice) -> tuple[np.ndarray, float] | None:
    """The slice's membership as a finite field on its grid and the level of its boundary
    (above it: inside); None when no grid point has a finite margin."""
    raw = np.asarray(sl.inside)
    level = 0.5 if raw.dtype == bool else 0.0
    z = raw.astype(float)
    finite = z[np.isfinite(z)]
    if not finite.size:
        return None
    # a point that does not assemble (margin -inf or nan) is outside, below every finite margin
    low = min(float(finite.min()), level) - (float(np.ptp(finite)) or 1.0)
    return np.where(np.isfinite(z), z, np.where(z == np.inf, float(finite.max()), low)), level


def points_text(label: str, n: int) -> str:
    """A point set's legend text saying what it counts: ``label`` with ``{n}`` filled in,
    else "label: n points"."""
    return label.format(n=n) if "{n}" in label else f"{label}: {n} points"


def box_corners(lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    return np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])


BOX_FACES = ([0, 1, 3, 2], [4, 5, 7, 6], [0, 1, 5, 4], [2, 3, 7, 6], [0, 2, 6, 4], [1, 3, 7, 5])
BOX_EDGES = ((0, 1), (1, 3), (3, 2), (2, 0), (4, 5), (5, 7), (7, 6), (6, 4), (0, 4), (1, 5), (2, 6), (3, 7))
#: colours of further boxes (a paper's formulation beside ours)
OTHER_BOXES = ("tab:purple", "tab:orange", "tab:green")


def box_sizes(lo: np.ndarray, hi: np.ndarray, scales: Sequence[tuple[float, str]]) -> str:
    units = {s[1] for s in scales}
    if len(units) == 1:
        return " × ".join(number(d) for d in hi - lo) + f" {units.pop()}".rstrip()
    return " × ".join(f"{number(d)} {u}".rstrip() for d, (_, u) in zip(hi - lo, scales))


@dataclass
class _Scene:
    """What the 3-D view and the projections of one workspace figure share, in display units:
    the points ``P``, the factor ``f`` of each axis, the scales and labels, the cuboid ``B``,
    the other boxes (SI), the hull's points (SI), the slices with their lines, and every
    point drawn (``both``, SI)."""

    P: np.ndarray
    f: np.ndarray
    size: float
    scales: list
    labels: list[str]
    names: Sequence[str]
    B: np.ndarray | None
    others: list
    hull_pts: np.ndarray | None
    lines_by_slice: list
    both: np.ndarray


def _slice_frame(sl: BoundarySlice) -> np.ndarray:
    """The four corners of a slice's extent, in 3-D (its plane at ``sl.at``)."""
    i, j = sl.axes
    grid = np.zeros((4, 3))
    grid[:, i] = [min(sl.x), max(sl.x)] * 2
    grid[:, j] = [min(sl.y), max(sl.y), max(sl.y), min(sl.y)]
    grid[:, 3 - i - j] = sl.at
    return grid


def _hull_3d(ax: Any, sc: _Scene) -> None:
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection
    from scipy.spatial import ConvexHull

    H = sc.hull_pts * sc.f
    faces = ConvexHull(H).simplices
    hull = Poly3DCollection([H[fc] for fc in faces], facecolor="tab:blue", edgecolor="none", alpha=0.15)
    hull.set_label(f"workspace: hull of {len(H)} vertices")
    ax.add_collection3d(hull)
    ax.scatter(H[:, 0], H[:, 1], H[:, 2], color="tab:blue", s=12)


def _slices_3d(ax: Any, sc: _Scene, label: str) -> None:
    """The boundary slices' lines in their planes (one legend entry for all)."""
    drawn = False
    for sl, lines in sc.lines_by_slice:
        i, j = sl.axes
        k = 3 - i - j
        for line in lines:
            xyz = np.zeros((len(line), 3))
            xyz[:, i], xyz[:, j], xyz[:, k] = line[:, 0], line[:, 1], sl.at
            xyz = xyz * sc.f
            ax.plot(xyz[:, 0], xyz[:, 1], xyz[:, 2], color="k", lw=1.2, label="_b" if drawn else label)
            drawn = True


def _boxes_3d(ax: Any, sc: _Scene, cuboid_label: str) -> None:
    """The cuboid (shaded) and the other boxes (dashed edges), each with its sizes in the legend."""
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    if sc.B is not None:
        lo, hi = sc.B.min(axis=0), sc.B.max(axis=0)
        corners = box_corners(lo, hi)
        faces = Poly3DCollection(
            [corners[fc] for fc in BOX_FACES], facecolor="tab:red", edgecolor="darkred", alpha=0.25
        )
        faces.set_label(f"{cuboid_label} ({box_sizes(lo, hi, sc.scales)})")
        ax.add_collection3d(faces)
    for (olo, ohi, olabel), colour in zip(sc.others, OTHER_BOXES):
        lo, hi = np.minimum(olo, ohi) * sc.f, np.maximum(olo, ohi) * sc.f
        corners = box_corners(lo, hi)
        label = f"{olabel} ({box_sizes(lo, hi, sc.scales)})"
        for n, (a, b) in enumerate(BOX_EDGES):
            ax.plot(*corners[[a, b]].T, color=colour, lw=1.8, ls="--", label=label if n == 0 else "_edge")


def _hull_2d(a2: Any, sc: _Scene, i: int, j: int) -> None:
    from scipy.spatial import ConvexHull

    H2 = (sc.hull_pts * sc.f)[:, [i, j]]
    try:
        loop = H2[ConvexHull(H2).vertices]
        a2.fill(loop[:, 0], loop[:, 1], color="tab:blue", alpha=0.15)
        a2.plot(*np.vstack([loop, loop[:1]]).T, color="tab:blue", lw=1)
    except (ValueError, RuntimeError):  # a flat projection: the points alone
        a2.plot(H2[:, 0], H2[:, 1], "o", color="tab:blue")


def section_label(sl: BoundarySlice) -> str:
    """The legend text of the sections' shaded regions."""
    return f"reachable region of each section (membership on a {len(sl.x)} × {len(sl.y)} grid)"


def _slice_of(sc: _Scene, i: int, j: int) -> tuple[BoundarySlice, list] | None:
    return next(((sl, lines) for sl, lines in sc.lines_by_slice if set(sl.axes) == {i, j}), None)


def _fill_region(ax: Any, u: np.ndarray, v: np.ndarray, w: np.ndarray, level: float, label: str) -> None:
    """The region where the field ``w`` (on the grid u, v) lies above ``level``, shaded:
    patches (one legend entry, ``label``)."""
    from contourpy import FillType, contour_generator
    from matplotlib.patches import PathPatch
    from matplotlib.path import Path

    gen = contour_generator(u, v, w, fill_type=FillType.OuterCode)
    points, codes = gen.filled(level, max(float(w.max()), level) + 1.0)
    for n, (pts, code) in enumerate(zip(points, codes)):
        patch = PathPatch(Path(pts, code), facecolor="tab:blue", edgecolor="none", alpha=0.15, zorder=0.5)
        patch.set_label(label if n == 0 else "_region")
        ax.add_patch(patch)


def _slices_2d(a2: Any, sc: _Scene, i: int, j: int) -> None:
    """The section of the workspace in the plane of axes i, j where a slice is given: its
    reachable region shaded and its boundary, titled by where it cuts (the cloud's points,
    off the plane, are not projected onto it: a section shows what lies in its plane);
    without a slice, the projection of all points, titled so."""
    f = sc.f
    found = _slice_of(sc, i, j)
    if found is None:
        if len(sc.P):
            a2.scatter(sc.P[:, i], sc.P[:, j], s=sc.size, color="tab:blue", alpha=0.3, lw=0, label="_projection")
            a2.set_title("projection of all points", fontsize="small")
        return
    sl, lines = found
    swap = sl.axes != (i, j)
    field = slice_field(sl)
    if field is not None and field[0].max() > field[1]:
        z, level = field
        gx, gy = np.asarray(sl.x, dtype=float) * f[sl.axes[0]], np.asarray(sl.y, dtype=float) * f[sl.axes[1]]
        u, v, w = (gy, gx, z.T) if swap else (gx, gy, z)
        _fill_region(a2, u, v, w, level, section_label(sl))
    for line in lines:
        u, v = (line[:, 1], line[:, 0]) if swap else (line[:, 0], line[:, 1])
        a2.plot(u * f[i], v * f[j], color="k", lw=1.2)
    k = 3 - i - j
    at = sl.at * f[k]
    at = 0.0 if abs(at) < 1e-9 * max(np.ptp(sc.both[:, k] * f[k]), 1e-300) else at
    a2.set_title(f"section at {pretty(sc.names[k])} = {number(at)} {sc.scales[k][1]}".rstrip(), fontsize="small")


def _boxes_2d(a2: Any, sc: _Scene, i: int, j: int) -> None:
    from matplotlib.patches import Rectangle

    if sc.B is not None:
        lo, hi = sc.B.min(axis=0), sc.B.max(axis=0)
        a2.add_patch(
            Rectangle((lo[i], lo[j]), hi[i] - lo[i], hi[j] - lo[j], fill=False, edgecolor="tab:red", lw=2.6, zorder=4)
        )
    for (olo, ohi, _), colour in zip(sc.others, OTHER_BOXES):
        lo, hi = np.minimum(olo, ohi) * sc.f, np.maximum(olo, ohi) * sc.f
        a2.add_patch(
            Rectangle(
                (lo[i], lo[j]), hi[i] - lo[i], hi[j] - lo[j], fill=False, edgecolor=colour, lw=1.6, ls="--", zorder=5
            )
        )


def _projection(a2: Any, sc: _Scene, i: int, j: int) -> None:
    """The plane of axes i, j: the section there (or the projection of the points), hull, boxes."""
    if sc.hull_pts is not None:
        _hull_2d(a2, sc, i, j)
    _slices_2d(a2, sc, i, j)
    _boxes_2d(a2, sc, i, j)
    a2.set_xlabel(sc.labels[i])
    a2.set_ylabel(sc.labels[j])
    a2.grid(True, alpha=0.3)
    a2.autoscale_view()


def _cloud_3d(fig: Any, ax: Any, sc: _Scene, label: str, colour_by_height: bool) -> Any:
    """The cloud in the 3-D view (None without points): one colour, or coloured by its height
    with a colour bar saying so, in the unit of that axis (an inset of the view: the figure's
    axes stay the view and its sections)."""
    P = sc.P
    if not len(P):
        return None
    cloud = ax.scatter(
        P[:, 0],
        P[:, 1],
        P[:, 2],
        s=sc.size,
        alpha=0.4,
        depthshade=False,
        label=label,
        **({"c": P[:, 2], "cmap": "viridis"} if colour_by_height else {"color": "tab:blue"}),
    )
    if colour_by_height:
        fig.colorbar(cloud, cax=ax.inset_axes((1.18, 0.2, 0.035, 0.6)), label=f"colour: {sc.labels[2]}")
    return cloud


def _figure_legend(fig: Any, cloud: Any, points_label: str) -> None:
    """One legend entry per label, the 3-D view's first, then the sections'; a colour-mapped
    cloud's swatch in the colour of a point drawn (the middle one by height)."""
    handles: dict[str, Any] = {}
    for a in fig.axes:
        for h, lab in zip(*a.get_legend_handles_labels()):
            if not lab.startswith("_"):
                handles.setdefault(lab, h)
    if not handles:
        return
    legend = fig.legend(
        list(handles.values()), list(handles), loc="outside lower center", ncols=min(2, len(handles)), fontsize="small"
    )
    if cloud is not None and cloud.get_array() is not None and points_label in handles:
        z = np.asarray(cloud.get_array())
        swatch = legend.legend_handles[list(handles).index(points_label)]
        swatch.set_array(None)  # one colour, not mapped again when drawn
        swatch.set_facecolor(cloud.to_rgba(z[np.argsort(z)[len(z) // 2]], alpha=cloud.get_alpha()))


def workspace_figure(
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
    colour_by_height: bool = False,
) -> Any:
    """A point cloud (N x 3, SI) in 3-D and its three projections (``colour_by_height``: the
    points coloured by their third coordinate, with a colour bar saying so), with an
    optional cuboid ``(lower corner, upper corner)`` drawn in, further
    ``boxes`` (lower, upper, label: e.g. a paper's formulation, dashed),
    boundary ``slices`` (the workspace's boundary in a plane through the box,
    drawn in the projection of that plane and in 3-D) and the convex ``hull``
    of given points (K x 3, SI; e.g. the vertices of an actuator workspace)."""
    Figure = figure_class()
    pts = np.asarray(points, dtype=float).reshape(-1, 3)
    pts = pts[np.all(np.isfinite(pts), axis=1)]
    if not len(pts) and cuboid is None and hull is None:
        raise InputError("no finite points to plot")
    box = None if cuboid is None else np.array([np.asarray(c, dtype=float).ravel()[:3] for c in cuboid])
    others = [(np.asarray(lo, dtype=float), np.asarray(hi, dtype=float), label) for lo, hi, label in boxes]
    hull_pts = None if hull is None else np.asarray(hull, dtype=float).reshape(-1, 3)
    parts = [pts] + ([] if box is None else [box]) + [np.vstack([lo, hi]) for lo, hi, _ in others]
    parts += ([] if hull_pts is None else [hull_pts]) + [_slice_frame(sl) for sl in slices]
    both = np.vstack(parts)
    # one unit per dimension, so that three lengths are read on one scale
    scales = [
        display_unit(dimensions[i], both[:, [j for j in range(3) if dimensions[j] == dimensions[i]]]) for i in range(3)
    ]
    f = np.array([s[0] for s in scales])
    P = pts * f
    sc = _Scene(
        P,
        f,
        float(np.clip(3000 / max(len(P), 1), 2, 25)),
        scales,
        [axis_label(n, s[1]) for n, s in zip(names, scales)],
        names,
        None if box is None else box * f,
        others,
        hull_pts,
        [(sl, slice_lines(sl)) for sl in slices],
        both,
    )
    fig = Figure(figsize=(11, 9), layout="constrained")
    ax = fig.add_subplot(2, 2, 1, projection="3d")
    cloud = _cloud_3d(fig, ax, sc, points_text(points_label, len(P)), colour_by_height)
    ax.set_xlabel(sc.labels[0])
    ax.set_ylabel(sc.labels[1])
    ax.set_zlabel(sc.labels[2])
    few_ticks(ax, True)
    if hull_pts is not None:
        _hull_3d(ax, sc)
    _slices_3d(ax, sc, slices_label)
    _boxes_3d(ax, sc, cuboid_label)
    for n, (i, j) in enumerate(((0, 1), (0, 2), (1, 2))):
        _projection(fig.add_subplot(2, 2, n + 2), sc, i, j)
    _figure_legend(fig, cloud, points_text(points_label, len(P)))
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
    Figure = figure_class()
    from matplotlib.patches import Rectangle

    pts = np.asarray(points, dtype=float).reshape(-1, 2)
    pts = pts[np.all(np.isfinite(pts), axis=1)]
    lines = [np.asarray(line, dtype=float).reshape(-1, 2) for line in outline]
    for sl in slices:
        lines += slice_lines(sl)
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
        ax.scatter(
            P[:, 0], P[:, 1], s=size, color="tab:blue", alpha=0.35, lw=0, label=points_text(points_label, len(P))
        )
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
                label=f"{cuboid_label} ({box_sizes(lo, hi, scales)})",
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
            ncols=1 if max(len(lab) for _, lab in handles) > 55 else min(2, len(handles)),
            fontsize="small",
            title=wrap(note, 95) or None,
            title_fontsize="x-small",
        )
    if title:
        fig.suptitle(title)
    return fig
