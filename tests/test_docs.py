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
  whitespace compared as one space); after an invalid mechanism file, the claims are
  about its error message.  Values the prose quotes from a result are checked by the
  page's own ``python`` blocks (``cn.solve``, ``cn.reproduce``), which run here too.
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
from cpm_nlp.mechanisms.registry import mechanism_names, mechanism_type
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
        if block.invalid:  # the page shows its error next; loading must fail as bad input, saying what it quotes
            with pytest.raises(cn.InputError) as error:
                cn.load_mechanism_file(path, register=False)
            _check_claims(block, str(error.value))
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


# -- the site's generated parts: figures, mechanism pages, rotation convention, user pages --

SITE = ROOT / "docs" / "site"


def _developer_pages() -> set[Path]:
    """The pages of the navigation's Developers section (the design notes, the benchmarks):
    they, and the changelog, may name the repository's files and issues."""
    nav = yaml.safe_load((ROOT / "docs" / "mkdocs.yml").read_text(encoding="utf-8"))["nav"]
    (section,) = [s["Developers"] for s in nav if isinstance(s, dict) and "Developers" in s]
    return {SITE / path for item in section for path in item.values()}


#: the pages a user reads
USER_PAGES = [p for p in sorted(SITE.rglob("*.md")) if p not in _developer_pages()]


def _docs_module(name: str):
    """docs/figures.py or docs/hooks.py, imported as the site build imports them."""
    import importlib

    if str(ROOT / "docs") not in sys.path:
        sys.path.insert(0, str(ROOT / "docs"))
    return importlib.import_module(name)


def test_figures_on_disk_are_the_scripts():
    """Every image docs/figures.py lists is on disk, and every image in its folders is listed
    (a figure dropped from the script is deleted, not left to drift)."""
    figures = _docs_module("figures")
    listed = {f.path for f in figures.all_figures()}
    assert not [str(p) for p in listed if not p.is_file()], "run python docs/figures.py"
    on_disk = {p for d in figures.GENERATED_DIRS for p in (figures.ASSETS / d).glob("*")}
    assert on_disk - listed == set(), "images no figure of docs/figures.py draws"
    names = [f.name for f in figures.all_figures()]
    assert len(names) == len(set(names))


def test_every_shipped_mechanism_has_its_page_and_sketch():
    """A page per registered mechanism (generated by docs/hooks.py), each with its sketch, and
    every shipped mechanism file among them."""
    hooks, figures = _docs_module("hooks"), _docs_module("figures")
    names = list(mechanism_names())
    shipped = {
        yaml.safe_load(p.read_text(encoding="utf-8"))["name"] for p in (ROOT / "problems" / "mechanisms").glob("*.yaml")
    }
    assert shipped <= set(names) and len(shipped) >= 10
    index = hooks.mechanisms_index(names)
    by_mechanism = figures.problem_files_by_mechanism()
    for name in names:
        assert f"(mechanisms/{name}.md)" in index, name
        page = hooks.mechanism_page(name, by_mechanism)
        assert (
            f"(../../assets/mechanisms/{name}.png)" in page
            and (figures.ASSETS / "mechanisms" / f"{name}.png").is_file()
        )
        assert all(f"`{o.name}`" in page for o in mechanism_type(name).parameters), name
        assert all(f"`{f}`" in page for f in by_mechanism[name]), name  # its shipped problem files
        assert f"problems/{figures.sketch_problem(name, by_mechanism)}" in page
    from cpm_nlp.mechanisms.registry import ALIASES  # the older names: 14 names in all today

    for alias, target in ALIASES.items():
        assert f"`{alias}`" in hooks.mechanism_page(target, by_mechanism), alias


def test_overview_pictures_are_drawn_by_the_commands_under_them():
    """Each picture of the overview is a figure of docs/figures.py, and the command printed under
    it is the one that drew it (same subcommand, problem file and plot options)."""
    figures = _docs_module("figures")
    text = (SITE / "overview.md").read_text(encoding="utf-8")
    overview = [f for f in figures.FIGURES if f.name.startswith("overview/")]
    assert len(overview) >= 8
    for f in overview:
        image = f"(assets/{f.name}.png)"
        assert image in text, image
        caption = text[text.index(image) :].split("\n\n")[1]
        command = f"cpm-nlp {f.argv[0]} {f.argv[1]}"
        assert command in caption, (f.name, caption)
        options = [a for k, a in enumerate(f.argv) if a in ("--type", "--best")]
        for option in options:
            assert f"{option} {f.argv[f.argv.index(option) + 1]}" in caption, (f.name, option)
    sweep = yaml.safe_load((ROOT / "problems" / "sweep_rpr_transmission.yaml").read_text(encoding="utf-8"))
    assert f"over {sweep['sweep']['samples']} sampled designs" in text


