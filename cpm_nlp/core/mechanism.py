"""The declared interface between a mechanism and the rest of cpm_nlp.

A mechanism type is one [`Mechanism`][cpm_nlp.core.mechanism.Mechanism] value.  Its required fields say
what the mechanism *is*; its optional fields are what every mechanism may
have (checks, a drawing, kinds of its own, problem files); everything a
single kind needs from it is a [`Part`][cpm_nlp.core.mechanism.Part], declared by that kind (in its
own module, not here) and registered by the mechanism in ``parts``.  A kind
reads a part by its type ([`Mechanism.part`][cpm_nlp.core.mechanism.Mechanism.part]), never by probing a module
for an attribute, so core does not change when a kind needs something new.
A misspelt field or a mistyped part is an error when the mechanism is
declared ([`declare`][cpm_nlp.core.mechanism.declare]) or registered, not a silently missing feature.

Required fields
---------------
``name``, ``title``
    the type name used in problem files (``mechanism.type``) and a one-line title.
``parameters``, ``limits``
    declared `Option` s of the geometry (SI, with
    dimension, default, bounds, description) and of the joint limits.
``closure``
    ``() -> LoopClosure``: the symbolic closure Φ(x, q; p).  Built once per
    process by the registry and shared by every model of the type.  Three
    capabilities live on the closure itself, as optional arguments of
    [`LoopClosure`][cpm_nlp.core.model.LoopClosure]: the closed-form IK (``ik``), the
    passive joint angles (``passive``, ``passive_coords``) and the
    assembly-branch indicator (``branch``).
``build``
    ``(closure, parameters, limits) -> Model``: a model from validated values (SI).

Optional fields
---------------
``paper``, cross-value checks (``check_parameters``, ``check_limits``), a
drawing of the mechanism at a pose (``geometry``: base, legs, joints,
platform), ``parts``, problem ``kinds`` of its own and the ``problem_files``
that reproduce its paper's figures.

Parts (each declared with the kind that reads it)
-------------------------------------------------
``synthesis`` ([`SynthesisFormulation`][cpm_nlp.kinds.synthesis.SynthesisFormulation]), ``cuboid``
([`CuboidExtras`][cpm_nlp.kinds.workspace.CuboidExtras]), ``paper_membership``
([`PaperMembership`][cpm_nlp.kinds.workspace.PaperMembership]), ``dynamics``
([`DynamicsModel`][cpm_nlp.analysis.dynamics.DynamicsModel]), ``stiffness``
([`JointStiffness`][cpm_nlp.analysis.compliance.JointStiffness]) and ``chains``
([`LegChains`][cpm_nlp.core.chains.LegChains], in core beside the chains it gives).
"""

from __future__ import annotations

import inspect
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, replace
from types import MappingProxyType
from typing import Any, ClassVar, TypeVar

from .errors import suggest
from .joints import JOINT_LETTERS
from .options import Option, validate_mapping
from .origin import Origin, as_origin


class MechanismDeclarationError(TypeError):
    """A mechanism declaration that breaks the interface (raised at declaration
    or registration, with the mechanism's name and the field at fault)."""


#: parts a `Drawing` may join or fill, in the order they are drawn
DRAWING_PARTS = ("base", "actuator", "link", "leg", "platform")
#: joint letters a `Drawing` may mark (prismatic, revolute, cylindrical, universal, spherical):
#: the letters of the joint table
JOINT_TYPES = JOINT_LETTERS


