"""Compliance, stiffness and strength of any mechanism by the pseudo-rigid-body
energy method.

Every compliant joint coordinate θ_j of a mechanism -- a pose coordinate x, an
actuator q or a passive joint angle of its closure (``passive_coords``) -- may
carry a hinge of stiffness k_j.  The hinges store the strain energy

    U(x, q) = ½ Σ_j k_j (θ_j(x, q) - θ_j0)²,

with θ_j0 the joint values at the mechanism's home pose (the undeflected
configuration).  On the loop closures Φ(x, q; p) = 0 the pose is a function
x(q) whose derivative is dx/dq = J = -Φ_x⁻¹ Φ_q (implicit function theorem), so

* the actuator forces that hold a pose against the hinges and against a
  generalized load f on the pose coordinates (force on a length, moment on an
  angle, conjugate to that coordinate) are the reduced gradient
  F = ∂V/∂q + Jᵀ ∂V/∂x of V = U - fᵀx (virtual work: Fᵀδq = δU - fᵀδx);
* the input stiffness is its total derivative K_q = ∂F/∂q + ∂F/∂x J, the
  Hessian of V(x(q), q), exact by algorithmic differentiation (the geometric
  stiffness of the load included);
* the output compliance with actuators of stiffness K_a (0: the actuator forces
  held; rigid: the positions held) is C_x = J (K_q + K_a)⁻¹ Jᵀ;
* the compliant forward kinematics minimises V + ½ (q - q_c)ᵀ K_a (q - q_c) - F_cᵀ (q - q_c)
  over (x, q) subject to Φ = 0 (IPOPT), F_c the actuator forces of the unloaded
  commanded pose, so that the commanded pose is the equilibrium without load.

This is a pseudo-rigid-body model: only the joint coordinates the kinematics
moves store energy, with the hinge's stiffness about that axis.  The other
five axes of each flexure (the 6-axis compliances of
`cpm_nlp.analysis.flexure_compliance`) would need the position and frame
of every hinge in space, which a loop closure does not carry; they supply the
stiffness of an axis only when a coordinate moves about it (e.g. the torsion
of a spherical flexure).  With the actuators rigidly held the model is a rigid
structure (no deflection); the platform compliance it gives is that of the
actuated directions.

Hinge stresses follow from the hinge moments M = k (θ - θ0) by the formulas of
`HINGE_TYPES` (nominal stresses at the thinnest section, each with its
source), combined by von Mises where a hinge carries bending and torsion.  The peak
stress is K_t times the nominal one (`Hinge.kt`: a hinge's ``Kt``, else its
type's published fit, else 1).
"""

from __future__ import annotations

import dataclasses
import functools
from collections.abc import Mapping
from dataclasses import dataclass, field
from types import MappingProxyType
from typing import Any, ClassVar

import casadi as ca
import numpy as np

from ..core.errors import InputError, suggest
from ..core.fast_calls import FastFunction
from ..core.mechanism import MechanismDeclarationError, Part
from ..core.model import LoopClosure, Model
from ..core.options import Option, validate_mapping
from ..core.schema import Either, MappingOf, Quantity, Record
from .beam_inputs import Body, bodies_of, merged_bodies, parse_bodies
from .flexure import Material, material, material_node
from .hinge_types import DIM_OPTIONS, HINGE_TABLE, NOTCH_TYPES, HingeType, check_leaf_fillet

#: the axes of a hinge a joint coordinate may turn (or stretch) it about
AXES = ("bend", "bend2", "torsion", "axial")
AXIS_TEXT = {
    "bend": "bending about the hinge's compliant axis",
    "bend2": "bending about the second (out-of-plane) axis",
    "torsion": "torsion about the hinge's length",
    "axial": "stretch along the hinge's length (a length coordinate)",
}


def six_axis_stiffness(h: Hinge) -> dict[str, float] | None:
    """The hinge's stiffness about and along all of `SIX_AXES` (N*m/rad, N/m),
    its given k where it has one; None without a flexure type and a material with E
    and nu (the other axes then cannot be computed)."""
    if h.kind is None or h.material is None or h.material.E is None or h.material.nu is None:
        return None
    out = {a: float(v) for a, v in HINGE_TYPES[h.kind].six_axis(h.material.E, h.material.G, h.dims).items()}
    out.update(h.k)
    return out


#: the hinge types a mechanism's or a problem's ``hinges`` may name: those of the one table
#: (`cpm_nlp.analysis.hinge_types.HINGE_TABLE`) that give a stiffness and a stress
HINGE_TYPES: Mapping[str, HingeType] = MappingProxyType(
    {name: t for name, t in HINGE_TABLE.items() if t.stiffness is not None}
)

HINGE_KEYS = ("joints", "type", "k", "material", "Kt", "r_fillet", *DIM_OPTIONS)


