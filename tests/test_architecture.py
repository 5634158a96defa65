"""The package's layers: no import cycle (imports inside functions included),
dependencies that flow one way, library code that never imports the CLI, and
generic modules that name no mechanism."""

from __future__ import annotations

import ast
import functools
import re
import subprocess
import sys
from pathlib import Path

import pytest

PKG = Path(__file__).resolve().parent.parent / "cpm_nlp"

#: rank of each layer: a module may import its own package or a lower rank only
#: (cli -> problems/sweep/plot/api -> mechanisms -> kinds -> analysis/io -> core)
LAYERS = {
    "core": 0,
    "analysis": 1,
    "io": 1,
    "kinds": 2,
    "mechanisms": 3,
    "problems": 4,
    "sweep": 5,
    "plot": 5,
    "api": 5,
    "cli": 6,
}
#: modules that must not name a mechanism or a paper-specific kind (code, not docstrings)
GENERIC = ("plot", "sweep", "cli", "kinds", "problems", "io", "analysis", "core")
MECHANISM_WORDS = ("prs3", "prc3", "rpr", "pantograph")
#: modules of text only, whose examples name shipped files and mechanisms (no code chooses by them)
TEXT_MODULES = ("cpm_nlp.cli.help",)


@functools.cache
def _parsed(path: Path) -> ast.Module:
    """The syntax tree of a module of the package, parsed once per process (the tests below
    only read it)."""
    return ast.parse(path.read_text(encoding="utf-8"))


def _modules() -> dict[str, Path]:
    out = {}
    for f in PKG.rglob("*.py"):
        rel = f.relative_to(PKG.parent).with_suffix("")
        parts = list(rel.parts)
        if parts[-1] == "__init__":
            parts = parts[:-1]
        out[".".join(parts)] = f
    return out


def _imports(name: str, path: Path, modules: dict[str, Path]) -> set[str]:
    """Modules of cpm_nlp that ``name`` imports anywhere in its code."""
    tree = _parsed(path)
    is_pkg = path.name == "__init__.py"
    package = name if is_pkg else name.rpartition(".")[0]
    found = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")
                base = base[: len(base) - (node.level - 1)]
                target = ".".join(base + ([node.module] if node.module else []))
            else:
                target = node.module or ""
            if not target.startswith("cpm_nlp"):
                continue
            for alias in node.names:
                sub = f"{target}.{alias.name}"
                found.add(sub if sub in modules else target)
        elif isinstance(node, ast.Import):
            found |= {a.name for a in node.names if a.name.startswith("cpm_nlp")}
    return {m for m in found if m in modules and m != name}


@pytest.fixture(scope="module")
def graph():
    modules = _modules()
    return {name: _imports(name, path, modules) for name, path in modules.items()}


#: modules of a mechanism's package that belong to the plot layer: a paper's own plot types,
#: declared in ``cpm_nlp.mechanisms.names.ADDON_PLOTS`` ("module:attribute"), never imported below the plots
PLOT_MODULES = re.compile(r"cpm_nlp\.mechanisms\.\w+\.plots")


def _layer(module: str) -> str | None:
    if PLOT_MODULES.fullmatch(module):
        return "plot"
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else None


def _package(module: str) -> str | None:
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else None


def test_no_import_cycle(graph):
    """Depth-first search over every import, those inside functions included."""
    state: dict[str, int] = {}
    stack: list[str] = []

    def visit(m: str) -> None:
        state[m] = 1
        stack.append(m)
        for n in sorted(graph[m]):
            if state.get(n) == 1:
                cycle = stack[stack.index(n) :] + [n]
                pytest.fail("import cycle: " + " -> ".join(cycle))
            if n not in state:
                visit(n)
        stack.pop()
        state[m] = 2

    for m in sorted(graph):
        if m not in state:
            visit(m)


