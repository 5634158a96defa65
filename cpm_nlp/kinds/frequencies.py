"""``natural_frequencies``: frequencies and mode shapes, linearized Lagrange at a pose, from
masses and inertias on the coordinates, the links' masses and the hinge stiffness (the
kinematic or the six-axis hinge model); the hinge kinds' common parts are in
`cpm_nlp.kinds.compliance`.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from ..analysis import compliance as cm
from ..analysis.compliance_values import (
    point_warnings,
    six_axis_warnings,
)
from ..analysis.dynamics import parse_inertia, parse_mass
from ..analysis.hinge_chains import LegChains
from ..analysis.hinge_models import (
    HINGE_MODELS,
    Prepared,
    has_chains,
)
from ..analysis.link_masses import LinkSection, link_bodies, link_mass_matrix, rigid_velocity_map, six_axis_modes
from ..core.canonical import canonical_eigh, degenerate_note, multiplicities
from ..core.errors import InputError
from ..core.kind import (
    actuator_options,
    task_options,
)
from ..core.kinematics import PoseSolution
from ..core.model import Model
from ..core.options import Option
from ..core.outputs import Output, Values, matrix, text, vector
from ..core.result import Result, SolverInfo, Status, poses_solver_info
from ..core.schema import Either, ListOf, MappingOf, Quantity, Record
from ..core.solver import SolverConfig
from ..core.units import result_unit
from .compliance import (
    _check_pose_inputs,
    _commanded_pose,
    _hinge_result,
    _HingeKind,
)
from .hinge_inputs import bodies_option, hinge_options, k_actuator_option, mass_node
from .kinematic import _pose_outputs, _pose_values

#: how many frequencies equal each mode's own
MULTIPLICITY = vector("multiplicity", "per mode: how many frequencies equal its own (1: a simple frequency)")


def _mode_outputs(c: Any) -> list[Output]:
    """M, K and the mode shapes, in the actuator and the pose coordinates."""
    qs = ", ".join(c.q_names)
    return [
        matrix("M", f"{result_unit('mass')} or {result_unit('inertia')} (generalized coordinates {qs})"),
        matrix("K", f"{result_unit('stiffness')} or {result_unit('rotational_stiffness')}"),
        matrix("modes_q", f"rows: modes; columns {qs} (M-normalized, canonical in the pose coordinates)"),
        matrix("modes_x", f"rows: modes; columns {', '.join(c.x_names)} (J times modes_q)"),
    ]


#: the links' masses and the count of modes with mass (the six-axis hinge model)
LINK_MASSES = vector("link_masses", f"per link of inputs.links, in order: its mass [{result_unit('mass')}]")
N_MODES = Output("n_modes", "dimensionless")


def _links_node() -> MappingOf:
    """``links``: the legs' links with a section of the material, or a mass (and inertias)."""
    length = {"lower": 0.0, "strict": True}
    section = Either(
        "section",
        "a bar of the material: {width, height} (width along the start joint's axis) or {d} (round)",
        (
            Record(
                "section",
                "rectangle",
                (Option("width", "length", "section width", **length), Option("height", "length", "height", **length)),
                what="section key",
            ),
            Record("section", "circle", (Option("d", "length", "section diameter", **length),), what="section key"),
        ),
        default=None,
        convert=lambda v, _p: None if v is None else LinkSection(v.get("width"), v.get("height"), v.get("d")),
    )
    inertia = ListOf(
        "inertia",
        "inertias about the link's centre about its own axes [along it, b1, b2]",
        Quantity("inertia", "an inertia", kinds=("inertia",), positive=True, si=True),
        min_len=3,
        max_len=3,
        default=None,
    )
    return MappingOf(
        "links",
        "the legs' links as rigid bodies with mass (the hinge model's chains): label -> {leg, after_joint, "
        "section | mass [, inertia]}; the link is the body from joint after_joint of the leg to the next joint",
        Record(
            "<link>",
            "one link of a leg (of each copy of a repeated leg)",
            (
                Option("leg", "str", "a leg name (leg1), or a repeated leg's (leg: every copy)"),
                Option("after_joint", "int", "the link's first joint, counted from the base (1, 2, ...)", lower=1),
                section,
                Quantity(
                    "mass",
                    "its mass (default: density x section area x length)",
                    kinds=("mass",),
                    default=None,
                    positive=True,
                    si=True,
                ),
                inertia,
            ),
            what="link key",
        ),
        key_what="link",
        default=None,
    )


