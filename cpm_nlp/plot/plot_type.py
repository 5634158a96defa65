"""The declaration of a plot type: what a registered plot is (its name, the results it
fits, the function drawing it, one line for ``--help``) and the checks every
declaration passes, whoever declares it (the built-in plots, a mechanism's add-on,
a plugin)."""

from __future__ import annotations

import importlib
import re
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from ..core.errors import InputError

#: a plot type's name: what ``--type`` takes
NAME = re.compile(r"[a-z][a-z0-9_]*")


class PlotDeclarationError(InputError):
    """A plot type declared wrongly (the message names where it was declared)."""


class Deferred:
    """A plot function named ``"module:attribute"``, imported when the plot is first drawn:
    declaring and listing plot types (``cpm-nlp plot --help``) imports no plot module, nor
    Matplotlib (issue 23, start-up)."""

    def __init__(self, target: str) -> None:
        module, _, attr = target.partition(":")
        if not module or not attr:
            raise PlotDeclarationError(f"expected a plot function as 'module:attribute', got {target!r}")
        self.target = target
        self._function: Callable[[Any, Any], Any] | None = None

    def resolve(self) -> Callable[[Any, Any], Any]:
        """The function itself (imported on first use)."""
        if self._function is None:
            module, _, attr = self.target.partition(":")
            self._function = getattr(importlib.import_module(module), attr)
        return self._function

    def __call__(self, data: Any, options: Any) -> Any:
        return self.resolve()(data, options)

    def __repr__(self) -> str:
        return f"Deferred({self.target!r})"


@dataclass(frozen=True)
class PlotType:
    """One plot type.

    Attributes
    ----------
    name
        what ``--type`` takes (lower case, digits, underscores).
    function
        ``(data, options) -> figure``: ``data`` a `ResultData`, ``options`` a `PlotOptions`;
        returns a Matplotlib figure (a Plotly one when ``options.interactive``), or raises
        `NotApplicable` saying why the result does not fit.
    description
        one line, listed by ``cpm-nlp plot --help``.
    kinds
        the problem kinds whose results it draws ("sweep": a sweep results file); empty: any
        result it finds its values in.
    interactive
        it draws an interactive (.html) 3-D figure too.
    origin
        who declared it ("built-in", "add-on of mechanism 'x'", "plugin 'y' (...)"), set by the
        registry.
    """

    name: str
    function: Callable[[Any, Any], Any]
    description: str
    kinds: tuple[str, ...] = ()
    interactive: bool = False
    origin: str = "built-in"

    def fits(self, kind: str) -> bool:
        """Whether it draws a result of this problem kind ("sweep" for a sweep results file)."""
        return not self.kinds or kind in self.kinds


def validate(plot: Any, where: str) -> PlotType:
    """``plot`` if it is a well-formed `PlotType`; else a `PlotDeclarationError`
    naming ``where`` it was declared."""
    if not isinstance(plot, PlotType):
        raise PlotDeclarationError(f"{where} must name a PlotType declaration, got {type(plot).__name__}")
    problems = []
    if not isinstance(plot.name, str) or not NAME.fullmatch(plot.name):
        problems.append(f"its name must be lower case letters, digits and underscores, got {plot.name!r}")
    if not callable(plot.function):
        problems.append(f"its function must be callable (data, options) -> figure, got {type(plot.function).__name__}")
    if not isinstance(plot.description, str) or not plot.description.strip() or "\n" in plot.description:
        problems.append("its description must be one line of text (listed by 'cpm-nlp plot --help')")
    if not isinstance(plot.kinds, tuple) or not all(isinstance(k, str) for k in plot.kinds):
        problems.append(f"its kinds must be a tuple of problem kind names, got {plot.kinds!r}")
    if not isinstance(plot.interactive, bool):
        problems.append(f"interactive must be True or False, got {plot.interactive!r}")
    if problems:
        raise PlotDeclarationError(f"{where}: plot type {plot.name!r}: " + "; ".join(problems))
    return plot