def _hinge_fields() -> tuple:
    """The keys of one hinge (``inputs.hinges.<name>``), each optional: a hinge of the
    problem file is merged key by key over the mechanism's hinge of the same name."""
    axis_names = ", ".join(AXES)
    stiffness = Quantity(
        "k",
        "stiffness (N*m/rad on a rotation, N/m on a slide; the joint's coordinate decides)",
        kinds=("rotational_stiffness", "stiffness"),
        positive=True,
    )
    joint = Option("name", "str", "a coordinate or a family of coordinates")
    return (
        Either(
            "joints",
            "the joint coordinates the hinge carries: a coordinate or family name (its bending axis), or a "
            "mapping axis -> name",
            (joint, MappingOf("joints", "axis -> joint", joint, keys=AXES, key_what="hinge axis", non_empty=True)),
            default=None,
            mismatch=f"expected joints: a coordinate or family name, or a mapping axis -> name (axes: {axis_names})",
        ),
        Option("type", "choice", "the flexure geometry", default=None, choices=tuple(HINGE_TYPES)),
        Either(
            "k",
            "stiffness per axis (one value for a one-axis hinge); default: the hinge formula of type and material",
            (stiffness, MappingOf("k", "axis -> stiffness", stiffness, keys=AXES, key_what="hinge axis")),
            default=None,
        ),
        material_node("material", "the hinge's own material (default: the problem's or the mechanism's)", None),
        Option(
            "Kt",
            "dimensionless",
            "stress-concentration factor on the nominal stress, for the peak stress (default: the type's "
            "published fit: circular_notch, filleted_rod, leaf_spring with a fillet radius r; else 1)",
            default=None,
            lower=1.0,
        ),
        Option("r_fillet", "length", "accepted for older files; not used (a filleted rod's fillet is r)", default=None),
        *(dataclasses.replace(o, default=None) for o in DIM_OPTIONS.values()),
    )


def hinges_node(description: str) -> MappingOf:
    """The declaration of ``inputs.hinges``: hinge name -> hinge (null removes a default hinge)."""
    return MappingOf(
        "hinges",
        description,
        Record(
            "<hinge>",
            "one hinge (its dimensions by its type: " + _type_dims() + ")",
            _hinge_fields(),
            what="hinge key",
            sparse=True,
        ),
        key_what="hinge",
        default=None,
        nullable=True,
        mismatch="expected a mapping of hinges (name -> {joints, type, k, ...})",
    )


def _type_dims() -> str:
    return "; ".join(f"{k}: {t.takes}" for k, t in HINGE_TYPES.items())


#: hinge name -> hinge, as a problem file's ``inputs.hinges`` and a mechanism's declared hinges take them
HINGES = hinges_node("hinges by name: name -> {joints, type, k, dimensions, Kt, material}; null removes one")


@dataclass(frozen=True, kw_only=True)
class HingeSpec:
    """One hinge as declared, parsed by `HINGES` (SI): the typed record a mechanism's
    hinge is parsed to once, and a problem file's hinge of the same name is merged over key
    by key (`over`).  ``keys``: the keys given (a key given as null clears the one below)."""

    joints: str | Mapping[str, str] | None = None
    type: str | None = None
    #: as written (one value or axis -> value): its dimension follows the joint it is on
    #: (N*m/rad on an angle, N/m on a length), known with the closure
    k: Any = None
    material: Material | None = None
    Kt: float | None = None
    #: the dimensions given (t, r, w, ... of `DIM_OPTIONS`)
    dims: Mapping[str, float | None] = field(default_factory=dict)
    keys: frozenset[str] = frozenset()

    @classmethod
    def parsed(cls, values: Mapping[str, Any]) -> HingeSpec:
        """The record of one hinge as `HINGES` parsed it (only the keys given)."""
        named = {k: values[k] for k in ("joints", "type", "k", "material", "Kt") if k in values}
        dims = MappingProxyType({d: values[d] for d in DIM_OPTIONS if d in values})
        return cls(**named, dims=dims, keys=frozenset(values))

    def over(self, base: HingeSpec | None) -> HingeSpec:
        """This hinge's keys over ``base`` (the mechanism's hinge of the same name)."""
        if base is None:
            return self
        named = {k: getattr(self, k) for k in ("joints", "type", "k", "material", "Kt") if k in self.keys}
        dims = MappingProxyType({**base.dims, **self.dims})
        return dataclasses.replace(base, **named, dims=dims, keys=base.keys | self.keys)