@dataclass(frozen=True, kw_only=True)
class Drawing:
    """The mechanism drawn at one pose, for plots: named 3-D points (SI, fixed
    frame) and what joins them.

    Attributes
    ----------
    points
        name -> (x, y, z).
    segments
        ``(from, to, part)``: a straight link between two points; part is one of `DRAWING_PARTS`
        (a rail or a lever is ``actuator``).
    faces
        ``(part, (names ...))``: a filled polygon (the base, the platform).
    joints
        point name -> joint letter (`JOINT_TYPES`), marked on the drawing.
    actuated
        the points of the actuated joints (drawn in the actuators' colour, seen even where the
        actuator's stroke is too short to draw).
    note
        what the drawing leaves out or where it departs from scale (shown with it).
    """

    points: Mapping[str, Any]
    segments: tuple[tuple[str, str, str], ...] = ()
    faces: tuple[tuple[str, tuple[str, ...]], ...] = ()
    joints: Mapping[str, str] = field(default_factory=dict)
    actuated: tuple[str, ...] = ()
    note: str = ""

    def __post_init__(self) -> None:
        names = set(self.points)
        for a, b, part in self.segments:
            if a not in names or b not in names or part not in DRAWING_PARTS:
                raise ValueError(f"drawing: segment ({a!r}, {b!r}, {part!r}) names an unknown point or part")
        for part, corners in self.faces:
            if part not in DRAWING_PARTS or not set(corners) <= names or len(corners) < 3:
                raise ValueError(f"drawing: face {part!r} {corners!r} names an unknown point or part")
        for name, letter in self.joints.items():
            if name not in names or letter not in JOINT_TYPES:
                raise ValueError(f"drawing: joint {name!r}: {letter!r} names an unknown point or joint type")
        if not set(self.actuated) <= set(self.joints):
            raise ValueError(f"drawing: actuated {self.actuated!r} names a point that is not a joint")


class Part:
    """Base of a mechanism's optional parts: what one kind (or analysis) needs from a mechanism
    beyond its closure, declared where that kind lives, never here.

    A kind names the part types it reads (`ProblemKind.parts`); a mechanism registers its implementations
    (`Mechanism.parts`, at most one of each type); [`Mechanism.part`][cpm_nlp.core.mechanism.Mechanism.part] is the one
    way to
    read one.  A subclass names its ``capability`` (listed by ``cpm-nlp describe``) and checks
    its own fields when made, raising `MechanismDeclarationError`.
    """

    #: the name ``cpm-nlp describe`` lists the part under
    capability: ClassVar[str] = ""


P = TypeVar("P", bound=Part)


def known_parts() -> dict[str, type]:
    """capability -> part type, of every part type imported so far (for the messages of a
    declaration that names a part as a keyword)."""
    out: dict[str, type] = {}
    todo = list(Part.__subclasses__())
    while todo:
        cls = todo.pop()
        todo.extend(cls.__subclasses__())
        if cls.capability and "capability" in vars(cls):
            out.setdefault(cls.capability, cls)
    return out


