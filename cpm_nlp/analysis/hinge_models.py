"""The hinge models of the compliance kinds, as objects: ``kinematic`` (the
pseudo-rigid-body model of `cpm_nlp.analysis.compliance`: each hinge only
about the axes the kinematics moves) and ``all`` (every flexure a six-axis spring
at its joint, `cpm_nlp.analysis.hinge_chains`; needs the mechanism's leg
chains).  A problem file names one (``inputs.hinge_axes``); the input's choices
are the keys of `HINGE_MODELS`.

Each model is prepared once per problem (`HingeModel.prepare`: the six-axis
springs built, or the default's fallback to ``kinematic`` noted) and then solves the
platform compliance at a commanded pose (`HingeModel.solve`): the output
compliance C, and the compliant forward kinematics under the load.  The
``platform_compliance`` kind only calls the chosen model.
"""

from __future__ import annotations

import logging
from collections.abc import Mapping
from dataclasses import dataclass, field
from types import MappingProxyType

import numpy as np

from ..core.errors import InputError
from ..core.kinematics import PoseSolution
from ..core.model import Model
from ..core.outputs import Output, Values, text, vector
from ..core.result import ResultWarning, SolverInfo, Status
from . import compliance as cm
from . import validity
from .compliance_values import (
    compliance_matrix,
    coordinate_list,
    deflection_values,
    diagonal_compliance,
    force_output,
    largest,
    linear_range,
    point_warnings,
    six_axis_warnings,
    stress_values,
)
from .hinge_chains import LegChains, SixAxisModel, six_axis_model

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class Prepared:
    """A hinge model ready for one problem: the model that solves (``kinematic`` where the
    default ``all`` cannot place the hinges), its six-axis springs (``all``), whether the
    problem file chose it, and the note on a fallback."""

    hinges: HingeModel
    six_axis: SixAxisModel | None = None
    chosen: bool = False
    note: str = ""

    def solve(
        self,
        model: Model,
        hs: cm.HingeSet,
        pose: PoseSolution,
        load: np.ndarray,
        k_actuator: np.ndarray | None,
        info: SolverInfo,
    ) -> HingeSolution:
        """The chosen model's compliance at ``pose`` (`HingeModel.solve`)."""
        return self.hinges.solve(self, model, hs, pose, load, k_actuator, info)


@dataclass
class HingeSolution:
    """What a hinge model gives at a commanded pose: the status, the declared values it adds
    after the pose's, the solver that ran, the message and the warnings."""

    status: Status
    values: Values
    solver: SolverInfo
    message: str
    warnings: list[ResultWarning] = field(default_factory=list)


@dataclass(frozen=True)
class HingeModel:
    """A hinge model of `HINGE_MODELS` (name, description): prepared once per problem,
    then solved at a pose."""

    name: str
    description: str

    def prepare(self, model: Model, hs: cm.HingeSet, path: tuple, chosen: bool) -> Prepared:
        """The model ready for ``hs`` on ``model``; ``chosen``: the problem file named it (else the
        default); ``path``: where it was named (for bad input)."""
        raise NotImplementedError

    def solve(
        self,
        prepared: Prepared,
        model: Model,
        hs: cm.HingeSet,
        pose: PoseSolution,
        load: np.ndarray,
        k_actuator: np.ndarray | None,
        info: SolverInfo,
    ) -> HingeSolution:
        """The output compliance at the solved ``pose`` and the compliant forward kinematics under
        ``load`` (``k_actuator`` None: the actuators rigidly held); ``info``: the solver of the pose,
        which a result that stops before the compliant solve reports."""
        raise NotImplementedError