def test_dependencies_flow_one_way(graph):
    bad = []
    for m, targets in graph.items():
        lm = _layer(m)
        if lm not in LAYERS:
            continue
        for t in targets:
            lt = _layer(t)
            if lt is None or lt not in LAYERS or lt == lm:
                continue
            if LAYERS[lt] >= LAYERS[lm]:
                bad.append(f"{m} ({lm}) imports {t} ({lt})")
    assert not bad, "imports against the layers:\n" + "\n".join(bad)


def test_library_never_imports_the_cli(graph):
    entry = ("cpm_nlp.__main__",)  # ``python -m cpm_nlp`` is the command itself
    bad = [
        m for m, ts in graph.items() if _layer(m) != "cli" and m not in entry and any(_layer(t) == "cli" for t in ts)
    ]
    assert not bad


def _code_words(path: Path) -> set[str]:
    """Identifiers and string constants of a module, docstrings left out."""
    tree = _parsed(path)
    docstrings = set()
    for node in ast.walk(tree):
        if isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)):
            body = getattr(node, "body", [])
            if body and isinstance(body[0], ast.Expr) and isinstance(body[0].value, ast.Constant):
                docstrings.add(id(body[0].value))
    words = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Constant) and isinstance(node.value, str) and id(node) not in docstrings:
            words |= set(node.value.replace(".", " ").replace("_", " ").replace(":", " ").split())
        elif isinstance(node, ast.Name):
            words.add(node.id)
        elif isinstance(node, ast.Attribute):
            words.add(node.attr)
        elif isinstance(node, ast.alias):
            words |= set(node.name.split("."))
    return words


def test_generic_modules_name_no_mechanism():
    bad = []
    for name, path in _modules().items():
        if _package(name) in GENERIC and name not in TEXT_MODULES:
            hits = sorted(w for w in _code_words(path) if w.lower() in MECHANISM_WORDS)
            if hits:
                bad.append(f"{name}: {', '.join(hits)}")
    assert not bad, "generic modules that name a mechanism:\n" + "\n".join(bad)


def test_a_mechanisms_plots_are_named_not_imported(graph):
    """A paper's plot module (mechanisms/<m>/plots.py) imports the plot layer; the layers
    below reach it only by name (the add-on's ``plots``), so nothing there imports it."""
    plots = [m for m in graph if PLOT_MODULES.fullmatch(m)]
    assert plots, "no mechanism declares plots of its own"
    bad = [f"{m} imports {t}" for m, ts in graph.items() for t in ts if t in plots and _layer(m) != "plot"]
    assert not bad


def test_plot_modules_stay_small():
    """One concept per module (issue 22, item 6): none of the plot layer over 800 lines."""
    big = {f.name: n for f in (PKG / "plot").glob("*.py") if (n := len(f.read_text().splitlines())) > 800}
    assert not big, big


def test_every_module_stays_small():
    """One concept per module (issue 22, item 6): no module of the package over 800 lines
    (kernels, the CLI, the URDF import, the RPR kinds and the mechanism-file reader, generator
    and graph were split for it)."""
    big = {str(f.relative_to(PKG)): n for f in PKG.rglob("*.py") if (n := len(f.read_text().splitlines())) > 800}
    assert not big, big


#: the most ``noqa: C901`` the package may keep (issue 22: "at most 8, each with its reason")
MOST_COMPLEX_WAIVERS = 8


def test_few_complexity_waivers_each_with_its_reason():
    """A long function is split, or a table of checks, not waived: at most
    :data:`MOST_COMPLEX_WAIVERS` ``noqa: C901`` in the package, each followed by its reason."""
    waivers = [
        (f"{f.relative_to(PKG)}:{i}", line.split("noqa: C901", 1)[1])
        for f in sorted(PKG.rglob("*.py"))
        for i, line in enumerate(f.read_text().splitlines(), 1)
        if "noqa: C901" in line
    ]
    assert len(waivers) <= MOST_COMPLEX_WAIVERS, [w for w, _ in waivers]
    unexplained = [w for w, rest in waivers if len(rest.strip(" -:")) < 10]
    assert not unexplained, f"a noqa: C901 without its reason: {unexplained}"


