"""The ``workspace`` plot type: a point cloud with its cuboid, the boundary of
the workspace traced from the membership margin, a planar workspace in its plane.
"""

from __future__ import annotations

import math
from dataclasses import replace
from typing import Any

import numpy as np

from ..analysis.workspace import membership, probe_region, sample_workspace
from ..core.errors import InputError
from ..kinds.workspace import CuboidExtras
from .draw_workspace import BoundarySlice, slice_lines, workspace_figure_2d
from .draw_workspace import workspace_figure as workspace_figure_png
from .interactive import workspace_html
from .results import (
    NotApplicable,
    PlotOptions,
    ResultData,
    dimension_of,
    figure_title,
    pose_name,
    require_lists,
    result_closure,
    result_mechanism,
    result_model,
    value_list,
)
from .style import as_floats

# -- workspace ------------------------------------------------------------------------------------


def workspace_plot(data: ResultData, options: PlotOptions) -> Any:
    """A point cloud with its cuboid (see the module's naming conventions)."""
    workspace_figure = workspace_html if options.interactive else workspace_figure_png
    v = data.values
    title = figure_title(data)
    if data.problem == "actuator_workspace":
        closure = result_closure(data)
        if len(closure.task) == 2:  # its points are x, y
            return _planar_workspace_plot(data, options, closure)
        if isinstance(v.get("points"), list):  # task coordinates
            return _stroke_images_plot(data, closure, workspace_figure, title)
    if v.get("points") is not None:
        return _given_points_plot(data, workspace_figure, title)
    closure = result_closure(data)
    task = list(closure.task)
    if len(task) == 2:
        return _planar_workspace_plot(data, options, closure)
    if len(task) != 3:
        raise NotApplicable(f"a workspace cloud needs 2 or 3 task coordinates; {closure.name} has {len(task)}")
    return _task_workspace_plot(data, closure, workspace_figure, title)


def _stroke_images_plot(data: ResultData, closure: Any, workspace_figure: Any, title: str) -> Any:
    """An actuator workspace's images of the stroke grid, in the task coordinates, in its bounding box."""
    v = data.values
    task = list(closure.task)
    lo, hi = [v.get(f"{t}_min") for t in task], [v.get(f"{t}_max") for t in task]
    box = (lo, hi) if all(isinstance(b, (int, float)) for b in lo + hi) else None
    # no hull: the faces between the corners' images are curved (the grid's images lie outside
    # the corners' hull), and the images themselves show the shape
    return workspace_figure(
        np.asarray(v["points"], dtype=float),
        cuboid=box,
        names=task,
        dimensions=[closure.x[i].kind for i in closure.task_index],
        title=title,
        points_label="images of the stroke grid",
        cuboid_label="bounding box",
    )


def _given_points_plot(data: ResultData, workspace_figure: Any, title: str) -> Any:
    """A result's own ``points`` [x, y, z] with its ``cuboid_lower`` … ``cuboid_upper``."""
    v = data.values
    pts = np.asarray(v["points"], dtype=float)
    if pts.ndim != 2 or pts.shape[1] != 3:
        raise NotApplicable(f"'points' must be a list of [x, y, z], got shape {pts.shape}")
    lower, upper = v.get("cuboid_lower"), v.get("cuboid_upper")
    cuboid = (lower, upper) if lower is not None and upper is not None else None
    dim = dimension_of(data, "points") or "length"
    names = v.get("point_names") or ("x", "y", "z")
    return workspace_figure(pts, cuboid=cuboid, names=names, dimensions=(dim,) * 3, title=title)


def _task_box(v: Any, task: list[str]) -> tuple | None:
    """The box ``<t>_min`` … ``<t>_max`` of the task coordinates, where every bound is a number."""
    if all(isinstance(v.get(f"{t}_min"), (int, float)) and isinstance(v.get(f"{t}_max"), (int, float)) for t in task):
        return [v[f"{t}_min"] for t in task], [v[f"{t}_max"] for t in task]
    return None


