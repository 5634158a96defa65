"""The kinematic problem kinds: forward_kinematics, inverse_kinematics,
jacobian and joint_requirements.

Inputs take a scalar per coordinate, or a list (a batch: one solve per
entry, values come back as lists with ``null`` for points that failed).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from ..core.conditioning import NEAR_SINGULAR_CONDITION
from ..core.errors import InputError
from ..core.kernels import batch_newton_supported
from ..core.kind import (
    ProblemKind,
    actuator_options,
    broadcast,
    check_actuator_limits,
    coordinate_dims,
    given,
    task_options,
    task_values,
)
from ..core.kinematics import PoseSolution, forward_kinematics, inverse_kinematics, jacobians
from ..core.model import Model
from ..core.multistart import DEFAULT_STARTS
from ..core.options import Option
from ..core.outputs import Output, declared_for, declared_result, outputs_of
from ..core.progress import track
from ..core.result import STATUS_TEXT, Result, SolverInfo, Status, poses_solver_info, worst_status
from ..core.schema import Record
from ..core.solver import SolverConfig
from ..core.units import result_unit

# the assembly-mode search, its certificate, the batches and the joint requirements are
# imported where they run: a single FK solve loads none of them (issue 23, start-up)
TYPE_CHECKING = False
if TYPE_CHECKING:
    from ..analysis.assembly import AssemblyModes
    from ..analysis.mode_certificate import ModeCertificate


def _pose_names(model: Model) -> tuple[list[str], dict[str, str]]:
    c = model.closure
    dims = coordinate_dims(c.x)
    for off, target in c.offsets.items():
        dims[off] = dims[target]
    dims.update(coordinate_dims(c.q))
    dims.update(coordinate_dims(c.passive_coords))
    dims["residual"] = "length" if c.residual_unit == "m" else "dimensionless"
    return list(dims), dims


def _pose_outputs(model: Model) -> list[Output]:
    """The pose a kinematic kind returns: task and dependent coordinates, their offsets from
    home (references to them), actuators, passive joints, the loop-closure residual."""
    offsets = model.closure.offsets
    names, dims = _pose_names(model)
    return [Output(n, dims[n], "reference", offsets[n]) if n in offsets else Output(n, dims[n]) for n in names]


def _pose_values(model: Model, sols: Sequence[PoseSolution], batch: bool) -> dict[str, Any]:
    """Values of solved poses under the papers' names; None for failed points (column-wise:
    a batch of 100 000 poses is a few numpy columns, not a loop per value)."""
    c = model.closure
    n = len(sols)
    good = [k for k, s in enumerate(sols) if s.ok]
    with_passive = [k for k in good if sols[k].passive is not None]

    def column(rows: list[int], values: np.ndarray) -> list:
        if len(rows) == n:
            return values.tolist()
        out = np.full(n, None, dtype=object)
        out[rows] = values.tolist()
        return out.tolist()

    X = np.array([sols[k].x for k in good], dtype=float).reshape(len(good), c.nx)
    Q = np.array([sols[k].q for k in good], dtype=float).reshape(len(good), c.nq)
    passive_names = list(c.passive_names)
    P = np.array([sols[k].passive for k in with_passive], dtype=float).reshape(len(with_passive), len(passive_names))
    x_names = list(c.x_names)
    cols: dict[str, list] = {}
    for i, name in enumerate(x_names):
        cols[name] = column(good, X[:, i])
    for off, target in c.offsets.items():
        i = x_names.index(target)
        cols[off] = column(good, X[:, i] - model.x_home[i])
    for j, name in enumerate(c.q_names):
        cols[name] = column(good, Q[:, j])
    for j, name in enumerate(passive_names):
        cols[name] = column(with_passive, P[:, j])
    cols["residual"] = column(good, np.array([float(sols[k].residual) for k in good], dtype=float))
    cols = {name: cols[name] for name in _pose_names(model)[0]}
    return {k: (v if batch else v[0]) for k, v in cols.items()}


def _summary(sols: Sequence[PoseSolution], batch: bool) -> tuple[Status, str, list[Status] | None]:
    statuses = [s.status for s in sols]
    status = worst_status(statuses)
    if not batch:
        s = sols[0]
        msg = STATUS_TEXT[s.status] + (f": {s.message}" if s.message else "")
        return status, msg, None
    failed = [(k, s) for k, s in enumerate(sols) if not s.ok]
    if not failed:
        return status, f"all {len(sols)} points solved", statuses
    k, s = failed[0]
    msg = f"{len(failed)} of {len(sols)} points not solved; first, point {k}: {s.status.value}" + (
        f" ({s.message})" if s.message else ""
    )
    return status, msg, statuses


def _solver_info(sols: Sequence[PoseSolution], fallback: str) -> SolverInfo:
    return poses_solver_info(sols, fallback)


def _result(
    kind: str,
    model: Model,
    sols: Sequence[PoseSolution],
    batch: bool,
    solver: SolverConfig,
    extra: Mapping[str, Any] | None = None,
    outputs: Sequence[Output] = (),
) -> Result:
    """The result of solved poses: the pose (`_pose_outputs`), then ``extra`` values
    (declared by ``outputs``)."""
    status, message, statuses = _summary(sols, batch)
    values = _pose_values(model, sols, batch)
    if extra:
        values.update(extra)
    warning = _singularity_warning(model, sols)
    return declared_result(
        kind,
        status,
        _pose_outputs(model) + list(outputs),
        values,
        solver=_solver_info(sols, solver.name),
        message=message,
        statuses=statuses,
        model=_model_info(model),
        warnings=[warning] if warning else [],
    )


def _condition(model: Model, s: PoseSolution) -> float:
    """cond(Φ_x) of a solved pose: the 2-norm value where the solve computed it, else its
    1-norm estimate, refined by the SVD when that is above the warning threshold."""
    cond = s.details.get("cond_phi_x")
    if cond is not None:
        return float(cond)
    cond1 = s.details.get("cond1_phi_x")
    if cond1 is None or not cond1 > NEAR_SINGULAR_CONDITION:
        return 0.0 if cond1 is None else float(cond1)
    c = model.closure
    sv = np.linalg.svd(np.asarray(c.phi_x(s.x, s.q, model.p), dtype=float), compute_uv=False)
    return float(sv[0] / sv[-1]) if sv[-1] > 0 else float("inf")


def _singularity_warning(model: Model, sols: Sequence[PoseSolution]) -> Any:
    """A ``near_singular`` warning for the worst solved pose whose cond(Φ_x) is above
    `NEAR_SINGULAR_CONDITION` (None when none is)."""
    conds = [(_condition(model, s), k) for k, s in enumerate(sols) if s.ok]
    near = [ck for ck in conds if ck[0] > NEAR_SINGULAR_CONDITION]
    if not near:
        return None
    from ..analysis.validity import near_singular_warning  # only for a warning (issue 23, start-up)

    cond, k = max(near)
    points = f" (at {len(near)} of {len(sols)} points; the worst, point {k})" if len(sols) > 1 else ""
    return near_singular_warning(cond, "Phi_x", "Phi_x", points)


def _model_info(model: Model) -> dict[str, Any]:
    return {"type": model.name, **dict(model.parameters), **dict(model.derived)}


class ForwardKinematics(ProblemKind):
    name = "forward_kinematics"
    description = "platform pose from the actuator displacements (FK), checked against IK"
    plots = ("io", "assembly_modes", "mechanism", "workspace")

    def input_options(self, model: Model) -> list[Option]:
        return actuator_options(model, "grid") + list(MODE_OPTIONS) + [_guess_option(model)]

    def check_inputs(self, inputs: dict[str, Any], model: Model, path: tuple) -> None:
        names = model.closure.q_names
        missing = [n for n in names if inputs.get(n) is None]
        if missing:
            raise InputError(
                f"missing actuator input(s) {', '.join(missing)}; give every one of {', '.join(names)}", path=path
            )
        check_actuator_limits(model, inputs, path)
        _qs, batch = broadcast([inputs[n] for n in names], names, path)
        if inputs.get("assembly_modes") == "all" and batch:
            raise InputError(
                "assembly_modes: all searches the modes of one actuator vector; give scalar actuator values",
                path=path + ("assembly_modes",),
            )

    def run(self, model: Model, inputs: Mapping[str, Any], solver: SolverConfig) -> Result:
        names = model.closure.q_names
        qs, batch = broadcast([inputs[n] for n in names], names, ("inputs",))
        guess = inputs.get("guess")
        if inputs.get("assembly_modes") == "all":
            from ..analysis.assembly import assembly_modes
            from ..analysis.mode_certificate import certify_modes

            found = assembly_modes(
                model, qs[0], solver, starts=inputs["mode_starts"], seed=inputs["mode_seed"], guess=guess
            )
            cert = certify_modes(model, found) if inputs.get("mode_certificate") else None
            return _modes_result(self.name, model, found, solver, cert)
        if batch and batch_newton_supported(solver):  # one vectorized Newton over every point
            from ..core.batch import batch_forward_kinematics

            sols = batch_forward_kinematics(model, qs, solver, guess).solutions()
        else:
            sols = [forward_kinematics(model, q, solver, guess) for q in track(qs, "forward kinematics")]
        return _result(self.name, model, sols, batch, solver)

    def outputs(self, model: Model) -> list[Output]:
        """The pose; with ``assembly_modes: all``, every mode found (declared ``when`` that input
        asks for them, so that they are not columns of every forward_kinematics sweep)."""
        return _pose_outputs(model) + mode_outputs(model)


def _guess_option(model: Model) -> Record:
    """``guess``: a start pose of the FK Newton (coordinates not given: the home pose), as an nx vector."""
    c = model.closure

    def vector(g: Any, _path: tuple) -> np.ndarray | None:
        if g is None:
            return None
        return np.array([model.x_home[i] if g[n] is None else g[n] for i, n in enumerate(c.x_names)])

    return Record(
        "guess",
        "start pose of the Newton solve (a coordinate not given: its home value), to pick an assembly mode",
        tuple(Option(x.name, x.kind, x.description, default=None) for x in c.x),
        default=None,
        what="pose coordinate",
        convert=vector,
    )


#: inputs of the forward_kinematics kind that ask for every assembly mode
MODE_OPTIONS = (
    Option(
        "assembly_modes",
        "choice",
        "'designated': the pose on the model's assembly branch; 'all': every distinct real solution that a "
        "seeded multi-start Newton search finds (not a proof of completeness)",
        default="designated",
        choices=("designated", "all"),
    ),
    Option(
        "mode_starts",
        "int",
        "Newton starts of the assembly-mode search",
        default=DEFAULT_STARTS,
        lower=1,
        upper=1_000_000,
    ),
    Option("mode_seed", "int", "seed of the assembly-mode search", default=0, lower=0, upper=2**32 - 1),
    Option(
        "mode_certificate",
        "bool",
        "also prove by interval branch and bound that the search region holds no other real mode "
        "(seconds for a planar linkage; not feasible for a 6-6 platform)",
        default=False,
    ),
)


#: what asks for the values of `mode_outputs`
ALL_MODES = "assembly_modes: all"


def mode_outputs(model: Model) -> list[Output]:
    """The values a forward_kinematics result with ``assembly_modes: all`` adds: each mode's pose
    and passive joints, status, residual, branch and basin, the nearest other mode, the designated
    pose's status, the search (and, with ``mode_certificate: true``, its certificate)."""
    c = model.closure
    dims = {"modes": "dimensionless"}
    dims |= {f"modes_{coord.name}": coord.kind for coord in (*c.x, *c.passive_coords)}
    dims |= {
        "modes_status": "text",
        "modes_message": "text",
        "modes_residual": "length" if c.residual_unit == "m" else "dimensionless",
        "modes_designated": "text",
        "modes_branch": "matrix",
        "modes_basin": "dimensionless",
        "branch_names": "text",
        "nearest_mode": "dimensionless",
        "distance_length": "length",
        "distance_angle": "angle",
        "designated_status": "text",
        "designated_message": "text",
        "mode_starts_converged": "dimensionless",
        "mode_region": "text",
        "mode_completeness": "text",
        "mode_search": "text",
    }
    out = [dataclasses.replace(o, when=ALL_MODES) for o in outputs_of(dims)]
    return out + [Output("mode_certificate", "text", "text", when=f"{ALL_MODES} and mode_certificate: true")]


