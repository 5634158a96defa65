"""The mechanism at a pose, from its :class:`~cpm_nlp.core.mechanism.Drawing`:
links, joints and faces in 3-D (a planar mechanism in its plane), arrows on it,
mode shapes on it, and the Jacobian figure (the pose beside cond and
manipulability over a workspace slice).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..core.errors import InputError
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
JOINT_NAME = {"P": "prismatic", "R": "revolute", "U": "universal", "S": "spherical", "C": "cylindrical"}


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
        colour, width = PART_STYLE[part]
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
        label = "_" if letter in kinds else f"{JOINT_NAME[letter]} joint ({letter})"
        kinds.add(letter)
        ax.scatter(
            *pts[name], marker=JOINT_MARKER[letter], s=40, facecolor=face, edgecolor="k", label=label, **joint_style
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
    few_ticks(ax, True)
    if title:
        ax.set_title(title, fontsize="small")
    return ax


def mechanism_figure(
    drawing: Any, *, home: Any = None, arrows: Sequence[Arrow] = (), title: str = "", note: str = ""
) -> Any:
    """The mechanism at a pose, alone: a 3-D view with its legend and ``note`` below."""
    Figure = figure_class()
    fig = Figure(figsize=(8, 7.5), layout="constrained")
    ax = mechanism_axes(fig, (1, 1, 1), drawing, home=home, arrows=arrows)
    legend_below(fig, ax, note)
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
    Figure = figure_class()
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
            title=f"mode {k + 1}: {number(frequencies[k])} Hz",
            label_points=False,
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
