"""Lagrange dynamics of the 3-PRC micromanipulator (Li, Li, Ding, Xu, "An investigation on
kinematics and dynamics performance of a novel 3-PRC-compliant parallel micromanipulator",
Adv. Mech. Eng. 2018, eq 28-41): the add-on's dynamics model.

The kinematics is the mechanism file ``problems/mechanisms/prc3.yaml``.  The energies here
use it through its loop closures only: the platform velocity is pdot = J qdot with J the AD
Jacobian of the *file's* closures at home (eq 26: J = -A2 I), so no closure is written twice.
The leg angles of the energies are the paper's small-motion ones (eq 31: beta_2 = z/L8,
gamma_2 = x/L7) -- formulas of the dynamics, not loop closures -- and the lever angles
theta_1 = A1 q/L2, theta_2 = A2 q/L4 are eq 28's.

Symbols follow the paper: L1..L8, r (Table 1's R), t, b (Table 1); A1 = L2/L1 and
A2 = L2 L4/(L1 L3) (eq 1); q = (q1, q2, q3) the piezo inputs, the generalized coordinates.
"""

from __future__ import annotations

import functools
import math
from typing import Any

import casadi as ca
import numpy as np

from ...analysis import flexure
from ...analysis.dynamics import DynamicsModel
from ...core.model import LoopClosure, Model

#: the kinematic parameters the energies use, by name (the file's closures take them in p)
KINEMATIC = ("L1", "L2", "L3", "L4", "L7")


def lever_ratios(L1, L2, L3, L4):
    """First-lever and total amplification of the secondary lever amplifier,
    A1 = L2/L1 and A2 = L2 L4 / (L1 L3) (eq 1); floats or CasADi symbols."""
    return L2 / L1, L2 * L4 / (L1 * L3)


MASSES = (
    ("m0", "mobile platform (eq 34)"),
    ("m1", "input block of the amplifier, moving with q (eq 29)"),
    ("m2", "first lever, length L2, turning about O1 (eq 29: I_G2 = m2 L2^2/3)"),
    ("m3", "coupler, length L5, moving with A1 q and turning with the first lever (I_G3 = m3 L5^2/12)"),
    ("m4", "second lever, length L4, turning about O2 (I_G4 = m4 L4^2/3)"),
    ("m5", "output link, length L6, moving with A2 q and turning with the second lever (I_G5)"),
    ("m6", "output block E of the amplifier, moving with A2 q (eq 29)"),
    ("m7", "each of the two bars of an R-C leg (eq 32: I_G6 = m7 L8^2/12, I_G7 = m7 L7^2/12)"),
)
#: parameters of the dynamics, in the order of the CasADi vector w: the hinge
#: material's E, the gravity g, the masses, and mechanism parameters by name
DYNAMIC_PARAMETERS = ("E", "g", "b", "t", "r", "L5", "L6", "L8") + tuple(m for m, _ in MASSES)


def _dynamic_symbols(parameters: tuple[str, ...]):
    q, qd = ca.SX.sym("q", 3), ca.SX.sym("qd", 3)
    p, w = ca.SX.sym("p", len(parameters)), ca.SX.sym("w", len(DYNAMIC_PARAMETERS))
    named = {n: w[k] for k, n in enumerate(DYNAMIC_PARAMETERS)}
    named.update({n: p[k] for k, n in enumerate(parameters)})
    return q, qd, p, w, named


def _gravity_coefficient(v: dict, A1, A2):
    """G_e as printed (eq 35, 38)."""
    return (
        v["m0"] * A2 + 6 * (v["m1"] + v["m2"] + v["m3"]) * A1 + 6 * (v["m4"] + v["m5"] + v["m6"] + v["m7"]) * A2
    ) * v["g"]


