"""Which figure a result makes, and the data it takes from it.

A result is the JSON of ``cpm-nlp solve -o`` (or a :class:`~cpm_nlp.core.result.Result`)
or a sweep results file; :func:`load` reads either into :class:`ResultData`.
The figure is chosen from the result's problem kind (its ``plots``, see
:class:`~cpm_nlp.core.kind.ProblemKind`: the first plot type that applies to
the values wins) or named (``--type``).

Extending: a plot type is one entry in :data:`PLOTS` (name -> function),
the function taking ``(data, options)`` and returning a Matplotlib figure
made by :mod:`cpm_nlp.plot.draw` from arrays, or raising
:class:`NotApplicable`; a problem kind lists its plot types in its
``plots`` attribute.  A kind needs no plotting code of its own when its values
use the names read here (SI values, units in the result):

* ``workspace`` -- a point cloud: ``cloud_<t>`` for each task coordinate t
  (the ``workspace`` kind), or ``points`` (N x 3); a cuboid: ``<t>_min`` and
  ``<t>_max`` (the ``inscribed_cuboid`` kind), or ``cuboid_lower`` and
  ``cuboid_upper``; a batch of poses (FK, IK) gives its task coordinates.  A
  cuboid without a cloud (``inscribed_cuboid``) is drawn in a cloud sampled
  from the model when the model is at hand (``cpm-nlp solve FILE --plot``);
* ``map`` -- the kind's ``map_axes`` name (x, y, value): x and y: x and y
  lists and the value either a list of the same length or a matrix
  (rows y, columns x; ``null`` outside the design space); optional
  ``in_region`` (same shape: outlined), ``<x>_best``/``<y>_best`` and
  ``<x>_design``/``<y>_design`` (marked), ``domain`` (vertices, outlined).
  A sweep maps a value over its two swept parameters.
"""

from __future__ import annotations

import json
import math
import os
import re
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from ..analysis.workspace import membership, probe_region, sample_workspace
from ..core.canonical import canonical_eigh, degenerate_note, eigen_clusters
from ..core.errors import InputError, suggest
from ..core.kinematics import jacobians, passive_joints
from ..core.result import ResultWarning
from ..core.units import DIMENSIONS
from ..io.inputs import MAX_RESULTS_BYTES, read_input_text
from ..io.results import FORMATS, read_results
from ..mechanisms.registry import build_model, closure_of, mechanism_type
from ..problems.registry import kind_names, problem_kind
from .draw import (
    Arrow,
    BoundarySlice,
    Comparison,
    Panel,
    _slice_lines,
    as_floats,
    comparison_figure,
    design_map_figure,
    display_unit,
    dynamics_figure,
    ellipsoid_figure,
    jacobian_figure,
    matrices_figure,
    mechanism_figure,
    modes_figure,
    modes_mechanism_figure,
    panels_figure,
    pretty,
    workspace_figure_2d,
)
from .draw import workspace_figure as workspace_figure_png
from .interactive import mechanism_html, workspace_html

SWEEP = "sweep"  # the "kind" of a sweep results file in DEFAULTS

#: plot types that may draw a sweep results file, the default first
SWEEP_PLOTS = ("map", "lines", "workspace")

#: sweep statuses of points outside the design space (drawn apart from points that did not solve)
OUTSIDE = ("infeasible", "invalid_input")

_BY_SI = {d.si: name for name, d in DIMENSIONS.items() if name != "dimensionless"}


class NotApplicable(InputError):
    """This plot type does not fit the result (the message says why)."""


class NothingSolved(InputError):
    """The result has no solved point: there is nothing to draw."""


@dataclass
class PlotOptions:
    """value: the quantity of a map or curves; x, y: the map's axes (names of
    swept keys or values); best: mark the "max" or "min" of a map."""

    value: str | None = None
    x: str | None = None
    y: str | None = None
    best: str | None = None
    #: an interactive Plotly figure (``.html``) of the 3-D view, not a Matplotlib one
    interactive: bool = False


@dataclass
class ResultData:
    """A result to plot.

    problem: the problem kind; sweep: True for a sweep results file, whose
    ``values`` are its columns (lists, one entry per point) and ``parameters``
    its swept keys; dimensions: of every value ("length", "angle" ...).
    """

    source: str
    problem: str
    values: dict[str, Any]
    dimensions: dict[str, str]
    statuses: list[str] | None = None
    model: dict[str, Any] = field(default_factory=dict)
    sweep: bool = False
    status: str = "solved"  # of the whole result
    live: Any = None  # the Model solved, when at hand (solve --plot): lets a plot sample its workspace
    parameters: list[dict[str, Any]] = field(default_factory=list)
    recorded: list[str] = field(default_factory=list)  # value columns of a sweep
    units: dict[str, str] = field(
        default_factory=dict
    )  # as the result writes them (matrices: what rows and columns are)
    #: published figures to draw beside the values: (value expression "dz[2]", published SI, label)
    published: list[tuple[str, float, str]] = field(default_factory=list)
    #: the result's warnings (:class:`~cpm_nlp.core.result.ResultWarning`), read back from its JSON
    warnings: list[Any] = field(default_factory=list)

    @property
    def kind(self) -> str:
        return "sweep" if self.sweep else self.problem

    @property
    def ok(self) -> np.ndarray | None:
        return None if self.statuses is None else np.array([s == "solved" for s in self.statuses])


def _dimension_of_unit(unit: Any) -> str | None:
    if unit == "":
        return "dimensionless"
    return _BY_SI.get(unit) if isinstance(unit, str) else None


def from_result(result: Any, source: str = "") -> ResultData:
    """A :class:`~cpm_nlp.core.result.Result` or its JSON dict."""
    d = result if isinstance(result, Mapping) or not hasattr(result, "to_dict") else result.to_dict()
    if not isinstance(d, Mapping) or not isinstance(d.get("values"), Mapping) or not isinstance(d.get("problem"), str):
        raise InputError("expected a cpm-nlp result (JSON with problem, status, values, units)", file=source or None)
    dims = {k: dim for k, u in (d.get("units") or {}).items() if (dim := _dimension_of_unit(u))}
    return ResultData(
        source,
        d["problem"],
        dict(d["values"]),
        dims,
        d.get("statuses"),
        dict(d.get("model") or {}),
        status=str(d.get("status")),
        units={k: str(u) for k, u in (d.get("units") or {}).items()},
        warnings=[ResultWarning.from_dict(w) for w in d.get("warnings") or [] if isinstance(d.get("warnings"), list)],
    )


