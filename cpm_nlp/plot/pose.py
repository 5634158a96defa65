"""The mechanism of a result at a pose: its model (the one solved, or rebuilt
from the parameters the result records), its drawing, the pose, home, the
exaggeration of micrometre motions and the title naming the pose.
"""

from __future__ import annotations

import math
from dataclasses import replace
from typing import Any

import numpy as np

from ..core.errors import InputError
from .results import NotApplicable, ResultData, result_mechanism, result_model
from .style import display_unit, pretty

# -- the mechanism ------------------------------------------------------------------------------------


def model_for(data: ResultData) -> Any:
    """The model of the result: the one solved (solve --plot), else built from the
    parameters the result records (without its joint limits)."""
    if data.live is not None:
        return data.live
    mech = result_mechanism(data)  # a changed or missing mechanism file: an InputError (exit 2)
    params = {o.name: data.model[o.name] for o in mech.parameters if data.model.get(o.name) is not None}
    try:
        return result_model(data, params)
    except InputError as exc:
        raise NotApplicable(f"cannot rebuild the {mech.name} model from the result ({exc.message})") from None


def geometry_of(model: Any) -> Any:
    mech = model.mechanism
    if mech is None or mech.geometry is None:
        raise NotApplicable(
            f"no drawing of the mechanism: {model.name} declares no geometry "
            "(the Mechanism.geometry capability, cpm_nlp.core.mechanism)"
        )
    return mech.geometry


def single_pose(data: ResultData, model: Any) -> tuple[np.ndarray, np.ndarray]:
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


def drawings(model: Any, x: np.ndarray, q: np.ndarray) -> tuple[Any, Any, float]:
    """(the drawing at the pose, at home, the exaggeration k): compliant mechanisms
    move micrometres, so where the joints move less than 2 % of the mechanism's
    size, the displacements from home are drawn k times larger (a round k that
    brings them to about 10 %)."""
    geometry = geometry_of(model)
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


def span_of(drawing: Any) -> float:
    """The size of a drawing (SI): the largest extent of its points."""
    pts = np.array([np.asarray(v, dtype=float).ravel()[:3] for v in drawing.points.values()])
    return float(np.ptp(pts, axis=0).max()) if len(pts) > 1 else 0.0


#: a pose coordinate below this fraction of the mechanism's size (lengths) or of a degree
#: (angles) is rounding noise of the solve: its title shows 0
TITLE_NOISE = 1e-9


def model_title(model: Any) -> str:
    """The title of the model's mechanism ("3-PRS compliant stage (Ruiz et al.)"), else its name
    (`results.mechanism_title` gives it from a result)."""
    mech = model.mechanism
    return str(mech.title) if mech is not None and mech.title else str(model.name)


def pose_title(model: Any, x: np.ndarray, k: float, size: float = 0.0, how: str = "") -> str:
    """The mechanism's title over its pose, e.g. "planar five-bar linkage (2-RRR), elbows out" /
    "forward kinematics: x = 0 mm, y = 203.8 mm": the task coordinates of the pose (symbols, each
    value in its own unit) after ``how`` the pose was found (a problem kind, "_" read as " ").  A
    value below `TITLE_NOISE` of the mechanism's ``size`` (SI: the span of its drawing;
    lengths) or of a degree (angles) is rounding noise, shown as 0 in the unit of the size (not
    "x = -7.939e-12 nm")."""
    c = model.closure
    lengths = [abs(x[i]) for i in c.task_index if c.x[i].kind == "length"]
    size = max([size, *lengths]) if lengths or size else 0.0
    parts = []
    for i in c.task_index:
        kind = c.x[i].kind
        scale = size if kind == "length" else math.radians(1.0) if kind == "angle" else 0.0
        v = 0.0 if abs(x[i]) <= TITLE_NOISE * scale else x[i]
        f, unit = display_unit(kind, [scale] if v == 0.0 and kind == "length" else [v])
        parts.append(f"{pretty(c.x[i].name)} = {v * f:.4g} {unit}".rstrip())
    lines = [", ".join(parts[n : n + 3]) for n in range(0, len(parts), 3)]  # three coordinates a line
    head = f"{how.replace('_', ' ')}: " if how else "pose: "
    text = model_title(model) + "\n" + head + ",\n".join(lines)
    return text + (f"\n(displacements from home drawn ×{k:g})" if k != 1.0 else "")
