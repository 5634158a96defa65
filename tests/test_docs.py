"""Every code block of the README and of the documentation (docs/site/**/*.md) runs.

The fenced blocks are extracted and executed, page by page, in a temporary copy of
``problems/``, ``configs/`` and ``examples/`` (so a page may write files and later blocks
of the page may read them):

* ``bash``: each line is a command. ``cpm-nlp ...`` runs in-process through the CLI's
  ``main`` and must exit 0, or the status named by a trailing ``|| test $? -eq N``. In a
  line joined by ``&&``, ``pip install -e ...`` is checked rather than run (the extras it
  names exist; the test environment is that installation) and ``python -m pytest`` must be
  the command ``.ci/run`` runs (it is this suite). A block with anything else (a heredoc,
  a compiler) runs as one ``bash -euo pipefail`` script with this installation first on
  ``PATH``.
* ``python``: executed, the blocks of a page sharing one namespace.
* ``yaml``: a problem file, written (to the path of a preceding ``<!-- file: PATH -->``
  comment, else a temporary name) and validated with ``cpm-nlp check``; a mechanism file
  (with ``legs``, or ``bodies`` and ``joints``) is written and loaded, and one marked ``<!-- file: PATH invalid -->``
  (a deliberate mistake the page shows) must fail to load as bad input.
* a ``bash`` block may be followed by ``<!-- output: TEXT -->`` lines: each claim the
  prose makes about that block's output, which must then contain TEXT (runs of
  whitespace compared as one space).
* ``text`` and ``toml``: illustrative only (usage synopses, a cluster's own commands, an
  error message, an entry-point table tested by tests/mechanisms/test_plugin.py); kept few.
"""

from __future__ import annotations

import os
import re
import shlex
import shutil
import subprocess
import sys
from dataclasses import dataclass
from importlib import metadata
from pathlib import Path

import pytest
import yaml

import cpm_nlp as cn
from cpm_nlp.mechanisms.registry import mechanism_names
from cpm_nlp.mechanisms.registry import unregister as unregister_mechanism
from tests.conftest import ROOT, run_cli

PAGES = [ROOT / "README.md", *sorted((ROOT / "docs" / "site").rglob("*.md"))]
EXECUTED = ("bash", "python", "yaml")
ILLUSTRATIVE = ("text", "toml")
MAX_ILLUSTRATIVE = 12
FENCE = re.compile(r"^(?P<indent>[ \t]*)```(?P<lang>[^\s`]*)[^\n]*\n(?P<body>.*?)^(?P=indent)```[ \t]*$", re.M | re.S)
FILE_MARK = re.compile(r"<!--\s*file:\s*(\S+)(?P<invalid>\s+invalid)?\s*-->\s*$")
EXPECT = re.compile(r"^(?P<cmd>.*?)\s*\|\|\s*test \$\? -eq (?P<code>\d+)$")
OUTPUT_MARK = re.compile(r"\A\s*<!--\s*output:\s*(?P<text>.*?)\s*-->[ \t]*\n?")


@dataclass
class Block:
    page: Path
    line: int
    lang: str
    body: str
    file: str | None
    invalid: bool = False  # a mechanism file written to show its error: loading it must fail (exit 2)
    outputs: tuple[str, ...] = ()  # <!-- output: TEXT --> after the block: what its output must contain


def blocks(page: Path) -> list[Block]:
    text = page.read_text(encoding="utf-8")
    out = []
    for m in FENCE.finditer(text):
        indent = m.group("indent")
        lines = m.group("body").splitlines(True)
        body = "".join(line[len(indent) :] if line.startswith(indent) else line for line in lines)
        before = text[: m.start()].rstrip("\n").rsplit("\n", 1)[-1]
        mark = FILE_MARK.search(before)
        line = text.count("\n", 0, m.start()) + 1
        file, invalid = (mark.group(1), bool(mark.group("invalid"))) if mark else (None, False)
        outputs, rest = [], text[m.end() :].lstrip("\n")
        while (claim := OUTPUT_MARK.match(rest)) is not None:
            outputs.append(claim.group("text"))
            rest = rest[claim.end() :]
        out.append(Block(page, line, m.group("lang"), body, file, invalid, tuple(outputs)))
    return out