def lagrangian(closure: LoopClosure) -> ca.Function:
    """Kinetic energy T(q, qd) and potential energy U(q) of the 3-PRC
    (eq 28-36), symbolic in the kinematic parameters p (those of ``closure``, the file's)
    and the dynamic ones w (`DYNAMIC_PARAMETERS`).  `cpm_nlp.analysis.dynamics`
    derives M = d2T/dqd2, K = d2U/dq2 and G = dU/dq at q = 0 (eq 37-38).

    Each energy is typed in as the first line of its equation (the sum over
    bodies and hinges); the collected second lines and eq 38 are
    `printed_coefficients`.  Readings (documented, not tuned):

    * Hinges: k = 2 E b t^2.5 / (9 pi r^0.5) for every hinge (after eq 28).
      Per limb, 2 x (4 hinges turning theta_1 = A1 q/L2 and 3 turning
      theta_2 = A2 q/L4) (eq 28), and 4 leg hinges bending by beta and gamma
      (eq 31).
    * The leg angles are platform displacement over length (eq 31:
      beta_2 = z/L8, gamma_2 = x/L7), cyclic for the other limbs (limb i
      bends by beta_i towards axis i+1 over L8, gamma_i towards axis i+2 over
      L7).  With x = -A2 q1 (eq 26) this gives the leg term
      4 k A2^2 (1/L7^2 + 1/L8^2) in K; eq 38 prints it without A2^2 (as does
      the last line of eq 31, where A stands for A2 but is dropped in eq 38).
      The model keeps the A2^2 of eq 31's first line.
    * Platform velocity: pdot = J qdot with J the AD Jacobian of the loop
      closures (the mechanism file's) at home, which equals -A2 I (eq 26).
    * m1 is the input block and moves with q: 1/2 m1 qdot^2 (eq 29, first
      line).  The collected line multiplies m1 by A1^2; the model does not.
    * I_G5: eq 29 lists I_G5 = m5 L6^2/3, its collected line and eq 38 use
      m5 L6^2/12.  m5 translates with A2 q *and* turns (like m3, whose I_G3 =
      m3 L5^2/12): its inertia about its own centre, m5 L6^2/12, is the
      consistent one and is used.
    * Gravity: U_G = G_e q2 with G_e as printed (eq 35).  It only shifts the
      static equilibrium (q = -K^-1 G) and does not enter the frequencies;
      the mass distribution behind it (Fig. 6) is not in the text.
    """
    q, qd, p, w, v = _dynamic_symbols(tuple(closure.parameters))
    A1, A2 = lever_ratios(v["L1"], v["L2"], v["L3"], v["L4"])
    k = flexure.circular_notch_stiffness(v["E"], v["b"], v["t"], v["r"])  # after eq 28
    m = [v[f"m{j}"] for j in range(8)]
    L2, L4, L5, L6, L7, L8 = (v[n] for n in ("L2", "L4", "L5", "L6", "L7", "L8"))
    IG2, IG3, IG4, IG5 = m[2] * L2**2 / 3, m[3] * L5**2 / 12, m[4] * L4**2 / 3, m[5] * L6**2 / 12  # eq 29
    IG6, IG7 = m[7] * L8**2 / 12, m[7] * L7**2 / 12  # eq 32
    # platform displacement and velocity from the AD Jacobian of the file's closures at home
    # (x = 0, q = 0: eq 9's d = 0 at p = 0), which is -A2 I (eq 26)
    xs, qs = ca.SX.sym("xs", closure.nx), ca.SX.sym("qs", closure.nq)
    phi = closure.phi(xs, qs, p)
    J = -ca.solve(ca.jacobian(phi, xs), ca.jacobian(phi, qs))
    J0 = ca.substitute(J, ca.vertcat(xs, qs), ca.SX.zeros(closure.nx + closure.nq))
    P, Pd = J0 @ q, J0 @ qd
    T, U = 0, 0
    for i in range(3):
        th1, th2 = A1 * q[i] / L2, A2 * q[i] / L4
        th1d, th2d = A1 * qd[i] / L2, A2 * qd[i] / L4
        U += 2 * (4 * 0.5 * k * th1**2 + 3 * 0.5 * k * th2**2)  # eq 28
        T += 2 * (  # eq 29, first line
            0.5 * m[1] * qd[i] ** 2
            + 0.5 * IG2 * th1d**2
            + 0.5 * m[3] * (A1 * qd[i]) ** 2
            + 0.5 * IG3 * th1d**2
            + 0.5 * IG4 * th2d**2
            + 0.5 * (m[5] + m[6]) * (A2 * qd[i]) ** 2
            + 0.5 * IG5 * th2d**2
        )
        nxt, prv = (i + 1) % 3, (i + 2) % 3
        beta, gamma = P[nxt] / L8, P[prv] / L7
        betad, gammad = Pd[nxt] / L8, Pd[prv] / L7
        U += 4 * 0.5 * k * (beta**2 + gamma**2)  # eq 31
        T += 2 * (  # eq 32, first line; the slider moves with d_i = A2 q_i (eq 2)
            0.5 * m[7] * ((A2 * qd[i]) ** 2 + (Pd[nxt] / 2) ** 2 + (Pd[prv] / 2) ** 2)
            + 0.5 * (IG6 * betad**2 + IG7 * gammad**2)
        )
    T += 0.5 * m[0] * ca.dot(Pd, Pd)  # eq 34
    U_G = _gravity_coefficient(v, A1, A2) * q[1]  # eq 35
    return ca.Function("lagrangian", [q, qd, p, w], [T, U + U_G, k], ["q", "qd", "p", "w"], ["T", "U", "k"])


