"""The registry of problem kinds: what question a problem file may ask.

Three sources, one namespace:

* the generic kinds of `cpm_nlp.kinds` (`GENERIC`), which apply to
  any mechanism that has what they need;
* the kinds each registered mechanism declares (``Mechanism.kinds``), e.g. the
  RPR's ``rpr_twists``;
* kinds that a third-party package adds without a mechanism, through the
  entry-point group ``cpm_nlp.kinds`` (``name = "package.module:KindClass"``).

A name declared twice is an error that names both sources.
"""

from __future__ import annotations

import importlib
import threading
from typing import Any

from ..core.errors import CpmError, InputError, suggest
from ..core.kind import ProblemKind
from ..mechanisms.registry import REGISTRY as MECHANISMS
from ..mechanisms.registry import PluginError, mechanism_names, mechanism_type

#: entry-point group of problem-kind plugins
ENTRY_POINT_GROUP = "cpm_nlp.kinds"

#: the generic kinds, which work on every mechanism that supports them: name ->
#: "module:class" under cpm_nlp.kinds, imported when first asked for (a solve loads
#: only its own kind's module)
GENERIC = {
    "forward_kinematics": "kinematic:ForwardKinematics",
    "inverse_kinematics": "kinematic:InverseKinematics",
    "jacobian": "kinematic:Jacobian",
    "joint_requirements": "kinematic:JointRequirements",
    "actuator_workspace": "analysis:ActuatorWorkspace",
    "dynamics": "analysis:Dynamics",
    "inscribed_cuboid": "workspace:InscribedCuboid",
    "workspace": "workspace:Workspace",
    "synthesis": "synthesis:Synthesis",
    "actuator_forces": "compliance:ActuatorForces",
    "platform_compliance": "compliance:PlatformCompliance",
    "natural_frequencies": "frequencies:NaturalFrequencies",
    "compliance_synthesis": "compliance_synthesis:ComplianceSynthesis",
}


def generic_kind(name: str) -> type[ProblemKind]:
    """The class of a generic kind (imports its module of cpm_nlp.kinds)."""
    module, _, cls = GENERIC[name].partition(":")
    return getattr(importlib.import_module(f"cpm_nlp.kinds.{module}"), cls)


class _Kinds:
    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._table: dict[str, tuple[type[ProblemKind], str]] | None = None
        self._version = -1

    def table(self) -> dict[str, tuple[type[ProblemKind], str]]:
        """Every kind, by name (rebuilt when a mechanism is registered or removed in code)."""
        with self._lock:
            if self._table is None or self._version != MECHANISMS.version:
                self._version = MECHANISMS.version
                self._table = _collect()
            return self._table


def _add(table: dict, name: str, cls: Any, origin: str) -> None:
    if not (isinstance(cls, type) and issubclass(cls, ProblemKind)):
        raise PluginError(f"problem kind {name!r} ({origin}) must be a ProblemKind subclass, got {cls!r:.60}")
    if cls.name != name:
        raise PluginError(f"problem kind {name!r} ({origin}) names itself {cls.name!r}; the two must agree")
    if name in table:
        raise PluginError(f"problem kind {name!r} is declared twice: by {table[name][1]} and by {origin}")
    table[name] = (cls, origin)


def _collect() -> dict[str, tuple[type[ProblemKind], str]]:
    table: dict[str, tuple[type[ProblemKind], str]] = {}
    for name in GENERIC:
        _add(table, name, generic_kind(name), "cpm_nlp.kinds")
    for mname in mechanism_names():
        mech = mechanism_type(mname)
        for name, cls in mech.kinds.items():
            _add(table, name, cls, f"mechanism {mname!r} ({mech.origin})")
    from importlib import metadata  # only here: a generic kind (problem_kind) never reads the entry points

    for ep in metadata.entry_points(group=ENTRY_POINT_GROUP):
        origin = f"plugin {ep.name!r} ({ep.value})"
        try:
            module, _, attr = ep.value.partition(":")
            cls = importlib.import_module(module)
            for part in attr.split("."):
                cls = getattr(cls, part)
        except Exception as exc:
            raise PluginError(f"problem kind {origin} failed to load: {type(exc).__name__}: {exc}") from exc
        _add(table, ep.name, cls, origin)
    return table


KINDS = _Kinds()


def kind_names() -> list[str]:
    """Every problem kind: generic, declared by mechanisms, and from plugins."""
    return sorted(KINDS.table())


def kind_origin(name: str) -> str:
    """Where a kind comes from: ``cpm_nlp.kinds``, a mechanism, or a plugin."""
    return KINDS.table()[name][1]


def problem_kind(name: Any, path: tuple = ("problem",)) -> ProblemKind:
    """Look up a problem kind by name (with a "did you mean" if unknown)."""
    if isinstance(name, str) and name in GENERIC:  # no need to load every mechanism
        return generic_kind(name)()
    table = KINDS.table()
    if not isinstance(name, str) or name not in table:
        raise InputError(
            f"unknown problem kind {name!r}; expected one of: {', '.join(sorted(table))}",
            path=path,
            suggestions=suggest(str(name), table),
        )
    try:
        return table[name][0]()
    except CpmError:
        raise
    except Exception as exc:
        raise PluginError(f"problem kind {name!r} ({table[name][1]}) failed to start: {exc}") from exc
