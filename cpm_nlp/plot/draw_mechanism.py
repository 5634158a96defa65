"""The mechanism at a pose, from its `Drawing`:
links, joints and faces in 3-D (a planar mechanism in its plane), arrows on it,
mode shapes on it, and the Jacobian figure (the pose beside cond and
manipulability over a workspace slice).
"""

from __future__ import annotations

import functools
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..core.errors import InputError
from ..core.joints import LETTER_NAMES
from .draw_tables import matrix_axes
from .style import (
    axis_label,
    cell_edges,
    display_unit,
    few_ticks,
    figure_class,
    legend_below,
    number,
    pretty,
)

# -- (e) the mechanism at a pose --------------------------------------------------------------------

#: colour and width of each part of a drawing
PART_STYLE = {
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
JOINT_MARKER = {"P": "s", "R": "o", "U": "D", "S": "o", "C": "^"}


@dataclass
class Arrow:
    """An arrow on a mechanism drawing: from ``origin`` (SI point) along ``vector``
    (drawn to the figure's scale), with a legend ``label``."""

    origin: Any
    vector: Any
    label: str = ""
    colour: str = "tab:red"


#: drawing order of a mechanism's layers (3-D axes draw in this order, not by depth: a leg
#: behind the translucent platform stays in sight)
ZORDER = {"faint": 0.5, "base": 1.0, "platform": 1.5, "link": 2.0, "leg": 2.0, "actuator": 2.5, "joint": 3.0}
ZORDER_ARROW, ZORDER_LABEL = 4.0, 5.0
#: a face's opacity: translucent, so that what is behind it shows
FACE_ALPHA = 0.22
#: the lines of a reference pose (home), drawn under the pose
FAINT_LINE = {"color": "0.6", "lw": 1.0, "ls": "--", "zorder": ZORDER["faint"]}


def draw_mechanism(
    ax: Any,
    drawing: Any,
    *,
    factor: float,
    faint: bool | str = False,
    label_points: bool = True,
    arrows: Sequence[Arrow] = (),
) -> None:
    """Draw a `Drawing` (SI) into a 3-D axes,
    shown = SI * factor; ``faint``: a reference pose (thin, grey, no labels; a text: its legend,
    else "home pose").
    The layers are drawn in a fixed order (`ZORDER`), faces translucent."""
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    ax.computed_zorder = False
    pts = {k: np.asarray(v, dtype=float).ravel()[:3] * factor for k, v in drawing.points.items()}
    for part, corners in drawing.faces:
        poly = np.array([pts[c] for c in corners])
        colour = "0.85" if faint else _FACE_COLOUR[part]
        ax.add_collection3d(
            Poly3DCollection(
                [poly],
                facecolor=colour,
                edgecolor="none" if faint else colour,
                alpha=0.1 if faint else FACE_ALPHA,
                zorder=ZORDER["faint"] if faint else ZORDER.get(part, 1.0),
            )
        )
        if faint:  # its outline dashed, as the home pose's links
            ax.plot(*np.vstack([poly, poly[:1]]).T, label=faint_label(faint), **FAINT_LINE)
    if not _links_and_joints(ax, drawing, pts, set(), faint, {"depthshade": False}):
        return
    if label_points:
        ax.add_artist(point_labels(pts, drawing.joints))
    for arrow in arrows:
        o = np.asarray(arrow.origin, dtype=float) * factor
        v = np.asarray(arrow.vector, dtype=float) * factor
        ax.quiver(
            *o, *v, color=arrow.colour, lw=2, arrow_length_ratio=0.15, label=arrow.label or "_", zorder=ZORDER_ARROW
        )


#: an actuator segment shorter than this fraction of the drawing is not named in the legend (the
#: actuated joint's marker shows where the actuator is)
SHORT_STROKE = 0.06


def faint_label(faint: bool | str) -> str:
    """The legend of a faint drawing: ``faint`` itself if a text, else "home pose"."""
    return faint if isinstance(faint, str) else "home pose"


def _links_and_joints(ax: Any, drawing: Any, pts: dict, seen: set[str], faint: Any, joint_style: dict) -> bool:
    """The links of a drawing (one legend entry per part not in ``seen``) and, unless
    ``faint``, its joints (one legend entry per joint type; actuated joints filled in the
    actuators' colour), in 2-D or 3-D axes alike (the points ``pts`` have 2 or 3
    coordinates); False for a faint drawing (nothing more to draw)."""
    allpts = np.array(list(pts.values()))
    span = float(np.ptp(allpts, axis=0).max()) if len(allpts) > 1 else 1.0
    for a, b, part in drawing.segments:
        colour, width = PART_STYLE[part]
        ends = np.array([pts[a], pts[b]])
        short = part == "actuator" and np.linalg.norm(ends[1] - ends[0]) < SHORT_STROKE * span
        label = "_" if faint or part in seen or short else part
        if label != "_":
            seen.add(part)
        if faint:  # every segment of the home pose named (the legend names it once): some show
            style, label = FAINT_LINE, faint_label(faint)
        else:
            style = {"color": colour, "lw": width, "ls": "-", "zorder": ZORDER[part], "solid_capstyle": "butt"}
        ax.plot(*ends.T, label=label, **style)
    if faint:
        return False
    driven = set(drawing.actuated)
    for name, letter in drawing.joints.items():  # every marker named (the legend names each kind once)
        act = name in driven
        face = ACTUATED_FACE if act else "white" if letter == "S" else "k"
        what = f"{LETTER_NAMES[letter]} joint ({letter})"
        label = f"actuated {what}" if act else what
        ax.scatter(
            *pts[name],
            marker=JOINT_MARKER[letter],
            s=70 if act else 40,
            facecolor=face,
            edgecolor="k",
            label=label,
            zorder=ZORDER["joint"] + (0 if act else 0.1),  # a passive joint at an actuated one: on top, smaller
            **joint_style,
        )
    return True


#: face colour of an actuated joint's marker (the actuators' colour)
ACTUATED_FACE = PART_STYLE["actuator"][0]


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
    faint: bool | str = False,
    label_points: bool = True,
    arrows: Sequence[Arrow] = (),
) -> None:
    """`draw_mechanism` for a planar mechanism, in a 2-D axes (its plane z = 0)."""
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
                edgecolor="none" if faint else colour,
                alpha=0.1 if faint else FACE_ALPHA,
                label=label,
                zorder=ZORDER["faint"] if faint else ZORDER.get(part, 1.0),
            )
        )
        if faint:  # its outline dashed, as the home pose's links
            ax.plot(*np.vstack([poly, poly[:1]]).T, label=faint_label(faint), **FAINT_LINE)
    if not _links_and_joints(ax, drawing, pts, seen, faint, {}):
        return
    if label_points:
        ax.add_artist(point_labels(pts, drawing.joints))
    for arrow in arrows:
        o = np.asarray(arrow.origin, dtype=float).ravel()[:2] * factor
        v = np.asarray(arrow.vector, dtype=float).ravel()[:2] * factor
        ax.annotate(
            "",
            o + v,
            xytext=o,
            arrowprops={"arrowstyle": "-|>", "color": arrow.colour, "lw": 2},
            zorder=ZORDER_ARROW,
            label=arrow.label or "_",
        )
        ax.plot(*np.array([o, o + v]).T, color=arrow.colour, lw=2, label=arrow.label or "_", zorder=ZORDER_ARROW)


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


