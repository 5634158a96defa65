"""Reading a mechanism file (a parsed mapping) into a [`Description`][cpm_nlp.mechanisms.described.spec.Description]:
its
top-level keys, each read in turn by its section's reader (the errors carry key paths), and
the small sections -- parameters, derived and passive values, actuators, the closed-form
inverse kinematics, joint-limit descriptions, stiffness and branch indicators.  The larger
sections have modules of their own: `read_platform`, `read_legs`,
`read_graph`."""

from __future__ import annotations

from collections.abc import Callable, Hashable, Mapping
from typing import Any

from ...analysis.compliance import HINGE_KEYS, JointStiffness
from ...core.errors import InputError, unknown_key_error
from ...core.finite import check_numbers
from ...core.options import REQUIRED
from ...core.units import parse_quantity
from .read_fields import as_dimension, as_list, as_mapping, as_name, as_text, as_type_name
from .read_graph import read_graph
from .read_legs import check_bodies, read_legs
from .read_platform import read_platform
from .spec import DIMENSIONS, ClosedFormIK, Description, Parameter, Quantity

TOP = {
    "name": "the mechanism type name (an identifier)",
    "title": "a one-line title",
    "paper": "where the mechanism comes from",
    "parameters": "name -> {dimension, default, bounds, strict, description}",
    "derived": "name -> expression (or {value, dimension, description})",
    "platform": "{coordinates, position, rotation, task, fixed, home, bounds}",
    "legs": "list of {name, repeat, joints}",
    "actuators": "name -> dimension or {dimension, home} (for closures written as expressions)",
    "branch": "assembly-branch indicators as expressions, positive on the working branch",
    "closures": "list of closure equations as expressions (an escape hatch)",
    "passive": "name -> {value, dimension, family, description}: extra reported joint values",
    "ik": "{let, pose, actuators, reach}: a closed-form inverse kinematics",
    "characteristic_length": "length expression for conditioning measures",
    "examples": "problem files that use the mechanism (relative to this file)",
    "limits": "joint-limit family -> its description (text)",
    "stiffness": "{hinges, material, source}: the compliant joints, defaults of the compliance kinds",
    "points": "name -> vector: named points of the drawing (bodies-and-joints files)",
    "bodies": "name -> [point names] or {points, description}: the rigid bodies (the ground is 'ground')",
    "joints": "list of {type, between: [body, body], at, axis, ...}: joints between any two bodies",
    "outputs": "name -> body.point: points of any body reported with every result",
}


def description_from_dict(data: Any, file: str | None = None) -> Description:
    """Read a mechanism description from a parsed mechanism file (errors carry key paths)."""
    if not isinstance(data, Mapping):  # not echoed: the file may be any file a problem file names
        size = f" of {len(data)} characters" if isinstance(data, str) else ""
        raise InputError(
            f"expected a mechanism description (a mapping with name, parameters, platform, legs), "
            f"got {'an empty file' if data is None else type(data).__name__ + size}"
        )
    data = as_mapping(data, (), "a mechanism description (a mapping with name, parameters, platform, legs)", TOP)
    check_numbers(data)  # no inf, NaN or 1500-digit integer anywhere
    for key in ("name", "platform"):
        if key not in data:
            raise InputError(f"missing required key {key!r} ({TOP[key]})")
    fields: dict[str, Any] = {}
    for read in _SECTIONS:
        fields.update(read(data, fields))
    return Description(**fields, file=file)


#: a section's reader: (the file's mapping, the fields read so far) -> the fields it reads
Section = Callable[[Mapping, dict], dict]


def _name_section(data: Mapping, _fields: dict) -> dict:
    return {"name": as_type_name(data["name"], ("name",))}


def _parameters(data: Mapping, _fields: dict) -> dict:
    raw = as_mapping(data.get("parameters") or {}, ("parameters",), "name -> {dimension, default}")
    return {
        "parameters": [
            _parameter(as_name(n, ("parameters", n), "a parameter name"), v, ("parameters", n)) for n, v in raw.items()
        ]
    }


def _quantities(key: str, what: str) -> Section:
    """The reader of a section of named quantities (``derived``, ``passive``)."""

    def read(data: Mapping, _fields: dict) -> dict:
        raw = as_mapping(data.get(key) or {}, (key,), what)
        return {key: [_quantity(as_name(n, (key, n), "a name"), v, (key, n)) for n, v in raw.items()]}

    return read


def _actuators(data: Mapping, _fields: dict) -> dict:
    actuators = {}
    for n, v in as_mapping(data.get("actuators") or {}, ("actuators",), "name -> dimension").items():
        path = ("actuators", n)
        as_name(n, path, "an actuator name")
        if isinstance(v, Mapping):
            v = as_mapping(v, path, "{dimension, home}", {"dimension": "", "home": ""})
            actuators[n] = (as_dimension(v.get("dimension"), path + ("dimension",)), v.get("home", 0))
        else:
            actuators[n] = (as_dimension(v, path), 0)
    return {"actuators": actuators}


