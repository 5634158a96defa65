"""The registry of mechanism types: built-in, and added by plugins.

A mechanism type is a [`Mechanism`][cpm_nlp.core.mechanism.Mechanism] declaration.
The built-in ones are listed in `BUILTIN`; a third-party package adds
its own through the entry-point group ``cpm_nlp.mechanisms``, without editing
cpm_nlp::

    # the plugin's pyproject.toml
    [project.entry-points."cpm_nlp.mechanisms"]
    delta = "my_package.delta:MECHANISM"

The entry point names a [`Mechanism`][cpm_nlp.core.mechanism.Mechanism] (or a function without arguments
returning one).  Registering validates it: a misspelt or mistyped capability
is an error that names the plugin, never a silently missing feature.

The symbolic closure is built once per process and shared by every model of
that type (it holds code, not problem data), so solvers built for one model
serve all of them.
"""

from __future__ import annotations

import dataclasses
import importlib
import logging
import re
import threading
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from ..core.errors import CpmError, InputError, suggest
from ..core.mechanism import Addon, Mechanism, MechanismDeclarationError, unknown_field_hint, validate, with_addon
from ..core.model import LoopClosure, Model
from ..core.origin import Origin
from . import described
from .names import ADDONS, ALIASES  # the built-in names' tables (read without importing a mechanism)

log = logging.getLogger(__name__)

#: entry-point group of mechanism plugins
ENTRY_POINT_GROUP = "cpm_nlp.mechanisms"

#: built-in mechanism type -> "module:attribute" of its declaration (every seed mechanism is a
#: file now: `BUILTIN_FILES`)
BUILTIN: dict[str, str] = {}

#: built-in mechanism type -> its shipped mechanism file (in problems/mechanisms/): the
#: mechanism is written once, in that file; its name resolves to the file without reading
#: any other (issue 21, item 5)
BUILTIN_FILES = {
    "prs3": "prs3.yaml",
    "prc3": "prc3.yaml",
    "rpr": "rpr.yaml",
    "pantograph": "pantograph.yaml",
}


def _builtin_specs() -> dict[str, tuple[str, Origin]]:
    """name -> (target, origin) of the built-in mechanisms (nothing read)."""
    specs = {name: (target, Origin("built-in", name)) for name, target in BUILTIN.items()}
    specs.update(
        {name: (f"file:{described.SHIPPED_DIR / f}", Origin("built-in", name)) for name, f in BUILTIN_FILES.items()}
    )
    return specs


#: what a mechanism file named by a problem file is called (the problem file reads only YAML files)
MECHANISM_FILE_SUFFIXES = (".yaml", ".yml")


class PluginError(InputError):
    """A mechanism plugin that cannot be loaded or breaks the interface (the message names the plugin)."""