_LEG_POINT = re.compile(r"([A-Za-z]+?)(\d+)_(\d+)")


def readable_names(names: Sequence[str], joints: Mapping[str, str]) -> dict[str, str]:
    """The label of each point: a leg's joint ``leg3_2`` by its joint letter and leg,
    ``$R_{3}$`` (``$R_{3,2}$`` where the leg has two joints of that letter; the leg by its
    number where every leg's name is one word and a number, else by its name: ``$U_{a1}$``,
    ``$U_{b1}$``); other names as they are (``A''``, ``P``)."""
    legs: dict[tuple[str, str], list[str]] = {}
    for name in names:
        m = _LEG_POINT.fullmatch(name)
        if m and name in joints:
            legs.setdefault(m.group(1, 2), []).append(joints[name])
    numbered = len({word for word, _ in legs}) == 1  # leg1, leg2 ...: the numbers name them
    out = {}
    for name in names:
        m = _LEG_POINT.fullmatch(name)
        if not (m and name in joints):
            out[name] = name
            continue
        letter, n = joints[name], m.group(3)
        leg = m.group(2) if numbered else m.group(1) + m.group(2)
        sub = leg if legs[m.group(1, 2)].count(letter) == 1 else f"{leg},{n}"
        out[name] = f"${letter}_{{{sub}}}$"
    return out


