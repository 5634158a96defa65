"""The help of ``cpm-nlp`` (issue 24, item 5): every subcommand has a description and
examples; every example parses with the real parser and names only files of the checkout
(or files an earlier example of the same help wrote); the plot types listed are the
registry's; listing them imports no add-on (issue 23, start-up)."""

from __future__ import annotations

import argparse
import contextlib
import io
import re
import shlex
import subprocess
import sys

import pytest

from cpm_nlp.cli.help import COMMANDS, TOP_EXAMPLES, USER_FILES
from cpm_nlp.cli.main import build_parser, main
from cpm_nlp.mechanisms.names import ADDON_PLOTS, ADDONS
from cpm_nlp.plot.builtin import BUILTIN
from cpm_nlp.plot.plot_type import Deferred
from cpm_nlp.plot.registry import plot_type, plot_type_names, plot_types
from tests.conftest import ROOT

#: the arguments of each subcommand that name a file it reads
INPUTS = {
    "solve": ("file",),
    "check": ("file",),
    "sweep": ("file",),
    "export": ("file",),
    "plot": ("result",),
    "reproduce": ("paths",),
    "describe": ("name", "mechanism"),
    "import": ("file", "sidecar"),
    "examples": (),
}
#: the arguments that name a file or directory a subcommand writes
OUTPUTS = ("output", "plot", "out", "dir")
#: the width the help is checked at (argparse reads COLUMNS)
WIDTH = 80


@pytest.fixture(autouse=True)
def columns(monkeypatch):
    monkeypatch.setenv("COLUMNS", str(WIDTH))


def _subparsers() -> dict[str, argparse.ArgumentParser]:
    parser = build_parser()
    action = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return dict(action.choices)


def _help(*argv: str) -> str:
    out = io.StringIO()
    with contextlib.redirect_stdout(out):  # argparse prints the help to sys.stdout
        code = main([*argv, "--help"], out=io.StringIO(), err=io.StringIO())
    assert code == 0
    return out.getvalue()


def _examples(text: str) -> list[str]:
    """The example commands of a help text: the lines under "examples:" that start a command."""
    assert "\nexamples:\n" in text, "no examples"
    block = text.split("\nexamples:\n", 1)[1].split("\n\n", 1)[0]
    return [line.strip() for line in block.splitlines() if line.startswith("  cpm-nlp ")]


def _flat(text: str) -> str:
    return " ".join(text.split())


def test_every_subcommand_has_its_help():
    assert set(_subparsers()) == set(COMMANDS)


@pytest.mark.parametrize("command", sorted(COMMANDS))
def test_every_subcommand_has_a_description_and_an_example(command):
    text = _help(command)
    description = COMMANDS[command].description
    assert len(description.split()) >= 20, "a paragraph, not a phrase"
    assert _flat(description) in _flat(text)
    examples = _examples(text)
    assert [e for e in examples if e.startswith(f"cpm-nlp {command}")], "no example of the command itself"
    assert [line for line in text.splitlines() if len(line) > WIDTH] == [], "lines wider than the terminal"


def test_top_level_help_lists_every_subcommand_on_one_line():
    text = _help()
    for name, h in COMMANDS.items():
        assert re.search(rf"^    {re.escape(name)} +{re.escape(h.summary)}$", text, re.M), name
    assert len(_examples(text)) == len(TOP_EXAMPLES)


def _help_texts() -> list[tuple[str, str]]:
    return [("", _help())] + [(name, _help(name)) for name in COMMANDS]


def test_every_example_parses_and_names_only_files_that_exist(tmp_path):
    """Each example is parsed by the real parser; what it reads is a file of the checkout, a
    file an earlier example of the same help wrote, or a file the help says is the user's."""
    checked = 0
    for where, text in _help_texts():
        written: set[str] = set()
        for example in _examples(text):
            argv = shlex.split(example)
            assert argv[0] == "cpm-nlp", example
            if "--help" in argv:
                with contextlib.redirect_stdout(io.StringIO()), pytest.raises(SystemExit) as exc:
                    build_parser().parse_args(argv[1:])
                assert exc.value.code == 0, example
                continue
            args = build_parser().parse_args(argv[1:])  # an error here is SystemExit(2): the test fails
            for name in INPUTS[args.command]:
                given = getattr(args, name)
                for f in given if isinstance(given, list) else [given] if given else []:
                    if args.command == "describe" and not f.endswith(".yaml"):
                        continue  # a mechanism or kind name, not a file
                    if (args.command, f) in USER_FILES:
                        assert "your own" in _help(args.command), f"{example}: a user's file, not said so"
                        continue
                    assert f in written or (ROOT / f).exists(), f"{where or 'cpm-nlp'} --help: {example}: no {f}"
                    assert ".." not in f.split("/"), example
            for name in OUTPUTS:
                target = getattr(args, name, None)
                if target:
                    assert not (ROOT / target).exists(), f"{example} would write over {target}"
                    written.add(target)
            checked += 1
    assert checked >= 2 * len(COMMANDS)


