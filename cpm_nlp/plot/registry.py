"""The registry of plot types: built-in, a mechanism's own, and added by plugins.

A plot type is a `PlotType` declaration.  Three
sources extend the registry, none by editing cpm_nlp:

* the built-in plot types (`cpm_nlp.plot.builtin.BUILTIN`);
* a built-in mechanism's add-on (`cpm_nlp.mechanisms.names.ADDON_PLOTS`): the plots
  of its paper, each declared by name, function ("module:attribute") and one line, drawn
  only for results of that mechanism; listing them imports neither the add-on nor its
  plot module (the function is imported when the plot is drawn);
* a third-party package, through the entry-point group ``cpm_nlp.plots``::

      # the plugin's pyproject.toml
      [project.entry-points."cpm_nlp.plots"]
      radar = "my_package.plots:RADAR"

  The entry point names a `PlotType` (or a function without arguments returning
  one) of the entry point's name.  Loading validates it: a plugin that fails to import,
  names something else or declares another name is an error naming the plugin, never a
  silently missing plot.

Nothing registers a plot type as a side effect: loading a problem file or a result
leaves the registry as it is; a mechanism's plots are looked up from the result's
mechanism when a figure is drawn.  `register` adds one in code (a script, a test).
"""

from __future__ import annotations

import importlib
import logging
import threading
from collections.abc import Sequence
from importlib import metadata
from typing import Any

from ..core.errors import CpmError, InputError
from ..mechanisms.names import ADDON_PLOTS, AddonPlot, addon_plots
from .builtin import BUILTIN
from .plot_type import Deferred, PlotDeclarationError, PlotType, validate

log = logging.getLogger(__name__)

#: entry-point group of plot plugins
ENTRY_POINT_GROUP = "cpm_nlp.plots"


class PlotPluginError(InputError):
    """A plot plugin (or a mechanism's plot) that cannot be loaded or breaks the interface
    (the message names it)."""


def _load_target(target: str, where: str) -> Any:
    """The object ``"module:attribute"`` names (called if it is a function without arguments)."""
    module, _, attr = target.partition(":")
    if not module or not attr:
        raise PlotPluginError(f"{where}: expected 'module:attribute', got {target!r}")
    try:
        obj: Any = importlib.import_module(module)
        for part in attr.split("."):
            obj = getattr(obj, part)
        if not isinstance(obj, (PlotType, Sequence)) and callable(obj):
            obj = obj()
    except CpmError:
        raise
    except Exception as exc:
        raise PlotPluginError(f"{where} failed to load: {type(exc).__name__}: {exc}") from exc
    return obj


def _from_addon(declared: AddonPlot, mechanism: str, where: str) -> PlotType:
    """The `PlotType` of an add-on's declaration, its function imported when drawn."""
    if not isinstance(declared, AddonPlot):
        raise PlotDeclarationError(f"{where} must be an AddonPlot declaration, got {type(declared).__name__}")
    try:
        function = Deferred(declared.function)
    except PlotDeclarationError as exc:
        raise PlotDeclarationError(f"{where}: {exc}") from None
    return PlotType(
        declared.name,
        function,
        declared.description,
        kinds=declared.kinds,
        interactive=declared.interactive,
        origin=f"mechanism {mechanism}",
    )


