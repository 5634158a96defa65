"""The public API of cpm_nlp: every name ``import cpm_nlp as cn`` gives (``cn.__all__``).

Load a problem file or build a mechanism in code, then call the algorithms
with numpy arrays, or take the CasADi Functions of the model (``model.closure``:
``phi``, ``phi_x``, ``phi_q``, ``jacobian``, ``inverse_jacobian``, ``ik``,
``passive``) into your own CasADi code.  The library never prints; it logs
to the ``cpm_nlp`` logger.
"""

import os

from .analysis.assembly import AssemblyMode, AssemblyModes, assembly_modes
from .analysis.certify import Certificate, certify_box
from .analysis.compliance import JointStiffness
from .analysis.dynamics import DynamicsModel
from .analysis.requirements import RequirementsReport, joint_requirements
from .analysis.workspace import CuboidResult, Membership, check_box, inscribed_cuboid, membership, sample_workspace
from .core.batch import BatchJacobians, BatchResult, batch_forward_kinematics, batch_inverse_kinematics, batch_jacobians
from .core.chains import LegChains
from .core.errors import CpmError, InputError
from .core.kind import ProblemKind
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
from .core.mechanism import Mechanism, Part, declare
from .core.model import Coordinate, LoopClosure, Model
from .core.outputs import Output
from .core.pose_checks import status_of
from .core.result import Result, ResultWarning, SolverInfo, Status
from .core.solver import SolverConfig
from .core.version import __version__
from .io.embed import ModelFunctions, model_functions
from .io.export import export_kinematics, load_exported
from .kinds.synthesis import SynthesisFormulation
from .kinds.workspace import CuboidExtras, PaperMembership
from .mechanisms import described as _described
from .mechanisms.described.spec import ClosedFormIK, Description, Joint, Leg, Parameter, Platform, Quantity
from .mechanisms.registry import build_model, mechanism_names, mechanism_type, register, unregister
from .problems.file import Problem, load_problem, problem_from_dict, solve
from .problems.overrides import apply_overrides
from .problems.registry import kind_names, problem_kind
from .problems.reproduce import Comparison, reproduce


def functions(
    source: Model | str | os.PathLike, solver: SolverConfig | None = None, *, backend: str = "auto"
) -> ModelFunctions:
    """The CasADi Functions of a model, or of the mechanism of a problem file.

    Parameters
    ----------
    source
        a [`Model`][cpm_nlp.core.model.Model] (e.g. from
        [`cpm_nlp.build_model`][cpm_nlp.mechanisms.registry.build_model]) or the path of a
        problem file (its mechanism, and its solver unless ``solver`` is given).
    solver
        tolerance and Newton options (abstol, abstolStep, max_iter) built into fk and ik
        (default: ``SolverConfig("newton")``).
    backend
        what evaluates fk, ik and jacobian called on numbers ("auto": the compiled C where a C
        compiler is available; "compiled"; "map": CasADi's virtual machine); on CasADi symbols
        they are CasADi Functions whatever the backend.
    """
    if isinstance(source, (str, os.PathLike)):
        problem = load_problem(source)
        return model_functions(problem.model, solver or problem.solver, backend=backend)
    return model_functions(source, solver, backend=backend)


def describe_mechanism(description: Description, *, register: bool = True) -> Mechanism:
    """A mechanism from a [`Description`][cpm_nlp.mechanisms.described.spec.Description] built in code (the dataclasses
    of a mechanism
    file: [`Parameter`][cpm_nlp.mechanisms.described.spec.Parameter],
    [`Platform`][cpm_nlp.mechanisms.described.spec.Platform], [`Leg`][cpm_nlp.mechanisms.described.spec.Leg],
    [`Joint`][cpm_nlp.mechanisms.described.spec.Joint] ...), generated
    and checked like a file; registered under its name unless ``register`` is false."""
    mech = _described.mechanism(description)
    return register_mechanism(mech, replace=True) if register else mech


def load_mechanism_file(path: str | os.PathLike, *, register: bool = True) -> Mechanism:
    """The mechanism a mechanism file describes (registered under its name unless ``register`` is false)."""
    mech = _described.load_file(path)
    return register_mechanism(mech, replace=True) if register else mech


#: a mechanism declared in code, with "did you mean" for a misspelt part
declare_mechanism = declare
#: add a mechanism declared in code to the registry
register_mechanism = register
#: remove a mechanism registered in code
unregister_mechanism = unregister

__all__ = [
    "AssemblyMode",
    "AssemblyModes",
    "assembly_modes",
    "Certificate",
    "certify_box",
    "ClosedFormIK",
    "Description",
    "Joint",
    "Leg",
    "Parameter",
    "Platform",
    "Quantity",
    "describe_mechanism",
    "load_mechanism_file",
    "BatchJacobians",
    "BatchResult",
    "Comparison",
    "Coordinate",
    "CpmError",
    "CuboidExtras",
    "CuboidResult",
    "DynamicsModel",
    "JointStiffness",
    "LegChains",
    "PaperMembership",
    "Part",
    "SynthesisFormulation",
    "InputError",
    "JacobianReport",
    "LoopClosure",
    "Mechanism",
    "Membership",
    "Model",
    "ModelFunctions",
    "Output",
    "PoseSolution",
    "Problem",
    "ProblemKind",
    "RequirementsReport",
    "Result",
    "ResultWarning",
    "SolverConfig",
    "SolverInfo",
    "Status",
    "__version__",
    "apply_overrides",
    "assess",
    "batch_forward_kinematics",
    "batch_inverse_kinematics",
    "batch_jacobians",
    "build_model",
    "check_box",
    "declare_mechanism",
    "export_kinematics",
    "forward_kinematics",
    "functions",
    "inscribed_cuboid",
    "inverse_kinematics",
    "jacobians",
    "joint_requirements",
    "kind_names",
    "load_exported",
    "load_problem",
    "mechanism_names",
    "mechanism_type",
    "membership",
    "passive_joints",
    "problem_from_dict",
    "problem_kind",
    "register_mechanism",
    "reproduce",
    "residual",
    "sample_workspace",
    "solve",
    "status_of",
    "unregister_mechanism",
]
