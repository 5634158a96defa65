"""The ``sweep`` section of a problem file: the values ``cpm-nlp sweep`` varies
(grids, lists or seeded random samples over dotted keys), validated against
the problem's declarations when the file is loaded.  Running a sweep is
`cpm_nlp.sweep`'s job."""

from __future__ import annotations

import dataclasses
import json
import math
from collections.abc import Iterator, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from ..core.errors import InputError, suggest, unknown_key_error
from ..core.options import MAX_GRID_POINTS, Option, validate_mapping
from ..core.schema import Node
from ..core.units import DIMENSIONS
from ..mechanisms.registry import mechanism_type
from .overrides import apply_overrides
from .solver_section import parse_solver

SECTION_KEYS = {
    "parameters": "the swept values: dotted key -> grid, list or {random: ...}",
    "samples": "number of draws of the random parameters",
    "seed": "seed of the random draws (default 0)",
}
DISTRIBUTIONS = ("uniform", "loguniform")
#: top-level sections a sweep may override
SWEEPABLE = ("mechanism", "inputs", "solver")


@dataclass(frozen=True)
class Axis:
    """One swept value.

    Attributes
    ----------
    key
        dotted key of the problem file;
    mode
        "grid", "list" or "random";
    values
        the SI values of a grid or list;
    low, high, distribution
        the range of a random parameter;
    dimension
        of a numeric value ("length", "angle", ...), None for other values.
    """

    key: str
    mode: str
    values: tuple = ()
    low: float | None = None
    high: float | None = None
    distribution: str = "uniform"
    dimension: str | None = None
    base: float | None = None  # the value (SI) of the base problem at this key, if a number

    @property
    def name(self) -> str:
        """The last part of the key (``L`` for ``mechanism.parameters.L``)."""
        return self.key.rsplit(".", 1)[-1]

    def describe(self) -> dict[str, Any]:
        """JSON-able description (stored with the results)."""
        out: dict[str, Any] = {"key": self.key, "name": self.name, "mode": self.mode, "dimension": self.dimension}
        if self.mode == "random":
            out.update({"distribution": self.distribution, "from": self.low, "to": self.high})
        else:
            out["count"] = len(self.values)
        out["base"] = self.base
        return out


@dataclass(frozen=True)
class SweepSpec:
    """A validated ``sweep`` section: which points to solve."""

    axes: tuple[Axis, ...]
    samples: int | None
    seed: int
    raw: Any  # the section as written (for the fingerprint)

    @property
    def grid_axes(self) -> tuple[Axis, ...]:
        return tuple(a for a in self.axes if a.mode != "random")

    @property
    def random_axes(self) -> tuple[Axis, ...]:
        return tuple(a for a in self.axes if a.mode == "random")

    @property
    def n_grid(self) -> int:
        return math.prod(len(a.values) for a in self.grid_axes)

    @property
    def size(self) -> int:
        return self.n_grid * (self.samples or 1)

    def point(self, k: int) -> dict[str, Any]:
        """The values of point ``k`` (0 <= k < size), key -> SI value."""
        if not 0 <= k < self.size:
            raise IndexError(f"point {k} is outside the sweep (0 .. {self.size - 1})")
        sample, g = divmod(k, self.n_grid)
        out: dict[str, Any] = {}
        for axis in reversed(self.grid_axes):  # the first axis varies slowest
            g, i = divmod(g, len(axis.values))
            out[axis.key] = axis.values[i]
        if self.random_axes:
            rng = np.random.default_rng([self.seed, sample])
            for axis in self.random_axes:
                u = float(rng.random())
                if axis.distribution == "loguniform":
                    out[axis.key] = math.exp(math.log(axis.low) + u * (math.log(axis.high) - math.log(axis.low)))
                else:
                    out[axis.key] = axis.low + u * (axis.high - axis.low)
        return {a.key: out[a.key] for a in self.axes}

    def points(self) -> Iterator[tuple[int, dict[str, Any]]]:
        for k in range(self.size):
            yield k, self.point(k)