def point_labels(pts: Mapping[str, np.ndarray], joints: Mapping[str, str]) -> Any:
    """The names of a drawing's points as one Matplotlib artist, placed when drawn (the view
    and the layout are then final): points that coincide share one label ("E = P"), points
    closer on the page than `LABEL_NEAR` and in space than `LABEL_NEAR_SPACE` one
    label ("$P_{1}$, $R_{1}$"); each label goes
    to the first place around its point (`LABEL_OFFSETS`) where it overlaps no other
    label and no other point."""
    return _point_labels_class()(pts, joints)


#: points closer than this on the page (points, 1/72 inch) and than this fraction of the drawing's
#: size in space share a label
LABEL_NEAR = 10.0
LABEL_NEAR_SPACE = 0.05
#: where a label may go, in order of preference: (dx, dy) in points from its point
LABEL_OFFSETS = tuple(
    (r * dx, r * dy)
    for r in (4.0, 10.0, 18.0)
    for dx, dy in ((1, 1), (1, -1), (-1, 1), (-1, -1), (1, 0), (-1, 0), (0, 1), (0, -1))
)


def _near_groups(at: np.ndarray, limit: float, where: np.ndarray, near: float) -> list[list[int]]:
    """Indices of the points grouped where they lie within ``limit`` of a group's first on the
    page (``at``, pixels) and within ``near`` of it in space (``where``): points that only look
    close from this view (one behind the other) keep their own labels."""
    groups: list[list[int]] = []
    for k in range(len(at)):
        for g in groups:
            if np.linalg.norm(at[g[0]] - at[k]) <= limit and np.linalg.norm(where[g[0]] - where[k]) <= near:
                g.append(k)
                break
        else:
            groups.append([k])
    return groups


def _place_label(text: Any, p: np.ndarray, renderer: Any, scale: float, placed: list, others: list, frame: Any) -> Any:
    """Move ``text`` to the first offset around ``p`` (pixels) that overlaps no label already
    ``placed`` and no point of ``others`` and stays in ``frame`` (else the least bad one);
    its box."""
    best, best_cost = None, None
    for dx, dy in LABEL_OFFSETS:
        ha = "left" if dx > 0 else "right" if dx < 0 else "center"
        va = "bottom" if dy > 0 else "top" if dy < 0 else "center"
        text.set(position=(p[0] + dx * scale, p[1] + dy * scale), ha=ha, va=va)
        box = text.get_window_extent(renderer).padded(1.5 * scale)
        cost = 10 * sum(box.overlaps(b) for b in placed) + sum(box.overlaps(b) for b in others)
        cost += 0 if frame.contains(box.x0, box.y0) and frame.contains(box.x1, box.y1) else 5
        if best_cost is None or cost < best_cost:
            best, best_cost = ((text.get_position(), ha, va), box), cost
        if cost == 0:
            break
    (pos, ha, va), box = best
    text.set(position=pos, ha=ha, va=va)
    return box


