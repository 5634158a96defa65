"""The 3-PRS forward kinematics inside your own optimization.

Question (prs3-ruiz.md, section 4 asks for at least ±0.2° of tilt over the
whole z range): at a platform height of dz = +2 mm and theta = 0, how far can
the stage tilt about x (psi) if the actuators have a ±2.3 mm stroke and the
spherical flexures may bend at most 1.9° about m (the paper's Fig. 6-7 ranges)?

The decision variables are the three actuator displacements q.  The pose
comes from cpm_nlp's forward kinematics, used as a CasADi Function inside
the NLP: its derivatives come from the implicit function theorem, exactly.
The optimum is then checked with cpm_nlp's own solver and closed-form IK.

Run:  python examples/prs3_fk_in_nlp.py
"""

from __future__ import annotations

import math

import casadi as ca
import numpy as np

import cpm_nlp as cn

STROKE = 2.3e-3  # m, the actuator range of Fig. 6 (-2.15 ... 2.30 mm)
BETA_M_MAX = math.radians(1.9)  # the spherical-joint bending of Fig. 7
DZ = 2e-3  # m above the home pose


def solve() -> dict:
    model = cn.build_model("prs3", {"b": "47.91 mm", "L": "109.215 mm", "alpha0": "45 deg"})
    fns = cn.functions(model)
    names = model.closure.passive_names
    beta_m = [names.index(f"beta_m{i}") for i in (1, 2, 3)]

    q = ca.MX.sym("q", 3)  # the user's decision variables
    fk = fns.fk(q=q, x0=fns.x_home)  # the toolkit's FK, differentiable
    x, passive = fk["x"], fk["passive"]
    pz0 = model.derived["pz0"]
    nlp = {
        "x": q,
        "f": -x[3],  # maximize psi
        "g": ca.vertcat(x[2] - (pz0 + DZ), x[4], passive[beta_m]),
    }
    solver = ca.nlpsol(
        "tilt", "ipopt", nlp, {"ipopt.print_level": 0, "ipopt.sb": "yes", "print_time": False, "ipopt.tol": 1e-12}
    )
    sol = solver(
        x0=[DZ, DZ, DZ],
        lbx=-STROKE,
        ubx=STROKE,
        lbg=[0, 0] + [-BETA_M_MAX] * 3,
        ubg=[0, 0] + [BETA_M_MAX] * 3,
    )
    q_opt = np.asarray(sol["x"]).ravel()

    # check the optimum with the toolkit's own solver and the paper's closed-form IK
    check = cn.forward_kinematics(model, q_opt, cn.SolverConfig("newton"))
    ik = cn.inverse_kinematics(model, [pz0 + DZ, check.x[3], 0.0])
    return {
        "success": bool(solver.stats()["success"]),
        "q": q_opt,
        "psi": float(check.x[3]),
        "status": check.status,
        "beta_m": check.passive[beta_m],
        "ik_q": ik.q,
    }


def main() -> None:
    r = solve()
    print(f"IPOPT success: {r['success']}")
    print("actuators s1..s3 [mm]: " + ", ".join(f"{v * 1e3:.4f}" for v in r["q"]))
    print(f"largest tilt psi at dz = +2 mm, theta = 0: {math.degrees(r['psi']):.4f} deg")
    print("spherical bending beta_m1..3 [deg]: " + ", ".join(f"{math.degrees(v):.4f}" for v in r["beta_m"]))
    print(
        f"check by cpm_nlp FK: {r['status'].value}; IK of that pose gives s = "
        + ", ".join(f"{v * 1e3:.4f}" for v in r["ik_q"])
        + " mm"
    )


if __name__ == "__main__":
    main()
