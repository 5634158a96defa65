"""The six-axis hinge model: compliant forward kinematics and platform compliance
with every flexure a six-degree-of-freedom spring at its joint.

The pseudo-rigid-body model of `cpm_nlp.analysis.compliance` lets a hinge
turn only about the axes the kinematics moves, so with the actuators held a
mechanism of rigid links does not deflect at all.  A real flexure also bends
about its second axis, twists, stretches and shears.  Here each leg is the
serial chain of its joints at the reference configuration (the part ``chains``,
[`LegChains`][cpm_nlp.core.chains.LegChains]) and every hinge adds, at its joint and
in its own frame (length axis t, compliant axis b1, second axis b2 = b1 x t),
the axes its joint does not move, each with the flexure library's stiffness
(`cpm_nlp.analysis.hinge_types.HINGE_TABLE`, each type's ``six_axis``):

    leg k:  G_k(z) = Π_j [ Π_d exp(ξ_jd θ_jd) · Π_a exp(η_ja ε_ja) ]      (product of exponentials)
    closure: G_k(z) = T_P(x) T_P(x_ref)⁻¹  at the leg's platform point (3 rows) and in rotation (3 rows)
    energy:  U(z) = ½ Σ_hinges Σ_axes k_a δ_a²,  δ the deflection from the reference configuration

with z = (x, q, θ, ε): the pose, the actuators, the chains' joint variables and
the hinges' extra deflections.  The loaded pose minimizes V = U - fᵀx (f the
load conjugate to the pose coordinates) subject to the 6 n_legs closures with
the actuators held (or on springs k_a about their unloaded forces): an NLP
solved by IPOPT, and by Newton on its KKT conditions (the fast path, checked
against IPOPT in the tests).

The output compliance is the linearization of that equilibrium: with
H = ∇²(V + λᵀg) and A = ∂g/∂z at the solution,

    [H  Aᵀ] [dz]   [E df]
    [A  0 ] [dλ] = [ 0  ],     C = Eᵀ dz/df  (nx x nx),

E selecting the pose coordinates.  With the extra axes made infinitely stiff it
reduces to the pseudo-rigid-body C = J (K_q + K_a)⁻¹ Jᵀ (tested), and at an
unstressed pose to the compliance-matrix method Σ_legs (Σ_h Ad C_h Adᵀ)⁻¹
(tested against an independent numpy derivation).

A link may be flexible (``bodies``: `cpm_nlp.analysis.beam_inputs`): a beam of
n elements between two neighbouring joints of a leg, each element six more
variables ε after the first joint's motions and the energy ½ εᵀ K_e ε
(`cpm_nlp.analysis.beams`, geometrically nonlinear).  The platform stays rigid.
"""

from __future__ import annotations

import logging
import threading
from collections import OrderedDict
from dataclasses import dataclass, field
from typing import Any

import casadi as ca
import numpy as np
import scipy.linalg

from ..core.blas import one_blas_thread
from ..core.chains import Chains, LegChains
from ..core.errors import InputError
from ..core.fast_calls import FastFunction
from ..core.model import Model
from ..core.screws import axis_rotation, vee
from .beam_inputs import PLATFORM, Body
from .beams import DEFORMATIONS, beam_elements, element_motions, element_wrenches
from .compliance import HINGE_TYPES, HingeSet, six_axis_stiffness
from .hinge_types import SIX_AXES

log = logging.getLogger(__name__)

_ROT_AXES = ("bend", "bend2", "torsion")


def _rot(axis: np.ndarray, angle: Any) -> Any:
    """Rotation by ``angle`` about the unit ``axis`` (Rodrigues: `axis_rotation`)."""
    return axis_rotation(ca.DM(np.asarray(axis, dtype=float).reshape(3, 1)), angle)


def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v)


def _perpendicular(v: np.ndarray) -> np.ndarray:
    trial = np.eye(3)[int(np.argmin(np.abs(v)))]
    return _unit(trial - np.dot(trial, v) * v)


@dataclass
class HingeFrame:
    """One hinge in the chains: where it sits, its frame, and the variable of each axis.

    Attributes
    ----------
    axes
        axis name -> (kind "R" or "P", unit vector);
    variables
        axis name -> (index in z, rest value);
    k
        axis name -> stiffness.
    """

    name: str
    kind: str | None
    dims: dict[str, float]
    centre: np.ndarray | None
    axes: dict[str, tuple[str, np.ndarray]] = field(default_factory=dict)
    variables: dict[str, tuple[int, float]] = field(default_factory=dict)
    k: dict[str, float] = field(default_factory=dict)
    extra: tuple[str, ...] = ()
    #: (leg, joint) of the chains it sits at
    loc: tuple[int, int] | None = None