@functools.cache
def _point_labels_class() -> Any:
    """The artist class of `point_labels` (made on first use: Matplotlib is imported
    only when a figure is drawn)."""
    from matplotlib.artist import Artist
    from matplotlib.text import Text
    from matplotlib.transforms import Bbox, IdentityTransform

    class PointLabels(Artist):
        def __init__(self, pts: Mapping[str, np.ndarray], joints: Mapping[str, str]) -> None:
            super().__init__()
            self.set_zorder(ZORDER_LABEL)
            groups = _coincident(pts)
            shown = readable_names([n for _, names in groups for n in names], joints)
            self._anchors = np.array([p for p, _ in groups])
            self._names = [" = ".join(shown[n] for n in names) for _, names in groups]
            self._texts: list[Any] = []

        def get_children(self) -> list[Any]:
            return list(self._texts)

        def _pixels(self) -> np.ndarray:
            P = self._anchors
            if P.shape[1] == 3:
                from mpl_toolkits.mplot3d import proj3d

                xs, ys, _ = proj3d.proj_transform(P[:, 0], P[:, 1], P[:, 2], self.axes.get_proj())
                P = np.c_[xs, ys]
            return self.axes.transData.transform(P)

        def draw(self, renderer: Any) -> None:
            self._texts = []
            if not self.get_visible() or not self._names:
                return
            at = self._pixels()
            scale = renderer.points_to_pixels(1.0)
            half = 5 * scale
            dots = [Bbox.from_extents(*(p - half), *(p + half)) for p in at]
            placed: list[Any] = []
            P = self._anchors
            near = LABEL_NEAR_SPACE * (float(np.ptp(P, axis=0).max()) if len(P) > 1 else 1.0)
            for g in _near_groups(at, LABEL_NEAR * scale, P, near):
                text = Text(
                    0,
                    0,
                    ", ".join(self._names[k] for k in g),
                    fontsize="x-small",
                    color="0.15",
                    transform=IdentityTransform(),
                    bbox={"boxstyle": "round,pad=0.1", "fc": "white", "ec": "none", "alpha": 0.75},
                )
                text.set_figure(self.figure)
                others = [b for k, b in enumerate(dots) if k not in g]
                placed.append(_place_label(text, at[g].mean(axis=0), renderer, scale, placed, others, self.axes.bbox))
                text.draw(renderer)
                self._texts.append(text)

    return PointLabels


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


def _same_pose(a: Any, b: Any) -> bool:
    """Whether two drawings put every point at the same place (to 1e-9 of their size)."""
    if set(a.points) != set(b.points):
        return False
    P = np.array([np.asarray(a.points[n], dtype=float).ravel()[:3] for n in a.points])
    Q = np.array([np.asarray(b.points[n], dtype=float).ravel()[:3] for n in a.points])
    span = float(np.ptp(P, axis=0).max()) if len(P) > 1 else 1.0
    return bool(np.abs(P - Q).max() <= 1e-9 * (span or 1.0))


def _planar_view(ax: Any, unit: str, frame: np.ndarray | None) -> None:
    """Equal scales, axis labels and a grid of a planar drawing; ``frame`` (shown units): the
    points its ranges hold (else the drawing's, with a margin)."""
    ax.set_aspect("equal", adjustable="datalim")
    ax.margins(0.12)
    if frame is not None:
        lo, hi = frame.min(axis=0), frame.max(axis=0)
        pad = 0.12 * (hi - lo)
        ax.set_xlim(lo[0] - pad[0], hi[0] + pad[0])
        ax.set_ylim(lo[1] - pad[1], hi[1] + pad[1])
    ax.set_xlabel(f"x ({unit})")
    ax.set_ylabel(f"y ({unit})")
    ax.grid(True, alpha=0.3)


def _frame_3d(ax: Any, allpts: np.ndarray, arrows: Sequence[Arrow], frame: Any, factor: float) -> None:
    """Equal scales around the points and arrows (or ``frame``, SI); a nearly flat mechanism
    (its height under a fifth of its size) seen from higher up, so that its plane opens."""
    shown = allpts * factor
    for arrow in arrows:
        o = np.asarray(arrow.origin, dtype=float) * factor
        shown = np.vstack([shown, o, o + np.asarray(arrow.vector, dtype=float) * factor])
    if frame is not None:
        shown = np.asarray(frame, dtype=float) * factor
    equal_aspect(ax, shown)
    span = float(np.ptp(allpts, axis=0).max()) or 1.0
    if np.ptp(allpts[:, 2]) < 0.2 * span:
        ax.view_init(elev=55, azim=-70)


