"""The paper's analyses of the 3D compliant pantograph (Elgammal, Fanni, Mohamed, "Design and
Analysis of a Novel 3D Decoupled Manipulator Based on Compliant Pantograph for
Micromanipulation", J. Intell. Robot. Syst. 2016), on the model of its mechanism file
problems/mechanisms/pantograph.yaml (the kinematics, eq 1-8, written once, there).

Every formula here is in the parameters a, b, the joint limits and the magnification factors
the model reads off the AD Jacobian of the file's loops (`complete`); none uses a copy of
the loop closures (the hand-written ones are the independent reference
tests/reference/pantograph_closures.py).

* the joint limits of the paper (section 5.2): ψ ∈ [ψ_min, ψ_max] for the hinges with
  horizontal axes, |φ| <= φ_max for those with vertical axes, given directly or from the hinge
  by eq 31 (ψ = π/2 ∓ δ_max, φ_max = δ_max, δ_max of the flexure by eq 30 or 38); ranges
  counted from home for θ1, θ2 (the hinges at A and B, which the paper does not limit) and
  the actuators (``stroke``, centred on dx0 = √2 a, dy0 = dz0 = 0);
* the reachable workspace in closed form (eq 17-29, `paper_membership`), the actuator
  ranges (eq 20-22), the paper's cuboid (eq 32-34, `paper_cuboid`).

Readings of the paper chosen here (documented, not tuned):

* **Home configuration**: the flexures are undeflected at ψ = π/2, φ = 0
  (eq 31 puts ψ_min, ψ_max symmetric about π/2; section 8: "the
  configuration corresponding to the middle of the input displacement
  ranges has zero deflection"): θ1 = π/4, θ2 = -π/4, dx0 = √2 a, dy = dz = 0
  (the prototype's dx range 28.234 ... 28.334 mm is centred on √2 · 20 mm).
* **Branch**: the elbow with θ1 > θ2; the singularity of section 5 (eq 25-29, θ_i = ±π/2)
  belongs to the guiding parallelograms, which eq 1-8 do not contain; it enters as the branch
  condition cos θ_i > 0 (the file's ``branch``), and with it, sin(θ1 - θ2) > 0 and cos φ > 0
  the loop model's workspace is exactly the region bounded by eq 24-29 (proof in
  `paper_membership`).
* **Magnification factors** Mx, My, Mz are read off the AD Jacobian of the file's loops at the
  home configuration (Model.derived), not typed in; the closed form Mx = 1 + b/a, My = Mz = b/a
  (eq 9-10) is checked against them in the tests.
* **Eq 31 discrepancy**: with l = 5 mm, t = 0.1 mm, E = 2 GPa, σ_all = 23.5
  MPa eq 30-31 give δ_max = 0.148·5·23.5e6/(2e9·0.1) = 0.0870 rad, while the
  paper prints φ_max = 0.0795 rad and ψ = 1.49/1.65 rad (= π/2 ∓ 0.08).  The
  printed limits are the ones its cuboid (V = 1.78e-6 m³) is computed with;
  problems/pantograph_cuboid_hinge.yaml shows both.
* **Eq 34c** as printed, ẑ <= a Mz x̂ tan φ_max / Mx, is not a length (a·x̂) and
  bounds ẑ at the far face x̂; the cuboid's corners on its near face px = k
  then leave the φ planes (eq 18: |pz| <= (Mz/Mx) px tan φ_max).  The paper's
  own optimum (ẑ = 0.0054 m) satisfies the bound at the near face,
  ẑ <= (Mz/Mx) k tan φ_max, which is also what membership requires.  See
  `paper_cuboid` (``reading``).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from types import MappingProxyType

import casadi as ca
import numpy as np

from ...analysis import hinge_types
from ...analysis.certify import certify_box
from ...analysis.workspace import check_box
from ...core.errors import InputError
from ...core.model import Model
from ...core.options import Option
from ...core.outputs import outputs_of
from ...core.solver import SolverConfig, solvers_of

HALF_PI = math.pi / 2
SQRT2 = math.sqrt(2.0)
#: the task coordinates of the file (the end-effector E), the rows of the magnification
TASK = ("px", "py", "pz")

#: the paper's joint limits (section 5.2, eq 31), beside the file's limit families (``theta``
#: replaces the file's family of that name: here it counts from home)
LIMITS = (
    Option("psi_min", "angle", "lowest hinge angle ACB (eq 17, 24)", default=None, lower=0.0, upper=math.pi),
    Option("psi_max", "angle", "highest hinge angle ACB (eq 17, 23)", default=None, lower=0.0, upper=math.pi),
    Option(
        "phi_max",
        "angle",
        "largest rotation |phi| of the vertical-axis hinges (eq 18)",
        default=None,
        lower=0.0,
        upper=HALF_PI,
        strict=True,
    ),
    Option(
        "theta",
        "angle",
        "range [low, high] of the rotations theta1 - pi/4 and theta2 + pi/4 of the hinges at A and B from home "
        "(not limited in the paper)",
        default=None,
        shape="range",
    ),
    Option(
        "stroke",
        "length",
        "actuator range [low, high] about the home configuration (dx0 = sqrt(2) a, dy0 = dz0 = 0), for each actuator",
        default=None,
        shape="range",
    ),
) + hinge_types.HINGE_LIMIT_OPTIONS

# -- limits -------------------------------------------------------------------------------------

_DIRECT = ("psi_min", "psi_max", "phi_max")
#: the file's limit families that say what a paper's limit says (not both)
_SAME = {"psi": ("psi_min", "psi_max"), "phi": ("phi_max",), "dx": ("stroke",), "dy": ("stroke",), "dz": ("stroke",)}


def check_limits(limits: dict, path: tuple) -> None:
    """Either the joint-angle limits or the hinge that sets them (eq 31), not both; a file's
    family and the paper's limit of the same joints, not both."""
    direct = [k for k in _DIRECT if limits.get(k) is not None]
    hinge = [k for k in hinge_types.HINGE_KEYS if limits.get(k) is not None]
    if direct and hinge:
        raise InputError(
            f"give either the joint-angle limits ({', '.join(direct)}) or the hinge that sets them by eq 31 "
            f"({', '.join(hinge)}), not both",
            path=path,
        )
    for family, papers in _SAME.items():
        given = [k for k in papers if limits.get(k) is not None]
        if hinge and family in ("psi", "phi"):
            given.append("hinge")
        if limits.get(family) is not None and given:
            raise InputError(
                f"give either {family} (a range of the joint) or {', '.join(given)} (the paper's limits), not both",
                path=path + (family,),
            )
    lo, hi = limits.get("psi_min"), limits.get("psi_max")
    if lo is not None and hi is not None and not lo < hi:
        raise InputError(
            f"expected psi_min < psi_max, got psi_min = {lo:.6g} rad, psi_max = {hi:.6g} rad", path=path + ("psi_min",)
        )
    hinge_types.hinge_rotation(limits, path)  # validates the hinge