def _frame(known: dict[str, np.ndarray], link: np.ndarray | None) -> dict[str, np.ndarray]:
    """The hinge frame (t, b1, b2) from the axes its joint gives and its link direction."""
    t = known.get("torsion")
    b1, b2 = known.get("bend"), known.get("bend2")
    if t is None:
        t = link if link is not None else _perpendicular(b1 if b1 is not None else b2)
        for b in (b1, b2):
            if b is not None:
                t = t - np.dot(t, b) * b
        t = _unit(t) if np.linalg.norm(t) > 1e-9 else _perpendicular(b1 if b1 is not None else b2)
    if b1 is None and b2 is None:
        b1 = _perpendicular(t)
    if b2 is None:
        b2 = _unit(np.cross(b1, t))
    if b1 is None:
        b1 = _unit(np.cross(t, b2))
    return {"torsion": t, "bend": b1, "bend2": b2}


class SixAxisModel:
    """The six-axis hinge model of one model and hinge set (built once, then solved
    at any pose and load).  Sizes: nz = nx + nq + chain variables + extra hinge axes,
    6 closure rows per leg."""

    def __init__(self, model: Model, hs: HingeSet, chains: Chains) -> None:
        c = model.closure
        self.model, self.hs, self.chains = model, hs, chains
        self.nx, self.nq = c.nx, c.nq
        _check_reference(model, chains)
        x_index = {n: i for i, n in enumerate(c.x_names)}
        q_index = {n: i for i, n in enumerate(c.q_names)}
        self.names: list[str] = list(c.x_names) + list(c.q_names)
        rest: list[float] = list(model.x_home) + list(model.q_home)
        self._dof: dict[str, tuple[int, float, int, int, int]] = {}  # coordinate -> (z, rest, leg, joint, dof)
        self._z: list[Any] = [ca.SX.sym(n) for n in self.names]
        self._where = _joint_places(chains)
        self._pinned: list[int] = []
        #: (leg, joint) -> the body whose beam is that joint's hinge (`Body.centred`)
        self.hinge_beams = _hinge_beams(hs, self._where, chains, set(c.x_names))
        legs = [self._leg_motions(li, x_index, q_index, rest) for li in range(len(chains.legs))]
        self.frames = self._hinge_frames(hs, c, x_index, q_index, chains)
        # the extra axes of each hinge: new variables, placed after their joint's own motions
        extra: dict[tuple[int, int], list[tuple[str, np.ndarray, Any]]] = {}
        for fr in self.frames:
            for a in fr.extra:
                fr.variables[a] = (self._new(f"{fr.name}_{a}", rest), 0.0)
                kind, u = fr.axes[a]
                extra.setdefault(fr.loc, []).append((kind, u, self._z[-1]))
        self.beams = self._beam_elements(hs, chains, rest, extra)
        self.rest = np.array(rest)
        self.nz = len(self._z)
        z = ca.vertcat(*self._z)
        self._legs, self._extra = legs, extra  # for the bodies' frames (`body_frames`)
        self._body_frames: ca.Function | None = None
        self._beam_nodes: ca.Function | None = None
        g = self._closures(z, legs, extra)
        self.ng = g.numel()
        self._functions(z, g)

    def _new(self, label: str, rest: list[float]) -> int:
        self._z.append(ca.SX.sym(label))
        self.names.append(label)
        rest.append(0.0)
        return len(self._z) - 1

    def _leg_motions(self, li: int, x_index: dict, q_index: dict, rest: list[float]) -> list:
        """Each joint of leg li with its elementary motions (kind, axis, displacement from the
        reference): an actuator's from q, a pose coordinate's from x, else a new variable."""
        leg, ch = self.chains.legs[li], self.chains
        rows = []
        for ji, j in enumerate(leg.joints):
            motions = []
            for d, kind in enumerate(j.motions):
                cname = j.coordinates[d]
                if j.actuated is not None:
                    qi = q_index[j.actuated]
                    value = j.gain * (self._z[self.nx + qi] - ch.q_reference[qi])
                elif cname and cname in x_index:
                    xi = x_index[cname]
                    value = self._z[xi] - ch.x_reference[xi]
                    self._dof[cname] = (xi, ch.x_reference[xi], li, ji, d)
                else:
                    zi = self._new(cname or f"{leg.name}_j{ji + 1}_{d + 1}", rest)
                    # a hinge modelled as a beam: the beam's elements carry the joint's motion, and the
                    # joint's own variable, out of the chain, is pinned at zero (`_functions`)
                    value = self._z[zi]
                    if (li, ji) in self.hinge_beams:
                        value = 0
                        self._pinned.append(zi)
                    if cname:
                        self._dof[cname] = (zi, 0.0, li, ji, d)
                motions.append((kind, j.axes[:, d], value))
            rows.append((j, motions))
        return rows

    def _closures(self, z: Any, legs: list, extra: dict) -> Any:
        """Per leg, its platform point (3 rows) and its rotation (3 rows) against the platform's."""
        ch = self.chains
        P, R = ch.platform(z[: self.nx])
        P0, R0 = (np.asarray(v, dtype=float) for v in ch.platform(ch.x_reference))
        P0 = P0.ravel()
        DR = R @ R0.T
        g = []
        for li, rows in enumerate(legs):
            Rm, tm = ca.SX.eye(3), ca.SX.zeros(3)
            for ji, (j, motions) in enumerate(rows):
                for kind, axis, value, *point in motions + extra.get((li, ji), []):
                    at = ca.DM(point[0] if point else j.at)  # a beam element turns about its spring point
                    if kind == "P":
                        Rk, tk = ca.SX.eye(3), value * ca.DM(axis)
                    else:
                        Rk = _rot(axis, value)
                        tk = at - Rk @ at
                    Rm, tm = Rm @ Rk, Rm @ tk + tm
            tip = ca.DM(ch.legs[li].tip)
            g.append(Rm @ tip + tm - (DR @ (tip - P0) + P))  # the leg's platform point
            M = DR.T @ Rm
            g.append(vee(M))  # rotation
        return ca.vertcat(*g)

    def body_frames(self) -> ca.Function:
        """``("<name>_body_frames", [z], [R, t])``: the rigid motion (R_b, t_b) of the body after
        each joint of each leg (a point p0 of it at the reference configuration is at
        R_b p0 + t_b), in leg and joint order, R stacked as 3 x 3 blocks side by side and t
        as columns.  The body after a joint moves with that joint's motions and its hinge's
        extra axes (the same product of exponentials as the closures).  Built once."""
        if self._body_frames is not None:
            return self._body_frames
        z = ca.vertcat(*self._z)
        Rs, ts = [], []
        for li, rows in enumerate(self._legs):
            Rm, tm = ca.SX.eye(3), ca.SX.zeros(3)
            for ji, (j, motions) in enumerate(rows):
                for kind, axis, value, *point in motions + self._extra.get((li, ji), []):
                    Rm, tm = _apply(Rm, tm, kind, axis, value, point[0] if point else j.at)
                Rs.append(Rm)
                ts.append(tm)
        name = f"{self.model.closure.name}_body_frames"
        self._body_frames = ca.Function(name, [z], [ca.horzcat(*Rs), ca.horzcat(*ts)], ["z"], ["R", "t"])
        return self._body_frames

    def beam_node_jacobians(self) -> ca.Function:
        """``("<name>_beam_node_jacobians", [z], [J])``: per beam element (of `beams`, in order), the
        12 x nz Jacobian of its nodes' velocities (v_0, ω_0, v_1, ω_1) read in the element's axes
        turned with its start node (the axes of its mass matrix, `cpm_nlp.analysis.beams.element_mass`),
        stacked.  The start node moves with the product up to the element's motions, the end node
        with it and them.  Built once."""
        if self._beam_nodes is not None:
            return self._beam_nodes
        z = ca.vertcat(*self._z)
        zd = ca.SX.sym("zd", self.nz)
        wanted = {(li, ja, p) for places in self._element_places for li, ja, p0, p1 in places for p in (p0, p1)}
        snap: dict[tuple[int, int, int], tuple[Any, Any]] = {}
        for li, rows in enumerate(self._legs):
            Rm, tm = ca.SX.eye(3), ca.SX.zeros(3)
            for ji, (j, motions) in enumerate(rows):
                for p, (kind, axis, value, *point) in enumerate(motions + self._extra.get((li, ji), [])):
                    if (li, ji, p) in wanted:
                        snap[(li, ji, p)] = (Rm, tm)
                    Rm, tm = _apply(Rm, tm, kind, axis, value, point[0] if point else j.at)
                p = len(motions) + len(self._extra.get((li, ji), []))
                if (li, ji, p) in wanted:
                    snap[(li, ji, p)] = (Rm, tm)
        rows_out = []
        for (_, _, elements), places in zip(self.beams, self._element_places, strict=True):
            for (el, _), (li, ja, p0, p1) in zip(elements, places, strict=True):
                axes = snap[(li, ja, p0)][0] @ ca.DM(el.axes)
                for (R, t), node in zip((snap[(li, ja, p0)], snap[(li, ja, p1)]), el.nodes):
                    Jv = ca.jacobian(R @ ca.DM(node) + t, z)
                    Rdot = ca.reshape(ca.jacobian(ca.reshape(R, 9, 1), z) @ zd, 3, 3)
                    Jw = ca.jacobian(vee(Rdot @ R.T), zd)
                    rows_out += [axes.T @ Jv, axes.T @ Jw]
        J = ca.densify(ca.vertcat(*rows_out)) if rows_out else ca.DM.zeros(0, self.nz)
        name = f"{self.model.closure.name}_beam_node_jacobians"
        self._beam_nodes = ca.Function(name, [z], [J], ["z"], ["J"])
        return self._beam_nodes

    def beam_mass_matrix(self, z: np.ndarray) -> np.ndarray:
        """M_z (nz x nz) of the flexible bodies' elements at z: Σ_e J_eᵀ M_e J_e with M_e the
        element's mass matrix (`Element.M`) and J_e its nodes' velocity Jacobian
        (`beam_node_jacobians`).  Raises ValueError when an element has no mass matrix (no density)."""
        M = np.zeros((self.nz, self.nz))
        if not self.beams:
            return M
        J = np.asarray(self.beam_node_jacobians()(z), dtype=float)
        k = 0
        for body, _, elements in self.beams:
            for el, _ in elements:
                if el.M is None:
                    raise ValueError(f"body {body.name}: its material has no density")
                Je = J[12 * k : 12 * k + 12]
                M += Je.T @ el.M @ Je
                k += 1
        return 0.5 * (M + M.T)

    def _functions(self, z: Any, g: Any) -> None:
        """The energy of every axis of every hinge, and the named CasADi functions."""
        name = self.model.closure.name
        U = 0
        for fr in self.frames:
            for a, (zi, r0) in fr.variables.items():
                U += 0.5 * fr.k[a] * (z[zi] - r0) ** 2
        for _, _, elements in self.beams:
            for el, idx in elements:
                e = ca.vertcat(*[z[i] for i in idx])
                U += 0.5 * ca.dot(e, ca.mtimes(ca.DM(el.K), e))
        for zi in self._pinned:  # out of the chain: a unit spring keeps the KKT matrix regular, at zero
            U += 0.5 * z[zi] ** 2
        f = ca.SX.sym("f", self.nx)
        qc, ka, Fc = ca.SX.sym("qc", self.nq), ca.SX.sym("ka", self.nq), ca.SX.sym("Fc", self.nq)
        dq = z[self.nx : self.nx + self.nq] - qc
        V = U - ca.dot(f, z[: self.nx]) + 0.5 * ca.dot(ka, dq * dq) - ca.dot(Fc, dq)
        lam = ca.SX.sym("lam", self.ng)
        par = ca.vertcat(f, qc, ka, Fc)
        L = V + ca.dot(lam, g)
        H = ca.hessian(L, z)[0]
        A = ca.jacobian(g, z)
        self.kkt = ca.Function(
            f"{name}_six_axis_kkt",
            [z, lam, par],
            [ca.gradient(L, z), g, ca.densify(H), ca.densify(A), V],
            ["z", "lam", "par"],
            ["grad_L", "g", "H", "A", "V"],
        )
        self._kkt_fast = FastFunction(self.kkt)
        self.closure_fn = ca.Function(f"{name}_six_axis_closure", [z], [g], ["z"], ["g"])
        self._nlp = {"x": z, "p": par, "f": V, "g": g}
        self._ipopt: Any = None
        self._last_kkt: tuple | None = None

    # -- the hinges in the chains ---------------------------------------------------------------
    def _hinge_frames(self, hs: HingeSet, c, x_index, q_index, chains: Chains) -> list[HingeFrame]:
        frames = []
        for h in hs.hinges:
            fr = HingeFrame(h.name, h.kind, dict(h.dims), None)
            known: dict[str, np.ndarray] = {}
            loc = None
            for a, i in h.axes.items():
                cname = hs.names[i]
                if cname in self._dof:
                    zi, r0, li, ji, d = self._dof[cname]
                    joint = chains.legs[li].joints[ji]
                    loc = (li, ji)
                    if joint.motions[d] == "R" and a in _ROT_AXES:
                        known[a] = joint.axes[:, d]
                elif cname in x_index:
                    zi, r0 = x_index[cname], float(self.model.x_home[x_index[cname]])
                elif cname in q_index:
                    zi, r0 = self.nx + q_index[cname], float(self.model.q_home[q_index[cname]])
                else:
                    raise InputError(
                        f"hinge {h.name}: joint {cname} is not in the legs' chains of {c.name}, so the six-axis "
                        "model cannot place it",
                        path=("inputs", "hinges", h.group),
                        hint="use hinge_axes: kinematic",
                    )
                fr.variables[a] = (zi, r0)
                fr.k[a] = h.k[a]
            six = six_axis_stiffness(h)
            if loc is not None and six is not None:
                joint = chains.legs[loc[0]].joints[loc[1]]
                fr.centre = joint.at
                frame = _frame(known, joint.link)
                dirs = {**frame, "axial": frame["torsion"], "shear": frame["bend2"], "shear2": frame["bend"]}
                fr.extra = () if loc in self.hinge_beams else tuple(a for a in SIX_AXES if a not in fr.variables)
                for a in fr.extra:
                    fr.axes[a] = ("R" if a in _ROT_AXES else "P", dirs[a])
                    fr.k[a] = six[a]
            fr.loc = loc
            frames.append(fr)
        return frames

    # -- the flexible bodies in the chains --------------------------------------------------------
    def _beam_elements(self, hs: HingeSet, chains: Chains, rest: list[float], extra: dict) -> list:
        """Each flexible body's beam elements on each leg, their deformation variables, and their
        motions after the body's first joint (`cpm_nlp.analysis.beams`): [(body, leg, [(element,
        z indices)])]."""
        where = self._where
        out = []
        self._beam_joints: list[tuple[int, int]] = []
        #: per beam of `beams`, per element: (leg, joint, its first and past-last place in the joint's product)
        self._element_places: list[list[tuple[int, int, int, int]]] = []
        for body in hs.bodies:
            for m, (first, second) in enumerate(body.members):
                if body.centred:
                    li, ja = where[first]
                    leg = chains.legs[li]
                    joint = leg.joints[ja]
                    t = joint.link if joint.link is not None else _perpendicular(joint.axes[:, 0])
                    half = 0.5 * float(body.beam.section.length or body.beam.length)
                    start, end, jb = joint.at - half * t, joint.at + half * t, ja
                else:
                    li, ja, jb = _body_ends(body, m, first, second, where, chains)
                    leg = chains.legs[li]
                    start = leg.joints[ja].at
                    end = leg.tip if jb == len(leg.joints) else leg.joints[jb].at
                bend = (
                    _first_rotation(leg.joints[ja])
                    if _first_rotation(leg.joints[ja]) is not None
                    else (_first_rotation(leg.joints[jb]) if jb < len(leg.joints) else None)
                )
                span = float(np.linalg.norm(np.asarray(end) - np.asarray(start)))
                ell = body.beam.section.length if body.beam.section.length is not None else body.beam.length
                if ell is not None and float(ell) > span * (1 + 1e-12):
                    raise InputError(
                        f"body {body.name}: a flexible length of {float(ell) * 1e3:g} mm does not fit the "
                        f"{span * 1e3:g} mm between its joints",
                        path=body.path + ("section" if body.beam.section.length is not None else "length",),
                    )
                mat = body.material
                elements, places = [], []
                for k, el in enumerate(beam_elements(body.beam, start, end, bend, mat.E, mat.nu, mat.density)):
                    idx = [self._new(f"{body.name}{m + 1}_e{k + 1}_{DEFORMATIONS[d]}", rest) for d in el.dofs]
                    # where the element's motions sit in its joint's product (the joint's own, then extra)
                    p0 = len(leg.joints[ja].motions) + len(extra.get((li, ja), []))
                    extra.setdefault((li, ja), []).extend(element_motions(el, [self._z[i] for i in idx]))
                    elements.append((el, idx))
                    places.append((li, ja, p0, p0 + len(idx)))
                out.append((body, li, elements))
                self._element_places.append(places)
                self._beam_joints.append((ja, m))
        return out

    def beam_places(self) -> list[tuple[int, int]]:
        """Per beam of `beams`: (leg, the joint its elements follow)."""
        return [(li, ja) for (_, li, _), (ja, _) in zip(self.beams, self._beam_joints, strict=True)]

    def flexible_links(self) -> dict[tuple[int, int], str]:
        """(leg, first joint) -> the flexible body that is the link after that joint (``between``)."""
        beams = zip(self.beams, self._beam_joints, strict=True)
        return {(li, ja): body.name for (body, li, _), (ja, _) in beams if not body.centred}

    def body_stresses(self, z: np.ndarray) -> dict[str, float]:
        """The largest nominal stress of each flexible body (over its legs and elements; a given
        section has none)."""
        out: dict[str, float] = {}
        for (body, _, _), worst in zip(self.beams, self._beam_stresses(z), strict=True):
            if worst is not None:
                out[body.name] = max(out.get(body.name, 0.0), worst)
        return out

    def _beam_stresses(self, z: np.ndarray) -> list[float | None]:
        """The largest nominal stress of each beam of `beams` (a body on one leg; None for a given
        section)."""
        out = []
        for body, _, elements in self.beams:
            vals = [v for el, idx in elements for v in element_wrenches(el, np.asarray(z)[idx], body.beam.section)]
            out.append(None if any(v is None for v in vals) else max(vals))
        return out

    @property
    def six_axis_hinges(self) -> list[str]:
        return [fr.name for fr in self.frames if fr.extra]

    # -- solves ---------------------------------------------------------------------------------
    @one_blas_thread  # small dense solves: BLAS threads cost more than they give
    def start(self, x: np.ndarray, q: np.ndarray) -> np.ndarray:
        """A start z at a rigid pose: the pose and actuators, the chains' variables from the
        closure's passive joint values where it reports them, then fitted to the pose
        (minimum-norm Gauss-Newton on the closures, the extra hinge axes starting at 0)."""
        z = self.rest.copy()
        z[: self.nx], z[self.nx : self.nx + self.nq] = x, q
        c = self.model.closure
        if c.passive is not None and self._dof:
            now = np.asarray(c.passive(x, q, self.model.p), dtype=float).ravel()
            ref = np.asarray(c.passive(self.chains.x_reference, self.chains.q_reference, self.model.p), dtype=float)
            for k, name in enumerate(c.passive_names):
                if name in self._dof and self._dof[name][0] >= self.nx + self.nq:
                    z[self._dof[name][0]] = now[k] - ref.ravel()[k]
        free = np.arange(self.nx + self.nq, self.nz)
        par = np.zeros(self.nx + 3 * self.nq)
        for _ in range(30):
            _, g, _, A = self._eval(z, np.zeros(self.ng), par)
            if np.max(np.abs(g)) < 1e-14:
                break
            Af = A[:, free]
            try:
                z[free] -= Af.T @ np.linalg.solve(Af @ Af.T, g)
            except np.linalg.LinAlgError:
                z[free] -= np.linalg.lstsq(Af, g, rcond=None)[0]
        return z

    def linearization(self, z: np.ndarray, lam: np.ndarray, ka: np.ndarray | None = None) -> tuple[np.ndarray, ...]:
        """H = ∇²(V + λᵀg) (nz x nz, with actuator springs ``ka`` on q) and A = ∂g/∂z (ng x nz) at
        (z, λ), no load, the actuators commanded where they are."""
        _, _, H, A = self._eval(z, lam, self._par(np.zeros(self.nx), z[self.nx : self.nx + self.nq], ka, None))
        return H, A

    def _eval(self, z: np.ndarray, lam: np.ndarray, par: np.ndarray) -> tuple[np.ndarray, ...]:
        """grad_L (nz), g (ng), H (nz x nz), A (ng x nz) as numpy arrays."""
        gl, g, H, A, _ = self._kkt_fast(z, lam, par)
        return gl, g, H.reshape(self.nz, self.nz, order="F"), A.reshape(self.ng, self.nz, order="F")

    @one_blas_thread
    def newton(
        self, z0: np.ndarray, f: np.ndarray, qc: np.ndarray, ka: np.ndarray | None, Fc: np.ndarray | None
    ) -> tuple[bool, np.ndarray, np.ndarray, int]:
        """The equilibrium by Newton on the KKT conditions from z0 (q held at qc when
        ka is None): (converged, z, λ, iterations)."""
        z = z0.copy()
        lam = np.zeros(self.ng)
        par = self._par(f, qc, ka, Fc)
        free = self._free(ka)
        if ka is None:
            z[self.nx : self.nx + self.nq] = qc
        length = max(1.0, self.model.characteristic_length)
        for it in range(1, 31):
            gl, g, H, A = self._eval(z, lam, par)
            r = np.concatenate([gl[free], g])
            K = self._kkt_matrix(H, A, free)
            step = _solve(K, -r)
            z[free] += step[: len(free)]
            lam += step[len(free) :]
            if np.max(np.abs(step[: len(free)])) < 1e-10 * length and np.max(np.abs(g)) < 1e-12 * length:
                # Newton converges quadratically: the next step would be below 1e-20, and the
                # KKT matrix of this one serves the linearization (it moves by O(step))
                self._last_kkt = (z.copy(), lam.copy(), ka is None, K)
                return True, z, lam, it
        return False, z, lam, 30

    def ipopt(
        self, z0: np.ndarray, f: np.ndarray, qc: np.ndarray, ka: np.ndarray | None, Fc: np.ndarray | None
    ) -> tuple[bool, np.ndarray, np.ndarray, int, str]:
        """The equilibrium by IPOPT (minimum of V on the closures): (ok, z, λ, iterations, status)."""
        if self._ipopt is None:
            opts = {
                "ipopt.print_level": 0,
                "print_time": False,
                "ipopt.sb": "yes",
                "ipopt.tol": 1e-14,
                "ipopt.constr_viol_tol": 1e-14,
                "ipopt.hessian_approximation": "exact",
            }
            self._ipopt = ca.nlpsol(f"{self.model.closure.name}_six_axis", "ipopt", self._nlp, opts)
        lbx, ubx = np.full(self.nz, -np.inf), np.full(self.nz, np.inf)
        if ka is None:
            lbx[self.nx : self.nx + self.nq] = ubx[self.nx : self.nx + self.nq] = qc
        sol = self._ipopt(x0=z0, p=self._par(f, qc, ka, Fc), lbx=lbx, ubx=ubx, lbg=0.0, ubg=0.0)
        st = self._ipopt.stats()
        z = np.asarray(sol["x"], dtype=float).ravel()
        res = float(np.max(np.abs(np.asarray(self.closure_fn(z), dtype=float))))
        ok = bool(st.get("success", False)) and res < 1e-10 * max(1.0, self.model.characteristic_length)
        return ok, z, np.asarray(sol["lam_g"], dtype=float).ravel(), int(st.get("iter_count", 0)), st["return_status"]

    @one_blas_thread
    def compliance(self, z: np.ndarray, lam: np.ndarray, ka: np.ndarray | None, Fc: np.ndarray | None) -> np.ndarray:
        """C = Eᵀ dz/df (nx x nx) at an equilibrium (z, λ)."""
        par = self._par(np.zeros(self.nx), z[self.nx : self.nx + self.nq], ka, Fc)
        free = self._free(ka)
        last = self._last_kkt
        if last is not None and last[2] and ka is None and np.array_equal(last[0], z) and np.array_equal(last[1], lam):
            K = last[3]  # the load enters the KKT matrix only through λ: the same matrix
        else:
            _, _, H, A = self._eval(z, lam, par)
            K = self._kkt_matrix(H, A, free)
        rhs = np.zeros((K.shape[0], self.nx))
        rhs[: self.nx, :] = np.eye(self.nx)  # the pose coordinates come first among the free variables
        dz = _solve(K, rhs)
        C = dz[: self.nx, :]
        return 0.5 * (C + C.T)

    def actuator_reactions(self, z: np.ndarray, lam: np.ndarray, f: np.ndarray) -> np.ndarray:
        """The forces the held actuators apply (∂(V + λᵀg)/∂q with the sign of a force on the mechanism)."""
        par = self._par(f, z[self.nx : self.nx + self.nq], None, None)
        gl = np.asarray(self.kkt(z, lam, par)[0], dtype=float).ravel()
        return gl[self.nx : self.nx + self.nq]

    @one_blas_thread
    def input_stiffness(self, z: np.ndarray, lam: np.ndarray, f: np.ndarray) -> np.ndarray:
        """K_q = dF/dq (nq x nq) at an equilibrium with the actuators held: the sensitivity of the
        reactions through the KKT system, [H_ff A_fᵀ; A_f 0][dz_f; dλ] = -[H_fq; A_q]."""
        par = self._par(f, z[self.nx : self.nx + self.nq], None, None)
        _, _, H, A = self._eval(z, lam, par)
        free, qi = self._free(None), np.arange(self.nx, self.nx + self.nq)
        K = self._kkt_matrix(H, A, free)
        rhs = -np.vstack([H[np.ix_(free, qi)], A[:, qi]])
        sol = _solve(K, rhs)
        dz, dlam = sol[: len(free)], sol[len(free) :]
        Kq = H[np.ix_(qi, qi)] + H[np.ix_(qi, free)] @ dz + A[:, qi].T @ dlam
        return 0.5 * (Kq + Kq.T)

    def energy(self, z: np.ndarray, f: np.ndarray) -> float:
        """V = U - fᵀx at z (the actuators held)."""
        par = self._par(f, z[self.nx : self.nx + self.nq], None, None)
        return float(self._eval_v(z, par))

    def _eval_v(self, z: np.ndarray, par: np.ndarray) -> float:
        return float(np.asarray(self.kkt(z, np.zeros(self.ng), par)[4]).ravel()[0])

    def joint_vector(self, z: np.ndarray, theta: np.ndarray) -> np.ndarray:
        """The hinge set's joint vector (x, q, passive) with each hinge's axes read from z."""
        out = np.array(theta, dtype=float)
        for fr, h in zip(self.frames, self.hs.hinges, strict=True):
            for a, i in h.axes.items():
                zi, r0 = fr.variables[a]
                out[i] = self.hs.theta0[i] + z[zi] - r0
        return out

    def stresses(self, z: np.ndarray) -> dict[str, float | None]:
        """Largest stress of each hinge from its moments (all three rotations) and axial force."""
        out: dict[str, float | None] = {}
        beams = zip(self.beams, self._beam_stresses(z), self._beam_joints, strict=True)
        beam_stress = {(li, ja): worst for (body, li, _), worst, (ja, _) in beams if body.centred}
        for fr in self.frames:
            if fr.loc in self.hinge_beams:  # a hinge modelled as a beam: the beam's largest stress
                out[fr.name] = beam_stress[fr.loc]
                continue
            if fr.kind is None:
                out[fr.name] = None
                continue
            loads = {a: fr.k[a] * (z[zi] - r0) for a, (zi, r0) in fr.variables.items() if a in (*_ROT_AXES, "axial")}
            out[fr.name] = float(HINGE_TYPES[fr.kind].stress(fr.dims, loads))
        return out

    def _par(self, f, qc, ka, Fc) -> np.ndarray:
        zeros = np.zeros(self.nq)
        return np.concatenate(
            [np.asarray(f, dtype=float), qc, zeros if ka is None else ka, zeros if Fc is None else Fc]
        )

    def _free(self, ka: np.ndarray | None) -> np.ndarray:
        if ka is not None:
            return np.arange(self.nz)
        return np.concatenate([np.arange(self.nx), np.arange(self.nx + self.nq, self.nz)])

    def _kkt_matrix(self, H: np.ndarray, A: np.ndarray, free: np.ndarray) -> np.ndarray:
        n = len(free)
        K = np.zeros((n + self.ng, n + self.ng))
        K[:n, :n] = H[np.ix_(free, free)]
        K[:n, n:] = A[:, free].T
        K[n:, :n] = A[:, free]
        return K