def from_table(table: Any) -> ResultData:
    """A sweep results file read by :func:`cpm_nlp.io.results.read_results`."""
    meta = table.meta
    names = ["point", *(p["key"] for p in table.parameters), "status", "message", "seconds", "warnings"]
    names += table.values
    values = {n: table.column(n) for n in names}
    dims = {p["key"]: p["dimension"] for p in table.parameters if p.get("dimension")}
    dims.update(meta.get("dimensions") or {})
    for n, u in (meta.get("units") or {}).items():
        if n not in dims and (dim := _dimension_of_unit(u)):
            dims[n] = dim
    model = {"type": meta.get("mechanism")}
    return ResultData(
        table.path,
        str(meta.get("problem")),
        values,
        dims,
        statuses=[str(s) for s in table.column("status")],
        model=model,
        sweep=True,
        parameters=table.parameters,
        recorded=table.values,
    )


def load(path: str | os.PathLike) -> ResultData:
    """Read a JSON result (``cpm-nlp solve -o``) or a sweep results file."""
    p = Path(path)
    if p.suffix.lower() in FORMATS:
        return from_table(read_results(p))
    text = read_input_text(p, MAX_RESULTS_BYTES)
    try:
        data = json.loads(text)
    except ValueError:
        raise InputError(
            "expected a JSON result written by 'cpm-nlp solve -o' or a sweep results file (.parquet, .csv)",
            file=str(path),
        ) from None
    return from_result(data, str(path))


def figure(
    data: ResultData, plot_type: str | None = None, options: PlotOptions | None = None, interactive: bool = False
) -> tuple[Any, str]:
    """The figure of a result: ``(figure, plot type)``; ``interactive``: a Plotly
    figure (for ``.html``) of a 3-D plot type (:data:`INTERACTIVE`).  Raises
    :class:`NothingSolved` for a result without a solved point."""
    options = replace(
        options or PlotOptions(), interactive=interactive or (options is not None and options.interactive)
    )
    ok = data.ok
    if (ok is not None and not ok.any()) or (ok is None and data.status != "solved"):
        raise NothingSolved(f"no point of {data.source or 'the result'} is solved; there is nothing to plot")
    if plot_type is not None:
        check_plot_type(plot_type)
        return _plot_function(plot_type)(data, options), plot_type
    candidates = SWEEP_PLOTS if data.sweep else _kind_plots(data.problem)
    if not candidates:
        known = [n for n in kind_names() if problem_kind(n).plots]
        raise NotApplicable(f"no plot is known for a {data.kind} result; known: {', '.join(known + ['sweep'])}")
    reasons = []
    for name in candidates:
        try:
            return _plot_function(name)(data, options), name
        except NotApplicable as exc:
            reasons.append(f"{name}: {exc.message}")
    raise NotApplicable("no plot fits this result (" + "; ".join(reasons) + ")")


def check_plot_type(plot_type: str | None) -> None:
    """An :class:`InputError` (``--type``, with "did you mean") unless ``plot_type``
    is None or a plot type of :data:`PLOTS` (checked before anything is solved)."""
    if plot_type is not None and plot_type not in PLOTS:
        raise InputError(
            f"unknown plot type {plot_type!r}; expected one of: {', '.join(sorted(PLOTS))}",
            path=("--type",),
            suggestions=suggest(plot_type, PLOTS),
        )


def _plot_function(name: str) -> Any:
    return PLOTS[name]


def _flat_only(options: PlotOptions, name: str) -> None:
    if options.interactive:
        raise NotApplicable(
            f"an interactive (.html) figure is drawn for the 3-D plots ({', '.join(INTERACTIVE)}); "
            f"'{name}' is drawn to .png, .svg or .pdf"
        )


def _kind_plots(name: str) -> tuple[str, ...]:
    """The plot types of a problem kind (none for a kind unknown here)."""
    return problem_kind(name).plots if name in kind_names() else ()


def _map_axes(name: str) -> tuple[str | None, str | None, str | None]:
    axes = problem_kind(name).map_axes if name in kind_names() else None
    return axes or (None, None, None)


# -- helpers ------------------------------------------------------------------------------------


def _closure(data: ResultData) -> Any:
    """The symbolic mechanism of the result (names of its coordinates)."""
    name = data.model.get("type")
    if not name:
        raise NotApplicable("the result does not name its mechanism (model.type)")
    return closure_of(mechanism_type(name, path=("model", "type")))


def _list(data: ResultData, name: str) -> list | None:
    v = data.values.get(name)
    return v if isinstance(v, list) else None


def _pose_name(data: ResultData, closure: Any, coord: str) -> str:
    """A coordinate, by its offset from home where the result has it (dz for pz)."""
    for off, target in closure.offsets.items():
        if target == coord and off in data.values:
            return off
    return coord


def _require_lists(data: ResultData, names: list[str], what: str) -> None:
    missing = [n for n in names if _list(data, n) is None]
    if missing:
        raise NotApplicable(
            f"{what} needs per-point lists of {', '.join(missing)} (solve a batch, without an outputs selection)"
        )


def _dims(data: ResultData, name: str) -> str | None:
    return data.dimensions.get(name)


# -- workspace ------------------------------------------------------------------------------------