def masses_node(model: Model) -> Record:
    """``masses``: a mass or an inertia per pose or actuator coordinate (a block of the material)."""
    c = model.closure
    names = c.x_names + c.q_names
    return Record(
        "masses",
        "mass (on a length coordinate: '12 g', or a block {length, width, height} of the material) or "
        "inertia (on an angle coordinate: kg*m^2, or a block {length, width, height, about: x|y|z} of the "
        "material turning about its own axis through its centre) per pose or actuator coordinate: " + ", ".join(names),
        tuple(mass_node(co.name, co.description, co.kind == "angle") for co in (*c.x, *c.q)),
        what="coordinate",
        sparse=True,
        mismatch="expected masses: a mapping of coordinate -> mass or inertia over " + ", ".join(names),
        default={},
    )


def _coordinate_masses(masses: Mapping[str, Any], model: Model, mat: Any, path: tuple) -> tuple[Any, Any]:
    """M_x (nx) and M_q (nq): the masses and inertias given on the pose and actuator coordinates
    (a block's of the hinge material ``mat``)."""
    c = model.closure
    density, name = (mat.density, mat.name) if mat else (None, "?")
    mx, mq = np.zeros(c.nx), np.zeros(c.nq)
    for key, value in masses.items():
        if value is None:
            continue
        where = path + ("masses", key)
        on_x = key in c.x_names
        kind = c.x[c.x_names.index(key)].kind if on_x else c.q[c.q_names.index(key)].kind
        m = parse_mass(value, density, name, where) if kind == "length" else parse_inertia(value, density, name, where)
        if on_x:
            mx[c.x_names.index(key)] = m
        else:
            mq[c.q_names.index(key)] = m
    return mx, mq


def _check_flexible_links(sm: Any, bodies: Sequence[Any], path: tuple) -> None:
    """A link that is a flexible body (between two joints) has its elements' masses: not a rigid link's too."""
    flexible = sm.flexible_links()
    for b in bodies:
        if (b.leg, b.joint) in flexible:
            raise InputError(
                f"link {b.name} is the flexible body {flexible[(b.leg, b.joint)]}, whose elements carry its mass "
                "(the material's density); remove the link",
                path=path,
            )


