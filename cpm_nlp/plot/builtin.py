"""The built-in plot types: one declaration each, in the order ``--help`` lists them.

Each function is named, not imported (`Deferred`): listing the
plot types imports no plot module (issue 23, start-up).
A mechanism adds the plots of its own paper through its add-on
(`cpm_nlp.core.mechanism.Addon.plots`), a third-party package through the
entry-point group ``cpm_nlp.plots`` (`cpm_nlp.plot.registry`).
"""

from __future__ import annotations

from .plot_type import Deferred, PlotType


def _in(module: str, function: str) -> Deferred:
    """The plot function ``function`` of ``cpm_nlp.plot.<module>``, imported when drawn."""
    return Deferred(f"cpm_nlp.plot.{module}:{function}")


BUILTIN = (
    PlotType(
        "workspace",
        _in("workspace_plots", "workspace_plot"),
        "a point cloud of the workspace with its cuboid and boundary (a planar one in its plane)",
        interactive=True,
    ),
    PlotType(
        "map",
        _in("sweep_plots", "map_plot"),
        "a value over two swept parameters, or over the grids of a kind's map_axes",
    ),
    PlotType("lines", _in("sweep_plots", "lines_plot"), "values of a one-parameter sweep against the parameter"),
    PlotType(
        "requirements",
        _in("curve_plots", "requirements_plot"),
        "joint requirements over the studied poses (actuators, passive joints)",
    ),
    PlotType("io", _in("curve_plots", "io_plot"), "outputs against the input that varies over a batch (FK, IK)"),
    PlotType(
        "mechanism",
        _in("mechanism_plots", "mechanism_plot"),
        "the mechanism at the result's pose, home faintly",
        interactive=True,
    ),
    PlotType(
        "assembly_modes",
        _in("assembly_plots", "assembly_modes_plot"),
        "the mechanism in each assembly mode a forward kinematics mode search found",
    ),
    PlotType(
        "design",
        _in("mechanism_plots", "design_plot"),
        "a synthesised design drawn at home, the file's design faintly",
        interactive=True,
    ),
    PlotType(
        "jacobian",
        _in("mechanism_plots", "jacobian_plot"),
        "the mechanism at the pose beside cond and manipulability over a workspace slice",
        interactive=True,
    ),
    PlotType(
        "comparison",
        _in("comparison_plots", "comparison_plot"),
        "values computed here beside their references (paper, reference design)",
    ),
    PlotType(
        "matrices", _in("comparison_plots", "matrices_plot"), "every matrix of the result as an annotated heat map"
    ),
    PlotType(
        "dynamics",
        _in("compliance_plots", "dynamics_plot"),
        "natural frequencies and mode shapes from M and K, beside printed values",
    ),
    PlotType("forces", _in("compliance_plots", "forces_plot"), "actuator forces and hinge stresses along a motion"),
    PlotType(
        "ellipsoid",
        _in("compliance_plots", "ellipsoid_plot"),
        "the compliance ellipsoid of the platform, on the mechanism",
    ),
    PlotType(
        "modes", _in("compliance_plots", "modes_plot"), "mode shapes as arrows on the mechanism, one panel per mode"
    ),
)