def _apply(Rm: Any, tm: Any, kind: str, axis: np.ndarray, value: Any, at: np.ndarray) -> tuple[Any, Any]:
    """(Rm, tm) followed by one elementary motion: a translation along ``axis``, or a rotation
    about it through ``at``."""
    if kind == "P":
        Rk, tk = ca.SX.eye(3), value * ca.DM(axis)
    else:
        Rk = _rot(axis, value)
        tk = ca.DM(at) - Rk @ ca.DM(at)
    return Rm @ Rk, Rm @ tk + tm


def _joint_places(chains: Chains) -> dict[str, tuple[int, int]]:
    """Every coordinate and actuator of the chains -> (leg, joint)."""
    where: dict[str, tuple[int, int]] = {}
    for li, leg in enumerate(chains.legs):
        for ji, j in enumerate(leg.joints):
            for cname in (*j.coordinates, j.actuated):
                if cname:
                    where[cname] = (li, ji)
    return where


def _hinge_beams(hs: HingeSet, where: dict, chains: Chains, pose: set[str]) -> dict[tuple[int, int], Body]:
    """(leg, joint) -> the body modelling that joint's hinge as a beam (``at``): a passive joint."""
    out: dict[tuple[int, int], Body] = {}
    for body in hs.bodies:
        if not body.centred:
            continue
        for first, _ in body.members:
            if first not in where:
                raise InputError(
                    f"body {body.name}: joint {first} is not in the legs' chains, so the body cannot be placed",
                    path=body.path + ("at",),
                )
            li, ji = where[first]
            joint = chains.legs[li].joints[ji]
            if joint.actuated is not None or any(c in pose for c in joint.coordinates):
                raise InputError(
                    f"body {body.name}: {first} is an actuated or pose joint; a hinge beam sits at a passive joint",
                    path=body.path + ("at",),
                )
            if (li, ji) in out:
                raise InputError(f"joint {first} carries two hinge beams", path=body.path + ("at",))
            out[(li, ji)] = body
    return out