IK_KEYS = {"let": "definitions in order", "pose": "dependent coordinates", "actuators": "", "reach": ""}


def _ik(data: Mapping, _fields: dict) -> dict:
    if data.get("ik") is None:
        return {"ik": None}
    raw = as_mapping(data["ik"], ("ik",), "{let, pose, actuators, reach}", IK_KEYS)
    return {
        "ik": ClosedFormIK(
            as_mapping(raw.get("let") or {}, ("ik", "let"), "name -> expression"),
            as_mapping(raw.get("pose") or {}, ("ik", "pose"), "name -> expression"),
            as_mapping(raw.get("actuators") or {}, ("ik", "actuators"), "name -> expression"),
            raw.get("reach"),
        )
    }


def _examples(data: Mapping, _fields: dict) -> dict:
    examples = as_list(data.get("examples") or [], ("examples",), "a list of problem files")
    return {"examples": tuple(str(e) for e in examples)}


def _limits(data: Mapping, _fields: dict) -> dict:
    raw = as_mapping(data.get("limits") or {}, ("limits",), "joint-limit family -> description")
    return {
        "limits": {as_name(n, ("limits", n), "a joint-limit family"): as_text(v, ("limits", n)) for n, v in raw.items()}
    }


def _legs(data: Mapping, _fields: dict) -> dict:
    legs = read_legs(data.get("legs") or [], ("legs",))
    check_bodies(legs)
    return {"legs": legs}


#: the fields a file of bodies and joints has besides a legs file's
GRAPH_FIELDS = ("points", "bodies", "joints", "outputs")


def _graph(data: Mapping, fields: dict) -> dict:
    if data.get("bodies") is not None:
        return dict(zip(GRAPH_FIELDS, read_graph(data, fields["legs"])))
    for key in ("points", "joints", "outputs"):
        if data.get(key) is not None:
            raise InputError(
                f"{key!r} belongs to a file of bodies and joints, and this file has no 'bodies'",
                path=(key,),
                hint="declare the bodies (name -> the points it carries), or describe the legs",
            )
    return {}


def _title(data: Mapping, fields: dict) -> dict:
    return {"title": as_text(data.get("title"), ("title",)) or fields["name"]}


def _platform(data: Mapping, _fields: dict) -> dict:
    return {"platform": read_platform(data["platform"], ("platform",), graph=data.get("bodies") is not None)}


def _closures(data: Mapping, _fields: dict) -> dict:
    return {"closures": list(as_list(data.get("closures") or [], ("closures",), "a list of expressions"))}


def _branch_section(data: Mapping, _fields: dict) -> dict:
    return {"branch": _branch(data.get("branch"), ("branch",)) if "branch" in data else None}


def _characteristic_length(data: Mapping, _fields: dict) -> dict:
    return {"characteristic_length": data.get("characteristic_length")}


def _paper(data: Mapping, _fields: dict) -> dict:
    return {"paper": as_text(data.get("paper"), ("paper",))}


def _stiffness_section(data: Mapping, _fields: dict) -> dict:
    raw = data.get("stiffness")
    return {"stiffness": None if raw is None else _stiffness(raw, ("stiffness",))}


#: the sections, in the order they are read (the first error found is the one reported)
_SECTIONS: tuple[Section, ...] = (
    _name_section,
    _parameters,
    _quantities("derived", "name -> expression"),
    _quantities("passive", "name -> {value, dimension}"),
    _actuators,
    _ik,
    _examples,
    _limits,
    _legs,
    _graph,
    _title,
    _platform,
    _closures,
    _branch_section,
    _characteristic_length,
    _paper,
    _stiffness_section,
)


PARAMETER_KEYS = {"dimension": "", "default": "", "bounds": "", "strict": "", "description": ""}


def _parameter(name: str, raw: Any, path: tuple) -> Parameter:
    if isinstance(raw, str) and raw in DIMENSIONS:
        raw = {"dimension": raw}
    raw = as_mapping(raw, path, "{dimension, default, bounds, strict, description}", PARAMETER_KEYS)
    dim = as_dimension(raw.get("dimension", "length"), path + ("dimension",))
    lower = upper = None
    if raw.get("bounds") is not None:
        b = raw["bounds"]
        if not isinstance(b, list) or len(b) != 2:
            raise InputError(f"expected [low, high] (null for none), got {b!r}", path=path + ("bounds",))
        lower, upper = (None if v is None else parse_quantity(v, dim, path + ("bounds", k)) for k, v in enumerate(b))
        if lower is not None and upper is not None and not lower < upper:
            raise InputError(f"expected [low, high] with low < high, got {b!r}", path=path + ("bounds",))
    default = REQUIRED if raw.get("default") is None else parse_quantity(raw["default"], dim, path + ("default",))
    strict = raw.get("strict", False)
    if not isinstance(strict, bool):
        raise InputError(
            f"expected true (the bounds exclude their ends) or false, got {strict!r:.60}", path=path + ("strict",)
        )
    if strict and lower is None and upper is None:
        raise InputError("'strict' makes the bounds exclusive, and there are no bounds", path=path + ("strict",))
    return Parameter(
        name, dim, default, lower, upper, as_text(raw.get("description"), path + ("description",)), strict=strict
    )


