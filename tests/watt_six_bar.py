"""A Watt II six-bar (two four-bars in series) written as a mechanism file through
the escape hatch (closures as expressions), with an independent numpy model: the
crank theta2 drives the four-bar A0-B-C-C0 (theta3 coupler, theta4 rocker); the
rocker's extension (length b4, at theta4 + delta) drives the second four-bar
(theta5 coupler, theta6 output rocker about E0 = (ex, ey)).  The designated branch:
both transmission angles' sines positive (each four-bar's open assembly)."""

from __future__ import annotations

import math

import numpy as np

from cpm_nlp.mechanisms.described import from_dict

GEOMETRY = {
    "a2": 2.742,
    "a3": 5.8,
    "a4": 4.728,
    "g1": 4.552,
    "b4": 2.226,
    "a5": 3.541,
    "a6": 5.241,
    "ex": 8.761,
    "ey": 0.835,
}
DELTA = -0.607


def closures(y: np.ndarray, t2: float) -> np.ndarray:
    g = GEOMETRY
    t3, t4, t5, t6 = y
    return np.array(
        [
            g["a2"] * math.cos(t2) + g["a3"] * math.cos(t3) - g["a4"] * math.cos(t4) - g["g1"],
            g["a2"] * math.sin(t2) + g["a3"] * math.sin(t3) - g["a4"] * math.sin(t4),
            g["g1"] + g["b4"] * math.cos(t4 + DELTA) + g["a5"] * math.cos(t5) - g["a6"] * math.cos(t6) - g["ex"],
            g["b4"] * math.sin(t4 + DELTA) + g["a5"] * math.sin(t5) - g["a6"] * math.sin(t6) - g["ey"],
        ]
    )


def newton(y: np.ndarray, t2: float) -> np.ndarray:
    """Newton on the closures with a central-difference Jacobian (numpy only)."""
    y = np.array(y, dtype=float)
    for _ in range(100):
        f = closures(y, t2)
        if np.max(np.abs(f)) < 1e-13:
            break
        J = np.empty((4, 4))
        for k in range(4):
            e = np.zeros(4)
            e[k] = 1e-7
            J[:, k] = (closures(y + e, t2) - closures(y - e, t2)) / 2e-7
        y = y - np.linalg.solve(J, f)
    return y


def home() -> np.ndarray:
    return newton(np.array([0.8, 1.1, 2.2, 2.5]), 0.0)


def path(t2: float, steps: int = 720) -> np.ndarray:
    """The designated pose at crank angle t2, followed in small steps from home (numpy)."""
    y = home()
    for k in range(1, steps + 1):
        y = newton(y, t2 * k / steps)
    return y


def description() -> dict:
    y = home()
    params = {k: {"dimension": "length", "default": f"{v} m"} for k, v in GEOMETRY.items()}
    params["delta"] = {"dimension": "angle", "default": f"{DELTA} rad"}
    return {
        "name": "watt2_six_bar",
        "title": "Watt II six-bar (test)",
        "parameters": params,
        "platform": {
            "coordinates": {f"theta{i}": "angle" for i in (3, 4, 5, 6)},
            "position": "[0*a2, 0*a2, 0*a2]",
            "rotation": [],
            "task": ["theta6"],
            "home": {f"theta{i}": float(y[i - 3]) for i in (3, 4, 5, 6)},
        },
        "actuators": {"theta2": {"dimension": "angle", "home": 0}},
        "closures": [
            "a2*cos(theta2) + a3*cos(theta3) - a4*cos(theta4) - g1",
            "a2*sin(theta2) + a3*sin(theta3) - a4*sin(theta4)",
            "g1 + b4*cos(theta4 + delta) + a5*cos(theta5) - a6*cos(theta6) - ex",
            "b4*sin(theta4 + delta) + a5*sin(theta5) - a6*sin(theta6) - ey",
        ],
        "branch": [{"transmission1": "sin(theta4 - theta3)"}, {"transmission2": "sin(theta6 - theta5)"}],
    }


def model():
    mech = from_dict(description())
    return mech.model(mech.closure(), {}, {}, ())