class _Registry:
    """Mechanism declarations by name, loaded on first use (thread-safe)."""

    def __init__(self) -> None:
        self._lock = threading.RLock()
        self._specs: dict[str, tuple[str, Origin]] | None = None  # name -> (target, origin)
        self._loaded: dict[str, Mechanism] = {}
        #: name -> (the declaration, its closure)
        self._closures: dict[str, tuple[Mechanism, LoopClosure]] = {}
        #: bumped by every register/unregister, so that tables derived from the registry refresh
        self.version = 0

    def _discover(self) -> dict[str, tuple[str, Origin]]:
        """Every name: the built-in ones, the shipped mechanism files (by file name, none
        read), then the plugins' entry points (a name already taken is the shipped one)."""
        if self._specs is None:
            from importlib import metadata  # only here: a shipped name never reads the entry points

            specs = _builtin_specs()
            builtin_files = {target for target, _origin in specs.values()}
            for path in described.shipped_files():
                if f"file:{path}" in builtin_files:  # a built-in's file (its name is the built-in's)
                    continue
                spec = _shipped_spec(path.stem)
                if spec is None or path.stem in specs:
                    log.warning("mechanism file %s ignored: its file name is no valid name, or it is taken", path)
                    continue
                specs[path.stem] = spec
            for ep in metadata.entry_points(group=ENTRY_POINT_GROUP):
                detail = ep.value + (f", package {ep.dist.name}" if ep.dist else "")
                origin = Origin("plugin", ep.name, detail=detail)
                if ep.name in specs:
                    log.warning(
                        "mechanism plugin %s ignored: the name %r is taken (%s)", origin, ep.name, specs[ep.name][1]
                    )
                    continue
                specs[ep.name] = (ep.value, origin)
            self._specs = specs
        return self._specs

    def names(self) -> list[str]:
        with self._lock:
            return sorted(self._discover())

    def register(self, mech: Mechanism, *, replace: bool = False) -> Mechanism:
        """Add a mechanism declared in code (validated)."""
        if not isinstance(mech, Mechanism):
            raise MechanismDeclarationError(f"expected a Mechanism declaration, got {type(mech).__name__}")
        validate(mech)
        with self._lock:
            specs = self._discover()
            if mech.name in specs and not replace:
                raise MechanismDeclarationError(
                    f"mechanism {mech.name!r} ({mech.origin}) is already registered ({specs[mech.name][1]})"
                )
            specs[mech.name] = ("", mech.origin)
            self._loaded[mech.name] = mech
            self._closures.pop(mech.name, None)
            self.version += 1
        return mech

    def entry(self, name: str) -> tuple[Any, Any, Any]:
        """What the registry holds under ``name`` (to put back with `restore`)."""
        with self._lock:
            return self._discover().get(name), self._loaded.get(name), self._closures.get(name)

    def restore(self, name: str, entry: tuple[Any, Any, Any]) -> None:
        """Put back what `entry` returned (nothing, if it held nothing)."""
        spec, loaded, closure = entry
        with self._lock:
            for table, value in ((self._discover(), spec), (self._loaded, loaded), (self._closures, closure)):
                if value is None:
                    table.pop(name, None)
                else:
                    table[name] = value
            self.version += 1

    def unregister(self, name: str) -> None:
        with self._lock:
            self._discover().pop(name, None)
            self._loaded.pop(name, None)
            self._closures.pop(name, None)
            self.version += 1

    def _spec(self, name: str) -> tuple[str, Origin] | None:
        """The (target, origin) of ``name``.  Before anything is registered, a built-in's or a
        shipped mechanism file's is found by its name alone (issue 23): no other shipped file
        is read and no plugin is discovered (a plugin never takes a shipped name)."""
        if self._specs is None:
            if name in BUILTIN.keys() | BUILTIN_FILES.keys():
                return _builtin_specs()[name]
            shipped = _shipped_spec(name)
            if shipped is not None:
                return shipped
        return self._discover().get(name)

    def get(self, name: str) -> Mechanism:
        with self._lock:
            mech = self._loaded.get(name)
            if mech is None:
                spec = self._spec(name)
                if spec is None:
                    raise KeyError(name)
                mech = _load(name, *spec)
                self._loaded[name] = mech
            return mech

    def lookup(self, name: str) -> Mechanism | None:
        """The declaration registered as ``name`` (or as the name an old alias stands for),
        None if there is none."""
        with self._lock:
            if self._spec(name) is not None:
                return self.get(name)
            if name in ALIASES and self._spec(ALIASES[name]) is not None:
                log.debug("mechanism %r is now called %r", name, ALIASES[name])
                return self.get(ALIASES[name])
            return None

    def holds(self, mech: Mechanism) -> bool:
        """Whether ``mech`` is the very declaration registered under its name."""
        with self._lock:
            return self._loaded.get(mech.name) is mech

    def closure(self, mech: Mechanism) -> LoopClosure:
        with self._lock:
            held = self._closures.get(mech.name)
            # by name, for this very mechanism: two described mechanisms of one name (a file
            # and an edited copy of it, loaded in turn) never share a closure
            if held is None or held[0] is not mech:
                held = (mech, _build_closure(mech))
                self._closures[mech.name] = held
            return held[1]