def test_mechanism_file_modules_stay_small_and_simple():
    """One concept per module (issue 22, item 6) in cpm_nlp/mechanisms/described: none over 800
    lines, no ``noqa: C901`` (a validator is a table of checks, not one long function), and no
    private name imported from a sibling module."""
    files = sorted((PKG / "mechanisms" / "described").glob("*.py"))
    big = {f.name: n for f in files if (n := len(f.read_text().splitlines())) > 800}
    waived = {f.name: f.read_text().count("noqa: C901") for f in files if "noqa: C901" in f.read_text()}
    private = [
        f"{f.name}: {a.name}"
        for f in files
        for node in ast.walk(_parsed(f))
        if isinstance(node, ast.ImportFrom) and node.level and node.module != "__future__"
        for a in node.names
        if a.name.startswith("_")
    ]
    assert not big and not waived and not private, (big, waived, private)


def test_plot_modules_import_no_private_name():
    """What a plot module shares with another is public (the common helpers in
    cpm_nlp.plot.style): no ``from .x import _name`` in the plot layer."""
    bad = []
    for name, path in _modules().items():
        if _layer(name) != "plot":
            continue
        for node in ast.walk(_parsed(path)):
            if isinstance(node, ast.ImportFrom) and node.module != "__future__":
                bad += [f"{name}: {a.name}" for a in node.names if a.name.startswith("_")]
    assert not bad


def test_every_module_imports_in_a_fresh_interpreter():
    """Every module of the package imports, in a new interpreter, in reverse order of
    the layers (the CLI first), so no module depends on another having been loaded."""
    names = sorted((n for n in _modules() if not n.endswith("__main__")), key=lambda n: -LAYERS.get(_layer(n), 9))
    code = f"import importlib\nfor n in {names!r}:\n    importlib.import_module(n)\n"
    run = subprocess.run(
        [sys.executable, "-W", "error::DeprecationWarning", "-c", code], capture_output=True, text=True
    )
    assert run.returncode == 0, run.stderr


def test_public_names_listed_once():
    import cpm_nlp as cn
    import cpm_nlp.api as api

    assert cn.__all__ is api.__all__
    assert len(set(cn.__all__)) == len(cn.__all__)
    for name in cn.__all__:
        assert getattr(cn, name) is getattr(api, name)


def test_legacy_module_names_still_import_with_a_warning():
    import importlib

    with pytest.warns(DeprecationWarning, match="cpm_nlp.workspace moved to cpm_nlp.analysis.workspace"):
        old = importlib.import_module("cpm_nlp.workspace")
    assert old is importlib.import_module("cpm_nlp.analysis.workspace")
    assert old.__spec__.name == "cpm_nlp.analysis.workspace"


def test_the_removed_prs3_module_says_where_the_mechanism_is():
    """cpm_nlp.prs3 (0.1) and cpm_nlp.mechanisms.prs3 left the package (issue 21): the
    3-PRS is problems/mechanisms/prs3.yaml."""
    import importlib

    with pytest.raises(ModuleNotFoundError, match="problems/mechanisms/prs3.yaml"):
        importlib.import_module("cpm_nlp.prs3")
    with pytest.raises(ModuleNotFoundError):
        importlib.import_module("cpm_nlp.mechanisms.prs3")


#: module globals of cpm_nlp.core that may be mutable containers, and why: process caches of
#: compiled code and threads (never problem data)
CORE_MUTABLE_ALLOWED = {
    "cpm_nlp.core.batch._MAPPED": "LRU cache of mapped CasADi functions (code, not problem data)",
    "cpm_nlp.core.batch._POOLS": "thread pools by worker count, made once per process",
    "cpm_nlp.core.blas._STATE": "the process's BLAS thread controller, set up once",
    "cpm_nlp.core.solver._BUILT": "each closure's built solvers and kernels (code), weakly keyed by the closure",
}