def workspace_plot(data: ResultData, options: PlotOptions) -> Any:  # noqa: C901 - one branch per source of points
    """A point cloud with its cuboid (see the module's naming conventions)."""
    workspace_figure = workspace_html if options.interactive else workspace_figure_png
    v = data.values
    title = f"Workspace ({data.model.get('type') or data.problem}, {data.problem})"
    if data.problem == "actuator_workspace" and len(_closure(data).task) == 2:  # its points are x, y
        return _planar_workspace_plot(data, options, _closure(data))
    if data.problem == "actuator_workspace" and isinstance(v.get("points"), list):  # task coordinates
        closure = _closure(data)
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
    if v.get("points") is not None:
        pts = np.asarray(v["points"], dtype=float)
        if pts.ndim != 2 or pts.shape[1] != 3:
            raise NotApplicable(f"'points' must be a list of [x, y, z], got shape {pts.shape}")
        lower, upper = v.get("cuboid_lower"), v.get("cuboid_upper")
        cuboid = (lower, upper) if lower is not None and upper is not None else None
        dim = _dims(data, "points") or "length"
        names = v.get("point_names") or ("x", "y", "z")
        return workspace_figure(pts, cuboid=cuboid, names=names, dimensions=(dim,) * 3, title=title)
    closure = _closure(data)
    task = list(closure.task)
    if len(task) == 2:
        return _planar_workspace_plot(data, options, closure)
    if len(task) != 3:
        raise NotApplicable(f"a workspace cloud needs 2 or 3 task coordinates; {closure.name} has {len(task)}")
    kinds = [closure.x[i].kind for i in closure.task_index]
    cuboid = None
    if all(isinstance(v.get(f"{t}_min"), (int, float)) and isinstance(v.get(f"{t}_max"), (int, float)) for t in task):
        cuboid = ([v[f"{t}_min"] for t in task], [v[f"{t}_max"] for t in task])
    if data.problem == "inscribed_cuboid":
        box_label = "maximal inscribed cuboid"
    else:
        box_label = "bounding box (" + ", ".join(f"{t}_min … {t}_max" for t in task) + ")"
    hull = None
    if isinstance(v.get("vertices"), list) and v["vertices"] and len(v["vertices"][0]) == 3:  # actuator_workspace
        hull = np.asarray(v["vertices"], dtype=float)
        box_label = "bounding box"
    if all(_list(data, f"cloud_{t}") is not None for t in task):  # the workspace kind
        pts = np.array([as_floats(v[f"cloud_{t}"]) for t in task]).T
        label = "reachable points (seeded sample)"
        if data.live is not None and all(isinstance(v.get(f"{t}_range"), list) for t in task):
            lo = np.array([v[f"{t}_range"][0] for t in task], dtype=float)
            hi = np.array([v[f"{t}_range"][1] for t in task], dtype=float)
            centre = np.clip(data.live.task_of(data.live.x_home), lo, hi)
            slices = _boundary_slices(data.live, lo, hi, centre)
            if data.live.closure.ik is not None:  # membership is cheap: each vertex bisected onto the boundary
                slices = [replace(sl, lines=_refined_boundary(data.live, sl, centre)) for sl in slices]
            return workspace_figure(
                pts,
                names=task,
                dimensions=kinds,
                title=title,
                points_label=label,
                slices=slices,
                slices_label="workspace boundary (slices through the home pose)",
            )
    elif cuboid is not None:  # inscribed_cuboid: the workspace around it from the model, if at hand
        pts, label, slices = np.zeros((0, 3)), "", ()
        boxes = _paper_boxes(data)
        if data.live is not None and data.problem == "inscribed_cuboid":
            pts, slices = _workspace_around(data.live, cuboid)
            label = f"reachable points (sample of {CLOUD_SAMPLE}, seed 0)"
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
            boxes=boxes,
            slices=slices,
            hull=hull,
        )
    else:  # a batch of poses, one sweep point per pose
        names = [_pose_name(data, closure, t) for t in task]
        _require_lists(data, names, "a workspace cloud")
        pts = np.array([as_floats(v[n]) for n in names]).T
        if data.ok is not None:
            pts = pts[data.ok]
        kinds = [_dims(data, n) or k for n, k in zip(names, kinds)]
        task, label = names, "solved poses"
    return workspace_figure(
        pts, cuboid=cuboid, names=task, dimensions=kinds, title=title, points_label=label, cuboid_label=box_label
    )


def _paper_boxes(data: ResultData) -> list[tuple]:
    """The box of the paper's own formulation, where the mechanism reads one from the result."""
    name = data.model.get("type")
    if not name:
        return []
    extras = mechanism_type(name, path=("model", "type")).cuboid
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
    for line in _slice_lines(sl):
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


def _planar_workspace_plot(data: ResultData, options: PlotOptions, closure: Any) -> Any:  # noqa: C901 - one branch per kind
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
    title = f"Workspace ({data.model.get('type') or data.problem}, {data.problem})"
    cuboid = None
    if all(isinstance(v.get(f"{t}_min"), (int, float)) and isinstance(v.get(f"{t}_max"), (int, float)) for t in task):
        cuboid = ([v[f"{t}_min"] for t in task], [v[f"{t}_max"] for t in task])
    common = {"names": task, "dimensions": kinds, "title": title}
    if data.problem == "actuator_workspace":
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
    note = MEMBERSHIP_BOUNDARY.format(g=PLANAR_GRID)
    if all(_list(data, f"cloud_{t}") is not None for t in task):  # the workspace kind
        pts = np.array([as_floats(v[f"cloud_{t}"]) for t in task]).T
        slices: list[BoundarySlice] = []
        if data.live is not None and all(isinstance(v.get(f"{t}_range"), list) for t in task):
            lo = np.array([v[f"{t}_range"][0] for t in task], dtype=float)
            hi = np.array([v[f"{t}_range"][1] for t in task], dtype=float)
            slices = _boundary_slices(data.live, lo, hi, (lo + hi) / 2, PLANAR_GRID)
        return workspace_figure_2d(
            pts,
            points_label="reachable points (seeded sample)",
            outline=[line for sl in slices for line in _refined_boundary(data.live, sl, (lo + hi) / 2)],
            note=note if slices else "no boundary: plot with solve --plot (the model at hand)",
            **common,
        )
    if cuboid is not None:  # inscribed_cuboid (or synthesis): the workspace around it, if the model is at hand
        pts, slices, label = np.zeros((0, 2)), [], ""
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
            label = f"reachable points (sample of {CLOUD_SAMPLE}, seed 0)"
        else:
            title += "\n(the rectangle alone: `cpm-nlp solve FILE --plot` draws the workspace around it)"
        common["title"] = title
        return workspace_figure_2d(
            pts,
            cuboid=cuboid,
            cuboid_label="maximal inscribed rectangle",
            points_label=label,
            outline=[line for sl in slices for line in _refined_boundary(data.live, sl, centre)],
            note=note if slices else "",
            **common,
        )
    names = [_pose_name(data, closure, t) for t in task]  # a batch of poses
    _require_lists(data, names, "a workspace plot")
    pts = np.array([as_floats(v[n]) for n in names]).T
    if data.ok is not None:
        pts = pts[data.ok]
    return workspace_figure_2d(pts, points_label="solved poses", **common)


# -- map ---------------------------------------------------------------------------------------------


