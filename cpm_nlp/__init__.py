"""cpm_nlp: kinematics and design of compliant parallel mechanisms with CasADi and IPOPT.

Quick start::

    import cpm_nlp as cn
    model = cn.build_model("prs3", {"b": "47.91 mm", "L": "109.215 mm", "alpha0": "45 deg"})
    pose = cn.forward_kinematics(model, [1e-3, 0.5e-3, -0.3e-3])
    pose.status, pose.x          # Status.SOLVED, (px, py, pz, psi, theta, phi) in SI

or, from a problem file::

    result = cn.solve(cn.load_problem("problems/prs3_forward_kinematics.yaml"))
"""

import importlib
import logging

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

__version__ = "0.1.0"

logging.getLogger(__name__).addHandler(logging.NullHandler())


def __getattr__(name: str) -> object:
    """The public API, imported on first use (PEP 562): ``import cpm_nlp`` and the
    ``cpm-nlp`` command line start without loading numpy, CasADi and the solvers
    until a name of :mod:`cpm_nlp.api` is used."""
    if name in __all__:
        value = getattr(importlib.import_module(".api", __name__), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))
