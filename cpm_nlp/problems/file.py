"""YAML problem files.

One schema family for every problem kind::

    problem: forward_kinematics        # the question (see cpm_nlp.core.kind.KINDS)
    description: free text
    mechanism:
      type: prs3                       # see cpm_nlp.mechanisms.registry.MODULES
      parameters: {b: 47.91 mm, L: 109.215 mm, alpha0: 45 deg}
      limits: {s: [-3 mm, 3 mm]}       # optional joint limits
    inputs: {s1: 1 mm, s2: 0.5 mm, s3: -0.3 mm}
    solver: newton                     # a preset under configs/, or a mapping:
    #   {preset: ..., method: ipopt|newton, options: {ipopt.tol: 1e-12}, tolerance: 1e-10}
    outputs: {values: [pz, psi, theta]}  # optional selection
    reproduce: {paper: ..., rows: [...]} # optional published figures
    sweep: {parameters: {...}}           # optional design sweep (cpm_nlp.sweep.run)

Every error names the file and the key path and says what was expected.
"""

from __future__ import annotations

import os
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import yaml

from ..core.errors import InputError, format_key_path, suggest, unknown_key_error
from ..core.kind import ProblemKind, problem_kind
from ..core.model import Model
from ..core.options import Option, validate_mapping
from ..core.result import Result
from ..core.solver import METHODS, SolverConfig
from ..mechanisms.registry import build_model

TOP_LEVEL = {
    "problem": "the problem kind",
    "description": "free text",
    "mechanism": "mechanism type, parameters and limits",
    "inputs": "the inputs of the problem kind",
    "solver": "a preset name or {preset, method, options, tolerance}",
    "outputs": "optional {values: [names]} selection",
    "reproduce": "published figures the file reproduces",
    "sweep": "values to sweep (cpm-nlp sweep)",
}

SOLVER_OPTIONS = (
    Option("preset", "str", "name of a preset under configs/", default=None),
    Option("method", "choice", "ipopt (NLP with bounds) or newton (rootfinder)", default=None, choices=METHODS),
    Option("options", "str", "CasADi/IPOPT options, passed unchanged", default=None),  # checked below
    Option(
        "tolerance",
        "dimensionless",
        "largest accepted loop-closure residual (SI)",
        default=None,
        lower=0.0,
        strict=True,
    ),
    Option("description", "str", "what the preset is for", default=None),
)


@dataclass
class Problem:
    """A validated problem: ready to :func:`solve`."""

    kind: ProblemKind
    model: Model
    inputs: dict[str, Any]
    solver: SolverConfig
    outputs: list[str] | None = None
    reproduce: Any = None
    file: str | None = None
    description: str = ""
    data: dict[str, Any] = field(default_factory=dict)
    sweep: Any = None  # a cpm_nlp.sweep.run.SweepSpec when the file has a sweep section


# -- reading ------------------------------------------------------------------------------------


class _Loader(yaml.SafeLoader):
    """YAML with two YAML 1.2 readings that users expect:

    * ``1e-10`` is a float (PyYAML's YAML 1.1 wants ``1.0e-10`` and would hand
      the solver the string "1e-10"),
    * only true/false are booleans (``ipopt.sb: yes`` stays the string IPOPT wants).
    """


_Loader.yaml_implicit_resolvers = {
    first: [(tag, rx) for tag, rx in resolvers if tag != "tag:yaml.org,2002:bool"]
    for first, resolvers in yaml.SafeLoader.yaml_implicit_resolvers.items()
}
_Loader.add_implicit_resolver(
    "tag:yaml.org,2002:bool", re.compile(r"^(?:true|True|TRUE|false|False|FALSE)$"), list("tTfF")
)
_Loader.add_implicit_resolver(
    "tag:yaml.org,2002:float",
    re.compile(r"^[-+]?(?:[0-9][0-9_]*)(?:\.[0-9_]*)?[eE][-+]?[0-9]+$"),
    list("-+0123456789"),
)


def load_yaml_text(text: str) -> Any:
    """Parse YAML text with the problem-file rules (see :class:`_Loader`)."""
    return yaml.load(text, Loader=_Loader)  # noqa: S506 - a SafeLoader subclass


