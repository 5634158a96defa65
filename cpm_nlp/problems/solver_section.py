"""The ``solver`` section of a problem file: a preset name, or
``{preset, method, options, tolerance}``; presets are YAML files under ``configs/``."""

from __future__ import annotations

import os
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from ..core.errors import InputError, suggest
from ..core.options import Option, validate_mapping
from ..core.solver import METHODS, SolverConfig, check_options
from .reader import read_yaml
from .shipped import shipped_configs_dir

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


def config_dirs(base_dir: Path | None) -> list[Path]:
    """Where solver presets are looked up, in order."""
    dirs = []
    env = os.environ.get("CPM_NLP_CONFIGS")
    if env:
        dirs.append(Path(env))
    if base_dir is not None:
        dirs += [base_dir / "configs", base_dir.parent / "configs"]
    dirs += [Path.cwd() / "configs", shipped_configs_dir()]
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
        kwargs["options"] = check_options(merged["method"] or "ipopt", merged["options"])  # typed: 50.0 -> 50
        config = SolverConfig(**kwargs)
        config.validate()
    except InputError as exc:
        raise InputError(exc.message, path=path + exc.path[1:], suggestions=exc.suggestions, hint=exc.hint) from None
    return config


# -- the whole file -----------------------------------------------------------------------------