@dataclass(frozen=True, kw_only=True)
class JointStiffness(Part):
    """The compliant joints of a mechanism as its paper gives them (the part ``stiffness``),
    used by the compliance kinds as defaults that a problem file may override hinge by hinge
    (``inputs.hinges``).

    Attributes
    ----------
    hinges
        hinge name -> the same mapping a problem file gives under ``inputs.hinges``: ``joints``
        (a coordinate or family name of x, q or the passive joints, or a mapping axis -> name
        with axes bend, bend2, torsion, axial), ``k`` (N*m/rad on angles, N/m on lengths; one
        value or one per axis), and optionally a flexure ``type`` with its dimensions (see
        `HINGE_TYPES`) for the stresses and the stiffness of the axes k does not give.  Kept as
        written (``cpm-nlp describe`` shows it); parsed once, when declared, to `records`.
    material
        the hinge material, a name of `cpm_nlp.analysis.flexure.MATERIALS` or an inline mapping
        ``{name, E, nu, density, yield_strength, allowable}``; parsed once to `parsed_material`.
    source
        where the paper gives them (file, section, table).
    """

    capability: ClassVar[str] = "stiffness"

    hinges: Mapping[str, Mapping[str, Any]]
    material: Any = None
    source: str = ""
    #: flexible bodies by name, as a problem file's ``inputs.bodies`` (`cpm_nlp.analysis.beam_inputs`)
    bodies: Mapping[str, Mapping[str, Any]] | None = None
    #: hinge name -> its record (`HingeSpec`), parsed once from ``hinges``
    records: Mapping[str, HingeSpec] = field(init=False, repr=False, compare=False)
    #: the material, parsed once (None when not given)
    parsed_material: Material | None = field(init=False, repr=False, compare=False)
    #: body name -> its record, parsed once from ``bodies``
    body_records: Mapping[str, Any] = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        if not isinstance(self.hinges, Mapping) or not all(
            isinstance(k, str) and isinstance(v, Mapping) for k, v in self.hinges.items()
        ):
            raise MechanismDeclarationError(
                f"stiffness: hinges must map names to hinge mappings, got {self.hinges!r:.60}"
            )
        parsed = HINGES.parse(self.hinges, ("stiffness", "hinges"))
        records = MappingProxyType({g: HingeSpec.parsed(v) for g, v in parsed.items()})
        object.__setattr__(self, "records", records)
        mat = None if self.material is None else material(self.material, ("stiffness", "material"))
        object.__setattr__(self, "parsed_material", mat)
        object.__setattr__(self, "body_records", parse_bodies(self.bodies, ("stiffness", "bodies")))


def check_geometry(kind: str, d: Mapping[str, float], path: tuple) -> None:
    """Reject a hinge that cannot exist (t >= 2r for a circular notch: the two
    notches would not leave a thinnest section narrower than the blank), or a leaf's fillet
    outside its K_t fit (`check_leaf_fillet`)."""
    if kind == "leaf_spring":
        check_leaf_fillet(d, path)
    if kind in NOTCH_TYPES and d["t"] >= 2.0 * d["r"]:
        raise InputError(
            f"impossible circular notch: thickness t = {d['t'] * 1e3:g} mm must be below twice the notch radius "
            f"2r = {2 * d['r'] * 1e3:g} mm",
            path=path + ("t",),
        )


@dataclass
class Hinge:
    """One flexure of the mechanism: the joint coordinates it carries (axis ->
    index in (x, q, passive)), its stiffness per axis and its stress formula."""

    name: str
    group: str
    kind: str | None
    dims: dict[str, float]
    axes: dict[str, int]
    k: dict[str, float]
    material: Material | None
    source: str = ""
    #: the hinge formula's stiffness per axis (where type and material give it), beside k
    k_formula: dict[str, float] = field(default_factory=dict)

    def stress(self, deflection: Mapping[str, float]) -> float | None:
        """Largest nominal stress for the axis deflections (θ - θ0); None without geometry."""
        if self.kind is None:
            return None
        loads = {a: self.k[a] * deflection[a] for a in self.axes}
        return float(HINGE_TYPES[self.kind].stress(self.dims, loads))

    @property
    def kt(self) -> float | None:
        """The stress-concentration factor K_t on the nominal stress (peak = K_t × nominal):
        the hinge's ``Kt`` where given, else its type's published fit
        (`kt`), else 1; None without geometry."""
        if self.kind is None:
            return None
        if self.dims.get("Kt") is not None:
            return float(self.dims["Kt"])
        fit = HINGE_TYPES[self.kind].kt
        return 1.0 if fit is None else float(fit(self.dims))

    def angle_limit(self, axis: str, sigma_allow: float) -> float | None:
        """The deflection about one axis alone at which the hinge reaches sigma_allow."""
        if self.kind is None:
            return None
        unit = self.stress({a: (1.0 if a == axis else 0.0) for a in self.axes})
        return sigma_allow / unit if unit > 0 else None