def _sweep_key(data: ResultData, name: str | None, option: str) -> str:
    """A swept key or value column of a sweep, named in full or by its last part."""
    keys = [p["key"] for p in data.parameters] + list(data.recorded)
    if name in keys:
        return name
    short = [k for k in keys if k.rsplit(".", 1)[-1] == name]
    if len(short) == 1:
        return short[0]
    raise InputError(
        f"unknown column {name!r}; expected one of: {', '.join(keys)}",
        path=(option,),
        suggestions=suggest(str(name), keys),
    )


def _numeric_columns(data: ResultData, names: list[str]) -> list[str]:
    out = []
    for n in names:
        col = data.values.get(n) or []
        if any(v is not None for v in col) and all(
            v is None or (isinstance(v, (int, float)) and not isinstance(v, bool)) for v in col
        ):
            out.append(n)
    return out


def _value_column(data: ResultData, options: PlotOptions) -> str:
    if options.value:
        return _sweep_key(data, options.value, "--value")
    numeric = _numeric_columns(data, data.recorded)
    if not numeric:
        raise NotApplicable("the sweep recorded no numeric value (select scalar values with outputs.values)")
    return numeric[0]


def map_plot(data: ResultData, options: PlotOptions) -> Any:
    """A design map: a value over two swept parameters, or over the two grids
    of a kind's ``map_axes`` (see the module's naming conventions)."""
    _flat_only(options, "map")
    if data.sweep:
        return _sweep_map(data, options)
    v = data.values
    axes = _map_axes(data.problem)
    xk, yk, zk = options.x or axes[0], options.y or axes[1], options.value or axes[2]
    if not (xk and yk and zk):
        raise NotApplicable("a map of a single result needs --x, --y and --value naming three of its lists")
    for n, opt in ((xk, "--x"), (yk, "--y"), (zk, "--value")):
        if _list(data, n) is None:
            raise InputError(
                f"expected the name of a list of the result, got {n!r}",
                path=(opt,),
                suggestions=suggest(n, [k for k in v if _list(data, k) is not None]),
            )
    x, y, z = v[xk], v[yk], v[zk]
    region = v.get("in_region")
    if z and isinstance(z[0], list):  # a matrix over the grids: rows y, columns x
        if len(z) != len(y) or any(len(row) != len(x) for row in z):
            raise NotApplicable(f"{zk} is not a {len(y)} x {len(x)} matrix over {yk} and {xk}")
        x, y = [xi for _ in y for xi in x], [yi for yi in y for _ in x]
        z = [zij for row in z for zij in row]
        if isinstance(region, list) and region and isinstance(region[0], list):
            region = [rij for row in region for rij in row]
        outside = [zij is None for zij in z]  # null: outside the design space
    else:
        outside = None
    marks = []
    for suffix, label in (("_design", "design (the file)"), ("_best", f"best {pretty(zk)} (the result)")):
        mx, my = v.get(xk + suffix), v.get(yk + suffix)
        if isinstance(mx, (int, float)) and isinstance(my, (int, float)):
            marks.append((mx, my, label))
    return design_map_figure(
        x,
        y,
        z,
        names=(xk, yk, zk),
        dimensions=(_dims(data, xk), _dims(data, yk), _dims(data, zk) if _dims(data, zk) != "matrix" else None),
        outside=outside,
        region=region if isinstance(region, list) and len(region) == len(z) else None,
        domain=v.get("domain"),
        best=options.best,
        marks=marks,
        title=f"{data.problem}, {data.model.get('type') or ''}",
    )


def _sweep_map(data: ResultData, options: PlotOptions) -> Any:
    params = _numeric_columns(data, [p["key"] for p in data.parameters])
    if options.x or options.y:
        xk = _sweep_key(data, options.x or params[0], "--x")
        yk = _sweep_key(data, options.y or next(p for p in params if p != xk), "--y")
    elif len(params) >= 2:
        xk, yk = params[0], params[1]
    else:
        raise NotApplicable(f"a map needs two swept numeric parameters; this sweep has {len(params)}")
    others = [p["key"] for p in data.parameters if p["key"] not in (xk, yk)]
    if others:
        raise NotApplicable(f"a map shows two parameters; this sweep also varies {', '.join(others)}")
    zk = _value_column(data, options)
    bases = {p["key"]: p.get("base") for p in data.parameters}
    return design_map_figure(
        data.values[xk],
        data.values[yk],
        data.values[zk],
        names=(xk, yk, zk),
        dimensions=(_dims(data, xk), _dims(data, yk), _dims(data, zk)),
        ok=data.ok,
        outside=[s in OUTSIDE for s in data.statuses or []] or None,
        best=options.best,
        marks=[(bases.get(xk), bases.get(yk), "base design (the file)")],
        title=f"sweep of {data.problem}, {data.model.get('type') or ''}",
    )


# -- curves ----------------------------------------------------------------------------------------


def lines_plot(data: ResultData, options: PlotOptions) -> Any:
    """Values of a one-parameter sweep against the parameter, one panel each."""
    _flat_only(options, "lines")
    if not data.sweep:
        raise NotApplicable("'lines' plots a sweep results file")
    params = _numeric_columns(data, [p["key"] for p in data.parameters])
    if len(data.parameters) != 1 or not params:
        raise NotApplicable(f"'lines' needs a sweep of one numeric parameter; this one has {len(data.parameters)}")
    x = params[0]
    names = [_value_column(data, options)] if options.value else _numeric_columns(data, data.recorded)
    if not names:
        raise NotApplicable("the sweep recorded no numeric value")
    order = np.argsort(np.asarray(data.values[x], dtype=float))
    ok = data.ok if data.ok is not None else np.ones(len(order), bool)
    panels = [Panel(n, _dims(data, n), {n: [data.values[n][i] if ok[i] else None for i in order]}) for n in names]
    xs = [data.values[x][i] for i in order]
    return panels_figure(xs, panels, xname=x, xdimension=_dims(data, x), title=f"{data.problem}: sweep of {x}")


def _families(coords: Any) -> dict[str, list[Any]]:
    out: dict[str, list[Any]] = {}
    for c in coords:
        out.setdefault(c.group, []).append(c)
    return out


