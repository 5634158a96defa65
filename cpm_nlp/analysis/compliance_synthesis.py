"""Compliance-driven synthesis: the hinge dimensions (t, r, w, d, l per hinge group) and the
links' sections that minimise (or maximise) a stiffness, stress or frequency measure under
requirements on the others, solved by IPOPT with exact derivatives through the compliance model.

The model is the pseudo-rigid-body hinge model of `cpm_nlp.analysis.compliance`
(each hinge about the axes the kinematics moves).  Its poses do not depend on the hinge
dimensions, so at each pose the joint deflections δ_j = θ_j(x, q) - θ_j0 and the kinematic
Jacobian J are numbers, and the hinge energy U = ½ Σ_j k_j δ_j² is linear in the
stiffnesses k_j.  Hence, exactly,

    K_q(k) = Σ_j k_j G_j          (G_j: the input stiffness of a unit stiffness on joint j alone,
                                   the reduced Hessian of `cpm_nlp.analysis.compliance.static_point`)
    C(k)   = J (K_q + K_a)⁻¹ Jᵀ   (the output compliance at home, actuators on springs K_a)
    σ_h    = σ(dims, {a: k_a δ_a})  at every corner of the required stroke and at the poses given
                                   (the hinge type's stress, nominal or K_t × nominal)
    M(s)   = Jᵀ M_x J + M_q + Tᵀ M_links(s) T   (`cpm_nlp.analysis.link_masses`)

with k_j = k_j(dims) the hinge type's stiffness formula (`cpm_nlp.analysis.hinge_types`,
called through the type's interface, on CasADi symbols: Gauss-Legendre quadrature of the
section integrals) and s the links' sections.  The first natural frequency enters through
a variable ω₁² = s_f and a Cholesky factor: K_q + K_a - s_f M = L Lᵀ with L lower triangular
and L_ii >= 0, which holds exactly when K_q + K_a - s_f M is positive semidefinite, i.e. when
f1 >= sqrt(s_f)/(2π) -- smooth where the eigenvalue is not (the 3-PRS's tilt frequencies are
repeated).  The stroke requirement (the stress-limited range covers the required stroke) is
σ <= σ_allow at every corner of the stroke box, the motion's largest deflections.  The
largest stress or input stiffness as an objective is min τ subject to every entry / scale <= τ
(an epigraph variable: smooth where several entries are equal).

The design variables are scaled to [0, 1] over their bounds.  The optimum is re-evaluated by
the forward analysis (`static_point`, `output_compliance`, the eigenvalues), and every
constraint is reported with its value, its bound, its multiplier and whether it is active.
"""

from __future__ import annotations

import dataclasses
import math
import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import Any

import casadi as ca
import numpy as np
import scipy.linalg

from ..core.model import Model
from . import compliance as cm
from .beams import Section, element_compliance
from .hinge_chains import six_axis_model
from .hinge_types import HINGE_TABLE
from .link_masses import LinkBody, LinkSection, body_jacobians, rigid_velocity_map

#: a constraint counts as active when its slack is below this fraction of its bound
ACTIVE_RTOL = 1e-6
#: the measures minimized through an epigraph variable (their components: max_i c_i)
EPIGRAPH = {
    "stress": lambda nlp: ca.vertcat(*[sigma for _, sigma in nlp.stresses]),
    "input_stiffness": lambda nlp: ca.diag(nlp.measures["K_q"]),
}
#: round-off: a KKT residual or a relative deviation below it is reported as this value (the
#: same on every machine; the digits below it depend on the BLAS kernel)
ROUND_OFF = 1e-12


def beam_section(link: LinkSection, declared: Section) -> Section:
    """The beam section of a link's section (width -> b, height -> h, or d), keeping the declared
    section's shear coefficient."""
    extra = {"kappa": declared.values["kappa"]} if declared.values.get("kappa") is not None else {}
    if link.d is not None:
        return Section("round", {"d": link.d, **extra})
    return Section("rectangle", {"b": link.width, "h": link.height, **extra})


@dataclass(frozen=True)
class Variable:
    """One design variable: a hinge group's dimension or a link's section dimension (SI)."""

    name: str
    owner: str
    key: str
    lower: float
    upper: float
    link: bool = False

    def value(self, y: Any) -> Any:
        return self.lower + (self.upper - self.lower) * y


