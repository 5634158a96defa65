"""Figures designers read, from plain arrays (Matplotlib, headless): the public
drawing functions, one module per concept, gathered here for one import.

Every function takes SI numbers and the dimension of each axis ("length",
"angle", ...), converts them for display (`style`) and returns a
``matplotlib.figure.Figure`` (no pyplot, no global state, no display: the
Agg and SVG renderers write files); `save` writes PNG, SVG or PDF
atomically (`output`).

* `draw_workspace` -- a reachable workspace as a 3-D point cloud with
  its inscribed cuboid, and the three projections (pantograph paper, Fig. 9-14);
* `draw_map` -- a value over two design parameters, on a grid or on
  scattered points of any domain (RPR paper, Fig. 4);
* `draw_panels` -- curves against one abscissa, one panel per quantity
  (3-PRS paper, Fig. 6-7; pantograph paper, Fig. 20-22);
* `draw_mechanism` -- the mechanism at a pose, arrows and mode shapes on it;
* `draw_compliance` -- the compliance ellipsoid, natural frequencies, mode shapes;
* `draw_tables` -- values beside references, matrices as heat maps.

`cpm_nlp.plot.figures` chooses and feeds these from results.
"""

from __future__ import annotations

from .draw_compliance import dynamics_figure, ellipsoid_figure, modes_figure, principal_axes
from .draw_map import design_map_figure
from .draw_mechanism import (
    Arrow,
    draw_mechanism,
    draw_mechanism_2d,
    drawing_factor,
    equal_aspect,
    is_planar,
    jacobian_figure,
    mechanism_axes,
    mechanism_figure,
    modes_mechanism_figure,
)
from .draw_panels import Panel, panels_figure
from .draw_tables import Comparison, comparison_axes, comparison_figure, matrices_figure, matrix_axes
from .draw_workspace import BoundarySlice, slice_lines, workspace_figure, workspace_figure_2d
from .output import FIGURE_FORMATS, check_figure_path, require_backend, save
from .style import NUMERICAL_ZERO, as_floats, axis_label, display_unit, pretty, unit_text, value_text

__all__ = [
    "FIGURE_FORMATS",
    "NUMERICAL_ZERO",
    "Arrow",
    "BoundarySlice",
    "Comparison",
    "Panel",
    "as_floats",
    "axis_label",
    "check_figure_path",
    "comparison_axes",
    "comparison_figure",
    "design_map_figure",
    "display_unit",
    "draw_mechanism",
    "draw_mechanism_2d",
    "drawing_factor",
    "dynamics_figure",
    "ellipsoid_figure",
    "equal_aspect",
    "is_planar",
    "jacobian_figure",
    "matrices_figure",
    "matrix_axes",
    "mechanism_axes",
    "mechanism_figure",
    "modes_figure",
    "modes_mechanism_figure",
    "panels_figure",
    "pretty",
    "principal_axes",
    "require_backend",
    "save",
    "slice_lines",
    "unit_text",
    "value_text",
    "workspace_figure",
    "workspace_figure_2d",
]
