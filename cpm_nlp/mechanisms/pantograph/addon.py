"""The pantograph's add-on: what its mechanism file (problems/mechanisms/pantograph.yaml)
cannot say.

The kinematics -- loop closures (eq 1-8), closed-form IK (eq 9-10, 17-18), passive joints,
branch, drawing, parameters, the paper, the problem files -- is the file.  This add-on (named by
`cpm_nlp.mechanisms.registry.ADDONS`) gives the paper's analyses, each on the file's model
(its coordinates and parameters), never on a copy of its closures (`analysis`):

* the paper's joint limits (section 5.2): psi_min, psi_max, phi_max, or the hinge that sets them
  by eq 31, ranges of theta and of the actuators (``stroke``) counted from home, and the check
  that not two of them say one limit (`check_limits`);
* the derived quantities Mx, My, Mz, omega (eq 9-16, from the AD Jacobian of the file's loops),
  dx0 and the angle limits (`complete`);
* the closed-form workspace of section 5 (eq 17-29, `paper_membership`);
* the paper's cuboid beside the general one (eq 32-34, `CUBOID`);
* the dimensional synthesis of section 6 (eq 35-38, `synthesis`).
"""

from __future__ import annotations

from ...core.mechanism import Addon
from ...kinds.workspace import CuboidExtras, PaperMembership
from . import analysis
from .synthesis import PantographSynthesis

#: the paper's cuboid (eq 32-34) reported beside the general one by ``inscribed_cuboid``
CUBOID = CuboidExtras(
    options=analysis.CUBOID_OPTIONS,
    outputs=analysis.CUBOID_OUTPUTS,
    values=analysis.cuboid_values,
    paper_box=analysis.paper_box,
)

ADDON = Addon(
    limits=analysis.LIMITS,
    check_limits=analysis.check_limits,
    complete=analysis.complete,
    parts=(PantographSynthesis(), CUBOID, PaperMembership(analysis.paper_membership)),
)