@dataclass(frozen=True)
class KinematicHinges(HingeModel):
    """The pseudo-rigid-body hinge model (``kinematic``): each hinge only about the axes the
    kinematics moves; the output compliance at the pose, the loaded pose by IPOPT."""

    def prepare(self, model: Model, hs: cm.HingeSet, path: tuple, chosen: bool) -> Prepared:  # noqa: ARG002 - one signature for every hinge model
        if hs.bodies:
            raise InputError(
                "the kinematic hinge model has rigid links; flexible bodies ("
                + ", ".join(b.name for b in hs.bodies)
                + ") need the six-axis model",
                path=path,
                hint="use hinge_axes: all",
            )
        return Prepared(self, None, chosen)

    def solve(
        self,
        prepared: Prepared,
        model: Model,
        hs: cm.HingeSet,
        pose: PoseSolution,
        load: np.ndarray,
        k_actuator: np.ndarray | None,
        info: SolverInfo,
    ) -> HingeSolution:
        c = model.closure
        f, ka = load, k_actuator
        out = Values().add(text("hinge_model"), "kinematic")
        sp = cm.static_point(model, hs, pose.x, pose.q)
        try:
            C = cm.output_compliance(sp, ka)
        except np.linalg.LinAlgError:
            msg = (
                "K_q + K_a is singular: the hinges and actuators leave a motion without stiffness "
                "(give a positive k_actuator, or more hinges)"
            )
            return HingeSolution(Status.SINGULAR, out, info, msg)
        lin = C @ f
        loaded = cm.compliant_fk(model, hs, pose.x, pose.q, sp.F, f, ka)
        out.extend(compliance_matrix(c, C, lin)).extend(diagonal_compliance(c, C))
        status, message = Status.SOLVED, "compliant forward kinematics by IPOPT (" + loaded.message + ")"
        if not np.any(f):
            message = "no load: the output compliance only"
        if loaded.ok:
            d = loaded.x - pose.x
            out.extend(deflection_values(c, d))
            spl = cm.static_point(model, hs, loaded.x, loaded.q)
            out.extend(stress_values(hs, [spl], False, "_loaded"))
            out.add(vector("q_loaded", coordinate_list(c.q)), loaded.q.tolist())
        else:
            status = Status.NOT_CONVERGED
        if ka is None:
            message += "; actuators rigidly held: a pseudo-rigid-body model with rigid links does not deflect"
        info = SolverInfo("ipopt", pose.iterations + loaded.iterations, pose.seconds)
        if not loaded.ok:
            warnings = validity.hinge_geometry_warnings(hs.hinges)
        else:
            warnings = point_warnings(hs, [spl]) + linear_range(c, d, lin)
        return HingeSolution(status, out, info, message + prepared.note, warnings)


#: why the default ``all`` gives way to ``kinematic`` at a pose where its stiffness is singular
SINGULAR_FALLBACK = (
    "; the six-axis hinge model is singular here (a motion of the legs' chains meets no hinge, "
    "e.g. a leg's spin between two spherical joints), so the default fell back to hinge_axes: kinematic"
)


@dataclass(frozen=True)
class SixAxisHinges(HingeModel):
    """Every flexure a six-axis spring at its joint (``all``), on the mechanism's leg chains: the
    unloaded equilibrium at the commanded actuators (Newton on the KKT), the output compliance
    there, the loaded pose by IPOPT."""

    def prepare(self, model: Model, hs: cm.HingeSet, path: tuple, chosen: bool) -> Prepared:
        if not has_chains(model):
            raise InputError(
                f"hinge_axes: all needs the legs of {model.name} as serial chains (the mechanism's chains "
                "capability; a mechanism file of spatial P, R, C, U, S legs gives them)",
                path=path,
                hint="use hinge_axes: kinematic",
            )
        if chosen or hs.bodies:  # flexible bodies: only the six-axis model has them
            return Prepared(self, six_axis_model(model, hs), True)
        try:  # the default: the six-axis model where it can place every hinge
            return Prepared(self, six_axis_model(model, hs), False)
        except InputError as exc:
            log.info("platform_compliance: the kinematic hinge model (%s)", exc.message)
            note = f"; hinge_axes: kinematic, as the six-axis model cannot place the hinges ({exc.message})"
            return Prepared(KINEMATIC, None, False, note)

    def solve(
        self,
        prepared: Prepared,
        model: Model,
        hs: cm.HingeSet,
        pose: PoseSolution,
        load: np.ndarray,
        k_actuator: np.ndarray | None,
        info: SolverInfo,
    ) -> HingeSolution:
        c = model.closure
        sm = prepared.six_axis
        f, ka = load, k_actuator
        out = Values()
        try:
            z0 = sm.start(pose.x, pose.q)
            ok, z_u, lam_u, it_u = sm.newton(z0, np.zeros(c.nx), pose.q, None, None)
            if not ok:
                msg = "six-axis hinge model: no unloaded equilibrium at the commanded actuators (Newton on the KKT)"
                return HingeSolution(Status.NOT_CONVERGED, out, info, msg)
            Fc = sm.actuator_reactions(z_u, lam_u, np.zeros(c.nx))
            C = sm.compliance(z_u, lam_u, ka, None if ka is None else Fc)
        except np.linalg.LinAlgError:
            if not prepared.chosen:  # the default: the kinematic model, saying why
                fallback = Prepared(KINEMATIC, None, False, SINGULAR_FALLBACK)
                return KINEMATIC.solve(fallback, model, hs, pose, load, k_actuator, info)
            msg = (
                "the six-axis hinge model's stiffness is singular: a motion of the legs' chains meets no hinge and "
                "no actuator (e.g. a leg's spin between two spherical joints; give a positive k_actuator, more "
                "hinges, or hinge_axes: kinematic)"
            )
            return HingeSolution(Status.SINGULAR, out, info, msg)
        out.extend(compliance_matrix(c, C, C @ f)).add(text("hinge_model"), "all")
        out.extend(diagonal_compliance(c, C))
        out.add(Output("stress_max_unloaded", "stress"), largest(sm.stresses(z_u)))
        out.add(Output("stress_peak_max_unloaded", "stress"), largest(sm.hs.peaks(sm.stresses(z_u))))
        note = f"six-axis hinges: {', '.join(sm.six_axis_hinges) or 'none'}; {sm.chains.note}"
        if hs.bodies:  # the chains' note speaks of rigid links: say which are not
            note += "; except the flexible bodies (beams): " + ", ".join(b.name for b in hs.bodies)
        if not np.any(f):
            info = SolverInfo("newton-kkt", pose.iterations + it_u, pose.seconds)
            msg = f"no load: the output compliance only ({note})"
            return HingeSolution(Status.SOLVED, out, info, msg, six_axis_warnings(sm, [z_u]))
        ok, z_l, lam_l, it_l, st = sm.ipopt(z_u, f, pose.q, ka, None if ka is None else Fc)
        info = SolverInfo("ipopt", pose.iterations + it_u + it_l, pose.seconds)
        if not ok:
            msg = f"six-axis compliant forward kinematics by IPOPT did not converge ({st})"
            return HingeSolution(Status.NOT_CONVERGED, out, info, msg)
        d = z_l[: c.nx] - z_u[: c.nx]
        out.extend(deflection_values(c, d))
        out.add(vector("q_loaded", coordinate_list(c.q)), z_l[c.nx : c.nx + c.nq].tolist())
        out.add(Output("stress_max_loaded", "stress"), largest(sm.stresses(z_l)))
        out.add(Output("stress_peak_max_loaded", "stress"), largest(sm.hs.peaks(sm.stresses(z_l))))
        if ka is None:
            F = sm.actuator_reactions(z_l, lam_l, f)
            out.add_all((force_output(f"F{j + 1}_loaded", q), float(F[j])) for j, q in enumerate(c.q))
        msg = f"compliant forward kinematics by IPOPT ({st}, {it_l} iterations); {note}"
        warnings = six_axis_warnings(sm, [z_l]) + linear_range(c, d, C @ f)
        return HingeSolution(Status.SOLVED, out, info, msg, warnings)


