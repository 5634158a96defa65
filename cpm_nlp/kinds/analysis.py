"""Problem kinds beyond pose solving: actuator workspace and dynamics.

* ``actuator_workspace`` -- the reachable workspace under the actuator strokes
  (`cpm_nlp.analysis.workspace`);
* ``dynamics`` -- M, K, G of Lagrange's equations and the natural
  frequencies (`cpm_nlp.analysis.dynamics`), for mechanisms with a dynamic model.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from ..analysis import dynamics as dyn
from ..analysis.compliance import JointStiffness
from ..analysis.dynamics import DynamicsModel
from ..analysis.flexure import material_node
from ..analysis.workspace import joint_box, reachable_workspace
from ..core.errors import InputError
from ..core.kind import ProblemKind
from ..core.model import Model
from ..core.options import REQUIRED, Option
from ..core.outputs import Output, declared_result, matrix, outputs_of, vector
from ..core.result import Result, ResultWarning, SolverInfo, Status
from ..core.solver import SolverConfig
from ..core.units import DIMENSIONS, result_unit, size_dimension
from .hinge_inputs import mass_node, stress_limit_option
from .kinematic import _model_info


def closed_form_result(
    kind: str,
    model: Model,
    values: dict,
    outputs: Mapping[str, str] | Sequence[Output],
    status=Status.SOLVED,
    message="",
    solver=None,
):
    """The result of a closed-form kind: its outputs declared (or given by their dimensions)."""
    return declared_result(
        kind,
        status,
        outputs_of(outputs) if isinstance(outputs, Mapping) else outputs,
        values,
        solver=solver or SolverInfo("closed_form"),
        message=message,
        model=_model_info(model),
    )


# -- workspace ------------------------------------------------------------------------------------


class ActuatorWorkspace(ProblemKind):
    name = "actuator_workspace"
    #: the hinges, the defaults of ``stress_limit``
    parts = (JointStiffness,)
    plots = ("workspace",)
    description = "reachable workspace under the actuator strokes: vertices, bounding box, volume, linearity"
    plots = ("workspace",)  # its points (inputs.points: true): the images of the stroke grid

    def input_options(self, model: Model) -> list[Option]:
        return [
            Option("samples", "int", "grid points per actuator over its stroke (ends included)", 11, 2, 101),
            Option("quadrature", "int", "Gauss-Legendre points per actuator for the volume", 4, 1, 20),
            Option("points", "bool", "also return every sampled point (a large list)", False),
            stress_limit_option(model),
        ]

    def check_inputs(self, inputs: dict[str, Any], model: Model, path: tuple) -> None:
        joint_box(inputs.get("stress_limit") or model)  # the stroke box, under the stress limits when given
        n = model.closure.nq
        if inputs["samples"] ** n > 200_000:
            raise InputError(
                f"samples^{n} = {inputs['samples'] ** n} grid points; expected at most 200000",
                path=path + ("samples",),
            )

    def _dims(self, model: Model) -> dict[str, str]:
        c = model.closure
        dims: dict[str, str] = {}
        for i in c.task_index:
            coord = c.x[i]
            dims.update({f"{coord.name}_min": coord.kind, f"{coord.name}_max": coord.kind})
        vol, si = size_dimension(c.x[i].kind for i in c.task_index)  # an area for a planar x, y
        vol = vol if vol in DIMENSIONS else si
        dims.update({"volume": vol, "linear_volume": vol, "box_volume": vol, "volume_ratio": "dimensionless"})
        dims["vertices"] = "matrix"
        dims["jacobian_deviation"] = "dimensionless"
        for i in c.task_index:
            dims[f"{c.x[i].name}_linear_error"] = c.x[i].kind
        dims["n_points"] = "dimensionless"
        dims.update(n_not_assembled="dimensionless", not_assembled_fraction="dimensionless", volume_border=vol)
        return dims

    def run(self, model: Model, inputs: Mapping[str, Any], solver: SolverConfig) -> Result:
        model = inputs.get("stress_limit") or model
        c = model.closure
        rep = reachable_workspace(model, inputs["samples"], inputs["quadrature"], solver)
        dims = self._dims(model)
        info = SolverInfo(
            "+".join(sorted({s.solver for s in rep.solutions if s.solver})) or solver.name,
            sum(s.iterations for s in rep.solutions),
            rep.seconds,
        )
        if not rep.status.ok:
            return closed_form_result(self.name, model, {}, dims, rep.status, rep.message, info)
        names = [c.x[i].name for i in c.task_index]
        values: dict[str, Any] = {}
        for k, n in enumerate(names):
            values[f"{n}_min"], values[f"{n}_max"] = float(rep.lower[k]), float(rep.upper[k])
        box = float(np.prod(rep.upper - rep.lower))
        values.update(
            volume=rep.volume,
            linear_volume=rep.linear_volume,
            box_volume=box,
            volume_ratio=rep.volume / box if box > 0 else None,
            vertices=rep.vertices.tolist(),
            jacobian_deviation=rep.jacobian_deviation,
        )
        for k, n in enumerate(names):
            values[f"{n}_linear_error"] = float(rep.linear_error[k])
        values["n_points"] = len(rep.q)
        missing = int(rep.details.get("not_assembled", 0))
        values.update(
            n_not_assembled=missing,
            not_assembled_fraction=missing / len(rep.q),
            volume_border=float(rep.details.get("volume_border", 0.0)),
        )
        vertices, points = _image_outputs(model, bool(missing))
        outputs = [vertices if o.name == "vertices" else o for o in outputs_of(dims)]
        if inputs["points"]:
            values["points"] = rep.t[np.all(np.isfinite(rep.t), axis=1)].tolist()
            outputs.append(points)
        res = closed_form_result(self.name, model, values, outputs, rep.status, rep.message, info)
        if missing:
            res.warn(
                ResultWarning(
                    "strokes_partly_assemble",
                    f"{missing} of {len(rep.q)} grid points of the stroke box do not assemble; the workspace "
                    "and its volume are those of the rest (the volume's error from the border of assembly "
                    f"is of the order of volume_border = {values['volume_border']:.6g})",
                    "inputs.samples",
                    missing / len(rep.q),
                )
            )
        return res

    def outputs(self, model: Model) -> list[Output]:
        vertices, points = _image_outputs(model, False)
        return [vertices if o.name == "vertices" else o for o in outputs_of(self._dims(model))] + [points]


def _image_outputs(model: Model, partly: bool) -> tuple[Output, Output]:
    """The images of the stroke box's corners (``vertices``) and of its grid (``points``), rows
    of task coordinates; ``partly``: only those that assemble."""
    c = model.closure
    cols = ", ".join(f"{c.x[i].name} [{result_unit(c.x[i].kind)}]" for i in c.task_index)
    that = " that assemble" if partly else ""
    return matrix("vertices", f"rows: box corners{that}; columns {cols}"), matrix(
        "points", f"rows: grid points{that}; columns {cols}"
    )


# -- dynamics -------------------------------------------------------------------------------------


class Dynamics(ProblemKind):
    name = "dynamics"
    parts = (DynamicsModel,)
    plots = ("dynamics", "matrices")
    description = "Lagrange dynamics at home: M, K, G (AD of the energies) and the natural frequencies"

    def supports(self, model: Model) -> str | None:
        if self.part(model, DynamicsModel) is None:
            return "it has no dynamic model (no energies)"
        return None

    def _lagrange(self, model: Model) -> DynamicsModel:
        """The mechanism's Lagrange model (its part ``dynamics``; `supports` said it has one)."""
        return self.part(model, DynamicsModel)

    def input_options(self, model: Model) -> list[Option]:
        masses = [
            mass_node(m, f"{d}; a mass or a block {{length, width, height}}", default=REQUIRED)
            for m, d in self._lagrange(model).masses
        ]
        return [
            material_node("material", "the hinge material: a name (Al 7075-T6, ...) or inline {E, nu, density}"),
            *masses,
            Option("g", "acceleration", "gravitational acceleration", default=9.81, lower=0.0),
        ]

    def resolve(self, inputs: dict[str, Any], model: Model, path: tuple) -> None:
        """The masses of blocks of the material, and its Young's modulus E."""
        mat = inputs["material"]
        for m, _ in self._lagrange(model).masses:
            inputs[m] = dyn.parse_mass(inputs[m], mat.density, mat.name, path + (m,))
        inputs["E"] = mat.require("E", path + ("material",), "the hinge stiffness needs it")
        missing = [n for n in self._lagrange(model).parameters if n not in inputs and n not in model.parameters]
        if missing:
            raise InputError(
                f"missing parameter(s) {', '.join(missing)}, needed by the dynamics "
                f"(see cpm-nlp describe {model.name})",
                path=("mechanism", "parameters"),
            )

    def run(self, model: Model, inputs: Mapping[str, Any], solver: SolverConfig) -> Result:
        dm = self._lagrange(model)
        w = np.array([inputs[n] if n in inputs else model.parameters[n] for n in dm.parameters], dtype=float)
        M, K, G = dyn.matrices(dm.lagrangian(), model.q_home, model.p, w)
        f = dyn.natural_frequencies(M, K)
        n = model.closure.nq
        values: dict[str, Any] = {m: inputs[m] for m, _ in dm.masses}
        for k in range(n):
            values[f"f{k + 1}"] = float(f[k])
        values.update(M=M.tolist(), K=K.tolist(), G=G.tolist(), q_static=(-np.linalg.solve(K, G)).tolist())
        if dm.values is not None:
            values.update(dm.values(model, w, M, K, G))
        return closed_form_result(
            self.name,
            model,
            values,
            _dynamics_outputs(model, dm),
            message=f"material {inputs['material'].name}; frequencies from |K - (2 pi f)^2 M| = 0",
        )

    def outputs(self, model: Model) -> list[Output]:
        return _dynamics_outputs(model, self._lagrange(model))


def _dynamics_outputs(model: Model, dm: DynamicsModel) -> list[Output]:
    """The masses, the natural frequencies, M, K, G, the static deflection, then the model's own values."""
    qs = ", ".join(model.closure.q_names)
    return [
        *(Output(m, "mass") for m, _ in dm.masses),
        *(Output(f"f{k + 1}", "frequency") for k in range(model.closure.nq)),
        matrix("M", f"{result_unit('mass')} (generalized coordinates {qs})"),
        matrix("K", result_unit("stiffness")),
        vector("G", result_unit("force")),
        vector("q_static", f"{result_unit('length')} (static deflection under G)"),
        *outputs_of(dm.dimensions),
    ]
