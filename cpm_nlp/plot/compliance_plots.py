"""The ``forces``, ``ellipsoid``, ``modes`` and ``dynamics`` plot types: actuator
forces and hinge stresses along a motion, the compliance ellipsoid of the
platform, mode shapes on the mechanism, natural frequencies.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..core.canonical import canonical_eigh, degenerate_note, eigen_clusters
from .comparison_plots import comparisons
from .draw_compliance import dynamics_figure, ellipsoid_figure, modes_figure
from .draw_forces import ForcePanel, Quantity, forces_figure, published_by_value, readable_group
from .draw_mechanism import Arrow, modes_mechanism_figure
from .pose import geometry_of, model_for, single_pose
from .results import (
    NotApplicable,
    PlotOptions,
    ResultData,
    dimension_of,
    mechanism_title,
    pose_name,
    require_lists,
    result_closure,
)
from .style import as_floats, display_unit, number, pretty

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
    title = _with_degenerate_note(f"Natural frequencies: {mechanism_title(data)}", clusters, len(freqs))
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
    """Actuator forces and hinge stresses along a motion (prs3-ruiz.md Table 2 extended
    to a curve), against the input that varies most: the result's points for a batch;
    for one pose, the motion from home through it (solved again along it, out past the
    pose where the first hinge reaches the allowable stress). With the allowable
    stress, that pose, and the published points of the problem's ``reproduce`` rows."""
    if data.sweep:
        raise NotApplicable("'forces' plots one actuator_forces result; for a sweep use 'lines'")
    c = result_closure(data)
    inputs = c.q_names + [pose_name(data, c, t) for t in c.task]
    forces = [f"F{j + 1}" for j in range(c.nq)]
    single = all(isinstance(data.values.get(n), (int, float)) for n in forces + inputs)
    if not single:
        require_lists(data, forces + inputs, "a forces plot (give the motion as lists, or one pose)")
    ray = _ray(data)
    if ray is not None:
        values, motion = _along(data, ray)
    elif single:
        raise NotApplicable(
            "a forces plot of one pose draws the motion from home through it, which needs the problem "
            "('cpm-nlp solve FILE --plot'); or give the motion as lists"
        )
    else:
        values, motion = data.values, f"at the {len(data.values[forces[0]])} solved points"
    cols = {n: as_floats(values[n]) for n in inputs}
    spread = {n: np.nanmax(v) - np.nanmin(v) if np.isfinite(v).any() else 0.0 for n, v in cols.items()}
    x = max(inputs, key=lambda n: spread[n])
    if spread[x] <= 0:
        raise NotApplicable("no input varies over the motion")
    same = [n for n in inputs if np.allclose(cols[n], cols[x], equal_nan=True) and dimension_of(data, n)]
    order = np.argsort(cols[x])
    at = {None: float(data.values[x])} if single else dict(enumerate(as_floats(data.values[x]).tolist()))
    published = published_by_value(data.published, at)
    panels = [_force_panel(values, forces, order, published), _stress_panel(data, values, order, published, x)]
    words = "actuator displacement" if x in c.q_names else "platform motion"
    return forces_figure(
        cols[x][order],
        f"{words} {' = '.join(pretty(n) for n in same)}",
        dimension_of(data, x),
        [p for p in panels if p is not None],
        title=f"Actuator forces and hinge stresses: {mechanism_title(data)}",
        subtitle=motion,
    )


#: samples of the motion from home through the solved poses, for the forces plot
MOTION_SAMPLES = 33


@dataclass
class _Ray:
    """The motion from home through the solved poses, when they lie on one ray: the
    inputs that give it (actuators, else task coordinates), their home values, the
    last pose's, and each pose's scale along the ray (1 at the last)."""

    keys: list[str]
    home: np.ndarray
    end: np.ndarray
    scales: np.ndarray


def _ray(data: ResultData) -> _Ray | None:
    """The ray from home through the problem's poses; None without the problem at hand,
    or when its poses do not lie on one ray from home."""
    problem = data.solved_problem
    if problem is None:
        return None
    model, inputs = problem.model, problem.inputs
    c = model.closure
    homes = {n: float(model.q_home[j]) for j, n in enumerate(c.q_names)}
    keys = [n for n in c.q_names if inputs.get(n) is not None]
    if not keys:
        homes = {c.x[i].name: float(model.x_home[i]) for i in c.task_index} | dict.fromkeys(c.offsets, 0.0)
        keys = [n for n in homes if inputs.get(n) is not None]
    if not keys:
        return None
    n = max((len(inputs[k]) for k in keys if isinstance(inputs[k], list)), default=1)
    pts = np.array([[float(v) for v in inputs[k]] if isinstance(inputs[k], list) else [inputs[k]] * n for k in keys]).T
    home = np.array([homes[k] for k in keys])
    d = pts[-1] - home
    if not np.linalg.norm(d) > 0:
        return None
    scales = (pts - home) @ d / (d @ d)
    if np.linalg.norm(pts - home - np.outer(scales, d)) > 1e-9 * np.linalg.norm(d) * n:
        return None
    return _Ray(keys, home, pts[-1], scales)