def _first_rotation(joint: Any) -> np.ndarray | None:
    for d, kind in enumerate(joint.motions):
        if kind == "R":
            return joint.axes[:, d]
    return None


def _body_ends(body: Body, m: int, first: str, second: str, where: dict, chains: Chains) -> tuple[int, int, int]:
    """(leg, first joint, second joint) of a body's member; the second joint len(joints) at the platform."""
    if first not in where or (second != PLATFORM and second not in where):
        missing = first if first not in where else second
        raise InputError(
            f"body {body.name}: joint {missing} is not in the legs' chains, so the body cannot be placed",
            path=body.path + ("between",),
        )
    li, ja = where[first]
    if second == PLATFORM:
        lj, jb = li, len(chains.legs[li].joints)
    else:
        lj, jb = where[second]
    ja, jb = min(ja, jb), max(ja, jb)
    if lj != li or jb != ja + 1:
        raise InputError(
            f"body {body.name}: {first} and {second} (member {m + 1}) are not neighbouring joints of one leg; a "
            "flexible body is the link between two neighbouring joints (or the last joint and the platform)",
            path=body.path + ("between",),
        )
    return li, ja, jb


def _check_reference(model: Model, chains: Chains) -> None:
    scale = max(model.characteristic_length, 1e-9)
    if not (
        np.allclose(model.x_home, chains.x_reference, atol=1e-9 * scale, rtol=0)
        and np.allclose(model.q_home, chains.q_reference, atol=1e-9 * scale, rtol=0)
    ):
        raise InputError(
            f"mechanism {model.name}: the six-axis hinge model takes the hinges at rest at the chains' "
            "reference configuration, and the home pose differs from it",
            path=("inputs", "hinge_axes"),
            hint="use hinge_axes: kinematic",
        )


