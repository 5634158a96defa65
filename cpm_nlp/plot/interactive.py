"""Interactive 3-D figures (Plotly): the same content as the 3-D views of
`cpm_nlp.plot.draw` -- a workspace cloud with its boundary slices and
boxes, a mechanism drawing -- in a self-contained HTML file a designer can
rotate (``--plot FILE.html``).  Plotly is an optional extra (``plot``), imported
only here and only when an HTML figure is asked for; the file embeds
plotly.js, so it opens without a network.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from ..core.joints import LETTER_NAMES
from .draw_mechanism import PART_STYLE, Arrow
from .draw_workspace import (
    BOX_EDGES,
    BOX_FACES,
    OTHER_BOXES,
    BoundarySlice,
    box_corners,
    box_sizes,
    points_text,
    slice_lines,
)
from .style import axis_label, display_unit

_PLOTLY_COLOURS = {
    "tab:blue": "#1f77b4",
    "tab:orange": "#ff7f0e",
    "tab:green": "#2ca02c",
    "tab:red": "#d62728",
    "tab:purple": "#9467bd",
    "tab:brown": "#8c564b",
    "tab:pink": "#e377c2",
    "tab:olive": "#bcbd22",
    "tab:cyan": "#17becf",
    "0.45": "#737373",
}
_JOINT_SYMBOL = {"P": "square", "R": "circle", "U": "diamond", "S": "circle-open", "C": "cross"}


def _go() -> Any:
    from ..core.extras import require

    return require("plotly.graph_objects", "plot", "interactive (.html) plots")


def _colour(name: str) -> str:
    return _PLOTLY_COLOURS.get(name, name)


def _layout(fig: Any, title: str, labels: Sequence[str], aspect: str = "cube") -> None:
    fig.update_layout(
        title={"text": _mathless(title).replace("\n", "<br>"), "x": 0.5},
        scene={
            "xaxis_title": labels[0],
            "yaxis_title": labels[1],
            "zaxis_title": labels[2],
            "aspectmode": aspect,
        },
        legend={"orientation": "h", "y": -0.05},
        margin={"l": 0, "r": 0, "t": 60, "b": 0},
        template="plotly_white",
    )


def _greek(m: Any) -> str:
    import unicodedata

    try:
        return unicodedata.lookup(f"GREEK SMALL LETTER {m.group(1).upper()}")
    except KeyError:
        return m.group(1)


def _mathless(label: str) -> str:
    """A label without Matplotlib's mathtext (Plotly shows it literally): ``$\\psi$`` -> ψ."""
    import re

    label = re.sub(r"\\([A-Za-z]+)", _greek, label)
    return label.replace("$", "").replace("{", "").replace("}", "")