@dataclass(frozen=True, kw_only=True)
class Mechanism:
    """A mechanism type: what every mechanism has, and its parts.

    Sizes in model terms: nx pose coordinates x, nq actuators q, np
    parameters p (see [`LoopClosure`][cpm_nlp.core.model.LoopClosure]).
    """

    #: type name in problem files (``mechanism.type``)
    name: str
    #: one-line title
    title: str
    #: geometry parameters (declared options, SI)
    parameters: tuple[Option, ...]
    #: joint limits (declared options, each a [low, high] range)
    limits: tuple[Option, ...]
    #: ``() -> LoopClosure``: the symbolic closure (with optional ik, passive, branch)
    closure: Callable[[], Any]
    #: ``(closure, parameters, limits) -> Model``
    build: Callable[[Any, dict, dict], Any]
    #: the paper the mechanism comes from: a citation, with its DOI where the paper gives one
    paper: str = ""
    #: ``(parameters, path) -> None``: rules over several parameters; raises InputError
    check_parameters: Callable[[dict, tuple], None] | None = None
    #: ``(limits, path) -> None``: rules over several limits; raises InputError
    check_limits: Callable[[dict, tuple], None] | None = None
    #: ``(model, x (nx,), q (nq,)) -> Drawing``: the mechanism at a pose (base, legs,
    #: joints, platform) for the plots, from its kinematic functions
    geometry: Callable[[Any, Any, Any], Drawing] | None = None
    #: what kinds need beyond the closure, one `Part` of each type (e.g. the extra
    #: values of the inscribed cuboid, a Lagrange model, its hinges); read by `part`
    parts: tuple[Part, ...] = ()
    #: problem kinds of its own: kind name -> ProblemKind subclass
    kinds: Mapping[str, type] = field(default_factory=dict)
    #: its shipped problem files: examples of its kinds, and (those with a ``reproduce:``
    #: section) its paper's figures; names under the shipped ``problems/`` directory, or
    #: absolute paths for a plugin's own files
    problem_files: tuple[str, ...] = ()
    #: where the declaration came from (`Origin`; a text given in
    #: code, e.g. "built-in", is made one)
    origin: Origin | str = "built-in"

    def __post_init__(self) -> None:
        origin = as_origin(self.origin, self.name)
        object.__setattr__(self, "origin", origin if origin.name else replace(origin, name=self.name))
        validate(self)

    def model(
        self, closure: Any, parameters: Mapping[str, Any] | None, limits: Mapping[str, Any] | None, path: tuple
    ) -> Any:
        """A model on ``closure`` from values given as in a problem file (numbers in SI
        or strings with units), validated against the declared options and checks; its
        ``mechanism`` is this declaration."""
        params = validate_mapping(parameters or {}, self.parameters, path + ("parameters",), what="parameter")
        lims = validate_mapping(limits or {}, self.limits, path + ("limits",), what="limit")
        if self.check_parameters is not None:
            self.check_parameters(params, path + ("parameters",))
        if self.check_limits is not None:
            self.check_limits(lims, path + ("limits",))
        model = self.build(closure, params, lims)
        model.mechanism = self
        return model

    def part(self, kind: type[P]) -> P | None:
        """The mechanism's part of type ``kind`` (a [`Part`][cpm_nlp.core.mechanism.Part] subclass), or None."""
        return next((p for p in self.parts if isinstance(p, kind)), None)

    def capabilities(self) -> list[str]:
        """Names of what this mechanism declares beyond the required parts: its checks and
        drawing, its parts (by their ``capability``), its own kinds and problem files."""
        own = [name for name in ("check_parameters", "check_limits", "geometry") if getattr(self, name) is not None]
        tail = [name for name in ("kinds", "problem_files") if getattr(self, name)]
        return own + [p.capability for p in self.parts] + tail


#: required parts of a mechanism
REQUIRED = ("name", "title", "parameters", "limits", "closure", "build")
#: optional fields of a mechanism
OPTIONAL = ("paper", "check_parameters", "check_limits", "geometry", "parts", "kinds", "problem_files", "origin")
#: every field a declaration may name
PARTS = REQUIRED + OPTIONAL


def _options(value: Any) -> str | None:
    if not isinstance(value, tuple) or not all(isinstance(o, Option) for o in value):
        return "a tuple of Option"
    names = [o.name for o in value]
    return None if len(set(names)) == len(names) else "a tuple of Options with distinct names"


def _callable(value: Any) -> str | None:
    return None if callable(value) else "callable"


def _optional_callable(value: Any) -> str | None:
    return None if value is None or callable(value) else "callable or None"


def _parts(value: Any) -> str | None:
    expected = "a tuple of mechanism parts (instances of cpm_nlp.core.mechanism.Part subclasses)"
    if not isinstance(value, tuple) or not all(isinstance(p, Part) and p.capability for p in value):
        return expected
    names = [p.capability for p in value]
    twice = sorted({n for n in names if names.count(n) > 1})
    return f"{expected}, one of each (twice: {', '.join(twice)})" if twice else None


