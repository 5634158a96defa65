"""Results and statuses.

Every solve returns a status.  Only ``solved`` carries numbers a user may
trust; any other status says why there is no answer, and the values of the
failed points are ``None`` (``null`` in JSON), never a number that looks right.
"""

from __future__ import annotations

import json
import math
import sys
from collections.abc import Mapping
from dataclasses import dataclass, field
from enum import Enum
from typing import Any

import numpy as np

from .origin import Origin


class Status(str, Enum):
    """Outcome of a solve (the string value is what files and JSON carry)."""

    SOLVED = "solved"
    NOT_CONVERGED = "not_converged"
    RESIDUAL_TOO_LARGE = "residual_too_large"
    WRONG_BRANCH = "wrong_branch"
    OUTSIDE_JOINT_LIMITS = "outside_joint_limits"
    UNREACHABLE = "unreachable"
    SINGULAR = "singular"
    INFEASIBLE = "infeasible"
    NOT_FINITE = "not_finite"

    def __str__(self) -> str:
        return self.value

    @property
    def ok(self) -> bool:
        return self is Status.SOLVED


#: Human explanation of each status (printed by the CLI, stored in results).
STATUS_TEXT = {
    Status.SOLVED: "converged; residual, assembly branch and joint limits checked",
    Status.NOT_CONVERGED: "the solver did not converge",
    Status.RESIDUAL_TOO_LARGE: "the solver stopped but the loop-closure residual is above tolerance",
    Status.WRONG_BRANCH: "the solution lies on another assembly branch than the one the model designates",
    Status.OUTSIDE_JOINT_LIMITS: "the pose needs a joint outside its declared limits",
    Status.UNREACHABLE: "the pose cannot be assembled (no real solution of the loop closures)",
    Status.SINGULAR: "the pose is singular (the loop-closure Jacobian is rank deficient)",
    Status.INFEASIBLE: "the problem has no feasible point",
    Status.NOT_FINITE: "a computed value is not finite (an overflow, a division by zero or a NaN)",
}


def worst_status(statuses: list[Status]) -> Status:
    """The overall status of a batch: solved only if every point is solved."""
    for s in statuses:
        if not s.ok:
            return s
    return Status.SOLVED


@dataclass
class SolverInfo:
    """Which solver ran, how many iterations (summed over points) and how long."""

    name: str
    iterations: int = 0
    seconds: float = 0.0

    def to_dict(self) -> dict[str, Any]:
        return {"name": self.name, "iterations": int(self.iterations), "seconds": float(self.seconds)}


def jsonable(value: Any) -> Any:  # noqa: C901 - one branch per kind of value
    """A copy of ``value`` that :func:`json.dumps` writes with ``allow_nan=False``, at any
    depth: numpy arrays and scalars to lists and numbers, non-finite floats (NaN, inf) to
    None (as an integer too large for any float), mapping keys to strings, enums to their
    values, anything else to its text."""
    if isinstance(value, Enum):
        return jsonable(value.value)
    if value is None or isinstance(value, (bool, str)):
        return value
    if isinstance(value, (np.bool_,)):
        return bool(value)
    if isinstance(value, (int, np.integer)):
        return int(value) if abs(int(value)) <= sys.float_info.max else None  # no float holds it
    if isinstance(value, (float, np.floating)):
        v = float(value)
        return v if math.isfinite(v) else None
    if isinstance(value, (complex, np.complexfloating)):
        return jsonable(value.real) if value.imag == 0 else str(value)
    if isinstance(value, np.ndarray):
        return jsonable(value.tolist())
    if isinstance(value, Mapping):
        return {k if isinstance(k, str) else str(jsonable(k)): jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple, set, frozenset)):
        return [jsonable(v) for v in value]
    return str(value)


