"""The declared interface between a mechanism and the rest of cpm_nlp.

A mechanism type is one :class:`Mechanism` value.  Its required parts say
what the mechanism *is*; its optional capabilities say what else it can do,
and every feature of the toolkit that needs a capability asks for it by its
field here, never by probing a module for an attribute.  A misspelt
capability is therefore an error when the mechanism is declared
(:func:`declare`) or registered, not a silently missing feature.

Required parts
--------------
``name``, ``title``
    the type name used in problem files (``mechanism.type``) and a one-line title.
``parameters``, ``limits``
    declared :class:`~cpm_nlp.core.options.Option` s of the geometry (SI, with
    dimension, default, bounds, description) and of the joint limits.
``closure``
    ``() -> LoopClosure``: the symbolic closure Φ(x, q; p).  Built once per
    process by the registry and shared by every model of the type.  Three
    capabilities live on the closure itself, as optional arguments of
    :class:`~cpm_nlp.core.model.LoopClosure`: the closed-form IK (``ik``), the
    passive joint angles (``passive``, ``passive_coords``) and the
    assembly-branch indicator (``branch``).
``build``
    ``(closure, parameters, limits) -> Model``: a model from validated values (SI).

Optional capabilities
---------------------
See the fields of :class:`Mechanism`: cross-value checks, a synthesis
formulation, extra inscribed-cuboid inputs and values, a closed-form
workspace membership from the paper, a dynamics model, default joint
stiffnesses and flexure hinges, problem kinds of its own, the problem files
that reproduce its paper's figures, and a drawing of the mechanism at a pose
(``geometry``: base, legs, joints, platform).
"""

from __future__ import annotations

import inspect
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, fields, replace
from typing import Any

from .errors import suggest
from .joints import JOINT_LETTERS
from .options import Option, validate_mapping
from .origin import Origin, as_origin


class MechanismDeclarationError(TypeError):
    """A mechanism declaration that breaks the interface (raised at declaration
    or registration, with the mechanism's name and the field at fault)."""


@dataclass(frozen=True, kw_only=True)
class CuboidExtras:
    """What a mechanism adds to the ``inscribed_cuboid`` kind.

    options: extra inputs of the kind for this mechanism.
    value_names: the names of the extra values, all of them (set to null when
        no cuboid was found).
    values: ``(model, lower, upper, inputs, solver) -> (values, dimensions)``
        for a found box ``lower <= t <= upper`` (SI, task coordinates).
    paper_box: optional ``(values) -> (lower, upper, label) | None``: the box of
        the paper's own formulation read from a result's values, drawn beside
        the found one by the workspace plot (None when the result has none).
    """

    options: tuple[Option, ...] = ()
    value_names: tuple[str, ...] = ()
    values: Callable[..., tuple[dict, dict]]
    paper_box: Callable[[Mapping[str, Any]], Any] | None = None


@dataclass(frozen=True, kw_only=True)
class DynamicsModel:
    """A Lagrange model of the mechanism, used by the ``dynamics`` kind.

    masses: ``(name, description)`` of each mass input (kg, or a block of the
        hinge material given by its dimensions).
    parameters: names, in order, of the vector w the energies take: ``E``,
        ``g``, the masses and any mechanism parameters by name.
    lagrangian: ``() -> ca.Function("...", [q, qd, p, w], [T, U, ...])``: the
        kinetic and potential energies in the actuator coordinates q (nq).
    values: optional ``(model, w, M, K, G) -> dict`` of named quantities of the
        paper, with their dimensions in ``dimensions``.
    """

    masses: tuple[tuple[str, str], ...]
    parameters: tuple[str, ...]
    lagrangian: Callable[[], Any]
    values: Callable[..., dict] | None = None
    dimensions: Mapping[str, str] = field(default_factory=dict)


#: parts a :class:`Drawing` may join or fill, in the order they are drawn
DRAWING_PARTS = ("base", "actuator", "link", "leg", "platform")
#: joint letters a :class:`Drawing` may mark (prismatic, revolute, cylindrical, universal, spherical):
#: the letters of the joint table
JOINT_TYPES = JOINT_LETTERS