def requirements_plot(data: ResultData, options: PlotOptions) -> Any:
    """The joint requirements over the studied poses: platform motions and
    actuator displacements (first row, 3-PRS paper Fig. 6), passive joint
    rotations, relative to home where home is not zero (Fig. 7)."""
    _flat_only(options, "requirements")
    if data.sweep:
        raise NotApplicable("'requirements' plots one joint_requirements result, not a sweep")
    c = _closure(data)
    task = [_pose_name(data, c, t) for t in c.task]
    names = task + c.q_names + c.passive_names
    _require_lists(data, names, "the requirements plot")
    n = len(data.values[task[0]])
    panels = [
        Panel(t, _dims(data, t) or c.x[c.x_names.index(x)].kind, {t: data.values[t]}) for t, x in zip(task, c.task)
    ]
    for fam, coords in _families(c.q).items():
        panels.append(Panel(fam, coords[0].kind, {q.name: data.values[q.name] for q in coords}, annotate_range=True))
    home: dict[str, float] = {}
    if c.passive is not None:
        try:
            model = build_model(data.model["type"], {p: data.model[p] for p in c.parameters})
            home = passive_joints(model, model.x_home, model.q_home)
        except (InputError, KeyError):
            home = {}
    for fam, coords in _families(c.passive_coords).items():
        shift = {j.name: home.get(j.name, 0.0) for j in coords}
        relative = any(abs(v) > 1e-12 for v in shift.values())
        series = {
            ("d" if relative else "") + j.name: [None if v is None else v - shift[j.name] for v in data.values[j.name]]
            for j in coords
        }
        panels.append(Panel(("d" if relative else "") + fam, coords[0].kind, series, annotate_range=True))
    return panels_figure(
        list(range(1, n + 1)),
        panels,
        xname="studied pose",
        title=f"Joint requirements of {data.model.get('type')} over {n} poses",
        ncols=len(task) + len(_families(c.q)),
    )


def io_plot(data: ResultData, options: PlotOptions) -> Any:
    """Outputs against the input that varies, one panel per output (pantograph
    paper, Fig. 20-22): pose coordinates against an actuator for FK, actuators
    and dependent coordinates against a task coordinate for IK."""
    _flat_only(options, "io")
    if data.sweep:
        raise NotApplicable("'io' plots one batch result; for a sweep use 'lines'")
    c = _closure(data)
    if data.problem == "inverse_kinematics":
        inputs = [_pose_name(data, c, t) for t in c.task]
        outputs = c.q_names + [_pose_name(data, c, c.x_names[i]) for i in c.dep_index]
    else:
        inputs = c.q_names
        outputs = [_pose_name(data, c, x) for x in c.x_names]
    if options.value:
        if options.value not in data.values:
            raise InputError(
                f"unknown value {options.value!r}", path=("--value",), suggestions=suggest(options.value, data.values)
            )
        outputs = [options.value]
    _require_lists(data, inputs + outputs, "an output/input plot")
    cols = {n: np.array([np.nan if v is None else v for v in data.values[n]], dtype=float) for n in inputs}
    spread = {n: np.nanmax(v) - np.nanmin(v) if np.isfinite(v).any() else 0.0 for n, v in cols.items()}
    x = max(inputs, key=lambda n: spread[n])
    if spread[x] <= 0:
        raise NotApplicable("no input varies over the batch")
    same = [n for n in inputs if np.allclose(cols[n], cols[x], equal_nan=True)]
    xname = " = ".join(same)
    order = np.argsort(cols[x])
    outputs = [o for o in outputs if o not in same]
    flat = [o for o in outputs if _constant(data.values[o])] if len(outputs) > 1 else []
    refs = _published_points(data, cols[x])
    panels = []
    for o in outputs:
        if o in flat:
            continue
        series = {o + " (this model)" if o in refs else o: [data.values[o][i] for i in order]}
        panels.append(Panel(o, _dims(data, o), series, points=refs.get(o, ())))
    if not panels:
        raise NotApplicable("every output is constant over the batch")
    title = f"Outputs against {xname} ({data.model.get('type')}, {data.problem})"
    if flat:
        title += "\nconstant over the batch: " + ", ".join(_constant_text(data, o) for o in flat)
    return panels_figure(cols[x][order], panels, xname=xname, xdimension=_dims(data, x), title=title)


def _constant(values: list) -> bool:
    arr = as_floats(values)
    arr = arr[np.isfinite(arr)]
    return bool(arr.size) and float(np.ptp(arr)) <= 1e-9 * max(float(np.abs(arr).max()), 1e-300)


def _constant_text(data: ResultData, name: str) -> str:
    arr = as_floats(data.values[name])
    v = float(arr[np.isfinite(arr)][0])
    f, unit = display_unit(_dims(data, name), [v])
    return f"{name} = {v * f:.4g} {unit}".rstrip()


def _published_points(data: ResultData, x: np.ndarray) -> dict[str, list[tuple[float, float, str]]]:
    """Published values of single points of the batch ("dz[1]": dz at the second
    input), as (input, published value, label) per output name."""
    out: dict[str, list[tuple[float, float, str]]] = {}
    for expr, value, label in data.published:
        m = re.fullmatch(r"(\w+)\[(\d+)\]", expr)
        if m is None or int(m.group(2)) >= len(x):
            continue
        out.setdefault(m.group(1), []).append((float(x[int(m.group(2))]), float(value), label))
    return out


# -- the mechanism ------------------------------------------------------------------------------------


def _model_for(data: ResultData) -> Any:
    """The model of the result: the one solved (solve --plot), else built from the
    parameters the result records (without its joint limits)."""
    if data.live is not None:
        return data.live
    name = data.model.get("type")
    if not name:
        raise NotApplicable("the result does not name its mechanism (model.type)")
    mech = mechanism_type(name, path=("model", "type"))
    params = {o.name: data.model[o.name] for o in mech.parameters if data.model.get(o.name) is not None}
    try:
        return build_model(name, params)
    except InputError as exc:
        raise NotApplicable(f"cannot rebuild the {name} model from the result ({exc.message})") from None


def _geometry(model: Any) -> Any:
    mech = model.mechanism
    if mech is None or mech.geometry is None:
        raise NotApplicable(
            f"no drawing of the mechanism: {model.name} declares no geometry "
            "(the Mechanism.geometry capability, cpm_nlp.core.mechanism)"
        )
    return mech.geometry


def _single_pose(data: ResultData, model: Any) -> tuple[np.ndarray, np.ndarray]:
    """The pose (x, q) of a one-pose result."""
    c = model.closure
    names = c.x_names + c.q_names
    missing = [n for n in names if n not in data.values]
    if missing:
        raise NotApplicable(f"a drawing of the mechanism needs the pose ({', '.join(missing)} missing)")
    if any(isinstance(data.values[n], list) for n in names):
        raise NotApplicable(
            "a drawing of the mechanism shows one pose; this result is a batch (use 'io' or 'workspace')"
        )
    if any(data.values[n] is None for n in names):
        raise NotApplicable("the pose did not solve: there is no mechanism to draw")
    x = np.array([float(data.values[n]) for n in c.x_names])
    q = np.array([float(data.values[n]) for n in c.q_names])
    return x, q


