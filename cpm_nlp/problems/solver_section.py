"""The ``solver`` section of a problem file: a preset name, or
``{preset, options, tolerance}``, or ``{method, options, tolerance}``
(a preset and a method together are refused: the preset names its method).

Presets are YAML files under ``configs/``, looked up in ``$CPM_NLP_CONFIGS``
(set by the user), beside the problem file (``configs/``, ``../configs/``: the
problem file's own folder, from which it also reads its mechanism files), then
among the presets shipped with cpm_nlp.  The working directory is not searched:
a ``configs/ipopt.yaml`` that happens to be there must not change what
``solver: ipopt`` means.  A preset is data like the problem file: its options
pass the same allow-list (`cpm_nlp.core.solver_options`), and a refusal
names the preset file."""

from __future__ import annotations

import os
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from ..core.errors import InputError, suggest
from ..core.options import Option, validate_mapping
from ..core.solver import METHODS, SolverConfig
from ..core.solver_options import check_options
from ..io.inputs import unique_paths
from .reader import read_yaml
from .shipped import shipped_configs_dir

SOLVER_OPTIONS = (
    Option("preset", "str", "name of a preset under configs/", default=None),
    Option("method", "choice", "ipopt (NLP with bounds) or newton (rootfinder)", default=None, choices=METHODS),
    Option("options", "str", "CasADi/IPOPT options from the allow-list", default=None),  # checked below
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


def config_dirs(base_dir: Path | None) -> list[Path]:
    """Where solver presets are looked up, in order."""
    dirs = []
    env = os.environ.get("CPM_NLP_CONFIGS")
    if env:
        dirs.append(Path(env))
    if base_dir is not None:
        dirs += [base_dir / "configs", base_dir.parent / "configs"]
    dirs.append(shipped_configs_dir())  # not the working directory: see the module docstring
    return [d.resolve() for d in unique_paths(dirs)]


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
        if raw.get("preset"):
            raise InputError("a preset cannot name another preset", path=("preset",))
        try:  # the preset's own options pass the allow-list
            check_options(raw.get("method") or SolverConfig.method, raw["options"])
        except InputError as exc:
            raise InputError(exc.message, path=exc.path[1:], suggestions=exc.suggestions, hint=exc.hint) from None
    except InputError as exc:  # the message names the preset file and its key, the problem file names the key
        inner = InputError(exc.message, path=exc.path, file=str(presets[name])).render()
        raise InputError(f"in the preset {inner}", path=path, suggestions=exc.suggestions, hint=exc.hint) from None
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
    if section.get("preset") and section.get("method"):
        method = section["method"]
        raise InputError(
            f"'preset' and 'method' given together (preset {section['preset']!r}, method {method!r}); "
            "use one: a preset names its method",
            path=path,
            hint=f"write solver: {method} (the preset), or solver: {{method: {method}, options: ...}}; "
            f"on the command line, --set solver={method}",
        )
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
        config = SolverConfig(**kwargs)  # checks the options against the allow-list (typed: 50.0 -> 50)
        config.validate()
    except InputError as exc:
        raise InputError(exc.message, path=path + exc.path[1:], suggestions=exc.suggestions, hint=exc.hint) from None
    return config


# -- the whole file -----------------------------------------------------------------------------