def _name(page: Path) -> str:
    return str(page.relative_to(ROOT)) if page.is_relative_to(ROOT) else str(page)


def test_every_block_is_executed_or_marked_illustrative():
    langs = [(b, b.lang) for p in PAGES for b in blocks(p)]
    bad = [f"{_name(b.page)}:{b.line} ```{lang}" for b, lang in langs if lang not in EXECUTED + ILLUSTRATIVE]
    assert not bad, "code blocks neither executed nor marked illustrative (text, toml): " + ", ".join(bad)
    illustrative = [b for b, lang in langs if lang in ILLUSTRATIVE]
    assert len(illustrative) <= MAX_ILLUSTRATIVE, [f"{_name(b.page)}:{b.line}" for b in illustrative]
    assert sum(lang in EXECUTED for _, lang in langs) >= 30  # the extraction finds them


def test_readme_starts_with_the_two_commands_ci_runs():
    first = blocks(ROOT / "README.md")[0]
    assert first.lang == "bash"
    assert first.body.splitlines() == [
        "pip install -e . && cpm-nlp solve problems/prs3_forward_kinematics.yaml && cpm-nlp reproduce",
        "pip install -e '.[test]' && python -m pytest",
    ]
    assert "\npip install -e '.[test]' && python -m pytest\n" in (ROOT / ".ci" / "run").read_text()


def test_no_links_outside_the_repository():
    for page in PAGES:
        assert "shared/papers" not in page.read_text(encoding="utf-8"), _name(page)


@pytest.fixture(scope="session")
def reproduce_memo():
    """``cpm-nlp reproduce`` runs in several pages over the same shipped problem files
    (the README and the published-figures page over all of them): a problem solved once
    in this session is not solved again.  The key is everything the result depends on
    (the kind, the mechanism's closure object, its parameters and limits, the file's parsed
    content after ``--set``), so a page that changes a problem still solves it; every block still runs
    the command, its comparison and its table."""
    from cpm_nlp.problems import reproduce

    solved: dict[str, tuple] = {}  # key -> (the closure, kept alive so that its id stays its own; result)
    real = reproduce.solve

    def solve(problem):
        key = repr(
            (
                problem.kind.name,
                id(problem.model.closure),  # a mechanism file's closure is its content's (and path's)
                sorted(problem.model.parameters.items()),
                sorted(problem.model.limits.items()),
                yaml.safe_dump(problem.data, sort_keys=True),
            )
        )
        if key not in solved:
            solved[key] = (problem.model.closure, real(problem))
        return solved[key][1]

    return reproduce, solve


@pytest.fixture
def workdir(tmp_path, monkeypatch, reproduce_memo):
    module, memo = reproduce_memo
    monkeypatch.setattr(module, "solve", memo)
    for d in ("problems", "configs", "examples"):
        shutil.copytree(ROOT / d, tmp_path / d)
    monkeypatch.chdir(tmp_path)
    before = set(mechanism_names())
    yield tmp_path
    for name in set(mechanism_names()) - before:  # mechanisms a page registered in code
        unregister_mechanism(name)


def _extras() -> set[str]:
    return set(metadata.metadata("cpm_nlp").get_all("Provides-Extra") or ())


def _check_pip(segment: str, where: str) -> None:
    """``pip install -e .``, ``pip install -e '.[EXTRAS]'`` (a checkout) or ``pip install
    'cpm_nlp[EXTRAS]'`` (a user's install): the extras it names exist."""
    m = re.fullmatch(
        r"pip install (?:-e (?:\.|'\.\[(?P<extras>[\w,]+)\]')|'?cpm_nlp(?:\[(?P<user>[\w,]+)\])?'?)", segment
    )
    assert m, f"{where}: unexpected install command {segment!r}"
    for extra in (m.group("extras") or m.group("user") or "").split(","):
        assert not extra or extra in _extras(), f"{where}: no extra {extra!r} in pyproject.toml"


def _run_cpm(command: str, where: str) -> str:
    expected = 0
    m = EXPECT.match(command)
    if m:
        command, expected = m.group("cmd"), int(m.group("code"))
    argv = shlex.split(command)
    assert argv[0] == "cpm-nlp", where
    run = run_cli(*argv[1:])
    detail = f"{run.err}{run.out[-2000:]}"
    assert run.code == expected, f"{where}: `{command}` exited {run.code}, expected {expected}\n{detail}"
    return run.out + run.err


