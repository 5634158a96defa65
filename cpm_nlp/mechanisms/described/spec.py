"""The description of a mechanism: dataclasses (the Python builder API); a mechanism
file is read into them by `read.description_from_dict`.

A mechanism file::

    name: my_stage                     # the type name (an identifier)
    title: one line
    parameters:                        # declared like the built-ins' options
      b: {dimension: length, default: 47.91 mm, bounds: [0 mm, 1 m], description: ...}
    derived:                           # named expressions of the parameters
      a: b + L*cos(alpha0)
    platform:
      coordinates: {px: length, ..., psi: angle}
      position: [px, py, pz]           # P, an expression over the coordinates
      rotation: [[y, theta], [x, psi], [z, phi]]   # R = Ry(theta) Rx(psi) Rz(phi)
      task: [pz, psi, theta]           # nq of them; the others are dependent (reported)
      fixed: {}                        # coordinates fixed by the structure: name -> value
      home: {pz: L*sin(alpha0)}        # the reference pose (others 0)
    legs:
      - name: leg
        repeat: {index: i, values: [1, 2, 3], rotate: 2*pi*(i-1)/3}
        joints:                        # base -> platform, at the reference pose
          - {type: P, at: [a, 0, 0], axis: [-1, 0, 0], actuated: "s{i}"}
          - {type: R, at: [a, 0, 0], axis: [0, -1, 0], coordinates: ["alpha{i}"], home: [alpha0]}
          - {type: S, at: [b, 0, L*sin(alpha0)], coordinates: ["bm{i}", "bn{i}", "bl{i}"]}

Every location and axis is a vector expression in the parameters, in the base
frame at the reference configuration (the home pose).  See the README for the
full list of keys.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from ...analysis.compliance import JointStiffness
from ...core.options import REQUIRED

DIMENSIONS = ("length", "angle", "dimensionless")
AXES = ("x", "y", "z")
#: the names the ground body may take
GROUND_NAMES = ("ground", "base")

Expr = Any  # an expression: a string, a number, or a list of them (a vector)


@dataclass
class Parameter:
    """A geometry parameter (declared like a built-in mechanism's options)."""

    name: str
    dimension: str = "length"
    default: Any = REQUIRED
    lower: float | None = None
    upper: float | None = None
    description: str = ""
    #: the bounds exclude their ends (``strict: true``, as a built-in option's ``strict=True``)
    strict: bool = False


@dataclass
class Quantity:
    """A named expression with its dimension (derived values, reported passive coordinates)."""

    name: str
    value: Expr
    dimension: str | None = None
    description: str = ""
    family: str = ""


@dataclass
class Flexure:
    """A flexure hinge that sets a joint's limits: hinge type, dimensions, material
    (the keys of `cpm_nlp.analysis.hinge_types.HINGE_LIMIT_OPTIONS`)."""

    values: dict[str, Any]


@dataclass
class Joint:
    """One joint of a leg, base side first.

    Attributes
    ----------
    at
        its location (vector expression, base frame, reference configuration); for ``distance``
        the point on the proximal body, ``to`` the one on the distal.
    axis
        its axis (R, P, C, planar_P);
    axes
        the two axes of a U, the three axes an S reports its angles about (default x, y, z).
    actuated
        the actuator coordinate driving it (a name), with ``gain`` (displacement per actuator
        unit) and ``home`` (the actuator value at the reference configuration).
    coordinates
        names of its reported joint values (one per degree of freedom), ``home`` their values at
        the reference configuration.
    limit
        the limit family of its coordinates (default: the name without digits).
    """

    type: str
    at: Expr = None
    to: Expr = None
    axis: Expr = None
    axes: tuple[Expr, ...] = ()
    actuated: str | None = None
    gain: Expr = 1
    home: tuple[Expr, ...] = ()
    coordinates: tuple[str, ...] = ()
    limit: str | None = None
    range: tuple[Any, Any] | None = None
    flexure: Flexure | None = None
    body: str | None = None  # the body it carries (distal side); optional, for connectivity checks
    path: tuple = ()
    #: a joint of a bodies-and-joints file: its name, the two bodies it joins (proximal first)
    #: and, for a distance joint, the rod's length (default: the distance in the drawing)
    name: str | None = None
    between: tuple[str, ...] = ()
    length: Expr = None


@dataclass
class Leg:
    """A serial chain from the base to the platform, optionally repeated: the
    ``index`` symbol takes each of ``values`` and every vector of the leg is
    turned by ``rotate`` (an angle expression in the index) about ``rotate_axis``."""

    name: str
    joints: list[Joint]
    index: str | None = None
    values: tuple[Any, ...] = ()
    rotate: Expr = None
    rotate_axis: str = "z"
    path: tuple = ()
    #: definitions of the leg (name -> expression, in order; may use the index)
    let: dict[str, Expr] = field(default_factory=dict)


@dataclass
class Platform:
    coordinates: dict[str, str]
    position: Expr
    rotation: list[tuple[str, Expr]]
    task: tuple[str, ...]
    fixed: dict[str, Expr] = field(default_factory=dict)
    home: dict[str, Expr] = field(default_factory=dict)
    bounds: dict[str, tuple[Expr, Expr]] = field(default_factory=dict)
    descriptions: dict[str, str] = field(default_factory=dict)
    planar: bool = False
    offsets: dict[str, str] = field(default_factory=dict)
    #: a bodies-and-joints file: the body whose frame the pose coordinates locate, and its point
    #: that ``position`` locates (None: the body's frame origin, the world origin in the drawing)
    body: str | None = None
    point: str | None = None
    #: the platform coordinates place the platform body (a legs file expanded into bodies and
    #: joints, `expand`): its pose is P(x), R(x) R_home^T, the legs close on it
    placed: bool = False


@dataclass
class Body:
    """A rigid body of a bodies-and-joints file: its named points in the drawing (world frame at
    the drawing configuration, which is also the body's own frame); None: the global point."""

    name: str
    points: dict[str, Expr]
    description: str = ""
    path: tuple = ()


@dataclass
class ClosedFormIK:
    """A closed-form inverse kinematics: ``let`` definitions in order, the
    dependent coordinates and the actuators as expressions of the task
    coordinates, and ``reach`` (< 0 when the pose cannot be assembled)."""

    let: dict[str, Expr]
    pose: dict[str, Expr]
    actuators: dict[str, Expr]
    reach: Expr = None


@dataclass
class Description:
    """A whole mechanism, as a file describes it (also built in code)."""

    name: str
    title: str
    parameters: list[Parameter]
    platform: Platform
    legs: list[Leg] = field(default_factory=list)
    derived: list[Quantity] = field(default_factory=list)
    #: actuators declared without joints: name -> (dimension, value at the reference configuration)
    actuators: dict[str, tuple[str, Expr]] = field(default_factory=dict)
    closures: list[Expr] = field(default_factory=list)
    #: the branch indicators: None (absent) the generated ones; a list: exactly these (an item is a
    #: generated indicator's name, an expression, or {name: expression}; [] none); a mapping
    #: {keep, remove, add}: the generated ones filtered and extended (see `read._branch`)
    branch: list[Any] | dict[str, Any] | None = None
    passive: list[Quantity] = field(default_factory=list)
    ik: ClosedFormIK | None = None
    characteristic_length: Expr = None
    paper: str = ""
    examples: tuple[str, ...] = ()
    #: joint-limit family -> its description (what ``describe`` and the error messages call it)
    limits: dict[str, str] = field(default_factory=dict)
    #: the compliant joints (hinges, material, source): the compliance kinds' defaults
    stiffness: JointStiffness | None = None
    file: str | None = None
    #: a bodies-and-joints file (see `graph`): the drawing's named points, the bodies, the
    #: joints between any two of them, and points of any body reported as outputs (name -> (body, point))
    points: dict[str, Expr] = field(default_factory=dict)
    bodies: list[Body] = field(default_factory=list)
    joints: list[Joint] = field(default_factory=list)
    outputs: dict[str, tuple[str, str, str]] = field(default_factory=dict)

    @property
    def is_graph(self) -> bool:
        """Whether the mechanism is a graph of bodies and joints (not legs)."""
        return bool(self.bodies)