@dataclass
class ResultWarning:
    """A result outside its model's validity: the numbers are given, and why
    they should not be trusted as they stand (a stress above the material's
    yield, a deflection beyond the hinge formula's range, a pose near a
    singularity ...).

    code: a stable identifier (see :data:`WARNING_CODES`); message: one line for
    a person; where: what it is about (a hinge, a value, a key path); value and
    limit: the number found and the bound it broke (SI), where there are such.
    """

    code: str
    message: str
    where: str = ""
    value: float | None = None
    limit: float | None = None

    def to_dict(self) -> dict[str, Any]:
        return {
            "code": self.code,
            "message": self.message,
            "where": self.where,
            "value": jsonable(self.value),
            "limit": jsonable(self.limit),
        }

    @classmethod
    def from_dict(cls, d: Any) -> ResultWarning:
        """A warning read back from a result's JSON (tolerant: a damaged entry keeps its text)."""
        if not isinstance(d, dict):
            return cls("unknown", str(d))

        def num(v: Any) -> float | None:
            return float(v) if isinstance(v, (int, float)) and not isinstance(v, bool) else None

        return cls(
            str(d.get("code", "unknown")),
            str(d.get("message", "")),
            str(d.get("where", "") or ""),
            num(d.get("value")),
            num(d.get("limit")),
        )

    def __str__(self) -> str:
        return self.message


#: Codes of :class:`ResultWarning` (docs/site/howto/read-status.md lists them).
WARNING_CODES = {
    "stress_above_yield": "a hinge stress above its material's yield strength",
    "stress_above_allowable": "a hinge stress above the allowable (design) stress",
    "deflection_beyond_formula": "a hinge deflection beyond the range of its stiffness formula",
    "hinge_geometry": "a hinge geometry outside its formula's validity",
    "beyond_linear_range": "compliant FK: linear and nonlinear deflection differ by more than 10 %",
    "near_singular": "a pose near a singularity (ill-conditioned Jacobian)",
    "strokes_partly_assemble": "part of the stroke box does not assemble: the workspace is the image of the rest",
}


@dataclass
class Result:
    """The answer to one problem.

    values:
        SI numbers (or lists of them) under the papers' symbols.
    units:
        SI unit of each value ("m", "rad", "" ...).
    dimensions:
        dimension of each value ("length", "angle", ...), used for printing.
    """

    problem: str
    status: Status
    values: dict[str, Any] = field(default_factory=dict)
    units: dict[str, str] = field(default_factory=dict)
    dimensions: dict[str, str] = field(default_factory=dict)
    solver: SolverInfo = field(default_factory=lambda: SolverInfo("none"))
    message: str = ""
    statuses: list[Status] | None = None  # per point, for batches
    model: dict[str, Any] = field(default_factory=dict)  # parameters used, SI
    #: where the numbers are outside their model's validity (empty when clean)
    warnings: list[ResultWarning] = field(default_factory=list)
    #: where the mechanism came from (recorded as ``origin``; None: not known, e.g. a model built in code)
    origin: Origin | None = None

    @property
    def ok(self) -> bool:
        return self.status.ok

    def warn(self, *warnings: ResultWarning) -> Result:
        """Add warnings (one per code and place: a repeated one is kept once)."""
        seen = {(w.code, w.where) for w in self.warnings}
        for w in warnings:
            if (w.code, w.where) not in seen:
                seen.add((w.code, w.where))
                self.warnings.append(w)
        return self

    def to_dict(self) -> dict[str, Any]:
        out: dict[str, Any] = {
            "problem": self.problem,
            "status": self.status.value,
            "values": jsonable(self.values),
            "solver": self.solver.to_dict(),
            "message": self.message,
            "units": jsonable(dict(self.units)),
        }
        if self.statuses is not None:
            out["statuses"] = [s.value for s in self.statuses]
        if self.model:
            out["model"] = jsonable(self.model)
        if self.origin is not None:
            out["origin"] = jsonable(self.origin.to_dict())
        out["warnings"] = [w.to_dict() for w in self.warnings]
        return out

    def to_json(self, indent: int | None = 2) -> str:
        return json.dumps(jsonable(self.to_dict()), indent=indent, allow_nan=False)
