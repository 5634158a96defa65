"""Units, labels and the small helpers every figure shares (Matplotlib, headless).

Every figure takes SI numbers and the dimension of each axis ("length",
"angle", ...) and converts them for display here: lengths to m, mm, µm or nm
following their size, angles to degrees.  A figure is a
``matplotlib.figure.Figure`` (no pyplot, no global state, no display).
"""

from __future__ import annotations

import re
from typing import Any

import numpy as np

from ..core.units import DIMENSIONS, to_display

_LENGTHS = (("m", 1.0), ("mm", 1e-3), ("µm", 1e-6), ("nm", 1e-9))
_GREEK = (
    "alpha",
    "beta",
    "gamma",
    "delta",
    "epsilon",
    "zeta",
    "eta",
    "theta",
    "kappa",
    "lambda",
    "mu",
    "nu",
    "xi",
    "rho",
    "sigma",
    "tau",
    "phi",
    "chi",
    "psi",
    "omega",
)


def figure_class() -> Any:
    from ..core.extras import require

    require("matplotlib", "plot", "plotting")
    from matplotlib.figure import Figure

    return Figure


# -- units and labels ---------------------------------------------------------------------------


def display_unit(dimension: str | None, values: Any = ()) -> tuple[float, str]:
    """``(factor, unit)`` to show SI values of a dimension: shown = SI * factor.

    Lengths take the largest of m, mm, µm, nm that keeps the largest value
    at or above 1; other dimensions their display unit (angles: deg).
    """
    if dimension == "length":
        arr = np.abs(np.asarray(values, dtype=float).ravel())
        arr = arr[np.isfinite(arr)]
        peak = float(arr.max()) if arr.size else 0.0
        if peak == 0.0:
            return 1e3, "mm"
        for unit, size in _LENGTHS:
            if peak >= size * (1 - 1e-9):
                return 1.0 / size, unit
        return 1e9, "nm"
    if dimension in DIMENSIONS and dimension != "dimensionless":
        factor, unit = to_display(1.0, dimension)
        return factor, unit
    return 1.0, ""


def pretty(name: str) -> str:
    """A symbol for axis labels: ``beta_m1`` -> β_m1, ``dalpha`` -> Δα,
    ``dz`` -> d_z, ``s_max`` -> s_max (Matplotlib mathtext); long plain words
    stay as they are."""
    name = str(name).rsplit(".", 1)[-1]
    head, _, tail = name.partition("_")
    delta = ""
    if len(head) > 1 and head[0] == "d" and head[1:].rstrip("0123456789") in _GREEK:
        delta, head = r"\Delta ", head[1:]  # a change of an angle (dalpha: alpha - alpha at home)
    elif len(head) == 2 and head[0] == "d" and head[1] in "xyz":
        head, tail = "d", "_".join(p for p in (head[1], tail) if p)  # d_z: a displacement along z
    m = re.fullmatch(r"([A-Za-z]+?)(\d*)", head)
    if m is None:
        return name
    letters, digits = m.groups()
    if letters.lower() in _GREEK:
        symbol = "\\" + letters
    elif len(letters) <= 2:
        symbol = letters
    else:
        return name
    sub = ",".join(p for p in (digits, *tail.split("_")) if p)
    return f"${delta}{symbol}" + (f"_{{{sub}}}" if sub else "") + "$"


def number(v: float) -> str:
    """3 significant digits, without an exponent for values up to 10^5."""
    return f"{v:.0f}" if 1e3 <= abs(v) < 1e5 else f"{v:.3g}"


def unit_text(unit: str) -> str:
    """A unit for a label, powers in mathtext: ``mm^3`` -> mm³ (``$\\mathrm{mm}^{3}$``)."""
    if "^" not in unit:
        return unit
    text = re.sub(r"[A-Za-zµ]+", lambda m: r"\mathrm{" + m.group() + "}", unit)
    text = re.sub(r"\^(-?\d+)", r"^{\1}", text).replace("*", r"\cdot ")
    return f"${text}$"


def axis_label(name: str, unit: str) -> str:
    return f"{pretty(name)} ({unit_text(unit)})" if unit else pretty(name)


def value_text(v: float, digits: int = 5) -> str:
    """A value to read: ``digits`` significant digits, more where rounding would
    make it look like a round number it is not (0.99999999991 is not "1")."""
    text = f"{v:.{digits}g}"
    shown = float(text)
    if shown != v and shown == round(shown):
        text = f"{v:.12g}"
    return text


#: SI values smaller than this are rounding noise of an exact zero (residuals are
#: accepted at 1e-10): shown as 0, not blown up to 1e-20 nm
NUMERICAL_ZERO = 1e-13


def as_floats(values: Any) -> np.ndarray:
    """SI values (None: not solved) as floats, NaN for None, rounding noise of zero as 0."""
    arr = np.asarray([np.nan if v is None else v for v in values], dtype=float)
    return np.where(np.abs(arr) < NUMERICAL_ZERO, 0.0, arr)


def wrap(text: str, width: int) -> str:
    import textwrap

    return "\n".join(textwrap.wrap(text, width)) or text


def few_ticks(ax: Any, three_d: bool) -> None:
    """At most four ticks per 3-D axis (long labels of a short range overlap otherwise)."""
    from matplotlib.ticker import MaxNLocator

    axes = (ax.xaxis, ax.yaxis, ax.zaxis) if three_d else (ax.xaxis, ax.yaxis)
    for axis in axes:
        axis.set_major_locator(MaxNLocator(4 if three_d else 6))


def legend_below(fig: Any, ax: Any, note: str = "") -> None:
    note = wrap(note, 140) if len(note) > 140 else note  # a long note in lines, not past the figure's edges
    handles, labels = ax.get_legend_handles_labels()
    keep = [(h, lab) for h, lab in zip(handles, labels) if not lab.startswith("_")]
    keep = [(h, lab) for n, (h, lab) in enumerate(keep) if lab not in [k[1] for k in keep[:n]]]  # each label once
    if keep:
        fig.legend(
            [h for h, _ in keep],
            [lab for _, lab in keep],
            loc="outside lower center",
            ncols=min(3, len(keep)),
            fontsize="small",
            title=note or None,
            title_fontsize="x-small",
        )


def cell_edges(u: np.ndarray) -> np.ndarray:
    mid = (u[1:] + u[:-1]) / 2
    return np.r_[u[0] - (mid[0] - u[0]), mid, u[-1] + (u[-1] - mid[-1])]