def _core_mutable_globals() -> dict[str, str]:
    """'module.NAME' -> type of every module global of cpm_nlp.core that is a mutable
    container (dict, list, set, bytearray, deque and their subclasses), or a read-only
    mapping holding one; a re-exported object counts once, where it is defined first."""
    import collections
    import importlib
    import pkgutil
    import weakref
    from types import MappingProxyType

    import cpm_nlp.core as core

    mutable = (dict, list, set, bytearray, collections.deque, weakref.WeakKeyDictionary, weakref.WeakValueDictionary)
    seen: set[int] = set()
    found: dict[str, str] = {}
    for info in sorted(pkgutil.walk_packages(core.__path__, "cpm_nlp.core."), key=lambda i: i.name):
        module = importlib.import_module(info.name)
        for name, value in vars(module).items():
            if name.startswith("__") or id(value) in seen:
                continue
            inner = list(value.values()) if isinstance(value, MappingProxyType) else []
            if isinstance(value, mutable) or any(isinstance(v, mutable) for v in inner):
                seen.add(id(value))
                found[f"{info.name}.{name}"] = type(value).__name__
    return found


def test_core_holds_no_mutable_module_state():
    """Issue 22: core's tables are read-only (MappingProxyType, tuples, frozensets), so nothing
    at run time can change what a later problem in the same process sees; the only mutable
    module globals are the declared process caches above."""
    found = _core_mutable_globals()
    unexpected = sorted(set(found) - set(CORE_MUTABLE_ALLOWED))
    assert not unexpected, f"mutable module state in cpm_nlp.core: {unexpected}"
    stale = sorted(set(CORE_MUTABLE_ALLOWED) - set(found))
    assert not stale, f"no longer mutable (drop from CORE_MUTABLE_ALLOWED): {stale}"


#: the test folders that are not a package path: suites of their own (issue 22, item 7)
OWN_SUITES = ("hostile", "conformance", "corpus")
#: tests of the project as a whole stay at the top of tests/
PROJECT_TESTS = ("test_architecture.py", "test_docs.py", "test_install.py", "test_benchmarks.py")


def test_tests_mirror_the_package():
    """A feature's tests are found from its package path: tests/<subpackage>/test_*.py for
    cpm_nlp/<subpackage>/, tests/mechanisms/<name>/ for a shipped mechanism (a package under
    cpm_nlp/mechanisms/ or a file problems/mechanisms/<name>.yaml), and the hostile and
    conformance suites and the external corpus in their own folders."""
    tests = Path(__file__).resolve().parent
    shipped = {p.stem for p in (PKG.parent / "problems" / "mechanisms").glob("*.yaml")}
    misplaced = []
    for f in sorted(tests.rglob("test_*.py")):
        rel = f.relative_to(tests)
        folder = rel.parent.parts
        if not folder:
            ok = rel.name in PROJECT_TESTS
        elif folder[0] in OWN_SUITES:
            ok = len(folder) == 1
        else:
            ok = (PKG.joinpath(*folder) / "__init__.py").is_file() or (
                len(folder) == 2 and folder[0] == "mechanisms" and folder[1] in shipped
            )
        if not ok:
            misplaced.append(str(rel))
    assert not misplaced, f"test files outside a package path: {misplaced}"
    # every test folder is a package (the same basename may appear in two folders)
    for d in {f.parent for f in tests.rglob("test_*.py")} - {tests}:
        assert (d / "__init__.py").is_file(), d


#: calls that make a mutable container (a module global made by one is module state)
_MUTABLE_CALLS = frozenset(
    {
        "dict",
        "list",
        "set",
        "defaultdict",
        "OrderedDict",
        "deque",
        "bytearray",
        "Counter",
        "WeakKeyDictionary",
        "WeakValueDictionary",
    }
)