#: a pose whose joints move less than this fraction of the mechanism's size from home is drawn exaggerated
SMALL_MOTION = 0.02


def _drawings(model: Any, x: np.ndarray, q: np.ndarray) -> tuple[Any, Any, float]:
    """(the drawing at the pose, at home, the exaggeration k): compliant mechanisms
    move micrometres, so where the joints move less than 2 % of the mechanism's
    size, the displacements from home are drawn k times larger (a round k that
    brings them to about 10 %)."""
    geometry = _geometry(model)
    pose, home = geometry(model, x, q), geometry(model, model.x_home, model.q_home)
    P = {k: np.asarray(v, dtype=float) for k, v in pose.points.items()}
    H = {k: np.asarray(v, dtype=float) for k, v in home.points.items()}
    span = float(np.ptp(np.array(list(H.values())), axis=0).max())
    move = max(float(np.linalg.norm(P[k] - H[k])) for k in P)
    if move <= TITLE_NOISE * span or span == 0.0 or move >= SMALL_MOTION * span:  # at home: no exaggeration
        return pose, home, 1.0
    k = 0.1 * span / move
    k = float(10 ** math.floor(math.log10(k)))
    shown = {n: H[n] + k * (P[n] - H[n]) for n in P}
    return replace(pose, points=shown), home, k


def _span(drawing: Any) -> float:
    """The size of a drawing (SI): the largest extent of its points."""
    pts = np.array([np.asarray(v, dtype=float).ravel()[:3] for v in drawing.points.values()])
    return float(np.ptp(pts, axis=0).max()) if len(pts) > 1 else 0.0


#: a pose coordinate below this fraction of the mechanism's size (lengths) or of a degree
#: (angles) is rounding noise of the solve: its title shows 0
TITLE_NOISE = 1e-9


def _pose_title(model: Any, x: np.ndarray, k: float, size: float = 0.0) -> str:
    """ "five_bar at x = 0 mm, y = 203.8 mm": the task coordinates of the pose, each in its
    own unit; a value below :data:`TITLE_NOISE` of the mechanism's ``size`` (SI: the span
    of its drawing; lengths) or of a degree (angles) is rounding noise, shown as 0 in the
    unit of the size (not "x = -7.939e-12 nm")."""
    c = model.closure
    lengths = [abs(x[i]) for i in c.task_index if c.x[i].kind == "length"]
    size = max([size, *lengths]) if lengths or size else 0.0
    parts = []
    for i in c.task_index:
        kind = c.x[i].kind
        scale = size if kind == "length" else math.radians(1.0) if kind == "angle" else 0.0
        v = 0.0 if abs(x[i]) <= TITLE_NOISE * scale else x[i]
        f, unit = display_unit(kind, [scale] if v == 0.0 and kind == "length" else [v])
        parts.append(f"{c.x[i].name} = {v * f:.4g} {unit}".rstrip())
    lines = [", ".join(parts[n : n + 3]) for n in range(0, len(parts), 3)]  # three coordinates a line
    text = f"{model.name} at " + ",\n".join(lines)
    return text + (f"\n(displacements from home drawn ×{k:g})" if k != 1.0 else "")


def mechanism_plot(data: ResultData, options: PlotOptions) -> Any:
    """The mechanism at the result's pose (legs, joints, platform), home faintly."""
    if data.sweep:
        raise NotApplicable("'mechanism' draws one pose, not a sweep")
    model = _model_for(data)
    x, q = _single_pose(data, model)
    pose, home, k = _drawings(model, x, q)
    draw = mechanism_html if options.interactive else mechanism_figure
    return draw(pose, home=home, title=_pose_title(model, x, k, _span(home)) + f" ({data.problem})", note=pose.note)


def design_plot(data: ResultData, options: PlotOptions) -> Any:
    """A synthesised design drawn at its home pose (its geometry parameters from
    the result's values), the design of the file faintly where it differs."""
    if data.sweep:
        raise NotApplicable("'design' draws one result")
    name = data.model.get("type")
    if not name:
        raise NotApplicable("the result does not name its mechanism (model.type)")
    mech = mechanism_type(name, path=("model", "type"))
    given = {o.name: data.model[o.name] for o in mech.parameters if data.model.get(o.name) is not None}
    found = {o.name: data.values[o.name] for o in mech.parameters if isinstance(data.values.get(o.name), (int, float))}
    if not found:
        raise NotApplicable(
            f"the result gives none of the {name} parameters ({', '.join(o.name for o in mech.parameters)})"
        )
    try:
        model = build_model(name, {**given, **found})
        start = build_model(name, given) if given and any(given.get(k) != v for k, v in found.items()) else None
    except InputError as exc:
        raise NotApplicable(f"cannot build the designed {name} ({exc.message})") from None
    geometry = _geometry(model)
    pose = geometry(model, model.x_home, model.q_home)
    home = None if start is None else geometry(start, start.x_home, start.q_home)
    kinds = {o.name: o.kind for o in mech.parameters}
    shown = [(k, v, *display_unit(kinds[k], [v])) for k, v in found.items()]
    text = ", ".join(f"{k} = {v * f:.4g} {unit}".rstrip() for k, v, f, unit in shown)
    title = f"Designed {name} at home: {text} ({data.problem})"
    note = "; ".join(t for t in (pose.note, "dashed: the design in the file" if home is not None else "") if t)
    draw = mechanism_html if options.interactive else mechanism_figure
    return draw(pose, home=home, title=title, note=note)


# -- jacobian --------------------------------------------------------------------------------------------

#: grid lines per axis of the conditioning slice of the jacobian plot
JACOBIAN_GRID = 15