@dataclass
class HingeSet:
    """The hinges of one model: stiffness k and rest values θ0 over the joint
    vector (x, q, passive), and the hinges for the stresses."""

    names: list[str]
    dims: list[str]
    k: np.ndarray
    theta0: np.ndarray
    hinges: list[Hinge]
    sigma_allow: float | None = None
    sources: list[str] = field(default_factory=list)
    #: material name -> (key path, message prefix) where it was given, for a message
    #: about it (the prefix names a mechanism file that declares it)
    material_at: dict[str, tuple[tuple, str]] = field(default_factory=dict)
    #: the flexible bodies (`cpm_nlp.analysis.beam_inputs.Body`): beams in the six-axis model
    bodies: list[Body] = field(default_factory=list)

    def moments(self, theta: np.ndarray) -> np.ndarray:
        return self.k * (np.asarray(theta, dtype=float) - self.theta0)

    def stresses(self, theta: np.ndarray) -> dict[str, float | None]:
        dev = np.asarray(theta, dtype=float) - self.theta0
        return {h.name: h.stress({a: float(dev[i]) for a, i in h.axes.items()}) for h in self.hinges}

    def peaks(self, stresses: Mapping[str, float | None]) -> dict[str, float | None]:
        """The peak stress K_t × nominal of each hinge (`Hinge.kt`), from its nominal stress."""
        kts = {h.name: h.kt for h in self.hinges}
        return {n: None if s is None else kts[n] * s for n, s in stresses.items()}

    def checked(self, stresses: Mapping[str, float | None], peak: bool) -> float | None:
        """The largest stress a stress limit checks: the nominal one (the papers'), or the peak."""
        vals = self.peaks(stresses) if peak else stresses
        return max((v for v in vals.values() if v is not None), default=None)


def joint_names(closure: LoopClosure) -> list[str]:
    return closure.x_names + closure.q_names + closure.passive_names


def _members(closure: LoopClosure, name: str, path: tuple) -> list[int]:
    coords = list(closure.x) + list(closure.q) + list(closure.passive_coords)
    exact = [i for i, c in enumerate(coords) if c.name == name]
    if exact:
        return exact
    fam = [i for i, c in enumerate(coords) if c.family == name]
    if fam:
        return fam
    known = sorted({c.name for c in coords} | {c.family for c in coords if c.family})
    raise InputError(
        f"unknown joint {name!r}; expected a coordinate or a family of {closure.name}: {', '.join(known)}",
        path=path,
        suggestions=suggest(name, known),
    )


def _stiffness_value(raw: Any, kind: str, path: tuple) -> float:
    """A hinge stiffness: positive, and within its dimension's sanity limit (1e9 N*m/rad,
    1e12 N/m), so that k * deflection^2 and the stresses stay finite."""
    dim = "rotational_stiffness" if kind == "angle" else "stiffness"
    return float(Option("k", dim, "hinge stiffness", lower=0.0, strict=True).parse(raw, path))


def _hinge_axes(closure: LoopClosure, joints: Any, path: tuple) -> dict[str, list[int]]:
    """axis -> the joint indices of a hinge's members (a name alone: the bending axis)."""
    if isinstance(joints, str):
        joints = {"bend": joints}
    if not joints:
        raise InputError(
            f"expected joints: a coordinate or family name, or a mapping axis -> name (axes: {', '.join(AXES)}), "
            f"got {joints!r}",
            path=path + ("joints",),
        )
    axes = {axis: _members(closure, str(jname), path + ("joints", axis)) for axis, jname in joints.items()}
    if len({len(v) for v in axes.values()}) != 1:
        raise InputError(
            "the joints of one hinge must have as many members each, got "
            + ", ".join(f"{a}: {len(v)}" for a, v in axes.items()),
            path=path + ("joints",),
        )
    return axes


def _hinge_dims(kind: str | None, spec: HingeSpec, path: tuple) -> dict[str, float]:
    """The dimensions of a hinge type (and its Kt), from a parsed hinge."""
    if kind is None:
        return {}
    t = HINGE_TYPES[kind]
    need, optional = t.dims, t.optional_dims
    if extra := [d for d in DIM_OPTIONS if d not in need + optional and spec.dims.get(d) is not None]:
        raise InputError(f"hinge type {kind} has no dimension {', '.join(extra)} (it takes {t.takes})", path=path)
    options = [DIM_OPTIONS[d] for d in need] + [dataclasses.replace(DIM_OPTIONS[d], default=None) for d in optional]
    dims = validate_mapping({d: spec.dims.get(d) for d in need + optional}, options, path, what="hinge dimension")
    dims = {d: v for d, v in dims.items() if v is not None}  # an optional dimension not given is absent
    check_geometry(kind, dims, path)
    if spec.Kt is not None:  # else the type's published fit (Hinge.kt)
        dims["Kt"] = float(spec.Kt)
    return dims


def _given_stiffness(raw_k: Any, axes: Mapping[str, Any], path: tuple) -> dict[str, Any]:
    """axis -> the stiffness given (as written) for it."""
    if isinstance(raw_k, Mapping):
        for a in raw_k:
            if a not in axes:
                raise InputError(
                    f"stiffness given for axis {a!r}, which this hinge does not use (its axes: {', '.join(axes)})",
                    path=path + ("k", str(a)),
                )
        return dict(raw_k)
    if raw_k is None:
        return {}
    if len(axes) != 1:
        raise InputError(
            f"this hinge has {len(axes)} axes ({', '.join(axes)}); give k per axis, e.g. k: {{bend: ...}}",
            path=path + ("k",),
        )
    return {next(iter(axes)): raw_k}


