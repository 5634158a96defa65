"""Biglide: a planar 2-PRR parallel mechanism, the smallest complete mechanism plugin.

Two sliders move along the x axis (q1, q2, measured from x = -d and x = +d);
a leg of length L joins each slider to the platform point P = (x, y):

    (x - (q1 - d))^2 + y^2 = L^2,    (x - (q2 + d))^2 + y^2 = L^2

On the working branch the platform is above the sliders (y > 0), leg 1 leans
right and leg 2 left.  IK in closed form: q1 = x + d - sqrt(L^2 - y^2),
q2 = x - d + sqrt(L^2 - y^2).
"""

import math
from pathlib import Path

import casadi as ca
import numpy as np

import cpm_nlp as cn
from cpm_nlp.core.options import Option

X = (cn.Coordinate("x", "length", "platform point, x"), cn.Coordinate("y", "length", "platform point, y"))
Q = tuple(cn.Coordinate(f"q{i}", "length", f"slider {i}", "q") for i in (1, 2))


def closure() -> cn.LoopClosure:
    x, q, p = ca.SX.sym("x", 2), ca.SX.sym("q", 2), ca.SX.sym("p", 2)
    d, L = p[0], p[1]
    legs = [(x[0] - (q[0] - d)) ** 2 + x[1] ** 2 - L**2, (x[0] - (q[1] + d)) ** 2 + x[1] ** 2 - L**2]
    phi = ca.Function("phi", [x, q, p], [ca.vertcat(*legs) / (2 * L)], ["x", "q", "p"], ["phi"])
    t = ca.SX.sym("t", 2)
    h2 = L**2 - t[1] ** 2
    root = ca.sqrt(ca.fmax(h2, 0))
    ik = ca.Function(
        "ik", [t, p], [t, ca.vertcat(t[0] + d - root, t[0] - d + root), h2 / (2 * L)], ["t", "p"], ["x", "q", "reach"]
    )
    g = ca.vertcat(x[1], x[0] - (q[0] - d), (q[1] + d) - x[0])
    branch = ca.Function("branch", [x, q, p], [g], ["x", "q", "p"], ["g"])
    return cn.LoopClosure(
        "biglide",
        x=X,
        q=Q,
        parameters=("d", "L"),
        phi=phi,
        task=("x", "y"),
        ik=ik,
        branch=branch,
        home=lambda p: (np.array([0.0, math.sqrt(p[1] ** 2 - p[0] ** 2)]), np.zeros(2)),
        bounds=lambda p: (np.array([-p[1], 0.0]), np.array([p[1], p[1]])),
    )


def build(closure_: cn.LoopClosure, parameters: dict, limits: dict) -> cn.Model:
    return cn.Model(closure_, parameters, {k: v for k, v in limits.items() if v is not None})


MECHANISM = cn.Mechanism(
    name="biglide",
    title="planar 2-PRR biglide (demo plugin)",
    parameters=(
        Option("d", "length", "half distance between the slider origins", default=0.05, lower=0.0, strict=True),
        Option("L", "length", "leg length", default=0.1, lower=0.0, strict=True),
    ),
    limits=(Option("q", "length", "slider stroke [low, high]", default=None, shape="range"),),
    closure=closure,
    build=build,
    problem_files=(str(Path(__file__).with_name("biglide_fk.yaml")),),
)
