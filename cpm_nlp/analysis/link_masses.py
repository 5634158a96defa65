"""Masses and inertias of a mechanism's links, and the natural frequencies of the
six-axis hinge model (`cpm_nlp.analysis.hinge_chains`) with them.

A link is the rigid body between two joints of a leg (the body after joint j,
up to joint j + 1, or to the platform point after the last joint).  Its mass
and inertia come from its section, its length (the distance of the two joints
at the reference configuration) and the material's density -- a straight bar
(`LinkSection`) -- or are given.  Its kinetic energy is

    T_b = ½ m_b |ċ_b|² + ½ ω_bᵀ I_b ω_b,    c_b(z) = R_b(z) c_b0 + t_b(z),  ω_b = vee(Ṙ_b R_bᵀ),

with (R_b, t_b) the rigid motion of the body in the legs' chains
(`SixAxisModel.body_frames`), so that over the six-axis model's variables z the
mass matrix is M_z = Σ_b m_b J_cᵀ J_c + J_ωᵀ R_b I_b0 R_bᵀ J_ω (J_c = ∂c_b/∂z, J_ω = ∂ω_b/∂ż),
plus the masses and inertias a problem gives on the pose and actuator coordinates.

Natural frequencies with the six-axis hinges: the equilibrium (z, λ) at the
commanded actuators, the Hessian H = ∇²(V + λᵀg) and the closures' Jacobian A
there; the motions that keep the closures, dz = N y with N a basis of the null
space of A (over the free variables: the actuators' too unless held), give
K_r = Nᵀ H N and M_r = Nᵀ M_z N.  Variables without mass (a hinge's extra axes
between massless links) make M_r singular: scipy's ``eigh(M_r, K_r)`` gives
μ = 1/ω², and μ = 0 are the massless motions (static condensation, exact: they
carry no inertia).  The frequencies and modes do not depend on the basis N; the
modes are reported in canonical form (`cpm_nlp.core.canonical`).

With the extra axes made infinitely stiff this is the pseudo-rigid-body model of
the ``natural_frequencies`` kind (the link masses then enter as Tᵀ M_z T with T
= dz/dq along the rigid kinematics, `rigid_velocity_map`).

The section here gives mass and inertia; its area and second moments
(`LinkSection.area`, `LinkSection.second_moments`) are what a flexible link's
stiffness needs too.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import casadi as ca
import numpy as np
import scipy.linalg

from ..core.canonical import canonical_basis, eigen_clusters
from ..core.errors import InputError
from .hinge_chains import SixAxisModel

#: a variable pair (M_r's eigenvalue μ = 1/ω²) counts as massless below this fraction of the largest
MASSLESS_RTOL = 1e-10


def _symbolic(*args: Any) -> bool:
    return any(isinstance(a, (ca.SX, ca.MX, ca.DM)) for a in args)


@dataclass(frozen=True)
class LinkSection:
    """The cross-section of a straight link: a rectangle ``width`` x ``height`` (width along
    the link's first bending axis b1, height along b2) or a circle of diameter ``d``.  Every
    property works on floats and on CasADi symbols (a design variable)."""

    width: Any = None
    height: Any = None
    d: Any = None

    @property
    def shape(self) -> str:
        return "round" if self.d is not None else "rectangle"

    def area(self) -> Any:
        if self.d is not None:
            return math.pi * self.d**2 / 4.0
        return self.width * self.height

    def second_moments(self) -> tuple[Any, Any]:
        """(I about b1, I about b2) of the section [m^4]: bending about b1 and about b2."""
        if self.d is not None:
            i = math.pi * self.d**4 / 64.0
            return i, i
        return self.width**3 * self.height / 12.0, self.width * self.height**3 / 12.0

    def bar_inertia(self, mass: Any, length: Any) -> tuple[Any, Any, Any]:
        """Inertias of a bar of this section, ``length`` and ``mass`` about its centre, about its
        own axes (t along it, b1, b2): a rectangle's m (w² + h²)/12, m (L² + h²)/12, m (L² + w²)/12;
        a circle's m d²/8 and m (L²/12 + d²/16) twice."""
        if self.d is not None:
            perp = mass * (length**2 / 12.0 + self.d**2 / 16.0)
            return mass * self.d**2 / 8.0, perp, perp
        w, h = self.width, self.height
        return mass * (w**2 + h**2) / 12.0, mass * (length**2 + h**2) / 12.0, mass * (length**2 + w**2) / 12.0


@dataclass(frozen=True)
class LinkBody:
    """One link of a leg of the chains: the body after joint ``joint`` (0-based) of leg ``leg``,
    from ``start`` to ``end`` (reference configuration, base frame), its own frame ``axes``
    (columns t, b1, b2), and its mass and inertias about its centre (t, b1, b2), or the
    section and density they follow from (``mass``/``inertia`` given override them)."""

    name: str
    leg: int
    joint: int
    start: np.ndarray
    end: np.ndarray
    axes: np.ndarray
    section: LinkSection | None = None
    density: float | None = None
    mass: float | None = None
    inertia: tuple[float, float, float] | None = None

    @property
    def length(self) -> float:
        return float(np.linalg.norm(self.end - self.start))

    @property
    def centre(self) -> np.ndarray:
        return 0.5 * (self.start + self.end)

    def mass_inertia(self, section: LinkSection | None = None) -> tuple[Any, tuple[Any, Any, Any]]:
        """(m, (I_t, I_b1, I_b2)): given, or of a bar of the section (``section`` overrides the
        body's own, e.g. a symbolic one of a synthesis) and the density; a mass given without a
        section is a slender bar (m L²/12 about both bending axes, nothing about its length)."""
        sec = section if section is not None else self.section
        L = self.length
        m = self.mass
        if m is None:
            m = self.density * sec.area() * L
        if self.inertia is not None:
            return m, self.inertia
        if sec is None:
            return m, (0.0, m * L**2 / 12.0, m * L**2 / 12.0)
        return m, sec.bar_inertia(m, L)


def body_axes(start: np.ndarray, end: np.ndarray, joint_axis: np.ndarray | None) -> np.ndarray:
    """The link frame (columns t, b1, b2): t along the link, b1 the start joint's rotation axis
    made normal to t where it has one (else the base axis least along t), b2 = t x b1."""
    d = end - start
    n = np.linalg.norm(d)
    t = d / n if n > 0 else (joint_axis if joint_axis is not None else np.array([0.0, 0.0, 1.0]))
    trial = joint_axis if joint_axis is not None and np.linalg.norm(np.cross(joint_axis, t)) > 1e-9 else None
    if trial is None:
        trial = np.eye(3)[int(np.argmin(np.abs(t)))]
    b1 = trial - np.dot(trial, t) * t
    b1 /= np.linalg.norm(b1)
    return np.column_stack([t, b1, np.cross(t, b1)])


def link_bodies(sm: SixAxisModel, specs: Mapping[str, Mapping[str, Any]], density: float | None, path: tuple):
    """The link bodies of ``specs`` (label -> {leg, after_joint, section | mass [, inertia]}) on
    the legs of the six-axis model ``sm``: a leg name (``leg1``) or a repeated leg's name (``leg``:
    each of its copies)."""
    legs = sm.chains.legs
    out: list[LinkBody] = []
    for label, spec in specs.items():
        where = path + (label,)
        chosen = [li for li, leg in enumerate(legs) if _leg_named(leg.name, spec["leg"])]
        if not chosen:
            names = sorted({leg.name for leg in legs} | {leg.name.rstrip("0123456789") for leg in legs})
            raise InputError(f"no leg named {spec['leg']!r}; the legs: {', '.join(names)}", path=where + ("leg",))
        for li in chosen:
            leg = legs[li]
            ji = spec["after_joint"] - 1
            if ji >= len(leg.joints):
                raise InputError(
                    f"leg {leg.name} has {len(leg.joints)} joints; after_joint must be 1 to {len(leg.joints)}",
                    path=where + ("after_joint",),
                )
            j = leg.joints[ji]
            start = np.asarray(j.at, dtype=float)
            end = np.asarray(leg.joints[ji + 1].at if ji + 1 < len(leg.joints) else leg.tip, dtype=float)
            rot = [j.axes[:, d] for d in range(j.dof) if j.motions[d] == "R"]
            section = spec.get("section")
            if spec.get("mass") is None and section is None:
                raise InputError("a link needs a section (of the material) or a mass", path=where)
            if spec.get("mass") is None and density is None:
                raise InputError(
                    "a link given by its section needs the material's density; give the density "
                    "(material: {E: ..., nu: ..., density: ...}) or the link's mass",
                    path=where + ("section",),
                )
            if np.linalg.norm(end - start) == 0 and spec.get("mass") is None:
                raise InputError(
                    f"the body after joint {ji + 1} of leg {leg.name} has no length (its joints coincide); "
                    "give its mass (and inertia) instead of a section",
                    path=where + ("section",),
                )
            inertia = spec.get("inertia")
            out.append(
                LinkBody(
                    f"{label}_{leg.name}" if len(chosen) > 1 else label,
                    li,
                    ji,
                    start,
                    end,
                    body_axes(start, end, rot[0] if rot else None),
                    section,
                    density,
                    spec.get("mass"),
                    None if inertia is None else tuple(float(v) for v in inertia),
                )
            )
    return out


def _leg_named(name: str, wanted: str) -> bool:
    return name == wanted or (name.startswith(wanted) and name[len(wanted) :].isdigit())


def _vee(S: Any) -> Any:
    return ca.vertcat(S[2, 1] - S[1, 2], S[0, 2] - S[2, 0], S[1, 0] - S[0, 1]) / 2


def body_jacobians(sm: SixAxisModel, bodies: Sequence[LinkBody]) -> ca.Function:
    """``("<name>_link_jacobians", [z], [Jc, W])``: per body, the Jacobian of its centre J_c
    (3 x nz, stacked) and W_b = J_ωᵀ R_b F_b (nz x 3, side by side: the angular velocity about
    the body's own axes t, b1, b2 per unit ż), so that M_z = Σ m J_cᵀ J_c + W diag(I) Wᵀ.
    Built once per six-axis model and set of bodies (their places and frames)."""
    key = tuple((b.leg, b.joint, tuple(b.centre), tuple(b.axes.ravel())) for b in bodies)
    return _body_jacobians(sm, key)


@functools.lru_cache(maxsize=16)
def _body_jacobians(sm: SixAxisModel, key: tuple) -> ca.Function:
    frames = sm.body_frames()
    z = ca.SX.sym("z", sm.nz)
    zd = ca.SX.sym("zd", sm.nz)
    R_all, t_all = frames(z)
    offsets = np.cumsum([0] + [len(leg.joints) for leg in sm.chains.legs])
    Jc, W = [], []
    for leg, joint, centre, axes in key:
        k = int(offsets[leg]) + joint
        R, t = R_all[:, 3 * k : 3 * k + 3], t_all[:, k]
        c = R @ ca.DM(centre) + t
        Jc.append(ca.jacobian(c, z))
        Rdot = ca.reshape(ca.jacobian(ca.reshape(R, 9, 1), z) @ zd, 3, 3)
        omega = _vee(Rdot @ R.T)
        J_omega = ca.jacobian(omega, zd)
        W.append(J_omega.T @ R @ ca.DM(np.reshape(axes, (3, 3))))
    name = f"{sm.model.closure.name}_link_jacobians"
    return ca.Function(name, [z], [ca.densify(ca.vertcat(*Jc)), ca.densify(ca.horzcat(*W))], ["z"], ["Jc", "W"])


def link_mass_matrix(sm: SixAxisModel, bodies: Sequence[LinkBody], z: np.ndarray, sections=None) -> Any:
    """M_z (nz x nz) of the link bodies at z; ``sections`` (one per body, or None) overrides
    their sections (symbolic in a synthesis: the result is then a CasADi expression)."""
    if not bodies:
        return np.zeros((sm.nz, sm.nz))
    Jc, W = (np.asarray(v, dtype=float) for v in body_jacobians(sm, bodies)(z))
    M: Any = np.zeros((sm.nz, sm.nz))
    for n, b in enumerate(bodies):
        m, inertia = b.mass_inertia(None if sections is None else sections[n])
        jc = Jc[3 * n : 3 * n + 3]
        w = W[:, 3 * n : 3 * n + 3]
        M = M + m * (jc.T @ jc)
        for a in range(3):
            M = M + inertia[a] * np.outer(w[:, a], w[:, a])
    return M


def rigid_velocity_map(sm: SixAxisModel, z: np.ndarray) -> np.ndarray:
    """T = dz/dq (nz x nq) along the rigid kinematics at z: the actuators move, the hinges'
    extra axes stay at rest, the chains' variables and the pose follow the closures
    (minimum norm where the chains leave a motion free, e.g. a leg's spin)."""
    _, A = sm.linearization(z, np.zeros(sm.ng))
    extra = {zi for fr in sm.frames for a, (zi, _) in fr.variables.items() if a in fr.extra}
    q_idx = np.arange(sm.nx, sm.nx + sm.nq)
    rest = [i for i in range(sm.nz) if i not in extra and not (sm.nx <= i < sm.nx + sm.nq)]
    T = np.zeros((sm.nz, sm.nq))
    T[q_idx, np.arange(sm.nq)] = 1.0
    T[rest] = -np.linalg.pinv(A[:, rest]) @ A[:, q_idx]
    return T


@dataclass
class Modes:
    """Natural frequencies [Hz] ascending, the modes over z (columns, M-normalized,
    canonical), the clusters of equal frequencies, and how many massive modes there are."""

    frequencies: np.ndarray
    modes_z: np.ndarray
    clusters: list[list[int]]


def six_axis_modes(
    sm: SixAxisModel,
    z: np.ndarray,
    lam: np.ndarray,
    M_z: np.ndarray,
    ka: np.ndarray | None,
    held: bool,
) -> Modes:
    """The natural frequencies and modes of the six-axis model about the equilibrium (z, λ):
    the actuators ``held``, else free on springs ``ka`` (0: no stiffness).  Raises
    LinAlgError when the stiffness on the closures' motions is singular or no motion has mass."""
    nx, nq = sm.nx, sm.nq
    kav = np.zeros(nq) if ka is None else np.asarray(ka, dtype=float)
    H, A = sm.linearization(z, lam, kav)
    free = np.concatenate([np.arange(nx), np.arange(nx + nq, sm.nz)]) if held else np.arange(sm.nz)
    N = scipy.linalg.null_space(A[:, free])
    Kr = N.T @ H[np.ix_(free, free)] @ N
    Mr = N.T @ M_z[np.ix_(free, free)] @ N
    Kr, Mr = 0.5 * (Kr + Kr.T), 0.5 * (Mr + Mr.T)
    try:  # K_r positive definite: the closures leave no motion without stiffness
        scipy.linalg.cholesky(Kr)
    except np.linalg.LinAlgError:
        raise np.linalg.LinAlgError("the stiffness on the motions that keep the closures is singular") from None
    mu, V = scipy.linalg.eigh(Mr, Kr)  # K-orthonormal; μ = 1/ω²
    keep = mu > MASSLESS_RTOL * max(float(mu.max()), 0.0)
    if not np.any(keep):
        raise np.linalg.LinAlgError("no motion has mass: give masses or link masses")
    omega2 = 1.0 / mu[keep][::-1]  # ascending frequency
    V = V[:, keep][:, ::-1]
    Z = np.zeros((sm.nz, V.shape[1]))
    Z[free] = N @ V
    Mf = np.zeros((sm.nz, sm.nz))
    Mf[np.ix_(free, free)] = M_z[np.ix_(free, free)]
    clusters = eigen_clusters(omega2)
    T = np.eye(sm.nz)[: nx + nq]  # read in the pose and actuator coordinates
    for idx in clusters:
        omega2[idx] = float(np.mean(omega2[idx]))
        Z[:, idx] = canonical_basis(Z[:, idx], Mf, T)
    return Modes(np.sqrt(omega2) / (2.0 * math.pi), Z, clusters)
