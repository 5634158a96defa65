"""The 3-PRC paper's own plot: the lever amplifier's output against its input (eq 1-2).

Declared, name and one line, in `cpm_nlp.mechanisms.names.ADDON_PLOTS`, so that
``cpm-nlp plot --help`` lists it without importing this module; drawn only for results of
the 3-PRC.  This module belongs to the plot layer (it imports `cpm_nlp.plot`; nothing
in the mechanisms layer imports it).
"""

from __future__ import annotations

import re
from typing import Any

TYPE_CHECKING = False
if TYPE_CHECKING:
    from ...plot.results import PlotOptions, ResultData


def amplifier_plot(data: ResultData, _options: PlotOptions) -> Any:
    """Output against input of the lever amplifier, d = A2 q (prc3 paper, eq 1-2)."""
    # the drawing modules are imported when a plot is drawn (issue 23, start-up)
    from ...plot.draw_panels import Panel, panels_figure
    from ...plot.results import NotApplicable

    v = data.values
    pairs = [(k, "d" + k[1:]) for k in v if re.fullmatch(r"q\d+", k) and isinstance(v[k], list)]
    pairs = [(a, b) for a, b in pairs if isinstance(v.get(b), list)]
    if not pairs or not isinstance(v.get("A2"), (int, float)):
        raise NotApplicable("an amplifier plot needs A2 and lists q<i>, d<i>")
    panels = []
    x = None
    for qn, dn in pairs:
        x = v[qn]
        panels.append(
            Panel(dn, "length", {dn: v[dn]}, title=f"{dn} = A2 {qn}, A2 = {v['A2']:.4g} (A1 = {v['A1']:.4g})")
        )
    return panels_figure(
        x, panels, xname=pairs[0][0], xdimension="length", title="Lever amplifier output (prc3, eq 1-2)"
    )