def joint_limits(limits: dict) -> dict:
    """psi_min, psi_max, phi_max (rad; None where unlimited) and delta_max, the hinge
    rotation of eq 30/38 (None unless a hinge is given), from validated limits."""
    delta = hinge_types.hinge_rotation(limits)
    if delta is not None:  # eq 31; a hinge that turns further than the geometry allows does not limit
        return {
            "psi_min": max(HALF_PI - delta, 0.0),
            "psi_max": min(HALF_PI + delta, math.pi),
            "phi_max": delta if delta < HALF_PI else None,
            "delta_max": delta,
        }
    out = {k: limits.get(k) for k in _DIRECT}
    out["delta_max"] = None
    return out


def magnification(model: Model) -> tuple[float, float, float, float]:
    """Mx, My, Mz (eq 9-10) and the manipulability ω = |det J| (eq 15-16), read off the AD
    Jacobian dt/dq of the file's loops at home."""
    c = model.closure
    J = np.asarray(c.jacobian(model.x_home, model.q_home, model.p), dtype=float)[[c.x_names.index(n) for n in TASK]]
    return float(J[0, 0]), float(-J[1, 1]), float(-J[2, 2]), abs(float(np.linalg.det(J)))


def magnification_symbolic(closure, a, b):
    """Mx, My, Mz from the AD Jacobian of the file's loops at home, symbolic in a, b (the home
    pose from the file's IK at E = ((a + b)√2, 0, 0), section 8)."""
    p = ca.vertcat(a, b)
    x0, q0, _reach = closure.ik(ca.vertcat((a + b) * SQRT2, 0, 0), p)
    J = closure.jacobian(x0, q0, p)
    i = [closure.x_names.index(n) for n in TASK]
    return J[i[0], 0], -J[i[1], 1], -J[i[2], 2]


