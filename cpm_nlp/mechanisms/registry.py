"""Registry of mechanism types.

Each mechanism is one module of the package that provides

* ``TITLE``, ``PAPER`` -- what it is and where it comes from,
* ``PARAMETERS``, ``LIMITS`` -- declared :class:`~cpm_nlp.core.options.Option` s,
* ``closure()`` -- its symbolic :class:`~cpm_nlp.core.model.LoopClosure`,
* ``build(closure, parameters, limits)`` -- a :class:`~cpm_nlp.core.model.Model`,
* optionally ``check_parameters(params, path)`` and ``check_limits(limits,
  path)`` for rules that involve several values.

The symbolic closure is built once per process and shared by every model of
that type (it holds code, not problem data), so solvers built for one model
serve all of them.
"""

from __future__ import annotations

import importlib
import threading
from collections.abc import Mapping
from dataclasses import dataclass
from types import ModuleType
from typing import Any

from ..core.errors import InputError, suggest
from ..core.model import LoopClosure, Model
from ..core.options import Option, validate_mapping

#: mechanism type -> module implementing it
MODULES = {
    "prc3": "cpm_nlp.mechanisms.prc3.kinematics",
    "prs3": "cpm_nlp.mechanisms.prs3",
    "rpr": "cpm_nlp.mechanisms.rpr.kinematics",
    "pantograph": "cpm_nlp.mechanisms.pantograph.kinematics",
}


@dataclass(frozen=True)
class MechanismType:
    name: str
    module: ModuleType

    @property
    def title(self) -> str:
        return self.module.TITLE

    @property
    def paper(self) -> str:
        return self.module.PAPER

    @property
    def parameters(self) -> tuple[Option, ...]:
        return tuple(self.module.PARAMETERS)

    @property
    def limits(self) -> tuple[Option, ...]:
        return tuple(self.module.LIMITS)


_lock = threading.Lock()
_closures: dict[str, LoopClosure] = {}


def mechanism_type(name: Any, path: tuple = ("mechanism", "type")) -> MechanismType:
    """Look up a mechanism type by name (with a "did you mean" if unknown)."""
    if not isinstance(name, str) or name not in MODULES:
        raise InputError(
            f"unknown mechanism type {name!r}; expected one of: {', '.join(sorted(MODULES))}",
            path=path,
            suggestions=suggest(str(name), MODULES),
        )
    return MechanismType(name, importlib.import_module(MODULES[name]))


def closure_of(mtype: MechanismType) -> LoopClosure:
    """The shared symbolic closure of a mechanism type."""
    with _lock:
        c = _closures.get(mtype.name)
        if c is None:
            c = mtype.module.closure()
            _closures[mtype.name] = c
        return c


def build_model(
    type_name: str,
    parameters: Mapping[str, Any] | None = None,
    limits: Mapping[str, Any] | None = None,
    *,
    path: tuple = ("mechanism",),
) -> Model:
    """Build a model from parameter values given as quantities.

    ``parameters`` and ``limits`` take numbers (SI) or strings with units,
    exactly as in a problem file, e.g.
    ``build_model("prs3", {"b": "47.91 mm", "L": "109.215 mm"})``.
    """
    mtype = mechanism_type(type_name, path + ("type",))
    params = validate_mapping(parameters or {}, mtype.parameters, path + ("parameters",), what="parameter")
    lims = validate_mapping(limits or {}, mtype.limits, path + ("limits",), what="limit")
    check = getattr(mtype.module, "check_parameters", None)
    if check is not None:
        check(params, path + ("parameters",))
    check_limits = getattr(mtype.module, "check_limits", None)
    if check_limits is not None:
        check_limits(lims, path + ("limits",))
    return mtype.module.build(closure_of(mtype), params, lims)
