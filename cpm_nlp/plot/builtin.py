"""The built-in plot types: one declaration each, in the order ``--help`` lists them.

A mechanism adds the plots of its own paper through its add-on
(:attr:`cpm_nlp.core.mechanism.Addon.plots`), a third-party package through the
entry-point group ``cpm_nlp.plots`` (:mod:`cpm_nlp.plot.registry`).
"""

from __future__ import annotations

from .comparison_plots import comparison_plot, matrices_plot
from .compliance_plots import dynamics_plot, ellipsoid_plot, forces_plot, modes_plot
from .curve_plots import io_plot, requirements_plot
from .mechanism_plots import design_plot, jacobian_plot, mechanism_plot
from .plot_type import PlotType
from .sweep_plots import lines_plot, map_plot
from .workspace_plots import workspace_plot

BUILTIN = (
    PlotType(
        "workspace",
        workspace_plot,
        "a point cloud of the workspace with its cuboid and boundary (a planar one in its plane)",
        interactive=True,
    ),
    PlotType("map", map_plot, "a value over two swept parameters, or over the grids of a kind's map_axes"),
    PlotType("lines", lines_plot, "values of a one-parameter sweep against the parameter"),
    PlotType(
        "requirements", requirements_plot, "joint requirements over the studied poses (actuators, passive joints)"
    ),
    PlotType("io", io_plot, "outputs against the input that varies over a batch (FK, IK)"),
    PlotType("mechanism", mechanism_plot, "the mechanism at the result's pose, home faintly", interactive=True),
    PlotType("design", design_plot, "a synthesised design drawn at home, the file's design faintly", interactive=True),
    PlotType(
        "jacobian",
        jacobian_plot,
        "the mechanism at the pose beside cond and manipulability over a workspace slice",
        interactive=True,
    ),
    PlotType("comparison", comparison_plot, "values computed here beside their references (paper, reference design)"),
    PlotType("matrices", matrices_plot, "every matrix of the result as an annotated heat map"),
    PlotType("dynamics", dynamics_plot, "natural frequencies and mode shapes from M and K, beside printed values"),
    PlotType("forces", forces_plot, "actuator forces and hinge stresses along a motion"),
    PlotType("ellipsoid", ellipsoid_plot, "the compliance ellipsoid of the platform, on the mechanism"),
    PlotType("modes", modes_plot, "mode shapes as arrows on the mechanism, one panel per mode"),
)