def test_every_problem_example_loads_with_its_changes():
    """The --set of an example names keys the file has: each problem file an example solves,
    checks or exports is checked as given (``cpm-nlp check``)."""
    for _where, text in _help_texts():
        for example in _examples(text):
            argv = shlex.split(example)[1:]
            if argv[0] not in ("solve", "check", "export") or "--help" in argv:
                continue
            args = build_parser().parse_args(argv)
            sets = [a for s in args.set or [] for a in ("--set", s)]
            out, err = io.StringIO(), io.StringIO()
            assert main(["check", str(ROOT / args.file), *sets], out=out, err=err) == 0, (example, err.getvalue())


# -- the plot types ---------------------------------------------------------------------------------


def _listed_plot_types(text: str) -> list[str]:
    listing = text.split("plot types (--type):\n", 1)[1]
    return re.findall(r"^  ([a-z][a-z0-9_]*) ", listing, re.M)


@pytest.mark.parametrize("command", [name for name, h in COMMANDS.items() if h.plot_types])
def test_the_plot_types_in_help_are_the_registrys(command):
    listed = _listed_plot_types(_help(command))
    assert listed == plot_type_names() == [p.name for p in plot_types()]
    assert {p.name for p in BUILTIN} < set(listed)
    assert {d.name for plots in ADDON_PLOTS.values() for d in plots} < set(listed)


def test_listing_the_plot_types_imports_no_add_on():
    """``plot --help`` reads the add-ons' declared plot types (names, one line each): it imports
    no add-on, no plot module of one, no mechanism, nor numpy, CasADi or Matplotlib."""
    body = (
        "import sys, io, contextlib\n"
        "from cpm_nlp.cli.main import main\n"
        "for command in ('plot', 'solve', 'sweep'):\n"
        "    with contextlib.redirect_stdout(io.StringIO()) as out:\n"
        "        assert main([command, '--help']) == 0\n"
        "    assert 'twists' in out.getvalue() and 'amplifier' in out.getvalue()\n"
        "print('loaded:' + ','.join(sorted(sys.modules)))\n"
    )
    run = subprocess.run([sys.executable, "-c", body], capture_output=True, text=True, cwd=ROOT, timeout=120)
    assert run.returncode == 0, run.stderr
    line = [ln for ln in run.stdout.splitlines() if ln.startswith("loaded:")][-1]
    loaded = set(line[len("loaded:") :].split(","))
    mechanisms = {m for m in loaded if m.startswith("cpm_nlp.mechanisms.")}
    assert mechanisms == {"cpm_nlp.mechanisms.names"}
    heavy = {"numpy", "casadi", "matplotlib", "yaml", "cpm_nlp.core.mechanism", "cpm_nlp.plot.figures"}
    assert loaded & heavy == set()


@pytest.mark.parametrize("mechanism", sorted(ADDON_PLOTS))
def test_an_add_ons_declared_plot_is_drawn_by_its_function(mechanism):
    """Each declared plot names a function of its add-on's own plot module, found when drawn."""
    assert mechanism in ADDONS
    for declared in ADDON_PLOTS[mechanism]:
        module, _, attr = declared.function.partition(":")
        assert module == f"cpm_nlp.mechanisms.{mechanism}.plots"
        function = Deferred(declared.function).resolve()
        assert callable(function) and function.__name__ == attr
        plot = plot_type(declared.name, mechanism)
        assert plot.function.resolve() is function
        assert plot.description == declared.description and plot.origin == f"mechanism {mechanism}"
