"""The public API of cpm_nlp (re-exported by the package).

Load a problem file or build a mechanism in code, then call the algorithms
with numpy arrays, or take the CasADi Functions of the model (``model.closure``:
``phi``, ``phi_x``, ``phi_q``, ``jacobian``, ``inverse_jacobian``, ``ik``,
``passive``) into your own CasADi code.  The library never prints; it logs
to the ``cpm_nlp`` logger.
"""

from .analysis.certify import Certificate, certify_box
from .analysis.requirements import RequirementsReport, joint_requirements
from .analysis.workspace import CuboidResult, Membership, check_box, inscribed_cuboid, membership, sample_workspace
from .core.batch import BatchJacobians, BatchResult, batch_forward_kinematics, batch_inverse_kinematics, batch_jacobians
from .core.errors import CpmError, InputError
from .core.kernels import status_of
from .core.kinematics import (
    JacobianReport,
    PoseSolution,
    assess,
    forward_kinematics,
    inverse_kinematics,
    jacobians,
    passive_joints,
    residual,
)
from .core.model import Coordinate, LoopClosure, Model
from .core.result import Result, SolverInfo, Status
from .core.solver import SolverConfig
from .io.embed import ModelFunctions, functions
from .io.export import export_kinematics, load_exported
from .mechanisms.registry import build_model, mechanism_type
from .problems.file import Problem, apply_overrides, load_problem, problem_from_dict, solve
from .problems.reproduce import Comparison, reproduce

__all__ = [
    "Certificate",
    "certify_box",
    "status_of",
    "ModelFunctions",
    "export_kinematics",
    "functions",
    "load_exported",
    "BatchJacobians",
    "BatchResult",
    "batch_forward_kinematics",
    "batch_inverse_kinematics",
    "batch_jacobians",
    "Comparison",
    "Coordinate",
    "CuboidResult",
    "CpmError",
    "InputError",
    "JacobianReport",
    "LoopClosure",
    "Membership",
    "Model",
    "PoseSolution",
    "Problem",
    "RequirementsReport",
    "Result",
    "SolverConfig",
    "SolverInfo",
    "Status",
    "apply_overrides",
    "assess",
    "build_model",
    "check_box",
    "forward_kinematics",
    "inscribed_cuboid",
    "inverse_kinematics",
    "jacobians",
    "joint_requirements",
    "load_problem",
    "mechanism_type",
    "membership",
    "passive_joints",
    "problem_from_dict",
    "reproduce",
    "residual",
    "sample_workspace",
    "solve",
]
