"""What is known of the built-in mechanisms without importing or reading any of them: the
old names, the add-ons, and the plot types each add-on brings (their names and one-line
summaries).

These tables import nothing of cpm_nlp: ``cpm-nlp plot --help`` lists the add-ons' plot types
from `ADDON_PLOTS` alone, and a plot module is imported only when its plot is drawn
(issue 24, item 5; issue 23, start-up).
"""

from __future__ import annotations

#: built-in file mechanism -> "module:attribute" of its `Addon`:
#: what its file cannot say (the paper's own kinds, a dynamics model, checks over several
#: parameters), added to the mechanism the file describes
ADDONS = {
    "prc3": "cpm_nlp.mechanisms.prc3.addon:ADDON",
    "rpr": "cpm_nlp.mechanisms.rpr.addon:ADDON",
    "pantograph": "cpm_nlp.mechanisms.pantograph.addon:ADDON",
}

#: old name -> the built-in mechanism it names now (the file twin became the built-in)
ALIASES = {
    "prs3_file": "prs3",
    "prc3_file": "prc3",
    "rpr_file": "rpr",
    "pantograph_file": "pantograph",
}


class AddonPlot:
    """A plot type of a built-in mechanism's add-on, declared without importing it.

    Attributes
    ----------
    name
        what ``--type`` takes.
    function
        ``"module:attribute"`` of the plot function ``(data, options) -> figure``, imported when
        the plot is first drawn (a module of the plot layer: it imports `cpm_nlp.plot`).
    description
        one line, listed by ``cpm-nlp plot --help``.
    kinds, interactive
        as `PlotType`'s fields.
    """

    # a plain class, not a dataclass: every solve imports this table, and a dataclass costs
    # 0.5 ms to create (issue 23, start-up)
    __slots__ = ("name", "function", "description", "kinds", "interactive")

    def __init__(
        self, name: str, function: str, description: str, kinds: tuple[str, ...] = (), interactive: bool = False
    ) -> None:
        self.name = name
        self.function = function
        self.description = description
        self.kinds = kinds
        self.interactive = interactive

    def __repr__(self) -> str:
        return f"AddonPlot({self.name!r}, {self.function!r})"


#: built-in mechanism (a key of `ADDONS`) -> the plot types of its paper, drawn only for
#: results of that mechanism (`cpm_nlp.plot.registry`)
ADDON_PLOTS: dict[str, tuple[AddonPlot, ...]] = {
    "prc3": (
        AddonPlot(
            "amplifier",
            "cpm_nlp.mechanisms.prc3.plots:amplifier_plot",
            "output against input of the 3-PRC's lever amplifier (eq 1-2)",
        ),
    ),
    "rpr": (
        AddonPlot(
            "twists",
            "cpm_nlp.mechanisms.rpr.plots:twists_plot",
            "the RPR platform's displacement twists as arrows on the mechanism (eq 45)",
            interactive=True,
        ),
    ),
}


def addon_plots(mechanism: str) -> tuple[AddonPlot, ...]:
    """The plot types of a built-in mechanism's add-on (or of the one an old name stands
    for); none for another mechanism."""
    return ADDON_PLOTS.get(ALIASES.get(mechanism, mechanism), ())
