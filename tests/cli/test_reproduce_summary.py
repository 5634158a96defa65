"""`cpm-nlp reproduce` prints a short summary by default (issue 24): per paper, named by its
reference and never by an internal file name, the figures that agree, differ for a stated
reason, or cannot be reproduced; a total line and how to get the full table.  `--full`
prints the whole table, `--output` writes it (.md, .csv, .json, each read back here), and a
progress bar is drawn on stderr only when stderr is a terminal."""

from __future__ import annotations

import csv
import io
import json
import re

import pytest

import cpm_nlp as cn
from cpm_nlp.cli.main import main
from cpm_nlp.cli.reproduce import WIDTH
from cpm_nlp.core import progress
from tests.cli.reproduce_table import verdict_cells_by_paper
from tests.conftest import PROBLEMS

#: the outcome a verdict cell of the full table shows
_OUTCOME = (("agrees", "agrees"), ("differs", "differs"), ("not reproducible", "not reproducible"))


@pytest.fixture(scope="module")
def shipped_rows():
    """Every shipped figure, solved once for the tests of this module."""
    return cn.reproduce()


@pytest.fixture
def cli_shipped(shipped_rows, monkeypatch):
    """The CLI on the shipped rows solved once (``reproduce`` without paths)."""
    import cpm_nlp.problems.reproduce as module

    monkeypatch.setattr(module, "reproduce", lambda paths=None: shipped_rows if paths is None else pytest.fail())

    def run(*argv: str) -> tuple[int, str, str]:
        out, err = io.StringIO(), io.StringIO()
        code = main(["reproduce", *argv], out=out, err=err)
        return code, out.getvalue(), err.getvalue()

    return run


def _summary_counts(text: str) -> dict[str, tuple[int, int, int, int]]:
    """Per paper of the printed summary: (agree, independent, differ, cannot reproduce)."""
    out = {}
    for line in text.splitlines():
        m = re.fullmatch(r"(.+?)\s+(\d+) \((\d+)\)\s+(\d+)\s+(\d+)", line)
        if m:
            out[m.group(1)] = tuple(int(g) for g in m.groups()[1:])
    return out


def test_the_summary_counts_are_the_full_tables(cli_shipped, shipped_rows):
    code, summary, _ = cli_shipped()
    assert code == 0
    code, full, _ = cli_shipped("--full")
    assert code == 0
    counts = _summary_counts(summary)
    cells = verdict_cells_by_paper(full)
    assert list(counts) == list(cells) == list(dict.fromkeys(r.paper for r in shipped_rows))
    for paper, verdicts in cells.items():
        table = [sum(v.startswith(word) for v in verdicts) for word, _ in _OUTCOME]
        agree, _independent, differ, cannot = counts[paper]
        assert (agree, differ, cannot) == tuple(table), paper
        assert not any("UNEXPECTED" in v for v in verdicts)
    # the independent agreements, counted from the rows themselves
    for paper, (_, independent, _, _) in counts.items():
        assert independent == sum(1 for r in shipped_rows if r.paper == paper and r.agrees and r.independent)
    n = len(shipped_rows)
    agree = sum(c[0] for c in counts.values())
    differ = sum(c[2] for c in counts.values())
    cannot = sum(c[3] for c in counts.values())
    assert agree + differ + cannot == n  # nothing unexpected: every figure is one of the three
    total = f"{n} figures: {agree} agree, {differ} differ for a stated reason, {cannot} cannot be reproduced;"
    assert total in summary
    assert "cpm-nlp reproduce --full" in summary.splitlines()[-1]
    head, hint = summary.rstrip("\n").rsplit("\n", 1)
    assert full.endswith(head + "\n") and hint not in full  # the full table closes with the same summary


def test_the_summary_is_short_and_names_papers_not_files(cli_shipped, shipped_rows):
    _, summary, _ = cli_shipped()
    lines = summary.splitlines()
    assert len(lines) <= 15
    assert max(len(line) for line in lines) <= WIDTH
    # no paper's file, no problem file: the one file name is the example of --output
    assert re.findall(r"[\w-]+\.(?:md|yaml)\b", summary) == []  # no file name: the hint says --output FILE
    assert "shared" not in summary and "papers/" not in summary
    for paper in {r.paper for r in shipped_rows}:  # authors, a year (or why none), a short title
        assert paper in summary
        assert re.search(r"\b(19|20)\d\d\b|year not printed", paper), paper