def _modes_result(
    kind: str, model: Model, found: AssemblyModes, solver: SolverConfig, cert: ModeCertificate | None = None
) -> Result:
    """A forward_kinematics result: the search that ran is ``solved``; the designated pose
    (the ordinary FK) is reported as usual, with its own status, and every mode found beside it."""
    c = model.closure
    modes = found.modes
    work = found.working_solution
    extra: dict[str, Any] = {"modes": found.count}
    for i, coord in enumerate(c.x):
        extra[f"modes_{coord.name}"] = [float(m.x[i]) for m in modes]
    for coord in c.passive_coords:
        extra[f"modes_{coord.name}"] = [m.passive.get(coord.name) for m in modes]
    extra["modes_status"] = [m.status.value for m in modes]
    extra["modes_message"] = [m.message for m in modes]
    extra["modes_residual"] = [m.residual for m in modes]
    extra["modes_designated"] = [m.designated for m in modes]
    extra["modes_branch"] = [m.branch.tolist() for m in modes]
    extra["modes_basin"] = [m.basin for m in modes]
    extra["branch_names"] = list(c.branch_names)
    extra["nearest_mode"] = found.nearest
    extra["distance_length"] = found.distance_length
    extra["distance_angle"] = found.distance_angle
    extra["designated_status"] = work.status.value
    extra["designated_message"] = work.message or STATUS_TEXT[work.status]
    extra["mode_starts_converged"] = found.converged
    extra["mode_region"] = found.region.as_dict()
    est = found.completeness
    extra["mode_completeness"] = est.as_dict()
    extra["mode_search"] = (
        f"{found.starts} Newton starts, {found.converged} converged to a real solution, "
        f"{found.count} distinct mode(s) (merged on {found.details['merged_on']}); "
        f"search region: {found.region.describe()}"
        + (f"; {found.outside_region} mode(s) found outside it (kept)" if found.outside_region else "")
        + f"; {est.note}"
    )
    if cert is not None:
        extra["mode_certificate"] = cert.as_dict()
        extra["mode_search"] += (
            f"; certificate: no other real mode in the region ({cert.boxes} sub-boxes, {cert.seconds:.3g} s)"
            if cert.certified
            else f"; certificate: not proven ({cert.reason}; {cert.boxes} sub-boxes, {cert.seconds:.3g} s)"
        )
    res = _result(kind, model, [work], False, solver, extra, declared_for(kind, mode_outputs(model), extra))
    res.status = Status.SOLVED
    designated = sum(m.designated for m in modes)
    summary = f"{found.count} assembly mode(s) found, {designated} on the designated branch"
    if designated > 1:
        summary += " (the branch indicators do not tell these apart)"
    if found.nearest is not None:
        summary += (
            f"; nearest other mode: {found.distance_length:.6g} m and {found.distance_angle:.6g} rad away"
            " (lengths and angles of the pose)"
        )
    if work.ok:
        pose = "designated pose: solved"
    else:
        pose = f"designated pose (the ordinary FK): {work.status.value}"
        pose += f" ({work.message})" if work.message else ""
    res.message = f"mode search ran; {summary}; {pose}; {est.note}"
    return res


