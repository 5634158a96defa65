"""``cpm-nlp reproduce``: every problem file that reproduces a published figure, as a table."""

from __future__ import annotations

import argparse
import json
from collections.abc import Sequence

from ..core import blas
from ..io.atomic import check_output_path, write_atomic
from .exits import EXIT_FAILED, EXIT_OK
from .streams import solver_output

TYPE_CHECKING = False  # typing itself is not imported at start-up; the annotations are strings
if TYPE_CHECKING:
    from typing import Any, TextIO


def _category_cell(r: Any) -> str:
    text = r.category.replace("_", " ")
    return text + (", echo" if r.echoes else "")


def render_reproduce(rows: Sequence[Any]) -> str:
    """The reproduction table, reasons numbered once below it.  The "what" column
    says what the published value is (its category) and ", echo" when the
    computed value is an input given back."""
    from ..core.units import format_quantity

    header = ("paper", "quantity", "source", "what", "published", "computed", "rel. error", "verdict")
    table = []
    reasons: dict[str, int] = {}

    def note(text: str) -> str:
        return f" [{reasons.setdefault(text, len(reasons) + 1)}]"

    for r in rows:
        comp = "—" if r.computed is None else format_quantity(r.computed, r.dimension, 5)
        rel = "—" if r.rel_error is None else f"{r.rel_error * 100:.2f} %"
        verdict = r.verdict + ("" if r.expected else "  [UNEXPECTED]")
        if r.reason:
            verdict += note(r.reason)
        if r.tolerance_reason:
            verdict += note("tolerance: " + r.tolerance_reason)
        if r.echoes:
            verdict += note("computed value echoes an input: " + r.echoes)
        table.append((r.paper, r.quantity, r.source, _category_cell(r), r.published_text, comp, rel, verdict))
    widths = [max(len(str(x)) for x in col) for col in zip(header, *table)]

    def line(cells: Sequence[Any]) -> str:
        return "  ".join(str(c).ljust(w) for c, w in zip(cells, widths)).rstrip()

    out = [line(header), line(["-" * w for w in widths])] + [line(t) for t in table]
    if reasons:
        out += ["", "reasons:"] + [f"  [{n}] {text}" for text, n in reasons.items()]
    return "\n".join(out)


def render_reproduce_summary(summary: dict[str, Any]) -> str:
    """Independent agreements apart from those that are not; the last line is
    "N figures, M unexpected"."""
    parts = [f"{n} {c.replace('_', ' ')}" for c, n in summary["agree_not_independent_by_category"].items()]
    if summary["agree_echoing_an_input"]:
        parts.append(f"{summary['agree_echoing_an_input']} echo an input")
    lines = [
        f"agree, independently: {summary['agree_independent']} (a printed figure, computed from other inputs)",
        f"agree, not independently: {summary['agree_not_independent']}" + (f" ({', '.join(parts)})" if parts else ""),
        f"differ, as explained: {summary['differ'] - summary['unexpected_differ']}; "
        f"not reproducible: {summary['not_reproducible']}",
        f"{summary['figures']} figures, {summary['unexpected']} unexpected",
    ]
    return "\n".join(lines)


def cmd_reproduce(args: argparse.Namespace, out: TextIO) -> int:
    blas.cap_process()  # first: before numpy loads its BLAS, the cap is its environment (core/blas.py)
    from ..core.result import jsonable
    from ..problems.published import summarize
    from ..problems.reproduce import reproduce

    check_output_path(args.output, args.paths)
    with solver_output(args):
        rows = reproduce(args.paths or None)
    summary = summarize(rows)
    report = jsonable({"figures": [r.to_dict() for r in rows], "summary": summary})  # no NaN: null
    document = json.dumps(report, indent=2, allow_nan=False) + "\n"
    if args.json:
        out.write(document)
    else:
        out.write(render_reproduce(rows) + "\n\n" + render_reproduce_summary(summary) + "\n")
    if args.output:
        write_atomic(args.output, document, inputs=args.paths)
    return EXIT_OK if all(r.expected for r in rows) else EXIT_FAILED