def _task_workspace_plot(data: ResultData, closure: Any, workspace_figure: Any, title: str) -> Any:
    """Three task coordinates: the workspace kind's cloud (with the boundary where the model is
    at hand), an inscribed cuboid (with the workspace around it), else a batch of solved poses."""
    v = data.values
    task = list(closure.task)
    kinds = [closure.x[i].kind for i in closure.task_index]
    cuboid = _task_box(v, task)
    if data.problem == "inscribed_cuboid":
        box_label = "maximal inscribed cuboid"
    else:
        box_label = "bounding box (" + ", ".join(f"{t}_min … {t}_max" for t in task) + ")"
    hull = None
    if isinstance(v.get("vertices"), list) and v["vertices"] and len(v["vertices"][0]) == 3:  # actuator_workspace
        hull = np.asarray(v["vertices"], dtype=float)
        box_label = "bounding box"
    if all(value_list(data, f"cloud_{t}") is not None for t in task):  # the workspace kind
        pts = np.array([as_floats(v[f"cloud_{t}"]) for t in task]).T
        label = "reachable points (seeded sample)"
        if all(isinstance(v.get(f"{t}_range"), list) for t in task):
            model, rebuilt = _model_for_boundary(data, pts)
            if model is not None:
                return _cloud_with_boundary(data, model, rebuilt, pts, task, kinds, workspace_figure, title)
    elif cuboid is not None:  # inscribed_cuboid: the workspace around it from the model, if at hand
        return _cuboid_plot(data, cuboid, (task, kinds, box_label, hull), workspace_figure, title)
    else:  # a batch of poses, one sweep point per pose
        names = [pose_name(data, closure, t) for t in task]
        require_lists(data, names, "a workspace cloud")
        pts = np.array([as_floats(v[n]) for n in names]).T
        if data.ok is not None:
            pts = pts[data.ok]
        kinds = [dimension_of(data, n) or k for n, k in zip(names, kinds)]
        task, label = names, "solved poses"
    return workspace_figure(
        pts, cuboid=cuboid, names=task, dimensions=kinds, title=title, points_label=label, cuboid_label=box_label
    )


def _model_for_boundary(data: ResultData, pts: np.ndarray) -> tuple[Any, bool]:
    """(the model whose boundary to draw, whether it was rebuilt): the model solved when at hand,
    else one rebuilt from the parameters and joint limits the result records, used only if every
    point of the result's cloud is inside it (else None: no boundary rather than another one)."""
    if data.live is not None:
        return data.live, False
    try:
        model = result_model(data, with_limits=True)
    except InputError:
        return None, False
    inside = np.asarray(membership(model, pts[np.all(np.isfinite(pts), axis=1)]).inside, dtype=bool)
    return (model, True) if inside.all() else (None, False)


def _cloud_with_boundary(
    data: ResultData,
    model: Any,
    rebuilt: bool,
    pts: np.ndarray,
    task: list[str],
    kinds: list[str],
    workspace_figure: Any,
    title: str,
) -> Any:
    """The workspace kind's cloud with the boundary of ``model`` in the planes through the home
    pose (``rebuilt``: a model rebuilt from the result, which the legend says)."""
    v = data.values
    lo = np.array([v[f"{t}_range"][0] for t in task], dtype=float)
    hi = np.array([v[f"{t}_range"][1] for t in task], dtype=float)
    centre = np.clip(model.task_of(model.x_home), lo, hi)
    slices = _boundary_slices(model, lo, hi, centre)
    if model.closure.ik is not None:  # membership is cheap: each vertex bisected onto the boundary
        slices = [replace(sl, lines=_refined_boundary(model, sl, centre)) for sl in slices]
    label = "workspace boundary (slices through the home pose)"
    if rebuilt:
        label = "workspace boundary (of the model rebuilt from the result)"
    return workspace_figure(
        pts,
        names=task,
        dimensions=kinds,
        title=title,
        points_label="reachable points (seeded sample)",
        slices=slices,
        slices_label=label,
        colour_by_height=True,
    )


def _cuboid_plot(data: ResultData, cuboid: tuple, axes: tuple, workspace_figure: Any, title: str) -> Any:
    """A cuboid (and the paper's box), with the workspace around it where the model is at hand."""
    task, kinds, box_label, hull = axes
    if data.problem == "inscribed_cuboid":
        title = figure_title(data, "maximal inscribed cuboid")
    pts, label, slices = np.zeros((0, 3)), "", ()
    if data.live is not None and data.problem == "inscribed_cuboid":
        pts, slices = _workspace_around(data.live, cuboid)
        label = f"reachable points: {{n}} of {CLOUD_SAMPLE} drawn uniformly (seed 0) in a box around the cuboid"
    elif data.problem == "inscribed_cuboid":
        title += "\n(the cuboid alone: `cpm-nlp solve FILE --plot` draws the workspace around it)"
    return workspace_figure(
        pts,
        cuboid=cuboid,
        names=task,
        dimensions=kinds,
        title=title,
        points_label=label,
        cuboid_label=box_label,
        boxes=_paper_boxes(data),
        slices=slices,
        hull=hull,
    )


