"""Synthesis of the 3D compliant pantograph (pantograph-3d-elgammal-2016.md,
section 6, eq 35-37), the formulation behind ``problem: synthesis`` for
``mechanism.type: pantograph``.

Design variables a, b, l, t (links and cantilever-notch hinges, all hinges
alike) and the cuboid x̂, ŷ, ẑ; minimise (eq 35)

    f = w1 a/a_nom + w2 b/b_nom + w3 n l/l_nom + w4 n t/t_nom

subject to the cuboid constraints (33)-(34) (pantograph.cuboid_constraints,
either reading of eq 34c), the hinge limits of eq 30-31 (δ = 0.148 l σ_all /
(E t), ψ = π/2 ∓ δ, φ_max = δ: the paper's "φ_max = ψ_max - π" is a typo
for ψ_max - π/2), the required cuboid (36) and, optionally, the actuator
strokes (37).  Mx, My, Mz are the AD Jacobian of the loops at home, as
symbolic functions of a and b.

Readings chosen here (documented, not tuned):

* **k** (the cuboid's near face) is a variable with k >= a Mx and
  k >= a Mx sqrt(2(1 - cos ψ_min)) instead of k = max(...): any such k gives
  a box [k, x̂] × [-ŷ, ŷ] × [-ẑ, ẑ] inside the workspace, and the smooth form
  suits IPOPT; at an optimum k sits at the max unless slack is free.
* **Eq 36** (sorted dimensions of the cuboid dominate the sorted d_i) holds
  exactly when some assignment of d1, d2, d3 to the box's dimensions
  (x̂ - k, 2ŷ, 2ẑ) is dominated componentwise, so every distinct assignment
  is solved as its own smooth NLP and the best kept.
* **Eq 37** is printed for a cube and two directions; with the assignment
  above it reads M_i δ_i >= d_assigned(i) for each direction i given.
* **Bounds**: the paper gives none; the problem file must (a_bounds ...).
* **Infeasible** requirements are recognised first: the largest multiple s
  of the required cuboid the bounds allow is found by the same NLP
  (maximise s); s < 1 gives status ``infeasible``, with s in the message.
"""

from __future__ import annotations

import itertools
import math
import time
from collections.abc import Mapping
from typing import Any

import casadi as ca
import numpy as np

from ...analysis import flexure, hinge_types
from ...analysis.workspace import CHECK_OPTION, check_box
from ...core.errors import InputError
from ...core.model import Model
from ...core.multistart import AGREEMENT, best_and_agreement, start_options, uniform_starts
from ...core.options import Option
from ...core.outputs import Output, declared_result, outputs_of
from ...core.result import Result, SolverInfo, Status
from ...core.schema import Record
from ...core.solver import SolverConfig, solvers_of
from ...kinds.synthesis import SynthesisFormulation
from . import analysis as P

DESIGN = ("a", "b", "l", "t")
SYNTH_IPOPT = {"ipopt.tol": 1e-10, "ipopt.max_iter": 1000, "ipopt.bound_relax_factor": 0.0}
#: the constraints (scaled by the largest required dimension) are kept this far inside their bounds
#: so that the membership check of the optimum (tolerance 1e-9 in SI) passes
SYNTH_MARGIN = 1e-9

REFERENCE_OPTIONS = tuple(
    Option(n, "length", f"{n} of the design to evaluate", lower=0.0, strict=n in DESIGN)
    for n in ("a", "b", "l", "t", "x_hat", "y_hat", "z_hat")
)