def complete(model: Model, limits: dict) -> None:
    """The paper's limits on the file's coordinates (ψ, φ, θ1, θ2, the actuators) and its
    derived quantities: Mx, My, Mz, ω (eq 9-16, AD), dx0, the angle limits and the hinge."""
    angles = joint_limits(limits)
    lim = dict(model.limits)
    if angles["psi_min"] is not None or angles["psi_max"] is not None:
        lim["psi"] = (
            angles["psi_min"] if angles["psi_min"] is not None else 0.0,
            angles["psi_max"] if angles["psi_max"] is not None else math.pi,
        )
    if angles["phi_max"] is not None:
        lim["phi"] = (-angles["phi_max"], angles["phi_max"])
    names = model.closure.x_names
    if limits.get("theta") is not None:  # about home: theta1 = pi/4, theta2 = -pi/4
        lo, hi = limits["theta"]
        for name in ("theta1", "theta2"):
            home = float(model.x_home[names.index(name)])
            lim[name] = (home + lo, home + hi)
    if limits.get("stroke") is not None:  # about home: dx0 = sqrt(2) a, dy0 = dz0 = 0
        lo, hi = limits["stroke"]
        for name, centre in zip(model.closure.q_names, model.q_home):
            lim[name] = (float(centre) + lo, float(centre) + hi)
    Mx, My, Mz, omega = magnification(model)
    derived = {
        "Mx": Mx,
        "My": My,
        "Mz": Mz,
        "omega": omega,
        "dx0": float(model.q_home[0]),
        "psi_min": angles["psi_min"],
        "psi_max": angles["psi_max"],
        "phi_max": angles["phi_max"],
    }
    if angles["delta_max"] is not None:
        derived["delta_max"] = angles["delta_max"]
        derived.update({k: limits[k] for k in ("l", "t", "r") if limits.get(k) is not None})  # the hinge
    dims = {"dx0": "length", "delta_max": "angle", "l": "length", "t": "length", "r": "length"}
    dims.update({k: "dimensionless" for k in ("Mx", "My", "Mz", "omega")})
    dims.update({k: "angle" for k in _DIRECT})
    model.limits = lim
    model.derived = {**model.derived, **derived}
    model.dimensions = {**model.dimensions, **{k: v for k, v in dims.items() if k in derived}}


# -- workspace in closed form (section 5) ----------------------------------------------------------


def _radius2(a, psi):
    """|AB|² = 2a²(1 - cos ψ) (eq 17)."""
    return 2 * a**2 * (1 - np.cos(psi))


def paper_membership(model: Model, points) -> tuple[np.ndarray, dict[str, np.ndarray]]:
    """The paper's reachable workspace (section 5) as a membership test.

    points: (N, 3) end-effector positions.  Returns (inside, margins), every
    margin >= 0 inside: ``outer`` and ``inner`` (eq 23-24), ``phi`` (the
    planes of eq 18), ``singular`` (outside both ellipsoids of eq 29, in units
    of their normalised radius), ``px`` (px >= 0).  The magnification factors
    are the model's (AD); missing limits are the rigid-body ones (section 5.1).

    Equivalence with the loop model: with AB = (dx, -dy, -dz), θ1,2 = m ± h,
    m = atan2(-dy, sqrt(dx² + dz²)), h = (π - ψ)/2, the condition cos θ_i > 0
    is |m| < ψ/2, i.e. |dy| < 2a sin²(ψ/2) = |AB|²/(2a), which is exactly
    "outside both spheres dx² + (dy ± a)² + dz² = a²", eq 29 in actuator space.
    """
    P = np.atleast_2d(np.asarray(points, dtype=float))
    a = model.parameters["a"]
    d = model.derived
    Mx, My, Mz = d["Mx"], d["My"], d["Mz"]
    psi_min = d["psi_min"] if d["psi_min"] is not None else 0.0
    psi_max = d["psi_max"] if d["psi_max"] is not None else math.pi
    px, py, pz = P[:, 0], P[:, 1], P[:, 2]
    s = (px / Mx) ** 2 + (py / My) ** 2 + (pz / Mz) ** 2  # eq 23-24, left side
    margins = {
        "outer": _radius2(a, psi_max) - s,  # eq 23
        "inner": s - _radius2(a, psi_min),  # eq 24
        "px": px,
    }
    if d["phi_max"] is not None:  # eq 18: |tan φ| = |Mx pz / (Mz px)| <= tan φ_max
        margins["phi"] = math.tan(d["phi_max"]) * px - np.abs(Mx * pz / Mz)
    sing = [(px / (a * Mx)) ** 2 + ((py + sgn * a * My) / (a * My)) ** 2 + (pz / (a * Mz)) ** 2 - 1 for sgn in (1, -1)]
    margins["singular"] = np.minimum(*sing)  # eq 29
    inside = np.all(np.vstack([m >= 0 for m in margins.values()]), axis=0)
    return inside, margins


