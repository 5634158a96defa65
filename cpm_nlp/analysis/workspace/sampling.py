"""A search region around the home pose (probed along the task axes) and a seeded point
cloud of the workspace."""

from __future__ import annotations

import logging
from dataclasses import dataclass

import numpy as np

from ...core.model import Model
from ...core.solver import SolverConfig
from .membership import UNDECIDED, membership

log = logging.getLogger(__name__)

# -- sampling ------------------------------------------------------------------------------------


#: bisection steps of `probe_region` along each direction
PROBE_BISECTIONS = 40
#: bisection levels decided per membership call (membership is one vectorised call, each
#: point decided on its own): the 2^k - 1 midpoints of the next k levels are tested at once
PROBE_LEVELS = 4


def _double(model: Model, solver: SolverConfig | None, t0: np.ndarray, dirs: np.ndarray) -> tuple:
    """Along each direction, the last doubling step inside and the first outside (1e4 where
    none is): every step of the doubling tested in one call where `PROBE_LEVELS` > 1."""
    d = t0.size
    inside_step = np.zeros(len(dirs))
    outside_step = np.full(len(dirs), np.nan)
    steps = [1e-9]
    while steps[-1] * 2 < 1e4:
        steps.append(steps[-1] * 2)
    block = len(steps) if PROBE_LEVELS > 1 else 1
    for first in range(0, len(steps), block):
        todo = np.flatnonzero(np.isnan(outside_step))
        if not todo.size:
            break
        s = np.array(steps[first : first + block])
        pts = t0 + s[None, :, None] * dirs[todo][:, None, :]
        inside = membership(model, pts.reshape(-1, d), solver, detail=False).inside.reshape(todo.size, s.size)
        for row, k in enumerate(todo):
            out = np.flatnonzero(~inside[row])
            # the step before the first outside one is inside (none before the first step)
            last_in = s[-1] if not out.size else (s[out[0] - 1] if out[0] > 0 else inside_step[k])
            inside_step[k] = last_in
            outside_step[k] = s[out[0]] if out.size else outside_step[k]
    return inside_step, np.where(np.isnan(outside_step), 1e4, outside_step)


def _bisect_levels(model, solver, t0, dirs, inside_step, outside_step, k: int) -> tuple:
    """``k`` levels of bisection along every direction in one membership call: the 2^k - 1
    midpoints those levels could visit, then the path each direction takes through them."""
    d = t0.size
    cols = np.arange(len(dirs))
    nodes = 2**k - 1  # a binary tree: node i has children 2i + 1 (outside) and 2i + 2 (inside)
    low, high, mid = (np.empty((nodes, len(dirs))) for _ in range(3))
    low[0], high[0] = inside_step, outside_step
    for i in range(nodes):
        mid[i] = 0.5 * (low[i] + high[i])
        if 2 * i + 2 < nodes:
            low[2 * i + 1], high[2 * i + 1] = low[i], mid[i]
            low[2 * i + 2], high[2 * i + 2] = mid[i], high[i]
    pts = t0 + mid[:, :, None] * dirs[None, :, :]
    inside = membership(model, pts.reshape(-1, d), solver, detail=False).inside.reshape(nodes, len(dirs))
    node = np.zeros(len(dirs), dtype=int)
    for _ in range(k):
        ins, m = inside[node, cols], mid[node, cols]
        inside_step = np.where(ins, m, inside_step)
        outside_step = np.where(ins, outside_step, m)
        node = np.where(ins, 2 * node + 2, 2 * node + 1)
    return inside_step, outside_step