def read_yaml(path: str | os.PathLike) -> Any:
    """Parse a YAML file; errors name the file and the line."""
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise InputError("file not found", file=str(path)) from None
    except IsADirectoryError:
        raise InputError("expected a YAML file, got a directory", file=str(path)) from None
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(f"cannot read the file ({exc.__class__.__name__}: {exc})", file=str(path)) from None
    try:
        return load_yaml_text(text)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f"line {mark.line + 1}, column {mark.column + 1}: " if mark is not None else ""
        problem = getattr(exc, "problem", None) or str(exc).splitlines()[0]
        raise InputError(f"malformed YAML: {where}{problem}", file=str(path)) from None
    except (ValueError, OverflowError, RecursionError) as exc:  # e.g. timestamps out of range
        raise InputError(f"malformed YAML: {exc}", file=str(path)) from None


# -- overrides (--set dotted.key=VALUE) -------------------------------------------------------


def parse_override(text: str) -> tuple[list[str | int], Any]:
    """``"mechanism.parameters.b=50 mm"`` -> (["mechanism", "parameters", "b"], "50 mm")."""
    if not isinstance(text, str) or "=" not in text:
        raise InputError(f"expected dotted.key=VALUE, got {text!r}", path=("--set",))
    key, _, raw = text.partition("=")
    key = key.strip()
    if not key or any(not part for part in key.replace("]", "").split(".")):
        raise InputError(f"expected dotted.key=VALUE with a non-empty key, got {text!r}", path=("--set",))
    parts: list[str | int] = []
    for part in key.split("."):
        while "[" in part and part.endswith("]"):
            head, _, idx = part.partition("[")
            if head:
                parts.append(head)
            try:
                parts.append(int(idx[:-1]))
            except ValueError:
                raise InputError(f"expected an integer list index in {text!r}", path=("--set",)) from None
            part = ""
        if part:
            parts.append(int(part) if part.isdigit() else part)
    try:
        value = load_yaml_text(raw) if raw.strip() else None
    except yaml.YAMLError:
        value = raw
    return parts, value


def apply_overrides(data: Any, overrides: Sequence[str]) -> dict[str, Any]:
    """Apply ``--set`` overrides (like Hydra) to a parsed problem file.

    Keys are dotted paths; integers or ``[i]`` index lists; under
    ``solver.options`` the rest of the path is one option name
    (``solver.options.ipopt.tol=1e-8``).  Missing mappings are created.
    """
    if not overrides:
        return data
    if not isinstance(data, dict):
        raise InputError("--set needs the problem file to be a mapping of keys (problem, mechanism, inputs ...)")
    data = _deep_copy(data)
    for text in overrides:
        parts, value = parse_override(text)
        if len(parts) > 2 and parts[:2] == ["solver", "options"]:
            parts = parts[:2] + [".".join(str(p) for p in parts[2:])]
        if len(parts) > 1 and parts[0] == "solver" and isinstance(data.get("solver"), str):
            data["solver"] = {"preset": data["solver"]}  # a preset name, now refined
        node: Any = data
        for depth, part in enumerate(parts[:-1]):
            where = tuple(parts[: depth + 1])
            if isinstance(node, list):
                if not isinstance(part, int) or not -len(node) <= part < len(node):
                    raise InputError(
                        f"--set {text}: no list element {part!r} at {format_key_path(where[:-1])}", path=("--set",)
                    )
                node = node[part]
                continue
            if not isinstance(node, dict):
                raise InputError(f"--set {text}: {format_key_path(where[:-1])} is not a mapping", path=("--set",))
            if part not in node or node[part] is None:
                node[part] = {}
            node = node[part]
        last = parts[-1]
        if isinstance(node, list):
            if not isinstance(last, int) or not -len(node) <= last < len(node):
                raise InputError(f"--set {text}: no list element {last!r}", path=("--set",))
            node[last] = value
        elif isinstance(node, dict):
            node[last] = value
        else:
            raise InputError(f"--set {text}: {format_key_path(parts[:-1])} is not a mapping", path=("--set",))
    return data


