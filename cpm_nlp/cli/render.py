"""The readable table of a result (``cpm-nlp solve`` without ``--json``)."""

from __future__ import annotations

from collections import Counter

TYPE_CHECKING = False  # typing itself is not imported at start-up; the annotations are strings
if TYPE_CHECKING:
    from typing import Any

    from ..core.result import Result


def _fmt_scalar(value: Any, dim: str | None) -> tuple[str, str]:
    from ..core.units import DIMENSIONS, format_quantity, si_unit

    if value is None:
        return "—", ""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return str(value), ""
    unit = si_unit(dim)
    si = f"{value:.10g}" + (f" {unit}" if unit else "")
    friendly = format_quantity(value, dim) if dim in DIMENSIONS and DIMENSIONS[dim].display != unit else ""
    return si, friendly


def _fmt_words(flat: list) -> str:
    """A long list of words (statuses, names): how many of each, or the first few."""
    counts = Counter(str(v) for v in flat)
    if len(counts) <= 6:
        return f"{len(flat)} values: " + ", ".join(f"{n} {w}" for w, n in counts.items())
    return f"{len(flat)} values: " + ", ".join(str(v) for v in flat[:6]) + ", ..."


def _fmt_list(value: list, dim: str | None) -> str:
    flat = value
    if flat and all(isinstance(v, list) for v in flat):
        cells = [x for row in flat for x in row]
        if len(cells) > 36:  # a grid: its size and range (the values are in --json / -o)
            nums = [x for x in cells if isinstance(x, (int, float)) and not isinstance(x, bool)]
            text = f"matrix {len(flat)} x {max(len(row) for row in flat)}"
            if nums:
                text += f", from {min(nums):.6g} to {max(nums):.6g}"
            nulls = sum(1 for x in cells if x is None)
            return text + (f", {nulls} null" if nulls else "")

        def cell(x: Any) -> str:
            if isinstance(x, list):  # a batch of matrices: one row per point
                return "[" + ", ".join(cell(v) for v in x) + "]"
            return "—" if x is None else str(x) if isinstance(x, bool) else f"{x:.6g}"

        return "matrix " + "; ".join("[" + ", ".join(cell(x) for x in row) + "]" for row in flat)
    nums = [v for v in flat if isinstance(v, (int, float))]
    nulls = len(flat) - len(nums)
    if len(flat) > 4 and all(isinstance(v, (str, bool)) for v in flat):
        return _fmt_words(flat)
    if len(flat) <= 4:
        return "[" + ", ".join(_fmt_scalar(v, dim)[1] or _fmt_scalar(v, dim)[0] for v in flat) + "]"
    text = f"{len(flat)} values"
    if nums:
        text += (
            f", from {_fmt_scalar(min(nums), dim)[1] or _fmt_scalar(min(nums), dim)[0]}"
            f" to {_fmt_scalar(max(nums), dim)[1] or _fmt_scalar(max(nums), dim)[0]}"
        )
    if nulls:
        text += f", {nulls} not solved"
    return text


def render_result(result: Result, title: str = "") -> str:
    """A readable table of a result."""
    from ..core.result import STATUS_TEXT
    from ..core.units import DIMENSIONS

    lines = []
    lines.append(f"problem : {result.problem}" + (f"  ({title})" if title else ""))
    n = len(result.warnings)
    flagged = f", with {n} warning{'s' if n != 1 else ''} (below)" if n else ""
    lines.append(f"status  : {result.status.value}{flagged}  -- {result.message or STATUS_TEXT[result.status]}")
    s = result.solver
    lines.append(f"solver  : {s.name}, {s.iterations} iterations, {s.seconds * 1e3:.2f} ms")
    if result.model:
        parts = []
        for k, v in result.model.items():
            if k == "type":
                continue
            if isinstance(v, list) and all(isinstance(e, float) for e in v):  # a derived vector
                parts.append(f"{k} = [" + ", ".join(f"{e:.6g}" for e in v) + "]")
            else:
                parts.append(f"{k} = {v:.6g}" if isinstance(v, float) else f"{k} = {v}")
        shown = ": " + ", ".join(parts) + "  (SI)" if parts else " (no parameters)"
        lines.append("model   : " + result.model.get("type", "") + shown)
    if not result.values:
        lines.append("(no values: the solve did not succeed)" if not result.ok else "(no values)")
        return "\n".join(lines + _warning_lines(result))
    width = max(len(k) for k in result.values)
    lines.append("")
    for name, value in result.values.items():
        dim = result.dimensions.get(name)
        if isinstance(value, list):
            text = _fmt_list(value, dim)
            unit = result.units.get(name, "")
            if unit and dim not in DIMENSIONS:
                text += f"   ({unit})"
            lines.append(f"{name:<{width}}  {text}")
        else:
            si, friendly = _fmt_scalar(value, dim)
            lines.append(f"{name:<{width}}  {si:<22}" + (f"  {friendly}" if friendly else ""))
    return "\n".join(lines + _warning_lines(result))


def _warning_lines(result: Result) -> list[str]:
    """The result's warnings, one "warning: ..." line each, after a blank line."""
    if not result.warnings:
        return []
    return ["", *(f"warning: {w.message}" for w in result.warnings)]
