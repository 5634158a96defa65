"""Flexure-joint design and the pseudo-rigid-body compliance model of the RPR
compliant mechanism (rpr-2rpu-upr-zhang-2022.md, sections 3-4, eq 27-44).

* `joint_design` -- the R and U flexure joints of one leg minimising the
  energy of eq 27 under unit constraint wrenches, with the rotation capability
  of eq 32, the 12 mm size box and the thinnest section (section 3.1), by IPOPT
  from several starts;
* `compliance_model` -- the bridge amplifier (eq 33-36), the mechanism
  stiffness K' = G_pᵀ K_J G_p (eq 39-40) and the compliances C and C_in
  (eq 41-44).

Readings and inputs the paper leaves out (documented, not tuned):

* **Joint compliances.**  Refs [31], [32] are not printed.  R joint: one
  right-circular notch (notch radius r, thinnest section t, width b); U joint:
  two orthogonal circular notches (r, t) cut next to each other in a square rod
  of side h (Table 1 gives no width for U).  Compliances:
  `cpm_nlp.analysis.flexure_compliance` (Lobontiu 2002).  The block height of the
  R joint (Table 1: h = 12 mm) does not enter a notch's compliance; the design
  reports the smallest block that holds the notch, t + 2r.
* **Objective (eq 27, 30, 31).**  The wrenches are the appendix's constraint
  wrenches of leg 1 (S_wc,1,1: a couple about the leg; S_wc,1,2: a force along y
  through B1) and its actuated wrench S_wa,1,1 (a force along A1B1 × y through
  B1), unit, at the initial pose.  Their work on the joint, with the joint's own
  rotation axes removed, gives exactly the terms of eq 30 (R at A1:
  cr_tx + cr_ty + |A1B1|² cr_mx + cr_mz) and eq 31 (U at B1: cu_tx + cu_ty +
  cu_mz).  Eq 30-31 print each compliance squared; that is neither the energy
  of eq 27 nor dimensionally consistent, so eq 27 is followed.  A unit couple
  (N m) and a unit force (N) are not commensurate: the couple is scaled by
  ``couple_arm`` (1 m reads eq 27 in SI units, as the paper's MATLAB would).
* **Rotation capability.**  Eq 32 as printed, θ_max = r σ_Y / (E t SF)
  (``rotation_limit = "eq32"``), or the circular-notch stress limit
  3π/(4E) sqrt(r/t) σ_Y/SF (``"notch"``, pantograph eq 38).  SF is not given;
  SF = 2 makes Table 1's R joint (r/t = 10) meet eq 32 at its bound.  Table 1's
  U joint (r = 1 mm, t = 0.4 mm) gives 1.0° / SF < 2° by eq 32 for any SF >= 1.
* **Bridge amplifier (eq 33-36).**  With the printed l1 = 1.6 mm and l2 = 16 mm,
  eq 36 gives D_out/D_in = A21/A11 = l1/l2 = 0.1, a reducer, while section 3.2
  and eq 60 (FEA: 8.4-9.5) describe an amplification of about 10 and eq 55/58
  imply platform compliances ten times the input compliance.  The printed
  values are taken as exchanged: l1 = 16 mm (the arm of the output force f_y in
  eq 33) and l2 = 1.6 mm (that of the input f_x), so the ratio is l1/l2 = 10.
  The leaf-hinge compliances c_r, c_t of the amplifier (Fig. 6) are not given:
  they are inputs (stiffnesses, or a leaf's length, thickness and width; c_r =
  12 L/(E w t³), c_t = L/(E w t), the PRB rotation and the stretch along the
  leaf).
* K_J holds the stiffness of each passive joint's working rotation (eq 39), in
  the order of the file's passive joints (problems/mechanisms/rpr.yaml, eq 13: R, U, U, U, U, R,
  R, U, U), each by its family (theta_R or theta_U).
"""

from __future__ import annotations

import logging
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import casadi as ca
import numpy as np

from ...analysis import compliance as cm
from ...analysis import flexure
from ...analysis import flexure_compliance as fc
from ...analysis.beams import Section, element_compliance
from ...analysis.flexure import Material
from ...core import screws
from ...core.kinematics import jacobians
from ...core.model import LoopClosure, Model
from ...core.result import Status
from ...core.solver import SolverConfig, solvers_of, translate_casadi_error
from . import screws as rpr_screws
from .design import optimisation_options