@dataclass(frozen=True)
class Requirements:
    """The objective and the constraints.  ``objective``: (sense +1 minimise / -1 maximise,
    measure: ``compliance_<x>``, ``f1``, ``stress`` or ``input_stiffness``); ``compliance_max``:
    pose index -> bound; ``stress_poses``: (label, x, q) of the poses where every hinge must stay
    below ``sigma_allow``: the corners of the required stroke and any poses given."""

    objective: tuple[int, str]
    compliance_max: Mapping[int, float] = field(default_factory=dict)
    input_stiffness_max: float | None = None
    frequency_min: float | None = None
    stress_poses: Sequence[tuple[str, np.ndarray, np.ndarray]] = ()
    sigma_allow: float | None = None
    peak: bool = False
    #: a unit direction u in the pose coordinates (all lengths or all angles) and the largest
    #: allowed compliance uᵀ C u along it
    direction: np.ndarray | None = None
    direction_max: float | None = None
    #: the output compliance C of the six-axis hinge model at home (True) or of the kinematic one
    six_axis: bool = False


@dataclass
class Constraint:
    """One requirement at the optimum: its value, bound, multiplier and whether it is active."""

    name: str
    value: float
    bound: float
    sense: str
    multiplier: float
    active: bool

    #: the bounds of a design variable, "[low, high]" (its text then names both)
    interval: str = ""

    def text(self) -> str:
        """One line; an inactive constraint's multiplier is 0 (IPOPT's interior-point value, of
        the order of its barrier parameter, is round-off and differs between machines)."""
        state = "active" if self.active else "inactive"
        if not self.active:
            mult = "0"
        elif math.isnan(self.multiplier):
            mult = "a matrix"
        else:
            mult = f"{self.multiplier:.3g}"
        value = f"{self.value:.6g} ({state}, multiplier {mult})"
        if self.interval:
            return f"{self.name} in {self.interval}: {value}"
        return f"{self.name} {self.sense} {self.bound:.6g}: {value}"


@dataclass
class SynthesisOutcome:
    """What the NLP gives: its status text, whether it found a design, and at the optimum the
    design values, the measures, the constraints and the KKT residual."""

    success: bool
    infeasible: bool
    message: str
    iterations: int
    seconds: float
    design: dict[str, float] = field(default_factory=dict)
    measures: dict[str, Any] = field(default_factory=dict)
    constraints: list[Constraint] = field(default_factory=list)
    kkt_residual: float | None = None
    y: np.ndarray | None = None
    lam_g: np.ndarray | None = None
    lam_x: np.ndarray | None = None
    #: the NLP's full solution (design, then ω₁² and L) and its parameters (scales)
    w: np.ndarray | None = None
    p: np.ndarray | None = None


def stiffness_basis(model: Model, hs: cm.HingeSet, x: np.ndarray, q: np.ndarray) -> np.ndarray:
    """G (n_joints x nq x nq): the input stiffness K_q of a unit stiffness on each joint alone
    at the pose (x, q); K_q(k) = Σ_j k_j G_j exactly (the energy is linear in k)."""
    n = len(hs.k)
    G = np.zeros((n, model.closure.nq, model.closure.nq))
    for j in np.flatnonzero(hs.k):
        unit = dataclasses.replace(hs, k=np.eye(n)[j])
        G[j] = cm.static_point(model, unit, x, q).K_q
    return G