KINEMATIC = KinematicHinges(
    "kinematic",
    "pseudo-rigid-body: each hinge only about the axes the kinematics moves; with the actuators held a "
    "mechanism of rigid links then does not deflect",
)

#: the hinge models by the name a problem file gives (``inputs.hinge_axes``)
HINGE_MODELS: Mapping[str, HingeModel] = MappingProxyType(
    {
        "all": SixAxisHinges(
            "all",
            "every flexure a six-axis spring at its joint, the axes the kinematics does not move with the "
            "flexure library's stiffness; needs the mechanism's leg chains",
        ),
        "kinematic": KINEMATIC,
    }
)


def six_axis_point(
    sm: SixAxisModel, model: Model, x: np.ndarray, q: np.ndarray, f: np.ndarray
) -> tuple[cm.StaticPoint, dict[str, float]] | None:
    """The actuator forces, input stiffness, hinge stresses and energy of the six-axis model
    (flexible bodies included) at the actuators q, starting from the rigid pose x: the
    equilibrium by Newton on the KKT conditions, None when it does not converge; and the
    largest stress of each flexible body."""
    try:
        ok, z, lam, _ = sm.newton(sm.start(x, q), f, q, None, None)
    except np.linalg.LinAlgError:  # a motion without stiffness: no equilibrium to report
        return None
    if not ok:
        return None
    theta = sm.joint_vector(z, cm.joint_vector(model, z[: model.closure.nx], q))
    F = sm.actuator_reactions(z, lam, f)
    sp = cm.StaticPoint(
        z[: model.closure.nx].copy(),
        np.asarray(q, dtype=float),
        F,
        sm.input_stiffness(z, lam, f),
        np.full((model.closure.nx, model.closure.nq), np.nan),  # J: not defined off the rigid kinematics
        theta,
        sm.energy(z, f),
        sm.stresses(z),
    )
    return sp, sm.body_stresses(z)


def has_chains(model: Model) -> bool:
    """Whether the model's mechanism gives its legs as serial chains (the part ``chains``)."""
    return model.mechanism is not None and model.mechanism.part(LegChains) is not None


def default_hinge_model(model: Model) -> HingeModel:
    """``all`` where the mechanism gives its chains, else ``kinematic``."""
    return HINGE_MODELS["all"] if has_chains(model) else HINGE_MODELS["kinematic"]


def hinge_model_text() -> str:
    """The description of the ``hinge_axes`` input, from the table."""
    models = " or ".join(f"'{m.name}' ({m.description})" for m in HINGE_MODELS.values())
    return f"the hinge model: {models}; default: all where the mechanism gives its chains, else kinematic"