def _box_edges(lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """The twelve edges of a box as one polyline, NaN between edges (display units)."""
    corners = box_corners(lo, hi)
    xyz = []
    for a, b in BOX_EDGES:
        xyz += [corners[a], corners[b], [np.nan] * 3]
    return np.array(xyz)


def workspace_html(
    points: Any,
    *,
    cuboid: Any = None,
    names: Sequence[str] = ("x", "y", "z"),
    dimensions: Sequence[str | None] = ("length",) * 3,
    title: str = "",
    points_label: str = "reachable points",
    cuboid_label: str = "maximal inscribed cuboid",
    boxes: Sequence[tuple] = (),
    slices: Sequence[BoundarySlice] = (),
    hull: Any = None,
    slices_label: str = "workspace boundary (slices through the box centre)",
    colour_by_height: bool = False,
) -> Any:
    """The 3-D view of `workspace_figure` as a Plotly figure."""
    go = _go()
    pts = np.asarray(points, dtype=float).reshape(-1, 3)
    pts = pts[np.all(np.isfinite(pts), axis=1)]
    parts = [pts]
    if cuboid is not None:
        parts.append(np.asarray(cuboid, dtype=float).reshape(2, 3))
    parts += [np.vstack([lo, hi]) for lo, hi, _ in boxes]
    if hull is not None:
        parts.append(np.asarray(hull, dtype=float).reshape(-1, 3))
    both = np.vstack(parts)
    scales = [
        display_unit(dimensions[i], both[:, [j for j in range(3) if dimensions[j] == dimensions[i]]]) for i in range(3)
    ]
    f = np.array([s[0] for s in scales])
    fig = go.Figure()
    if len(pts):
        P = pts * f
        fig.add_trace(
            go.Scatter3d(
                x=P[:, 0],
                y=P[:, 1],
                z=P[:, 2],
                mode="markers",
                marker={"size": 2, "color": _colour("tab:blue"), "opacity": 0.5}
                if not colour_by_height
                else {
                    "size": 2,
                    "color": P[:, 2],
                    "colorscale": "Viridis",
                    "opacity": 0.5,
                    "colorbar": {"title": {"text": f"colour: {_mathless(axis_label(names[2], scales[2][1]))}"}},
                },
                name=points_text(points_label, len(P)),
            )
        )
    if hull is not None:
        from scipy.spatial import ConvexHull

        H = np.asarray(hull, dtype=float).reshape(-1, 3) * f
        tri = ConvexHull(H).simplices
        fig.add_trace(
            go.Mesh3d(
                x=H[:, 0],
                y=H[:, 1],
                z=H[:, 2],
                i=tri[:, 0],
                j=tri[:, 1],
                k=tri[:, 2],
                opacity=0.2,
                name="workspace hull",
            )
        )
    first = True
    for sl in slices:
        i, j = sl.axes
        k = 3 - i - j
        for line in slice_lines(sl):
            xyz = np.zeros((len(line), 3))
            xyz[:, i], xyz[:, j], xyz[:, k] = line[:, 0], line[:, 1], sl.at
            xyz = xyz * f
            fig.add_trace(
                go.Scatter3d(
                    x=xyz[:, 0],
                    y=xyz[:, 1],
                    z=xyz[:, 2],
                    mode="lines",
                    line={"color": "black", "width": 3},
                    name=slices_label,
                    legendgroup="boundary",
                    showlegend=first,
                )
            )
            first = False
    # the paper's boxes first, wide and dashed; ours last, over them: shaded, solid edges (issue 24:
    # ours was hidden under an equal paper's box)
    for (lo, hi, label), colour in zip(boxes, OTHER_BOXES):
        lo, hi = np.minimum(lo, hi) * f, np.maximum(lo, hi) * f
        xyz = _box_edges(lo, hi)
        line = {"color": _colour(colour), "width": 10, "dash": "dash"}
        name = f"{label} ({box_sizes(lo, hi, scales)})"
        fig.add_trace(go.Scatter3d(x=xyz[:, 0], y=xyz[:, 1], z=xyz[:, 2], mode="lines", line=line, name=name))
    if cuboid is not None:
        lo, hi = np.asarray(cuboid, dtype=float).reshape(2, 3) * f
        lo, hi = np.minimum(lo, hi), np.maximum(lo, hi)
        cuboid_label = f"{cuboid_label} ({box_sizes(lo, hi, scales)})"
        corners = box_corners(np.minimum(lo, hi), np.maximum(lo, hi))
        tri = np.array(
            [[a, b, c] for face in BOX_FACES for a, b, c in ((face[0], face[1], face[2]), (face[0], face[2], face[3]))]
        )
        fig.add_trace(
            go.Mesh3d(
                x=corners[:, 0],
                y=corners[:, 1],
                z=corners[:, 2],
                i=tri[:, 0],
                j=tri[:, 1],
                k=tri[:, 2],
                color=_colour("tab:red"),
                opacity=0.25,
                name=cuboid_label,
                legendgroup="cuboid",
                showlegend=False,
            )
        )
        xyz = _box_edges(np.minimum(lo, hi), np.maximum(lo, hi))
        fig.add_trace(
            go.Scatter3d(
                x=xyz[:, 0],
                y=xyz[:, 1],
                z=xyz[:, 2],
                mode="lines",
                line={"color": _colour("tab:red"), "width": 4},
                name=cuboid_label,
                legendgroup="cuboid",
            )
        )
    labels = [_mathless(f"{n} ({u})" if u else n) for n, (_, u) in zip(names, scales)]
    _layout(fig, title, labels)
    return fig


def mechanism_html(
    drawing: Any, *, home: Any = None, arrows: Sequence[Arrow] = (), title: str = "", note: str = ""
) -> Any:
    """The mechanism at a pose (and faintly at home) as a Plotly figure, equal scales."""
    go = _go()
    allpts = np.array([np.asarray(v, dtype=float).ravel()[:3] for v in drawing.points.values()])
    factor, unit = display_unit("length", allpts)
    fig = go.Figure()
    for d, faint in ((home, True), (drawing, False)):
        if d is None:
            continue
        pts = {k: np.asarray(v, dtype=float).ravel()[:3] * factor for k, v in d.points.items()}
        for part, corners in d.faces:
            poly = np.array([pts[c] for c in corners])
            n = len(poly)
            fig.add_trace(
                go.Mesh3d(
                    x=poly[:, 0],
                    y=poly[:, 1],
                    z=poly[:, 2],
                    i=[0] * (n - 2),
                    j=list(range(1, n - 1)),
                    k=list(range(2, n)),
                    color="lightgrey" if faint or part == "base" else "#2ca02c",
                    opacity=0.15 if faint else 0.35,
                    name=("home " if faint else "") + part,
                    showlegend=not faint,
                )
            )
        seen: set[str] = set()
        for a, b, part in d.segments:
            colour, width = PART_STYLE[part]
            xyz = np.array([pts[a], pts[b]])
            fig.add_trace(
                go.Scatter3d(
                    x=xyz[:, 0],
                    y=xyz[:, 1],
                    z=xyz[:, 2],
                    mode="lines",
                    line={"color": "#bbbbbb" if faint else _colour(colour), "width": 2 if faint else 2 * width},
                    name="home pose" if faint else part,
                    legendgroup="home" if faint else part,
                    showlegend=(("home" if faint else part) not in seen),
                )
            )
            seen.add("home" if faint else part)
        if not faint:
            for letter in sorted(set(d.joints.values())):
                names = [n for n, j in d.joints.items() if j == letter]
                xyz = np.array([pts[n] for n in names])
                fig.add_trace(
                    go.Scatter3d(
                        x=xyz[:, 0],
                        y=xyz[:, 1],
                        z=xyz[:, 2],
                        mode="markers+text",
                        text=names,
                        marker={"size": 5, "color": "black", "symbol": _JOINT_SYMBOL[letter]},
                        name=f"{LETTER_NAMES[letter]} joint ({letter})",
                    )
                )
    for arrow in arrows:
        o = np.asarray(arrow.origin, dtype=float) * factor
        v = np.asarray(arrow.vector, dtype=float) * factor
        xyz = np.array([o, o + v])
        fig.add_trace(
            go.Scatter3d(
                x=xyz[:, 0],
                y=xyz[:, 1],
                z=xyz[:, 2],
                mode="lines+markers",
                marker={"size": [0, 5], "color": _colour(arrow.colour)},
                line={"color": _colour(arrow.colour), "width": 6},
                name=arrow.label,
            )
        )
    _layout(
        fig, title + (f"<br><sup>{note}</sup>" if note else ""), [f"x ({unit})", f"y ({unit})", f"z ({unit})"], "data"
    )
    return fig