def actuator_ranges(model: Model) -> dict[str, float]:
    """Actuator ranges of eq 20-22 (from psi_max and phi_max)."""
    a = model.parameters["a"]
    psi_max = model.derived["psi_max"] if model.derived["psi_max"] is not None else math.pi
    r = math.sqrt(_radius2(a, psi_max))
    phi_max = model.derived["phi_max"]
    dz = r if phi_max is None else math.sqrt(r**2 / (1 + 1 / math.tan(phi_max) ** 2))
    return {"dx_max": r, "dx_min": 0.0, "dy_max": r, "dy_min": -r, "dz_max": dz, "dz_min": -dz}


# -- the paper's cuboid (eq 32-34) ---------------------------------------------------------------

#: readings of eq 34c (see the module docstring)
READINGS = ("near_face", "printed")


def inner_extent(a, Mx, psi_min):
    """k = max(a Mx, a sqrt(2 Mx² (1 - cos ψ_min))): the largest px semi-axis of the
    inner ellipsoids, eq 24 and 29 (text after eq 32).  Floats or CasADi."""
    if isinstance(a, (ca.SX, ca.MX)) or isinstance(psi_min, (ca.SX, ca.MX)):
        return ca.fmax(a * Mx, a * Mx * ca.sqrt(2 * (1 - ca.cos(psi_min))))
    return max(a * Mx, a * Mx * math.sqrt(2 * (1 - math.cos(psi_min))))


def cuboid_constraints(a, Mx, My, Mz, psi_max, phi_max, k, x_hat, y_hat, z_hat, reading: str):
    """Constraints g >= 0 of the paper's cuboid [k, x̂] × [-ŷ, ŷ] × [-ẑ, ẑ]:
    eq 33a (corner in the outer ellipsoid; 33b follows from it as x̂ >= k),
    34a, 34c (both readings, see the module docstring) and x̂ >= k.
    Floats or CasADi symbols; every entry is a length (eq 33a as a distance
    in actuator space)."""
    R2 = 2 * a**2 * (1 - ca.cos(psi_max))  # eq 23, right side
    R = R2**0.5
    corner = (x_hat / Mx) ** 2 + (y_hat / My) ** 2 + (z_hat / Mz) ** 2
    face = k if reading == "near_face" else x_hat
    return [
        (R2 - corner) / (2 * R),  # eq 33a
        x_hat - k,  # eq 34a, lower
        Mx * R - x_hat,  # eq 34a, upper
        My * R - y_hat,  # eq 34b
        Mz * R - z_hat,  # eq 34c, second term
        Mz * face * ca.tan(phi_max) / Mx - z_hat,  # eq 34c, first term (reading)
    ]


