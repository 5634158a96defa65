"""The texts that ship (issue 24): the problem files, mechanism files and solver presets, and the
package's own comments, cite only what a user has.  Every ``cpm-nlp ...`` command they cite
parses with the real parser; none refers to the papers' texts beside the checkout
(``../shared/papers``), to a paper by its internal file name, or to a path that does not ship
(``tests/``, ``docs/``, a module that is gone)."""

from __future__ import annotations

import re
import shlex
from pathlib import Path

import pytest

from cpm_nlp.cli.main import build_parser
from tests.conftest import PROBLEMS, ROOT

#: the data files that ship (setup.py: problems/ and configs/ as cpm_nlp/data/...)
DATA_FILES = sorted([*PROBLEMS.rglob("*.yaml"), *(ROOT / "configs").glob("*.yaml")])
#: the package's own files (their comments and docstrings ship too)
PACKAGE_FILES = sorted((ROOT / "cpm_nlp").rglob("*.py"))

#: a command on a line of its own in a comment ("#   cpm-nlp sweep FILE --plot eta.png")
_COMMAND_LINE = re.compile(r"^\s*#\s+(cpm-nlp\s.*?)\s*$", re.M)
#: a command quoted in prose: `cpm-nlp ...`, ``cpm-nlp ...``, or (cpm-nlp WORD)
_QUOTED = re.compile(r"``(cpm-nlp [^`]+)``|`(cpm-nlp [^`]+)`|\((cpm-nlp [a-z][\w-]*)\)")


def _comments(path: Path) -> str:
    """The comments of a YAML file; all the text of a Python file (its comments and docstrings)."""
    text = path.read_text(encoding="utf-8")
    if path.suffix == ".py":
        return text
    return "\n".join(line[line.index("#") :] for line in text.splitlines() if "#" in line)


def _cited_commands() -> list[tuple[str, str, bool]]:
    """(file, command, complete): a command line of a YAML comment is complete (it must run as
    written); a quoted one may name only the subcommand ("`cpm-nlp solve` on this file")."""
    out = []
    for path in DATA_FILES + PACKAGE_FILES:
        text = _comments(path)
        name = str(path.relative_to(ROOT))
        if path.suffix == ".yaml":
            out += [(name, m.group(1), True) for m in _COMMAND_LINE.finditer(text)]
        out += [(name, next(g for g in m.groups() if g), False) for m in _QUOTED.finditer(text)]
    return out


CITED = _cited_commands()


def test_the_cited_commands_are_found():
    assert len(CITED) >= 20
    assert any("sweep_rpr_transmission.yaml" in f and complete for f, _, complete in CITED)


def _subcommands() -> set[str]:
    parser = build_parser()
    action = next(a for a in parser._actions if a.__class__.__name__ == "_SubParsersAction")
    return set(action.choices)


@pytest.mark.parametrize("where, command, complete", CITED, ids=[f"{f}:{c}" for f, c, _ in CITED])
def test_every_cited_command_parses(where, command, complete):
    argv = shlex.split(command)[1:]
    words = [a for a in argv if not a.startswith("-")]
    assert words or argv == ["--help"] or argv == ["--version"], f"{where}: {command!r}"
    if not words:
        return
    assert words[0] in _subcommands(), f"{where}: {command!r} names no subcommand of cpm-nlp"
    if complete:
        try:
            build_parser().parse_args(argv)
        except SystemExit as exc:  # argparse's way of refusing
            pytest.fail(f"{where}: {command!r} does not parse (exit {exc.code})")


@pytest.mark.parametrize("suffix", [".yaml", ".py"])
def test_no_shipped_file_refers_to_the_papers_texts(suffix):
    """The papers' texts (../shared/papers/*.md) do not ship: a file cites a paper by its
    reference (authors, year, title), not by the name of its text."""
    internal = re.compile(r"shared/papers|\b[\w-]+-(?:\d{4}|ruiz)\.md\b")
    files = [p for p in DATA_FILES + PACKAGE_FILES if p.suffix == suffix]
    if suffix == ".py":  # the module docstrings cite papers; the rest of a module is code
        files = [p for p in files if "shared/papers" in p.read_text(encoding="utf-8")]
    found = [
        f"{p.relative_to(ROOT)}: {m.group(0)}" for p in files for m in internal.finditer(p.read_text(encoding="utf-8"))
    ]
    assert not found, "\n".join(found)


def _paths_cited(path: Path) -> list[str]:
    return re.findall(r"(?<![\w/.-])((?:\.\./)+[\w./-]+|(?:tests|docs|benchmarks|cpm_nlp)/[\w./-]*\w)", _comments(path))


@pytest.mark.parametrize("path", DATA_FILES, ids=[str(p.relative_to(ROOT)) for p in DATA_FILES])
def test_a_shipped_data_file_names_only_shipped_paths(path):
    """A path named in a shipped file's comments or values is one that ships: a sibling file
    (``../prs3_jacobian.yaml``) or a module of the package, never the test suite, the
    documentation's sources or a module that is gone."""
    text = path.read_text(encoding="utf-8")
    names = _paths_cited(path) + re.findall(r"(?<![\w/.-])((?:\.\./)+[\w./-]+\.yaml)", text)
    missing = []
    for name in names:
        target = (path.parent / name) if name.startswith("../") else (ROOT / name)
        shipped = target.resolve().is_relative_to(PROBLEMS) or target.resolve().is_relative_to(ROOT / "cpm_nlp")
        if not (shipped and target.exists()):
            missing.append(name)
    assert not missing, f"{path.relative_to(ROOT)} names paths that do not ship: {missing}"


def test_what_the_library_shows_cites_papers_by_reference():
    """Texts the user sees through ``describe`` and the results (materials' and hinge types'
    sources) name a paper by its reference, not its file."""
    from cpm_nlp.analysis.flexure import MATERIALS
    from cpm_nlp.analysis.hinge_types import HINGE_TABLE

    internal = re.compile(r"\b[\w-]+-(?:\d{4}|ruiz)\.md\b")
    texts = [m.source for m in MATERIALS.values()]
    texts += [t for h in HINGE_TABLE.values() for t in (h.source, h.limit_source)]
    assert len(texts) > 10
    assert not [t for t in texts if internal.search(t or "")]
