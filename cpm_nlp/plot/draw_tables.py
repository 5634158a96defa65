"""Numbers beside numbers: values computed here against their references
(ratio bars, both values written out) and matrices as annotated heat maps.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from .style import (
    display_unit,
    figure_class,
    pretty,
    unit_text,
    wrap,
)

# -- (f) comparisons and matrices ----------------------------------------------------------------------


@dataclass
class Comparison:
    """One quantity computed here beside a reference (a paper's printed value, a
    reference design): shown as the reference's ratio to ours."""

    name: str
    ours: float
    reference: float
    dimension: str | None = None
    #: where the reference comes from (a paper's table or equation), shown beside the name
    source: str = ""


def comparison_axes(
    ax: Any, rows: Sequence[Comparison], *, reference_label: str, ours_label: str = "this model"
) -> None:
    """Rows of reference / ours on a log axis (1: agree), each with both values written out."""
    y = np.arange(len(rows))[::-1]
    ratios = []
    for r in rows:
        ratio = r.reference / r.ours if r.ours not in (0, 0.0) and r.ours is not None else np.nan
        ratios.append(ratio if np.isfinite(ratio) and ratio > 0 else np.nan)
    ratios = np.array(ratios)
    ax.axvline(1.0, color="k", lw=1)
    ax.barh(
        y,
        np.nan_to_num(ratios - 1.0),
        left=1.0,
        color=["tab:green" if abs(r - 1) < 0.01 else "tab:orange" for r in np.nan_to_num(ratios, nan=1)],
        height=0.6,
    )
    ax.set_yticks(y, [pretty(r.name) + (f"\n({r.source})" if r.source else "") for r in rows])
    for yi, r in zip(y, rows):
        f, unit = display_unit(r.dimension, [r.ours, r.reference])
        ax.annotate(
            f"{ours_label} {r.ours * f:.4g} · {reference_label} {r.reference * f:.4g} {unit_text(unit)}".rstrip(),
            (0, yi),
            xycoords=("axes fraction", "data"),
            xytext=(4, 9),
            textcoords="offset points",
            fontsize="x-small",
            va="bottom",
        )
    finite = ratios[np.isfinite(ratios)]
    span = max(float(np.max(np.abs(finite - 1.0))) if finite.size else 0.0, 0.05)
    ax.set_xlim(1.0 - 1.3 * span, 1.0 + 1.3 * span)
    ax.set_ylim(-0.7, len(rows) - 0.1)
    ax.set_xlabel(f"{reference_label} / {ours_label}")
    ax.grid(True, axis="x", alpha=0.3)


def matrix_axes(ax: Any, M: Any, *, title: str = "", rows: Sequence[str] = (), cols: Sequence[str] = ()) -> None:
    """A matrix as a heat map of log10 |entry|, each entry written in."""
    M = np.asarray(M, dtype=float)
    mag = np.log10(np.where(np.abs(M) > 0, np.abs(M), np.nan))
    im = ax.imshow(mag, cmap="Blues", aspect="auto")
    big = float(np.abs(M).max()) if M.size else 0.0
    for (i, j), v in np.ndenumerate(M):
        v = 0.0 if abs(v) <= 1e-12 * big else v  # rounding noise of an exact zero
        dark = np.isfinite(mag[i, j]) and im.norm(mag[i, j]) > 0.6
        ax.text(j, i, f"{v:.3g}", ha="center", va="center", fontsize="x-small", color="white" if dark else "black")
    ax.set_xticks(range(M.shape[1]), [pretty(c) for c in cols] if len(cols) == M.shape[1] else range(1, M.shape[1] + 1))
    ax.set_yticks(range(M.shape[0]), [pretty(r) for r in rows] if len(rows) == M.shape[0] else range(1, M.shape[0] + 1))
    ax.set_title(title, fontsize="small")
    return im


def comparison_figure(
    groups: Sequence[tuple[str, Sequence[Comparison]]], spread: Mapping[str, Any] | None = None, *, title: str = ""
) -> Any:
    """One panel per kind of reference (`comparison_axes`), and the
    multi-start record (starts, converged, agreed; distinct optima) if given."""
    Figure = figure_class()
    spread = dict(spread or {})
    heights = [max(len(rows), 1) * 0.55 + 1.0 for _, rows in groups]
    extra = 1 if spread else 0
    fig = Figure(figsize=(8, sum(heights) + 2.2 * extra + 0.8), layout="constrained")
    axes = fig.subplots(len(groups) + extra, 1, height_ratios=heights + [2.2] * extra, squeeze=False)[:, 0]
    for ax, (label, rows) in zip(axes, groups):
        comparison_axes(ax, rows, reference_label=label)
        ax.set_title(f"against the {label}", fontsize="small")
    if spread:
        ax = axes[-1]
        optima = spread.pop("optima", None)
        counts = {k: v for k, v in spread.items() if isinstance(v, (int, float))}
        if counts:
            names = list(counts)
            ax.bar(range(len(names)), [counts[n] for n in names], color="tab:blue", width=0.6)
            ax.set_xticks(range(len(names)), [n.replace("_", " ") for n in names], fontsize="small")
            ax.set_ylabel("starts")
        text = "multi-start: " + ", ".join(f"{k.replace('_', ' ')} {v}" for k, v in counts.items())
        if optima:
            text += f"; {len(optima)} distinct optim{'um' if len(optima) == 1 else 'a'}"
        ax.set_title(text, fontsize="small")
    if title:
        fig.suptitle(title)
    return fig


def matrices_figure(mats: Sequence[tuple[str, Any]], units: Mapping[str, str] | None = None, *, title: str = "") -> Any:
    """Matrices as annotated heat maps (`matrix_axes`), the unit text of each below it."""
    Figure = figure_class()
    units = units or {}
    n = len(mats)
    ncols = min(n, 3)
    nrows = math.ceil(n / ncols)
    fig = Figure(figsize=(4.6 * ncols, 4.0 * nrows + 0.6), layout="constrained")
    for k, (name, M) in enumerate(mats):
        ax = fig.add_subplot(nrows, ncols, k + 1)
        matrix_axes(ax, M, title=pretty(name))
        note = units.get(name, "")
        if note:
            ax.set_xlabel(wrap(note, 60), fontsize="x-small")
    if title:
        fig.suptitle(title)
    return fig
