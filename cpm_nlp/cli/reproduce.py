"""``cpm-nlp reproduce``: every problem file that reproduces a published figure.

By default a short summary: per paper, the figures that agree, that differ for
a stated reason, and that cannot be reproduced, then a total.  ``--full`` prints
the whole table (grouped by paper and problem file, cells wrapped, reasons
numbered once per paper); ``--output FILE`` writes it to a file whose suffix
gives the format (`FORMATS`: ``.md``, ``.csv``, ``.json``), atomically;
``--json`` prints the JSON document.  Every printed line is at most
`WIDTH` characters.
"""

from __future__ import annotations

import argparse
import csv
import io
import json
import re
import textwrap
from collections.abc import Callable, Sequence
from pathlib import Path

from ..core import blas
from ..io.atomic import check_output_path, write_atomic
from .exits import EXIT_FAILED, EXIT_OK
from .streams import solver_output

TYPE_CHECKING = False  # typing itself is not imported at start-up; the annotations are strings
if TYPE_CHECKING:
    from typing import Any, TextIO

#: the widest line printed (summary and full table)
WIDTH = 100


def _category_note(r: Any) -> str:
    """What the published value is, when it is not simply a printed number, and an echo."""
    parts = [] if r.category == "published" else [r.category.replace("_", " ")]
    return ", ".join(parts + (["echo"] if r.echoes else []))


def _computed(r: Any) -> str:
    """The computed value with the prefix that suits it, to five digits (one more than
    elsewhere: the printed figure it is compared with often has four)."""
    from .numbers import engineering

    return "—" if r.computed is None else engineering(r.computed, r.dimension, 5)


def _rel(r: Any) -> str:
    """The relative error in per cent, two decimals below 10 % (the JSON keeps every digit)."""
    if r.rel_error is None:
        return "—"
    pct = r.rel_error * 100
    if pct == 0:
        return "0 %"
    if pct < 0.005:
        return "<0.01 %"
    return f"{pct:.0f} %" if pct >= 99.95 else f"{pct:.1f} %" if pct >= 9.995 else f"{pct:.2f} %"


def _verdict(r: Any) -> str:
    note = _category_note(r)
    return r.verdict + (f" ({note})" if note else "") + ("" if r.expected else " UNEXPECTED")


def _notes(r: Any) -> list[str]:
    """The reasons a row carries, each a footnote of the full table."""
    out = [r.reason] if r.reason else []
    if r.tolerance_reason:
        out.append("tolerance: " + r.tolerance_reason)
    if r.echoes:
        out.append("the computed value echoes an input: " + r.echoes)
    return out


def _papers(rows: Sequence[Any]) -> dict[str, list[Any]]:
    """The rows by paper, in the order the papers first come."""
    out: dict[str, list[Any]] = {}
    for r in rows:
        out.setdefault(r.paper, []).append(r)
    return out


# -- the summary ---------------------------------------------------------------------------------


def render_summary(rows: Sequence[Any], summary: dict[str, Any], hint: bool = True) -> str:
    """Per paper the counts of each outcome, a total line, and (``hint``) how to get the full table."""
    papers = summary["papers"]
    unexpected = summary["unexpected"]
    head = ["paper", "agree (independent)", "differ", "cannot reproduce"] + (["UNEXPECTED"] if unexpected else [])
    numbers = [
        [f"{c['agrees']} ({c['independent']})", str(c["differs"]), str(c["not reproducible"])]
        + ([str(c["unexpected"])] if unexpected else [])
        for c in papers.values()
    ]
    widths = [len(h) for h in head[1:]]
    name_width = min(max(len(p) for p in papers), WIDTH - sum(w + 2 for w in widths))
    names = [p if len(p) <= name_width else p[: name_width - 1] + "…" for p in papers]

    def line(name: str, cells: Sequence[str]) -> str:
        return (name.ljust(name_width) + "".join("  " + c.rjust(w) for c, w in zip(cells, widths))).rstrip()

    n_files = len({r.file for r in rows})
    agree = sum(c["agrees"] for c in papers.values())
    independent = sum(c["independent"] for c in papers.values())
    differ = sum(c["differs"] for c in papers.values())
    out = [
        f"Published figures of {len(papers)} paper{'s' if len(papers) != 1 else ''}, "
        f"computed from {n_files} problem file{'s' if n_files != 1 else ''}:",
        "",
        line(head[0], head[1:]),
        *(line(n, c) for n, c in zip(names, numbers)),
        "",
    ]
    out += textwrap.wrap(
        f"{summary['figures']} figures: {agree} agree, {differ} differ for a stated reason, "
        f"{summary['not_reproducible']} cannot be reproduced; {unexpected} unexpected.",
        WIDTH,
    )
    out += textwrap.wrap(
        f"Independent agreements ({independent}): a number the paper prints, computed from other inputs.", WIDTH
    )
    if hint:
        out.append("Every figure and reason: cpm-nlp reproduce --full, or --output FILE (.md, .csv, .json)")
    return "\n".join(out)


