"""The flexible bodies of a mechanism as declared (``stiffness.bodies`` of a mechanism file,
``inputs.bodies`` of a problem file): the declaration (`BODIES`), the parsed record of one
body (`BodySpec`) and the bodies of one model (`Body`: a beam per member pair of joints).
The beam elements themselves are `cpm_nlp.analysis.beams`."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from ..core.errors import InputError, suggest
from ..core.model import LoopClosure
from ..core.options import Option
from ..core.schema import Either, ListOf, MappingOf, Record
from .beams import ELEMENT_MODELS, SECTION_KINDS, THEORIES, BeamSpec, Section
from .flexure import Material, material, material_node

#: the end of a body at the platform point of its leg (instead of a joint)
PLATFORM = "platform"
#: most elements per body (a sanity limit: the six-axis model grows by 6 variables per element)
MAX_ELEMENTS = 200

_SECTION_TEXT = (
    "a section: {b, h} (a rectangle, h the thickness across which it bends about its compliant axis, b the "
    "width along that axis), {d} (round), {A, I} with optional I2, J (given), or {profile: circular_notch, t, r, "
    "w} (a notch as a beam of varying thickness t(x) = t + 2(r - sqrt(r^2 - x^2))); kappa optional"
)


def _section_fields() -> tuple:
    length = [("b", "width along the compliant axis"), ("h", "thickness"), ("d", "diameter")]
    notch = [("t", "notch: thinnest section"), ("r", "notch: radius"), ("w", "notch: width")]
    out = [Option(n, "length", text, default=None, lower=0.0, strict=True) for n, text in length + notch]
    given = [
        ("A", "area", "given: area"),
        ("I", "area_moment", "given: second moment about the compliant axis"),
        ("I2", "area_moment", "given: second moment about the other axis (default I)"),
        ("J", "area_moment", "given: torsion constant (default I + I2)"),
        ("kappa", "dimensionless", "shear coefficient (default Cowper's)"),
    ]
    out += [Option(n, dim, text, default=None, lower=0.0, strict=True) for n, dim, text in given]
    out.append(Option("profile", "choice", "a varying section", default=None, choices=("circular_notch",)))
    return tuple(out)


def _section(value: Mapping[str, Any], path: tuple) -> Section:
    given = {k for k, v in value.items() if v is not None and k != "kappa"}
    if value.get("profile") == "circular_notch":
        kind = "circular_notch"
    else:
        kinds = [k for k, keys in SECTION_KINDS.items() if k != "circular_notch" and set(keys) <= given]
        if len(kinds) != 1:
            raise InputError(f"expected {_SECTION_TEXT}, got {sorted(given)}", path=path)
        kind = kinds[0]
    allowed = set(SECTION_KINDS[kind]) | ({"I2", "J"} if kind == "given" else set()) | {"profile"}
    extra = sorted(given - allowed)
    missing = [k for k in SECTION_KINDS[kind] if k not in given]
    if extra or missing:
        why = f"no {', '.join(extra)}" if extra else f"missing {', '.join(missing)}"
        raise InputError(f"a {kind} section takes {', '.join(SECTION_KINDS[kind])}: {why}", path=path)
    if kind == "circular_notch" and value["t"] >= 2.0 * value["r"]:
        raise InputError("impossible circular notch: t must be below 2r", path=path + ("t",))
    vals = {k: value[k] for k in SECTION_KINDS[kind]}
    for k in ("I2", "J", "kappa"):
        if value.get(k) is not None:
            vals[k] = value[k]
    return Section(kind, vals)


def _stiffness_models(value: Any, path: tuple) -> tuple[str, ...]:
    items = value if isinstance(value, list) else [value]
    for i, v in enumerate(items):
        if v not in ELEMENT_MODELS:
            where = path + ((i,) if isinstance(value, list) else ())
            raise InputError(
                f"expected an element stiffness model ({' or '.join(ELEMENT_MODELS)}), got {v!r}",
                path=where,
                suggestions=suggest(str(v), ELEMENT_MODELS),
            )
    return tuple(items)


BODY = Record(
    "<body>",
    "one flexible body: a beam between two neighbouring joints of each leg, or a joint's hinge as a beam",
    (
        ListOf(
            "between",
            "the joints at its two ends, by a coordinate or family name each (the second may be 'platform': the "
            "leg's platform point); they must be neighbours in a leg",
            Option("joint", "str", "a coordinate or family name"),
            min_len=2,
            max_len=2,
            default=None,
        ),
        Option(
            "at",
            "str",
            "instead of between: a passive joint (coordinate or family name) whose hinge this beam is, centred there "
            "along the link (a notch profile's 2r long, else length): it replaces the hinge's six-axis spring and the "
            "joint's own rotation",
            default=None,
        ),
        Record("section", _SECTION_TEXT, _section_fields(), what="section key", sparse=True, convert=_section),
        Option("beam", "choice", "the beam theory", default="timoshenko", choices=THEORIES),
        Option("elements", "int", "the number of elements", default=4, lower=1, upper=MAX_ELEMENTS),
        Either(
            "stiffness",
            "each element's stiffness model: distributed (the element's exact beam compliance, integrated along "
            "it) or lumped (a six-axis spring at its midpoint, rigid halves); one for all, or a list, one per element",
            (
                Option("stiffness", "choice", "one model for every element", choices=ELEMENT_MODELS),
                ListOf("stiffness", "one model per element", Option("model", "choice", "", choices=ELEMENT_MODELS)),
            ),
            default="distributed",
        ),
        Option(
            "length",
            "length",
            "the flexible length, centred between the two joints (default: the whole distance; a notch profile: 2r)",
            default=None,
            lower=0.0,
            strict=True,
        ),
        material_node("material", "the body's material (default: the mechanism's)", None),
    ),
    what="body key",
)

#: body name -> body, as a mechanism file's ``stiffness.bodies`` and a problem file's ``inputs.bodies`` take them
BODIES = MappingOf(
    "bodies",
    "flexible bodies by name: name -> {between, section, beam, elements, stiffness, length, material}; null "
    "removes one of the mechanism's",
    BODY,
    key_what="body",
    default=None,
    nullable=True,
    mismatch="expected a mapping of flexible bodies (name -> {between, section, ...})",
    convert=lambda value, path: None if value is None else _specs(value, path),
)


def _specs(value: Mapping[str, Any], path: tuple) -> dict[str, BodySpec | None]:
    return {n: None if v is None else body_spec(n, v, path + (n,)) for n, v in value.items()}


@dataclass(frozen=True)
class BodySpec:
    """One body as parsed by `BODIES` (SI)."""

    between: tuple[str, str] | None
    beam: BeamSpec
    material: Material | None
    #: the joint whose hinge the beam is (instead of ``between``)
    at: str | None = None


def body_spec(name: str, value: Mapping[str, Any], path: tuple) -> BodySpec:
    """The record of one body from its parsed mapping."""
    raw_models = value["stiffness"]
    models = _stiffness_models(raw_models, path + ("stiffness",))
    if len(models) not in (1, value["elements"]):
        raise InputError(
            f"expected one stiffness model or one per element ({value['elements']}), got {len(models)}",
            path=path + ("stiffness",),
        )
    beam = BeamSpec(name, value["section"], value["beam"], int(value["elements"]), models, value["length"])
    mat = None if value.get("material") is None else material(value["material"], path + ("material",))
    if (value.get("between") is None) == (value.get("at") is None):
        raise InputError("give either between (a link's two joints) or at (a joint's hinge)", path=path)
    if value.get("at") is not None and value["section"].length is None and value["length"] is None:
        raise InputError(
            "a hinge as a beam (at) needs its length: give length, or a notch profile (2r long)",
            path=path + ("length",),
        )
    between = None if value.get("between") is None else tuple(value["between"])
    return BodySpec(between, beam, mat, value.get("at"))


def parse_bodies(raw: Any, path: tuple) -> dict[str, BodySpec | None]:
    """name -> body record (None: remove the mechanism's body of that name)."""
    if raw is None:
        return {}
    if all(v is None or isinstance(v, BodySpec) for v in raw.values()):  # parsed already (a kind's input)
        return dict(raw)
    return BODIES.parse(raw, path)


@dataclass(frozen=True)
class Body:
    """One flexible body of a model: its beam between the joints of each member pair
    (coordinate names; the second may be `PLATFORM`), and its material."""

    name: str
    beam: BeamSpec
    members: tuple[tuple[str, str], ...]
    material: Material
    path: tuple
    #: a hinge's beam, centred at the first joint of each member (the second is "")
    centred: bool = False


def _members(closure: LoopClosure, name: str, path: tuple) -> list[str]:
    coords = list(closure.x) + list(closure.q) + list(closure.passive_coords)
    exact = [c.name for c in coords if c.name == name]
    if exact:
        return exact
    fam = [c.name for c in coords if c.family == name]
    if fam:
        return fam
    known = sorted({c.name for c in coords} | {c.family for c in coords if c.family} | {PLATFORM})
    raise InputError(
        f"unknown joint {name!r}; expected a coordinate or a family of {closure.name}, or 'platform': "
        + ", ".join(known),
        path=path,
        suggestions=suggest(name, known),
    )


def bodies_of(
    closure: LoopClosure, specs: Mapping[str, BodySpec], mat: Material | None, paths: Mapping[str, tuple]
) -> list[Body]:
    """The bodies of ``specs`` on a closure: their member pairs of joints, and a material with E and nu."""
    out = []
    for name, spec in specs.items():
        path = paths[name]
        if spec.at is not None:
            first = _members(closure, spec.at, path + ("at",))
            m = _material(spec, mat, name, path)
            out.append(Body(name, spec.beam, tuple((f, "") for f in first), m, path, True))
            continue
        first = _members(closure, spec.between[0], path + ("between", 0))
        second = (
            [PLATFORM] * len(first)
            if spec.between[1] == PLATFORM
            else _members(closure, spec.between[1], path + ("between", 1))
        )
        if len(first) != len(second):
            raise InputError(
                f"the two ends of body {name} have {len(first)} and {len(second)} members; give two families of "
                "as many members (one per leg)",
                path=path + ("between",),
            )
        m = _material(spec, mat, name, path)
        out.append(Body(name, spec.beam, tuple(zip(first, second, strict=True)), m, path))
    return out


def _material(spec: BodySpec, mat: Material | None, name: str, path: tuple) -> Material:
    m = spec.material or mat
    if m is None:
        raise InputError(f"body {name}: its stiffness needs a material", path=path + ("material",))
    m.require("E", path + ("material",), "a flexible body")
    m.require("nu", path + ("material",), "a flexible body's shear and torsion")
    return m


def merged_bodies(
    c: LoopClosure, declared: Mapping[str, BodySpec | None], bodies: Any, mat: Material | None, path: tuple
) -> list[Body]:
    """A mechanism's declared bodies merged, body by body, with a problem file's ``bodies``
    (a body of the same name replaces the mechanism's; null removes it)."""
    given = parse_bodies(bodies, path + ("bodies",))
    merged = {**declared, **given}
    specs = {n: b for n, b in merged.items() if b is not None}
    paths = {n: path + ("bodies", n) if n in given else ("mechanism", "stiffness", "bodies", n) for n in specs}
    return bodies_of(c, specs, mat, paths)


__all__ = ["BODIES", "PLATFORM", "Body", "BodySpec", "bodies_of", "body_spec", "merged_bodies", "parse_bodies"]
