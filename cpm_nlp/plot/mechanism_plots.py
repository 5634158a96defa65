"""The ``mechanism``, ``design`` and ``jacobian`` plot types: the mechanism at the
result's pose, a synthesised design at home, and cond and manipulability over a
slice of the workspace through the pose.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..analysis.workspace import membership, probe_region
from ..core.errors import InputError
from ..core.kinematics import jacobians
from .draw_mechanism import jacobian_figure, mechanism_figure
from .interactive import mechanism_html
from .pose import drawings, geometry_of, model_for, model_title, pose_title, single_pose, span_of
from .results import NotApplicable, PlotOptions, ResultData, result_mechanism, result_model
from .style import display_unit


def mechanism_plot(data: ResultData, options: PlotOptions) -> Any:
    """The mechanism at the result's pose (legs, joints, platform), home faintly."""
    if data.sweep:
        raise NotApplicable("'mechanism' draws one pose, not a sweep")
    model = model_for(data)
    x, q = single_pose(data, model)
    pose, home, k = drawings(model, x, q)
    draw = mechanism_html if options.interactive else mechanism_figure
    return draw(pose, home=home, title=pose_title(model, x, k, span_of(home), data.problem), note=pose.note)


def design_plot(data: ResultData, options: PlotOptions) -> Any:
    """A synthesised design drawn at its home pose (its geometry parameters from
    the result's values), the design of the file faintly where it differs."""
    if data.sweep:
        raise NotApplicable("'design' draws one result")
    mech = result_mechanism(data)
    name = mech.name
    given = {o.name: data.model[o.name] for o in mech.parameters if data.model.get(o.name) is not None}
    found = {o.name: data.values[o.name] for o in mech.parameters if isinstance(data.values.get(o.name), (int, float))}
    if not found:
        raise NotApplicable(
            f"the result gives none of the {name} parameters ({', '.join(o.name for o in mech.parameters)})"
        )
    try:
        model = result_model(data, {**given, **found})
        start = result_model(data, given) if given and any(given.get(k) != v for k, v in found.items()) else None
    except InputError as exc:
        raise NotApplicable(f"cannot build the designed {name} ({exc.message})") from None
    geometry = geometry_of(model)
    pose = geometry(model, model.x_home, model.q_home)
    home = None if start is None else geometry(start, start.x_home, start.q_home)
    kinds = {o.name: o.kind for o in mech.parameters}
    shown = [(k, v, *display_unit(kinds[k], [v])) for k, v in found.items()]
    text = ", ".join(f"{k} = {v * f:.4g} {unit}".rstrip() for k, v, f, unit in shown)
    title = f"{model_title(model)}\ndesigned by {data.problem.replace('_', ' ')}, at home: {text}"
    if options.interactive:
        note = "; ".join(t for t in (pose.note, "dashed: the design in the file" if home is not None else "") if t)
        return mechanism_html(pose, home=home, title=title, note=note)
    return mechanism_figure(pose, home=home, title=title, note=pose.note, home_label="the design in the file (at home)")


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
    model = model_for(data)
    x, q = single_pose(data, model)
    pose, home, k = drawings(model, x, q)
    if options.interactive:
        return mechanism_html(
            pose, home=home, title=pose_title(model, x, k, span_of(home), data.problem), note=pose.note
        )
    got = _conditioning_slice(model, x)
    panels = [("cond", 2), ("manipulability", 3)] if got is not None else []
    fig = jacobian_figure(pose, home, got, panels, data.values)
    fig.suptitle(pose_title(model, x, k, span_of(home), data.problem))
    return fig