class _LoadedClosures:
    """The closures of described mechanisms a problem file loaded (never registered): one per
    Mechanism object, which `described` caches by the content hash of
    its file (or description), so a file read again reuses its closure and its compiled solvers.
    Not a registry: [`mechanism_names`][cpm_nlp.mechanisms.registry.mechanism_names] and
    [`mechanism_type`][cpm_nlp.mechanisms.registry.mechanism_type] never see these."""

    def __init__(self) -> None:
        self._lock = threading.RLock()
        self._by_id: dict[int, tuple[Mechanism, LoopClosure]] = {}  # the Mechanism kept alive: its id stays its

    def closure(self, mech: Mechanism) -> LoopClosure:
        with self._lock:
            held = self._by_id.get(id(mech))
            if held is None or held[0] is not mech:
                held = (mech, _build_closure(mech))
                self._by_id[id(mech)] = held
            return held[1]


def _build_closure(mech: Mechanism) -> LoopClosure:
    """The symbolic closure of ``mech``, checked."""
    try:
        c = mech.closure()
    except CpmError:
        raise
    except Exception as exc:
        raise PluginError(f"mechanism {mech.name!r} ({mech.origin}): building its closure failed: {exc}") from exc
    if not isinstance(c, LoopClosure):
        raise PluginError(
            f"mechanism {mech.name!r} ({mech.origin}): closure() must return a LoopClosure, got {type(c).__name__}"
        )
    return c


_UNEXPECTED = re.compile(r"unexpected keyword argument '(\w+)'")


def _shipped_spec(name: Any) -> tuple[str, Origin] | None:
    """The (target, origin) of the shipped mechanism file ``<name>.yaml`` (a shipped file is
    named by its file name, which its ``name`` must repeat), None if there is none; nothing
    is read.  Only an identifier is looked up: never a path out of the shipped directory."""
    if not isinstance(name, str) or not name.isidentifier() or name in BUILTIN_FILES:
        return None
    path = described.SHIPPED_DIR / f"{name}.yaml"
    if not path.is_file():
        return None
    return f"file:{path}", Origin("file", name, path=str(path))


def _load(name: str, target: str, origin: Origin) -> Mechanism:
    """Import and validate one declaration; every failure names its origin."""
    if target.startswith("file:"):
        return _load_file(name, target[len("file:") :], origin)
    module, _, attr = target.partition(":")
    try:
        obj: Any = importlib.import_module(module)
        for part in attr.split(".") if attr else ():
            obj = getattr(obj, part)
        if not isinstance(obj, Mechanism) and callable(obj):
            obj = obj()
    except TypeError as exc:
        hint = ""
        m = _UNEXPECTED.search(str(exc))
        if m:
            said = unknown_field_hint(m.group(1))
            hint = f"; {said}" if said else ""
        raise PluginError(f"mechanism {name!r} ({origin}) failed to load: {exc}{hint}") from exc
    except Exception as exc:
        raise PluginError(f"mechanism {name!r} ({origin}) failed to load: {type(exc).__name__}: {exc}") from exc
    if not isinstance(obj, Mechanism):
        raise PluginError(f"mechanism {name!r} ({origin}) must name a Mechanism declaration, got {type(obj).__name__}")
    if obj.name != name:
        raise PluginError(f"mechanism {name!r} ({origin}) declares the name {obj.name!r}; the two must agree")
    if origin.kind != "built-in" and obj.origin.kind == "built-in":
        obj = _with_origin(obj, origin)
    return obj


