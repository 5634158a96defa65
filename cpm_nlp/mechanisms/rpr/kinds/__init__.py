"""Problem kinds of the RPR compliant mechanism (rpr-2rpu-upr-zhang-2022.md):

* ``rpr_screw_jacobian`` -- eq 7-13 by screw theory beside the AD Jacobians;
* ``rpr_twists`` -- displacement twists of the platform per actuator (eq 45);
* ``rpr_transmission_map`` -- η over the (s, t) triangle (Fig. 4), plot-ready;
* ``synthesis`` (the shared kind, via the add-on's ``synthesis``) -- maximise η under eq 22 (eq 19-26);
* ``rpr_joint_design`` -- the R and U flexure joints (eq 27-32, Table 1);
* ``rpr_compliance`` -- the pseudo-rigid-body compliance model (eq 33-44).

Every kind applies to the ``rpr`` mechanism only (`supports`), the mechanism of the file
problems/mechanisms/rpr.yaml, and runs on its closures (pose, passive joints, Jacobians).  One
module per kind; the classes are named here as well, as ``cpm_nlp.mechanisms.rpr.kinds`` (the
home of 0.1's ``cpm_nlp.rpr_problems``) has always named them.
"""

from .compliance import Compliance
from .joint_design import JointDesign
from .screw_jacobian import ScrewJacobian
from .synthesis import Synthesis
from .transmission import TransmissionMap
from .twists import Twists

__all__ = ["Compliance", "JointDesign", "ScrewJacobian", "Synthesis", "TransmissionMap", "Twists"]