def _parse_hinge(
    closure: LoopClosure, gname: str, spec: HingeSpec, default_material: Material | None, path: tuple
) -> list[Hinge]:
    """The hinges of one parsed hinge entry (`HingeSpec`): one per member of its joints."""
    axes = _hinge_axes(closure, spec.joints, path)
    coords = list(closure.x) + list(closure.q) + list(closure.passive_coords)
    kind = spec.type
    dims = _hinge_dims(kind, spec, path)
    mat = default_material if spec.material is None else material(spec.material, path + ("material",))
    # stiffness: given per axis (or one value for a one-axis hinge), else the hinge formula
    raw_k = spec.k
    given = _given_stiffness(raw_k, axes, path)
    formula: dict[str, float] = {}
    if kind is not None and any(a not in given for a in axes) and mat is None:
        raise InputError(
            f"hinge {gname}: its stiffness needs a material (or k for every axis)", path=path + ("material",)
        )
    if kind is not None and mat is not None and mat.E is not None:
        G = mat.G if mat.nu is not None else None
        formula = {a: float(v) for a, v in HINGE_TYPES[kind].stiffness(mat.E, G, dims).items()}
    out: list[Hinge] = []
    n = len(next(iter(axes.values())))
    for m in range(n):
        idx = {a: v[m] for a, v in axes.items()}
        k: dict[str, float] = {}
        for a, i in idx.items():
            if a in given:
                sub = path + ("k", a) if isinstance(raw_k, Mapping) else path + ("k",)
                k[a] = _stiffness_value(given[a], coords[i].kind, sub)
            elif a in formula:
                k[a] = float(formula[a])
            else:
                why = "a hinge type (and material)" if kind is None else "nu in the material"
                raise InputError(
                    f"hinge {gname}: no stiffness about {a} ({AXIS_TEXT[a]}); give k.{a} or {why}", path=path
                )
        name = gname if n == 1 else f"{gname}{m + 1}"
        src = HINGE_TYPES[kind].source if kind else "given k"
        out.append(Hinge(name, gname, kind, dims, idx, k, mat, src, {a: formula[a] for a in idx if a in formula}))
    return out


def parse_hinges(
    closure: LoopClosure, specs: Mapping[str, HingeSpec], mat: Material | None, paths: Mapping[str, tuple]
) -> tuple[np.ndarray, list[Hinge]]:
    """The hinges of ``specs`` (name -> hinge record) on a closure: the stiffness over
    the joint vector (x, q, passive) and the hinges; ``paths`` gives each hinge's key
    path for the messages.  A joint may carry one hinge only."""
    names = joint_names(closure)
    k = np.zeros(len(names))
    out: list[Hinge] = []
    for gname, spec in specs.items():
        hpath = paths[gname]
        for h in _parse_hinge(closure, gname, spec, mat, hpath):
            for a, i in h.axes.items():
                if k[i] != 0.0:
                    raise InputError(f"joint {names[i]} carries two hinges", path=hpath + ("joints", a))
                k[i] = h.k[a]
            out.append(h)
    return k, out


def check_declared(
    closure: LoopClosure, hinges: Mapping[str, Any], material_spec: Any, path: tuple, bodies: Any = None
) -> None:
    """Check a mechanism's declared hinges and material (its part ``stiffness``)
    against its closure, by the rules of a problem file's ``inputs.hinges``: joints
    that name coordinates or families, known hinge types and keys, possible geometry,
    a known material.  Key paths under ``path`` (``stiffness`` of a mechanism file)."""
    mat = None if material_spec is None else material(material_spec, path + ("material",))
    parsed = {g: HingeSpec.parsed(v) for g, v in HINGES.parse(hinges, path + ("hinges",)).items()}
    parse_hinges(closure, parsed, mat, {g: path + ("hinges", g) for g in parsed})
    specs = {n: b for n, b in parse_bodies(bodies, path + ("bodies",)).items() if b is not None}
    bodies_of(closure, specs, mat, {n: path + ("bodies", n) for n in specs})