def _along(data: ResultData, ray: _Ray) -> tuple[dict[str, Any], str]:
    """The result's problem solved along its ray from home, out to 1.15 times the
    farthest of its poses and the pose where the first hinge reaches the allowable
    stress, the solved poses among the samples: the values as lists, and a line saying so."""
    problem = data.solved_problem
    scale = data.values.get("scale_at_allowable")
    top = 1.15 * max(1.0, float(ray.scales.max()), float(scale) if isinstance(scale, (int, float)) else 0.0)
    bottom = 1.15 * min(0.0, float(ray.scales.min()))  # poses on both sides of home: the curve through both
    lams = np.unique(np.r_[np.linspace(bottom, top, MOTION_SAMPLES), 0.0, ray.scales])
    inputs = dict(problem.inputs)
    for k, h, e in zip(ray.keys, ray.home, ray.end):
        inputs[k] = [float(h + lam * (e - h)) for lam in lams]
    inputs["stress_limit"] = False
    result = problem.kind.run(problem.model, inputs, problem.solver)
    through = "the solved pose" if len(ray.scales) == 1 else f"the {len(ray.scales)} solved poses"
    return dict(result.values), f"along the motion from home through {through} ({_end_text(data, ray)})"


def _end_text(data: ResultData, ray: _Ray) -> str:
    """The last pose's inputs, equal ones together: "s1 = s2 = s3 = 2.865 mm"."""
    parts: list[tuple[list[str], float]] = []
    for k, v in zip(ray.keys, ray.end):
        for names, value in parts:
            if value == v:
                names.append(k)
                break
        else:
            parts.append(([k], float(v)))
    out = []
    for names, v in parts:
        f, unit = display_unit(dimension_of(data, names[0]), [v])
        out.append(" = ".join(pretty(k) for k in names) + f" = {v * f:.4g} {unit}".rstrip())
    return ", ".join(out)


def _force_panel(values: dict, forces: list[str], order: np.ndarray, published: dict) -> ForcePanel:
    curves = [Quantity(pretty(f), as_floats(values[f])[order]) for f in forces]
    points = [
        (x, y, f"{text}: {' = '.join(pretty(f) for f in forces if f in published)}")
        for f in forces
        for x, y, text in published.get(f, ())
    ]
    return ForcePanel("actuator force", "force", curves, points=points)


def _stress_panel(data: ResultData, values: dict, order: np.ndarray, published: dict, x: str) -> ForcePanel | None:
    """Each hinge group's largest nominal stress (the largest of all, stress_max, is their upper
    envelope: drawn only without groups), the largest peak stress (K_t times the nominal one,
    where the result gives it), the allowable stress and where it is reached."""
    groups = sorted(
        k
        for k in values
        if k.startswith("stress_") and k != "stress_max" and not k.startswith("stress_peak_") and "_loaded" not in k
    )
    groups = [g for g in groups if isinstance(values[g], list)]
    if not groups and not isinstance(values.get("stress_max"), list):
        return None
    curves = [Quantity(readable_group(g.removeprefix("stress_")), as_floats(values[g])[order]) for g in groups]
    if not curves:
        curves = [Quantity("largest hinge stress", as_floats(values["stress_max"])[order])]
    if isinstance(values.get("stress_peak_max"), list):  # the notch's stress concentration
        curves.append(Quantity("largest peak stress ($K_t$ × nominal)", as_floats(values["stress_peak_max"])[order]))
    points = [(px, py, f"{text}: largest joint stress") for px, py, text in published.get("stress_max", ())]
    for g in groups:
        name = readable_group(g.removeprefix("stress_"))
        points += [(px, py, f"{text}: {name}") for px, py, text in published.get(g, ())]
    lines, marks = [], []
    sigma = _allowable(data)
    if sigma is not None:
        lines.append((sigma, f"allowable stress {_stress_text(sigma)}"))
        reached = data.values.get(f"{x}_at_allowable")
        if isinstance(reached, (int, float)):
            f, unit = display_unit(dimension_of(data, x), [reached])
            text = f"first hinge at the allowable: {pretty(x)} = {reached * f:.4g} {unit}"
            marks.append((float(reached), sigma, text))
    return ForcePanel("hinge stress", "stress", curves, points=points, lines=lines, marks=marks)


def _stress_text(sigma: float) -> str:
    f, unit = display_unit("stress", [sigma])
    return f"{sigma * f:.4g} {unit}"


def _allowable(data: ResultData) -> float | None:
    """The allowable stress: the result's (a stress limit was asked), else the one the
    problem's hinges give (their material's), else None."""
    sigma = data.values.get("sigma_allow")
    if isinstance(sigma, (int, float)):
        return float(sigma)
    problem = data.solved_problem
    if problem is None or "hinge_set" not in problem.inputs:
        return None
    from ..analysis.compliance import allowable
    from ..core.errors import InputError

    try:
        return allowable(
            problem.inputs["hinge_set"], problem.inputs.get("sigma_allow"), problem.inputs.get("safety_factor", 1.0), ()
        )
    except InputError:  # no material: no allowable stress to draw
        return None


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
        title=f"Compliance ellipsoid of the platform: {mechanism_title(data)}",
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
        title = _with_degenerate_note(f"Mode shapes: {mechanism_title(data)}", _mode_clusters(data), len(modes))
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