def _solve(K: np.ndarray, r: np.ndarray) -> np.ndarray:
    """K⁻¹ r with symmetric diagonal equilibration (hinge stiffnesses span ten decades);
    raises LinAlgError when K is singular (LAPACK's reciprocal condition estimate)."""
    d = np.sqrt(np.maximum(np.max(np.abs(K), axis=1), 1e-300))
    s = 1.0 / d
    Ks = K * s[:, None] * s[None, :]
    lu, piv = scipy.linalg.lu_factor(Ks, check_finite=False)
    rcond, info = scipy.linalg.lapack.dgecon(lu, np.linalg.norm(Ks, 1), norm="1")
    if info != 0 or not rcond > 1e-13:
        raise np.linalg.LinAlgError("the KKT matrix of the six-axis hinge model is singular")
    rs = r * (s[:, None] if r.ndim == 2 else s)
    y = scipy.linalg.lu_solve((lu, piv), rs, check_finite=False)
    return y * (s[:, None] if r.ndim == 2 else s)


#: built six-axis models by content (mechanism, parameters, hinges): symbolic construction
#: and the IPOPT set-up once per design, not once per solve (a sweep over loads or poses)
_BUILT: OrderedDict[tuple, SixAxisModel] = OrderedDict()
_BUILT_MAX = 8
_LOCK = threading.Lock()


