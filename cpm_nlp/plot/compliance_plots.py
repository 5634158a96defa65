"""The ``forces``, ``ellipsoid``, ``modes`` and ``dynamics`` plot types: actuator
forces and hinge stresses along a motion, the compliance ellipsoid of the
platform, mode shapes on the mechanism, natural frequencies.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ..core.canonical import canonical_eigh, degenerate_note, eigen_clusters
from .comparison_plots import comparisons
from .draw_compliance import dynamics_figure, ellipsoid_figure, modes_figure
from .draw_mechanism import Arrow, modes_mechanism_figure
from .draw_panels import Panel, panels_figure
from .pose import geometry_of, mechanism_title, model_for, single_pose
from .results import NotApplicable, PlotOptions, ResultData, dimension_of, pose_name, require_lists, result_closure
from .style import as_floats, display_unit, number

# -- dynamics ---------------------------------------------------------------------------------------------


def dynamics_plot(data: ResultData, _options: PlotOptions) -> Any:
    """Natural frequencies and mode shapes: the generalized eigenproblem K v = ω² M v
    of the result's M and K (in the actuator coordinates), beside the paper's
    printed values where the result has them."""
    M, K = data.values.get("M"), data.values.get("K")
    if not (isinstance(M, list) and isinstance(K, list)):
        raise NotApplicable("a dynamics plot needs the mass and stiffness matrices M and K")
    # the canonical modes (core.canonical): the same bars on every BLAS kernel; the result's own
    # modes_q where it has them (read in the pose coordinates, which M and K alone do not give)
    w2, modes, clusters = canonical_eigh(np.asarray(K, dtype=float), np.asarray(M, dtype=float))
    given = data.values.get("modes_q")
    if isinstance(given, list) and np.shape(given) == modes.T.shape:
        modes = np.asarray(given, dtype=float).T
    freqs = np.sqrt(np.clip(w2, 0, None)) / (2 * math.pi)
    closure = result_closure(data)
    groups = comparisons(data)
    title = _with_degenerate_note(f"Dynamics ({data.model.get('type')})", clusters, len(freqs))
    return dynamics_figure(freqs, modes, closure.q_names, groups, title=title)


def _with_degenerate_note(title: str, clusters: list[list[int]], shown: int) -> str:
    """``title`` with a line per repeated frequency among the first ``shown`` modes,
    e.g. "f2 = f3: any combination of modes 2 and 3 is a mode"."""
    notes = [degenerate_note(idx) for idx in clusters if len(idx) > 1 and idx[0] < shown]
    return "\n".join([title, *notes])


def _mode_clusters(data: ResultData) -> list[list[int]]:
    """The repeated frequencies of a natural_frequencies result (also of one written
    before results carried ``multiplicity``): clusters of equal f^2 (core.canonical)."""
    freqs, k = [], 1
    while isinstance(data.values.get(f"f{k}"), (int, float)):
        freqs.append(float(data.values[f"f{k}"]))
        k += 1
    return eigen_clusters(np.square(freqs)) if freqs else []


def forces_plot(data: ResultData, _options: PlotOptions) -> Any:
    """Actuator forces and hinge stresses along a motion (actuator_forces over a
    list of inputs; prs3-ruiz.md Table 2 extended to a curve), against the input
    that varies most."""
    if data.sweep:
        raise NotApplicable("'forces' plots one actuator_forces result; for a sweep use 'lines'")
    c = result_closure(data)
    inputs = c.q_names + [pose_name(data, c, t) for t in c.task]
    forces = [f"F{j + 1}" for j in range(c.nq)]
    stresses = sorted(k for k in data.values if k.startswith("stress_") and not k.endswith("_loaded"))
    require_lists(data, forces + inputs, "a forces plot (give the motion as lists)")
    cols = {n: as_floats(data.values[n]) for n in inputs}
    spread = {n: np.nanmax(v) - np.nanmin(v) if np.isfinite(v).any() else 0.0 for n, v in cols.items()}
    x = max(inputs, key=lambda n: spread[n])
    if spread[x] <= 0:
        raise NotApplicable("no input varies over the motion")
    order = np.argsort(cols[x])
    panels = [Panel("actuator force", "force", {f: [data.values[f][i] for i in order] for f in forces})]
    if stresses and isinstance(data.values[stresses[0]], list):
        panels.append(Panel("hinge stress", "stress", {s: [data.values[s][i] for i in order] for s in stresses}))
    return panels_figure(
        cols[x][order],
        panels,
        xname=x,
        xdimension=dimension_of(data, x),
        title=f"Actuator forces and hinge stresses ({data.model.get('type')})",
        ncols=len(panels),
    )


def _translational(c: Any) -> list[int]:
    return [i for i, x in enumerate(c.x) if x.kind == "length"][:3]


def ellipsoid_plot(data: ResultData, _options: PlotOptions) -> Any:
    """The compliance ellipsoid of the platform: the translational block of C."""
    if data.sweep or not isinstance(data.values.get("C"), list):
        raise NotApplicable("'ellipsoid' plots the output compliance C of one platform_compliance result")
    c = result_closure(data)
    idx = _translational(c)
    if len(idx) < 2:
        raise NotApplicable("the platform has fewer than two translational coordinates")
    C = np.asarray(data.values["C"], dtype=float)[np.ix_(idx, idx)]
    drawn = drawn_pose(data)
    drawing, centre, note = None, None, ""
    if drawn is not None:
        model, geometry, x, q = drawn
        drawing = geometry(model, x, q)
        centre, note = _platform_centre(drawing, c, x), drawing.note
    return ellipsoid_figure(
        C,
        [c.x_names[i] for i in idx],
        title=f"Compliance ellipsoid of the platform ({data.model.get('type')})",
        drawing=drawing,
        centre=centre,
        note=note,
    )


def drawn_pose(data: ResultData) -> tuple | None:
    """(model, geometry, x, q) of a one-pose result whose mechanism has a drawing, else None."""
    try:
        model = model_for(data)
        geometry = geometry_of(model)
        x, q = single_pose(data, model)
    except NotApplicable:
        return None
    return model, geometry, x, q


def _platform_centre(drawing: Any, c: Any, x: np.ndarray) -> np.ndarray:
    """The platform centre: the drawing's point P, else the translational pose coordinates."""
    if "P" in drawing.points:
        return np.asarray(drawing.points["P"], dtype=float).ravel()[:3]
    out = np.zeros(3)
    idx = _translational(c)
    out[: len(idx)] = x[idx]
    return out


