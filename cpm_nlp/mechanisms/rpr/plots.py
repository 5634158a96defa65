"""The RPR paper's own plot: the displacement twists of the platform on the mechanism (eq 45).

Declared, name and one line, in `cpm_nlp.mechanisms.names.ADDON_PLOTS`, so that
``cpm-nlp plot --help`` lists it without importing this module; drawn only for results of
the RPR.  This module belongs to the plot layer (it imports `cpm_nlp.plot`; nothing
in the mechanisms layer imports it).
"""

from __future__ import annotations

from typing import Any

TYPE_CHECKING = False
if TYPE_CHECKING:
    from ...plot.results import PlotOptions, ResultData


def twists_plot(data: ResultData, options: PlotOptions) -> Any:
    """The displacement twists of the platform, one per actuator, as arrows on the
    mechanism at the pose: the rotation (ω) and the translation (v) of the
    reference point, each scaled to the drawing (RPR paper, eq 45)."""
    # numpy and the drawing modules are imported when a plot is drawn (issue 23, start-up)
    import numpy as np

    from ...plot.draw_mechanism import Arrow, mechanism_figure
    from ...plot.interactive import mechanism_html
    from ...plot.pose import geometry_of, model_for, model_title
    from ...plot.results import NotApplicable

    T = data.values.get("T")
    if not isinstance(T, list) or len(T) != 6:
        raise NotApplicable("a twists plot needs the 6 x n twist matrix T")
    model = model_for(data)
    c = model.closure
    x = np.array([float(data.values.get(n, h)) for n, h in zip(c.x_names, model.x_home)])
    q = model.q_home if not all(n in data.values for n in c.q_names) else [data.values[n] for n in c.q_names]
    pose = geometry_of(model)(model, x, np.asarray(q, dtype=float))
    ref = np.asarray(data.values.get("reference_point") or pose.points.get("P", np.zeros(3)), dtype=float)
    T = np.asarray(T, dtype=float)
    span = float(np.ptp(np.array([np.asarray(v, dtype=float) for v in pose.points.values()]), axis=0).max())
    colours = ("tab:red", "tab:purple", "tab:brown", "tab:pink", "tab:olive", "tab:cyan")
    arrows = []
    for block, what, style in ((slice(0, 3), "ω", "rotation"), (slice(3, 6), "v", "translation")):
        big = float(np.abs(T[block]).max())
        if big == 0:
            continue
        scale = 0.35 * span / big
        for j in range(T.shape[1]):
            vec = T[block, j]
            if np.linalg.norm(vec) > 0:
                arrows.append(
                    Arrow(
                        ref + (0 if style == "rotation" else 0.02 * span),
                        vec * scale,
                        f"{what} of actuator {j + 1} ({style}, ×{scale:.3g})",
                        colours[j % len(colours)] if style == "rotation" else colours[(j + 3) % len(colours)],
                    )
                )
    draw = mechanism_html if options.interactive else mechanism_figure
    return draw(
        pose,
        arrows=arrows,
        title=f"{model_title(model)}\ndisplacement twists of the platform, at the reference point",
        note=_note(data),
    )


def _note(data: ResultData) -> str:
    """What T's rows and columns are, and the convention of its moments (a result's value)."""
    convention = data.values.get("convention")
    return data.units.get("T", "") + (f"; {convention} convention" if isinstance(convention, str) else "")