def _conditioning_slice(model: Any, x: np.ndarray) -> tuple | None:
    """cond and manipulability over the plane of the first two task coordinates
    through the pose (the third fixed), in the region probed from the pose; None
    if there is no region (the pose outside the workspace)."""
    c = model.closure
    t0 = model.task_of(x)
    region = probe_region(model, centre=t0, factor=1.0)
    if region is None:
        return None
    lo, hi = region
    gx, gy = (np.linspace(lo[i], hi[i], JACOBIAN_GRID) for i in (0, 1))
    X, Y = np.meshgrid(gx, gy)
    T = np.repeat(t0[None, :], X.size, axis=0)
    T[:, 0], T[:, 1] = X.ravel(), Y.ravel()
    member = membership(model, T)
    cond = np.full(X.size, np.nan)
    manip = np.full(X.size, np.nan)
    for n in np.flatnonzero(member.inside):
        rep = jacobians(model, member.X[n], member.Q[n])
        cond[n], manip[n] = rep.cond, rep.manipulability
    names = [c.x[i].name for i in c.task_index]
    kinds = [c.x[i].kind for i in c.task_index]
    return gx, gy, cond.reshape(X.shape), manip.reshape(X.shape), names, kinds, t0


def jacobian_plot(data: ResultData, options: PlotOptions) -> Any:
    """The mechanism at the pose, and cond and manipulability over a slice of the
    workspace through it (first two task coordinates); from the JSON alone (no
    joint limits) the slice is of the unlimited model."""
    if data.sweep:
        raise NotApplicable("'jacobian' plots one jacobian result")
    if not isinstance(data.values.get("J_task"), list):
        raise NotApplicable("a jacobian plot needs J_task")
    model = _model_for(data)
    x, q = _single_pose(data, model)
    pose, home, k = _drawings(model, x, q)
    if options.interactive:
        return mechanism_html(
            pose, home=home, title=_pose_title(model, x, k, _span(home)) + f" ({data.problem})", note=pose.note
        )
    got = _conditioning_slice(model, x)
    panels = [("cond", 2), ("manipulability", 3)] if got is not None else []
    fig = jacobian_figure(pose, home, got, panels, data.values)
    fig.suptitle(_pose_title(model, x, k, _span(home)) + f" ({data.problem})")
    return fig


# -- twists ------------------------------------------------------------------------------------------


def twists_plot(data: ResultData, options: PlotOptions) -> Any:
    """The displacement twists of the platform, one per actuator, as arrows on the
    mechanism at the pose: the rotation (ω) and the translation (v) of the
    reference point, each scaled to the drawing (RPR paper, eq 45)."""
    T = data.values.get("T")
    if not isinstance(T, list) or len(T) != 6:
        raise NotApplicable("a twists plot needs the 6 x n twist matrix T")
    model = _model_for(data)
    c = model.closure
    x = np.array([float(data.values.get(n, h)) for n, h in zip(c.x_names, model.x_home)])
    q = model.q_home if not all(n in data.values for n in c.q_names) else [data.values[n] for n in c.q_names]
    pose = _geometry(model)(model, x, np.asarray(q, dtype=float))
    ref = np.asarray(data.values.get("reference_point") or pose.points.get("P", np.zeros(3)), dtype=float)
    T = np.asarray(T, dtype=float)
    span = float(np.ptp(np.array([np.asarray(v, dtype=float) for v in pose.points.values()]), axis=0).max())
    colours = ("tab:red", "tab:purple", "tab:brown", "tab:pink", "tab:olive", "tab:cyan")
    arrows = []
    for block, what, style in ((slice(0, 3), "ω", "rotation"), (slice(3, 6), "v", "translation")):
        big = float(np.abs(T[block]).max())
        if big == 0:
            continue
        scale = 0.35 * span / big
        for j in range(T.shape[1]):
            vec = T[block, j]
            if np.linalg.norm(vec) > 0:
                arrows.append(
                    Arrow(
                        ref + (0 if style == "rotation" else 0.02 * span),
                        vec * scale,
                        f"{what} of actuator {j + 1} ({style}, ×{scale:.3g})",
                        colours[j % len(colours)] if style == "rotation" else colours[(j + 3) % len(colours)],
                    )
                )
    draw = mechanism_html if options.interactive else mechanism_figure
    return draw(
        pose,
        arrows=arrows,
        title=f"Displacement twists ({data.model.get('type')}, {data.problem}), at the reference point",
        note=data.units.get("T", ""),
    )


# -- comparisons, matrices ----------------------------------------------------------------------------

#: how a result names a reference value beside its own (prefix or suffix, legend label)
REFERENCES = (
    ("reference_", "", "reference design"),
    ("paper_", "", "paper"),
    ("", "_printed", "paper (printed)"),
    ("", "_compare", "compared design"),
    ("", "_design", "design in the file"),
)


def _comparisons(data: ResultData) -> list[tuple[str, list[Comparison]]]:
    """Pairs (ours, reference) of scalar values, grouped by kind of reference."""
    v = data.values
    groups = []
    for prefix, suffix, label in REFERENCES:
        rows = []
        for name, ref in v.items():
            if not (name.startswith(prefix) and name.endswith(suffix)) or name == prefix + suffix:
                continue
            base = name[len(prefix) : len(name) - len(suffix) if suffix else None]
            ours = v.get(base)
            if base == name or not all(isinstance(u, (int, float)) and not isinstance(u, bool) for u in (ours, ref)):
                continue
            rows.append(Comparison(base, float(ours), float(ref), _dims(data, base)))
        if rows:
            groups.append((label, rows))
    return groups


def comparison_plot(data: ResultData, options: PlotOptions) -> Any:
    """Values computed here beside their references (a paper's printed values, a
    reference design, the design in the file): the reference's ratio to ours,
    both values written out; a multi-start spread where the result has one."""
    _flat_only(options, "comparison")
    if data.sweep:
        raise NotApplicable("'comparison' plots one result")
    groups = _comparisons(data)
    if not groups:
        raise NotApplicable("the result has no value beside a reference (reference_*, paper_*, *_printed ...)")
    spread = _multistart(data)
    return comparison_figure(
        groups, spread, title=f"{data.problem} ({data.model.get('type')}): ours against references"
    )


def _multistart(data: ResultData) -> dict[str, Any]:
    v = data.values
    out = {k: v[k] for k in ("starts", "starts_converged", "starts_agreed", "converged", "at_best") if k in v}
    if isinstance(v.get("optima"), list) and v["optima"] and isinstance(v["optima"][0], list):
        out["optima"] = v["optima"]
    return out


def _matrices(data: ResultData) -> list[tuple[str, np.ndarray]]:
    out = []
    for name, value in data.values.items():
        if isinstance(value, list) and value and isinstance(value[0], list):
            try:
                M = np.array(value, dtype=float)
            except (TypeError, ValueError):
                continue
            if M.ndim == 2 and M.size <= 100 and np.isfinite(M).all():
                out.append((name, M))
    return out