def _makes_mutable(node: ast.expr) -> bool:
    """Whether ``node`` makes a mutable container: a dict, list or set display or
    comprehension, or a call of :data:`_MUTABLE_CALLS` (one wrapped in MappingProxyType,
    tuple or frozenset is a call of those, and read-only)."""
    if isinstance(node, (ast.Dict, ast.List, ast.Set, ast.DictComp, ast.ListComp, ast.SetComp)):
        return True
    if isinstance(node, ast.Call):
        f = node.func
        name = f.id if isinstance(f, ast.Name) else f.attr if isinstance(f, ast.Attribute) else ""
        return name in _MUTABLE_CALLS
    return False


def _core_mutable_assignments() -> dict[str, int]:
    """'module.NAME' -> line of every module-level assignment in cpm_nlp/core whose value
    makes a mutable container (read from the source, so a table built by a function and
    never read at import is found too)."""
    found: dict[str, int] = {}
    for path in sorted((PKG / "core").rglob("*.py")):
        module = ".".join(path.relative_to(PKG.parent).with_suffix("").parts).removesuffix(".__init__")
        for st in _parsed(path).body:
            if isinstance(st, ast.Assign):
                targets, value = st.targets, st.value
            elif isinstance(st, (ast.AnnAssign, ast.AugAssign)):
                targets, value = [st.target], st.value
            else:
                continue
            if value is None or not _makes_mutable(value):
                continue
            for t in targets:
                for name in ast.walk(t):
                    if isinstance(name, ast.Name):
                        found[f"{module}.{name.id}"] = st.lineno
    return found


def test_core_source_assigns_no_mutable_module_state():
    """Issue 22: no module of cpm_nlp.core assigns a dict, list or set (display,
    comprehension, or dict()/list()/set()/defaultdict() ...) at module level, unless it is
    a declared process cache; a table is a MappingProxyType, a tuple or a frozenset."""
    found = _core_mutable_assignments()
    unexpected = sorted(f"{name} (line {line})" for name, line in found.items() if name not in CORE_MUTABLE_ALLOWED)
    assert not unexpected, f"mutable module state in cpm_nlp/core: {unexpected}"
    stale = sorted(set(CORE_MUTABLE_ALLOWED) - set(found))
    assert not stale, f"not assigned as a mutable container (drop from CORE_MUTABLE_ALLOWED): {stale}"


def test_the_mutable_state_check_sees_each_form():
    """The check above finds each form of a mutable module global, and passes the read-only ones."""
    src = (
        "A = {}\nB: list = []\nC = {1}\nD = {k: 1 for k in ()}\nE = [x for x in ()]\nF = dict(a=1)\n"
        "G = collections.defaultdict(list)\nH = set()\nI = weakref.WeakKeyDictionary()\n"
        "OK1 = MappingProxyType({})\nOK2 = (1, 2)\nOK3 = frozenset({1})\nOK4 = tuple([1])\n"
    )
    made = {
        ast.unparse(st.targets[0] if isinstance(st, ast.Assign) else st.target)
        for st in ast.parse(src).body
        if _makes_mutable(st.value)
    }
    assert made == set("ABCDEFGHI")


def test_results_are_built_from_declared_outputs_only():
    """Issue 22, item 2: outside cpm_nlp.core no code calls ``Result(...)``: a kind builds its
    result from its declared outputs (core.outputs.declared_result), so it writes no unit or
    dimension by hand."""
    calls = []
    for path in sorted(PKG.rglob("*.py")):
        if path.is_relative_to(PKG / "core"):
            continue
        for node in ast.walk(_parsed(path)):
            if isinstance(node, ast.Call):
                f = node.func
                name = f.id if isinstance(f, ast.Name) else f.attr if isinstance(f, ast.Attribute) else ""
                if name == "Result":
                    calls.append(f"{path.relative_to(PKG.parent)}:{node.lineno}")
    assert not calls, calls