class _Registry:
    """Plot types by name: built-in and registered in code at once, plugins on first use,
    a mechanism's own when a result of that mechanism is drawn (thread-safe)."""

    def __init__(self) -> None:
        self._lock = threading.RLock()
        self._types: dict[str, PlotType] = {p.name: p for p in BUILTIN}
        self._plugins: dict[str, tuple[Any, str]] | None = None  # name -> (entry point, origin), not loaded
        self._mechanism_plots: dict[str, dict[str, PlotType]] = {}

    # -- plugins ---------------------------------------------------------------------------------

    def _plugin_specs(self) -> dict[str, tuple[Any, str]]:
        if self._plugins is None:
            specs = {}
            for ep in metadata.entry_points(group=ENTRY_POINT_GROUP):
                origin = f"plugin {ep.name!r} ({ep.value}" + (f", package {ep.dist.name})" if ep.dist else ")")
                if ep.name in self._types or ep.name in specs:
                    taken = self._types[ep.name].origin if ep.name in self._types else specs[ep.name][1]
                    log.warning("plot plugin %s ignored: the name %r is taken (%s)", origin, ep.name, taken)
                    continue
                specs[ep.name] = (ep, origin)
            self._plugins = specs
        return self._plugins

    def _load_plugin(self, name: str) -> PlotType:
        ep, origin = self._plugin_specs()[name]
        where = f"plot type {name!r} ({origin})"
        plot = validate(_load_target(ep.value, where), where)
        if plot.name != name:
            raise PlotPluginError(f"{where} declares the name {plot.name!r}; the two must agree")
        plot = PlotType(**{**plot.__dict__, "origin": origin})
        self._types[name] = plot
        del self._plugins[name]
        return plot

    # -- a mechanism's own -------------------------------------------------------------------------

    def mechanism_plots(self, mechanism: str) -> dict[str, PlotType]:
        """The plot types of a built-in mechanism's add-on (none for another mechanism),
        from their declarations (`ADDON_PLOTS`): nothing is
        imported until a plot is drawn."""
        with self._lock:
            if mechanism not in self._mechanism_plots:
                found: dict[str, PlotType] = {}
                for declared in addon_plots(mechanism):
                    what = repr(declared.name) if isinstance(declared, AddonPlot) else repr(declared)
                    where = f"plot {what} of the add-on of mechanism {mechanism!r}"
                    plot = validate(_from_addon(declared, mechanism, where), where)
                    if plot.name in self._types or plot.name in self._plugin_specs() or plot.name in found:
                        raise PlotDeclarationError(f"{where}: the plot type {plot.name!r} is declared twice")
                    found[plot.name] = plot
                self._mechanism_plots[mechanism] = found
            return self._mechanism_plots[mechanism]

    # -- lookups ----------------------------------------------------------------------------------

    def shared(self) -> dict[str, PlotType]:
        """The plot types of every result: built-in, registered in code, plugins (loaded)."""
        with self._lock:
            for name in list(self._plugin_specs()):
                self._load_plugin(name)
            return dict(self._types)

    def get(self, name: str, mechanism: str | None = None) -> PlotType | None:
        """The plot type ``name`` for a result of ``mechanism``, None if there is none."""
        with self._lock:
            if name in self._types:
                return self._types[name]
            if name in self._plugin_specs():
                return self._load_plugin(name)
            return self.mechanism_plots(mechanism).get(name) if mechanism else None

    def has(self, name: str) -> bool:
        """Whether ``name`` is a registered plot type (nothing loaded that need not be: a
        mechanism's add-on is read only for a name that is neither built-in nor a plugin's)."""
        with self._lock:
            return name in self._types or name in self._plugin_specs() or bool(self.owners(name))

    def owners(self, name: str) -> list[str]:
        """The built-in mechanisms whose add-ons declare the plot type ``name``."""
        return [m for m in sorted(ADDON_PLOTS) if name in self.mechanism_plots(m)]

    def names(self) -> list[str]:
        """Every plot type's name: built-in, in code, plugins (not loaded), the mechanisms' own."""
        with self._lock:
            names = list(self._types) + list(self._plugin_specs())
            for m in sorted(ADDON_PLOTS):
                names += [n for n in self.mechanism_plots(m) if n not in names]
            return names

    def everything(self) -> list[PlotType]:
        """Every plot type (plugins loaded), the built-in first, then plugins, then the mechanisms' own."""
        plots = list(self.shared().values())
        for m in sorted(ADDON_PLOTS):
            plots += [p for p in self.mechanism_plots(m).values() if p.name not in {q.name for q in plots}]
        return plots

    # -- in code ------------------------------------------------------------------------------------

    def register(self, plot: PlotType, *, replace: bool = False) -> PlotType:
        plot = validate(plot, f"plot type {getattr(plot, 'name', plot)!r} ({getattr(plot, 'origin', 'code')})")
        with self._lock:
            taken = plot.name in self._types or plot.name in self._plugin_specs()
            if taken and not replace:
                origin = self._types[plot.name].origin if plot.name in self._types else "a plugin"
                raise PlotDeclarationError(f"plot type {plot.name!r} is already registered ({origin})")
            self._plugin_specs().pop(plot.name, None)
            self._types[plot.name] = plot
        return plot

    def unregister(self, name: str) -> None:
        """Remove a plot type registered in code or by a plugin (a built-in one stays)."""
        with self._lock:
            if any(p.name == name for p in BUILTIN):
                self._types[name] = next(p for p in BUILTIN if p.name == name)
                return
            self._types.pop(name, None)
            self._plugin_specs().pop(name, None)

    def forget_plugins(self) -> None:
        """Read the entry points again on next use (a test that installs a plugin)."""
        with self._lock:
            builtin = {p.name for p in BUILTIN}
            self._types = {k: v for k, v in self._types.items() if k in builtin or not v.origin.startswith("plugin ")}
            self._plugins = None


REGISTRY = _Registry()


def register(plot: PlotType, *, replace: bool = False) -> PlotType:
    """Register a plot type declared in code (validated), e.g. in a script or a test."""
    return REGISTRY.register(plot, replace=replace)


def unregister(name: str) -> None:
    """Remove a plot type registered in code."""
    REGISTRY.unregister(name)


def plot_type_names() -> list[str]:
    """The name of every registered plot type (built-in, plugins, the mechanisms' own)."""
    return REGISTRY.names()


def plot_types() -> list[PlotType]:
    """Every registered plot type (plugins loaded: a broken one is an error naming it)."""
    return REGISTRY.everything()


def plot_type(name: str, mechanism: str | None = None) -> PlotType | None:
    """The plot type ``name`` as a result of ``mechanism`` sees it: built-in, plugins, and
    the plots of that mechanism's add-on; None if there is none."""
    return REGISTRY.get(name, mechanism)


def interactive_names(mechanism: str | None = None) -> list[str]:
    """The plot types a result of ``mechanism`` may draw as an interactive (.html) figure."""
    with REGISTRY._lock:  # the plot types loaded: a plugin not named yet is not read for this
        plots = list(REGISTRY._types.values())
    plots += list(REGISTRY.mechanism_plots(mechanism).values()) if mechanism else []
    return [p.name for p in plots if p.interactive]
