"""What every generator of a loop closure shares (the legs' `Generator`, the
graph's `GraphGenerator`): the parameters and derived values, expressions read
in an environment of symbols, the platform's pose coordinates, the actuators, the joint values
made unknowns or reported, their names and their limits (the declared joint-limit options)."""

from __future__ import annotations

import re
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import casadi as ca

from ...analysis import hinge_types
from ...core.errors import InputError, format_key_path
from ...core.joints import JOINT_TYPES
from ...core.model import Coordinate
from ...core.options import Option, validate_mapping
from ...core.units import parse_quantity
from . import expr as ex
from .motions import JOINT_DIMS, ResolvedJoint, rot
from .spec import Description, Joint, Leg


@dataclass
class Reported:
    """A reported joint value (not a pose coordinate): its coordinate, its expression of (x, q, p),
    its default limits and the key path of what declares it."""

    coord: Coordinate
    value: ca.SX
    limit: tuple | None = None
    path: tuple = ()


def family(name: str) -> str:
    """The limit family of a coordinate name: the name less its trailing digits (``s1`` -> ``s``)."""
    return re.sub(r"\d+$", "", name) or name


class ClosureBuilder:
    """The state and the shared steps of building the symbolic closure of one description (errors
    carry key paths); a generator adds its own topology (legs, or bodies and joints)."""

    def __init__(self, d: Description) -> None:
        self.d = d
        self.p = ca.SX.sym("p", len(d.parameters))
        self.env: dict[str, ex.Value] = {}
        for k, par in enumerate(d.parameters):
            if par.name in ex.RESERVED:
                raise InputError(f"{par.name!r} is a function or constant name", path=("parameters", par.name))
            self.env[par.name] = ex.Value(self.p[k], ex.DIMENSION_OF[par.dimension])
        self.derived: list[tuple[str, ca.SX, str]] = []
        for q in d.derived:
            v = self.value(q.value, ("derived", q.name), self.env, q.dimension)
            self.bind(self.env, q.name, v, ("derived", q.name))
            self.derived.append((q.name, v.sx, q.dimension or dim_name(v.dim)))
        self.reported: list[Reported] = []
        self.rows: list[tuple[ca.SX, str]] = []
        #: the assembly-branch indicators: (expression, name, what it measures)
        self.branch: list[tuple[ca.SX, str, str]] = []
        #: eliminated links whose indicator waits for Φ_x: (position in branch, rows, working mode, what)
        self.pending: list[tuple[int, list[int], ca.SX | None, str]] = []
        self.q_coords: list[Coordinate] = []
        self.q_syms: list[ca.SX] = []
        self.q_home: list[ca.SX] = []
        self.q_limits: dict[str, tuple] = {}
        self.platform_radius: list[ca.SX] = []
        #: (quantity that must vanish at the reference configuration, what it means, key path)
        self.requirements: list[tuple[ca.SX, str, tuple]] = []
        #: passive joints of the proximal chains: (coordinate, symbol, home value, limit, key path)
        self.extra: list[tuple] = []
        self.extra_limits: dict[str, tuple] = {}
        #: each leg's resolved joints, base first (for the chains of the six-axis hinge model)
        self.leg_joints: list[tuple[Leg, list[ResolvedJoint]]] = []
        #: per leg, for the drawing: (leg name, [(joint letter, location at the pose, actuated, slides)])
        self.drawn: list[tuple[str, list[tuple[str, ca.SX, bool, bool]]]] = []

    # -- expressions -----------------------------------------------------------------------
    def value(self, text: Any, path: tuple, env: Mapping[str, ex.Value], dimension: str | None = None) -> ex.Value:
        try:
            v = ex.parse(text, env)
        except ex.ExpressionError as exc:
            shown = "[" + ", ".join(str(t) for t in text) + "]" if isinstance(text, list) else str(text)
            if len(shown) > 80:  # the message, not the expression, must fit in the line
                shown = f"{shown[:60]}... ({len(shown) - 60} more characters)"
            hint = None
            if "never closed" in exc.message:
                hint = "inside a YAML [list] or {mapping}, quote an expression that contains a comma"
            if len(shown) > 80:  # the reason must fit in the one message line
                shown = shown[:60] + f"... ({len(shown)} characters)"
            raise InputError(f"in {shown!r}: column {exc.column}: {exc.message}", path=path, hint=hint) from None
        if dimension is None:
            return v
        want = ex.DIMENSION_OF[dimension]
        if not (ex.adapts(v) or ex.compatible(v.dim, want)):
            raise InputError(f"expected {ex.describe(want)}, got {ex.describe(v.dim)} in {text!r}", path=path)
        # the declared dimension is the value's (a bare number is SI of it; a plain number an angle in rad)
        return ex.Value(v.sx, want)

    def scalar(self, text: Any, path: tuple, env: Mapping[str, ex.Value], dimension: str | None = None) -> ca.SX:
        v = self.value(text, path, env, dimension)
        if v.size != 1:
            raise InputError(f"expected a scalar, got a vector of {v.size} in {text!r}", path=path)
        return v.sx

    def vector(self, text: Any, path: tuple, env: Mapping[str, ex.Value], dimension: str | None) -> ca.SX:
        v = self.value(text, path, env, dimension)
        n = 2 if self.d.platform.planar else 3
        if v.size != n:
            raise InputError(f"expected a vector of {n} elements, got {v.size} in {text!r}", path=path)
        return ca.vertcat(v.sx, 0) if n == 2 else v.sx

    @staticmethod
    def bind(env: dict, name: str, v: ex.Value, path: tuple) -> None:
        if name in env or name in ex.RESERVED:
            raise InputError(f"the name {name!r} is already taken (a parameter, coordinate or function)", path=path)
        env[name] = v

    # -- platform ----------------------------------------------------------------------------
    def platform(self) -> None:
        pf = self.d.platform
        for t in pf.task:
            if t in pf.fixed:
                raise InputError(f"{t!r} is both a task coordinate and fixed", path=("platform", "task"))
        self.x_names = [c for c in pf.coordinates if c not in pf.fixed]
        self.x_coords = [
            Coordinate(n, pf.coordinates[n], pf.descriptions.get(n, "platform coordinate")) for n in self.x_names
        ]
        self.x = ca.SX.sym("x", len(self.x_names))
        self.xenv = dict(self.env)
        for k, name in enumerate(self.x_names):
            self.bind(
                self.xenv,
                name,
                ex.Value(self.x[k], ex.DIMENSION_OF[pf.coordinates[name]]),
                ("platform", "coordinates", name),
            )
        for name, text in pf.fixed.items():
            v = self.value(text, ("platform", "fixed", name), self.env, pf.coordinates[name])
            self.bind(self.xenv, name, v, ("platform", "fixed", name))
        if self.d.is_graph and pf.position == []:  # the platform body's point is the position (graph)
            self.P = None
        else:
            self.P = self.vector(pf.position, ("platform", "position"), self.xenv, "length")
        R = ca.SX.eye(3)
        for k, (axis, angle) in enumerate(pf.rotation):
            if pf.planar and axis != "z":
                raise InputError("a planar platform turns about z only", path=("platform", "rotation", k))
            R = R @ rot(axis, self.scalar(angle, ("platform", "rotation", k, 1), self.xenv, "angle"))
        self.R = R
        home = []
        for name in self.x_names:
            text = pf.home.get(name, 0)
            home.append(self.scalar(text, ("platform", "home", name), self.env, pf.coordinates[name]))
        self.x_home = ca.vertcat(*home)
        self.P_home = ca.SX.zeros(3) if self.P is None else ca.substitute(self.P, self.x, self.x_home)
        self.R_home = ca.substitute(self.R, self.x, self.x_home)

    def platform_point(self, B0: ca.SX) -> ca.SX:
        """The platform point that is at B0 at the reference pose, at the pose x."""
        self.platform_radius.append(ca.norm_2(B0 - self.P_home))
        return self.P + self.R @ self.R_home.T @ (B0 - self.P_home)

    # -- actuators -------------------------------------------------------------------------
    def actuator(self, j: Joint, env: Mapping[str, ex.Value]) -> ca.SX:
        name = j.actuated
        if name in [c.name for c in self.q_coords]:
            raise InputError(f"actuator {name!r} drives two joints", path=j.path + ("actuated",))
        dim = JOINT_DIMS.get(j.type)
        if not JOINT_TYPES[j.type].actuable:
            can = ", ".join(n for n, t in JOINT_TYPES.items() if t.actuable)
            raise InputError(f"a {j.type} joint cannot be actuated ({can} can)", path=j.path + ("actuated",))
        fam = j.limit or family(name)
        self.q_coords.append(Coordinate(name, dim, f"actuator of the {j.type} joint at {format_key_path(j.path)}", fam))
        sym = ca.SX.sym(name)
        self.q_syms.append(sym)
        home = j.home[0] if j.home else 0
        qh = self.scalar(home, j.path + ("home",), env, dim)
        self.q_home.append(qh)
        gain = self.scalar(j.gain, j.path + ("gain",), env, "dimensionless")
        if j.range is not None and fam not in self.q_limits:
            self.q_limits[fam] = (dim, j.range, j.path + ("range",))
        return gain * (sym - qh)

    #: |det| of an S joint's three unit axes below which they count as linearly dependent
    DEPENDENT_AXES = 1e-6

    def independent_axes(self, axes: list, path: tuple) -> None:
        """An S joint's three axes span space: its angles about them (and its motion as three
        revolutes) need three independent directions.  Axes that depend on the parameters are
        checked with the parameters' values (a requirement of the reference configuration)."""
        det = ca.det(ca.horzcat(*axes))
        text = "the S joint's three axes are linearly dependent (parallel or in one plane)"
        if det.is_constant():
            value = float(ca.DM(det))
            if not abs(value) > self.DEPENDENT_AXES:
                raise InputError(
                    f"expected three independent axes, got axes whose triple product is {value:.3g}: {text}; "
                    "give three directions that span space (default: x, y, z)",
                    path=path,
                )
            return
        text = f"expected three independent axes; with these parameters {text}"
        self.requirements.append((ca.if_else(ca.fabs(det) > self.DEPENDENT_AXES, 0, 1), text, path))

    def flexure_range(self, j: ResolvedJoint, dim: str, home: Any) -> tuple | None:
        """The joint's limits; a flexure's are a deflection about the reference value."""
        lim = self.joint_limit(j, dim)
        if lim is None or j.spec.flexure is None or (isinstance(home, (int, float)) and home == 0):
            return lim
        home_sx = ca.SX(home)
        if not home_sx.is_constant():
            raise InputError(
                "a flexure hinge limits the deflection from the reference configuration, and this joint's "
                "reference value depends on the parameters; report the deflection (home 0) or give its range",
                path=j.spec.path + ("flexure",),
            )
        h = float(ca.DM(home_sx))
        return (h + lim[0], h + lim[1])

    def joint_limit(self, j: ResolvedJoint, dim: str) -> tuple | None:
        if j.spec.flexure is not None:
            path = j.spec.path + ("flexure",)
            values = validate_mapping(j.spec.flexure.values, hinge_types.HINGE_LIMIT_OPTIONS, path, what="flexure key")
            if values.get("hinge") is None:
                raise InputError(f"missing key 'hinge' (one of: {', '.join(hinge_types.LIMIT_TYPES)})", path=path)
            rot = hinge_types.hinge_rotation(values, path)
            return (-rot, rot)
        if j.spec.range is not None:
            rng = tuple(parse_quantity(v, dim, j.spec.path + ("range", k)) for k, v in enumerate(j.spec.range))
            if not rng[0] < rng[1]:
                raise InputError(f"expected low < high, got {list(j.spec.range)}", path=j.spec.path + ("range",))
            return rng
        return None

    def check_task_count(self) -> None:
        """As many task coordinates as actuators."""
        task = self.d.platform.task
        if len(task) != len(self.q_coords):
            raise InputError(
                f"{len(task)} task coordinate(s) for {len(self.q_coords)} actuator(s) "
                f"({', '.join(c.name for c in self.q_coords)}); they must be as many",
                path=("platform", "task"),
            )

    def add_unknowns(self) -> None:
        if not self.extra:
            return
        self.x = ca.vertcat(self.x, *[e[1] for e in self.extra])
        self.x_home = ca.vertcat(self.x_home, *[e[2] for e in self.extra])
        for coord, _sym, _home, limit, path in self.extra:
            if coord.name in self.x_names or coord.name in [c.name for c in self.q_coords]:
                raise InputError(f"the coordinate name {coord.name!r} is used twice", path=path + ("coordinates",))
            self.x_names.append(coord.name)
            self.x_coords.append(coord)
            self.extra_limits[coord.group] = (coord.kind, limit, coord.description)

    def unique_names(self) -> None:
        """Every reported joint value has a name of its own (two joints declaring one
        coordinate name would lose one value from the result)."""
        seen = {n: ("platform", "coordinates", n) for n in self.x_names}
        seen.update({c.name: ("actuators", c.name) for c in self.q_coords})
        for r in self.reported:
            name = r.coord.name
            if name in seen:
                path = r.path + ("coordinates",) if r.path and r.path[0] != "passive" else r.path
                where = format_key_path(seen[name])
                also = "by every copy of this repeated leg" if seen[name] == r.path else f"also at {where}"
                raise InputError(
                    f"the coordinate name {name!r} is declared twice ({also}); give each joint value its own "
                    "name (in a repeated leg, with its index: e.g. 'alpha{i}')",
                    path=path,
                )
            seen[name] = r.path

    # -- declared options -----------------------------------------------------------------------
    def limit_options(self) -> tuple[Option, ...]:
        seen: dict[str, Option] = {}
        for fam, (dim, rng, path) in self.q_limits.items():
            lim = tuple(parse_quantity(v, dim, path + (k,)) for k, v in enumerate(rng))
            seen[fam] = Option(fam, dim, f"range [low, high] of every actuator {fam}*", default=lim, shape="range")
        for c in self.q_coords:
            if c.group not in seen:
                seen[c.group] = Option(
                    c.group, c.kind, f"range [low, high] of every actuator {c.group}*", default=None, shape="range"
                )
        for c in self.q_coords:  # one actuator alone (its homes may differ: the 3-RRR's cranks)
            if c.name not in seen and sum(o.group == c.group for o in self.q_coords) > 1:
                seen[c.name] = Option(
                    c.name,
                    c.kind,
                    f"range [low, high] of {c.name} alone (overrides {c.group})",
                    default=None,
                    shape="range",
                )
        for fam, (dim, lim, desc) in self.extra_limits.items():
            if fam not in seen:
                seen[fam] = Option(fam, dim, f"range [low, high] of every {fam}* ({desc})", default=lim, shape="range")
        for r in self.reported:
            fam = r.coord.group
            if fam not in seen:
                seen[fam] = Option(
                    fam,
                    r.coord.kind,
                    f"range [low, high] of every {fam}* ({r.coord.description})",
                    default=r.limit,
                    shape="range",
                )
        return tuple(seen.values())


def dim_name(dim: ex.Dim) -> str:
    """The dimension a value's (length, angle) exponents name: length, angle or dimensionless."""
    if dim is None or dim[0] == 0:
        return "angle" if dim is not None and dim[1] else "dimensionless"
    return "length"
