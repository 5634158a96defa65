"""Compliance and vibration from arrays: the compliance ellipsoid of a
translational block, natural frequencies and mode shapes.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np

from ..core.canonical import canonical_eigh
from ..core.errors import InputError
from .draw_mechanism import drawing_factor, mechanism_axes
from .draw_tables import Comparison, comparison_axes
from .style import (
    axis_label,
    display_unit,
    figure_class,
    legend_below,
    number,
    pretty,
)


def principal_axes(S: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Principal compliances (ascending) and axes (columns) of a symmetric block S, in
    the canonical form of `cpm_nlp.core.canonical.canonical_eigh`: each axis'
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
            label = "compliance ellipse (scaled)" if k == 0 else "_axis"
            ax.plot(*np.array([centre[:2] - a, centre[:2] + a]).T, color="tab:purple", lw=3, zorder=10, label=label)
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
        label = "compliance ellipsoid (scaled)" if k == n - 1 else "_axis"
        ax.plot(*np.array([centre - a, centre + a]).T, color="tab:purple", lw=3, zorder=10, label=label)
    ax.computed_zorder = False  # the ellipsoid over the platform's face


#: colours of the principal axes, the largest compliance first
AXIS_COLOURS = ("tab:red", "tab:orange", "tab:green")
_PREFIXES = ((1e9, "G"), (1e6, "M"), (1e3, "k"), (1.0, ""), (1e-3, "m"), (1e-6, "µ"), (1e-9, "n"), (1e-12, "p"))


def prefixed(value: float, unit: str) -> str:
    """A value with the engineering prefix that puts it in [1, 1000): 10000 N -> "10 kN"."""
    mag = abs(value)
    scale, prefix = next(((s, p) for s, p in _PREFIXES if mag >= s * (1 - 1e-12)), _PREFIXES[-1])
    if mag == 0:
        scale, prefix = 1.0, ""
    return f"{number(value / scale)} {prefix}{unit}"


def compliance_text(c: float) -> str:
    """A compliance (m/N) in its own length prefix: 3.49 µm/N, 16.3 nm/N."""
    return prefixed(abs(c), "m/N")


def _principal_axes_on(ax: Any, w: np.ndarray, V: np.ndarray, f: float, names: Sequence[str]) -> None:
    """The principal axes of the ellipsoid (2-D: ellipse) centred at 0, the largest first, each
    labelled with its half-length (the principal compliance) and direction; marked at its ends so
    that an axis too short to see as a line still shows."""
    n = len(w)
    order = np.argsort(-np.abs(w), kind="stable")
    for rank, k in enumerate(order):
        a = V[:, k] * abs(w[k]) * f
        direction = ", ".join(f"{0.0 if abs(c) < 5e-4 else c:.3g}" for c in V[:, k])
        label = f"{compliance_text(w[k])} along ({direction}) in ({', '.join(names[:n])})"
        ends = np.array([-a, a]).T
        ax.plot(*ends, color=AXIS_COLOURS[rank % 3], lw=2.2, marker="o", ms=4, label=label, zorder=5)


# -- (d) compliance ellipsoid and mode shapes -------------------------------------------------------


def ellipsoid_figure(
    C: Any, names: Sequence[str], *, title: str = "", drawing: Any = None, centre: Any = None, note: str = ""
) -> Any:
    """The compliance ellipsoid {C f : |f| = 1} of a 2x2 or 3x3 translational
    compliance block C (m/N): the deflections a unit force in any direction
    causes, in 3-D (or 2-D) with its principal axes listed.  With a ``drawing``
    of the mechanism (and the platform ``centre``, SI), a first panel draws the
    ellipsoid there on the mechanism, scaled to a quarter of its size."""
    Figure = figure_class()
    Cm = np.asarray(C, dtype=float)
    n = Cm.shape[0]
    if n not in (2, 3) or Cm.shape != (n, n):
        raise InputError(f"a compliance ellipsoid needs a 2x2 or 3x3 block, got {Cm.shape}")
    S = 0.5 * (Cm + Cm.T)
    w, V = principal_axes(S)
    peak = float(np.max(np.abs(w))) if w.size else 0.0
    f, unit = display_unit("length", [peak])
    text = ", ".join(compliance_text(v) for v in w[::-1])
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
        on.set_title(
            f"at the platform centre: the deflections under a force of {prefixed(force, 'N')} in any direction",
            fontsize="small",
        )
        legend_below(fig, on, note)
    if n == 3:
        ax = fig.add_subplot(1, panels, panels, projection="3d")
        u, v = np.meshgrid(np.linspace(0, 2 * np.pi, 40), np.linspace(0, np.pi, 20))
        dirs = np.stack([np.cos(u) * np.sin(v), np.sin(u) * np.sin(v), np.cos(v)], axis=-1)
        pts = dirs @ S.T * f
        ax.plot_surface(pts[..., 0], pts[..., 1], pts[..., 2], alpha=0.25, color="tab:blue")
        _principal_axes_on(ax, w, V, f, names)
        ax.set_zlabel(axis_label(names[2], unit + "/N"))
        # equal scales on the three axes, so a flat ellipsoid looks flat (not a sphere)
        lim = 1.05 * peak * f or 1.0
        ax.set_xlim(-lim, lim), ax.set_ylim(-lim, lim), ax.set_zlim(-lim, lim)
        ax.set_box_aspect((1, 1, 1))
    else:
        ax = fig.add_subplot(1, panels, panels)
        t = np.linspace(0, 2 * np.pi, 200)
        pts = np.stack([np.cos(t), np.sin(t)], axis=-1) @ S.T * f
        ax.plot(pts[:, 0], pts[:, 1], color="tab:blue", label="compliance ellipse")
        _principal_axes_on(ax, w, V, f, names)
        ax.set_aspect("equal")
        ax.grid(True, alpha=0.3)
    ax.set_xlabel(axis_label(names[0], unit + "/N"))
    ax.set_ylabel(axis_label(names[1], unit + "/N"))
    ax.set_title(f"principal compliances: {text}", fontsize="small")
    ranked = np.sort(np.abs(w))[::-1]
    equal = [k for k in range(len(ranked) - 1) if abs(ranked[k] - ranked[k + 1]) <= 1e-9 * max(peak, 1e-300)]
    heading = "principal axes (half-lengths)"
    if equal:  # a circle or a sphere in those axes: the directions drawn are one choice of many
        pairs = "; ".join(f"axes {k + 1} and {k + 2} equal: any direction in their plane is principal" for k in equal)
        heading += "\n" + pairs
    # 3-D: in the view's empty top corner; 2-D: beside the axes (inside, it would cover the ellipse)
    where = {"loc": "upper left"} if n == 3 else {"loc": "upper left", "bbox_to_anchor": (1.02, 1.0)}
    ax.legend(fontsize="x-small", title=heading, title_fontsize="x-small", **where)
    if title:
        fig.suptitle(title)
    return fig


def modes_figure(
    points: Any, shapes: Sequence[Any], frequencies: Sequence[float], names: Sequence[str], *, title: str = ""
) -> Any:
    """Mode shapes as arrows: one panel per mode, an arrow at each point (N x 3,
    SI) along its displacement in that mode (N x 3, normalized to the largest)."""
    Figure = figure_class()
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
        ax.set_title(f"mode {k + 1}: {number(freq)} Hz", fontsize="small")
        ax.set_xlabel(axis_label(names[0], unit))
        ax.set_ylabel(axis_label(names[1], unit))
        ax.set_zlabel(axis_label(names[2], unit))
    if title:
        fig.suptitle(title)
    return fig


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
    Figure = figure_class()
    freqs = np.asarray(freqs, dtype=float)
    modes = np.asarray(modes, dtype=float)
    heights = [0.55 * len(rows) + 1.2 for _, rows in groups]  # inches: a row of bars and its written values each
    fig = Figure(figsize=(11, 4.2 + sum(heights)), layout="constrained")
    top, bottom = fig.subfigures(2, 1, height_ratios=[4.2, sum(heights)]) if groups else (fig, None)
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
    low = float(np.min(modes / np.abs(modes).max(axis=0), initial=0.0))
    a2.set_ylim(1.1 * low if low < 0 else 0.0, 1.45)  # room above the bars for the legend
    a2.legend(fontsize="x-small", loc="upper center", ncols=max(modes.shape[1], 1))
    a2.set_title("eigenvectors of K v = ω² M v", fontsize="small")
    if bottom is not None:
        axes = bottom.subplots(len(groups), 1, squeeze=False, height_ratios=heights)[:, 0]
        for ax, (label, rows) in zip(axes, groups):
            comparison_axes(ax, rows, reference_label=label)
    if title:
        fig.suptitle(title)
    return fig