class InverseKinematics(ProblemKind):
    name = "inverse_kinematics"
    description = "actuator displacements and passive joints for a platform pose (IK)"
    plots = ("io", "mechanism", "workspace")

    def input_options(self, model: Model) -> list[Option]:
        return task_options(model, "grid") + [
            Option(
                "method",
                "choice",
                "closed form (the paper's) or solved from the loop closures",
                default="auto",
                choices=("auto", "closed_form", "solve"),
            )
        ]

    def check_inputs(self, inputs: dict[str, Any], model: Model, path: tuple) -> None:
        cols = task_values(inputs, model, path)
        broadcast(cols, list(model.closure.task), path)
        if inputs["method"] == "closed_form" and model.closure.ik is None:
            raise InputError(
                f"mechanism {model.name} has no closed-form IK; use 'solve' or 'auto'", path=path + ("method",)
            )

    def run(self, model: Model, inputs: Mapping[str, Any], solver: SolverConfig) -> Result:
        ts, batch = broadcast(task_values(inputs, model, ("inputs",)), list(model.closure.task), ("inputs",))
        if batch and model.closure.ik is not None and inputs["method"] != "solve":  # closed form, vectorized
            from ..core.batch import batch_inverse_kinematics

            sols = batch_inverse_kinematics(model, ts, solver).solutions()
        else:
            sols = [inverse_kinematics(model, t, solver, inputs["method"]) for t in track(ts, "inverse kinematics")]
        return _result(self.name, model, sols, batch, solver)

    def outputs(self, model: Model) -> list[Output]:
        return _pose_outputs(model)


