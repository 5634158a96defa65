"""``cpm-nlp COMMAND ...`` builds only COMMAND's parser (`cpm_nlp.cli.main.build_parser`,
issue 23 item 2, start-up): the same arguments parse to the same values, the same help and
the same errors as with every subcommand's parser built."""

from __future__ import annotations

import argparse
import contextlib
import io

import pytest

from cpm_nlp.cli.main import build_parser, main

#: argument lists of every subcommand (valid, and invalid: an unknown option, a missing argument)
ARGVS = [
    ["solve", "problems/prs3_forward_kinematics.yaml", "--set", "inputs.s1=1 mm", "-o", "out.json", "--json"],
    ["solve", "p.yaml", "--plot", "f.png", "--type", "pose", "--value", "x", "--best", "max", "-q"],
    ["sweep", "p.yaml", "--workers", "2", "--chunk", "10", "--overwrite"],
    ["plot", "r.json", "-o", "f.png", "--x", "a", "--y", "b"],
    ["check", "p.yaml", "--set", "a=1"],
    ["reproduce", "problems", "--full"],
    ["export", "p.yaml", "--what", "fk", "--format", "c", "--out", "d"],
    ["examples", "d", "--force"],
    ["describe", "prs3", "--mechanism", "prs3"],
    ["import", "r.urdf", "--sidecar", "s.yaml", "--spatial"],
    ["solve"],
    ["solve", "p.yaml", "--no-such-option"],
    ["plot", "r.json"],
    ["sweep", "p.yaml", "--workers", "two"],
    ["solvee", "p.yaml"],
    ["-v", "solve", "p.yaml"],
    ["--version"],
    [],
]


def _namespace(args: argparse.Namespace) -> dict:
    out = dict(vars(args))
    func = out.pop("func", None)
    out["func"] = None if func is None else (func.module, func.name)
    return out


def _parse(parser: argparse.ArgumentParser, argv: list[str]) -> tuple:
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            return ("ok", _namespace(parser.parse_args(argv)))
        except SystemExit as exc:
            return ("exit", exc.code, out.getvalue(), err.getvalue())


@pytest.mark.parametrize("argv", ARGVS, ids=lambda a: " ".join(a) or "none")
def test_one_command_parses_as_all(argv, monkeypatch):
    monkeypatch.setenv("COLUMNS", "80")
    one = build_parser(argv[0] if argv else None)
    assert _parse(one, argv) == _parse(build_parser(), argv)


@pytest.mark.parametrize("command", ["solve", "sweep", "plot", "check", "reproduce", "export", "describe"])
def test_one_command_has_the_same_help(command, monkeypatch):
    monkeypatch.setenv("COLUMNS", "80")
    assert _parse(build_parser(command), [command, "--help"]) == _parse(build_parser(), [command, "--help"])


def test_only_the_command_is_built():
    parser = build_parser("solve")
    action = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    assert list(action.choices) == ["solve"]
    everything = build_parser("no-such-command")  # a name that is no subcommand: all of them
    action = next(a for a in everything._actions if isinstance(a, argparse._SubParsersAction))
    assert {"solve", "sweep", "plot", "describe", "import"} <= set(action.choices)


def test_main_reports_an_unknown_command_with_every_choice():
    err = io.StringIO()
    with contextlib.redirect_stderr(err):
        code = main(["solvee", "p.yaml"], out=io.StringIO(), err=io.StringIO())
    assert code == 2
    assert "invalid choice: 'solvee'" in err.getvalue() and "'sweep'" in err.getvalue()
