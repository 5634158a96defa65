"""The readable table of a result (``cpm-nlp solve`` without ``--json``)."""

from __future__ import annotations

from collections import Counter
from collections.abc import Mapping

from .numbers import NO_NOISE, Noise, engineering

TYPE_CHECKING = False  # typing itself is not imported at start-up; the annotations are strings
if TYPE_CHECKING:
    from typing import Any

    from ..core.result import Result


def _fmt_scalar(value: Any, dim: str | None, noise: Noise = NO_NOISE) -> tuple[str, str]:
    """(the SI value, the value for people): noise below the solve's tolerance is 0, and the
    value for people has the prefix that suits it (`cpm_nlp.cli.numbers`)."""
    from ..core.units import DIMENSIONS, si_unit

    if value is None:
        return "—", ""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return str(value), ""
    if isinstance(value, int):
        return str(value), ""
    value = noise.clean(value, dim)
    unit = si_unit(dim)
    si = ("0" if value == 0 else f"{value:.10g}") + (f" {unit}" if unit else "")
    friendly = engineering(value, dim) if dim in DIMENSIONS and unit else ""
    return si, friendly if friendly != si else ""


def _shown(value: Any, dim: str | None, noise: Noise) -> str:
    si, friendly = _fmt_scalar(value, dim, noise)
    return friendly or si


def _plain(x: float) -> str:
    """A matrix entry (SI): six significant digits, never -0."""
    text = f"{x:.6g}"
    return "0" if float(text) == 0 else text


def _fmt_words(flat: list) -> str:
    """A long list of words (statuses, names): how many of each, or the first few."""
    counts = Counter(str(v) for v in flat)
    if len(counts) <= 6:
        return f"{len(flat)} values: " + ", ".join(f"{n} {w}" for w, n in counts.items())
    return f"{len(flat)} values: " + ", ".join(str(v) for v in flat[:6]) + ", ..."


def _fmt_list(value: list, dim: str | None, noise: Noise = NO_NOISE) -> str:
    flat = value
    if flat and all(isinstance(v, list) for v in flat):
        cells = [x for row in flat for x in row]
        if len(cells) > 36:  # a grid: its size and range (the values are in --json / -o)
            nums = [x for x in cells if isinstance(x, (int, float)) and not isinstance(x, bool)]
            text = f"matrix {len(flat)} x {max(len(row) for row in flat)}"
            if nums:
                text += f", from {_plain(noise.clean(min(nums), dim))} to {_plain(noise.clean(max(nums), dim))}"
            nulls = sum(1 for x in cells if x is None)
            return text + (f", {nulls} null" if nulls else "")

        def cell(x: Any) -> str:
            if isinstance(x, list):  # a batch of matrices: one row per point
                return "[" + ", ".join(cell(v) for v in x) + "]"
            return "—" if x is None else str(x) if isinstance(x, bool) else _plain(noise.clean(x, dim))

        return "matrix " + "; ".join("[" + ", ".join(cell(x) for x in row) + "]" for row in flat)
    nums = [v for v in flat if isinstance(v, (int, float))]
    nulls = len(flat) - len(nums)
    if len(flat) > 4 and all(isinstance(v, (str, bool)) for v in flat):
        return _fmt_words(flat)
    if len(flat) <= 4:
        return "[" + ", ".join(_shown(v, dim, noise) for v in flat) + "]"
    text = f"{len(flat)} values"
    if nums:
        text += f", from {_shown(min(nums), dim, noise)} to {_shown(max(nums), dim, noise)}"
    if nulls:
        text += f", {nulls} not solved"
    return text


#: solver names of results computed without an iterative solve
_NOT_ITERATIVE = {
    "closed_form": "closed form, no iterations",
    "none": "no numerical solver (the formulas evaluated directly)",
}


