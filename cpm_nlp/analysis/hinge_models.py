"""The hinge models of the compliance kinds, as objects: ``kinematic`` (the
pseudo-rigid-body model of :mod:`cpm_nlp.analysis.compliance`: each hinge only
about the axes the kinematics moves) and ``all`` (every flexure a six-axis spring
at its joint, :mod:`cpm_nlp.analysis.hinge_chains`; needs the mechanism's leg
chains).  A problem file names one (``inputs.hinge_axes``); the input's choices
are the keys of :data:`HINGE_MODELS`.
"""

from __future__ import annotations

import logging
from collections.abc import Mapping
from dataclasses import dataclass
from types import MappingProxyType

from ..core.errors import InputError
from ..core.model import Model
from .compliance import HingeSet
from .hinge_chains import LegChains, SixAxisModel, six_axis_model

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class HingeModel:
    """The pseudo-rigid-body hinge model (``kinematic``): no six-axis model to build."""

    name: str
    description: str

    def six_axis(self, model: Model, hs: HingeSet, path: tuple, chosen: bool) -> tuple[SixAxisModel | None, str]:  # noqa: ARG002 - one signature for every hinge model
        """The six-axis model the kind solves with (None: the pseudo-rigid-body one), and a
        note on a fallback; ``chosen``: the problem file named this model (else the default)."""
        return None, ""


@dataclass(frozen=True)
class SixAxisHinges(HingeModel):
    """Every flexure a six-axis spring at its joint (``all``), on the mechanism's leg chains."""

    def six_axis(self, model: Model, hs: HingeSet, path: tuple, chosen: bool) -> tuple[SixAxisModel | None, str]:
        if not has_chains(model):
            raise InputError(
                f"hinge_axes: all needs the legs of {model.name} as serial chains (the mechanism's chains "
                "capability; a mechanism file of spatial P, R, C, U, S legs gives them)",
                path=path,
                hint="use hinge_axes: kinematic",
            )
        if chosen:
            return six_axis_model(model, hs), ""
        try:  # the default: the six-axis model where it can place every hinge
            return six_axis_model(model, hs), ""
        except InputError as exc:
            log.info("platform_compliance: the kinematic hinge model (%s)", exc.message)
            return None, f"; hinge_axes: kinematic, as the six-axis model cannot place the hinges ({exc.message})"


#: the hinge models by the name a problem file gives (``inputs.hinge_axes``)
HINGE_MODELS: Mapping[str, HingeModel] = MappingProxyType(
    {
        "all": SixAxisHinges(
            "all",
            "every flexure a six-axis spring at its joint, the axes the kinematics does not move with the "
            "flexure library's stiffness; needs the mechanism's leg chains",
        ),
        "kinematic": HingeModel(
            "kinematic",
            "pseudo-rigid-body: each hinge only about the axes the kinematics moves; with the actuators held a "
            "mechanism of rigid links then does not deflect",
        ),
    }
)


def has_chains(model: Model) -> bool:
    """Whether the model's mechanism gives its legs as serial chains (the part ``chains``)."""
    return model.mechanism is not None and model.mechanism.part(LegChains) is not None


def default_hinge_model(model: Model) -> HingeModel:
    """``all`` where the mechanism gives its chains, else ``kinematic``."""
    return HINGE_MODELS["all"] if has_chains(model) else HINGE_MODELS["kinematic"]


def hinge_model_text() -> str:
    """The description of the ``hinge_axes`` input, from the table."""
    models = " or ".join(f"'{m.name}' ({m.description})" for m in HINGE_MODELS.values())
    return f"the hinge model: {models}; default: all where the mechanism gives its chains, else kinematic"