def hinge_set(
    model: Model,
    hinges: Mapping[str, Any] | None,
    material_spec: Any = None,
    sigma_allow: float | None = None,
    path: tuple = ("inputs",),
    bodies: Any = None,
) -> HingeSet:
    """The hinges of a model: the mechanism's declared defaults (its part ``stiffness``,
    parsed when it was declared) merged, hinge by hinge and key by key, with ``hinges`` from
    the problem file (as written or parsed by `HINGES`); ``material_spec`` overrides
    the default material."""
    c = model.closure
    mech = model.mechanism
    decl = mech.part(JointStiffness) if mech is not None else None
    given = HINGES.parse(hinges, path + ("hinges",)) if hinges is not None else {}
    merged: dict[str, HingeSpec] = dict(decl.records) if decl else {}
    for name, spec in given.items():
        if spec is None:  # null removes a default hinge
            merged.pop(name, None)
        else:
            merged[name] = HingeSpec.parsed(spec).over(merged.get(name))
    if not merged:
        raise InputError(
            f"mechanism {model.name} declares no joint stiffness; give inputs.hinges "
            "(name -> {joints: <coordinate or family>, k: ... or a hinge type with its dimensions})",
            path=path + ("hinges",),
        )
    mat = None
    if material_spec is not None:
        mat = material(material_spec, path + ("material",))
    elif decl is not None:
        mat = decl.parsed_material
    paths = {g: path + ("hinges", g) if g in given else ("mechanism", "stiffness", g) for g in merged}
    k, out = parse_hinges(c, merged, mat, paths)
    coords = list(c.x) + list(c.q) + list(c.passive_coords)
    names = joint_names(c)
    theta0 = joint_vector(model, model.x_home, model.q_home)
    hs = HingeSet(names, [co.kind for co in coords], k, theta0, out, sigma_allow, [decl.source] if decl else [])
    hs.material_at = _material_at(mech, out, merged, given, material_spec, path)
    hs.bodies = merged_bodies(c, decl.body_records if decl else {}, bodies, mat, path)
    return hs


def _material_at(mech: Any, out: list[Hinge], merged: Mapping, hinges: Any, material_spec: Any, path: tuple) -> dict:
    """Where each hinge material was given: the problem file's key, or a mechanism file's
    ``stiffness`` section (named in the message, as the problem file holds no such key)."""
    origin = mech.origin if mech is not None else None

    def declared(*keys: str) -> tuple[tuple, str] | None:
        if origin is not None and origin.kind == "file":
            return ("mechanism", "file"), f"in the mechanism file {origin.path}: stiffness.{'.'.join(keys)}: "
        return None

    default = (path + ("material",), "")
    if material_spec is None:
        default = declared("material") or default
    at: dict[str, tuple[tuple, str]] = {}
    for h in out:
        if h.material is None:
            continue
        where = default
        if h.group in merged and merged[h.group].material is not None:
            given = hinges.get(h.group) if isinstance(hinges, Mapping) else None
            if isinstance(given, Mapping) and given.get("material") is not None:
                where = (path + ("hinges", h.group, "material"), "")
            else:
                where = declared("hinges", h.group, "material") or (("mechanism", "stiffness", h.group, "material"), "")
        at.setdefault(h.material.name, where)
    return at


def allowable(hs: HingeSet, sigma_allow: float | None, safety_factor: float, path: tuple) -> float:
    """σ_allow: sigma_allow / safety_factor when given; else, with a safety factor above 1,
    the hinge material's yield strength / safety_factor; else the material's allowable
    (design) stress, which already holds its source's safety factor, or its yield strength.
    The smallest over the hinge materials."""
    if sigma_allow is not None:
        return sigma_allow / safety_factor
    mats = {h.material.name: h.material for h in hs.hinges if h.material is not None and h.kind is not None}
    if not mats:
        raise InputError("a stress limit needs sigma_allow or a hinge material", path=path + ("sigma_allow",))
    values = []
    why = "a stress limit needs it (or give sigma_allow)"
    for name, m in mats.items():
        if safety_factor > 1 or m.allowable is None:
            where, prefix = hs.material_at.get(name, (path + ("material",), ""))
            try:
                values.append(m.require("yield_strength", where, why) / safety_factor)
            except InputError as exc:
                raise InputError(prefix + exc.message, path=exc.path) from None
        else:
            values.append(m.allowable)
    return min(values)


def joint_vector(model: Model, x: np.ndarray, q: np.ndarray) -> np.ndarray:
    """(x, q, passive) at one pose."""
    c = model.closure
    parts = [np.asarray(x, dtype=float).ravel(), np.asarray(q, dtype=float).ravel()]
    if c.passive is not None:
        parts.append(np.asarray(c.passive(x, q, model.p), dtype=float).ravel())
    return np.concatenate(parts)


# -- CasADi functions, built once per mechanism type --------------------------------------------------


