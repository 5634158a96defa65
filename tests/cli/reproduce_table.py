"""Reading back the full text table of ``cpm-nlp reproduce --full`` (for the tests)."""

from __future__ import annotations


def verdict_cells_by_paper(text: str) -> dict[str, list[str]]:
    """Per paper (a title underlined with '='), the verdict cell of every row, a wrapped
    cell's lines joined.  A row starts on the line whose error cell is filled (an error
    never wraps); the lines after it, up to the next such line, continue its cells."""
    lines = text.splitlines()
    out: dict[str, list[str]] = {}
    paper = None
    columns = None  # (start of the error column, start of the verdict column)
    for k, line in enumerate(lines):
        if k + 1 < len(lines) and lines[k + 1].startswith("===") and line:
            paper, columns = line, None
            out[paper] = []
            continue
        words = line.split()
        if words[:2] == ["quantity", "source"]:
            columns = (line.index("error"), line.index("verdict"))
            continue
        if line.startswith("  [") and line[3:4].isdigit():
            columns = None  # the reasons: this paper's table is over
        if paper is None or columns is None or not line.startswith("  "):
            continue
        if line.endswith(":") and len(words) == 1:  # a problem file's heading
            continue
        error, verdict = line[columns[0] : columns[1]].strip(), line[columns[1] :].strip()
        if error:
            out[paper].append(verdict)
        elif verdict and out[paper]:
            out[paper][-1] += " " + verdict
    return out