class _PaperCuboidNLP:
    """Eq 32-34 by IPOPT (built once per reading): maximise v = 4 (x̂ - k) ŷ ẑ (eq 32)
    as -log(x̂ - k) - log ŷ - log ẑ (same maximiser; the problem is then convex:
    a convex objective over an ellipsoid cut by half-spaces, so one start suffices)."""

    def __init__(self, reading: str, with_phi: bool, config: SolverConfig):
        v = ca.SX.sym("v", 3)  # (x̂ - k, ŷ, ẑ) / L
        P = ca.SX.sym("P", 7)  # a, Mx, My, Mz, psi_max, phi_max, k
        a, Mx, My, Mz, psi_max, phi_max, k = (P[i] for i in range(7))
        L = a * Mx
        x_hat, y_hat, z_hat = k + L * v[0], L * v[1], L * v[2]
        g = cuboid_constraints(a, Mx, My, Mz, psi_max, phi_max, k, x_hat, y_hat, z_hat, reading)
        if not with_phi:
            g = g[:-1]
        nlp = {"x": v, "p": P, "f": -ca.sum1(ca.log(v)), "g": ca.vertcat(*g[:1], *g[2:]) / L}
        opts = {**config.casadi_options(), "ipopt.tol": 1e-12, "ipopt.bound_relax_factor": 0.0, **dict(config.options)}
        self.solver = ca.nlpsol(f"pantograph_paper_cuboid_{reading}", "ipopt", nlp, opts)


def paper_cuboid(model: Model, reading: str = "near_face", solver: SolverConfig | None = None) -> dict:
    """The paper's maximal cuboid, eq 32-34: [k, x̂] × [-ŷ, ŷ] × [-ẑ, ẑ].

    reading: "near_face" bounds ẑ by the φ planes at the cuboid's near face px = k,
    "printed" at its far face x̂, as eq 34c is printed (without its stray
    factor a, which would make the bound a·length).  Returns ``status``
    ("solved", "infeasible" or "not_converged"), ``message`` and, when solved,
    x_hat, y_hat, z_hat, k, volume (SI).
    """
    if reading not in READINGS:
        raise InputError(f"expected one of {', '.join(READINGS)}, got {reading!r}", path=("inputs", "paper_reading"))
    config = solver or SolverConfig()
    a = model.parameters["a"]
    d = model.derived
    Mx, My, Mz = d["Mx"], d["My"], d["Mz"]
    psi_min = d["psi_min"] if d["psi_min"] is not None else 0.0
    psi_max = d["psi_max"] if d["psi_max"] is not None else math.pi
    with_phi = d["phi_max"] is not None
    k = inner_extent(a, Mx, psi_min)
    room = Mx * math.sqrt(_radius2(a, psi_max)) - k  # eq 34a: x̂ can exceed k at all
    if not room > 0:
        return {"status": "infeasible", "message": f"eq 34a: k = {k:.6g} m is not below the outer ellipsoid"}
    built = solvers_of(model.closure).get(
        f"paper_cuboid:{reading}:{with_phi}", config, lambda: _PaperCuboidNLP(reading, with_phi, config)
    )
    L = a * Mx
    P = [a, Mx, My, Mz, psi_max, d["phi_max"] if with_phi else 0.0, k]
    v0 = [0.5 * room / L, 1e-4 * room / L, 1e-6 * room / L]
    try:
        out = built.solver(x0=v0, p=P, lbx=1e-14, ubx=np.inf, lbg=0, ubg=np.inf)
    except RuntimeError as exc:
        return {"status": "not_converged", "message": f"IPOPT: {exc}".splitlines()[0]}
    stats = built.solver.stats()
    if not stats.get("success", False):
        status = "infeasible" if "Infeasible" in str(stats.get("return_status")) else "not_converged"
        return {"status": status, "message": f"IPOPT: {stats.get('return_status')}"}
    v = np.asarray(out["x"]).ravel()
    x_hat, y_hat, z_hat = k + L * v[0], L * v[1], L * v[2]
    return {
        "status": "solved",
        "message": "",
        "x_hat": x_hat,
        "y_hat": y_hat,
        "z_hat": z_hat,
        "k": k,
        "volume": 4 * (x_hat - k) * y_hat * z_hat,  # eq 32
    }


# -- hooks of the inscribed_cuboid problem kind --------------------------------------------------

CUBOID_OPTIONS = (
    Option(
        "paper_reading",
        "choice",
        "reading of eq 34c for the paper's formulation reported beside the general one: ẑ bounded by the "
        "phi planes at the near face px = k (near_face) or at x_hat as printed (printed)",
        default="near_face",
        choices=READINGS,
    ),
)