class _SynthesisNLP:
    """Eq 35-37 for one reading of eq 34c, with or without strokes, in one of two
    phases: "design" (minimise f) or "scale" (maximise the multiple s of the
    required cuboid).  Built once per mechanism type and configuration."""

    # parameter layout
    NP = 19  # E, sigma, w1..w4, a_nom, b_nom, l_nom, t_nom, n, d_x, d_y, d_z, δx, δy, δz, d_ref, k_ref

    def __init__(self, closure, reading: str, with_stroke: bool, phase: str, config: SolverConfig):
        nv = 9 if phase == "scale" else 8
        v = ca.SX.sym("v", nv)
        par = ca.SX.sym("P", self.NP)
        E, sigma = par[0], par[1]
        w = par[2:6]
        noms = par[6:10]
        n = par[10]
        d = par[11:14]
        stroke = par[14:17]
        d_ref, k_ref = par[17], par[18]
        a, b, l, t = (noms[i] * v[i] for i in range(4))
        k = k_ref * v[4]
        e, y_hat, z_hat = d_ref * v[5], d_ref * v[6], d_ref * v[7]
        s = v[8] if phase == "scale" else 1.0
        delta = flexure.cantilever_notch_rotation(E, l, t, sigma)  # eq 30
        psi_min, psi_max, phi_max = math.pi / 2 - delta, math.pi / 2 + delta, delta  # eq 31
        Mx, My, Mz = P.magnification_symbolic(closure, a, b)
        x_hat = k + e
        g = [
            k - a * Mx,  # k >= the singularity ellipsoid's semi-axis (eq 29)
            k - a * Mx * ca.sqrt(2 * (1 - ca.cos(psi_min))),  # k >= the inner ellipsoid's (eq 24)
            math.pi / 2 - delta,  # psi_min >= 0
        ]
        g += P.cuboid_constraints(a, Mx, My, Mz, psi_max, phi_max, k, x_hat, y_hat, z_hat, reading)  # eq 33-34
        g += [e - s * d[0], 2 * y_hat - s * d[1], 2 * z_hat - s * d[2]]  # eq 36, one assignment
        if with_stroke:
            g += [Mx * stroke[0] - s * d[0], My * stroke[1] - s * d[1], Mz * stroke[2] - s * d[2]]  # eq 37
        scale = ca.vertcat(*([d_ref] * len(g)))
        scale[2] = 1.0
        f_design = w[0] * a / noms[0] + w[1] * b / noms[1] + w[2] * n * l / noms[2] + w[3] * n * t / noms[3]  # eq 35
        f = -s if phase == "scale" else f_design
        nlp = {"x": v, "p": par, "f": f, "g": ca.vertcat(*g) / scale}
        opts = {**config.casadi_options(), **SYNTH_IPOPT, **dict(config.options)}
        self.solver = ca.nlpsol(f"pantograph_synthesis_{phase}_{reading}", "ipopt", nlp, opts)
        self.outputs = ca.Function(
            "pantograph_design",
            [v, par],
            [ca.vertcat(a, b, l, t, x_hat, y_hat, z_hat, k, delta, Mx, My, Mz, f_design)],
            ["v", "p"],
            ["design"],
        )

    def solve(self, v0, par, lbx, ubx):
        try:
            out = self.solver(x0=v0, p=par, lbx=lbx, ubx=ubx, lbg=SYNTH_MARGIN, ubg=np.inf)
        except RuntimeError as exc:
            return None, f"solver error: {exc}".splitlines()[0], 0
        stats = self.solver.stats()
        z = np.asarray(out["x"]).ravel()
        ok = bool(stats.get("success", False)) and bool(np.all(np.isfinite(z)))
        return (z if ok else None), str(stats.get("return_status", "")), int(stats.get("iter_count", 0))


DESIGN_NAMES = ("a", "b", "l", "t", "x_hat", "y_hat", "z_hat", "k", "delta_max", "Mx", "My", "Mz", "objective")
OUTPUT_DIMS = {
    **{n: "length" for n in ("a", "b", "l", "t", "x_hat", "y_hat", "z_hat", "k", "dim_x", "dim_y", "dim_z")},
    **{n: "length" for n in ("stroke_x", "stroke_y", "stroke_z")},
    **{n: "angle" for n in ("delta_max", "psi_min", "psi_max", "phi_max")},
    **{n: "dimensionless" for n in ("Mx", "My", "Mz", "objective", "starts", "starts_converged", "starts_agreed")},
    "volume": "volume",
    "assignment": "text",
    "check_points": "dimensionless",
    "check_outside": "dimensionless",
    "check_margin": "si",
    "check_binding": "text",
    "reference_objective": "dimensionless",
    "reference_feasible": "text",
    "reference_violation": "length",
    "reference_violated": "text",
    "reference_dim_x": "length",
    "reference_dim_y": "length",
    "reference_dim_z": "length",
    "reference_k": "length",
    "reference_delta_max": "angle",
}


