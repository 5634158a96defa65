"""Lagrange dynamics of a mechanism about its home configuration.

A mechanism that has a dynamic model registers a [`DynamicsModel`][cpm_nlp.analysis.dynamics.DynamicsModel] among its
parts (the part ``dynamics``, read by the ``dynamics`` kind):

* ``lagrangian()`` -- ``ca.Function("lagrangian", [q, qd, p, w], [T, U, ...])``:
  kinetic energy T(q, qd) and potential energy U(q) (elastic and gravity),
  symbolic in the kinematic parameters p and the dynamic parameters w,
* ``parameters`` -- the names of w: ``E`` (the hinge material's
  Young's modulus), ``g``, the masses of ``masses``, or parameter names of
  the mechanism (hinge and link dimensions),
* ``masses`` -- ``(name, description)`` of every rigid body's mass,
* optionally ``values(model, w, M, K, G)`` and ``dimensions`` -- the paper's
  own named quantities.

Lagrange's equation d/dt dL/dqd - dL/dq = F with L = T - U (prc3-li-2018.md
eq 36-37), linearized at q = q_home, qd = 0, gives M qdd + K q + G = F (eq 38)
with M = d2T/dqd2, K = d2U/dq2, G = dU/dq, all by algorithmic
differentiation; the natural frequencies solve |K - lambda M| = 0,
f = sqrt(lambda) / (2 pi) (eq 39-40).
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any, ClassVar

import casadi as ca
import numpy as np
import scipy.linalg

from ..core.errors import InputError
from ..core.mechanism import MechanismDeclarationError, Part
from ..core.options import Option, validate_mapping
from ..core.units import parse_quantity


@dataclass(frozen=True, kw_only=True)
class DynamicsModel(Part):
    """A Lagrange model of the mechanism (the part ``dynamics``), used by the ``dynamics`` kind.

    Attributes
    ----------
    masses
        ``(name, description)`` of each mass input (kg, or a block of the hinge material given
        by its dimensions).
    parameters
        names, in order, of the vector w the energies take: ``E``, ``g``, the masses and any
        mechanism parameters by name.
    lagrangian
        ``() -> ca.Function("...", [q, qd, p, w], [T, U, ...])``: the kinetic and potential
        energies in the actuator coordinates q (nq).
    values
        optional ``(model, w, M, K, G) -> dict`` of named quantities of the paper, with their
        dimensions in ``dimensions``.
    """

    capability: ClassVar[str] = "dynamics"

    masses: tuple[tuple[str, str], ...]
    parameters: tuple[str, ...]
    lagrangian: Callable[[], Any]
    values: Callable[..., dict] | None = None
    dimensions: Mapping[str, str] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if not callable(self.lagrangian) or not (self.values is None or callable(self.values)):
            raise MechanismDeclarationError("dynamics: lagrangian must be callable, and values callable or None")
        if not all(isinstance(n, str) for n in self.parameters):
            raise MechanismDeclarationError(f"dynamics: parameters must be names, got {self.parameters!r:.60}")


#: a mass given as a block: density (of the material) x length x width x height
BLOCK = (
    Option("length", "length", "block length", lower=0.0, strict=True),
    Option("width", "length", "block width", lower=0.0, strict=True),
    Option("height", "length", "block height", lower=0.0, strict=True),
)


def parse_mass(raw: Any, density: float | None, material: str, path: tuple) -> float:
    """A mass: a quantity ("12 g") or a rectangular block
    ``{length, width, height}`` of the material (its density times its volume)."""
    if isinstance(raw, Mapping):
        dims = validate_mapping(raw, BLOCK, path, what="block dimension")
        if density is None:
            raise InputError(
                f"a block mass needs the density of the material, and material '{material}' gives none; "
                "give the mass ('12 g') or the density (material: {E: ..., density: ...})",
                path=path,
            )
        return density * dims["length"] * dims["width"] * dims["height"]
    mass = parse_quantity(raw, "mass", path)
    if not mass > 0:
        raise InputError(
            f"expected a positive mass such as '12 g' or a block {{length, width, height}}, got {raw!r}", path=path
        )
    return mass


#: a block's inertia about an axis through its centre: the block's own axes are x
#: along its length, y along its width, z along its height
INERTIA_BLOCK = (
    *BLOCK,
    Option("about", "choice", "the axis the coordinate turns the block about", choices=("x", "y", "z")),
)


def parse_inertia(raw: Any, density: float | None, material: str, path: tuple) -> float:
    """An inertia: a quantity ("2e-4 kg*m^2") or a rectangular block ``{length, width,
    height, about}`` of the material turning about its x (length), y (width) or z
    (height) axis through its centre: m (b² + c²)/12 of the other two sides."""
    if isinstance(raw, Mapping):
        dims = validate_mapping(raw, INERTIA_BLOCK, path, what="block key")
        mass = parse_mass({k: raw[k] for k in ("length", "width", "height")}, density, material, path)
        sides = {"x": ("width", "height"), "y": ("length", "height"), "z": ("length", "width")}[dims["about"]]
        return mass * (dims[sides[0]] ** 2 + dims[sides[1]] ** 2) / 12.0
    inertia = parse_quantity(raw, "inertia", path)
    if not inertia > 0:
        raise InputError(
            f"expected a positive inertia such as '2e-4 kg*m^2' or a block {{length, width, height, about}}, "
            f"got {raw!r}",
            path=path,
        )
    return inertia


@functools.lru_cache(maxsize=8)
def linearized(lagrangian: ca.Function) -> ca.Function:
    """``("lagrange_matrices", [q0, p, w], [M, K, G])`` from a Lagrangian
    Function (built once per mechanism type and reused)."""
    nq = lagrangian.size1_in(0)
    q, qd = ca.SX.sym("q", nq), ca.SX.sym("qd", nq)
    p, w = ca.SX.sym("p", lagrangian.size1_in(2)), ca.SX.sym("w", lagrangian.size1_in(3))
    out = lagrangian(q=q, qd=qd, p=p, w=w)
    T, U = out["T"], out["U"]
    M = ca.substitute(ca.hessian(T, qd)[0], qd, ca.SX.zeros(nq))
    K = ca.hessian(U, q)[0]
    G = ca.gradient(U, q)
    return ca.Function("lagrange_matrices", [q, p, w], [M, K, G], ["q0", "p", "w"], ["M", "K", "G"])


def matrices(lagrangian: ca.Function, q0: np.ndarray, p: np.ndarray, w: np.ndarray):
    """M, K (nq x nq) and G (nq) of eq 38 at q0, as numpy arrays."""
    M, K, G = linearized(lagrangian)(q0, p, w)
    return np.asarray(M), np.asarray(K), np.asarray(G).ravel()


def natural_frequencies(M: np.ndarray, K: np.ndarray) -> np.ndarray:
    """f_i = sqrt(lambda_i) / (2 pi) with |K - lambda M| = 0 (eq 40), ascending.
    M must be symmetric positive definite (it is for positive masses)."""
    lam = scipy.linalg.eigh(K, M, eigvals_only=True)
    return np.sqrt(np.clip(lam, 0.0, None)) / (2.0 * math.pi)