log = logging.getLogger(__name__)

JOINTS = ("R", "U")
ROTATION_LIMITS = ("eq32", "notch")
#: free (working) rotation axes of each joint in the joint frame, wrench order (f; m)
FREE_AXES = {"R": (4,), "U": (3, 4)}
#: design variables of each joint (SI), in order
VARIABLES = {"R": ("r", "t", "b"), "U": ("r", "t", "h")}
#: the diagonal compliances reported, named as eq 28-29
COMPLIANCE_NAMES = ("tx", "ty", "tz", "mx", "my", "mz")


# -- joints --------------------------------------------------------------------------------------------


def joint_compliance(joint: str, E, G, dims) -> Any:
    """6 x 6 compliance of the R or U joint (joint frame, z along the leg) for
    dims = (r, t, b) or (r, t, h)."""
    r, t, w = dims
    if joint == "R":
        return fc.r_joint_compliance(E, G, w, t, r, axis="y")
    return fc.u_joint_compliance(E, G, w, t, r)


def working_compliance(joint: str, E, G, dims) -> Any:  # noqa: ARG001 - one signature for every joint type
    """Compliance of the joint's working rotation [rad/(N m)] (the notch's rz)."""
    r, t, w = dims
    return fc.circular_notch_compliances(E, G, w, t, r)["rz"]


def rotation_capability(mode: str, E, sigma_y, SF, dims) -> Any:
    r, t = dims[0], dims[1]
    if mode == "eq32":
        return fc.rotation_limit_eq32(E, t, r, sigma_y, SF)
    return flexure.circular_notch_max_rotation(E, t, r, sigma_y / SF)


def design_wrenches(model: Model, couple_arm: float) -> dict[str, np.ndarray]:
    """The unit wrenches of eq 27 at each joint of leg 1 (initial pose), in the
    joint frame (= the fixed frame: leg 1 runs along z): S_wc,1,1 (couple, scaled
    by ``couple_arm``), S_wc,1,2 and S_wa,1,1, referred to A1 (R) and to B1 (U)."""
    x = model.x_home
    p = rpr_screws.paper_parameters(model)
    out = [np.asarray(v) for v in rpr_screws.screw_function()(x, p)]
    wa, wc = out[3], out[4]  # leg 1: ta1, tc1, wa1, wc1 follow S_t
    o_ = np.array([0.0, 0.0, x[2]])
    A1 = np.array([p[0], 0.0, 0.0])
    B1 = A1 + np.array([0.0, 0.0, x[2]])
    couple = wc[:, 0] / np.linalg.norm(wc[:, 0][3:]) * couple_arm
    force_y = screws.normalize(wc[:, 1])
    force_x = screws.normalize(wa[:, 0])
    ws = [couple, force_y, force_x]
    return {
        "R": np.column_stack([screws.transport(w, o_, A1) for w in ws]),
        "U": np.column_stack([screws.transport(w, o_, B1) for w in ws]),
    }


def constraint_energy(joint: str, C: np.ndarray, wrenches: np.ndarray) -> float:
    """Σ wᵀ C w over the wrenches (columns; eq 27), the joint's working
    rotations removed (eq 30-31 leave out cr_my, cu_mx, cu_my)."""
    keep = np.ones(6)
    keep[list(FREE_AXES[joint])] = 0.0
    W = np.asarray(wrenches) * keep[:, None]
    return float(np.einsum("ik,ij,jk->", W, np.asarray(C), W))


@dataclass
class JointDesign:
    """Optimum of one joint: dims (r, t, b|h) [m], objective f (eq 27),
    rotation capability theta_max, the diagonal compliances (eq 28-29) and the
    working compliance; the multi-start record as for the synthesis."""

    joint: str
    status: Status
    dims: tuple[float, float, float] | None = None
    f: float | None = None
    theta_max: float | None = None
    compliances: dict[str, float] = field(default_factory=dict)
    working: float | None = None
    starts: int = 0
    converged: int = 0
    at_best: int = 0
    iterations: int = 0
    seconds: float = 0.0
    message: str = ""


@dataclass(frozen=True)
class JointSpec:
    """Everything the joint optimisation takes besides the joint type."""

    material: Material
    SF: float
    theta_des: float
    box: float
    t_min: float
    couple_arm: float
    rotation_limit: str = "eq32"