def test_every_test_path_named_by_a_script_or_file_exists():
    """The CI scripts and the shipped files name test files by path: each path still exists
    (the mindeps step named the tests' old flat paths after the move of issue 22, item 7)."""
    root = PKG.parent
    named = [
        (f.relative_to(root), m.group(0))
        for f in [*sorted((root / ".ci").iterdir()), *sorted((root / "problems").rglob("*.yaml"))]
        if f.is_file()
        for m in re.finditer(r"tests/[\w/]+\.py", f.read_text())
    ]
    assert named, "no test path found: the check reads nothing"
    missing = [f"{f}: {p}" for f, p in named if not (root / p).is_file()]
    assert not missing, missing


def _executed(body: list[ast.stmt]):
    """The import statements that run when a module is imported: at module level (in an
    ``if`` or ``try`` too), not in a function or class, nor under ``if TYPE_CHECKING:``."""
    for node in body:
        if isinstance(node, (ast.Import, ast.ImportFrom)):
            yield node
        elif isinstance(node, ast.If):
            if "TYPE_CHECKING" not in ast.unparse(node.test):
                yield from _executed(node.body)
            yield from _executed(node.orelse)
        elif isinstance(node, ast.Try):
            for block in (node.body, node.orelse, node.finalbody, *[h.body for h in node.handlers]):
                yield from _executed(block)


def _top_level_imports(name: str, path: Path, modules: dict[str, Path]) -> set[str]:
    """Modules of cpm_nlp that importing ``name`` imports (a package's parents too)."""
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    found: set[str] = set()
    for node in _executed(_parsed(path).body):
        if isinstance(node, ast.Import):
            found |= {a.name for a in node.names}
            continue
        parts = package.split(".")
        base = ".".join(parts[: len(parts) - node.level + 1]) if node.level else ""
        target = ".".join(t for t in (base, node.module or "") if t)
        found |= {f"{target}.{a.name}" if f"{target}.{a.name}" in modules else target for a in node.names}
    out = set()
    for m in found:  # importing a.b.c runs a, a.b and a.b.c
        parts = m.split(".")
        out |= {".".join(parts[:k]) for k in range(1, len(parts) + 1)}
    return {m for m in out if m in modules and m != name}


def test_every_module_that_logs_has_the_packages_null_handler():
    """The library never prints: the ``cpm_nlp`` logger has a NullHandler before any module
    logs.  ``cpm_nlp/__init__`` does not import logging (``cpm-nlp --help`` starts without it,
    issue 23); ``cpm_nlp.core.errors`` attaches the handler, and every module that makes a
    logger imports it at module level, directly or through the modules it imports."""
    modules = _modules()
    graph = {name: _top_level_imports(name, path, modules) for name, path in modules.items()}
    assert 'logging.getLogger("cpm_nlp").addHandler(logging.NullHandler())' in (PKG / "core" / "errors.py").read_text()

    def reaches(start: str) -> set[str]:
        seen, todo = set(), [start]
        while todo:
            for n in graph[todo.pop()] - seen:
                seen.add(n)
                todo.append(n)
        return seen

    # the command line is the application: main() gives the logger its own handler first
    library = {name: path for name, path in modules.items() if _layer(name) != "cli"}
    loggers = [name for name, path in library.items() if "getLogger(" in path.read_text()]
    assert len(loggers) >= 10
    bad = [m for m in loggers if m != "cpm_nlp.core.errors" and "cpm_nlp.core.errors" not in reaches(m)]
    assert bad == [], "modules that may log before the NullHandler is attached: " + ", ".join(bad)
    run = subprocess.run(
        [
            sys.executable,
            "-c",
            "import cpm_nlp.core.errors, logging; "
            "print(any(isinstance(h, logging.NullHandler) for h in logging.getLogger('cpm_nlp').handlers))",
        ],
        capture_output=True,
        text=True,
        cwd=PKG.parent,
        check=True,
    )
    assert run.stdout.strip() == "True"