class Jacobian(ProblemKind):
    name = "jacobian"
    description = "forward/inverse Jacobians (AD) and singularity measures at one pose"
    plots = ("jacobian", "matrices")

    def input_options(self, model: Model) -> list[Option]:
        return (
            task_options(model, "scalar")
            + actuator_options(model, "scalar")
            + [
                Option(
                    "characteristic_length",
                    "length",
                    "length that turns angle rates into length rates for cond and manipulability "
                    "(default: the mechanism's)",
                    default=None,
                    lower=0.0,
                    strict=True,
                )
            ]
        )

    def check_inputs(self, inputs: dict[str, Any], model: Model, path: tuple) -> None:
        c = model.closure
        pose_keys = given(inputs, [o.name for o in task_options(model, "scalar")])
        act_keys = given(inputs, c.q_names)
        if pose_keys and act_keys:
            raise InputError(
                "give either the pose ("
                + ", ".join(pose_keys)
                + ") or the actuators ("
                + ", ".join(act_keys)
                + "), not both",
                path=path,
            )
        if act_keys:
            if len(act_keys) != c.nq:
                raise InputError(f"give every actuator: {', '.join(c.q_names)}", path=path)
            check_actuator_limits(model, inputs, path)
        else:
            task_values(inputs, model, path)

    def run(self, model: Model, inputs: Mapping[str, Any], solver: SolverConfig) -> Result:
        c = model.closure
        if given(inputs, c.q_names):
            sol = forward_kinematics(model, [inputs[n] for n in c.q_names], solver)
        else:
            sol = inverse_kinematics(model, task_values(inputs, model, ("inputs",)), solver)
        extra: dict[str, Any] = {}
        if sol.ok:
            rep = jacobians(model, sol.x, sol.q, inputs.get("characteristic_length"))
            extra = {
                "J": rep.J.tolist(),
                "J_task": rep.J_task.tolist(),
                "J_inv": rep.J_inv.tolist(),
                "Phi_x": rep.phi_x.tolist(),
                "Phi_q": rep.phi_q.tolist(),
                "det_Phi_x": rep.det_phi_x,
                "det_Phi_y": rep.det_phi_y,
                "cond": rep.cond,
                "manipulability": rep.manipulability,
                "characteristic_length": rep.characteristic_length,
            }
        res = _result(self.name, model, [sol], False, solver, extra, _jacobian_outputs(c) if extra else ())
        if extra:  # an inverse (type I) singularity: the homogenized J_task loses rank
            from ..analysis.validity import near_singular_warning

            res.warn(*filter(None, [near_singular_warning(extra["cond"], "J_task, homogenized", "cond")]))
        return res

    def outputs(self, model: Model) -> list[Output]:
        return _pose_outputs(model) + _jacobian_outputs(model.closure)