def _deep_copy(value: Any) -> Any:
    if isinstance(value, dict):
        return {k: _deep_copy(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_deep_copy(v) for v in value]
    return value


# -- presets ----------------------------------------------------------------------------------


def config_dirs(base_dir: Path | None) -> list[Path]:
    """Where solver presets are looked up, in order."""
    dirs = []
    env = os.environ.get("CPM_NLP_CONFIGS")
    if env:
        dirs.append(Path(env))
    if base_dir is not None:
        dirs += [base_dir / "configs", base_dir.parent / "configs"]
    dirs += [Path.cwd() / "configs", Path(__file__).resolve().parent.parent / "configs"]
    seen, out = set(), []
    for d in dirs:
        r = d.resolve()
        if r not in seen:
            seen.add(r)
            out.append(r)
    return out


def available_presets(base_dir: Path | None) -> dict[str, Path]:
    found: dict[str, Path] = {}
    for d in config_dirs(base_dir):
        if d.is_dir():
            for f in sorted(d.glob("*.yaml")):
                found.setdefault(f.stem, f)
    return found


def load_preset(name: str, base_dir: Path | None, path: tuple) -> dict[str, Any]:
    presets = available_presets(base_dir)
    if name not in presets:
        where = ", ".join(str(d) for d in config_dirs(base_dir))
        raise InputError(
            f"unknown solver preset '{name}'; expected one of: {', '.join(sorted(presets)) or '(none found)'}",
            path=path,
            suggestions=suggest(name, presets),
            hint=f"presets are looked up in {where}",
        )
    data = read_yaml(presets[name])
    try:
        raw = _solver_mapping(data, ())
    except InputError as exc:
        raise exc.at(file=str(presets[name])) from None
    if raw.get("preset"):
        raise InputError("a preset cannot name another preset", path=("preset",), file=str(presets[name]))
    return raw


def _solver_mapping(raw: Any, path: tuple) -> dict[str, Any]:
    if not isinstance(raw, Mapping):
        raise InputError(
            f"expected a preset name or a mapping with keys preset, method, options, tolerance; got {raw!r}", path=path
        )
    opts = raw.get("options")
    if opts is not None:
        if not isinstance(opts, Mapping) or not all(isinstance(k, str) for k in opts):
            raise InputError(
                f"expected a mapping of CasADi option names to values, got {opts!r}", path=path + ("options",)
            )
    cleaned = {k: v for k, v in raw.items() if k != "options"}
    out = validate_mapping(cleaned, SOLVER_OPTIONS, path, what="solver key")
    out["options"] = dict(opts) if opts else {}
    return out


def parse_solver(raw: Any, base_dir: Path | None, path: tuple = ("solver",)) -> SolverConfig:
    """A SolverConfig from the ``solver`` section (preset name or mapping)."""
    if raw is None:
        return SolverConfig()
    if isinstance(raw, str):
        raw = {"preset": raw}
    section = _solver_mapping(raw, path)
    merged: dict[str, Any] = {"method": None, "options": {}, "tolerance": None}
    if section.get("preset"):
        preset = load_preset(section["preset"], base_dir, path + ("preset",))
        merged.update({k: v for k, v in preset.items() if k in ("method", "tolerance") and v is not None})
        merged["options"] = dict(preset["options"])
    for k in ("method", "tolerance"):
        if section.get(k) is not None:
            merged[k] = section[k]
    merged["options"].update(section["options"])
    kwargs: dict[str, Any] = {"options": merged["options"], "preset": section.get("preset")}
    if merged["method"] is not None:
        kwargs["method"] = merged["method"]
    if merged["tolerance"] is not None:
        kwargs["tolerance"] = float(merged["tolerance"])
    try:
        config = SolverConfig(**kwargs)
        config.validate()
    except InputError as exc:
        raise InputError(exc.message, path=path + exc.path[1:], suggestions=exc.suggestions, hint=exc.hint) from None
    return config


# -- the whole file -----------------------------------------------------------------------------


def problem_from_dict(data: Any, *, file: str | None = None, base_dir: Path | None = None) -> Problem:
    """Validate a parsed problem mapping into a :class:`Problem`."""
    try:
        return _problem_from_dict(data, file, base_dir)
    except InputError as exc:
        raise exc.at(file=file) from None


def _problem_from_dict(data: Any, file: str | None, base_dir: Path | None) -> Problem:
    if not isinstance(data, dict):
        kind = "an empty file" if data is None else f"{type(data).__name__} {data!r}"[:80]
        raise InputError(f"expected a mapping with keys {', '.join(TOP_LEVEL)}; got {kind}")
    for key in data:
        if key not in TOP_LEVEL:
            raise unknown_key_error(str(key), TOP_LEVEL, (), "top-level key")
    if data.get("problem") is None:
        raise InputError("missing required key 'problem' (the problem kind, e.g. forward_kinematics)")
    kind = problem_kind(data["problem"])
    mech = data.get("mechanism")
    if not isinstance(mech, Mapping):
        raise InputError(
            "expected a mapping with keys type, parameters, limits"
            + ("" if mech is not None else " (the key is missing)"),
            path=("mechanism",),
        )
    for key in mech:
        if key not in ("type", "parameters", "limits"):
            raise unknown_key_error(str(key), ("type", "parameters", "limits"), ("mechanism",), "mechanism key")
    if "type" not in mech:
        raise InputError("missing required key 'type' (the mechanism, e.g. prs3)", path=("mechanism",))
    model = build_model(mech["type"], mech.get("parameters"), mech.get("limits"))
    reason = kind.supports(model)
    if reason:
        raise InputError(
            f"problem kind '{kind.name}' does not apply to mechanism '{model.name}': {reason}", path=("problem",)
        )
    inputs = kind.parse_inputs(data.get("inputs"), model, ("inputs",))
    solver = parse_solver(data.get("solver"), base_dir)
    kind.check_solver(solver)
    outputs = _parse_outputs(data.get("outputs"), kind.output_names(model))
    description = data.get("description") or ""
    if not isinstance(description, str):
        raise InputError(f"expected free text, got {description!r}", path=("description",))
    reproduce = None
    if data.get("reproduce") is not None:
        from .reproduce import parse_reproduce

        reproduce = parse_reproduce(data["reproduce"], ("reproduce",))
    sweep = None
    if data.get("sweep") is not None:
        from ..sweep.run import parse_sweep

        sweep = parse_sweep(data["sweep"], data, kind, model, base_dir)
    return Problem(kind, model, inputs, solver, outputs, reproduce, file, description, data, sweep)


def _parse_outputs(raw: Any, names: list[str]) -> list[str] | None:
    if raw is None:
        return None
    path = ("outputs",)
    if not isinstance(raw, Mapping):
        raise InputError(f"expected a mapping {{values: [names]}}, got {raw!r}", path=path)
    for key in raw:
        if key != "values":
            raise unknown_key_error(str(key), ["values"], path, "outputs key")
    values = raw.get("values")
    if values is None:
        return None
    if not isinstance(values, list) or not all(isinstance(v, str) for v in values) or not values:
        raise InputError(f"expected a non-empty list of value names, got {values!r}", path=path + ("values",))
    for i, v in enumerate(values):
        if v not in names:
            raise InputError(
                f"unknown value '{v}'; this problem gives: {', '.join(names)}",
                path=path + ("values", i),
                suggestions=suggest(v, names),
            )
    return list(values)


def load_problem(path: str | os.PathLike, overrides: Sequence[str] = ()) -> Problem:
    """Read, override (``--set``) and validate a problem file."""
    file = str(path)
    data = read_yaml(path)
    try:
        data = apply_overrides(data, overrides)
    except InputError as exc:
        raise exc.at(file=file) from None
    return problem_from_dict(data, file=file, base_dir=Path(path).resolve().parent)


def solve(problem: Problem) -> Result:
    """Run a validated problem; the result carries its status (never raises
    for a failed solve)."""
    result = problem.kind.run(problem.model, problem.inputs, problem.solver)
    if problem.outputs is not None:
        keep = set(problem.outputs)
        result.values = {k: v for k, v in result.values.items() if k in keep}
    return result