class PantographSynthesis(SynthesisFormulation):
    description = "pantograph synthesis, eq 35-37: smallest links and hinges for a required cuboid"

    def input_options(self, model: Model) -> list[Option]:
        mm = 1e-3
        return (
            [
                Option(
                    "cuboid",
                    "length",
                    "required cuboid d1, d2, d3 (eq 36)",
                    shape="list",
                    max_len=3,
                    lower=0.0,
                    strict=True,
                ),
                flexure.material_node("material", f"hinge material, one of: {', '.join(flexure.MATERIALS)}"),
                *(o for o in hinge_types.HINGE_LIMIT_OPTIONS if o.name in ("E", "sigma_all")),
                Option(
                    "weights",
                    "dimensionless",
                    "w1 .. w4 of eq 35 (summing to 1)",
                    default=[0.25] * 4,
                    shape="list",
                    max_len=4,
                    lower=0.0,
                ),
                Option("a_nom", "length", "nominal a (eq 35)", default=15 * mm, lower=0.0, strict=True),
                Option("b_nom", "length", "nominal b (eq 35)", default=30 * mm, lower=0.0, strict=True),
                Option("l_nom", "length", "nominal hinge length l (eq 35)", default=0.2 * mm, lower=0.0, strict=True),
                Option(
                    "t_nom", "length", "nominal hinge thickness t (eq 35)", default=0.1 * mm, lower=0.0, strict=True
                ),
                Option("hinges", "int", "n, the number of flexure hinges (eq 35)", default=30, lower=1, upper=10_000),
                Option("a_bounds", "length", "[low, high] of a", shape="range"),
                Option("b_bounds", "length", "[low, high] of b", shape="range"),
                Option("l_bounds", "length", "[low, high] of the hinge length l", shape="range"),
                Option("t_bounds", "length", "[low, high] of the hinge thickness t", shape="range"),
                Option(
                    "stroke",
                    "length",
                    "actuator strokes delta_x, delta_y, delta_z (eq 37; optional)",
                    default=None,
                    shape="list",
                    max_len=3,
                    lower=0.0,
                    strict=True,
                ),
                Option(
                    "paper_reading",
                    "choice",
                    "reading of eq 34c (see pantograph.py)",
                    default="near_face",
                    choices=P.READINGS,
                ),
            ]
            + start_options()
            + [
                CHECK_OPTION,
                Record(
                    "reference",
                    "a design to evaluate beside the optimum",
                    REFERENCE_OPTIONS,
                    default=None,
                    what="design value",
                ),
            ]
        )

    def check_inputs(self, inputs: dict[str, Any], model: Model, path: tuple) -> None:
        for name, n in (("cuboid", 3), ("weights", 4), ("stroke", 3)):
            if inputs.get(name) is not None and len(inputs[name]) != n:
                raise InputError(f"expected {n} values, got {len(inputs[name])}", path=path + (name,))
        total = sum(inputs["weights"])
        if abs(total - 1.0) > 1e-9:
            raise InputError(
                f"expected weights summing to 1 (eq 35), got a sum of {total:.6g}", path=path + ("weights",)
            )
        if model.limits:
            raise InputError(
                "the synthesis sets the joint limits from the hinge of each design (eq 31); remove mechanism.limits",
                path=("mechanism", "limits"),
            )
        _material(inputs, path)

    def outputs(self, model: Model) -> list[Output]:
        return outputs_of(OUTPUT_DIMS, named=False)

    def run(self, model: Model, inputs: Mapping[str, Any], solver: SolverConfig) -> Result:
        t0 = time.perf_counter()
        E, sigma = _material(inputs, ("inputs",))
        d = np.asarray(inputs["cuboid"], dtype=float)
        stroke = inputs.get("stroke")
        reading = inputs["paper_reading"]
        with_stroke = stroke is not None
        assignments = sorted(set(itertools.permutations(range(3))), key=lambda perm: tuple(d[list(perm)]))
        assignments = list({tuple(d[list(perm)]): perm for perm in assignments}.values())
        closure = model.closure

        def nlp(phase):
            return solvers_of(closure).get(
                f"synthesis:{phase}:{reading}:{with_stroke}",
                solver,
                lambda: _SynthesisNLP(closure, reading, with_stroke, phase, solver),
            )

        bounds = np.array([inputs[f"{n}_bounds"] for n in DESIGN])
        noms = np.array([inputs[f"{n}_nom"] for n in DESIGN])
        d_ref = float(d.max())
        k_ref = float(bounds[0, 1] + bounds[1, 1]) * math.sqrt(2)
        first = [
            model.parameters["a"],
            model.parameters["b"],
            math.sqrt(bounds[2, 0] * bounds[2, 1]),
            math.sqrt(bounds[3, 0] * bounds[3, 1]),
        ]
        starts = uniform_starts(bounds[:, 0], bounds[:, 1], inputs["starts"], inputs["seed"], first)
        iterations = 0
        runs = []  # (phase value, design vector, assignment)
        scale_best = 0.0
        for phase in ("scale", "design"):
            built = nlp(phase)
            for perm in assignments:
                par = np.r_[
                    E,
                    sigma,
                    inputs["weights"],
                    noms,
                    inputs["hinges"],
                    d[list(perm)],
                    stroke if with_stroke else np.zeros(3),
                    d_ref,
                    k_ref,
                ]
                for x in starts:
                    v0, lbx, ubx = _start(x, noms, bounds, k_ref, E, sigma, phase)
                    z, status, iters = built.solve(v0, par, lbx, ubx)
                    iterations += iters
                    if phase == "scale":
                        if z is not None:
                            scale_best = max(scale_best, float(z[8]))
                        continue
                    design = None if z is None else np.asarray(built.outputs(z, par)).ravel()
                    runs.append((design, perm, status))
            if phase == "scale" and scale_best < 1.0 - 1e-6:
                names = list(OUTPUT_DIMS)
                return self._result(
                    Status.INFEASIBLE,
                    {n: None for n in names},
                    f"the required cuboid does not fit: within the bounds at most {scale_best:.4g} times it "
                    f"is reachable (eq 33-37, {len(assignments)} assignment(s) x {len(starts)} starts)",
                    iterations,
                    t0,
                    model,
                    (E, sigma),
                )
        objectives = [None if r[0] is None else float(r[0][-1]) for r in runs]
        best, agreed = best_and_agreement(objectives)
        if best is None:
            statuses = sorted({r[2] for r in runs})
            return self._result(
                Status.NOT_CONVERGED,
                {n: None for n in OUTPUT_DIMS},
                f"no start converged ({', '.join(statuses)})",
                iterations,
                t0,
                model,
                (E, sigma),
            )
        design, perm, _ = runs[best]
        values = dict(zip(DESIGN_NAMES, (float(v) for v in design)))
        delta = values["delta_max"]
        values.update(psi_min=math.pi / 2 - delta, psi_max=math.pi / 2 + delta, phi_max=delta)
        values.update(dim_x=values["x_hat"] - values["k"], dim_y=2 * values["y_hat"], dim_z=2 * values["z_hat"])
        values["volume"] = values["dim_x"] * values["dim_y"] * values["dim_z"]
        req = d[list(perm)]
        values["assignment"] = "d = ({:.6g}, {:.6g}, {:.6g}) m along x, y, z".format(*req)
        # required actuator strokes (text after eq 36): delta_i = d_i / M_i
        values.update(stroke_x=req[0] / values["Mx"], stroke_y=req[1] / values["My"], stroke_z=req[2] / values["Mz"])
        values.update(
            starts=len(starts) * len(assignments),
            starts_converged=sum(o is not None for o in objectives),
            starts_agreed=agreed,
        )
        # the optimum's cuboid against the membership test of the loop model
        built_model = _design_model(model, values)
        lo = [values["k"], -values["y_hat"], -values["z_hat"]]
        hi = [values["x_hat"], values["y_hat"], values["z_hat"]]
        check = check_box(built_model, lo, hi, inputs["check_per_edge"])[0]
        values.update(
            check_points=check.points,
            check_outside=check.outside,
            check_margin=check.margin,
            check_binding=check.binding,
        )
        values.update(evaluate_reference(inputs, E, sigma, closure))
        msg = (
            f"best of {len(runs)} starts ({len(assignments)} assignment(s) of d x {len(starts)}; "
            f"{agreed} agree within {AGREEMENT:g}); membership check of its cuboid: "
        )
        if not check.passed:
            names = list(OUTPUT_DIMS)
            return self._result(
                Status.OUTSIDE_JOINT_LIMITS,
                {n: None for n in names},
                msg + f"{check.outside} of {check.points} points outside (worst {check.binding}, "
                f"{check.margin:.3g}); eq 34c read as '{reading}' does not keep the cuboid in the workspace",
                iterations,
                t0,
                model,
                (E, sigma),
            )
        msg += f"{check.points} points, all inside"
        return self._result(Status.SOLVED, values, msg, iterations, t0, model, (E, sigma))

    def _result(self, status, values, message, iterations, t0, model, material) -> Result:
        dims = {k: OUTPUT_DIMS.get(k, "dimensionless") for k in values}
        return declared_result(
            "synthesis",
            status,
            outputs_of(dims, named=False),
            values,
            solver=SolverInfo("ipopt", iterations, time.perf_counter() - t0),
            message=message,
            model={"type": model.name, "E": material[0], "sigma_all": material[1]},
        )