class _JointSolver:
    """IPOPT for one joint type and rotation model, built once per solver
    configuration; the material, limits and wrenches are NLP parameters."""

    NP = 6 + 18  # E, G, sigma_y, SF, theta_des, box, 3 wrenches

    def __init__(self, joint: str, mode: str, config: SolverConfig) -> None:
        z = ca.SX.sym("z", 3)  # mm
        p = ca.SX.sym("p", self.NP + 1)  # + objective scale
        E, G, sy, SF, th_des, box = (p[k] for k in range(6))
        W = ca.reshape(p[6:24], 6, 3)
        dims = [z[0] * 1e-3, z[1] * 1e-3, z[2] * 1e-3]
        C = joint_compliance(joint, E, G, dims)
        keep = np.ones(6)
        keep[list(FREE_AXES[joint])] = 0.0
        Wk = ca.diag(ca.DM(keep)) @ W
        f = ca.sum1(ca.diag(Wk.T @ C @ Wk))  # eq 27, as constraint_energy
        r, t, w = dims
        cap = rotation_capability(mode, E, sy, SF, dims)
        g = [cap / th_des - 1.0, (w - (t + 2 * r)) / box]
        if joint == "R":
            g += [(box - 2 * r) / box, (box - (t + 2 * r)) / box]
        else:
            g += [(box - 4 * r) / box]
        self.objective = ca.Function(f"rpr_joint_{joint}_f", [z, p], [f], ["z", "p"], ["f"])
        self.ng = len(g)
        try:
            self.fn = ca.nlpsol(
                f"rpr_joint_{joint}_{mode}",
                "ipopt",
                {"x": z, "p": p, "f": f / p[self.NP], "g": ca.vertcat(*g)},
                optimisation_options(config),
            )
        except RuntimeError as exc:
            raise translate_casadi_error(exc, config.options) from exc


def _parameters(spec: JointSpec, wrenches: np.ndarray) -> np.ndarray:
    m = spec.material
    return np.r_[m.E, m.G, m.yield_strength, spec.SF, spec.theta_des, spec.box, np.asarray(wrenches).T.ravel()]


def evaluate_joint(joint: str, spec: JointSpec, wrenches: np.ndarray, dims: Sequence[float]) -> dict[str, Any]:
    """Objective, rotation capability, compliances and constraint margins of a
    given joint (e.g. Table 1's), in SI."""
    m = spec.material
    C = np.asarray(joint_compliance(joint, m.E, m.G, dims))
    r, t, w = dims
    cap = float(rotation_capability(spec.rotation_limit, m.E, m.yield_strength, spec.SF, dims))
    margins = {
        "rotation": cap - spec.theta_des,
        "thinnest": t - spec.t_min,
        "width": w - (t + 2 * r),
        "box": spec.box - (2 * r if joint == "R" else 4 * r),
        "size": spec.box - w,
    }
    if joint == "R":
        margins["height"] = spec.box - (t + 2 * r)
    return {
        "f": float(constraint_energy(joint, C, wrenches)),
        "theta_max": cap,
        "compliances": {f"c{joint.lower()}_{n}": float(C[k, k]) for k, n in enumerate(COMPLIANCE_NAMES)},
        "working": float(working_compliance(joint, m.E, m.G, dims)),
        "margins": margins,
        "feasible": all(v >= -1e-12 for v in margins.values()),
    }


