"""The ``comparison`` and ``matrices`` plot types: values beside their references
(a paper's printed values, a reference design, the design in the file) and every
matrix of a result.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from .draw_tables import Comparison, comparison_figure, matrices_figure
from .results import NotApplicable, PlotOptions, ResultData, dimension_of, figure_title, problem_words

# -- comparisons, matrices ----------------------------------------------------------------------------

#: how a result names a reference value beside its own (prefix or suffix, legend label). Each
#: label says what the reference is: a value computed here from a paper's formulas or
#: formulation is not a number the paper prints (issue 24: eq 38 of prc3-li-2018.md evaluated
#: with assumed masses, 96.5 Hz, was labelled "paper (printed)"; the paper prints 93.83 Hz).
#: Numbers a paper prints come from the problem's reproduce rows (`PRINTED`).
REFERENCES = (
    ("reference_", "", "reference design"),
    ("paper_", "", "paper's formulation (solved here)"),
    ("", "_printed", "printed formulas (evaluated here)"),
    ("", "_compare", "compared design"),
    ("", "_design", "design in the file"),
)

#: the label of the numbers a paper prints (the problem's ``reproduce`` rows)
PRINTED = "printed in the paper"


def comparisons(data: ResultData) -> list[tuple[str, list[Comparison]]]:
    """Pairs (ours, reference) of scalar values, grouped by kind of reference."""
    v = data.values
    groups = []
    for prefix, suffix, label in REFERENCES:
        rows = []
        for name, ref in v.items():
            if not (name.startswith(prefix) and name.endswith(suffix)) or name == prefix + suffix:
                continue
            base = name[len(prefix) : len(name) - len(suffix) if suffix else None]
            ours = v.get(base)
            if base == name or not all(isinstance(u, (int, float)) and not isinstance(u, bool) for u in (ours, ref)):
                continue
            rows.append(Comparison(base, float(ours), float(ref), dimension_of(data, base)))
        if rows:
            groups.append((label, rows))
    printed = printed_comparisons(data)
    if printed:
        groups.append((PRINTED, printed))
    return groups


def printed_comparisons(data: ResultData) -> list[Comparison]:
    """The result's scalar values beside the numbers the paper prints for them (the problem's
    ``reproduce`` rows, at hand with ``cpm-nlp solve FILE --plot``), each named with its source."""
    rows = []
    for expr, published, label in data.published:
        ours = data.values.get(expr)
        if isinstance(ours, (int, float)) and not isinstance(ours, bool):
            source = label[label.find("(") + 1 : -1] if label.endswith(")") and "(" in label else label
            rows.append(Comparison(expr, float(ours), float(published), dimension_of(data, expr), source))
    return rows


def comparison_plot(data: ResultData, _options: PlotOptions) -> Any:
    """Values computed here beside their references (a paper's printed values, a
    reference design, the design in the file): the reference's ratio to ours,
    both values written out; a multi-start spread where the result has one."""
    if data.sweep:
        raise NotApplicable("'comparison' plots one result")
    groups = comparisons(data)
    if not groups:
        raise NotApplicable("the result has no value beside a reference (reference_*, paper_*, *_printed ...)")
    spread = _multistart(data)
    return comparison_figure(
        groups, spread, title=figure_title(data, f"{problem_words(data)}: ours against references")
    )


def _multistart(data: ResultData) -> dict[str, Any]:
    v = data.values
    out = {k: v[k] for k in ("starts", "starts_converged", "starts_agreed", "converged", "at_best") if k in v}
    if isinstance(v.get("optima"), list) and v["optima"] and isinstance(v["optima"][0], list):
        out["optima"] = v["optima"]
    return out


def _matrices(data: ResultData) -> list[tuple[str, np.ndarray]]:
    out = []
    for name, value in data.values.items():
        if isinstance(value, list) and value and isinstance(value[0], list):
            try:
                M = np.array(value, dtype=float)
            except (TypeError, ValueError):
                continue
            if M.ndim == 2 and M.size <= 100 and np.isfinite(M).all():
                out.append((name, M))
    return out


def matrices_plot(data: ResultData, _options: PlotOptions) -> Any:
    """Every matrix of the result (up to 10 x 10) as a heat map of its entries'
    magnitudes, each entry written in (units from the result)."""
    if data.sweep:
        raise NotApplicable("'matrices' plots one result")
    mats = _matrices(data)
    if not mats:
        raise NotApplicable("the result has no matrix")
    return matrices_figure(mats, data.units, title=figure_title(data))