def _material(inputs: Mapping[str, Any], path: tuple) -> tuple[float, float]:
    return flexure.elastic_limits(inputs, path, "the synthesis")


def _start(x, noms, bounds, k_ref, E, sigma, phase):
    """A start for one design (a, b, l, t): the inner-ellipsoid k of that design,
    a small cuboid in front of it; scaled variables and their bounds."""
    a, b, l, t = x
    delta = flexure.cantilever_notch_rotation(E, l, t, sigma)
    Mx = 1 + b / a  # only a starting guess; the NLP uses the AD magnification
    k = P.inner_extent(a, Mx, max(math.pi / 2 - delta, 0.0))
    v0 = list(np.asarray(x) / noms) + [k / k_ref, 1e-3, 1e-3, 1e-3]
    lbx = list(bounds[:, 0] / noms) + [0.0, 0.0, 0.0, 0.0]
    ubx = list(bounds[:, 1] / noms) + [np.inf] * 4
    if phase == "scale":
        v0.append(0.0)
        lbx.append(0.0)
        ubx.append(np.inf)
    return np.array(v0), np.array(lbx), np.array(ubx)


def _design_model(model: Model, values: Mapping[str, float]) -> Model:
    """The synthesized design as a model of the same mechanism (validated like a problem file's)."""
    return model.mechanism.model(
        model.closure,
        {"a": values["a"], "b": values["b"]},
        {"psi_min": values["psi_min"], "psi_max": values["psi_max"], "phi_max": values["phi_max"]},
        ("mechanism",),
    )