#: the mode shapes drawn on the mechanism: the largest point displacement of a mode, as a fraction of its size
MODE_ARROW = 0.25


def mode_arrows(model: Any, geometry: Any, x: np.ndarray, q: np.ndarray, mx: Any, mq: Any) -> list[Arrow]:
    """Arrows at the drawing's points along their displacements in one mode (central
    difference of the drawing between the pose -/+ eps times the mode), scaled to be seen."""
    mx, mq = np.asarray(mx, dtype=float), np.asarray(mq, dtype=float)
    at = geometry(model, x, q)
    names = list(at.points)
    P = np.array([np.asarray(at.points[n], dtype=float).ravel()[:3] for n in names])
    span = float(np.ptp(P, axis=0).max()) or 1.0
    size = max(float(np.abs(mx).max(initial=0.0)), float(np.abs(mq).max(initial=0.0))) or 1.0
    eps = 1e-6 / size
    plus, minus = geometry(model, x + eps * mx, q + eps * mq), geometry(model, x - eps * mx, q - eps * mq)
    D = np.array(
        [np.asarray(plus.points[n], dtype=float)[:3] - np.asarray(minus.points[n], dtype=float)[:3] for n in names]
    ) / (2 * eps)
    peak = float(np.linalg.norm(D, axis=1).max())
    if peak == 0.0:
        return []
    D *= MODE_ARROW * span / peak
    factor, unit = display_unit("length", P)
    label = (
        f"point displacement in the mode, scaled: the largest drawn {number(MODE_ARROW * span * factor)} {unit} "
        f"long ({MODE_ARROW:.0%} of the mechanism's size; a mode shape has no amplitude of its own)"
    )
    arrows: list[Arrow] = []
    seen: list[np.ndarray] = []
    for p, d in zip(P, D):
        if np.linalg.norm(d) < 1e-3 * MODE_ARROW * span or any(np.linalg.norm(p - o) < 1e-9 * span for o in seen):
            continue
        seen.append(p)
        arrows.append(Arrow(p, d, "" if arrows else label, "tab:red"))
    return arrows


def modes_plot(data: ResultData, _options: PlotOptions) -> Any:
    """Mode shapes as arrows, one panel per mode (up to three): on the mechanism's
    drawing where it has one (an arrow at each point along its displacement in the
    mode), else at the platform point (the translational pose coordinates) and at
    each actuator."""
    if data.sweep or not isinstance(data.values.get("modes_x"), list):
        raise NotApplicable("'modes' plots the mode shapes of one natural_frequencies result")
    c = result_closure(data)
    drawn = drawn_pose(data)
    if drawn is not None:
        model, geometry, x, q = drawn
        modes = list(zip(data.values["modes_x"], data.values["modes_q"]))[:3]
        arrows = [mode_arrows(model, geometry, x, q, mx, mq) for mx, mq in modes]
        freqs = [data.values[f"f{k + 1}"] for k in range(len(modes))]
        pose = geometry(model, x, q)
        title = _with_degenerate_note(f"Mode shapes: {mechanism_title(model)}", _mode_clusters(data), len(modes))
        return modes_mechanism_figure(pose, arrows, freqs, title=title, note=pose.note)
    idx = _translational(c)
    platform = np.zeros(3)
    platform[: len(idx)] = [data.values[c.x_names[i]] for i in idx]
    pts = [platform]
    for j in range(c.nq):  # the actuators, spread on a circle around the platform for display
        a = 2 * np.pi * j / max(c.nq, 1)
        r = max(float(np.abs(platform).max()), 1e-3)
        pts.append(platform + r * np.array([np.cos(a), np.sin(a), -1.0]))
    shapes = []
    for mq, mx in zip(data.values["modes_q"], data.values["modes_x"]):
        d = np.zeros((1 + c.nq, 3))
        d[0, : len(idx)] = [mx[i] for i in idx]
        for j in range(c.nq):
            d[1 + j, 2] = mq[j]
        shapes.append(d)
    freqs = [data.values[f"f{k + 1}"] for k in range(len(shapes))]
    names = [c.x_names[i] for i in idx] + ["z"] * (3 - len(idx))
    title = _with_degenerate_note(f"Mode shapes ({data.model.get('type')})", _mode_clusters(data), len(shapes))
    return modes_figure(np.array(pts), shapes, freqs, names, title=title)