def _kinds(value: Any) -> str | None:
    expected = "a mapping of kind name -> ProblemKind subclass"
    if not isinstance(value, Mapping):
        return expected
    for kname, cls in value.items():
        if not isinstance(kname, str) or not inspect.isclass(cls) or not hasattr(cls, "run"):
            return f"{expected} (entry {kname!r})"
        if getattr(cls, "name", kname) != kname:
            return f"keyed by each kind's own name ({cls.__name__}.name is {cls.name!r}, key {kname!r})"
    return None


def _file_names(value: Any) -> str | None:
    ok = isinstance(value, tuple) and all(isinstance(f, str) for f in value)
    return None if ok else "a tuple of file names"


#: field -> its check: None if the value is right, else what was expected
CHECKS: Mapping[str, Callable[[Any], str | None]] = MappingProxyType(
    {
        "title": lambda v: None if isinstance(v, str) else "a string",
        "parameters": _options,
        "limits": _options,
        "closure": _callable,
        "build": _callable,
        "check_parameters": _optional_callable,
        "check_limits": _optional_callable,
        "geometry": _optional_callable,
        "parts": _parts,
        "kinds": _kinds,
        "problem_files": _file_names,
    }
)


def validate(mech: Mechanism) -> None:
    """Check the types of every field of a declaration (registration calls it too); each
    part checked its own fields when it was made."""
    if not isinstance(mech.name, str) or not mech.name.isidentifier():
        raise MechanismDeclarationError(f"a mechanism name must be an identifier, got {mech.name!r} ({mech.origin})")
    for name, check in CHECKS.items():
        expected = check(getattr(mech, name))
        if expected is not None:
            value = getattr(mech, name)
            raise MechanismDeclarationError(
                f"mechanism {mech.name!r} ({mech.origin}): {name} must be {expected}, "
                f"got {type(value).__name__} {value!r:.60}"
            )


def unknown_field_hint(name: str) -> str:
    """What to say of a keyword a declaration does not take: a part's capability says where it
    goes (``parts=(...)``), else a "did you mean"."""
    parts = known_parts()
    if name in parts:
        return f"{name} is a part: give parts=({parts[name].__name__}(...),)"
    close = suggest(name, PARTS + tuple(parts))
    return f"did you mean {', '.join(repr(c) for c in close)}?" if close else ""


def declare(**fields_: Any) -> Mechanism:
    """A [`Mechanism`][cpm_nlp.core.mechanism.Mechanism] from keyword fields, with a "did you mean" for a misspelt one
    (``Mechanism(...)`` itself only says "unexpected keyword")."""
    unknown = [k for k in fields_ if k not in PARTS]
    if unknown:
        hints = [f"{k!r} ({unknown_field_hint(k)})" if unknown_field_hint(k) else repr(k) for k in unknown]
        raise MechanismDeclarationError(
            f"mechanism {fields_.get('name', '?')!r}: unknown part(s) {', '.join(hints)}; "
            f"required: {', '.join(REQUIRED)}; optional: {', '.join(OPTIONAL)}"
        )
    missing = [k for k in REQUIRED if k not in fields_]
    if missing:
        raise MechanismDeclarationError(
            f"mechanism {fields_.get('name', '?')!r}: missing required part(s) {', '.join(missing)}"
        )
    return Mechanism(**fields_)