@functools.lru_cache(maxsize=16)
def energy_function(closure: LoopClosure) -> ca.Function:
    """``("pseudo_rigid_body", [x, q, p, k, theta0, f], [V, F, K_q, J, theta])``: the
    energy V = U - fᵀx, the actuator forces F, the input stiffness K_q, the
    forward Jacobian J and the joint vector θ = (x, q, passive), all symbolic
    (the reference `static_point` is checked against; slower, as the
    symbolic Φ_x⁻¹ grows the expression)."""
    c = closure
    x, q, p = ca.SX.sym("x", c.nx), ca.SX.sym("q", c.nq), ca.SX.sym("p", c.np)
    n = c.nx + c.nq + len(c.passive_coords)
    k, th0, f = ca.SX.sym("k", n), ca.SX.sym("theta0", n), ca.SX.sym("f", c.nx)
    theta = _theta(c, x, q, p)
    d = theta - th0
    V = 0.5 * ca.dot(k, d * d) - ca.dot(f, x)
    J = c.jacobian(x, q, p)
    F = ca.gradient(V, q) + J.T @ ca.gradient(V, x)
    Kq = ca.jacobian(F, q) + ca.jacobian(F, x) @ J
    return ca.Function(
        "pseudo_rigid_body",
        [x, q, p, k, th0, f],
        [V, F, Kq, J, theta],
        ["x", "q", "p", "k", "theta0", "f"],
        ["V", "F", "K_q", "J", "theta"],
    )


def _theta(c: LoopClosure, x: Any, q: Any, p: Any) -> Any:
    return ca.vertcat(*([x, q] + ([c.passive(x, q, p)] if c.passive is not None else [])))


@functools.lru_cache(maxsize=16)
def energy_parts(closure: LoopClosure) -> Any:
    """The derivatives the reduced quantities need, over z = (x, q):
    ``("pseudo_rigid_body_parts", [x, q, p, k, theta0, f], [V, dV, d2V, dPhi, d2Phi, theta])``
    with d2Phi the Hessians of the nx residuals stacked.  With λ = Φ_x⁻ᵀ V_x (adjoint),
    F = V_q - Φ_qᵀ λ and K_q = Zᵀ (∇²V - Σ λ_i ∇²Φ_i) Z, Z = [J; I] (the reduced
    Hessian of V(x(q), q)); the small linear algebra is done in numpy.  Wrapped for
    fast calls (`FastFunction`)."""
    c = closure
    x, q, p = ca.SX.sym("x", c.nx), ca.SX.sym("q", c.nq), ca.SX.sym("p", c.np)
    n = c.nx + c.nq + len(c.passive_coords)
    k, th0, f = ca.SX.sym("k", n), ca.SX.sym("theta0", n), ca.SX.sym("f", c.nx)
    z = ca.vertcat(x, q)
    theta = _theta(c, x, q, p)
    d = theta - th0
    V = 0.5 * ca.dot(k, d * d) - ca.dot(f, x)
    dV, d2V = ca.gradient(V, z), ca.hessian(V, z)[0]
    phi = c.phi(x, q, p)
    dphi = ca.jacobian(phi, z)
    d2phi = ca.vertcat(*[ca.hessian(phi[i], z)[0] for i in range(c.nx)])
    fn = ca.Function(
        "pseudo_rigid_body_parts",
        [x, q, p, k, th0, f],
        [ca.densify(e) for e in (V, dV, d2V, dphi, d2phi, theta)],
        ["x", "q", "p", "k", "theta0", "f"],
        ["V", "dV", "d2V", "dPhi", "d2Phi", "theta"],
    )
    return FastFunction(fn)


@dataclass
class StaticPoint:
    """Actuator forces, input stiffness and hinge stresses at one pose."""

    x: np.ndarray
    q: np.ndarray
    F: np.ndarray
    K_q: np.ndarray
    J: np.ndarray
    theta: np.ndarray
    energy: float
    stresses: dict[str, float | None]

    @property
    def stress_max(self) -> float | None:
        vals = [s for s in self.stresses.values() if s is not None]
        return max(vals) if vals else None


def static_point(model: Model, hs: HingeSet, x, q, f=None) -> StaticPoint:
    """Forces, stiffness and stresses at a solved pose (x, q) under the load f (nx)."""
    c = model.closure
    nx, nq = c.nx, c.nq
    nz = nx + nq
    load = np.zeros(nx) if f is None else np.asarray(f, dtype=float)
    V, dV, d2V, dphi, d2phi, theta = energy_parts(c)(x, q, model.p, hs.k, hs.theta0, load)
    d2V = d2V.reshape(nz, nz, order="F")
    dphi = dphi.reshape(nx, nz, order="F")
    # the stacked Hessians, (nx nz) x nz column-major: flat index i*nz + a + b*nx*nz -> [b, a, i]
    d2phi = d2phi.reshape(nz, nx, nz).transpose(0, 2, 1)
    phi_x, phi_q = dphi[:, :nx], dphi[:, nx:]
    inv = np.linalg.inv(phi_x)
    J = -inv @ phi_q
    lam = inv.T @ dV[:nx]
    F = dV[nx:] - phi_q.T @ lam
    H = d2V - d2phi @ lam  # Hessians are symmetric, so [b, a] = [a, b]
    Z = np.empty((nz, nq))
    Z[:nx], Z[nx:] = J, np.eye(nq)
    Kq = Z.T @ H @ Z
    return StaticPoint(
        np.asarray(x, dtype=float),
        np.asarray(q, dtype=float),
        F,
        0.5 * (Kq + Kq.T),
        J,
        theta,
        float(V[0]),
        hs.stresses(theta),
    )