@dataclass(frozen=True, kw_only=True)
class Drawing:
    """The mechanism drawn at one pose, for plots: named 3-D points (SI, fixed
    frame) and what joins them.

    points: name -> (x, y, z).
    segments: ``(from, to, part)``: a straight link between two points; part
        is one of :data:`DRAWING_PARTS` (a rail or a lever is ``actuator``).
    faces: ``(part, (names ...))``: a filled polygon (the base, the platform).
    joints: point name -> joint letter (:data:`JOINT_TYPES`), marked on the drawing.
    note: what the drawing leaves out or where it departs from scale (shown with it).
    """

    points: Mapping[str, Any]
    segments: tuple[tuple[str, str, str], ...] = ()
    faces: tuple[tuple[str, tuple[str, ...]], ...] = ()
    joints: Mapping[str, str] = field(default_factory=dict)
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


@dataclass(frozen=True, kw_only=True)
class JointStiffness:
    """The compliant joints of a mechanism as its paper gives them (the
    ``stiffness`` capability), used by the compliance kinds as defaults that a
    problem file may override hinge by hinge (``inputs.hinges``).

    hinges: hinge name -> the same mapping a problem file gives under
        ``inputs.hinges``: ``joints`` (a coordinate or family name of x, q or the
        passive joints, or a mapping axis -> name with axes bend, bend2, torsion,
        axial), ``k`` (N*m/rad on angles, N/m on lengths; one value or one per
        axis), and optionally a flexure ``type`` with its dimensions (see
        :data:`cpm_nlp.analysis.compliance.HINGE_TYPES`) for the stresses and the
        stiffness of the axes k does not give.
    material: the hinge material, a name of :data:`cpm_nlp.analysis.flexure.MATERIALS`
        or an inline mapping ``{name, E, nu, density, yield_strength, allowable}``.
    source: where the paper gives them (file, section, table).
    """

    hinges: Mapping[str, Mapping[str, Any]]
    material: Any = None
    source: str = ""


@dataclass(frozen=True, kw_only=True)
class Mechanism:
    """A mechanism type: required parts and optional capabilities.

    Sizes in model terms: nx pose coordinates x, nq actuators q, np
    parameters p (see :class:`~cpm_nlp.core.model.LoopClosure`).
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
    #: ``() -> ProblemKind``: the paper's dimensional synthesis, run by the ``synthesis`` kind
    synthesis: Callable[[], Any] | None = None
    #: extra inputs and values of the ``inscribed_cuboid`` kind
    cuboid: CuboidExtras | None = None
    #: ``(model, points (N, nq)) -> (inside (N,), margins)``: the paper's closed-form
    #: workspace membership, reported by the ``workspace`` kind beside the general test
    paper_membership: Callable[[Any, Any], tuple[Any, dict]] | None = None
    #: a Lagrange model for the ``dynamics`` kind
    dynamics: DynamicsModel | None = None
    #: ``(model, x (nx,), q (nq,)) -> Drawing``: the mechanism at a pose (base, legs,
    #: joints, platform) for the plots, from its kinematic functions
    geometry: Callable[[Any, Any, Any], Drawing] | None = None
    #: default joint stiffnesses and flexure hinges, for the compliance kinds
    stiffness: JointStiffness | None = None
    #: ``(model) -> Chains``: each leg as a serial chain of joints at the reference
    #: configuration (:mod:`cpm_nlp.core.chains`), for the six-axis hinge model
    chains: Callable[[Any], Any] | None = None
    #: problem kinds of its own: kind name -> ProblemKind subclass
    kinds: Mapping[str, type] = field(default_factory=dict)
    #: its shipped problem files: examples of its kinds, and (those with a ``reproduce:``
    #: section) its paper's figures; names under the shipped ``problems/`` directory, or
    #: absolute paths for a plugin's own files
    problem_files: tuple[str, ...] = ()
    #: where the declaration came from (:class:`~cpm_nlp.core.origin.Origin`; a text given in
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
        or strings with units), validated against the declared options and checks."""
        params = validate_mapping(parameters or {}, self.parameters, path + ("parameters",), what="parameter")
        lims = validate_mapping(limits or {}, self.limits, path + ("limits",), what="limit")
        if self.check_parameters is not None:
            self.check_parameters(params, path + ("parameters",))
        if self.check_limits is not None:
            self.check_limits(lims, path + ("limits",))
        return self.build(closure, params, lims)

    def capabilities(self) -> list[str]:
        """Names of the optional capabilities this mechanism declares."""
        return [f.name for f in fields(self) if f.name in CAPABILITIES and getattr(self, f.name)]