def _paper_boxes(data: ResultData) -> list[tuple]:
    """The box of the paper's own formulation, where the mechanism reads one from the result."""
    if not data.model.get("type") and data.origin is None:
        return []
    extras = result_mechanism(data).part(CuboidExtras)
    if extras is None or extras.paper_box is None:
        return []
    box = extras.paper_box(data.values)
    return [] if box is None else [box]


#: points of the cloud drawn around a cuboid, and grid lines per axis of each boundary slice
CLOUD_SAMPLE = 6000
SLICE_GRID = 61


def _workspace_around(model: Any, cuboid: tuple) -> tuple[np.ndarray, list[BoundarySlice]]:
    """The workspace around a cuboid: a region holding the cuboid and the region
    probed from its centre (twice the distance to the boundary along each axis),
    a quarter wider each way, so that the boundary shows on every side; in it a
    seeded cloud and the boundary in the three planes through the box centre."""
    lo, hi = (np.asarray(c, dtype=float) for c in cuboid)
    centre = (lo + hi) / 2
    probed = probe_region(model, centre=centre)
    if probed is None:
        probed = probe_region(model)
    if probed is not None:
        lo, hi = np.minimum(lo, probed[0]), np.maximum(hi, probed[1])
    margin = 0.25 * (hi - lo)
    lo, hi = lo - margin, hi + margin
    cloud = sample_workspace(model, CLOUD_SAMPLE, 0, (lo, hi))[0]
    slices = _boundary_slices(model, lo, hi, centre)
    if model.closure.ik is not None and model.closure.x[model.closure.task_index[-1]].kind == "angle":
        # a planar x, y, phi (the 3-RRR): cheap membership, each vertex bisected onto the boundary
        slices = [replace(sl, lines=_refined_boundary(model, sl, centre)) for sl in slices]
    return cloud, slices


def _boundary_slices(
    model: Any, lo: np.ndarray, hi: np.ndarray, centre: np.ndarray, grid: int = SLICE_GRID
) -> list[BoundarySlice]:
    """The workspace's boundary in the planes of two task axes through ``centre`` (one
    plane for two task coordinates, three for three): the membership margin on a grid
    of the box (lo, hi), positive inside; its zero level is the boundary (where a leg
    stops reaching, the branch changes or a joint limit binds), traced, not a hull."""
    n = len(lo)
    pairs = ((0, 1),) if n == 2 else ((0, 1), (0, 2), (1, 2))
    slices = []
    for i, j in pairs:
        gx, gy = np.linspace(lo[i], hi[i], grid), np.linspace(lo[j], hi[j], grid)
        X, Y = np.meshgrid(gx, gy)
        T = np.tile(np.asarray(centre, dtype=float), (X.size, 1))
        T[:, i], T[:, j] = X.ravel(), Y.ravel()
        member = membership(model, T)
        margin = np.where(np.isfinite(member.margin), member.margin, -np.inf)  # does not assemble: outside
        margin = np.where(member.inside, np.maximum(margin, 0.0), np.minimum(margin, -1e-300))
        at = float(centre[3 - i - j]) if n == 3 else 0.0
        slices.append(BoundarySlice((i, j), gx, gy, margin.reshape(X.shape), at))
    return slices


def _refined_boundary(model: Any, sl: BoundarySlice, centre: Any, iterations: int = 14) -> list[np.ndarray]:
    """The boundary of a slice (polylines, SI) with each vertex moved onto the true
    boundary: contour vertices lie on grid edges between an inside and an outside node
    (where the margin is -inf, i.e. the pose does not assemble, the contour would sit
    anywhere between them); bisection on membership along that edge places it to
    2^-iterations of the grid step."""
    i, j = sl.axes
    gx, gy = np.asarray(sl.x, dtype=float), np.asarray(sl.y, dtype=float)
    dy = float(np.diff(gy).min())

    def inside(uv: np.ndarray) -> np.ndarray:
        T = np.tile(np.asarray(centre, dtype=float), (len(uv), 1))
        T[:, i], T[:, j] = uv[:, 0], uv[:, 1]
        return np.asarray(membership(model, T).inside, dtype=bool)

    out = []
    for line in slice_lines(sl):
        P = np.asarray(line, dtype=float).copy()
        ky = np.abs(gy[None, :] - P[:, 1:2]).argmin(axis=1)
        horizontal = np.abs(gy[ky] - P[:, 1]) <= 1e-6 * dy
        kx = np.clip(np.searchsorted(gx, P[:, 0]) - 1, 0, len(gx) - 2)
        ky0 = np.clip(np.searchsorted(gy, P[:, 1]) - 1, 0, len(gy) - 2)
        a = np.where(horizontal[:, None], np.c_[gx[kx], P[:, 1]], np.c_[P[:, 0], gy[ky0]])
        b = np.where(horizontal[:, None], np.c_[gx[kx + 1], P[:, 1]], np.c_[P[:, 0], gy[ky0 + 1]])
        ina, inb = inside(a), inside(b)
        move = ina != inb
        lo = np.where(ina[:, None], a, b)[move]  # the inside end
        hi = np.where(ina[:, None], b, a)[move]
        for _ in range(iterations if move.any() else 0):
            mid = 0.5 * (lo + hi)
            m = inside(mid)
            lo = np.where(m[:, None], mid, lo)
            hi = np.where(m[:, None], hi, mid)
        P[move] = 0.5 * (lo + hi)
        out.append(P)
    return out