def output_compliance(sp: StaticPoint, k_actuator: np.ndarray | None) -> np.ndarray:
    """C_x = J (K_q + K_a)⁻¹ Jᵀ (nx x nx); k_actuator None: positions held (C = 0)."""
    nx = sp.J.shape[0]
    if k_actuator is None:
        return np.zeros((nx, nx))
    K = sp.K_q + np.diag(k_actuator)
    if np.linalg.cond(K) > 1e12:
        raise np.linalg.LinAlgError("K_q + K_a is singular")
    return sp.J @ np.linalg.solve(K, sp.J.T)


@functools.lru_cache(maxsize=16)
def compliant_fk_solver(closure: LoopClosure) -> ca.Function:
    """IPOPT: min_{x,q} U - fᵀx + ½ Σ ka (q - qc)² - Fcᵀ(q - qc) s.t. Φ(x, q; p) = 0,
    with parameters (qc, p, k, theta0, f, ka, Fc); scaled by ``scale`` (a stiffness)."""
    c = closure
    x, q = ca.SX.sym("x", c.nx), ca.SX.sym("q", c.nq)
    p = ca.SX.sym("p", c.np)
    n = c.nx + c.nq + len(c.passive_coords)
    k, th0, f = ca.SX.sym("k", n), ca.SX.sym("theta0", n), ca.SX.sym("f", c.nx)
    qc, ka, Fc = ca.SX.sym("qc", c.nq), ca.SX.sym("ka", c.nq), ca.SX.sym("Fc", c.nq)
    scale = ca.SX.sym("scale")
    theta = ca.vertcat(*([x, q] + ([c.passive(x, q, p)] if c.passive is not None else [])))
    d = theta - th0
    dq = q - qc
    V = 0.5 * ca.dot(k, d * d) - ca.dot(f, x) + 0.5 * ca.dot(ka, dq * dq) - ca.dot(Fc, dq)
    nlp = {
        "x": ca.vertcat(x, q),
        "p": ca.vertcat(qc, p, k, th0, f, ka, Fc, scale),
        "f": V / scale,
        "g": c.phi(x, q, p),
    }
    opts = {
        "ipopt.print_level": 0,
        "print_time": False,
        "ipopt.sb": "yes",
        "ipopt.tol": 1e-12,
        "ipopt.constr_viol_tol": 1e-13,
        "ipopt.hessian_approximation": "exact",
    }
    return ca.nlpsol(f"{c.name}_compliant_fk", "ipopt", nlp, opts)


@dataclass
class CompliantPose:
    ok: bool
    x: np.ndarray
    q: np.ndarray
    message: str
    iterations: int


def compliant_fk(
    model: Model, hs: HingeSet, x_c, q_c, F_c, f, k_actuator: np.ndarray | None, tol: float = 1e-10
) -> CompliantPose:
    """The loaded pose from the unloaded commanded pose (x_c, q_c) whose actuator
    forces are F_c; k_actuator None holds the positions."""
    c = model.closure
    solver = compliant_fk_solver(c)
    ka = np.zeros(c.nq) if k_actuator is None else np.asarray(k_actuator, dtype=float)
    scale = max(float(np.max(hs.k)), 1e-300)
    # no bounds: the loaded pose stays next to the commanded one (checked on the branch
    # afterwards), and without inequalities IPOPT runs as a plain Newton-SQP (no barrier)
    lbx = np.full(c.nx + c.nq, -np.inf)
    ubx = np.full(c.nx + c.nq, np.inf)
    if k_actuator is None:
        lbx[c.nx :] = ubx[c.nx :] = q_c
    par = np.concatenate([q_c, model.p, hs.k, hs.theta0, f, ka, F_c, [scale]])
    sol = solver(x0=np.concatenate([x_c, q_c]), p=par, lbx=lbx, ubx=ubx, lbg=0.0, ubg=0.0)
    stats = solver.stats()
    z = np.asarray(sol["x"], dtype=float).ravel()
    x, q = z[: c.nx], z[c.nx :]
    res = float(np.max(np.abs(np.asarray(c.phi(x, q, model.p), dtype=float)))) if c.nx else 0.0
    ok = bool(stats.get("success", False)) and res <= tol
    msg = stats.get("return_status", "") + (f"; residual {res:.3g}" if res > tol else "")
    if ok and c.branch is not None:
        g = np.asarray(c.branch(x, q, model.p), dtype=float).ravel()
        if not np.all(g > 0):
            ok, msg = False, msg + "; the loaded pose left the assembly branch"
    return CompliantPose(ok, x, q, msg, int(stats.get("iter_count", 0)))