#: required parts of a mechanism
REQUIRED = ("name", "title", "parameters", "limits", "closure", "build")
#: optional capabilities (fields) of a mechanism
CAPABILITIES = (
    "check_parameters",
    "check_limits",
    "synthesis",
    "cuboid",
    "paper_membership",
    "dynamics",
    "geometry",
    "stiffness",
    "chains",
    "kinds",
    "problem_files",
)
#: every part a declaration may name
PARTS = REQUIRED + CAPABILITIES + ("paper", "origin")


def _fail(mech: Any, name: str, expected: str) -> None:
    value = getattr(mech, name)
    raise MechanismDeclarationError(
        f"mechanism {mech.name!r} ({mech.origin}): {name} must be {expected}, got {type(value).__name__} {value!r:.60}"
    )


def validate(mech: Mechanism) -> None:  # noqa: C901 - one flat check per declared part
    """Check the types of every part of a declaration (registration calls it too)."""
    if not isinstance(mech.name, str) or not mech.name.isidentifier():
        raise MechanismDeclarationError(f"a mechanism name must be an identifier, got {mech.name!r} ({mech.origin})")
    if not isinstance(mech.title, str):
        _fail(mech, "title", "a string")
    for group in ("parameters", "limits"):
        value = getattr(mech, group)
        if not isinstance(value, tuple) or not all(isinstance(o, Option) for o in value):
            _fail(mech, group, "a tuple of Option")
        names = [o.name for o in value]
        if len(set(names)) != len(names):
            _fail(mech, group, "a tuple of Options with distinct names")
    for name in ("closure", "build"):
        if not callable(getattr(mech, name)):
            _fail(mech, name, "callable")
    for name in ("check_parameters", "check_limits", "synthesis", "paper_membership", "geometry", "chains"):
        if getattr(mech, name) is not None and not callable(getattr(mech, name)):
            _fail(mech, name, "callable or None")
    if mech.cuboid is not None and not isinstance(mech.cuboid, CuboidExtras):
        _fail(mech, "cuboid", "a CuboidExtras or None")
    if mech.dynamics is not None and not isinstance(mech.dynamics, DynamicsModel):
        _fail(mech, "dynamics", "a DynamicsModel or None")
    if mech.stiffness is not None:
        if not isinstance(mech.stiffness, JointStiffness):
            _fail(mech, "stiffness", "a JointStiffness or None")
        if not isinstance(mech.stiffness.hinges, Mapping) or not all(
            isinstance(k, str) and isinstance(v, Mapping) for k, v in mech.stiffness.hinges.items()
        ):
            _fail(mech, "stiffness", "a JointStiffness whose hinges map names to hinge mappings")
    if not isinstance(mech.kinds, Mapping):
        _fail(mech, "kinds", "a mapping of kind name -> ProblemKind subclass")
    for kname, cls in mech.kinds.items():
        if not isinstance(kname, str) or not inspect.isclass(cls) or not hasattr(cls, "run"):
            _fail(mech, "kinds", f"a mapping of kind name -> ProblemKind subclass (entry {kname!r})")
        if getattr(cls, "name", kname) != kname:
            _fail(mech, "kinds", f"keyed by each kind's own name ({cls.__name__}.name is {cls.name!r}, key {kname!r})")
    if not isinstance(mech.problem_files, tuple) or not all(isinstance(f, str) for f in mech.problem_files):
        _fail(mech, "problem_files", "a tuple of file names")