def matrices_plot(data: ResultData, options: PlotOptions) -> Any:
    """Every matrix of the result (up to 10 x 10) as a heat map of its entries'
    magnitudes, each entry written in (units from the result)."""
    _flat_only(options, "matrices")
    if data.sweep:
        raise NotApplicable("'matrices' plots one result")
    mats = _matrices(data)
    if not mats:
        raise NotApplicable("the result has no matrix")
    return matrices_figure(mats, data.units, title=f"{data.problem} ({data.model.get('type')})")


# -- dynamics ---------------------------------------------------------------------------------------------


def dynamics_plot(data: ResultData, options: PlotOptions) -> Any:
    """Natural frequencies and mode shapes: the generalized eigenproblem K v = ω² M v
    of the result's M and K (in the actuator coordinates), beside the paper's
    printed values where the result has them."""
    _flat_only(options, "dynamics")
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
    closure = _closure(data)
    groups = _comparisons(data)
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


# -- amplifier ----------------------------------------------------------------------------------------------


def amplifier_plot(data: ResultData, options: PlotOptions) -> Any:
    """Output against input of the lever amplifier, d = A2 q (prc3 paper, eq 1-2)."""
    _flat_only(options, "amplifier")
    v = data.values
    pairs = [(k, "d" + k[1:]) for k in v if re.fullmatch(r"q\d+", k) and isinstance(v[k], list)]
    pairs = [(a, b) for a, b in pairs if isinstance(v.get(b), list)]
    if not pairs or not isinstance(v.get("A2"), (int, float)):
        raise NotApplicable("an amplifier plot needs A2 and lists q<i>, d<i>")
    panels = []
    x = None
    for qn, dn in pairs:
        x = v[qn]
        panels.append(
            Panel(dn, "length", {dn: v[dn]}, title=f"{dn} = A2 {qn}, A2 = {v['A2']:.4g} (A1 = {v['A1']:.4g})")
        )
    return panels_figure(
        x, panels, xname=pairs[0][0], xdimension="length", title="Lever amplifier output (prc3, eq 1-2)"
    )


#: plot types with an interactive (.html) 3-D figure
INTERACTIVE = ("workspace", "mechanism", "design", "jacobian", "twists")


def forces_plot(data: ResultData, options: PlotOptions) -> Any:
    """Actuator forces and hinge stresses along a motion (actuator_forces over a
    list of inputs; prs3-ruiz.md Table 2 extended to a curve), against the input
    that varies most."""
    _flat_only(options, "forces")
    if data.sweep:
        raise NotApplicable("'forces' plots one actuator_forces result; for a sweep use 'lines'")
    c = _closure(data)
    inputs = c.q_names + [_pose_name(data, c, t) for t in c.task]
    forces = [f"F{j + 1}" for j in range(c.nq)]
    stresses = sorted(k for k in data.values if k.startswith("stress_") and not k.endswith("_loaded"))
    _require_lists(data, forces + inputs, "a forces plot (give the motion as lists)")
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
        xdimension=_dims(data, x),
        title=f"Actuator forces and hinge stresses ({data.model.get('type')})",
        ncols=len(panels),
    )


def _translational(c: Any) -> list[int]:
    return [i for i, x in enumerate(c.x) if x.kind == "length"][:3]


def ellipsoid_plot(data: ResultData, options: PlotOptions) -> Any:
    """The compliance ellipsoid of the platform: the translational block of C."""
    _flat_only(options, "ellipsoid")
    if data.sweep or not isinstance(data.values.get("C"), list):
        raise NotApplicable("'ellipsoid' plots the output compliance C of one platform_compliance result")
    c = _closure(data)
    idx = _translational(c)
    if len(idx) < 2:
        raise NotApplicable("the platform has fewer than two translational coordinates")
    C = np.asarray(data.values["C"], dtype=float)[np.ix_(idx, idx)]
    drawn = _drawn_pose(data)
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


def _drawn_pose(data: ResultData) -> tuple | None:
    """(model, geometry, x, q) of a one-pose result whose mechanism has a drawing, else None."""
    try:
        model = _model_for(data)
        geometry = _geometry(model)
        x, q = _single_pose(data, model)
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


def _mode_arrows(model: Any, geometry: Any, x: np.ndarray, q: np.ndarray, mx: Any, mq: Any) -> list[Arrow]:
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
    arrows: list[Arrow] = []
    seen: list[np.ndarray] = []
    for p, d in zip(P, D):
        if np.linalg.norm(d) < 1e-3 * MODE_ARROW * span or any(np.linalg.norm(p - o) < 1e-9 * span for o in seen):
            continue
        seen.append(p)
        arrows.append(Arrow(p, d, "" if arrows else "displacement in the mode (scaled)", "tab:red"))
    return arrows


def modes_plot(data: ResultData, options: PlotOptions) -> Any:
    """Mode shapes as arrows, one panel per mode (up to three): on the mechanism's
    drawing where it has one (an arrow at each point along its displacement in the
    mode), else at the platform point (the translational pose coordinates) and at
    each actuator."""
    _flat_only(options, "modes")
    if data.sweep or not isinstance(data.values.get("modes_x"), list):
        raise NotApplicable("'modes' plots the mode shapes of one natural_frequencies result")
    c = _closure(data)
    drawn = _drawn_pose(data)
    if drawn is not None:
        model, geometry, x, q = drawn
        modes = list(zip(data.values["modes_x"], data.values["modes_q"]))[:3]
        arrows = [_mode_arrows(model, geometry, x, q, mx, mq) for mx, mq in modes]
        freqs = [data.values[f"f{k + 1}"] for k in range(len(modes))]
        pose = geometry(model, x, q)
        title = _with_degenerate_note(f"Mode shapes ({data.model.get('type')})", _mode_clusters(data), len(modes))
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


#: plot type -> function(data, options) -> Figure
PLOTS = {
    "forces": forces_plot,
    "ellipsoid": ellipsoid_plot,
    "modes": modes_plot,
    "workspace": workspace_plot,
    "map": map_plot,
    "requirements": requirements_plot,
    "io": io_plot,
    "lines": lines_plot,
    "mechanism": mechanism_plot,
    "design": design_plot,
    "jacobian": jacobian_plot,
    "twists": twists_plot,
    "comparison": comparison_plot,
    "matrices": matrices_plot,
    "dynamics": dynamics_plot,
    "amplifier": amplifier_plot,
}