def _simple(line: str) -> bool:
    return all(s.startswith(("cpm-nlp ", "pip install ", "python -m pytest")) for s in line.split(" && "))


def _check_claims(block: Block, output: str) -> None:
    """Each ``<!-- output: TEXT -->`` after the block is in what it printed."""
    flat = " ".join(output.split())
    for claim in block.outputs:
        assert " ".join(claim.split()) in flat, f"{_name(block.page)}:{block.line}: the output lacks {claim!r}"


def _run_bash(block: Block) -> None:
    where = f"{_name(block.page)}:{block.line}"
    lines = [line for line in block.body.splitlines() if line.strip() and not line.lstrip().startswith("#")]
    if all(_simple(line) for line in lines):
        printed = []
        for line in lines:
            for segment in line.split(" && "):
                if segment.startswith("pip install "):
                    _check_pip(segment, where)
                elif segment.startswith("python -m pytest"):
                    assert segment == "python -m pytest", where  # this suite, run by .ci/run
                else:
                    printed.append(_run_cpm(segment, where))
        _check_claims(block, "\n".join(printed))
        return
    env = dict(os.environ, PATH=str(Path(sys.executable).parent) + os.pathsep + os.environ.get("PATH", ""))
    proc = subprocess.run(
        ["bash", "-euo", "pipefail", "-c", block.body], capture_output=True, text=True, env=env, timeout=600
    )
    assert proc.returncode == 0, f"{where}: exit {proc.returncode}\n{proc.stderr[-3000:]}{proc.stdout[-2000:]}"
    _check_claims(block, proc.stdout + proc.stderr)


def _run_yaml(block: Block, k: int) -> None:
    where = f"{_name(block.page)}:{block.line}"
    data = yaml.safe_load(block.body)
    path = Path(block.file) if block.file else Path("problems") / f"_doc_block_{k}.yaml"
    mechanism = isinstance(data, dict) and ("legs" in data or "bodies" in data)  # legs, or bodies and joints
    if mechanism and block.file:  # a mechanism file, used by the blocks after it
        path.write_text(block.body, encoding="utf-8")
        if block.invalid:  # the page shows its error next; loading must fail as bad input
            with pytest.raises(cn.InputError):
                cn.load_mechanism_file(path, register=False)
            return
        cn.load_mechanism_file(path, register=False)
        return
    assert isinstance(data, dict) and "problem" in data, f"{where}: a yaml block must be a whole problem file"
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(block.body, encoding="utf-8")
    run = run_cli("check", str(path))
    assert run.code == 0, f"{where}: cpm-nlp check failed\n{run.err}"


def _page_params():
    return [pytest.param(p, id=_name(p)) for p in PAGES if any(b.lang in EXECUTED for b in blocks(p))]


@pytest.mark.parametrize("page", _page_params())
def test_page_runs(page, workdir):
    namespace: dict = {"__name__": "__doc_page__"}
    for k, block in enumerate(blocks(page)):
        if block.lang == "bash":
            _run_bash(block)
        elif block.lang == "python":
            code = compile(block.body, f"{_name(page)}:{block.line}", "exec")
            exec(code, namespace)  # noqa: S102 - the documentation's own example code
        elif block.lang == "yaml":
            _run_yaml(block, k)


def test_output_claims_are_read_and_checked(tmp_path):
    """``<!-- output: TEXT -->`` after a bash block: read with the block, and a claim the
    output does not bear out fails the page."""
    page = tmp_path / "page.md"
    page.write_text("```bash\ncpm-nlp --version\n```\n<!-- output: cpm-nlp -->\n<!-- output: not printed -->\n")
    (block,) = blocks(page)
    assert block.outputs == ("cpm-nlp", "not printed")
    _check_claims(Block(page, 1, "bash", "", None, outputs=("cpm-nlp  0",)), "cpm-nlp\t0\n")
    with pytest.raises(AssertionError, match="lacks 'not printed'"):
        _check_claims(block, "cpm-nlp 0.1\n")
