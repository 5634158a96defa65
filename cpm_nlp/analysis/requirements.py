"""Joint requirements: the actuator strokes and passive-joint rotations a
mechanism needs to cover a set of poses (3-PRS paper, section 4, Fig. 6-7).

Every combination of the given task-coordinate values is solved by inverse
kinematics; the result holds each pose's joints and, per joint family, the
range over all poses.
"""

from __future__ import annotations

import itertools
import time
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from ..core.batch import batch_inverse_kinematics
from ..core.kinematics import PoseSolution, inverse_kinematics, passive_joints
from ..core.model import Model
from ..core.result import Status, worst_status
from ..core.solver import SolverConfig

#: a family whose home value is further than this from zero also gets ranges
#: relative to home (d<family>_min/max), e.g. the revolute angles alpha_i.
_HOME_ZERO = 1e-12


@dataclass
class RequirementsReport:
    """IK over a grid of task coordinates.

    Attributes
    ----------
    poses
        the grid, shape (N, nq) in the order of closure.task;
    solutions
        one PoseSolution per pose;
    ranges
        ``name -> value`` for ``<family>_min``, ``<family>_max`` (and ``d<family>_min/max`` for
        families with a non-zero home value).  Empty unless every pose is solved.
    """

    poses: np.ndarray
    solutions: list[PoseSolution]
    status: Status
    ranges: dict[str, float] = field(default_factory=dict)
    range_dimensions: dict[str, str] = field(default_factory=dict)
    seconds: float = 0.0


def full_factorial(values: Sequence[Sequence[float]]) -> np.ndarray:
    """Every combination of the given per-coordinate values, shape (N, k)."""
    return np.array(list(itertools.product(*values)), dtype=float).reshape(-1, len(values))


def joint_requirements(
    model: Model, grid: Sequence[Sequence[float]], solver: SolverConfig | None = None
) -> RequirementsReport:
    """Solve IK at every combination of ``grid`` (one value list per task
    coordinate, in the order of ``model.closure.task``) and collect ranges."""
    c = model.closure
    t0 = time.perf_counter()
    poses = full_factorial(grid)
    if c.ik is not None:  # the closed form, vectorized over the grid
        solutions = batch_inverse_kinematics(model, poses, solver).solutions()
    else:
        solutions = [inverse_kinematics(model, t, solver) for t in poses]
    status = worst_status([s.status for s in solutions])
    report = RequirementsReport(poses, solutions, status, seconds=time.perf_counter() - t0)
    if status is not Status.SOLVED:
        return report
    # families: actuators, dependent pose coordinates, passive joints
    columns: dict[str, list[np.ndarray]] = {}
    homes: dict[str, list[float]] = {}
    dims: dict[str, str] = {}
    home_passive = passive_joints(model, model.x_home, model.q_home)
    for j, coord in enumerate(c.q):
        columns.setdefault(coord.group, []).append(np.array([s.q[j] for s in solutions]))
        homes.setdefault(coord.group, []).append(float(model.q_home[j]))
        dims[coord.group] = coord.kind
    for i in c.dep_index:
        coord = c.x[i]
        columns.setdefault(coord.group, []).append(np.array([s.x[i] for s in solutions]))
        homes.setdefault(coord.group, []).append(float(model.x_home[i]))
        dims[coord.group] = coord.kind
    for j, coord in enumerate(c.passive_coords):
        columns.setdefault(coord.group, []).append(np.array([s.passive[j] for s in solutions]))
        homes.setdefault(coord.group, []).append(home_passive[coord.name])
        dims[coord.group] = coord.kind
    for fam, cols in columns.items():
        data = np.vstack(cols)
        report.ranges[f"{fam}_min"] = float(data.min())
        report.ranges[f"{fam}_max"] = float(data.max())
        report.range_dimensions[f"{fam}_min"] = report.range_dimensions[f"{fam}_max"] = dims[fam]
        home = np.array(homes[fam])[:, None]
        if np.any(np.abs(home) > _HOME_ZERO):
            dev = data - home
            report.ranges[f"d{fam}_min"] = float(dev.min())
            report.ranges[f"d{fam}_max"] = float(dev.max())
            report.range_dimensions[f"d{fam}_min"] = report.range_dimensions[f"d{fam}_max"] = dims[fam]
    return report