def evaluate_reference(inputs: Mapping[str, Any], E: float, sigma: float, closure) -> dict[str, Any]:
    """The reference design (the paper's) under eq 30-37 as written: objective,
    the largest constraint violation (m) and which constraints it violates.
    Here k = max(...) exactly as defined after eq 32 and eq 36 in its sorted
    form (min, median, max)."""
    ref = inputs.get("reference")
    if ref is None:
        return {}
    a, b, l, t = (ref[n] for n in DESIGN)
    x_hat, y_hat, z_hat = ref["x_hat"], ref["y_hat"], ref["z_hat"]
    w, n = inputs["weights"], inputs["hinges"]
    f = (
        w[0] * a / inputs["a_nom"]
        + w[1] * b / inputs["b_nom"]
        + w[2] * n * l / inputs["l_nom"]
        + w[3] * n * t / inputs["t_nom"]
    )  # eq 35
    delta = flexure.cantilever_notch_rotation(E, l, t, sigma)  # eq 30
    psi_min, psi_max = math.pi / 2 - delta, math.pi / 2 + delta  # eq 31
    Mx, My, Mz = (float(v) for v in P.magnification_symbolic(closure, a, b))
    k = P.inner_extent(a, Mx, psi_min)
    g = P.cuboid_constraints(a, Mx, My, Mz, psi_max, delta, k, x_hat, y_hat, z_hat, inputs["paper_reading"])
    names = ["eq 33a", "eq 34a (x_hat >= k)", "eq 34a", "eq 34b", "eq 34c (2nd)", "eq 34c (1st)"]
    dims = np.array([x_hat - k, 2 * y_hat, 2 * z_hat])
    d = np.asarray(inputs["cuboid"], dtype=float)
    g += [dims.min() - d.min(), dims.max() - d.max(), float(np.median(dims) - np.median(d))]  # eq 36
    names += ["eq 36a", "eq 36b", "eq 36c"]
    if inputs.get("stroke") is not None:
        dx, dy, dz = inputs["stroke"]
        g += [Mx * dx - d[0], My * dy - d[1], Mz * dz - d[2]]  # eq 37
        names += ["eq 37 (x)", "eq 37 (y)", "eq 37 (z)"]
    for name, lo_hi, v in zip(DESIGN, (inputs[f"{n}_bounds"] for n in DESIGN), (a, b, l, t)):
        g += [v - lo_hi[0], lo_hi[1] - v]
        names += [f"{name} >= low", f"{name} <= high"]
    g = np.array([float(v) for v in g])
    violated = [nm for nm, v in zip(names, g) if v < -1e-12]
    return {
        "reference_objective": f,
        "reference_feasible": not violated,
        "reference_violation": float(max(0.0, -g.min())),
        "reference_violated": ", ".join(violated) if violated else "none",
        "reference_dim_x": float(dims[0]),
        "reference_dim_y": float(dims[1]),
        "reference_dim_z": float(dims[2]),
        "reference_k": k,
        "reference_delta_max": delta,
    }