@functools.lru_cache(maxsize=4)
def printed_coefficients(parameters: tuple[str, ...] = KINEMATIC) -> ca.Function:
    """M_e, K_e, G_e exactly as printed in eq 38 (and eq 41's f from them), with p the
    kinematic parameters named ``parameters``, in that order."""
    _q, _qd, p, w, v = _dynamic_symbols(parameters)
    A1, A2 = lever_ratios(v["L1"], v["L2"], v["L3"], v["L4"])
    m = [v[f"m{j}"] for j in range(8)]
    L2, L4, L5, L6, L7, L8 = (v[n] for n in ("L2", "L4", "L5", "L6", "L7", "L8"))
    M_e = (
        2 * (m[1] + m[2] / 3 + (1 + L5**2 / (12 * L2**2)) * m[3]) * A1**2
        + (2 * m[4] / 3 + 2 * (1 + L6**2 / (12 * L4**2)) * m[5] + 2 * m[6] + 10 * m[7] / 3 + m[0]) * A2**2
    )
    K_e = (
        8
        * v["E"]
        * v["b"]
        * v["t"] ** 2.5
        / (9 * math.pi * v["r"] ** 0.5)
        * (2 * A1**2 / L2**2 + 3 * A2**2 / (2 * L4**2) + (1 / L7**2 + 1 / L8**2))
    )
    G_e = _gravity_coefficient(v, A1, A2)
    f = ca.sqrt(K_e / M_e) / (2 * math.pi)  # eq 41
    return ca.Function("eq38", [p, w], [M_e, K_e, G_e, f], ["p", "w"], ["M_e", "K_e", "G_e", "f"])


#: dimension of each value of the model's ``values``
DYNAMICS_DIMENSIONS = {
    "k": "rotational_stiffness",
    "k_exact": "rotational_stiffness",
    "M_e": "mass",
    "K_e": "stiffness",
    "G_e": "force",
    "f": "frequency",
    "M_e_printed": "mass",
    "K_e_printed": "stiffness",
    "G_e_printed": "force",
    "f_printed": "frequency",
}


def dynamics_model(closure: LoopClosure) -> DynamicsModel:
    """The Lagrange model (eq 28-41) on the mechanism file's closure ``closure``."""
    missing = [n for n in KINEMATIC if n not in closure.parameters]
    if missing or (closure.nx, closure.nq) != (3, 3):
        raise ValueError(f"{closure.name}: not the 3-PRC's closure (parameters {missing} missing, or not 3 x 3)")
    parameters = tuple(closure.parameters)

    @functools.cache
    def energies() -> ca.Function:
        return lagrangian(closure)

    def values(model: Model, w: np.ndarray, M: np.ndarray, K: np.ndarray, G: np.ndarray) -> dict[str, Any]:
        """The paper's named quantities: k (after eq 28), M_e, K_e, G_e (eq 38) of the model
        and as printed, and f (eq 41) both ways."""
        _T, _U, k = (float(v) for v in energies()(np.zeros(3), np.zeros(3), model.p, w))
        v = dict(zip(DYNAMIC_PARAMETERS, w))
        M_p, K_p, G_p, f_p = (float(x) for x in printed_coefficients(parameters)(model.p, w))
        return {
            "k": k,
            "k_exact": float(flexure.circular_notch_stiffness_exact(v["E"], v["b"], v["t"], v["r"])),
            "M_e": float(M[0, 0]),
            "K_e": float(K[0, 0]),
            "G_e": float(G[1]),
            "f": math.sqrt(K[0, 0] / M[0, 0]) / (2 * math.pi),  # eq 41
            "M_e_printed": M_p,
            "K_e_printed": K_p,
            "G_e_printed": G_p,
            "f_printed": f_p,
        }

    return DynamicsModel(
        masses=MASSES,
        parameters=DYNAMIC_PARAMETERS,
        lagrangian=energies,
        values=values,
        dimensions=DYNAMICS_DIMENSIONS,
    )
