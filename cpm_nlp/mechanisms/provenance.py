"""Where a result's mechanism came from, and the mechanism rebuilt from that record.

A problem's ``mechanism:`` section gives a built-in (or plugin) by name, a mechanism
file, or a description inline; `section_origin` makes the
`Origin` a result records (a file by its absolute path
and the SHA-256 of its bytes, an inline description as written).
`recorded_mechanism` reads the mechanism back for a plot: a file only if it is
still at its path with the same hash, else one clear [`InputError`][cpm_nlp.core.errors.InputError] (never a
silently different mechanism).  Nothing read back is registered: the registry keeps
what it had.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

from ..core.errors import InputError
from ..core.mechanism import Mechanism
from ..core.model import LoopClosure, Model
from ..core.origin import Origin, data_sha256, file_sha256
from ..core.result import jsonable
from . import described
from .registry import (
    ALIASES,
    BUILTIN,
    BUILTIN_FILES,
    MECHANISM_FILE_SUFFIXES,
    REGISTRY,
    build_model,
    closure_of,
    mechanism_type,
)


def _file_origin(name: str, path: Path) -> Origin:
    path = path.resolve()
    return Origin("file", name, path=str(path), sha256=file_sha256(path))


def section_origin(section: Mapping[str, Any], base_dir: Any, model: Model) -> Origin:
    """The origin of the mechanism a problem file's ``mechanism:`` section built ``model`` of."""
    name = model.name
    if section.get("file") is not None:
        raw = Path(str(section["file"]))
        return _file_origin(name, raw if raw.is_absolute() or base_dir is None else Path(base_dir) / raw)
    if section.get("description") is not None:
        desc = jsonable(section["description"])
        folder = str(Path(base_dir).resolve()) if base_dir is not None else ""
        return Origin("inline", name, path=folder, sha256=data_sha256(desc), description=desc)
    typed = str(section.get("type"))
    if ALIASES.get(typed, typed) in BUILTIN.keys() | BUILTIN_FILES.keys():
        return Origin("built-in", name)
    origin = model.mechanism.origin if model.mechanism is not None else Origin("code", name)
    if origin.kind == "file" and Path(origin.path).is_file():  # a shipped file, or one loaded before
        return _file_origin(name, Path(origin.path))
    return Origin(origin.kind, name, detail=origin.detail)


def recorded_mechanism(record: Any, type_name: Any, source: str | None = None) -> Mechanism:
    """The mechanism of a result: from its ``origin`` record, else (a result written before
    results recorded it) the registered mechanism ``type_name``.  ``source``: the result
    file, named in the messages."""
    origin = Origin.from_dict(record) if record is not None else None
    if origin is None:
        if record is not None:
            raise InputError(f"expected an origin record (kind, name ...), got {record!r:.120}", path=("origin",))
        return mechanism_type(type_name, path=("model", "type"))
    if origin.kind == "file":
        return _recorded_file(origin, source)
    if origin.kind == "inline":
        return _recorded_inline(origin, source)
    return mechanism_type(origin.name, path=("origin", "name"))


def _recorded_file(origin: Origin, source: str | None) -> Mechanism:
    path = Path(origin.path)
    again = "put the file back as it was, or solve the problem again"
    if path.suffix.lower() not in MECHANISM_FILE_SUFFIXES:  # a result file reads YAML, as a problem file does
        raise InputError(
            f"expected a mechanism file ending in .yaml or .yml, got {origin.path!r:.200}",
            path=("origin", "path"),
            file=source,
        )
    if not path.is_file():
        raise InputError(
            f"the mechanism file {path} this result was solved with is missing (moved or deleted); {again}",
            path=("origin", "path"),
            file=source,
        )
    now = file_sha256(path)
    if now != origin.sha256:
        raise InputError(
            f"the mechanism file {path} has changed since this result was solved "
            f"(SHA-256 {now[:12]}..., recorded {origin.sha256[:12]}...): the result belongs to the file "
            f"as it was; {again}",
            path=("origin", "sha256"),
            file=source,
        )
    return described.load_file(path)


def _recorded_inline(origin: Origin, source: str | None) -> Mechanism:
    desc = origin.description
    if desc is None:
        raise InputError(
            f"the result's mechanism {origin.name!r} was described in code and its description is not "
            "recorded; solve the problem again",
            path=("origin",),
            file=source,
        )
    if data_sha256(desc) != origin.sha256:
        raise InputError(
            "the result's inline mechanism description does not match its recorded SHA-256 (the result "
            "file was edited); solve the problem again",
            path=("origin", "description"),
            file=source,
        )
    return described.from_dict(desc, base_dir=Path(origin.path) if origin.path else None)


def recorded_model(
    mech: Mechanism,
    parameters: Mapping[str, Any] | None,
    path: tuple = ("model",),
    limits: Mapping[str, Any] | None = None,
) -> Model:
    """A model of a mechanism `recorded_mechanism` gave: a registered one through the
    registry (its shared closure), one read back from a file or a description without
    registering it (the registry keeps what it had); ``limits``: its joint limits, if given."""
    if _registered(mech):
        return build_model(mech.name, parameters, limits, path=path)
    return mech.model(recorded_closure(mech), parameters, limits, path)


def _registered(mech: Mechanism) -> bool:
    return mech.origin.kind not in ("file", "inline") or REGISTRY.lookup(mech.name) is mech


def recorded_closure(mech: Mechanism) -> LoopClosure:
    """The closure of a mechanism `recorded_mechanism` gave (not put in the registry)."""
    if _registered(mech):
        return closure_of(mech)
    return mech.closure()
