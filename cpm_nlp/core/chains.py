"""Serial chains of a mechanism's legs, as the six-axis hinge model needs them.

A loop closure Φ(x, q; p) = 0 says where the platform can be; it does not say
where each joint sits in space.  The six-axis hinge model
(`cpm_nlp.analysis.hinge_chains`) needs exactly that: every flexure hinge
is a six-degree-of-freedom spring at its own location, so each leg is written
as a serial chain, base first, at the reference configuration (product of
exponentials: a joint's variable is its displacement from there).

A mechanism that can give its legs this way registers the part ``chains``,
[`LegChains`][cpm_nlp.core.chains.LegChains] (``(model) -> Chains``, numeric at the model's parameters);
it sits here, beside the data it gives, so that a mechanism file declares it
without loading the six-axis model (and scipy) at start-up.
Mechanisms described in files get it from their legs
(`cpm_nlp.mechanisms.described.chains`).

Sizes in model terms: a leg has joints j = 1..n_j, joint j has d_j
degrees of freedom (P, R: 1; C, U: 2; S: 3).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from types import MappingProxyType
from typing import Any, ClassVar

import numpy as np

from .joints import JOINT_TYPES
from .mechanism import MechanismDeclarationError, Part

#: degrees of freedom of each joint type the chains take: the spatial joints with
#: coordinates (the joint table's P, R, C, U, S)
JOINT_DOF = MappingProxyType({n: t.dof for n, t in JOINT_TYPES.items() if t.spatial and t.dof})


@dataclass(frozen=True)
class ChainJoint:
    """One joint of a leg at the reference configuration (base frame, SI).

    Attributes
    ----------
    type
        P, R, C, U or S.
    at
        its location (3,).
    axes
        (3, d) unit vectors, one per degree of freedom: the axis of an R or a P, a C's axis
        twice (its rotation, then its slide), a U's two axes, an S's three axes (its reported
        angles turn about them, in this order).
    motions
        "R" or "P" per degree of freedom.
    coordinates
        per degree of freedom, the name of the closure coordinate (pose, actuator or passive)
        that reports it, or "" where none does.
    actuated
        the actuator that drives it (a 1-dof P or R), with ``gain`` (displacement per actuator
        unit).
    link
        unit direction from this joint to the next one (to the platform point for the last): a
        hinge's length axis where its declaration gives none.
    """

    type: str
    at: np.ndarray
    axes: np.ndarray
    motions: tuple[str, ...]
    coordinates: tuple[str, ...]
    actuated: str | None = None
    gain: float = 1.0
    link: np.ndarray | None = None

    @property
    def dof(self) -> int:
        return len(self.motions)


@dataclass(frozen=True)
class LegChain:
    """One leg, base first: its joints and the platform point it carries (at the
    reference configuration)."""

    name: str
    joints: tuple[ChainJoint, ...]
    tip: np.ndarray


@dataclass(frozen=True)
class Chains:
    """The legs of a mechanism, and its platform frame as a function of the pose.

    Attributes
    ----------
    platform
        ``ca.Function("platform_frame", [x], [P, R])``: the platform's reference point P (3) and
        rotation R (3 x 3) at the pose x (nx), at the model's parameters.
    x_reference, q_reference
        the pose and actuators of the reference configuration, where every chain variable is
        zero.
    note
        what the chains leave out (shown with results).
    """

    legs: tuple[LegChain, ...]
    platform: Any
    x_reference: np.ndarray
    q_reference: np.ndarray
    note: str = ""


@dataclass(frozen=True)
class LegChains(Part):
    """The legs of a mechanism as serial chains of joints at the reference configuration
    (the part ``chains``), for the six-axis hinge model.

    of: ``(model) -> Chains`` (`Chains`), numeric at the model's
        parameters.
    """

    capability: ClassVar[str] = "chains"

    of: Callable[[Any], Chains]

    def __post_init__(self) -> None:
        if not callable(self.of):
            raise MechanismDeclarationError(f"chains must be callable, got {self.of!r:.60}")