def test_rotation_page_states_each_mechanisms_rotation():
    """The table of reference/rotation.md gives, for every registered mechanism, the product its
    mechanism file writes (its matrix against the model's is checked by the page's own code)."""
    hooks = _docs_module("hooks")
    text = (SITE / "reference" / "rotation.md").read_text(encoding="utf-8")
    stated = {}
    for row in re.finditer(r"^\| (?P<names>`[^|]+) \| (?P<r>R = [^|]+?|no platform rotation) \|", text, re.M):
        for name in re.findall(r"`(\w+)`", row.group("names")):
            stated[name] = row.group("r")
    assert set(stated) == set(mechanism_names())
    for name, r in stated.items():
        code = hooks._rotation_text(mechanism_type(name))
        if r == "no platform rotation":  # a linkage of bodies and joints (Jansen's leg)
            assert code.startswith("not a platform rotation"), (name, r, code)
            continue
        assert (code == r) if r != "R = I" else code.startswith("fixed: R = I"), (name, r, code)


_INTERNAL = [
    (re.compile(r"shared/|\.\./\.\./"), "a path outside the package"),
    (re.compile(r"\bissues?\s+#?\d+", re.I), "an issue number"),
    (re.compile(r"(?<![\w/])(tests|\.ci|benchmarks|tools|docs)/"), "a folder of the repository that does not ship"),
    (re.compile(r"\b[\w.-]+\.md\b"), "a file name (a page is linked, not named)"),
]


def _user_text(page_text: str) -> str:
    """What a user reads: link targets (other pages) and the home page's developer section left out."""
    text = re.sub(r"\]\([^)]*\)", "]", page_text)
    return re.sub(r"^## For developers\n.*?(?=^## |\Z)", "", text, flags=re.M | re.S)


def _generated_pages() -> dict[str, str]:
    hooks = _docs_module("hooks")
    from cpm_nlp.core.solver_options import reference_markdown as solver_options_markdown
    from cpm_nlp.problems.describe import reference_markdown

    names = list(mechanism_names())
    pages = {"reference/kinds.md": reference_markdown(), "reference/solver-options.md": solver_options_markdown()}
    pages["reference/mechanisms.md"] = hooks.mechanisms_index(names)
    by_mechanism = _docs_module("figures").problem_files_by_mechanism()
    pages.update({hooks.mechanism_page_path(n): hooks.mechanism_page(n, by_mechanism) for n in names})
    return pages


def test_user_pages_name_no_internal_paths_or_issues():
    """The user documentation (everything but the design notes and the changelog) names what
    ships: no paths outside the package, no issue numbers, no repository folders a user does not
    have, no file names of pages or papers; examples use the shipped problem files."""
    pages = {str(p.relative_to(SITE)): p.read_text(encoding="utf-8") for p in USER_PAGES}
    pages.update(_generated_pages())
    bad = []
    for name, text in pages.items():
        for pattern, what in _INTERNAL:
            bad += [f"{name}: {m.group(0)!r} ({what})" for m in pattern.finditer(_user_text(text))]
    assert not bad, "\n".join(bad)


_REST_ROLE = re.compile(r":(?:py:)?(?:class|func|meth|attr|data|mod|exc|obj|const|ref):`")