#: grid lines per axis of the boundary of a planar (two task coordinates) workspace
PLANAR_GRID = 121
#: what the boundary of a planar workspace is, under its legend
MEMBERSHIP_BOUNDARY = (
    "boundary: the zero level of the membership margin on a {g} x {g} grid, each vertex bisected onto "
    "the boundary (where a leg stops reaching, the branch changes or a joint limit binds): traced, not "
    "a hull, so a non-convex workspace keeps its holes and dents"
)
STROKE_BOUNDARY = (
    "boundary: the image of the stroke square's edges under the forward kinematics (the workspace's "
    "boundary where no singularity lies inside the strokes)"
)


def _stroke_edges(data: ResultData, closure: Any) -> list[np.ndarray]:
    """The image of the stroke square's edges (polylines, SI) of a 2-actuator
    actuator_workspace: its ``points`` grid (samples per actuator, first actuator
    slowest) walked round the edges, else FK along the edges of the live model's strokes."""
    v = data.values
    pts = np.asarray(v["points"], dtype=float) if isinstance(v.get("points"), list) else None
    if closure.nq != 2:
        return []
    if pts is not None and pts.ndim == 2 and pts.shape[1] == 2:
        n = math.isqrt(len(pts))
        if n >= 2 and n * n == len(pts):
            G = pts.reshape(n, n, 2)  # [i of q1, j of q2]
            loop = np.vstack([G[0, :], G[:, -1], G[-1, ::-1], G[::-1, 0]])
            return [loop]
    if data.live is None:
        return []
    from ..analysis.workspace import joint_box
    from ..core.batch import batch_forward_kinematics

    lo, hi = joint_box(data.live)
    s = np.linspace(0.0, 1.0, 41)
    walk = np.vstack(
        [
            np.c_[np.full_like(s, lo[0]), lo[1] + s * (hi[1] - lo[1])],
            np.c_[lo[0] + s * (hi[0] - lo[0]), np.full_like(s, hi[1])],
            np.c_[np.full_like(s, hi[0]), hi[1] - s * (hi[1] - lo[1])],
            np.c_[hi[0] - s * (hi[0] - lo[0]), np.full_like(s, lo[1])],
        ]
    )
    res = batch_forward_kinematics(data.live, walk)
    T = np.asarray(res.x, dtype=float)[:, closure.task_index]
    ok = np.asarray(res.ok, dtype=bool)
    return [T[ok]] if ok.sum() > 1 else []


def _planar_workspace_plot(data: ResultData, options: PlotOptions, closure: Any) -> Any:
    """A planar workspace (two task coordinates, e.g. the five-bar's x, y) in its plane:
    the points, the rectangle (inscribed_cuboid) or the bounding box (actuator_workspace),
    and the boundary: the zero level of the membership margin (workspace,
    inscribed_cuboid, with the model at hand) or the image of the stroke square's edges
    (actuator_workspace)."""
    if options.interactive:
        raise NotApplicable("a planar workspace is drawn as .png, .svg or .pdf (no interactive .html figure)")
    v = data.values
    task = list(closure.task)
    kinds = [closure.x[i].kind for i in closure.task_index]
    title = figure_title(data)
    cuboid = _task_box(v, task)
    common = {"names": task, "dimensions": kinds, "title": title}
    if data.problem == "actuator_workspace":
        return _planar_strokes_plot(data, closure, cuboid, common)
    if all(value_list(data, f"cloud_{t}") is not None for t in task):  # the workspace kind
        return _planar_cloud_plot(data, task, common)
    if cuboid is not None:  # inscribed_cuboid (or synthesis): the workspace around it, if the model is at hand
        return _planar_rectangle_plot(data, cuboid, common)
    names = [pose_name(data, closure, t) for t in task]  # a batch of poses
    require_lists(data, names, "a workspace plot")
    pts = np.array([as_floats(v[n]) for n in names]).T
    if data.ok is not None:
        pts = pts[data.ok]
    return workspace_figure_2d(pts, points_label="solved poses", **common)