def _is_number(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def _jsonable(value: Any) -> Any:
    if isinstance(value, tuple):
        return [_jsonable(v) for v in value]
    if isinstance(value, list):
        return [_jsonable(v) for v in value]
    return value


# -- parsing ------------------------------------------------------------------------------


def parse_sweep(raw: Any, data: Mapping[str, Any], kind: Any, model: Any, base_dir: Path | None) -> SweepSpec:
    """Validate the ``sweep`` section of a problem file.

    ``data`` is the whole (parsed) file, ``kind`` and ``model`` the validated
    base problem: every swept key is resolved against what it overrides.
    """
    path = ("sweep",)
    if not isinstance(raw, Mapping):
        raise InputError(
            f"expected a mapping with keys {', '.join(SECTION_KEYS)}; got {type(raw).__name__} {raw!r}"[:200],
            path=path,
        )
    for key in raw:
        if key not in SECTION_KEYS:
            raise unknown_key_error(str(key), SECTION_KEYS, path, "sweep key")
    settings = validate_mapping(
        {k: v for k, v in raw.items() if k != "parameters"},
        (
            Option("samples", "int", SECTION_KEYS["samples"], default=None, lower=1, upper=MAX_GRID_POINTS),
            Option("seed", "int", SECTION_KEYS["seed"], default=0, lower=0, upper=2**63 - 1),
        ),
        path,
        what="sweep key",
    )
    params = raw.get("parameters")
    if not isinstance(params, Mapping) or not params:
        raise InputError(
            "expected a non-empty mapping of dotted keys (e.g. mechanism.parameters.L) to a grid "
            "{from, to, count}, a list, or {random: uniform, from, to}"
            + ("" if params is not None else " (the key is missing)"),
            path=path + ("parameters",),
        )
    axes = []
    for key, spec in params.items():
        if not isinstance(key, str):
            raise InputError(f"expected dotted keys as strings, got {key!r}", path=path + ("parameters",))
        axes.append(_parse_axis(key, spec, data, kind, model, base_dir, path + ("parameters", key)))
    randoms = [a.key for a in axes if a.mode == "random"]
    samples = settings["samples"]
    if randoms and samples is None:
        raise InputError(
            f"missing 'samples' (how many draws of the random parameter(s) {', '.join(randoms)})", path=path
        )
    if samples is not None and not randoms:
        raise InputError(
            "'samples' applies to random parameters ({random: uniform, from: ..., to: ...}), and none is given",
            path=path + ("samples",),
        )
    spec = SweepSpec(tuple(axes), samples, settings["seed"], _jsonable_raw(raw))
    if spec.size > MAX_GRID_POINTS:
        raise InputError(f"the sweep has {spec.size} points; expected at most {MAX_GRID_POINTS}", path=path)
    return spec


def _jsonable_raw(raw: Any) -> Any:
    return json.loads(json.dumps(raw, default=str))


def _parse_axis(
    key: str, spec: Any, data: Mapping[str, Any], kind: Any, model: Any, base_dir: Path | None, path: tuple
) -> Axis:
    option = _resolve(key, kind, model, path)[0]
    if isinstance(option, Node):
        return _nested_axis(key, spec, option, path)
    axis = _axis(key, spec, data, kind, model, base_dir, path)
    return dataclasses.replace(axis, base=_base_value(data, key, option))


def _base_value(data: Mapping[str, Any], key: str, option: Option | None) -> float | None:
    """The base problem's value at ``key`` in SI, if it is one number (else None)."""
    node: Any = data
    for part in key.split("."):
        if not isinstance(node, Mapping) or part not in node:
            return None
        node = node[part]
    if isinstance(node, list) and len(node) == 1:
        node = node[0]
    if option is None or option.kind not in DIMENSIONS:
        return float(node) if _is_number(node) else None
    try:
        value = dataclasses.replace(option, shape="scalar").parse(node, ())
    except InputError:  # a list, a pair, a mapping: no single base value
        return None
    return float(value) if _is_number(value) else None


def _axis(
    key: str, spec: Any, data: Mapping[str, Any], kind: Any, model: Any, base_dir: Path | None, path: tuple
) -> Axis:
    option, solver_key = _resolve(key, kind, model, path)
    dimension = option.kind if option is not None and option.kind in DIMENSIONS else None
    if isinstance(spec, Mapping) and "random" in spec:
        axis = _random_axis(key, spec, option, dimension, path)
        if solver_key:  # a drawn value must be one the solver takes (not a method name, not an integer)
            for u in (0.0, 0.3183098861837907, 1.0):
                value = axis.low + u * (axis.high - axis.low)
                _check_solver_value(key, value, data, base_dir, path)
        return axis
    if isinstance(spec, Mapping) and solver_key is None and option is not None and option.shape != "range":
        scalar = dataclasses.replace(option, shape="scalar")
        for end in ("from", "to"):  # the ends as written, with the bounds of the value they override
            if spec.get(end) is not None:
                scalar.parse(spec[end], path + (end,))
        values = dataclasses.replace(option, shape="grid").parse(spec, path)  # {from, to, count}
        return Axis(key, "grid", tuple(_check_each(option, values, path)), dimension=dimension)
    if isinstance(spec, Mapping) and not solver_key:
        raise InputError(f"expected a list of values for {key} (a grid needs a numeric value)", path=path)
    values = list(spec) if isinstance(spec, list) else [spec]
    if not values:
        raise InputError("expected a non-empty list of values", path=path)
    where = [path + (i,) if isinstance(spec, list) else path for i in range(len(values))]
    if solver_key:
        parsed = [_check_solver_value(key, v, data, base_dir, w) for v, w in zip(values, where)]
        dimension = "dimensionless" if all(_is_number(v) for v in parsed) else None
        return Axis(key, "list", tuple(parsed), dimension=dimension)
    parsed = [_jsonable(option.parse(v, w)) for v, w in zip(values, where)]
    return Axis(key, "list", tuple(parsed), dimension=dimension)


def _nested_axis(key: str, spec: Any, node: Node, path: tuple) -> Axis:
    """The values of a nested input (a material, hinges), each checked by its schema and
    swept as written."""
    values = list(spec) if isinstance(spec, list) else [spec]
    for i, v in enumerate(values):
        node.parse(v, path + (i,) if isinstance(spec, list) else path)
    return Axis(key, "list", tuple(_jsonable_raw(v) for v in values), dimension=None)


def _check_each(option: Option, values: list, path: tuple) -> list:
    """Values of a grid, each checked like a single value (integers, bounds)."""
    scalar = dataclasses.replace(option, shape="scalar")
    return [scalar.parse(v, path) for v in values]


def _random_axis(key: str, spec: Mapping, option: Option | None, dimension: str | None, path: tuple) -> Axis:
    kind = option.kind if option is not None else "dimensionless"
    if kind not in DIMENSIONS or (option is not None and option.shape == "range"):
        raise InputError(f"expected a list of values for {key} (a random sample needs a numeric value)", path=path)
    bound = {"lower": option.lower, "upper": option.upper, "strict": option.strict} if option is not None else {}
    opts = (
        Option("random", "choice", "the distribution", choices=DISTRIBUTIONS),
        Option("from", kind, "lowest value", **bound),
        Option("to", kind, "highest value", **bound),
    )
    parsed = validate_mapping(spec, opts, path, what="random key")
    low, high = parsed["from"], parsed["to"]
    if not low < high:
        raise InputError(f"expected from < to, got from {spec.get('from')!r}, to {spec.get('to')!r}", path=path)
    if parsed["random"] == "loguniform" and low <= 0:
        raise InputError(f"a loguniform sample needs from > 0, got {spec.get('from')!r}", path=path + ("from",))
    return Axis(key, "random", low=low, high=high, distribution=parsed["random"], dimension=dimension or kind)


def _resolve(key: str, kind: Any, model: Any, path: tuple) -> tuple[Option | None, str | None]:
    """The declaration a dotted key overrides: (option, None), or (None,
    solver-key) for the solver section (validated through the solver parser)."""
    parts = key.split(".")
    if any(not p for p in parts):
        raise InputError(f"expected a dotted key such as mechanism.parameters.L, got {key!r}", path=path)
    top = parts[0]
    if top not in SWEEPABLE:
        raise InputError(
            f"cannot sweep {top!r}; expected a key under {', '.join(SWEEPABLE)} "
            "(e.g. mechanism.parameters.L, inputs.dz, solver.method)",
            path=path,
            suggestions=suggest(top, SWEEPABLE),
        )
    if top == "solver":
        return None, key
    if top == "mechanism":
        section = parts[1] if len(parts) > 1 else ""
        if section not in ("parameters", "limits") or len(parts) != 3:
            hint = suggest(section, ("parameters", "limits")) if section else ()
            raise InputError(
                f"expected mechanism.parameters.<name> or mechanism.limits.<name>, got {key!r}",
                path=path,
                suggestions=[f"mechanism.{h}.{parts[-1]}" for h in hint] if len(parts) == 3 else (),
            )
        mtype = model.mechanism if model.mechanism is not None else mechanism_type(model.name)
        options = mtype.parameters if section == "parameters" else mtype.limits
        what = "parameter" if section == "parameters" else "limit"
    else:
        if len(parts) != 2:
            raise InputError(f"expected inputs.<name>, got {key!r}", path=path)
        options = kind.input_options(model)
        what = f"input of {kind.name}"
    by_name = {o.name: o for o in options}
    if parts[-1] not in by_name:
        raise unknown_key_error(parts[-1], by_name, path, what)
    return by_name[parts[-1]], None


def _check_solver_value(key: str, value: Any, data: Mapping[str, Any], base_dir: Path | None, path: tuple) -> Any:
    """A swept solver value: the base solver section with the override must parse."""
    try:
        section = apply_overrides({"solver": data.get("solver")}, [override(key, value)]).get("solver")
        parse_solver(section, base_dir)
    except InputError as exc:
        raise InputError(
            f"value {value!r}: {exc.message}", path=path, suggestions=exc.suggestions, hint=exc.hint
        ) from None
    return value


def override(key: str, value: Any) -> str:
    """``--set`` text for one swept value (JSON is YAML: the value round-trips exactly)."""
    return f"{key}={json.dumps(value)}"