QUANTITY_KEYS = {"value": "", "dimension": "", "description": "", "family": ""}


def _quantity(name: str, raw: Any, path: tuple) -> Quantity:
    if not isinstance(raw, Mapping):
        return Quantity(name, raw)
    raw = as_mapping(raw, path, "{value, dimension, description}", QUANTITY_KEYS)
    if "value" not in raw:
        raise InputError("missing key 'value' (an expression)", path=path)
    dim = None if raw.get("dimension") is None else as_dimension(raw["dimension"], path + ("dimension",))
    fam = raw.get("family") or ""
    if not isinstance(fam, Hashable):  # a family names an option (a key)
        what = f"expected a joint-limit family (a name such as 'alpha'), got {fam!r:.60}"
        raise InputError(what, path=path + ("family",))
    return Quantity(name, raw["value"], dim, as_text(raw.get("description"), path + ("description",)), fam)


BRANCH_KEYS = {
    "keep": "generated indicators to keep (names, or all / none; default all)",
    "remove": "generated indicators to remove (names)",
    "add": "indicators to add (expressions, or {name: expression})",
}


def _branch(raw: Any, path: tuple) -> list[Any] | dict[str, Any]:
    """The ``branch`` section: a list (exactly these indicators) or {keep, remove, add}.  The
    names of generated indicators are checked when the mechanism is generated."""
    if raw is None:
        return []
    if isinstance(raw, list):
        return [_branch_item(v, path + (k,)) for k, v in enumerate(raw)]
    m = as_mapping(raw, path, "a list of indicators, or {keep, remove, add}", BRANCH_KEYS)
    keep = m.get("keep", "all")
    if keep not in ("all", "none"):
        keep = [
            as_text(v, path + ("keep", k)) for k, v in enumerate(as_list(keep, path + ("keep",), "a list of names"))
        ]
    removed = as_list(m.get("remove") or [], path + ("remove",), "a list of names")
    remove = [as_text(v, path + ("remove", k)) for k, v in enumerate(removed)]
    added = as_list(m.get("add") or [], path + ("add",), "a list of expressions")
    add = [_branch_item(v, path + ("add", k)) for k, v in enumerate(added)]
    return {"keep": keep, "remove": remove, "add": add}


def _branch_item(v: Any, path: tuple) -> Any:
    if isinstance(v, dict):
        if len(v) != 1:
            raise InputError(f"expected one {{name: expression}}, got {v!r:.60}", path=path)
        ((name, text),) = v.items()
        return {as_text(name, path): text}
    if isinstance(v, bool) or not isinstance(v, (str, int, float)):
        raise InputError(f"expected an indicator's name or an expression, got {v!r:.60}", path=path)
    return v


STIFFNESS_KEYS = {
    "hinges": "name -> {joints, type, k, t, r, w, d, l, Kt, material}, as a problem file's inputs.hinges",
    "material": "the hinge material: a name or an inline {name, E, nu, density, yield_strength, allowable}",
    "source": "where the values come from (paper, section, table)",
    "bodies": "name -> {between, section, beam, elements, stiffness, length, material}: flexible bodies (beams), "
    "as a problem file's inputs.bodies",
}


def _stiffness(raw: Any, path: tuple) -> JointStiffness:
    """The ``stiffness`` section: its shape and keys (the hinges are checked against the
    generated closure when the mechanism is built, by the rules of ``inputs.hinges``)."""
    raw = as_mapping(raw, path, "a mapping {hinges, material, source, bodies}", STIFFNESS_KEYS)
    if not raw.get("hinges"):
        raise InputError("missing key 'hinges' (" + STIFFNESS_KEYS["hinges"] + ")", path=path)
    hinges = {}
    for name, spec in as_mapping(raw["hinges"], path + ("hinges",), "name -> hinge mapping").items():
        p = path + ("hinges", name)
        as_name(name, p, "a hinge name")
        hinges[name] = as_mapping(spec, p, "a hinge mapping {joints, type, k, ...}")
        for key in hinges[name]:
            if key not in HINGE_KEYS:
                raise unknown_key_error(str(key), HINGE_KEYS, p + (str(key),), "hinge key")
    return JointStiffness(
        hinges=hinges,
        material=raw.get("material"),
        source=as_text(raw.get("source"), path + ("source",)),
        bodies=raw.get("bodies"),
    )
