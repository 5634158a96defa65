"""RPR compliant mechanism from a 2-RPU-UPR (Zhang, Liu, Ding 2022).

* :mod:`.kinematics` -- loop closures, IK, passive joints, screw-theory Jacobian (eq 2-13);
* :mod:`.design` -- transmission index and dimensional synthesis (eq 14-32);
* :mod:`.compliance` -- the pseudo-rigid-body compliance model (eq 33-58);
* :mod:`.kinds` -- its own problem kinds (``rpr_*``) and its synthesis formulation.
"""

from ...core.mechanism import JointStiffness, Mechanism
from . import kinematics
from .kinds import Compliance, JointDesign, ScrewJacobian, Synthesis, TransmissionMap, Twists

#: Table 1's flexure joints as circular notches (the reading of problems/rpr_compliance.yaml):
#: R joints one notch r 4 mm, t 0.4 mm, 12 mm wide; each axis of a U joint one notch r 1 mm,
#: t 0.4 mm in the 12 mm square rod; Al 7075 (section 5, the FEA's material).  Stiffness and
#: stresses from the hinge formulas (the paper prints no joint stiffness).
STIFFNESS = JointStiffness(
    hinges={
        "R": {"joints": "theta_R", "type": "circular_notch", "r": "4 mm", "t": "0.4 mm", "w": "12 mm"},
        "U": {"joints": "theta_U", "type": "circular_notch", "r": "1 mm", "t": "0.4 mm", "w": "12 mm"},
    },
    material="Al 7075-T6",
    source="rpr-2rpu-upr-zhang-2022.md Table 1 (joint dimensions) and section 5 (Al-7075)",
)

MECHANISM = Mechanism(
    name="rpr",
    title="RPR compliant mechanism from a 2-RPU-UPR (Zhang, Liu, Ding)",
    paper=(
        "S. Zhang, J. Liu, H. Ding, Design and Analysis of a Novel Compliant Mechanism with RPR Degrees of Freedom, "
        "Chin. J. Mech. Eng. 35, 2022, doi:10.1186/s10033-022-00777-2"
    ),
    parameters=kinematics.PARAMETERS,
    limits=kinematics.LIMITS,
    closure=kinematics.closure,
    build=kinematics.build,
    synthesis=Synthesis,
    geometry=kinematics.geometry,
    stiffness=STIFFNESS,
    kinds={k.name: k for k in (ScrewJacobian, Twists, TransmissionMap, JointDesign, Compliance)},
    problem_files=(
        "rpr_forward_kinematics.yaml",
        "rpr_inverse_kinematics.yaml",
        "rpr_jacobian.yaml",
        "rpr_screw_jacobian.yaml",
        "rpr_twists.yaml",
        "rpr_twists_eq47.yaml",
        "rpr_twists_eq49.yaml",
        "rpr_twists_velocity.yaml",
        "rpr_transmission_map.yaml",
        "rpr_synthesis.yaml",
        "rpr_synthesis_fixed_P.yaml",
        "rpr_joint_design.yaml",
        "rpr_compliance.yaml",
    ),
)
