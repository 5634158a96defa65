"""Results and statuses.

Every solve returns a status.  Only ``solved`` carries numbers a user may
trust; any other status says why there is no answer, and the values of the
failed points are ``None`` (``null`` in JSON), never a number that looks right.
"""

from __future__ import annotations

import dataclasses
import json
import math
import re
import sys
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass
from enum import Enum
from types import MappingProxyType
from typing import Any

import numpy as np

from .finite import nonfinite_paths, nulled
from .origin import Origin
from .units import result_unit


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
STATUS_TEXT: Mapping[Status, str] = MappingProxyType(
    {
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
)


def worst_status(statuses: list[Status]) -> Status:
    """The overall status of a batch: solved only if every point is solved."""
    for s in statuses:
        if not s.ok:
            return s
    return Status.SOLVED


@dataclass
class SolverInfo:
    """Which solver ran, how many iterations (summed over points; None where the method
    does not count them: a compiled Newton kernel) and how long the solve took
    (``seconds``), apart from the time spent building what it ran the first time
    (``build_seconds``: the symbolic construction and compilation of a kernel, once per
    process).  ``path``: which formulation of the Newton FK answered ("closed": the
    closed form, no iterations; "reduced": Newton on the task coordinates through the
    closed-form IK; "full": Newton on the loop closures), "" for the others."""

    name: str
    iterations: int | None = None  # not counted unless a kind says how many
    seconds: float = 0.0
    build_seconds: float = 0.0
    path: str = ""

    def to_dict(self) -> dict[str, Any]:
        return {
            "name": self.name,
            "iterations": None if self.iterations is None else int(self.iterations),
            "seconds": float(self.seconds),
            "build_seconds": float(self.build_seconds),
            "path": self.path or None,
        }


def poses_solver_info(sols: Sequence[Any], fallback: str) -> SolverInfo:
    """The solver of solved poses ([`cpm_nlp.core.kinematics.PoseSolution`][cpm_nlp.core.kinematics.PoseSolution]): its
    name,
    iterations (None where a compiled kernel answered without counting them), the solve time
    and, apart, the time spent building the kernel, and the Newton FK's path."""
    names = sorted({s.solver for s in sols if s.solver}) or [fallback]
    counted = all(s.details.get("iterations_counted", True) for s in sols)
    return SolverInfo(
        "+".join(names),
        sum(s.iterations for s in sols) if counted else None,
        sum(s.seconds for s in sols),
        sum(float(s.details.get("build_seconds", 0.0)) for s in sols),
        "+".join(sorted({s.path for s in sols if s.path})),
    )


def _bounded_int(value: Any) -> int | None:
    return int(value) if abs(int(value)) <= sys.float_info.max else None  # no float holds it


def _finite_float(value: Any) -> float | None:
    v = float(value)
    return v if math.isfinite(v) else None


def _real_or_text(value: Any) -> Any:
    return jsonable(value.real) if value.imag == 0 else str(value)


def _json_mapping(value: Mapping) -> dict[str, Any]:
    return {k if isinstance(k, str) else str(jsonable(k)): jsonable(v) for k, v in value.items()}


#: (types, conversion) in the order tried: the first that fits converts (an enum before
#: the str it may be, a bool before the int it is)
_JSON_CONVERSIONS: tuple[tuple[Any, Any], ...] = (
    (Enum, lambda v: jsonable(v.value)),
    ((type(None), bool, str), lambda v: v),
    (np.bool_, bool),
    ((int, np.integer), _bounded_int),
    ((float, np.floating), _finite_float),
    ((complex, np.complexfloating), _real_or_text),
    (np.ndarray, lambda v: jsonable(v.tolist())),
    (Mapping, _json_mapping),
    ((list, tuple, set, frozenset), lambda v: [jsonable(x) for x in v]),
)


def jsonable(value: Any) -> Any:
    """A copy of ``value`` that `json.dumps` writes with ``allow_nan=False``, at any
    depth: numpy arrays and scalars to lists and numbers, non-finite floats (NaN, inf) to
    None (as an integer too large for any float), mapping keys to strings, enums to their
    values, anything else to its text."""
    for types, convert in _JSON_CONVERSIONS:
        if isinstance(value, types):
            return convert(value)
    return str(value)


@dataclass
class ResultWarning:
    """A result outside its model's validity: the numbers are given, and why
    they should not be trusted as they stand (a stress above the material's
    yield, a deflection beyond the hinge formula's range, a pose near a
    singularity ...).

    Attributes
    ----------
    code
        a stable identifier (see `WARNING_CODES`);
    message
        one line for a person;
    where
        what it is about (a hinge, a value, a key path); value and
    limit
        the number found and the bound it broke (SI), where there are such.
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


#: Codes of `ResultWarning` (docs/site/howto/read-status.md lists them).
WARNING_CODES: Mapping[str, str] = MappingProxyType(
    {
        "stress_above_yield": "a hinge stress above its material's yield strength",
        "stress_above_allowable": "a hinge stress above the allowable (design) stress",
        "deflection_beyond_formula": "a hinge deflection beyond the range of its stiffness formula",
        "hinge_geometry": "a hinge geometry outside its formula's validity",
        "beyond_linear_range": "compliant FK: linear and nonlinear deflection differ by more than 10 %",
        "near_singular": "a pose near a singularity (ill-conditioned Jacobian)",
        "strokes_partly_assemble": "part of the stroke box does not assemble: the workspace is the image of the rest",
    }
)


#: what an output is: one number per point ("value"), a number relative to another
#: output ("reference", ``refers_to`` names it), a matrix whose rows and columns the
#: unit text describes ("matrix"), a free text ("text")
ROLES = ("value", "reference", "matrix", "text")


#: a field of a family's name ("stress_{group}")
_FIELD = re.compile(r"\{(\w+)\}")


@dataclass(frozen=True)
class Output:
    """One value a kind returns, declared once.

    per: a **family** of outputs, one per item of what ``per`` names (a hinge group of the
    problem's hinges): its name has fields in braces (``stress_{group}``), and each member
    ([`member`][cpm_nlp.core.result.Output.member]) is an output of the family's dimension, role and unit.  A kind
    declares
    the family; a [`Result`][cpm_nlp.core.result.Result] declares only its members.

    when: the input that asks for this output where the kind returns it only then
    ("assembly_modes: all"); such an output is not among the kind's default names (a
    sweep's columns, [`output_names`][cpm_nlp.core.kind.ProblemKind.output_names]).

    Attributes
    ----------
    name
        its name in the result (the papers' symbol);
    dimension
        "length", "angle" ... (or "matrix", "vector", "text" for what has no SI unit);
    role
        one of `ROLES`;
    refers_to
        the output a "reference" is taken from (x0 of an offset dx);
    unit
        the unit text where the dimension's SI unit does not say it (a matrix's rows and
        columns).
    """

    name: str
    dimension: str
    role: str = "value"
    refers_to: str = ""
    unit: str | None = None
    per: str = ""
    when: str = ""

    def __post_init__(self) -> None:
        if self.role not in ROLES:
            raise ValueError(f"output {self.name!r}: role must be one of {', '.join(ROLES)}, got {self.role!r}")
        if (self.role == "reference") != bool(self.refers_to):
            raise ValueError(f"output {self.name!r}: a 'reference' output, and only it, names what it refers_to")
        if bool(self.per) != bool(_FIELD.search(self.name)) or "{" in _FIELD.sub("", self.name):
            raise ValueError(f"output {self.name!r}: a family (per=...), and only it, has fields in braces in its name")

    @property
    def si(self) -> str:
        """The unit the result writes (`result_unit` unless given)."""
        return self.unit if self.unit is not None else result_unit(self.dimension)

    @property
    def family(self) -> bool:
        return bool(self.per)

    def member(self, **fields: str) -> Output:
        """The output of a family for the given fields (``group="leaf"`` -> ``stress_leaf``)."""
        if not self.family:
            raise ValueError(f"output {self.name!r} is no family")
        return dataclasses.replace(self, name=self.name.format(**fields), per="")

    def covers(self, output: Output) -> bool:
        """Whether ``output`` is this declaration: the same output, or a member of this family."""
        if not self.family:
            return output == self
        pattern = "".join("(.+)" if k % 2 else re.escape(part) for k, part in enumerate(_FIELD.split(self.name)))
        return re.fullmatch(pattern, output.name) is not None and output == dataclasses.replace(
            self, name=output.name, per=""
        )


@dataclass(frozen=True)
class Entry:
    """A value of a result with its declaration (its unit and dimension are the declaration's)."""

    output: Output
    value: Any


class Result:
    """The answer to one problem.

    A result holds the outputs its kind declared ([`Output`][cpm_nlp.core.result.Output]: name, dimension, role,
    in the declared order) and the values computed for them (in the order computed); a
    value is always of a declared output, so its unit and dimension cannot disagree with
    it. ``values``, ``units`` and ``dimensions`` are read-only views of the two:

    An output may be declared and have no value (one not computed, or left out by a
    problem's ``outputs``): its unit is still written.

    Attributes
    ----------
    values
        SI numbers (or lists of them) under the papers' symbols.
    units
        SI unit of each declared output ("m", "rad", "" ...).
    dimensions
        dimension of each declared output ("length", "angle", ...), used for printing.
    """

    def __init__(
        self,
        problem: str,
        status: Status,
        outputs: Sequence[Output] = (),
        values: Mapping[str, Any] | None = None,
        *,
        solver: SolverInfo | None = None,
        message: str = "",
        statuses: list[Status] | None = None,
        model: Mapping[str, Any] | None = None,
        warnings: Sequence[ResultWarning] = (),
        origin: Origin | None = None,
    ) -> None:
        if isinstance(outputs, Mapping):  # the values, as Result took them before it held its outputs
            raise TypeError(
                f"{problem}: a Result takes its declared outputs (a sequence of Output), then the values; "
                "build it with cpm_nlp.core.outputs.declared_result"
            )
        self.problem = problem
        self.status = status
        self._outputs: dict[str, Output] = {}
        self._values: dict[str, Any] = {}
        self.declare(outputs)
        self.set(values or {})
        self.solver = solver or SolverInfo("none")
        self.message = message
        #: per point, for batches
        self.statuses = statuses
        #: parameters used, SI
        self.model: dict[str, Any] = dict(model or {})
        #: where the numbers are outside their model's validity (empty when clean)
        self.warnings: list[ResultWarning] = list(warnings)
        #: where the mechanism came from (recorded as ``origin``; None: not known, e.g. a model built in code)
        self.origin = origin

    def __repr__(self) -> str:
        return f"Result({self.problem!r}, {self.status.value}, {dict(self._values)!r}, message={self.message!r})"

    def _key(self) -> tuple:
        return (
            self.problem,
            self.status,
            self.outputs,
            self._values,
            self.solver,
            self.message,
            self.statuses,
            self.model,
            self.warnings,
            self.origin,
        )

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Result) and self._key() == other._key()

    __hash__ = None  # type: ignore[assignment]  # mutable, as the dataclass it was

    # -- the declaration and the values ------------------------------------------------------

    def declare(self, outputs: Sequence[Output]) -> Result:
        """Add declared outputs (after those declared so far); a name is declared once."""
        families = [o.name for o in outputs if o.family]
        if families:
            raise ValueError(
                f"{self.problem}: {', '.join(map(repr, families))} is a family of outputs; a result declares its "
                "members (Output.member)"
            )
        names = [o.name for o in outputs]
        twice = sorted({n for n in names if n in self._outputs or names.count(n) > 1})
        if twice:
            raise ValueError(f"{self.problem}: output {', '.join(map(repr, twice))} is declared twice")
        self._outputs.update((o.name, o) for o in outputs)
        return self

    def set(self, values: Mapping[str, Any]) -> Result:
        """Set values of declared outputs (a new one after the others, a known one in its place)."""
        undeclared = [k for k in values if k not in self._outputs]
        if undeclared:
            raise ValueError(f"{self.problem}: value(s) of no declared output: {', '.join(map(str, undeclared))}")
        self._values.update(values)
        return self

    def keep(self, names: Iterable[str]) -> Result:
        """Keep only the values of ``names`` (the declarations stay, with their units)."""
        keep = set(names)
        self._values = {k: v for k, v in self._values.items() if k in keep}
        return self

    @property
    def outputs(self) -> tuple[Output, ...]:
        """The declared outputs, in the declared order."""
        return tuple(self._outputs.values())

    @property
    def entries(self) -> Mapping[str, Entry]:
        """Each value with its declaration, in the order computed."""
        return MappingProxyType({k: Entry(self._outputs[k], v) for k, v in self._values.items()})

    @property
    def values(self) -> Mapping[str, Any]:
        return MappingProxyType(self._values)

    @property
    def units(self) -> Mapping[str, str]:
        return MappingProxyType({n: o.si for n, o in self._outputs.items()})

    @property
    def dimensions(self) -> Mapping[str, str]:
        return MappingProxyType({n: o.dimension for n, o in self._outputs.items()})

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
            "values": jsonable(self._values),
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


def finite_status(result: Result) -> Result:
    """``result`` with no non-finite number in its values: each becomes None, and a result
    that said ``solved`` says ``not_finite`` instead, naming the values (a NaN or an inf is
    never an answer)."""
    bad = nonfinite_paths(result.values)
    if not bad:
        return result
    result.set(
        {k: nulled(v) for k, v in result.values.items() if any(b == k or b.startswith((f"{k}[", f"{k}.")) for b in bad)}
    )
    shown = ", ".join(bad[:5]) + (f" and {len(bad) - 5} more" if len(bad) > 5 else "")
    note = f"not finite (an overflow, a division by zero or a NaN): {shown}"
    if result.status is Status.SOLVED:
        result.status = Status.NOT_FINITE
    result.message = f"{note}; {result.message}" if result.message else note
    return result