# -- the full table as text ----------------------------------------------------------------------

#: the columns of the full text table: header and width (the last one takes the rest)
_COLUMNS = (("quantity", 23), ("source", 14), ("published", 11), ("computed", 12), ("error", 7), ("verdict", 0))
_INDENT = "  "


#: a number and its unit ("1 %", "0.008 mm") stay on one line of a wrapped cell
_NUMBER_UNIT = re.compile(r"(?<=\d) (?=[^\d\s(\[])")


def _wrap(text: str, width: int) -> list[str]:
    held = _NUMBER_UNIT.sub("\0", text)
    return [line.replace("\0", " ") for line in textwrap.wrap(held, width, break_on_hyphens=False)]


def _wrapped_row(cells: Sequence[str], widths: Sequence[int]) -> list[str]:
    """One table row whose cells are wrapped to their widths (a row of several lines)."""
    columns = [_wrap(c, w) or [""] for c, w in zip(cells, widths)]
    depth = max(len(c) for c in columns)
    lines = []
    for i in range(depth):
        parts = [(col[i] if i < len(col) else "").ljust(w) for col, w in zip(columns, widths)]
        lines.append((_INDENT + "  ".join(parts)).rstrip())
    return lines


def render_full(rows: Sequence[Any]) -> str:
    """The full table: per paper, per problem file, one row per figure (cells wrapped),
    the reasons numbered once per paper below its rows."""
    widths = [w for _, w in _COLUMNS[:-1]]
    widths.append(WIDTH - len(_INDENT) - sum(widths) - 2 * (len(widths)))
    out: list[str] = []
    for paper, paper_rows in _papers(rows).items():
        notes: dict[str, int] = {}
        out += ["", paper, "=" * min(len(paper), WIDTH)]
        file = None
        for r in paper_rows:
            if r.file != file:
                file = r.file
                out += ["", f"{_INDENT}{Path(file).name}:", *_wrapped_row([h for h, _ in _COLUMNS], widths)]
            marks = "".join(f" [{notes.setdefault(n, len(notes) + 1)}]" for n in _notes(r))
            cells = [r.quantity, r.source, r.published_text, _computed(r), _rel(r), _verdict(r) + marks]
            out += _wrapped_row(cells, widths)
        if notes:
            out.append("")
            for text, n in notes.items():
                mark = f"{_INDENT}[{n}] "
                out += textwrap.wrap(text, WIDTH, initial_indent=mark, subsequent_indent=" " * len(mark))
    return "\n".join(out).lstrip("\n")


# -- the full table in a file ----------------------------------------------------------------------

_FIELDS = (
    "paper",
    "file",
    "quantity",
    "source",
    "category",
    "published_text",
    "published",
    "computed",
    "unit",
    "rel_error",
    "verdict",
    "outcome",
    "independent",
    "echoes_input",
    "reason",
    "tolerance_reason",
    "expected",
)


def _record(r: Any) -> dict[str, Any]:
    d = r.to_dict()
    d["file"] = Path(r.file).name
    d["outcome"] = r.outcome
    return {k: d[k] for k in _FIELDS}


