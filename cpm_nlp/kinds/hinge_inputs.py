"""The declared inputs of the hinge kinds (`cpm_nlp.kinds.compliance`) and of the
workspace kinds' ``stress_limit``, by the schema of `cpm_nlp.core.schema`: the hinges
and material, the platform load, the actuator stiffness, masses and inertias, and the hinge
stress limits.  Each is parsed to what the kinds consume (an nx load vector, the model with
the stress limits ...)."""

from __future__ import annotations

from typing import Any

import numpy as np

from ..analysis import compliance as cm
from ..analysis.beam_inputs import BODIES
from ..analysis.dynamics import BLOCK, INERTIA_BLOCK
from ..analysis.flexure import material_node
from ..analysis.stress_limits import stress_angle_limits, with_limits
from ..core.errors import InputError
from ..core.model import Model
from ..core.options import Option
from ..core.schema import Either, ListOf, Quantity, Record


def hinge_options() -> list[Any]:
    """``hinges`` (over the mechanism's defaults) and ``material`` of the hinge kinds."""
    return [
        cm.hinges_node(
            "hinges over the mechanism's defaults, hinge by hinge and key by key: name -> {joints, type, k, "
            "dimensions, Kt, material}; null removes a default hinge"
        ),
        material_node("material", "the hinge material (default: the mechanism's)", None),
    ]


def bodies_option() -> Any:
    """``bodies``: flexible bodies (beams) over the mechanism's, body by body; the six-axis hinge model."""
    return BODIES


def _load_dimension(kind: str) -> str:
    return "force" if kind == "length" else "moment"


def load_option(model: Model) -> Record:
    """``load``: a force on each length and a moment on each angle of the pose, as an nx vector."""
    c = model.closure
    names = ", ".join(f"{x.name} ({_load_dimension(x.kind)})" for x in c.x)

    def vector(values: Any, _path: tuple) -> np.ndarray:
        return np.array([0.0 if not values else values[n] for n in c.x_names], dtype=float)

    return Record(
        "load",
        f"external load on the platform, conjugate to the pose coordinates: a mapping over {names}",
        tuple(
            Quantity(x.name, f"{_load_dimension(x.kind)} on {x.name}", (_load_dimension(x.kind),), 0.0, si=True)
            for x in c.x
        ),
        default=None,
        what="pose coordinate",
        convert=vector,
    )


def k_actuator_option(model: Model) -> Either:
    """``k_actuator``: 'rigid' (None), or a stiffness >= 0 per actuator (one for all, or a list)."""
    c = model.closure
    dims = [_stiffness_dimension(q.kind) for q in c.q]
    same = len(set(dims)) == 1
    one = (
        Option("k_actuator", dims[0], "one stiffness for every actuator", lower=0.0)
        if same
        else Quantity("k_actuator", "one stiffness for every actuator", kinds=tuple(dict.fromkeys(dims)))
    )
    per = ListOf(
        "k_actuator",
        "one stiffness per actuator",
        Quantity("k", "an actuator's stiffness", kinds=tuple(dict.fromkeys(dims))),
    )

    def vector(value: Any, path: tuple) -> np.ndarray | None:
        if value is None or value == "rigid":
            return None
        values = value if isinstance(value, list) else [value] * c.nq
        if len(values) != c.nq:
            raise InputError(f"expected one actuator stiffness or {c.nq}, got {len(values)}", path=path)
        out = []
        for k, (v, dim) in enumerate(zip(values, dims)):
            opt = Option("k_actuator", dim, "actuator stiffness", lower=0.0)
            out.append(opt.parse(v, path + ((k,) if isinstance(value, list) else ())))
        return np.array(out, dtype=float)

    return Either(
        "k_actuator",
        "actuator stiffness: 'rigid' (positions held), 0 N/m (the actuator forces held, the load case of a "
        "FEM with forces at the actuators), or a stiffness (one, or one per actuator)",
        (Option("k_actuator", "choice", "positions held", choices=("rigid",)), one, per),
        default="rigid",
        convert=vector,
    )


def _stiffness_dimension(kind: str) -> str:
    return "stiffness" if kind == "length" else "rotational_stiffness"


def mass_node(name: str, description: str, angle: bool = False, default: Any = None) -> Either:
    """A mass (on a length coordinate) or an inertia (``angle``: on an angle coordinate): a
    quantity, or a block of the hinge material.  The value is checked here and read by
    `parse_mass` / ``parse_inertia`` once the material is known."""
    block = (*BLOCK, INERTIA_BLOCK[-1]) if angle else BLOCK
    return Either(
        name,
        description,
        (
            Quantity(name, "an inertia" if angle else "a mass", kinds=("inertia" if angle else "mass",)),
            Record(
                "block",
                "a block of the hinge material" + (" turning about its own axis x, y or z" if angle else ""),
                block,
                what="block key" if angle else "block dimension",
                sparse=True,
            ),
        ),
        default=default,
    )


# -- stress limits for the workspace kinds ---------------------------------------------------------

_STRESS_DESCRIPTION = (
    "hinge stress limits in place of angle limits: true (the mechanism's hinges and material) or a mapping "
    "{sigma_allow, safety_factor, hinges, material}; each hinge's deflection about each axis alone at sigma_allow "
    "becomes a limit of its joint (generalizing eq 31 of Elgammal et al. 2016); parsed to the model "
    "with those limits"
)


def stress_limit_option(model: Model) -> Either:
    """``stress_limit`` of the workspace kinds (workspace, inscribed_cuboid, actuator_workspace):
    parsed to the model with the joint limits it sets (None when not given)."""
    spec = Record(
        "stress_limit",
        "the allowable stress and the hinges",
        (
            Option("sigma_allow", "stress", "allowable stress", default=None, lower=0.0, strict=True),
            Option("safety_factor", "dimensionless", "divides the allowable stress", default=1.0, lower=1.0),
            *hinge_options(),
        ),
        what="stress_limit key",
    )

    def limited(value: Any, path: tuple) -> Model | None:
        if value is None or value is False:
            return None
        vals = spec.parse({}, path) if value is True else value
        hs = cm.hinge_set(model, vals["hinges"], vals["material"], None, path)
        if not any(h.kind is not None for h in hs.hinges):
            raise InputError("a stress limit needs hinges with a flexure type and dimensions", path=path + ("hinges",))
        sigma = cm.allowable(hs, vals["sigma_allow"], vals["safety_factor"], path)
        return with_limits(model, stress_angle_limits(hs, sigma))

    return Either(
        "stress_limit",
        _STRESS_DESCRIPTION,
        (Option("stress_limit", "bool", "true: the mechanism's hinges and material"), spec),
        default=None,
        mismatch="expected stress_limit: true or a mapping {sigma_allow, safety_factor, hinges, material}",
        convert=limited,
    )