@dataclass(frozen=True, kw_only=True)
class Addon:
    """What a mechanism file cannot say, given in Python for the mechanism of one shipped file
    (issue 21, item 5): the file is the mechanism (its closures, IK, passive joints, branch,
    drawing, paper, problem files); the add-on refers to it by the registry's table
    `cpm_nlp.mechanisms.names.ADDONS` and adds only what is not kinematics.

    The paper's own plot types are not an add-on's field: they are declared, name and one
    line each, in `cpm_nlp.mechanisms.names.ADDON_PLOTS`, so that ``cpm-nlp plot
    --help`` lists them without importing the add-on (a plot belongs to the plot layer,
    above the mechanisms).

    Attributes
    ----------
    parameters
        optional parameters the closures do not use (e.g. a dynamics model's lengths and hinge
        sizes); a value given is kept in the model's ``parameters``, never in p.
    check_parameters, check_limits
        as the [`Mechanism`][cpm_nlp.core.mechanism.Mechanism] fields of the same names.
    parts
        the paper's parts ([`Part`][cpm_nlp.core.mechanism.Part]), registered as a mechanism
        registers its own (the paper's formulations that refer to the file's mechanism).
    closure_parts
        ``(closure) -> Part`` each: a part made from the file's closure (e.g. a Lagrange model
        that uses the file's loop closures, their Jacobian, never a copy).
    kinds
        problem kinds of the paper's own: kind name -> ProblemKind subclass.
    limits
        the paper's own limit options (e.g. a hinge from which a formula sets the joint limits,
        or ranges counted from home), beside the file's limit families; one named like a family
        of the file replaces it (the paper's meaning of that name wins).
    complete
        ``(model, limits) -> None``: completes the file's model with what ``limits`` gives
        (joint limits on the file's coordinates) and the paper's derived quantities
        (``model.derived``), from the file's closure and model, never a copy of them.
    """

    parameters: tuple[Option, ...] = ()
    check_parameters: Callable[[dict, tuple], None] | None = None
    check_limits: Callable[[dict, tuple], None] | None = None
    parts: tuple[Part, ...] = ()
    closure_parts: tuple[Callable[[Any], Part], ...] = ()
    kinds: Mapping[str, type] = field(default_factory=dict)
    limits: tuple[Option, ...] = ()
    complete: Callable[[Any, dict], None] | None = None


#: the add-on's checks, taken as they are (each must not be given by the file too)
ADDON_CHECKS = ("check_parameters", "check_limits")


def with_addon(mech: Mechanism, addon: Addon) -> Mechanism:
    """The mechanism of a file with its add-on's parts (validated like any declaration).  A
    part the add-on gives that the file has too (a parameter, a kind, a check, a part of one
    type) is an error: each part is written once.  The add-on's parts come first."""
    if not isinstance(addon, Addon):
        raise MechanismDeclarationError(f"mechanism {mech.name!r}: expected an Addon, got {type(addon).__name__}")
    parts = addon.parts + tuple(make(mech.closure()) for make in addon.closure_parts)
    own = {o.name for o in mech.parameters}
    clash = sorted(own & {o.name for o in addon.parameters}) + sorted(set(mech.kinds) & set(addon.kinds))
    clash += [name for name in ADDON_CHECKS if getattr(addon, name) and getattr(mech, name)]
    clash += [p.capability for p in parts if any(p.capability == q.capability for q in mech.parts)]
    if clash:
        raise MechanismDeclarationError(
            f"mechanism {mech.name!r} ({mech.origin}): its add-on repeats what the file declares ({', '.join(clash)})"
        )
    extra = tuple(o.name for o in addon.parameters)
    dims = {o.name: o.kind for o in addon.parameters}
    own_limits = {o.name for o in addon.limits}
    file_build = mech.build

    def build(closure: Any, parameters: dict, limits: dict) -> Any:
        file_limits = {k: v for k, v in limits.items() if k not in own_limits}
        model = file_build(closure, {k: v for k, v in parameters.items() if k not in extra}, file_limits)
        given = {k: parameters[k] for k in extra if parameters.get(k) is not None}
        model.parameters = {**model.parameters, **given}
        model.dimensions = {**model.dimensions, **{k: dims[k] for k in given}}
        if addon.complete is not None:
            addon.complete(model, {k: v for k, v in limits.items() if k in own_limits})
        return model

    return replace(
        mech,
        parameters=mech.parameters + addon.parameters,
        limits=tuple(o for o in mech.limits if o.name not in own_limits) + addon.limits,
        build=build,
        **{name: getattr(addon, name) or getattr(mech, name) for name in ADDON_CHECKS},
        parts=parts + mech.parts,
        kinds={**mech.kinds, **addon.kinds},
    )