def _solver_lines(s: Any) -> list[str]:
    """Which method answered and its iterations; then the solve's time and, apart, the time
    spent building what it ran (symbolic construction, compilation: once per process)."""
    from ..core.kernels import REDUCED_STEPS

    n = s.iterations
    counted = "iterations not counted" if n is None else f"{n} iteration{'' if n == 1 else 's'}"
    what = {
        "closed": "closed form, no iterations",
        "reduced": f"{s.name}, reduced path: Newton on the task coordinates through the closed-form IK "
        f"({REDUCED_STEPS} or {2 * REDUCED_STEPS} steps, not counted)",
        "full": f"{s.name}, full path: Newton on the loop closures ({counted})",
    }.get(getattr(s, "path", ""), f"{s.name}, {counted}")
    if s.name in _NOT_ITERATIVE and not getattr(s, "path", ""):
        what = _NOT_ITERATIVE[s.name]
    time = f"solve {_milliseconds(s.seconds)}"
    build = getattr(s, "build_seconds", 0.0)
    if build > 0.0005:
        time += f"; build {_milliseconds(build)} (symbolic construction and compilation, once per process)"
    return [f"solver  : {what}", f"time    : {time}"]


def _milliseconds(seconds: float) -> str:
    return f"{seconds * 1e3:.3g} ms" if seconds < 1 else f"{seconds:.3g} s"


def _model_text(model: Mapping[str, Any], dims: Mapping[str, str]) -> str:
    """The model's parameters: a declared one with its unit (``b = 47.91 mm``), the others
    (derived values of a Python mechanism) in SI."""
    named, plain = [], []
    for k, v in model.items():
        if k == "type":
            continue
        if isinstance(v, float) and k in dims:
            named.append(f"{k} = {engineering(v, dims[k], 6)}")  # as typed: six digits
        elif isinstance(v, list) and all(isinstance(e, float) for e in v):  # a derived vector
            plain.append(f"{k} = [" + ", ".join(_plain(e) for e in v) + "]")
        else:
            plain.append(f"{k} = {_plain(v)}" if isinstance(v, float) else f"{k} = {v}")
    if not named and not plain:
        return " (no parameters)"
    if named and len(plain) > DERIVED_SHOWN:  # a file's many derived values: in the JSON, not on one line
        return ": " + ", ".join(named) + f"; {len(plain)} derived values (in the JSON result, --json)"
    return ": " + "; ".join(x for x in (", ".join(named), ", ".join(plain) + "  (SI)" if plain else "") if x)


#: derived model values printed on the model line at most (more are counted, not listed)
DERIVED_SHOWN = 4


def render_result(
    result: Result,
    title: str = "",
    tolerance: float | None = None,
    length: float | None = None,
    parameter_dims: Mapping[str, str] | None = None,
) -> str:
    """A readable table of a result.  ``tolerance``: the solve's (``solver.tolerance``) and
    ``length``: the mechanism's largest length parameter, which say what is rounding noise
    (`cpm_nlp.cli.numbers.Noise`); without a tolerance only -0 is.  ``parameter_dims``:
    the dimension of each declared parameter, shown with its unit."""
    from ..core.result import STATUS_TEXT
    from ..core.units import DIMENSIONS

    lines = []
    lines.append(f"problem : {result.problem}" + (f"  ({title})" if title else ""))
    n = len(result.warnings)
    flagged = f", with {n} warning{'s' if n != 1 else ''} (below)" if n else ""
    lines.append(f"status  : {result.status.value}{flagged}  -- {result.message or STATUS_TEXT[result.status]}")
    s = result.solver
    lines += _solver_lines(s)
    if result.model:
        lines.append("model   : " + result.model.get("type", "") + _model_text(result.model, parameter_dims or {}))
    if not result.values:
        lines.append("(no values: the solve did not succeed)" if not result.ok else "(no values)")
        return "\n".join(lines + _warning_lines(result))
    noise = Noise(tolerance, result.values, result.dimensions, length)
    width = max(len(k) for k in result.values)
    lines.append("")
    for name, value in result.values.items():
        dim = result.dimensions.get(name)
        if isinstance(value, list):
            text = _fmt_list(value, dim, noise)
            unit = result.units.get(name, "")
            if unit and dim not in DIMENSIONS:
                text += f"   ({unit})"
            lines.append(f"{name:<{width}}  {text}")
        else:
            si, friendly = _fmt_scalar(value, dim, noise)
            lines.append(f"{name:<{width}}  {si:<22}" + (f"  {friendly}" if friendly else ""))
    return "\n".join(lines + _warning_lines(result))


def _warning_lines(result: Result) -> list[str]:
    """The result's warnings, one "warning: ..." line each, after a blank line."""
    if not result.warnings:
        return []
    return ["", *(f"warning: {w.message}" for w in result.warnings)]