def _load_file(name: str, path: str, origin: Origin) -> Mechanism:
    """A mechanism file; a built-in one with its add-on (`ADDONS`), if it has one."""
    mech = described.load_file(path)
    if mech.name != name:  # a shipped file is found by its file name: the two must agree
        raise PluginError(
            f"mechanism file {path} declares the name {mech.name!r}, but its file name says {name!r}; "
            "the two must agree"
        )
    if origin.kind == "built-in" and name in ADDONS:
        mech = described.with_same_text(with_addon(mech, _addon(name, ADDONS[name])), mech)
    return mech


def _addon(name: str, target: str) -> Addon:
    """The add-on of a built-in file mechanism (``module:attribute`` of an `Addon`)."""
    module, _, attr = target.partition(":")
    obj = getattr(importlib.import_module(module), attr)
    if not isinstance(obj, Addon):
        raise PluginError(f"the add-on of mechanism {name!r} ({target}) must be an Addon, got {type(obj).__name__}")
    return obj


def _with_origin(mech: Mechanism, origin: Origin) -> Mechanism:
    return dataclasses.replace(mech, origin=origin)


REGISTRY = _Registry()
#: closures of the mechanisms problem files described (not registered)
_LOADED = _LoadedClosures()


def mechanism_names() -> list[str]:
    """Names of every registered mechanism type (built-in and plugins)."""
    return REGISTRY.names()


def register(mech: Mechanism, *, replace: bool = False) -> Mechanism:
    """Register a mechanism declared in code, e.g. in a script or a test."""
    return REGISTRY.register(mech, replace=replace)


def unregister(name: str) -> None:
    """Remove a mechanism registered in code."""
    REGISTRY.unregister(name)


def mechanism_type(name: Any, path: tuple = ("mechanism", "type")) -> Mechanism:
    """The declaration of a mechanism type (with a "did you mean" if unknown); an old name
    (`ALIASES`) gives the mechanism it stands for."""
    mech = REGISTRY.lookup(name) if isinstance(name, str) else None
    if mech is not None:
        return mech
    names = REGISTRY.names()
    raise InputError(
        f"unknown mechanism type {name!r}; expected one of: {', '.join(names)}",
        path=path,
        suggestions=suggest(str(name), names),
    )


def resolve_described(mech: Mechanism, path: tuple) -> Mechanism:
    """The mechanism a problem file describes (a file or inline), checked against the registry
    without changing it: the built-in itself where the description is the built-in's own file
    or an unchanged copy of it; a changed copy under a built-in's name, or a description named
    like a mechanism declared in code or by a plugin, is an error (``type: NAME`` keeps meaning
    the registered one).  Two files of one name but different text load side by side."""
    with REGISTRY._lock:
        current = REGISTRY._spec(mech.name)
        if current is not None and current[0].startswith("file:") and current[1].kind == "built-in":
            builtin = REGISTRY.get(mech.name)
            if builtin is mech or described.same_text(builtin, mech):
                return builtin  # the built-in's own file, or an unchanged copy of it (cpm-nlp examples)
            raise InputError(
                f"the described mechanism's name {mech.name!r} is the built-in mechanism of "
                f"{current[0][len('file:') :]}, and this description differs from it; rename it",
                path=path + ("name",),
                hint="a changed copy of a shipped mechanism file needs a name of its own "
                f"(e.g. {mech.name}_edited), so that 'type: {mech.name}' keeps meaning the shipped one",
            )
        if current is not None and current[1].kind not in ("file", "inline"):
            raise InputError(
                f"the described mechanism's name {mech.name!r} is taken by a {current[1]} mechanism; rename it",
                path=path + ("name",),
            )
    return mech


#: keys of a problem file's mechanism section
SECTION_KEYS = ("type", "file", "description", "parameters", "limits")