def declare(**parts: Any) -> Mechanism:
    """A :class:`Mechanism` from keyword parts, with a "did you mean" for a
    misspelt part (``Mechanism(...)`` itself only says "unexpected keyword")."""
    unknown = [k for k in parts if k not in PARTS]
    if unknown:
        hints = [f"{k!r} (did you mean {', '.join(repr(s) for s in suggest(k, PARTS))}?)" for k in unknown]
        name = parts.get("name", "?")
        raise MechanismDeclarationError(
            f"mechanism {name!r}: unknown part(s) {', '.join(hints)}; "
            f"required: {', '.join(REQUIRED)}; optional: {', '.join(CAPABILITIES)}, paper, origin"
        )
    missing = [k for k in REQUIRED if k not in parts]
    if missing:
        raise MechanismDeclarationError(
            f"mechanism {parts.get('name', '?')!r}: missing required part(s) {', '.join(missing)}"
        )
    return Mechanism(**parts)


@dataclass(frozen=True, kw_only=True)
class Addon:
    """What a mechanism file cannot say, given in Python for the mechanism of one shipped file
    (issue 21, item 5): the file is the mechanism (its closures, IK, passive joints, branch,
    drawing, paper, problem files); the add-on refers to it by the registry's table
    :data:`cpm_nlp.mechanisms.registry.ADDONS` and adds only what is not kinematics.

    parameters: optional parameters the closures do not use (e.g. a dynamics model's lengths
        and hinge sizes); a value given is kept in the model's ``parameters``, never in p.
    check_parameters: ``(parameters, path) -> None``: rules over several parameters.
    dynamics: ``(closure) -> DynamicsModel``: the Lagrange model, given the file's closure
        (so that it may use the file's loop closures, e.g. their Jacobian, never a copy).
    kinds: problem kinds of the paper's own: kind name -> ProblemKind subclass.
    check_limits, synthesis, cuboid, paper_membership, stiffness, chains: as the
        :class:`Mechanism` fields of the same names (the paper's formulations that refer to
        the file's mechanism).
    limits: the paper's own limit options (e.g. a hinge from which a formula sets the joint
        limits, or ranges counted from home), beside the file's limit families; one named
        like a family of the file replaces it (the paper's meaning of that name wins).
    complete: ``(model, limits) -> None``: completes the file's model with what ``limits``
        gives (joint limits on the file's coordinates) and the paper's derived quantities
        (``model.derived``), from the file's closure and model, never a copy of them.
    plots: the paper's own plot types, each ``"module:attribute"`` of a
        :class:`~cpm_nlp.plot.plot_type.PlotType` (named, not imported: a plot belongs to
        the plot layer, above the mechanisms); drawn only for results of this mechanism
        (:mod:`cpm_nlp.plot.registry`).
    """

    parameters: tuple[Option, ...] = ()
    check_parameters: Callable[[dict, tuple], None] | None = None
    dynamics: Callable[[Any], DynamicsModel] | None = None
    kinds: Mapping[str, type] = field(default_factory=dict)
    check_limits: Callable[[dict, tuple], None] | None = None
    synthesis: Callable[[], Any] | None = None
    cuboid: CuboidExtras | None = None
    paper_membership: Callable[[Any, Any], tuple[Any, dict]] | None = None
    stiffness: JointStiffness | None = None
    chains: Callable[[Any], Any] | None = None
    limits: tuple[Option, ...] = ()
    complete: Callable[[Any, dict], None] | None = None
    plots: tuple[str, ...] = ()


#: the add-on's parts taken as they are (each must not be given by the file too)
ADDON_PARTS = ("check_parameters", "check_limits", "synthesis", "cuboid", "paper_membership", "stiffness", "chains")


def with_addon(mech: Mechanism, addon: Addon) -> Mechanism:
    """The mechanism of a file with its add-on's parts (validated like any declaration).  A
    part the add-on gives that the file has too (a parameter, a kind, a check) is an error:
    each part is written once."""
    if not isinstance(addon, Addon):
        raise MechanismDeclarationError(f"mechanism {mech.name!r}: expected an Addon, got {type(addon).__name__}")
    own = {o.name for o in mech.parameters}
    clash = sorted(own & {o.name for o in addon.parameters}) + sorted(set(mech.kinds) & set(addon.kinds))
    clash += [part for part in ADDON_PARTS + ("dynamics",) if getattr(addon, part) and getattr(mech, part)]
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
        dynamics=addon.dynamics(mech.closure()) if addon.dynamics else mech.dynamics,
        **{part: getattr(addon, part) or getattr(mech, part) for part in ADDON_PARTS},
        kinds={**mech.kinds, **addon.kinds},
    )