class ComplianceSynthesisNLP:
    """The NLP of one model, hinge set, design and requirements (symbolic, built once)."""

    def __init__(
        self,
        model: Model,
        hs: cm.HingeSet,
        variables: Sequence[Variable],
        req: Requirements,
        k_actuator: np.ndarray | None,
        M_x: np.ndarray,
        M_q: np.ndarray,
        links: tuple[Any, Sequence[tuple[str, LinkBody]]] | None = None,
        flexible: Mapping[str, tuple[str, LinkSection]] | None = None,
    ) -> None:
        c = model.closure
        self.model, self.hs, self.variables, self.req = model, hs, list(variables), req
        self.nq = c.nq
        self.ka = None if k_actuator is None else np.asarray(k_actuator, dtype=float)
        y = ca.SX.sym("y", len(self.variables))
        self.y = y
        values = {(v.owner, v.key): v.value(y[i]) for i, v in enumerate(self.variables)}
        self.k = self._stiffness(values)  # joint stiffness, SX over the joint vector
        self._values = values
        #: flexible body name -> (the links' label whose section it takes, that section)
        self.flexible = dict(flexible or {})
        sp = cm.static_point(model, hs, model.x_home, model.q_home)
        self.J = sp.J
        G = stiffness_basis(model, hs, model.x_home, model.q_home)
        Kq = ca.SX.zeros(c.nq, c.nq)
        for j in np.flatnonzero(hs.k):
            Kq += self.k[j] * ca.DM(G[j])
        self.K = Kq + (ca.diag(ca.DM(self.ka)) if self.ka is not None else 0)
        self.M = self._mass(M_x, M_q, values, links)
        self.measures: dict[str, Any] = {"K_q": Kq}
        if req.six_axis or self.ka is not None:
            if req.six_axis:
                C = self._six_axis_compliance()
            else:
                C = ca.mtimes(ca.DM(self.J), ca.solve(self.K, ca.DM(self.J.T)))
            self.measures["C"] = C
            for i, x in enumerate(c.x):
                self.measures[f"compliance_{x.name}"] = C[i, i]
            if req.direction is not None:
                u = ca.DM(req.direction)
                self.measures["compliance_direction"] = ca.mtimes([u.T, C, u])
        self.measures["input_stiffness"] = ca.mmax(ca.diag(Kq))
        self.stresses = self._stresses()
        if self.stresses:
            ratio = ca.vertcat(*[s for _, s in self.stresses]) / req.sigma_allow
            self.measures["stress_ratio"] = ratio
            self.measures["stress"] = ca.mmax(ratio) * req.sigma_allow
        self._build()

    # -- the model's pieces ---------------------------------------------------------------------
    def _stiffness(self, values: Mapping[tuple[str, str], Any]) -> list[Any]:
        """k_j over the joint vector: the hinge formula on the designed dimensions, the given k elsewhere."""
        k: list[Any] = [float(v) for v in self.hs.k]
        self.designed: dict[str, dict[str, Any]] = {}
        formulas: dict[str, Any] = {}  # a group's members share their type, dimensions and material
        for h in self.hs.hinges:
            dims = {d: values.get((h.group, d), v) for d, v in h.dims.items() if d != "Kt"}
            if not any((h.group, d) in values for d in dims):
                continue
            mat = h.material
            G = mat.G if mat.nu is not None else None
            key = f"{h.group}/{mat.name}/{mat.E}/{mat.nu}"
            if key not in formulas:
                formulas[key] = HINGE_TABLE[h.kind].stiffness(mat.E, G, dims)
            formula = formulas[key]
            for a, i in h.axes.items():  # an axis the formula does not give (no nu) keeps its given k
                k[i] = formula.get(a, h.k[a])
            self.designed[h.name] = dims
        return k

    def _six_axis_compliance(self) -> Any:
        """C of the six-axis hinge model at home (`cpm_nlp.analysis.hinge_chains`): unstressed, so
        λ = 0 and the Hessian is diag(k) over the hinges' axis variables (plus K_a on q); with N a
        basis of the closures' motions (actuators held, or free on K_a), C = P (Nᵀ diag(k) N)⁻¹ Pᵀ,
        P the pose rows of N.  The designed hinges' k symbolic: their kinematic axes by the type's
        stiffness formula, the others by its six-axis formula."""
        model, nx, nq = self.model, self.model.closure.nx, self.nq
        sm = six_axis_model(model, self.hs)
        ok, z, lam, _ = sm.newton(sm.start(model.x_home, model.q_home), np.zeros(nx), model.q_home, None, None)
        if not ok:  # pragma: no cover - home is the chains' reference, an equilibrium by construction
            raise np.linalg.LinAlgError("no unloaded equilibrium of the six-axis model at home")
        H, A = sm.linearization(z, lam, self.ka)
        h: list[Any] = list(np.diag(H))
        groups = {hg.name: hg for hg in self.hs.hinges}
        six: dict[str, Any] = {}
        for fr in sm.frames:
            hinge = groups.get(fr.name)
            if hinge is None or hinge.name not in self.designed:
                continue
            if hinge.group not in six:
                mat = hinge.material
                six[hinge.group] = HINGE_TABLE[hinge.kind].six_axis(mat.E, mat.G, self.designed[hinge.name])
            for a, (zi, _) in fr.variables.items():
                h[zi] = self.k[hinge.axes[a]] if a in hinge.axes else six[hinge.group][a]
        Hs = self._home_hessian(sm, H, h)
        held = self.ka is None
        free = np.concatenate([np.arange(nx), np.arange(nx + nq, sm.nz)]) if held else np.arange(sm.nz)
        N = scipy.linalg.null_space(A[:, free])
        Kr = ca.mtimes([ca.DM(N.T), Hs[free.tolist(), free.tolist()], ca.DM(N)])
        P = ca.DM(N[:nx])  # the pose coordinates come first among the free variables
        return ca.mtimes(P, ca.solve(Kr, P.T))

    def _home_hessian(self, sm: Any, H: np.ndarray, h: Sequence[Any]) -> Any:
        """H at home with the designed parts symbolic: the hinges' axes on the diagonal (``h``), the
        designed flexible links' element blocks K_e (full: their energy ½ εᵀ K_e ε)."""
        Hs = ca.SX(ca.DM(H))
        for i, hi in enumerate(h):
            Hs[i, i] = hi
        for _, elements, K_sym in self._beam_stiffness(sm):
            for (_, idx), K in zip(elements, K_sym, strict=True):
                for a, ia in enumerate(idx):
                    for b, ib in enumerate(idx):
                        Hs[ia, ib] = K[a, b]
        return Hs

    def _beam_stiffness(self, sm: Any) -> list[tuple[Any, list, list[Any]]]:
        """(body, its elements with their z indices, each element's symbolic K_e) of every flexible
        body that is a designed link: its section is the link's (`LinkSection`: width along the first
        joint's axis is the beam's b, height its h; or d), the designed dimensions symbols, so EA, EI,
        GJ and κGA enter K_e = C_e⁻¹ (`cpm_nlp.analysis.beams.element_compliance`) symbolically."""
        out = []
        for body, _, elements in sm.beams:
            if body.name not in self.flexible:
                continue
            label, sec = self.flexible[body.name]
            given = {key: self._values.get((label, key), getattr(sec, key)) for key in ("width", "height", "d")}
            section = beam_section(LinkSection(given["width"], given["height"], given["d"]), body.beam.section)
            mat, spec = body.material, body.beam
            Ks = []
            for k, (el, _) in enumerate(elements):
                model = spec.model_of(k)
                C, _ = element_compliance(section, mat.E, mat.nu, el.s0, el.s1, el.x_centre, spec.theory, model)
                dofs = list(el.dofs)
                Ce = C[dofs, dofs]
                Ks.append(ca.solve(Ce, ca.SX.eye(len(dofs))))
            out.append((body, elements, Ks))
        return out

    def _stresses(self) -> list[tuple[str, Any]]:
        """(label, σ) of every hinge with a type at every stroke pose where it deflects."""
        out = []
        for where, x, q in self.req.stress_poses:
            theta = cm.joint_vector(self.model, x, q)
            dev = theta - self.hs.theta0
            for h in self.hs.hinges:
                if h.kind is None or not any(abs(dev[i]) > 0 for i in h.axes.values()):
                    continue
                dims = self.designed.get(h.name, {d: v for d, v in h.dims.items() if d != "Kt"})
                loads = {a: self.k[i] * float(dev[i]) for a, i in h.axes.items()}
                sigma = HINGE_TABLE[h.kind].stress(dims, loads)
                if self.req.peak:
                    kt = h.dims.get("Kt")
                    fit = HINGE_TABLE[h.kind].kt
                    sigma = sigma * (kt if kt is not None else 1.0 if fit is None else fit(dims))
                out.append((f"stress {h.name} at {where}", sigma))
        return out

    def _mass(self, M_x, M_q, values, links) -> Any:
        J = self.J
        M = ca.DM(J.T @ np.diag(M_x) @ J + np.diag(M_q))
        if not links:
            return M
        sm, bodies = links
        if not bodies:
            return M
        z = sm.start(self.model.x_home, self.model.q_home)
        T = rigid_velocity_map(sm, z)
        Jc, W = (np.asarray(v, dtype=float) for v in body_jacobians(sm, [b for _, b in bodies])(z))
        for n, (label, b) in enumerate(bodies):
            sec = b.section
            if sec is not None:
                keys = ("width", "height", "d")
                given = {key: values.get((label, key), getattr(sec, key)) for key in keys}
                sec = LinkSection(given["width"], given["height"], given["d"])
            m, inertia = b.mass_inertia(sec)
            jc = Jc[3 * n : 3 * n + 3] @ T
            w = W[:, 3 * n : 3 * n + 3].T @ T
            M += m * ca.DM(jc.T @ jc)
            for a in range(3):
                M += inertia[a] * ca.DM(np.outer(w[a], w[a]))
        return M

    # -- the NLP --------------------------------------------------------------------------------
    def _build(self) -> None:
        req = self.req
        self.frequency = req.frequency_min is not None or req.objective[1] == "f1"
        w = [self.y]
        g: list[Any] = []
        self.g_info: list[tuple[str, str, float]] = []  # (name, sense, bound) of each inequality
        self.n_eq = 0
        self.kscale = ca.SX.zeros(0)
        if self.frequency:
            w += self._frequency_variables()
            g += self._frequency_equations()
        g += self._inequalities()
        self.n_ineq = len(self.g_info)
        sense, measure = req.objective
        self.fscale = ca.SX.sym("fscale")
        self.n_epi = 0
        if measure == "f1":
            f = -self.s if sense < 0 else self.s
        elif measure in EPIGRAPH:  # min max_i c_i as min τ s.t. c_i / scale <= τ: smooth
            parts = EPIGRAPH[measure](self)
            self.tau = ca.SX.sym("tau")
            w.append(self.tau)
            g += [parts[i] / self.fscale - self.tau for i in range(parts.numel())]
            self.n_epi = parts.numel()
            f = self.measures[measure]
        else:
            f = sense * self.measures[measure]
        self.w = ca.vertcat(*w)
        self.g = ca.vertcat(*g) if g else ca.SX.zeros(0)
        self.f_raw = f
        self.p = ca.vertcat(self.fscale, self.kscale)
        self.f = self.tau if self.n_epi else f / self.fscale
        self.nlp_fn = ca.Function(
            "compliance_synthesis_nlp",
            [self.w, self.p],
            [self.f, self.g, ca.gradient(self.f, self.w), ca.jacobian(self.g, self.w)],
            ["w", "p"],
            ["f", "g", "grad_f", "jac_g"],
        )
        outs = {"K": self.K, "M": self.M, "k": ca.vertcat(*self.k)}
        for key in ("C", "K_q", "stress", "input_stiffness", "compliance_direction"):
            if key in self.measures:
                outs[key] = self.measures[key]
        self.values_fn = ca.Function("compliance_synthesis_values", [self.y], list(outs.values()), ["y"], list(outs))

    def _inequalities(self) -> list[Any]:
        """The requirements g <= 1 (each scaled by its bound), recorded in ``g_info``."""
        req, g = self.req, []
        for i, bound in req.compliance_max.items():
            x = self.model.closure.x[i]
            g.append(self.measures[f"compliance_{x.name}"] / bound)
            self.g_info.append((f"C_{x.name}", "<=", bound))
        if req.direction_max is not None:
            g.append(self.measures["compliance_direction"] / req.direction_max)
            self.g_info.append(("C along the direction", "<=", req.direction_max))
        if req.input_stiffness_max is not None:
            for j, qn in enumerate(self.model.closure.q_names):
                g.append(self.measures["K_q"][j, j] / req.input_stiffness_max)
                self.g_info.append((f"K_q[{qn}]", "<=", req.input_stiffness_max))
        for label, sigma in self.stresses:
            g.append(sigma / req.sigma_allow)
            self.g_info.append((label, "<=", req.sigma_allow))
        for h in self.hs.hinges:  # a circular notch must leave a thinnest section: t < 2r
            dims = self.designed.get(h.name)
            if dims is not None and h.kind == "circular_notch" and h.name == self._first_of_group(h.group):
                g.append(dims["t"] / (2.0 * dims["r"]))
                self.g_info.append((f"t/(2r) of {h.group}", "<=", 1.0))
        return g

    def _frequency_variables(self) -> list[Any]:
        """ω₁² and the lower triangle of L (K - ω₁² M = L Lᵀ)."""
        nq = self.nq
        self.s = ca.SX.sym("omega1_sq")
        self.L = ca.SX.sym("L", nq * (nq + 1) // 2)
        Lm = ca.SX.zeros(nq, nq)
        for k, (i, j) in enumerate(zip(*np.tril_indices(nq))):
            Lm[i, j] = self.L[k]
        self.Lm = Lm
        self.kscale = ca.SX.sym("kscale")
        return [self.s, self.L]

    def _frequency_equations(self) -> list[Any]:
        """K - ω₁² M - L Lᵀ = 0 (the lower triangle), scaled by the stiffness at the start."""
        R = self.K - self.s * self.M - self.Lm @ self.Lm.T
        eq = [R[i, j] / self.kscale for i, j in zip(*np.tril_indices(self.nq))]
        self.n_eq = len(eq)
        return eq

    def _first_of_group(self, group: str) -> str:
        return next(h.name for h in self.hs.hinges if h.group == group)

    def evaluate(self, y: np.ndarray) -> dict[str, np.ndarray]:
        """The measures at a design (scaled y): K, M, k, C, K_q, stress, input_stiffness."""
        out: dict[str, Any] = {}
        for k, v in self.values_fn(y=y).items():
            a = np.asarray(v, dtype=float)
            out[k] = float(a.ravel()[0]) if k in ("stress", "input_stiffness", "compliance_direction") else a
        return out

    def start(self, y0: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The start (w0) and the scales (p) at the design y0."""
        vals = self.evaluate(y0)
        w0 = [y0]
        kscale = []
        if self.frequency:
            K, M = vals["K"], vals["M"]
            lam = float(scipy.linalg.eigh(K, M, eigvals_only=True)[0])
            s0 = 0.5 * max(lam, 0.0)
            if self.req.objective[1] != "f1" and self.req.frequency_min is not None:
                s0 = min(s0, (2 * math.pi * self.req.frequency_min) ** 2)
            Lc = np.linalg.cholesky(K - s0 * M + 1e-12 * np.abs(K).max() * np.eye(self.nq))
            w0 += [np.array([s0]), Lc[np.tril_indices(self.nq)]]
            kscale = [float(np.abs(K).max())]
        if self.req.objective[1] == "f1":
            f0 = float(w0[1][0])  # ω₁² at the start
        else:
            f0 = float(ca.Function("f0", [self.y], [self.f_raw])(y0))
        if self.n_epi:
            w0.append(np.array([1.0]))  # τ = max_i c_i / scale at the start
        return np.concatenate(w0), np.array([max(abs(f0), 1e-300), *kscale])

    def bounds(self) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        nw = self.w.numel()
        lbx, ubx = np.full(nw, -np.inf), np.full(nw, np.inf)
        nv = len(self.variables)
        lbx[:nv], ubx[:nv] = 0.0, 1.0
        if self.frequency:
            fmin = self.req.frequency_min
            lbx[nv] = (2 * math.pi * fmin) ** 2 if fmin is not None else 0.0
            if self.req.objective[1] != "f1":  # a requirement only: K - ω_min² M ⪰ 0
                ubx[nv] = lbx[nv]
            k = nv + 1
            for i in range(self.nq):
                for j in range(i + 1):
                    if i == j:
                        lbx[k] = 0.0
                    k += 1
        ng = self.g.numel()
        lbg, ubg = np.full(ng, -np.inf), np.ones(ng)
        lbg[: self.n_eq] = ubg[: self.n_eq] = 0.0
        ubg[self.n_eq + self.n_ineq :] = 0.0  # the epigraph: c_i / scale - τ <= 0
        return lbx, ubx, lbg, ubg

    def solve(self, y0: np.ndarray, max_iter: int = 500) -> SynthesisOutcome:
        t0 = time.process_time()
        w0, par = self.start(y0)
        lbx, ubx, lbg, ubg = self.bounds()
        opts = {
            "ipopt.print_level": 0,
            "print_time": False,
            "ipopt.sb": "yes",
            "ipopt.tol": 1e-10,
            "ipopt.constr_viol_tol": 1e-10,
            "ipopt.max_iter": max_iter,
            "ipopt.hessian_approximation": "exact",
        }
        nlp = {"x": self.w, "p": self.p, "f": self.f, "g": self.g}
        solver = ca.nlpsol("compliance_synthesis", "ipopt", nlp, opts)
        sol = solver(x0=w0, p=par, lbx=lbx, ubx=ubx, lbg=lbg, ubg=ubg)
        st = solver.stats()
        status = st.get("return_status", "")
        w = np.asarray(sol["x"], dtype=float).ravel()
        lam_g = np.asarray(sol["lam_g"], dtype=float).ravel()
        lam_x = np.asarray(sol["lam_x"], dtype=float).ravel()
        out = SynthesisOutcome(
            bool(st.get("success", False)),
            status in ("Infeasible_Problem_Detected",),
            status,
            int(st.get("iter_count", 0)),
            time.process_time() - t0,
        )
        if not out.success:
            return out
        f, g, gf, jg = (np.asarray(v, dtype=float) for v in self.nlp_fn(w, par))
        grad_L = gf.ravel() + jg.T @ lam_g + lam_x
        out.kkt_residual = float(np.max(np.abs(grad_L)))
        nv = len(self.variables)
        y = w[:nv]
        out.y, out.lam_g, out.lam_x, out.w, out.p = y, lam_g, lam_x, w, par
        out.design = {v.name: float(v.value(y[i])) for i, v in enumerate(self.variables)}
        g = g.ravel()
        _, _, _, ubg = self.bounds()
        viol = max([0.0, *(g[self.n_eq :] - ubg[self.n_eq :])]) if g.size else 0.0
        if g.size and self.n_eq:
            viol = max(viol, float(np.max(np.abs(g[: self.n_eq]))))
        if viol > 1e-7:
            out.success, out.message = False, f"{status}, but a constraint is violated by {viol:.3g}"
            return out
        for k, (name, sense, bound) in enumerate(self.g_info):
            gi = float(g[self.n_eq + k])
            mult = float(lam_g[self.n_eq + k])
            out.constraints.append(Constraint(name, gi * bound, bound, sense, mult, 1.0 - gi <= ACTIVE_RTOL))
        vals = self.evaluate(y)
        f1 = None  # without masses, or with the actuators held, no frequency
        if self.ka is not None and np.any(vals["M"]):
            try:
                lam = scipy.linalg.eigh(vals["K"], vals["M"], eigvals_only=True)[0]
                f1 = float(np.sqrt(max(lam, 0.0)) / (2 * math.pi))
            except np.linalg.LinAlgError:  # M singular: a motion without mass has no frequency
                f1 = None
        out.measures = {**vals, "f1": f1}
        if self.req.frequency_min is not None:
            fmin = self.req.frequency_min
            # the multiplier of ω₁² >= ω_min² (on its bound when f1 is the objective; else the
            # requirement holds through K - ω_min² M = L Lᵀ, whose multiplier is a matrix: NaN)
            mult = float(lam_x[nv]) if self.req.objective[1] == "f1" else float("nan")
            out.constraints.append(Constraint("f1", f1, fmin, ">=", mult, f1 - fmin <= 1e-5 * fmin))
        for i, v in enumerate(self.variables):
            at = "lower" if y[i] <= ACTIVE_RTOL else "upper" if y[i] >= 1 - ACTIVE_RTOL else None
            bound = v.lower if at == "lower" else v.upper
            out.constraints.append(
                Constraint(
                    f"{v.name}",
                    out.design[v.name],
                    bound,
                    ">=" if at == "lower" else "<=",
                    float(lam_x[i]),
                    at is not None,
                    f"[{v.lower:.6g}, {v.upper:.6g}]",
                )
            )
        return out
