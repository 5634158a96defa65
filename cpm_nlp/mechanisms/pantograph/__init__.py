"""3D compliant pantograph, decoupled XYZ (Elgammal, Fanni, Mohamed 2016).

* :mod:`.kinematics` -- loop closures, magnification, workspace limits and the paper's cuboid (eq 1-34);
* :mod:`.synthesis` -- its dimensional synthesis (eq 35-38).
"""

from ...core.mechanism import CuboidExtras, Mechanism
from . import kinematics
from .synthesis import PantographSynthesis

MECHANISM = Mechanism(
    name="pantograph",
    title="3D compliant pantograph, decoupled XYZ (Elgammal et al.)",
    paper=(
        "A. T. Elgammal, M. Fanni, A. M. Mohamed, Design and Analysis of a Novel 3D Decoupled Manipulator Based on "
        "Compliant Pantograph for Micromanipulation, J. Intell. Robot. Syst., 2016 (published online 29 Dec 2016)"
    ),
    parameters=kinematics.PARAMETERS,
    limits=kinematics.LIMITS,
    closure=kinematics.closure,
    build=kinematics.build,
    check_limits=kinematics.check_limits,
    synthesis=PantographSynthesis,
    cuboid=CuboidExtras(
        options=kinematics.CUBOID_OPTIONS,
        value_names=kinematics.CUBOID_VALUE_NAMES,
        values=kinematics.cuboid_values,
        paper_box=kinematics.paper_box,
    ),
    geometry=kinematics.geometry,
    paper_membership=kinematics.paper_membership,
    problem_files=(
        "pantograph_forward_kinematics.yaml",
        "pantograph_inverse_kinematics.yaml",
        "pantograph_jacobian.yaml",
        "pantograph_workspace.yaml",
        "pantograph_cuboid.yaml",
        "pantograph_cuboid_eq34_printed.yaml",
        "pantograph_cuboid_hinge.yaml",
        "pantograph_table1.yaml",
        "pantograph_table1_ba5.yaml",
        "pantograph_synthesis.yaml",
        "pantograph_synthesis_paper_bounds.yaml",
    ),
)