def joint_design(model: Model, joint: str, spec: JointSpec, config: SolverConfig, starts: int = 6) -> JointDesign:
    """Optimise the R or U joint of leg 1 (eq 27-32) by IPOPT from ``starts``
    Halton points of the size box."""
    if spec.material.yield_strength is None:
        raise ValueError("the material needs a yield strength (eq 32)")
    t0 = time.perf_counter()
    wrenches = design_wrenches(model, spec.couple_arm)[joint]
    built = solvers_of(model.closure).get(
        f"rpr_joint_{joint}_{spec.rotation_limit}", config, lambda: _JointSolver(joint, spec.rotation_limit, config)
    )
    box_mm, tmin_mm = spec.box * 1e3, spec.t_min * 1e3
    r_max = box_mm / (2.0 if joint == "R" else 4.0)
    lbx = np.array([1e-3 * box_mm, tmin_mm, tmin_mm])
    ubx = np.array([r_max, box_mm, box_mm])
    p = _parameters(spec, wrenches)
    mid = (lbx + ubx) / 2.0
    scale = float(built.objective(mid, np.r_[p, 1.0]))
    p = np.r_[p, scale if scale > 0 else 1.0]
    from scipy.stats import qmc  # here: scipy.stats takes 0.5 s to import (start-up of every rpr problem)

    sampler = qmc.Halton(d=3, scramble=False)
    x0s = lbx + (ubx - lbx) * sampler.random(starts)
    found = []
    iterations = 0
    failures = []
    for x0 in x0s:
        try:
            out = built.fn(x0=x0, p=p, lbx=lbx, ubx=ubx, lbg=0.0, ubg=ca.inf)
        except RuntimeError as exc:
            log.debug("joint %s, start %s: %s", joint, x0, exc)
            failures.append(str(exc).splitlines()[0])
            continue
        stats = built.fn.stats()
        iterations += int(stats.get("iter_count", 0))
        if not stats.get("success", False):
            failures.append(str(stats.get("return_status", "")))
            continue
        z = np.asarray(out["x"]).ravel()
        found.append((z, float(out["f"])))
    if not found:
        infeasible = any("Infeasible" in f for f in failures)
        return JointDesign(
            joint,
            Status.INFEASIBLE if infeasible else Status.NOT_CONVERGED,
            starts=len(x0s),
            iterations=iterations,
            seconds=time.perf_counter() - t0,
            message=f"no start converged ({failures[0] if failures else 'no start'})",
        )
    found.sort(key=lambda item: item[1])
    z, fbest = found[0]
    at_best = sum(1 for _, f in found if abs(f - fbest) <= 1e-7 * max(1.0, abs(fbest)))
    dims = tuple(float(v) * 1e-3 for v in z)
    ev = evaluate_joint(joint, spec, wrenches, dims)
    return JointDesign(
        joint,
        Status.SOLVED,
        dims,
        ev["f"],
        ev["theta_max"],
        ev["compliances"],
        ev["working"],
        len(x0s),
        len(found),
        at_best,
        iterations,
        time.perf_counter() - t0,
        f"{len(found)} of {len(x0s)} starts converged, {at_best} to the best design",
    )


# -- pseudo-rigid-body compliance model, eq 33-44 ------------------------------------------------------


def leaf_compliances(material: Material, length: float, thickness: float, width: float) -> tuple[float, float]:
    """(c_r, c_t) of a leaf hinge of the amplifier: rotation 12 L/(E w t³)
    (= 1 / `cpm_nlp.analysis.flexure.leaf_spring_stiffness`) and stretch along the
    leaf L/(E w t)."""
    c_r = 1.0 / flexure.leaf_spring_stiffness(material.E, width, thickness, length)
    c_t = length / (material.E * width * thickness)
    return c_r, c_t


def leaf_beam_compliances(
    material: Material, length: float, thickness: float, width: float
) -> tuple[float, float, float]:
    """(c_r, c_t, c_s) of a leaf hinge as a Timoshenko beam (`cpm_nlp.analysis.beams`: the
    Castigliano integral over the leaf, carried to its centre, where the PRB model of Fig. 8 puts
    its pivot): the rotation and the stretch the bridge model takes (eq 33-36; for a prismatic
    leaf exactly the PRB's L/(EI) and L/(EA)), and the transverse compliance L³/(12 EI) +
    L/(κ G A) that it leaves out ("ignores the deformations of the leaf spring in other
    directions", section 3.2)."""
    sec = Section("rectangle", {"b": width, "h": thickness})
    C, _ = element_compliance(sec, material.E, material.nu, 0.0, length, length / 2, "timoshenko", "distributed")
    C = np.array(C, dtype=float)
    Ad = np.eye(6)
    Ad[1, 5], Ad[2, 4] = -length / 2, length / 2  # (delta, theta) at the centre, rigid with the tip
    Cc = Ad @ C @ Ad.T
    return float(Cc[4, 4]), float(Cc[0, 0]), float(Cc[2, 2])


