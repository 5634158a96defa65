"""Reachable workspace of any mechanism given by its loop closures and joint limits.

A point t of the task coordinates belongs to the workspace when the mechanism
assembles there on the branch the model designates and every actuator, pose
coordinate and passive joint with declared limits lies within them:

* [`membership`][cpm_nlp.analysis.workspace.membership.membership] -- that test for many points at once (the closed-form
  IK of the model when it has one, with the limited quantities, residuals
  and Φ_x of all points in one mapped CasADi call; else the IK solved point
  by point);
* `probe_region` and [`sample_workspace`][cpm_nlp.analysis.workspace.sampling.sample_workspace] -- a box around the home
  pose found by probing along the task axes, and a seeded point cloud;
* [`inscribed_cuboid`][cpm_nlp.analysis.workspace.cuboid.inscribed_cuboid] -- the largest axis-aligned box in the task
  coordinates inside the workspace, by IPOPT, seeded multi-start, verified
  afterwards on a dense sample of its faces, edges and interior.

Nothing here knows a particular mechanism.  The cuboid NLP is a discretised
semi-infinite program: the box [c + D∘u, c + D∘(u + w)] (normalised by the
region's centre c and size D) carries N sample points s_j on its surface
(a grid of n per edge, so corners, edge and face centres are among them);
each sample has its own pose unknowns y_j = (dependent pose coordinates,
actuators) with Φ(t_j, y_j) = 0 and the limits as bounds on the limited
quantities; the objective is -Σ log w_i (the log of the volume).  With a
closed-form IK the same NLP is solved without pose unknowns, the limited
quantities being functions of the sample points through the IK, on working
sets of its rows (`cpm_nlp.analysis.cuboid_ik`; ``formulation`` chooses).  The dense
check afterwards finds any point of the box that is outside (between the
samples, or a hole inside); its worst points become extra samples and the
NLP is solved again (an exchange method), a few rounds at most.  If points
are still outside after that, the box is shrunk about its centre until the
check passes, and the result says by how much.

The image of the actuator-stroke box under the forward kinematics (the
"hexahedron" of prc3-li-2018.md, eq 27, Fig. 5) is a second view of the same
set when the strokes are the binding limits:

* `reachable_workspace` -- FK on a grid over the box (faces included),
  the vertices, the axis-aligned bounding box, the volume, and how far the
  kinematics strays from its linearization at home over the workspace;
* `joint_box` -- the actuator strokes of a model.
"""

from __future__ import annotations

from ...core.pose_checks import SINGULAR_CONDITION
from .box import WorkspaceReport, box_corners, box_grid, gauss_box, joint_box, reachable_workspace
from .cuboid import (
    ADDED_PER_ROUND,
    CHECK_OPTION,
    CLOSED_FORM_IPOPT,
    CUBOID_IPOPT,
    DEFAULT_CHECK_POINTS,
    DEFAULT_NLP_SAMPLES,
    EXTRA_SLOTS,
    FORMULATIONS,
    MAX_CHECK_POINTS,
    MAX_NLP_SAMPLES,
    NLP_MARGIN,
    CuboidCheck,
    CuboidFormulation,
    CuboidNLP,
    CuboidResult,
    _closed_form_cuboid,
    _start_box,
    box_volume,
    check_box,
    check_grid,
    check_grid_sizes,
    check_per_edge_of,
    check_per_edge_option,
    cuboid_formulation,
    cuboid_nlp,
    default_per_edge,
    inscribed_cuboid,
    surface_count,
    surface_grid,
)
from .membership import (
    CHECK_TOLERANCE,
    INSIDE,
    OUTSIDE,
    UNDECIDED,
    Membership,
    condition_numbers,
    limit_bounds,
    limited_function,
    membership,
    pose_check_function,
    poses,
    task_point_function,
)
from .sampling import PROBE_BISECTIONS, PROBE_LEVELS, Cloud, probe_region, sample_workspace, workspace_cloud

__all__ = [
    "ADDED_PER_ROUND",
    "CHECK_OPTION",
    "CHECK_TOLERANCE",
    "CLOSED_FORM_IPOPT",
    "DEFAULT_CHECK_POINTS",
    "DEFAULT_NLP_SAMPLES",
    "MAX_CHECK_POINTS",
    "MAX_NLP_SAMPLES",
    "CUBOID_IPOPT",
    "Cloud",
    "CuboidCheck",
    "CuboidFormulation",
    "CuboidNLP",
    "CuboidResult",
    "EXTRA_SLOTS",
    "FORMULATIONS",
    "INSIDE",
    "OUTSIDE",
    "UNDECIDED",
    "Membership",
    "NLP_MARGIN",
    "PROBE_BISECTIONS",
    "PROBE_LEVELS",
    "SINGULAR_CONDITION",
    "WorkspaceReport",
    "_closed_form_cuboid",
    "_start_box",
    "box_corners",
    "box_grid",
    "box_volume",
    "check_box",
    "check_grid",
    "check_grid_sizes",
    "check_per_edge_of",
    "check_per_edge_option",
    "condition_numbers",
    "cuboid_formulation",
    "cuboid_nlp",
    "default_per_edge",
    "gauss_box",
    "inscribed_cuboid",
    "joint_box",
    "limit_bounds",
    "limited_function",
    "membership",
    "pose_check_function",
    "poses",
    "probe_region",
    "reachable_workspace",
    "sample_workspace",
    "surface_count",
    "surface_grid",
    "task_point_function",
    "workspace_cloud",
]
