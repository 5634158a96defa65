"""The 3-PRC's add-on: what its mechanism file (problems/mechanisms/prc3.yaml) cannot say.

The kinematics -- loop closures, IK, passive joints, branch, drawing -- is the file.  This
add-on (named by `cpm_nlp.mechanisms.registry.ADDONS`) gives the paper's own parts:

* the parameters only the dynamics uses (Table 1: L5, L6, L8, the hinge's r, t, b, and h),
  optional, never in the closures' p;
* the hinge check of eq 28 (`check_parameters`);
* the Lagrange model of eq 28-41 (`dynamics`), on the file's closures;
* the paper's kind ``amplifier`` (eq 1-2, `kinds`).
"""

from __future__ import annotations

from ...analysis import flexure
from ...core.mechanism import Addon
from ...core.options import Option
from .dynamics import dynamics_model
from .kinds import Amplifier


def _length(name: str, description: str) -> Option:
    return Option(name, "length", description, lower=0.0, upper=1.0, strict=True, default=None)


#: Table 1's parameters the loop closures do not use (the dynamics does, eq 28-32)
PARAMETERS = (
    _length("L5", "coupler link of the first lever (Table 1; I_G3, eq 29) -- used by the dynamics"),
    _length("L6", "output link of the second lever (Table 1; I_G5, eq 29) -- used by the dynamics"),
    _length("L8", "second bending length of the R-C legs (Table 1; beta_i, I_G6, eq 31-32) -- dynamics"),
    _length("r", "notch radius of the circular flexure hinges (Table 1's R; eq 28)"),
    _length("t", "notch thickness of the circular flexure hinges (Table 1; eq 28)"),
    _length("b", "width of the circular flexure hinges (Table 1; eq 28)"),
    _length("h", "h of Table 1 (the paper does not say what it is; no equation uses it)"),
)


def check_parameters(params: dict, path: tuple) -> None:
    """The hinge must be one the circular-notch formula of eq 28 describes."""
    if params.get("t") is not None and params.get("r") is not None:
        flexure.check_circular_notch(params["t"], params["r"], path + ("t",))


ADDON = Addon(
    parameters=PARAMETERS,
    check_parameters=check_parameters,
    closure_parts=(dynamics_model,),
    kinds={"amplifier": Amplifier},
)
