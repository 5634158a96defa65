"""The RPR's add-on: what its mechanism file (problems/mechanisms/rpr.yaml) cannot say.

The kinematics -- loop closures, IK, passive joints, branch, drawing, the Table 1 hinges -- is
the file.  This add-on (named by `cpm_nlp.mechanisms.registry.ADDONS`) gives the paper's
own parts, each run on the file's closures:

* the kinds ``rpr_screw_jacobian`` (eq 7-13, beside the AD Jacobians of the file's closures),
  ``rpr_twists`` (eq 45), ``rpr_transmission_map`` (eq 19-23, Fig. 4), ``rpr_joint_design``
  (eq 27-32) and ``rpr_compliance`` (eq 33-44), `kinds`;
* the synthesis formulation of the shared kind ``synthesis`` (maximise eta under eq 22,
  eq 19-26; `kinds.Synthesis`).
"""

from __future__ import annotations

from ...core.mechanism import Addon
from ...kinds.synthesis import SynthesisFormulation
from .kinds import Compliance, JointDesign, ScrewJacobian, Synthesis, TransmissionMap, Twists


class RprSynthesis(Synthesis, SynthesisFormulation):
    """The RPR's synthesis (`kinds.Synthesis`) as the mechanism's part ``synthesis``."""


ADDON = Addon(
    kinds={k.name: k for k in (ScrewJacobian, Twists, TransmissionMap, JointDesign, Compliance)},
    parts=(RprSynthesis(),),
)
