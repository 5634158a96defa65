"""3-PRC micromanipulator with secondary lever amplifiers (Li, Li, Ding, Xu 2018).

* :mod:`.kinematics` -- loop closures, IK, Jacobians, and the Lagrange model (eq 1-41);
* :mod:`.kinds` -- its own problem kind ``amplifier`` (eq 1-2).
"""

from ...core.mechanism import DynamicsModel, Mechanism
from . import kinematics
from .kinds import Amplifier

MECHANISM = Mechanism(
    name="prc3",
    title="3-PRC micromanipulator with secondary lever amplifiers (Li et al. 2018)",
    paper=(
        "X.-C. Li, Y. Li, B.-X. Ding, H.-Y. Xu, An investigation on kinematics and dynamics performance of a novel "
        "3-PRC-compliant parallel micromanipulator, Adv. Mech. Eng. 10(7), 2018, doi:10.1177/1687814018789800"
    ),
    parameters=kinematics.PARAMETERS,
    limits=kinematics.LIMITS,
    closure=kinematics.closure,
    build=kinematics.build,
    check_parameters=kinematics.check_parameters,
    dynamics=DynamicsModel(
        masses=kinematics.MASSES,
        parameters=kinematics.DYNAMIC_PARAMETERS,
        lagrangian=kinematics.lagrangian,
        values=kinematics.dynamics_values,
        dimensions=kinematics.DYNAMICS_DIMENSIONS,
    ),
    geometry=kinematics.geometry,
    kinds={"amplifier": Amplifier},
    problem_files=(
        "prc3_forward_kinematics.yaml",
        "prc3_inverse_kinematics.yaml",
        "prc3_jacobian.yaml",
        "prc3_amplifier.yaml",
        "prc3_workspace.yaml",
        "prc3_cuboid.yaml",
        "prc3_dynamics.yaml",
    ),
)