def table_csv(rows: Sequence[Any], summary: dict[str, Any]) -> str:  # noqa: ARG001 (one signature for all formats)
    """One CSV line per figure, every field (numbers in SI, full precision)."""
    buf = io.StringIO()
    writer = csv.DictWriter(buf, fieldnames=_FIELDS, lineterminator="\n")
    writer.writeheader()
    for r in rows:
        writer.writerow({k: "" if v is None else v for k, v in _record(r).items()})
    return buf.getvalue()


def _md_cell(text: str) -> str:
    return str(text).replace("|", "\\|").replace("\n", " ")


def table_markdown(rows: Sequence[Any], summary: dict[str, Any]) -> str:
    """The summary, then per paper a Markdown table and its numbered reasons."""
    out = ["# Published figures reproduced by cpm_nlp", ""]
    out += [
        "| paper | agree | independent | differ | cannot reproduce | unexpected |",
        "| --- | ---: | ---: | ---: | ---: | ---: |",
    ]
    for paper, c in summary["papers"].items():
        out.append(
            f"| {_md_cell(paper)} | {c['agrees']} | {c['independent']} | {c['differs']} | "
            f"{c['not reproducible']} | {c['unexpected']} |"
        )
    for paper, paper_rows in _papers(rows).items():
        notes: dict[str, int] = {}
        out += ["", f"## {paper}", "", "| file | quantity | source | published | computed | error | verdict |"]
        out.append("| --- | --- | --- | --- | --- | ---: | --- |")
        for r in paper_rows:
            marks = "".join(f" [{notes.setdefault(n, len(notes) + 1)}]" for n in _notes(r))
            cells = [Path(r.file).name, r.quantity, r.source, r.published_text, _computed(r), _rel(r)]
            out.append("| " + " | ".join(_md_cell(c) for c in [*cells, _verdict(r) + marks]) + " |")
        if notes:
            out += ["", *(f"{n}. {_md_cell(text)}" for text, n in notes.items())]
    return "\n".join(out) + "\n"


def table_json(rows: Sequence[Any], summary: dict[str, Any]) -> str:
    """The JSON document of ``--json``: every figure (SI, full precision) and the summary."""
    from ..core.result import jsonable

    report = jsonable({"figures": [r.to_dict() for r in rows], "summary": summary})  # no NaN: null
    return json.dumps(report, indent=2, allow_nan=False) + "\n"


#: the formats of ``--output``, by suffix
FORMATS: dict[str, Callable[[Sequence[Any], dict[str, Any]], str]] = {
    ".md": table_markdown,
    ".csv": table_csv,
    ".json": table_json,
}


def _output_format(path: str | None) -> Callable[[Sequence[Any], dict[str, Any]], str] | None:
    """The writer of ``--output`` by its suffix; any other suffix is bad input (before solving)."""
    if path is None:
        return None
    from ..core.errors import InputError

    suffix = Path(path).suffix.lower()
    if suffix not in FORMATS:
        raise InputError(
            f"unknown table format {suffix or '(no suffix)'!r}; expected a file name ending in "
            + ", ".join(list(FORMATS)[:-1])
            + f" or {list(FORMATS)[-1]}",
            file=path,
            path=("--output",),
        )
    return FORMATS[suffix]


def cmd_reproduce(args: argparse.Namespace, out: TextIO) -> int:
    blas.cap_process()  # first: before numpy loads its BLAS, the cap is its environment (core/blas.py)
    from ..core import progress
    from ..problems.published import summarize
    from ..problems.reproduce import default_problem_dirs, problem_files, reproduce
    from .bars import progress_bars

    inputs = problem_files(args.paths or default_problem_dirs())  # never written over
    check_output_path(args.output, inputs, option="--output")
    writer = _output_format(args.output)
    with solver_output(args), progress.reporting(progress_bars(args)):
        rows = reproduce(args.paths or None)
    summary = summarize(rows)
    if args.json:
        out.write(table_json(rows, summary))
    elif args.full:
        out.write(render_full(rows) + "\n\n" + render_summary(rows, summary, hint=False) + "\n")
    else:
        out.write(render_summary(rows, summary) + "\n")
    if writer is not None:
        write_atomic(args.output, writer(rows, summary), inputs=inputs, option="--output")
    return EXIT_OK if all(r.expected for r in rows) else EXIT_FAILED