def probe_region(
    model: Model, solver: SolverConfig | None = None, centre=None, factor: float = 2.0
) -> tuple[np.ndarray, np.ndarray] | None:
    """A box around ``centre`` (default: the home pose) in the task coordinates:
    the distance to the workspace boundary along each task axis (both ways,
    by doubling and bisection), times ``factor``.  None if the centre itself
    is outside.

    The steps of the doubling are tested in one call and the bisection decides
    `PROBE_LEVELS` levels per call (all midpoints those levels could visit);
    the result is the same as one level per call.
    """
    t0 = model.task_of(model.x_home) if centre is None else np.asarray(centre, dtype=float)
    d = t0.size
    if not membership(model, t0[None, :], solver, detail=False).inside[0]:
        return None
    dirs = np.vstack([np.eye(d), -np.eye(d)])
    inside_step, outside_step = _double(model, solver, t0, dirs)
    done = 0
    while done < PROBE_BISECTIONS:  # bisection, k levels per call
        k = min(PROBE_LEVELS, PROBE_BISECTIONS - done)
        inside_step, outside_step = _bisect_levels(model, solver, t0, dirs, inside_step, outside_step, k)
        done += k
    plus, minus = inside_step[:d], inside_step[d:]
    span = np.maximum(plus + minus, 1e-12)
    return t0 - factor * np.maximum(minus, 0.25 * span), t0 + factor * np.maximum(plus, 0.25 * span)


@dataclass
class Cloud:
    """A seeded point cloud of the workspace.

    Attributes
    ----------
    points
        the points inside (M, nq);
    region
        the box they were drawn from (None if the home pose is outside and no region was given);
    drawn, inside, undecided
        counts;
    volume
        the Monte-Carlo estimate (region volume × inside / drawn), with its standard error
        ``volume_error``;
    volume_upper
        the same with the undecided points counted inside (equal to ``volume`` when none is
        undecided);
    undecided_points
        those points (U, nq).
    """

    points: np.ndarray
    region: tuple[np.ndarray, np.ndarray] | None
    drawn: int = 0
    inside: int = 0
    undecided: int = 0
    volume: float = 0.0
    volume_upper: float = 0.0
    undecided_points: np.ndarray | None = None

    @property
    def volume_error(self) -> float:
        """The standard error of ``volume``: region volume × sqrt(p (1 - p) / drawn), p = inside / drawn
        (a binomial count; the Monte Carlo's own error, beside any undecided points)."""
        if not self.drawn or self.region is None:
            return 0.0
        p = self.inside / self.drawn
        return float(np.prod(self.region[1] - self.region[0])) * float(np.sqrt(p * (1.0 - p) / self.drawn))


def workspace_cloud(
    model: Model,
    count: int,
    seed: int = 0,
    region: tuple[np.ndarray, np.ndarray] | None = None,
    solver: SolverConfig | None = None,
) -> Cloud:
    """``count`` points drawn uniformly in ``region`` (default: `probe_region`)
    with a seeded generator, each decided by [`membership`][cpm_nlp.analysis.workspace.membership.membership] (see
    `Cloud`)."""
    nq = model.closure.nq
    if region is None:
        region = probe_region(model, solver)
        if region is None:
            return Cloud(np.zeros((0, nq)), None, undecided_points=np.zeros((0, nq)))
    lo, hi = (np.asarray(v, dtype=float) for v in region)
    rng = np.random.default_rng(seed)
    T = lo + (hi - lo) * rng.random((count, lo.size))
    mem = membership(model, T, solver)
    undecided = np.array([s == UNDECIDED for s in mem.status], dtype=bool)
    n_in, n_und = int(np.count_nonzero(mem.inside)), int(np.count_nonzero(undecided))
    box = float(np.prod(hi - lo))
    return Cloud(
        T[mem.inside],
        (lo, hi),
        count,
        n_in,
        n_und,
        box * n_in / max(count, 1),
        box * (n_in + n_und) / max(count, 1),
        T[undecided],
    )


def sample_workspace(
    model: Model,
    count: int,
    seed: int = 0,
    region: tuple[np.ndarray, np.ndarray] | None = None,
    solver: SolverConfig | None = None,
) -> tuple[np.ndarray, tuple[np.ndarray, np.ndarray] | None, float]:
    """A seeded point cloud of the workspace: ``count`` points drawn uniformly
    in ``region`` (default: `probe_region`), those inside kept.  Returns
    (points inside (M, nq), the region, the Monte-Carlo volume estimate); see
    `workspace_cloud` for the counts of undecided points."""
    cloud = workspace_cloud(model, count, seed, region, solver)
    return cloud.points, cloud.region, cloud.volume