class NaturalFrequencies(_HingeKind):
    name = "natural_frequencies"
    #: the hinges, and the legs as serial chains for the six-axis hinge model and the link masses
    parts = (cm.JointStiffness, LegChains)
    description = (
        "natural frequencies and mode shapes at a pose: linearized Lagrange with the masses and inertias on the "
        "coordinates and the links' masses; the kinematic hinge model (K = K_q, M = J^T M_x J + M_q) or every "
        "hinge a six-axis spring (hinge_axes: all)"
    )
    plots = ("modes",)

    def input_options(self, model: Model) -> list[Option]:
        opts = task_options(model, "scalar") + actuator_options(model, "scalar") + hinge_options() + [bodies_option()]
        opts.append(masses_node(model))
        ka = k_actuator_option(model)
        return [
            *opts,
            _links_node(),
            Option(
                "hinge_axes",
                "choice",
                "the hinge model: 'kinematic' (each hinge only about the axes the kinematics moves; the default) or "
                "'all' (every flexure a six-axis spring at its joint; needs the mechanism's leg chains)",
                default="kinematic",
                choices=tuple(HINGE_MODELS),
            ),
            dataclasses.replace(
                ka,
                description="actuator stiffness: 0 N/m (free, the default: only the hinges hold the actuated "
                "motions), a stiffness (one, or one per actuator), or 'rigid' (held; with hinge_axes: all)",
                default=0.0,
            ),
            Option("n_modes", "int", "how many modes to report with hinge_axes: all (default: nx)", None, 1, 60),
        ]

    def resolve(self, inputs: dict[str, Any], model: Model, path: tuple) -> None:
        """The hinges, the mass matrices M_x, M_q of the masses (a block's of the hinge material),
        the hinge model and the links."""
        super().resolve(inputs, model, path)
        hs: cm.HingeSet = inputs["hinge_set"]
        if hs.bodies and inputs["hinge_axes"] != "all":
            raise InputError(
                "the kinematic hinge model takes rigid links, and the mechanism declares flexible bodies "
                f"({', '.join(b.name for b in hs.bodies)}); give hinge_axes: all (the six-axis model with the "
                "beams' elements)",
                path=("mechanism", "stiffness", "bodies"),
            )
        for b in hs.bodies:
            if b.material.density is None:
                raise InputError(
                    f"body {b.name}: its elements' masses need the material's density "
                    "(material: {E: ..., nu: ..., density: ...})",
                    path=b.path + ("material",),
                )
        mat = next((h.material for h in hs.hinges if h.material is not None), None)
        density = mat.density if mat else None
        mx, mq = inputs["M_x"], inputs["M_q"] = _coordinate_masses(inputs["masses"] or {}, model, mat, path)
        six = inputs["hinge_axes"] == "all"
        if six and inputs["k_actuator"] is None and not np.any(mx):
            raise InputError("with the actuators held, give masses on the pose coordinates", path=path + ("masses",))
        if not six and inputs["k_actuator"] is None:
            raise InputError(
                "k_actuator: rigid holds the actuators, and the kinematic hinge model then has no motion left; "
                "give a stiffness, or hinge_axes: all",
                path=path + ("k_actuator",),
            )
        inputs["hinge_model"] = None
        if six or inputs["links"]:
            why = "hinge_axes: all" if six else "links"
            if not has_chains(model):
                raise InputError(
                    f"{why} needs the legs of {model.name} as serial chains (the mechanism's chains capability; a "
                    "mechanism file of spatial P, R, C, U, S legs gives them)",
                    path=path + (("hinge_axes",) if six else ("links",)),
                )
            where = path + (("hinge_axes",) if six else ("links",))
            inputs["hinge_model"] = HINGE_MODELS["all"].prepare(model, hs, where, True)
        inputs["link_bodies"] = []
        if inputs["links"]:
            sm = inputs["hinge_model"].six_axis
            inputs["link_bodies"] = link_bodies(sm, inputs["links"], density, path + ("links",))
            _check_flexible_links(sm, inputs["link_bodies"], path + ("links",))
        if not np.any(mx) and not np.any(mq) and not inputs["link_bodies"] and not hs.bodies:
            raise InputError(
                "expected masses: a mapping of coordinate -> mass or inertia, or links with mass",
                path=path + ("masses",),
            )

    def check_inputs(self, inputs: dict[str, Any], model: Model, path: tuple) -> None:
        _check_pose_inputs(model, inputs, path, required=False)

    def run(self, model: Model, inputs: Mapping[str, Any], solver: SolverConfig) -> Result:
        c = model.closure
        hs: cm.HingeSet = inputs["hinge_set"]
        sol = _commanded_pose(model, inputs, solver)
        out = Values(_pose_outputs(model), _pose_values(model, [sol], False))
        info = poses_solver_info([sol], solver.name)
        if not sol.ok:
            return _hinge_result(self.name, model, sol.status, out, info, sol.message)
        bodies = inputs["link_bodies"]
        prepared: Prepared | None = inputs["hinge_model"]
        sm = prepared.six_axis if prepared is not None else None
        if bodies:
            out.add(LINK_MASSES, [float(b.mass_inertia()[0]) for b in bodies])
        if inputs["hinge_axes"] == "all":
            return self._six_axis(model, inputs, sol, out, info)
        sp = cm.static_point(model, hs, sol.x, sol.q)
        M = sp.J.T @ np.diag(inputs["M_x"]) @ sp.J + np.diag(inputs["M_q"])
        if bodies:  # the links move with the rigid kinematics: T^T M_z T
            z = sm.start(sol.x, sol.q)
            T = rigid_velocity_map(sm, z)
            M = M + T.T @ link_mass_matrix(sm, bodies, z) @ T
        K = 0.5 * (sp.K_q + sp.K_q.T) + np.diag(inputs["k_actuator"])
        try:  # canonical modes: the same on every BLAS kernel (docs/site/guide/compliance.md)
            lam, modes, clusters = canonical_eigh(K, M, T=sp.J)  # read in the pose coordinates
        except np.linalg.LinAlgError:
            msg = "the mass matrix J^T M_x J + M_q is singular: give masses that move every actuated direction"
            return _hinge_result(self.name, model, Status.SINGULAR, out, info, msg)
        freq = np.sqrt(np.clip(lam, 0.0, None)) / (2 * np.pi)
        out.add_all((Output(f"f{k + 1}", "frequency"), float(freq[k])) for k in range(c.nq))
        out.add_all(zip(_mode_outputs(c), (M.tolist(), K.tolist(), modes.T.tolist(), (sp.J @ modes).T.tolist())))
        out.add(MULTIPLICITY, multiplicities(clusters))
        out.add(text("hinge_model"), "kinematic").add(N_MODES, c.nq)
        msg = "kinematic hinge model: frequencies from |K_q - (2 pi f)^2 M| = 0 at the pose"
        repeated = [idx for idx in clusters if len(idx) > 1]
        if repeated:
            msg += "; " + "; ".join(degenerate_note(idx) for idx in repeated)
        res = _hinge_result(self.name, model, Status.SOLVED, out, info, msg)
        return res.warn(*point_warnings(hs, [sp]))

    def _six_axis(
        self, model: Model, inputs: Mapping[str, Any], sol: PoseSolution, out: Values, info: SolverInfo
    ) -> Result:
        """The modes of the six-axis hinge model about its equilibrium at the commanded actuators."""
        c = model.closure
        sm = inputs["hinge_model"].six_axis
        z0 = sm.start(sol.x, sol.q)
        ok, z, lam, it = sm.newton(z0, np.zeros(c.nx), sol.q, None, None)
        info = SolverInfo("newton-kkt", info.iterations + it, info.seconds)
        if not ok:
            msg = "six-axis hinge model: no equilibrium at the commanded actuators (Newton on the KKT)"
            return _hinge_result(self.name, model, Status.NOT_CONVERGED, out, info, msg)
        M_z = link_mass_matrix(sm, inputs["link_bodies"], z) + sm.beam_mass_matrix(z)  # the beams' elements
        M_z[: c.nx, : c.nx] += np.diag(inputs["M_x"])
        M_z[c.nx : c.nx + c.nq, c.nx : c.nx + c.nq] += np.diag(inputs["M_q"])
        held = inputs["k_actuator"] is None
        try:
            modes = six_axis_modes(sm, z, lam, M_z, inputs["k_actuator"], held)
        except np.linalg.LinAlgError as exc:
            msg = f"six-axis hinge model: {exc} (give a positive k_actuator, or masses that move every direction)"
            return _hinge_result(self.name, model, Status.SINGULAR, out, info, msg)
        n = min(inputs["n_modes"] or c.nx, len(modes.frequencies))
        f = modes.frequencies[:n]
        out.add_all((Output(f"f{k + 1}", "frequency"), float(f[k])) for k in range(n))
        Z = modes.modes_z[:, :n]
        outs = _mode_outputs(c)
        out.add_all(zip(outs[2:], (Z[c.nx : c.nx + c.nq].T.tolist(), Z[: c.nx].T.tolist())))
        clusters = [[i for i in idx if i < n] for idx in modes.clusters]
        clusters = [idx for idx in clusters if idx]
        out.add(MULTIPLICITY, multiplicities(clusters))
        out.add(text("hinge_model"), "all").add(N_MODES, len(modes.frequencies))
        held_text = "actuators held" if held else "actuators on k_actuator"
        msg = (
            f"six-axis hinge model ({held_text}): the {n} lowest of {len(modes.frequencies)} modes with mass, from "
            f"|K - (2 pi f)^2 M| = 0 on the motions that keep the closures; six-axis hinges: "
            f"{', '.join(sm.six_axis_hinges) or 'none'}; {sm.chains.note}"
        )
        if sm.hs.bodies:
            models = sorted({mdl for b in sm.hs.bodies for mdl in b.beam.models})
            masses = " and ".join({"distributed": "consistent", "lumped": "lumped"}[mdl] for mdl in models)
            names = ", ".join(b.name for b in sm.hs.bodies)
            msg += f"; but the links that are flexible bodies ({names}) are beams with {masses} element masses"
        repeated = [idx for idx in clusters if len(idx) > 1]
        if repeated:
            msg += "; " + "; ".join(degenerate_note(idx) for idx in repeated)
        res = _hinge_result(self.name, model, Status.SOLVED, out, info, msg)
        return res.warn(*six_axis_warnings(sm, [z]))

    def outputs(self, model: Model) -> list[Output]:
        c = model.closure
        frequencies = [Output(f"f{k + 1}", "frequency") for k in range(max(c.nq, c.nx))]
        extra = [text("hinge_model"), N_MODES, LINK_MASSES]
        return [*_pose_outputs(model), *frequencies, *_mode_outputs(c), MULTIPLICITY, *extra]