def _key(model: Model, hs: HingeSet) -> tuple:
    mech = model.mechanism
    hinges = tuple(
        (
            h.name,
            h.kind,
            tuple(sorted(h.dims.items())),
            tuple(sorted(h.k.items())),
            tuple(sorted(h.axes.items())),
            None if h.material is None else (h.material.E, h.material.nu),
        )
        for h in hs.hinges
    )
    bodies = tuple((repr(b.beam), b.members, b.material.E, b.material.nu, b.material.density) for b in hs.bodies)
    return (mech.name, mech.origin, tuple(np.asarray(model.p, dtype=float)), tuple(model.x_home), hinges, bodies)


def six_axis_model(model: Model, hs: HingeSet) -> SixAxisModel | None:
    """The six-axis hinge model, or None when the mechanism gives no chains (built once per
    mechanism, parameters and hinges, then reused)."""
    mech = model.mechanism
    chains = mech.part(LegChains) if mech is not None else None
    if chains is None:
        return None
    key = _key(model, hs)
    with _LOCK:
        built = _BUILT.get(key)
        if built is not None:
            _BUILT.move_to_end(key)
            return built
    built = SixAxisModel(model, hs, chains.of(model))
    with _LOCK:
        _BUILT[key] = built
        while len(_BUILT) > _BUILT_MAX:
            _BUILT.popitem(last=False)
    return built


__all__ = ["HingeFrame", "LegChains", "SixAxisModel", "six_axis_model"]
