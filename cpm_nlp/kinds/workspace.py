"""Workspace problem kinds: ``inscribed_cuboid`` and ``workspace``.

Both work for any mechanism from its loop closures and joint limits (see
`cpm_nlp.analysis.workspace`).  A mechanism may add to them through
two parts declared here ([`Part`][cpm_nlp.core.mechanism.Part]), which a
mechanism registers in ``Mechanism.parts``:

* ``cuboid`` ([`CuboidExtras`][cpm_nlp.kinds.workspace.CuboidExtras]): extra inputs and values of the cuboid
  found, e.g. the paper's names for it and the paper's own formulation;
* ``paper_membership`` ([`PaperMembership`][cpm_nlp.kinds.workspace.PaperMembership]): a closed-form membership
  test from the paper, reported beside the general one.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any, ClassVar

import numpy as np

from ..analysis.certify import CERTIFICATE_DIMENSIONS, CERTIFY_OPTION, certificate_values
from ..analysis.compliance import JointStiffness
from ..analysis.workspace import (
    ADDED_PER_ROUND,
    CHECK_OPTION,
    DEFAULT_NLP_SAMPLES,
    EXTRA_SLOTS,
    check_grid_sizes,
    inscribed_cuboid,
    membership,
    workspace_cloud,
)
from ..core.errors import InputError
from ..core.kind import ProblemKind, broadcast, require_ipopt
from ..core.mechanism import MechanismDeclarationError, Part
from ..core.model import Model
from ..core.multistart import start_options
from ..core.options import Option
from ..core.outputs import Output, declared_for, declared_result, outputs_of, size
from ..core.result import Result, SolverInfo, Status
from ..core.solver import SolverConfig
from ..core.units import size_dimension
from .hinge_inputs import stress_limit_option
from .kinematic import _model_info


@dataclass(frozen=True, kw_only=True)
class CuboidExtras(Part):
    """What a mechanism adds to the ``inscribed_cuboid`` kind (the part ``cuboid``).

    Attributes
    ----------
    options
        extra inputs of the kind for this mechanism.
    outputs
        the extra values, all of them, declared ([`Output`][cpm_nlp.core.result.Output]: name,
        dimension, unit text where the dimension has no SI unit); set to null when no cuboid was
        found.
    values
        ``(model, lower, upper, inputs, solver) -> values`` for a found box ``lower <= t <=
        upper`` (SI, task coordinates), each of a declared output.
    paper_box
        optional ``(values) -> (lower, upper, label) | None``: the box of the paper's own
        formulation read from a result's values, drawn beside the found one by the workspace
        plot (None when the result has none).
    """

    capability: ClassVar[str] = "cuboid"

    options: tuple[Option, ...] = ()
    outputs: tuple[Output, ...] = ()
    values: Callable[..., dict[str, Any]]
    paper_box: Callable[[Mapping[str, Any]], Any] | None = None

    def __post_init__(self) -> None:
        if not isinstance(self.options, tuple) or not all(isinstance(o, Option) for o in self.options):
            raise MechanismDeclarationError(f"cuboid: options must be a tuple of Option, got {self.options!r:.60}")
        if not isinstance(self.outputs, tuple) or not all(isinstance(o, Output) and not o.family for o in self.outputs):
            raise MechanismDeclarationError(f"cuboid: outputs must be a tuple of Output, got {self.outputs!r:.60}")
        if not callable(self.values) or not (self.paper_box is None or callable(self.paper_box)):
            raise MechanismDeclarationError("cuboid: values must be callable, and paper_box callable or None")

    @property
    def value_names(self) -> tuple[str, ...]:
        """The names of `outputs`."""
        return tuple(o.name for o in self.outputs)


@dataclass(frozen=True)
class PaperMembership(Part):
    """The paper's closed-form workspace membership (the part ``paper_membership``),
    reported by the ``workspace`` kind beside the general test.

    test: ``(model, points (N, nq)) -> (inside (N,), margins)``.
    """

    capability: ClassVar[str] = "paper_membership"

    test: Callable[[Any, Any], tuple[Any, dict]]

    def __post_init__(self) -> None:
        if not callable(self.test):
            raise MechanismDeclarationError(f"paper_membership must be callable, got {self.test!r:.60}")


def _declared(model: Model, dims: Mapping[str, str]) -> list[Output]:
    """The outputs of the workspace kinds by their dimensions: no unit for what has none, a
    margin's of the binding quantity, a task box's size by its sides."""
    kinds = [model.closure.x[i].kind for i in model.closure.task_index]
    return [size(o.name, kinds) if o.dimension == "task volume" else o for o in outputs_of(dims, named=False)]


def _region_options(model: Model) -> list[Option]:
    c = model.closure
    return [
        Option(
            f"{c.x[i].name}_range",
            c.x[i].kind,
            f"search region of {c.x[i].name} [low, high] (default: probed around the home pose)",
            default=None,
            shape="range",
        )
        for i in c.task_index
    ]


def _region(inputs: Mapping[str, Any], model: Model, path: tuple) -> tuple[np.ndarray, np.ndarray] | None:
    names = [f"{t}_range" for t in model.closure.task]
    given = [n for n in names if inputs.get(n) is not None]
    if not given:
        return None
    if len(given) != len(names):
        missing = [n for n in names if n not in given]
        raise InputError(f"give a search range for every task coordinate; missing {', '.join(missing)}", path=path)
    return np.array([inputs[n][0] for n in names]), np.array([inputs[n][1] for n in names])


def _volume_dimension(model: Model) -> tuple[str, str]:
    """Dimension and SI unit of the size of a box in the task coordinates: a length, an
    area or a volume by the number of translational task coordinates, times the angles'
    (`size_dimension`)."""
    return size_dimension(model.closure.x[i].kind for i in model.closure.task_index)


class InscribedCuboid(ProblemKind):
    name = "inscribed_cuboid"
    #: its extra inputs and values; the hinges, the defaults of ``stress_limit``
    parts = (CuboidExtras, JointStiffness)
    description = "largest axis-aligned box of task coordinates inside the reachable workspace (IPOPT, multi-start)"
    plots = ("workspace",)

    def input_options(self, model: Model) -> list[Option]:
        rounds = EXTRA_SLOTS // ADDED_PER_ROUND
        opts = start_options() + [
            Option(
                "samples_per_edge",
                "int",
                "sample points per box edge in the NLP (odd keeps face centres; default: 5 for up to 3 task "
                f"coordinates, fewer above, at most {DEFAULT_NLP_SAMPLES} samples)",
                default=None,
                lower=2,
                upper=9,
            ),
            CHECK_OPTION,
            CERTIFY_OPTION,
            Option(
                "refinements",
                "int",
                "exchange rounds that add outside points of the check to the NLP",
                default=rounds,
                lower=0,
                upper=rounds,
            ),
            Option(
                "installation_volume",
                "volume",
                "installation volume of the mechanism; gives ratio = volume / installation_volume",
                default=None,
                lower=0.0,
                strict=True,
            ),
        ]
        opts += _region_options(model)
        extras = self.part(model, CuboidExtras)
        opts += list(extras.options) if extras else []
        return opts + [stress_limit_option(model)]

    def check_inputs(self, inputs: dict[str, Any], model: Model, path: tuple) -> None:
        _region(inputs, model, path)
        check_grid_sizes(model.closure.nq, inputs["samples_per_edge"], inputs["check_per_edge"], path)

    def check_solver(self, solver: SolverConfig) -> None:
        require_ipopt(solver, self.name)

    def outputs(self, model: Model) -> list[Output]:
        """The box (each task coordinate's bounds, its size), the starts, the membership check,
        the certificate and the mechanism's own values (its part ``cuboid``)."""
        c = model.closure
        dims: dict[str, str] = {}
        for i in c.task_index:
            dims[f"{c.x[i].name}_min"] = dims[f"{c.x[i].name}_max"] = c.x[i].kind
        dims["volume"] = _volume_dimension(model)[0]
        dims |= dict.fromkeys(
            ("ratio", "starts", "starts_converged", "starts_agreed", "refinements", "shrink"), "dimensionless"
        )
        dims |= {"check_points": "dimensionless", "check_outside": "dimensionless", "check_margin": "si"}
        dims |= {"check_binding": "text", **CERTIFICATE_DIMENSIONS}
        extras = self.part(model, CuboidExtras)
        return _declared(model, dims) + list(extras.outputs if extras else ())

    def run(self, model: Model, inputs: Mapping[str, Any], solver: SolverConfig) -> Result:
        model = inputs.get("stress_limit") or model
        require_ipopt(solver, self.name)
        c = model.closure
        res = inscribed_cuboid(
            model,
            solver,
            starts=inputs["starts"],
            seed=inputs["seed"],
            samples_per_edge=inputs["samples_per_edge"],
            check_per_edge=inputs["check_per_edge"],
            refinements=inputs["refinements"],
            region=_region(inputs, model, ("inputs",)),
        )
        vdim = _volume_dimension(model)[0]
        values: dict[str, Any] = {}
        for k, t in enumerate(c.task):
            values[f"{t}_min"] = float(res.lower[k]) if res.found else None
            values[f"{t}_max"] = float(res.upper[k]) if res.found else None
        values["volume"] = res.volume
        vol_inst = inputs.get("installation_volume")
        if vol_inst is not None:
            values["ratio"] = res.volume / vol_inst if res.found and vdim == "volume" else None
        values.update(
            starts=res.starts,
            starts_converged=res.converged,
            starts_agreed=res.agreed,
            refinements=res.refinements,
            shrink=res.shrink if res.found else None,
        )
        chk = res.check
        values.update(
            check_points=chk.points if chk else None,
            check_outside=chk.outside if chk else None,
            check_margin=chk.margin if chk else None,
            check_binding=chk.binding if chk else None,
        )
        lower, upper = (res.lower, res.upper) if res.found else (None, None)
        values.update(certificate_values(model, lower, upper, inputs["certify"])[0])
        extras = self.part(model, CuboidExtras)
        if extras is not None and res.found:
            values.update(extras.values(model, res.lower, res.upper, dict(inputs), solver))
        if not res.found:  # no numbers that look like an answer
            keep = ("starts", "starts_converged")
            values = {k: (v if k in keep else None) for k, v in values.items()}
            values.update({k: None for k in (extras.value_names if extras else ())})
        status = Status.SOLVED if res.found else (Status.INFEASIBLE if res.infeasible else Status.NOT_CONVERGED)
        message = res.message
        if res.found:
            message += (
                f"; membership check: {chk.points} points of its faces, edges and interior, "
                f"all inside (worst margin {chk.margin:.3g}, {chk.binding})"
            )
            if values.get("certificate"):
                message += f"; {values['certificate']}"
        return declared_result(
            self.name,
            status,
            declared_for(self.name, self.outputs(model), values),
            values,
            solver=SolverInfo("ipopt", res.iterations, res.seconds),
            message=message,
            model=_model_info(model),
        )


class Workspace(ProblemKind):
    name = "workspace"
    #: the paper's membership test; the hinges, the defaults of ``stress_limit``
    parts = (PaperMembership, JointStiffness)
    description = "membership of given points and a seeded point cloud of the reachable workspace"
    plots = ("workspace",)

    def input_options(self, model: Model) -> list[Option]:
        c = model.closure
        opts = [
            Option(c.x[i].name, c.x[i].kind, f"points to test: {c.x[i].description}", default=None, shape="grid")
            for i in c.task_index
        ]
        opts += [
            Option("samples", "int", "points drawn for the point cloud (0: none)", default=0, lower=0, upper=200_000),
            Option("seed", "int", "seed of the point cloud", default=0, lower=0, upper=2**32 - 1),
        ]
        return opts + _region_options(model) + [stress_limit_option(model)]

    def check_inputs(self, inputs: dict[str, Any], model: Model, path: tuple) -> None:
        _region(inputs, model, path)
        task = list(model.closure.task)
        have = [t for t in task if inputs.get(t) is not None]
        if have and len(have) != len(task):
            raise InputError(f"give every task coordinate of the points to test: {', '.join(task)}", path=path)
        if not have and not inputs["samples"]:
            raise InputError(f"give points to test ({', '.join(task)}) or samples > 0 for a point cloud", path=path)
        if have:
            broadcast([inputs[t] for t in task], task, path)

    def outputs(self, model: Model) -> list[Output]:
        """Membership of the given points (inside, status, margin, binding, the paper's own
        test where the mechanism has one), then the cloud, its volume estimate and region."""
        c = model.closure
        task = [c.x[i] for i in c.task_index]
        dims = dict.fromkeys(("inside", "status"), "text") | {"margin": "si", "binding": "text", "inside_paper": "text"}
        dims |= dict.fromkeys(("count_inside", "count_undecided"), "dimensionless")
        dims |= {f"cloud_{x.name}": x.kind for x in task}
        dims |= dict.fromkeys(("cloud_count", "cloud_undecided"), "dimensionless")
        dims |= dict.fromkeys(
            ("volume_estimate", "volume_estimate_error", "volume_estimate_upper"), _volume_dimension(model)[0]
        )
        return _declared(model, dims | {f"{x.name}_range": x.kind for x in task})

    def run(self, model: Model, inputs: Mapping[str, Any], solver: SolverConfig) -> Result:
        model = inputs.get("stress_limit") or model
        c = model.closure
        task = list(c.task)
        values: dict[str, Any] = {}
        dims: dict[str, str] = {}
        if inputs.get(task[0]) is not None:
            T, _batch = broadcast([inputs[t] for t in task], task, ("inputs",))
            mem = membership(model, T, solver)
            values["inside"] = mem.inside.tolist()
            values["status"] = list(mem.status)
            values["margin"] = [float(m) if np.isfinite(m) else None for m in mem.margin]
            values["binding"] = mem.binding
            values["count_inside"] = int(np.count_nonzero(mem.inside))
            values["count_undecided"] = mem.count_undecided
            dims.update(
                inside="text",
                status="text",
                margin="si",
                binding="text",
                count_inside="dimensionless",
                count_undecided="dimensionless",
            )
            paper = self.part(model, PaperMembership)
            if paper is not None:
                values["inside_paper"] = paper.test(model, T)[0].tolist()
                dims["inside_paper"] = "text"
        status, message = Status.SOLVED, ""
        if inputs["samples"]:
            cloud = workspace_cloud(model, inputs["samples"], inputs["seed"], _region(inputs, model, ()), solver)
            if cloud.region is None:
                status = Status.INFEASIBLE
                message = "the home configuration is outside the workspace; give a search region (<task>_range)"
            else:
                vdim = _volume_dimension(model)[0]
                for k, t in enumerate(task):
                    values[f"cloud_{t}"] = cloud.points[:, k].tolist()
                    values[f"{t}_range"] = [float(cloud.region[0][k]), float(cloud.region[1][k])]
                    dims[f"cloud_{t}"] = dims[f"{t}_range"] = c.x[c.task_index[k]].kind
                values["cloud_count"] = len(cloud.points)
                values["cloud_undecided"] = cloud.undecided
                values["volume_estimate"] = cloud.volume
                values["volume_estimate_error"] = cloud.volume_error
                values["volume_estimate_upper"] = cloud.volume_upper
                dims.update(cloud_count="dimensionless", cloud_undecided="dimensionless")
                dims["volume_estimate"] = dims["volume_estimate_upper"] = dims["volume_estimate_error"] = vdim
                message = (
                    f"{cloud.inside} of {cloud.drawn} points of the search region inside, "
                    f"{cloud.drawn - cloud.inside - cloud.undecided} outside, {cloud.undecided} undecided; "
                    f"volume_estimate's standard error (Monte Carlo) is {cloud.volume_error:.3g}"
                )
                if cloud.undecided:
                    message += " (volume_estimate counts them outside, volume_estimate_upper inside)"
        if values.get("status") is not None and mem.count_undecided:
            message = (message + "; " if message else "") + (
                f"{mem.count_undecided} of {len(mem.status)} given points undecided (no pose on the designated "
                "branch found from any start)"
            )
        return declared_result(
            self.name,
            status,
            _declared(model, dims),
            values,
            solver=SolverInfo(solver.name),
            message=message,
            model=_model_info(model),
        )