def test_docstrings_use_no_rest_roles():
    """The API reference renders numpy-style docstrings through mkdocstrings, where a reST role
    (``:class:`X```) shows as raw text: a reference is a cross-reference
    (``[`X`][cpm_nlp.module.X]``) or inline code.  Every docstring of the package, public or
    not (a private one becomes public by a rename)."""
    import ast

    bad = []
    for path in sorted((ROOT / "cpm_nlp").rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            body = getattr(node, "body", None)
            if not (isinstance(body, list) and body and isinstance(body[0], ast.Expr)):
                continue
            doc = body[0].value
            if isinstance(doc, ast.Constant) and isinstance(doc.value, str) and _REST_ROLE.search(doc.value):
                bad.append(f"{path.relative_to(ROOT)}:{doc.lineno}")
    assert not bad, f"{len(bad)} docstrings with reST roles: " + ", ".join(bad[:20])


def _entry(text: str, angles: dict[str, float]) -> float:
    """A cell of the page's matrix, e.g. ``−cθ sφ + sψ sθ cφ``, at the given angles."""
    import math

    value = 0.0
    for sign, term in re.findall(r"([+−-]?)\s*((?:[cs][ψθφ]\s*)+)", text):
        product = 1.0
        for fn, angle in re.findall(r"([cs])([ψθφ])", term):
            product *= (math.cos if fn == "c" else math.sin)(angles[angle])
        value += -product if sign in ("−", "-") else product
    return value


def test_rotation_page_matrix_is_the_models():
    """The matrix reference/rotation.md writes for the 3-PRS (eq 4 of Ruiz et al., as a table of
    cψ, sθ ... products) equals the model's rotation matrix at a sample pose."""
    import numpy as np

    text = (SITE / "reference" / "rotation.md").read_text(encoding="utf-8")
    rows = re.findall(r"^\| ([xyz]) \| (.+?) \| (.+?) \| (.+?) \|$", text, re.M)
    assert [r[0] for r in rows] == ["x", "y", "z"]
    angles = {"ψ": 0.3, "θ": -0.7, "φ": 1.1}
    written = np.array([[_entry(cell, angles) for cell in row[1:]] for row in rows])
    model = cn.build_model("prs3", {"b": "47.91 mm", "L": "109.215 mm"})
    names = [c.name for c in model.closure.x]
    x = np.array(model.x_home, dtype=float)
    for name, symbol in (("psi", "ψ"), ("theta", "θ"), ("phi", "φ")):
        x[names.index(name)] = angles[symbol]
    R = np.array(model.closure.frame(x, model.p)[0])
    assert np.allclose(written, R, atol=1e-12), (written, R)
    assert abs(np.linalg.det(written) - 1) < 1e-12


def test_quoted_errors_are_output_claims():
    """An error message a page quotes (a ``> error: ...`` block quote) is one of the page's
    ``<!-- output: -->`` claims, so the command it follows is checked to print it as quoted."""
    for page in PAGES:
        text = page.read_text(encoding="utf-8")
        claims = {" ".join(c.split()) for b in blocks(page) for c in b.outputs}
        for quote in re.findall(r"(?:^> .*\n?)+", text, re.M):
            flat = " ".join(line[2:] for line in quote.splitlines())
            if flat.startswith("error:"):
                assert " ".join(flat.split()) in claims, f"{_name(page)}: quoted error not checked: {flat}"


def test_api_page_documents_every_public_name():
    """reference/api.md renders (``::: path``) the definition of every name of ``cn.__all__``."""
    import importlib

    text = (SITE / "reference" / "api.md").read_text(encoding="utf-8")
    shown = set()
    for path in re.findall(r"^:::\s*(\S+)", text, re.M):
        module, _, name = path.rpartition(".")
        shown.add(id(getattr(importlib.import_module(module), name)))
    public = {n for n in cn.__all__ if n != "__version__"}
    assert not [n for n in public if id(getattr(cn, n)) not in shown]


def test_rotation_page_joint_angles_are_the_generators():
    """The joint-angle convention the rotation page states, M = Rx(a) Ry(b) Rz(c), is the one
    the generator reads a joint's angles with (its inverse, at a sample rotation)."""
    import casadi as ca
    import numpy as np

    from cpm_nlp.mechanisms.described.motions import xyz_angles

    text = " ".join((SITE / "reference" / "rotation.md").read_text(encoding="utf-8").split())
    assert "M = Rx(a) Ry(b) Rz(c) in the joint's own frame" in text
    assert "R = Rz(yaw) Ry(pitch) Rx(roll)" in text

    def rot(axis, t):
        c, s = np.cos(t), np.sin(t)
        i, j = [(1, 2), (2, 0), (0, 1)]["xyz".index(axis)]
        m = np.eye(3)
        m[i, i], m[i, j], m[j, i], m[j, j] = c, -s, s, c
        return m

    a, b, c = 0.3, -0.4, 0.9
    M = rot("x", a) @ rot("y", b) @ rot("z", c)
    got = ca.Function("angles", [], xyz_angles(ca.SX(M)))()
    assert np.allclose([float(got[k]) for k in sorted(got)], [a, b, c])


def test_status_and_warning_lists_are_the_codes():
    """The exported status codes the export page lists (in order) are the statuses' order, and
    the read-status page's warning table has every warning code and no other."""
    from cpm_nlp.core.result import WARNING_CODES

    export = " ".join((SITE / "howto" / "export-c.md").read_text(encoding="utf-8").split())
    codes = ", ".join(f"{k} {s.value}" for k, s in enumerate(cn.Status))
    assert f"in order: {codes})" in export
    status_page = (SITE / "howto" / "read-status.md").read_text(encoding="utf-8")
    table = re.findall(r"^\| `(\w+)` \|", status_page.split("## Warnings", 1)[1], re.M)
    assert table == list(WARNING_CODES)


def test_plots_guide_has_every_plot_type():
    """The plots guide's table has a row for every registered plot type (built-in and the
    mechanisms' own), and no other."""
    from cpm_nlp.plot.registry import plot_type_names

    guide = (SITE / "guide" / "plots.md").read_text(encoding="utf-8")
    rows = re.findall(r"^\| `(\w+)`", guide, re.M)
    assert sorted(rows) == sorted(plot_type_names())