def test_the_full_table_keeps_to_the_width(cli_shipped):
    _, full, _ = cli_shipped("--full")
    assert max(len(line) for line in full.splitlines()) <= WIDTH
    assert ".md" not in full  # the problem files are named (users can run them), the papers' texts are not


@pytest.mark.parametrize("suffix", [".md", ".csv", ".json"])
def test_output_writes_the_full_table_and_it_parses_back(cli_shipped, shipped_rows, tmp_path, suffix):
    path = tmp_path / f"table{suffix}"
    code, printed, _ = cli_shipped("--output", str(path))
    assert code == 0
    assert printed == cli_shipped()[1]  # stdout keeps the summary
    assert sorted(p.name for p in tmp_path.iterdir()) == [path.name]  # no temporary file left
    text = path.read_text()
    n = len(shipped_rows)
    if suffix == ".json":
        doc = json.loads(text)
        assert len(doc["figures"]) == doc["summary"]["figures"] == n
        assert [f["computed"] for f in doc["figures"]] == [r.computed for r in shipped_rows]  # full precision
    elif suffix == ".csv":
        table = list(csv.DictReader(io.StringIO(text)))
        assert len(table) == n
        for got, r in zip(table, shipped_rows):
            assert got["quantity"] == r.quantity and got["outcome"] == r.outcome
            assert (float(got["computed"]) if got["computed"] else None) == r.computed  # every digit
    else:
        rows = [line for line in text.splitlines() if line.startswith("| ") and line.endswith(" |")]
        figures = [line for line in rows if re.match(r"\| [\w.-]+\.yaml \|", line)]
        assert len(figures) == n
        per_paper = [line for line in rows if re.search(r"( \| \d+){5} \|$", line)]
        assert len(per_paper) == len({r.paper for r in shipped_rows})
        assert sum(int(c.split(" | ")[1]) for c in per_paper) == sum(r.agrees for r in shipped_rows)
        assert text.startswith("# ") and all(f"## {p}" in text for p in {r.paper for r in shipped_rows})


def test_output_refuses_an_unknown_format_and_an_input(cli, tmp_path):
    f = PROBLEMS / "prc3_amplifier.yaml"
    run = cli("reproduce", str(f), "--output", str(tmp_path / "t.txt"))
    assert run.code == 2 and "'.txt'" in run.err and ".md, .csv or .json" in run.err and run.out == ""
    before = f.read_bytes()
    run = cli("reproduce", str(f), "--output", str(f))
    assert run.code == 2 and "input of this command" in run.err and f.read_bytes() == before
    assert list(tmp_path.iterdir()) == []


class _Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


@pytest.mark.parametrize("tty", [True, False])
def test_a_progress_bar_only_on_a_terminal(monkeypatch, tty):
    monkeypatch.setattr(progress, "INTERVAL", 0.0)  # every problem file reports
    out, err = io.StringIO(), (_Terminal() if tty else io.StringIO())
    files = [str(PROBLEMS / n) for n in ("prc3_amplifier.yaml", "rpr_twists_eq47.yaml", "rpr_twists_eq49.yaml")]
    assert main(["reproduce", *files], out=out, err=err) == 0
    drawn = err.getvalue()
    if tty:
        assert "reproducing the published figures" in drawn and "problem files" in drawn
    else:
        assert drawn == ""
    assert "reproducing" not in out.getvalue()  # the bar never goes to stdout


def test_an_unexpected_figure_gets_its_column_and_exit_1(cli, tmp_path):
    """A figure that differs without a stated reason is counted apart, flagged in the full table,
    and the exit status is 1 as before."""
    import yaml

    text = (PROBLEMS / "prc3_amplifier.yaml").read_text().split("reproduce:")[0]
    row = {"quantity": "A1", "source": "eq 1", "published": 3.0, "value": "A1", "tolerance": "0.02 %"}
    paper = "Li et al. 2018, 3-PRC micromanipulator"
    f = tmp_path / "amp.yaml"
    f.write_text(text + yaml.safe_dump({"reproduce": {"paper": paper, "rows": [row]}}))
    run = cli("reproduce", str(f))
    assert run.code == 1
    head = next(line for line in run.out.splitlines() if line.startswith("paper"))
    assert head.split()[-1] == "UNEXPECTED"
    assert re.search(rf"^{re.escape(paper)} +0 \(0\) +0 +0 +1$", run.out, re.M)
    assert "1 figures: 0 agree, 0 differ for a stated reason, 0 cannot be reproduced; 1 unexpected." in run.out
    full = cli("reproduce", "--full", str(f))
    assert full.code == 1 and verdict_cells_by_paper(full.out)[paper][0].endswith("UNEXPECTED")