def _planar_strokes_plot(data: ResultData, closure: Any, cuboid: tuple | None, common: dict) -> Any:
    """A planar actuator workspace: the images of the stroke grid, its bounding box, the
    image of the stroke square's edges (unless part of the box does not assemble)."""
    v = data.values
    pts = np.asarray(v["points"], dtype=float) if isinstance(v.get("points"), list) else np.zeros((0, 2))
    corners = np.asarray(v["vertices"], dtype=float) if isinstance(v.get("vertices"), list) else None
    partial = bool(v.get("n_not_assembled"))  # the stroke edges' image is not the boundary then
    edges = [] if partial else _stroke_edges(data, closure)
    note = STROKE_BOUNDARY if edges else "no boundary: give inputs.points: true or plot with solve --plot"
    if partial:
        note = "no boundary drawn: part of the stroke box does not assemble (images of the grid points that do)"
    return workspace_figure_2d(
        pts,
        cuboid=cuboid,
        cuboid_label="bounding box",
        points_label="images of the stroke grid",
        outline=edges,
        corners=corners,
        note=note,
        **common,
    )


#: the note of a planar cloud without its model at hand (no boundary is traced)
NO_MODEL_NOTE = "no boundary: plot with solve --plot (the model at hand)"


def _planar_cloud_plot(data: ResultData, task: list[str], common: dict) -> Any:
    """The workspace kind's cloud in its plane, with the boundary where the model is at hand."""
    v = data.values
    pts = np.array([as_floats(v[f"cloud_{t}"]) for t in task]).T
    outline: list[np.ndarray] = []
    slices: list[BoundarySlice] = []
    if data.live is not None and all(isinstance(v.get(f"{t}_range"), list) for t in task):
        lo = np.array([v[f"{t}_range"][0] for t in task], dtype=float)
        hi = np.array([v[f"{t}_range"][1] for t in task], dtype=float)
        slices = _boundary_slices(data.live, lo, hi, (lo + hi) / 2, PLANAR_GRID)
        outline = [line for sl in slices for line in _refined_boundary(data.live, sl, (lo + hi) / 2)]
    return workspace_figure_2d(
        pts,
        points_label="reachable points (seeded sample)",
        outline=outline,
        note=MEMBERSHIP_BOUNDARY.format(g=PLANAR_GRID) if slices else NO_MODEL_NOTE,
        **common,
    )


def _planar_rectangle_plot(data: ResultData, cuboid: tuple, common: dict) -> Any:
    """An inscribed rectangle, with the workspace around it where the model is at hand."""
    pts, outline, label = np.zeros((0, 2)), [], ""
    slices: list[BoundarySlice] = []
    if data.live is not None:
        lo, hi = (np.asarray(c, dtype=float) for c in cuboid)
        centre = (lo + hi) / 2
        for probed in (probe_region(data.live, centre=centre), probe_region(data.live)):
            if probed is not None:  # the box, the region probed from its centre and from home
                lo, hi = np.minimum(lo, probed[0]), np.maximum(hi, probed[1])
        pad = 0.1 * (hi - lo)
        lo, hi = lo - pad, hi + pad
        pts = sample_workspace(data.live, CLOUD_SAMPLE, 0, (lo, hi))[0]
        slices = _boundary_slices(data.live, lo, hi, centre, PLANAR_GRID)
        outline = [line for sl in slices for line in _refined_boundary(data.live, sl, centre)]
        label = f"reachable points: {{n}} of {CLOUD_SAMPLE} drawn uniformly (seed 0) in a box around the rectangle"
    else:
        common = {
            **common,
            "title": common["title"]
            + "\n(the rectangle alone: `cpm-nlp solve FILE --plot` draws the workspace around it)",
        }
    return workspace_figure_2d(
        pts,
        cuboid=cuboid,
        cuboid_label="maximal inscribed rectangle",
        points_label=label,
        outline=outline,
        note=MEMBERSHIP_BOUNDARY.format(g=PLANAR_GRID) if slices else "",
        **common,
    )