def _section_described(section: Mapping[str, Any], base_dir: Any, path: tuple) -> Mechanism | None:
    """The mechanism a section's ``file`` or ``description`` describes (not registered), or
    None for a ``type``."""
    given = [k for k in ("type", "file", "description") if section.get(k) is not None]
    if len(given) != 1:
        raise InputError(
            "expected exactly one of 'type' (e.g. prs3), 'file' (a mechanism file) or 'description' "
            f"(a mechanism described inline); got {', '.join(given) or 'none'}",
            path=path,
        )
    if given[0] == "type":
        return None
    if given[0] == "file":
        raw = section["file"]
        if not isinstance(raw, str) or not raw.strip():
            raise InputError(f"expected the path of a mechanism file, got {raw!r}", path=path + ("file",))
        target = Path(raw) if Path(raw).is_absolute() or base_dir is None else Path(base_dir) / raw
        if target.suffix.lower() not in MECHANISM_FILE_SUFFIXES:  # a problem file reads YAML, not /etc/passwd
            raise InputError(
                f"expected a mechanism file ending in .yaml or .yml, got {raw!r:.200}", path=path + ("file",)
            )
        if not target.is_file():
            raise InputError(f"mechanism file not found: {target}", path=path + ("file",))
        try:
            mech = described.load_file(target)
        except InputError as exc:  # the message names the mechanism file, the problem file names the key
            # (its "did you mean" and hint follow the whole message, so that a long message keeps them)
            inner = InputError(exc.message, path=exc.path, file=exc.file).render()
            raise InputError(
                f"in the mechanism file {inner}", path=path + ("file",), suggestions=exc.suggestions, hint=exc.hint
            ) from None
        return mech
    try:
        mech = described.inline(section["description"], base_dir=Path(base_dir) if base_dir else None)
    except InputError as exc:
        raise exc.at(prefix=path + ("description",)) from None
    return mech


def section_model(section: Mapping[str, Any], base_dir: Any = None, path: tuple = ("mechanism",)) -> Model:
    """The model of a problem file's ``mechanism:`` section.  A mechanism file or inline
    description gives its model directly: no global registry changes (issue 22, item 3), so
    a later problem in the same process, and [`mechanism_names`][cpm_nlp.mechanisms.registry.mechanism_names], see the
    registry as it was."""
    described_mech = _section_described(section, base_dir, path)
    if described_mech is None:
        return build_model(section["type"], section.get("parameters"), section.get("limits"))
    mech = resolve_described(described_mech, path)
    return _model(mech, section.get("parameters"), section.get("limits"), path)


def closure_of(mech: Mechanism) -> LoopClosure:
    """The shared symbolic closure of a mechanism type (a registered one's, or the closure of
    a mechanism a problem file described)."""
    return REGISTRY.closure(mech) if REGISTRY.holds(mech) else _LOADED.closure(mech)


def build_model(
    type_name: str | Mechanism,
    parameters: Mapping[str, Any] | None = None,
    limits: Mapping[str, Any] | None = None,
    *,
    path: tuple = ("mechanism",),
) -> Model:
    """Build a model from parameter values given as quantities.

    ``parameters`` and ``limits`` take numbers (SI) or strings with units,
    exactly as in a problem file, e.g.
    ``build_model("prs3", {"b": "47.91 mm", "L": "109.215 mm"})``; ``type_name`` may be a
    [`Mechanism`][cpm_nlp.core.mechanism.Mechanism] itself (one a problem file described, not registered).
    """
    mech = type_name if isinstance(type_name, Mechanism) else mechanism_type(type_name, path + ("type",))
    return _model(mech, parameters, limits, path)


def _model(mech: Mechanism, parameters: Any, limits: Any, path: tuple) -> Model:
    """The model of the declaration ``mech`` (registered or not) with these values."""
    closure = closure_of(mech)
    if mech.origin.kind == "built-in":
        return mech.model(closure, parameters, limits, path)
    try:
        return mech.model(closure, parameters, limits, path)
    except CpmError:
        raise
    except Exception as exc:
        raise PluginError(
            f"mechanism {mech.name!r} ({mech.origin}): build failed: {type(exc).__name__}: {exc}"
        ) from exc