def mechanism_axes(
    fig: Any,
    position: Any,
    drawing: Any,
    *,
    home: Any = None,
    arrows: Sequence[Arrow] = (),
    title: str = "",
    label_points: bool = True,
    frame: Any = None,
    home_label: str = "home pose",
) -> Any:
    """A 3-D axes of ``fig`` (subplot ``position``) with the mechanism drawn at
    its pose (and faintly at ``home``), axes in one length unit, equal scales; a
    planar mechanism (every point in z = 0) in a 2-D axes of its plane.  ``frame``:
    points (SI, n x 3) the view must hold; panels given the same frame share their ranges.
    A nearly flat mechanism (its height under a fifth of its size) is seen from higher up."""
    allpts = np.array([np.asarray(v, dtype=float).ravel()[:3] for v in drawing.points.values()])
    if home is not None and _same_pose(drawing, home):
        home = None  # at home: nothing to draw faintly (it would hide under the pose)
    if home is not None:
        allpts = np.vstack([allpts, [np.asarray(v, dtype=float).ravel()[:3] for v in home.points.values()]])
    factor, unit = display_unit("length", allpts)
    if is_planar(drawing, *([home] if home is not None else [])):
        ax = fig.add_subplot(*position)
        if home is not None:
            draw_mechanism_2d(ax, home, factor=factor, faint=home_label)
        draw_mechanism_2d(ax, drawing, factor=factor, arrows=arrows, label_points=label_points)
        _planar_view(ax, unit, None if frame is None else np.asarray(frame, dtype=float)[:, :2] * factor)
        if title:
            ax.set_title(title, fontsize="small")
        return ax
    ax = fig.add_subplot(*position, projection="3d")
    if home is not None:
        draw_mechanism(ax, home, factor=factor, faint=home_label)
    draw_mechanism(ax, drawing, factor=factor, arrows=arrows, label_points=label_points)
    _frame_3d(ax, allpts, arrows, frame, factor)
    ax.set_xlabel(f"x ({unit})")
    ax.set_ylabel(f"y ({unit})")
    ax.set_zlabel(f"z ({unit})")
    few_ticks(ax, True)
    if title:
        ax.set_title(title, fontsize="small")
    return ax


def mechanism_figure(
    drawing: Any,
    *,
    home: Any = None,
    arrows: Sequence[Arrow] = (),
    title: str = "",
    note: str = "",
    home_label: str = "home pose",
) -> Any:
    """The mechanism at a pose, alone: a 3-D view with its legend and ``note`` below; ``home``
    drawn faintly under it, named ``home_label`` in the legend."""
    Figure = figure_class()
    fig = Figure(figsize=(8, 7.5), layout="constrained")
    ax = mechanism_axes(fig, (1, 1, 1), drawing, home=home, arrows=arrows, home_label=home_label)
    legend_below(fig, ax, note)
    if title:
        fig.suptitle(title)
    return fig


def drawing_factor(drawing: Any) -> tuple[float, str]:
    """The length unit `mechanism_axes` shows a drawing in (factor from SI, unit)."""
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
    Figure = figure_class()
    n = min(len(arrows), 3)
    if n == 0:
        raise InputError("no mode to draw")
    fig = Figure(figsize=(4.6 * n, 5.4), layout="constrained")
    frame = [np.asarray(v, dtype=float).ravel()[:3] for v in drawing.points.values()]
    for a in (a for shown in arrows[:n] for a in shown):  # one frame for every panel: the same ranges
        o = np.asarray(a.origin, dtype=float).ravel()[:3]
        frame += [o, o + np.asarray(a.vector, dtype=float).ravel()[:3]]
    for k in range(n):
        mechanism_axes(
            fig,
            (1, n, k + 1),
            drawing,
            arrows=arrows[k],
            title=f"mode {k + 1}: {number(frequencies[k])} Hz",
            label_points=False,
            frame=np.array(frame),
        )
    legend_below(fig, fig.axes[0], note)
    if title:
        fig.suptitle(title)
    return fig


def jacobian_figure(pose: Any, home: Any, got: Any, panels: Sequence[tuple[str, int]], values: Mapping) -> Any:
    """The mechanism at the pose beside cond and manipulability over a slice of
    the workspace (``got`` from the figure module), or beside J_task when there
    is no slice."""
    Figure = figure_class()
    fig = Figure(figsize=(15, 5.2), layout="constrained")
    fig.get_layout_engine().set(wspace=0.12)  # the 3-D view's z label reaches past its axes: room beside it
    ax = mechanism_axes(fig, (1, 3, 1), pose, home=home)
    legend_below(fig, ax, pose.note)
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
            cell_edges(gx * fx), cell_edges(gy * fy), np.ma.masked_invalid(Z), cmap="viridis", shading="flat", norm=norm
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
            at += f" at {pretty(names[k])} = {number(t0[k] * fk)} {uk}"
        a.set_title(f"{name}{at} (blank: outside)".replace("  ", " "), fontsize="small")
        value = values.get(name)
        if isinstance(value, (int, float)):
            a.legend(fontsize="x-small", title=f"{name} = {value:.4g}", title_fontsize="x-small", loc="upper right")
    return fig