def amplifier_matrices(l1: float, l2: float, c_r: float, c_t: float) -> dict[str, np.ndarray]:
    """A11, A12, A21, A22 of eq 36 (diagonal, one entry per leg); l1 is the arm
    of the output force, l2 that of the input force (see the module notes)."""
    eye = np.eye(3)
    return {
        "A11": l2**2 * c_r / 4.0 * eye,
        "A12": l1 * l2 * c_r / 4.0 * eye,
        "A21": l1 * l2 * c_r / 4.0 * eye,
        "A22": (l1**2 * c_r + 4.0 * c_t) / 4.0 * eye,
    }


def stiffness_order(model: Model, k_R: float, k_U: float) -> np.ndarray:
    """K_J diagonal in the order of the model's passive joints, by their family (eq 39)."""
    return np.array([k_R if c.family == "theta_R" else k_U for c in model.closure.passive_coords])


def passive_jacobian(closure: LoopClosure) -> ca.Function:
    """``("passive_jacobian", [x, q, p], [dj_dx, dj_dq])``: the partial derivatives of the
    closure's passive joint angles (the file's, eq 13) by AD, built once per closure (code)."""

    def build() -> ca.Function:
        x, q, p = ca.SX.sym("x", closure.nx), ca.SX.sym("q", closure.nq), ca.SX.sym("p", closure.np)
        j = closure.passive(x, q, p)
        return ca.Function(
            "passive_jacobian",
            [x, q, p],
            [ca.jacobian(j, x), ca.jacobian(j, q)],
            ["x", "q", "p"],
            ["dj_dx", "dj_dq"],
        )

    return solvers_of(closure).memo(("rpr_passive_jacobian",), build)


def passive_rates(model: Model, x: Sequence[float]) -> tuple[np.ndarray, np.ndarray]:
    """(G, G_p) at the pose x, by AD: G = dx/dq (eq 11), G_p = d(passive)/dq (eq 13)."""
    xv = np.asarray(x, dtype=float)
    q = np.asarray(model.closure.ik(xv, model.p)[1]).ravel()
    G = jacobians(model, xv, q).J
    dj_dx, dj_dq = (np.asarray(v) for v in passive_jacobian(model.closure)(xv, q, model.p))
    return G, dj_dx @ G + dj_dq  # the passive angles' total rate per actuator rate (eq 13)


def mechanism_stiffness(model: Model, x: Sequence[float], k_J: Sequence[float]) -> np.ndarray:
    """K' of eq 40 as an instance of the generic pseudo-rigid-body method
    (`cpm_nlp.analysis.compliance`): hinges of stiffness k_J on the passive
    joints, undeflected at the home pose, give the input stiffness K_q, the Hessian of
    the strain energy along the loop closures.  At the home pose (the paper's initial
    pose, where eq 40 is evaluated) it equals G_pᵀ K_J G_p exactly; away from it K_q
    also holds the terms of the hinges' preload (the energy's gradient times the
    curvature of the passive angles), which eq 40 leaves out."""
    c = model.closure
    xv = np.asarray(x, dtype=float)
    q = np.asarray(c.ik(xv, model.p)[1]).ravel()
    names = cm.joint_names(c)
    k = np.zeros(len(names))
    k[c.nx + c.nq :] = np.asarray(k_J, dtype=float)
    hs = cm.HingeSet(names, [], k, cm.joint_vector(model, model.x_home, model.q_home), [])
    return cm.static_point(model, hs, xv, q).K_q


def compliance_model(
    model: Model, x: Sequence[float], *, l1: float, l2: float, c_r: float, c_t: float, k_J: Sequence[float]
) -> dict[str, Any]:
    """C (eq 43: (θ, α, P) per input force) and C_in (eq 44: input
    displacement per input force) with every intermediate matrix."""
    G, G_p = passive_rates(model, x)
    K_J = np.diag(np.asarray(k_J, dtype=float))
    K = mechanism_stiffness(model, x, k_J)  # eq 40, by the generic energy method
    A = amplifier_matrices(l1, l2, c_r, c_t)
    M = np.linalg.solve(np.eye(3) + A["A22"] @ K, A["A21"])  # D_out = M F_in (eq 36, 40)
    C = G @ M  # eq 43
    C_in = A["A11"] - A["A12"] @ K @ M  # eq 44
    return {
        **A,
        "G": G,
        "G_p": G_p,
        "K_J": K_J,
        "K_prime": K,
        "M": M,
        "C": C,
        "C_in": C_in,
        "amp": np.diag(M) / np.diag(C_in),
    }