#: the values the pantograph adds to ``inscribed_cuboid`` (`CUBOID`): the cuboid under
#: the paper's names, the parameters and derived quantities it depends on, and the paper's own
#: formulation (eq 32-34) solved, checked and certified beside the general one
CUBOID_DIMENSIONS: Mapping[str, str] = MappingProxyType(
    {
        **dict.fromkeys(("x_hat", "y_hat", "z_hat", "x_near", "a", "b"), "length"),
        **dict.fromkeys(("Mx", "My", "Mz", "omega"), "dimensionless"),
        **dict.fromkeys(("psi_min", "psi_max", "phi_max", "delta_max"), "angle"),
        **dict.fromkeys(("l", "t", "r", "paper_x_hat", "paper_y_hat", "paper_z_hat", "paper_k"), "length"),
        "paper_volume": "volume",
        "paper_status": "text",
        "paper_check_outside": "dimensionless",
        "paper_check_margin": "si",
        **dict.fromkeys(
            (
                "paper_check_binding",
                "paper_certified",
                "paper_certificate_quantity",
                "paper_certificate_failing",
                "paper_certificate",
            ),
            "text",
        ),
    }
)
CUBOID_OUTPUTS = tuple(outputs_of(CUBOID_DIMENSIONS, named=False))

#: sub-box budget of the certificate of the paper's cuboid (the near-face reading touches the
#: inner ellipsoid, eq 24, at the centre of its near face: not provable, so the budget ends it)
PAPER_CERTIFY_BOXES = 5_000


def cuboid_values(model: Model, lower, upper, inputs: dict, solver: SolverConfig) -> dict:
    """The cuboid under the paper's names, and the paper's own formulation (eq 32-34)
    solved and checked against the membership test beside it."""
    d = model.derived
    values = {
        "x_hat": None,
        "y_hat": None,
        "z_hat": None,
        "x_near": None,
        "a": model.parameters["a"],
        "b": model.parameters["b"],
        "Mx": d["Mx"],
        "My": d["My"],
        "Mz": d["Mz"],
        "omega": d["omega"],
        "psi_min": d["psi_min"],
        "psi_max": d["psi_max"],
        "phi_max": d["phi_max"],
    }
    values.update({k: d[k] for k in ("delta_max", "l", "t", "r") if k in d})
    if lower is not None:
        values.update(
            x_hat=float(upper[0]),
            y_hat=float(upper[1] - lower[1]) / 2,
            z_hat=float(upper[2] - lower[2]) / 2,
            x_near=float(lower[0]),
        )
    paper = paper_cuboid(model, inputs.get("paper_reading", "near_face"), solver)
    for name in ("x_hat", "y_hat", "z_hat", "k", "volume"):
        values[f"paper_{name}"] = paper.get(name)
    values["paper_status"] = paper["status"]
    values["paper_check_outside"] = None
    if paper["status"] == "solved":
        box_lo = [paper["k"], -paper["y_hat"], -paper["z_hat"]]
        box_hi = [paper["x_hat"], paper["y_hat"], paper["z_hat"]]
        check = check_box(model, box_lo, box_hi, inputs.get("check_per_edge", 17), solver)[0]
        values["paper_check_outside"] = check.outside
        values["paper_check_margin"] = check.margin
        values["paper_check_binding"] = check.binding
        if inputs.get("certify", True):
            cert = certify_box(model, box_lo, box_hi, max_boxes=PAPER_CERTIFY_BOXES)
            values["paper_certified"] = cert.certified
            values["paper_certificate_quantity"] = cert.failing_quantity or None
            values["paper_certificate_failing"] = cert.region(model.closure.task) or None
            values["paper_certificate"] = cert.message
    return values


def paper_box(values) -> tuple[list, list, str] | None:
    """The box of the paper's formulation (eq 32-34) in a cuboid result:
    k <= px <= x_hat, |py| <= y_hat, |pz| <= z_hat; None if it did not solve."""
    names = ("paper_k", "paper_x_hat", "paper_y_hat", "paper_z_hat")
    if values.get("paper_status") != "solved" or not all(isinstance(values.get(n), (int, float)) for n in names):
        return None
    k, xh, yh, zh = (float(values[n]) for n in names)
    outside = values.get("paper_check_outside")
    label = "paper's eq 32-34 box"
    if isinstance(outside, int) and outside > 0:
        label += f", {outside} of {values.get('check_points', '?')} check points outside"
    return [k, -yh, -zh], [xh, yh, zh], label