def _jacobian_outputs(c: Any) -> list[Output]:
    """The Jacobians of a solved pose (their units say their rows and columns)."""
    rows = ", ".join(f"{x.name} [{result_unit(x.kind)}]" for x in c.x)
    task_rows = ", ".join(f"{c.x[i].name} [{result_unit(c.x[i].kind)}]" for i in c.task_index)
    cols = ", ".join(f"{q.name} [{result_unit(q.kind)}]" for q in c.q)
    return [
        Output("J", "matrix", "matrix", unit=f"rows {rows} per columns {cols}"),
        Output("J_task", "matrix", "matrix", unit=f"rows {task_rows} per columns {cols}"),
        Output("J_inv", "matrix", "matrix", unit=f"rows {cols} per columns {task_rows}"),
        Output("Phi_x", "matrix", "matrix", unit=f"d(phi) [{c.residual_unit}] / d({', '.join(c.x_names)})"),
        Output("Phi_q", "matrix", "matrix", unit=f"d(phi) [{c.residual_unit}] / d({', '.join(c.q_names)})"),
        *(Output(n, "dimensionless") for n in ("det_Phi_x", "det_Phi_y", "cond", "manipulability")),
        Output("characteristic_length", "length"),
    ]


class JointRequirements(ProblemKind):
    name = "joint_requirements"
    description = "actuator strokes and passive-joint rotations over every combination of task values"
    plots = ("requirements", "workspace")

    def input_options(self, model: Model) -> list[Option]:
        return task_options(model, "grid")

    def check_inputs(self, inputs: dict[str, Any], model: Model, path: tuple) -> None:
        cols = task_values(inputs, model, path)
        n = int(np.prod([len(v) if isinstance(v, list) else 1 for v in cols]))
        if n > 200_000:
            raise InputError(
                f"the grid has {n} poses; expected at most 200000 (use fewer values per coordinate)", path=path
            )

    def run(self, model: Model, inputs: Mapping[str, Any], solver: SolverConfig) -> Result:
        c = model.closure
        grid = [v if isinstance(v, list) else [v] for v in task_values(inputs, model, ("inputs",))]
        from ..analysis.requirements import joint_requirements

        rep = joint_requirements(model, grid, solver)
        sols = rep.solutions
        res = _result(self.name, model, sols, True, solver, rep.ranges, outputs_of(rep.range_dimensions))
        if rep.status.ok:
            res.message = (
                f"{len(sols)} poses ({' x '.join(str(len(g)) for g in grid)} over {', '.join(c.task)}) solved by IK"
            )
        return res

    def outputs(self, model: Model) -> list[Output]:
        """The pose, then the range of each family of joints (actuators, dependent pose
        coordinates, passive joints) and of its deviation from home
        ([`joint_requirements`][cpm_nlp.analysis.requirements.joint_requirements])."""
        c = model.closure
        dims = {co.group: co.kind for co in (*c.q, *(c.x[i] for i in c.dep_index), *c.passive_coords)}
        fams = sorted(dims)
        ranges = [Output(f"{f}_{e}", dims[f]) for f in fams for e in ("min", "max")]
        ranges += [Output(f"d{f}_{e}", dims[f]) for f in fams for e in ("min", "max")]
        return _pose_outputs(model) + ranges
