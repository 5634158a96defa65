"""The ``cpm-nlp`` command line: the parser, which wires one module per subcommand
(`solve` for ``solve`` and ``check``, `sweep`,
`plot`, `reproduce`, `export`,
`examples`, `describe`, `urdf` for
``import``; their help texts in `help`), and the entry point with its
handling of errors, Ctrl-C and a closed stdout.

Exit status (`cpm_nlp.cli.exits`): 0 solved, 1 a solve that did not succeed (the result
says why), 2 bad input (one message naming the file, the key path and what was expected), 70
an internal error (a bug: please report it).

Start-up is kept short on purpose (issue 23): this module imports only argparse and a few
standard modules; a subcommand's module is imported when that subcommand runs
(`_Command`), and each subcommand and renderer imports what it needs when it runs
(units, numpy, CasADi, the problem kinds, Matplotlib, Dask, logging), so ``cpm-nlp --help``
loads none of them, nor any subcommand module.
"""

from __future__ import annotations

import argparse
import contextlib
import os
import signal
import sys
from collections.abc import Callable, Sequence

from ..core.version import __version__
from .exits import EXIT_BROKEN_PIPE, EXIT_FAILED, EXIT_INPUT, EXIT_INTERNAL, EXIT_INTERRUPTED, EXIT_OK
from .help import TOP_DESCRIPTION, TOP_EXAMPLES, Formatter, examples_text, parser_help

TYPE_CHECKING = False  # typing itself is not imported at start-up; the annotations are strings
if TYPE_CHECKING:
    from typing import Any, TextIO


def build_parser(command: str | None = None) -> argparse.ArgumentParser:
    """The parser of the command line; ``command``: only that subcommand's parser is built,
    the others left out (none is needed to parse its arguments: about 3 ms of the start-up,
    issue 23); a name that is no subcommand builds them all."""
    parser = argparse.ArgumentParser(
        prog="cpm-nlp", description=TOP_DESCRIPTION, epilog=examples_text(TOP_EXAMPLES), formatter_class=Formatter
    )
    parser.add_argument("--version", action="store_true", help="print the version of cpm_nlp and exit")
    parser.add_argument("--debug", action="store_true", help="show tracebacks of internal errors")
    parser.add_argument("-v", "--verbose", action="count", default=0, help="log progress to stderr (-vv: debug)")
    sub = _Subcommands(parser.add_subparsers(dest="command", metavar="COMMAND"), command)

    p = sub.add_parser("solve", **parser_help("solve"))
    p.add_argument("file", help="problem file (YAML)")
    p.add_argument(
        "--set",
        action="append",
        metavar="KEY=VALUE",
        help="override a value of the file, e.g. --set mechanism.parameters.b='50 mm' (repeatable)",
    )
    p.add_argument("--json", action="store_true", help="print the result as JSON")
    p.add_argument("-o", "--output", metavar="FILE", help="write the result as JSON to FILE (atomically)")
    p.add_argument("-q", "--quiet", action="store_true", help="print nothing; the exit status tells")
    _add_plot_arguments(p, "--plot")
    p.set_defaults(func=_Command("solve", "cmd_solve"))

    p = sub.add_parser("sweep", **parser_help("sweep"))
    p.add_argument("file", help="problem file (YAML) with a sweep section")
    p.add_argument("--set", action="append", metavar="KEY=VALUE", help="override a value of the file (repeatable)")
    p.add_argument(
        "-o", "--output", metavar="RESULTS", help="results file, .parquet or .csv (default: FILE's name, .parquet)"
    )
    p.add_argument(
        "--scheduler",
        metavar="tcp://HOST:PORT",
        help="address of an existing Dask scheduler (default: start a local cluster, one process per core)",
    )
    p.add_argument("--workers", type=int, metavar="N", help="worker processes of the local cluster (default: cores)")
    p.add_argument("--chunk", type=int, metavar="N", help="points per Dask task (default: about 0.5 s of work)")
    p.add_argument("--overwrite", action="store_true", help="discard RESULTS and start again instead of resuming")
    p.add_argument("-q", "--quiet", action="store_true", help="no progress bar, no summary")
    _add_plot_arguments(p, "--plot")
    p.set_defaults(func=_Command("sweep", "cmd_sweep"))

    p = sub.add_parser("plot", **parser_help("plot"))
    p.add_argument("result", help="JSON result of 'cpm-nlp solve -o', or a sweep results file (.parquet, .csv)")
    p.add_argument(
        "-o", "--output", metavar="FIGURE", required=True, help="figure file: .png, .svg, .pdf (.html: interactive 3-D)"
    )
    p.add_argument("--x", metavar="NAME", help="map: parameter (or value) on the horizontal axis")
    p.add_argument("--y", metavar="NAME", help="map: parameter (or value) on the vertical axis")
    _add_plot_arguments(p, None)
    p.set_defaults(func=_Command("plot", "cmd_plot"))

    p = sub.add_parser("check", **parser_help("check"))
    p.add_argument("file", help="problem file (YAML)")
    p.add_argument("--set", action="append", metavar="KEY=VALUE", help="override a value of the file (repeatable)")
    p.set_defaults(func=_Command("solve", "cmd_check"))

    p = sub.add_parser("reproduce", **parser_help("reproduce"))
    p.add_argument("paths", nargs="*", help="problem files or directories (default: problems/)")
    p.add_argument("--full", action="store_true", help="print the full table, every figure and reason")
    p.add_argument("--json", action="store_true", help="print the full table as JSON")
    p.add_argument(
        "-o", "--output", metavar="FILE", help="write the full table to FILE: .md, .csv or .json (atomically)"
    )
    p.set_defaults(func=_Command("reproduce", "cmd_reproduce"))

    p = sub.add_parser("export", **parser_help("export"))
    p.add_argument("file", help="problem file (YAML); its mechanism and solver section are used")
    p.add_argument("--what", default="fk,ik,jacobian", help="comma-separated: fk, ik, jacobian (default: all)")
    p.add_argument("--format", default="casadi", help="casadi (.casadi files) or c (source + header)")
    p.add_argument("--out", required=True, metavar="DIR", help="output directory (created if missing)")
    p.add_argument("--set", action="append", metavar="KEY=VALUE", help="override a value of the file")
    p.set_defaults(func=_Command("export", "cmd_export"))

    p = sub.add_parser("examples", **parser_help("examples"))
    p.add_argument("dir", metavar="DIR", help="directory to copy into (created if missing)")
    p.add_argument("--force", action="store_true", help="overwrite files of the same name")
    p.set_defaults(func=_Command("examples", "cmd_examples"))

    p = sub.add_parser("describe", **parser_help("describe"))
    p.add_argument("name", nargs="?", help="a mechanism, a problem kind or a mechanism file (.yaml)")
    p.add_argument(
        "--mechanism",
        metavar="NAME",
        help="with a problem kind: its inputs and values for this mechanism (a name or a mechanism file)",
    )
    p.add_argument(
        "--plot", metavar="FIGURE", help="with a mechanism file: also draw its body graph (.png, .svg, .pdf)"
    )
    p.set_defaults(func=_Command("describe", "cmd_describe"))

    p = sub.add_parser("import", **parser_help("import"))
    p.add_argument("file", help="the URDF (.urdf)")
    p.add_argument("--sidecar", metavar="FILE", help="the Extended URDF sidecar (robot.yaml): closures, actuators")
    p.add_argument("-o", "--output", metavar="FILE", help="write the mechanism file to FILE (default: print it)")
    p.add_argument("--actuated", metavar="J1,J2", help="the actuated joints (URDF names), instead of name_mot")
    p.add_argument("--name", metavar="NAME", help="the mechanism's name (default: the robot's name)")
    p.add_argument(
        "--platform", metavar="FRAME", help="the platform: a link or joint name (default: platform, effector)"
    )
    p.add_argument("--task", metavar="X,Y", help="the task coordinates (default: by the number of actuators)")
    p.add_argument("--spatial", action="store_true", help="write a spatial file even if the mechanism is planar")
    p.set_defaults(func=_Command("urdf", "cmd_import"))
    return parser if command is None or sub.found else build_parser()


class _Subcommands:
    """The subparsers, with only ``command``'s built (None: every one)."""

    def __init__(self, sub: Any, command: str | None) -> None:
        self.sub = sub
        self.command = command
        self.found = False

    def add_parser(self, name: str, **kwargs: Any) -> Any:
        if self.command is not None and name != self.command:
            return _LeftOut()
        self.found = True
        return self.sub.add_parser(name, **kwargs)


class _LeftOut:
    """A subcommand's parser that is not built: its arguments are not declared."""

    def add_argument(self, *_args: Any, **_kwargs: Any) -> None:
        return None

    def set_defaults(self, **_kwargs: Any) -> None:
        return None


class _Command:
    """The handler of a subcommand, ``cpm_nlp.cli.<module>.<name>``, imported only when that
    subcommand runs: the parser (and ``--help``) loads no subcommand module."""

    def __init__(self, module: str, name: str) -> None:
        self.module = module
        self.name = name

    def resolve(self) -> Callable[[argparse.Namespace, TextIO], int]:
        import importlib

        return getattr(importlib.import_module(f".{self.module}", __package__), self.name)


def _add_plot_arguments(p: argparse.ArgumentParser, flag: str | None) -> None:
    if flag:
        p.add_argument(
            flag,
            metavar="FIGURE",
            help="also plot the result to FIGURE (.png, .svg, .pdf; .html: interactive 3-D, Plotly)",
        )
    p.add_argument(
        "--type",
        metavar="TYPE",
        help="plot type, one of those listed below (default: chosen from the result)",
    )
    p.add_argument("--value", metavar="NAME", help="the value to plot (map colour, curves)")
    p.add_argument("--best", choices=("max", "min"), help="map: mark the largest or smallest value")


def main(argv: Sequence[str] | None = None, out: TextIO | None = None, err: TextIO | None = None) -> int:
    """Run the CLI; returns the exit status (also usable in-process by tests)."""
    out = out or sys.stdout
    err = err or sys.stderr
    argv = list(sys.argv[1:] if argv is None else argv)
    parser = build_parser(argv[0] if argv else None)
    try:
        args = parser.parse_args(argv)
    except SystemExit as exc:  # argparse already printed the usage message
        return int(exc.code) if isinstance(exc.code, int) else EXIT_INPUT
    if args.version:
        out.write(f"cpm-nlp {__version__}\n")
        return EXIT_OK
    if args.command is None:
        parser.print_help(out)
        return EXIT_INPUT
    import logging  # here, not at the top: ``--help`` and ``--version`` run without it

    handler = logging.StreamHandler(err)
    handler.setFormatter(logging.Formatter("%(levelname)s %(name)s: %(message)s"))
    root = logging.getLogger("cpm_nlp")
    root.addHandler(handler)
    root.setLevel(logging.WARNING - 10 * min(args.verbose, 2))
    from ..core.errors import CpmError, InputError
    from ..io.inputs import inputs_scope
    from .bars import close_bars

    args.err = err
    try:
        func = args.func.resolve()
        with inputs_scope():
            return func(args, out)
    except InputError as exc:
        err.write(f"error: {exc}\n")
        return EXIT_INPUT
    except CpmError as exc:
        err.write(f"error: {exc}\n")
        return EXIT_FAILED
    except KeyboardInterrupt:
        close_bars(args)
        err.write("interrupted\n")
        with contextlib.suppress(Exception):
            err.flush()
        _INTERRUPT["said"] = True  # a second Ctrl-C from now on adds nothing
        return EXIT_INTERRUPTED
    except BrokenPipeError:  # the reader of our output went away (cpm-nlp describe | head): quietly, as Unix tools
        return EXIT_BROKEN_PIPE
    except Exception as exc:  # a bug, not a user error: say so, and how to get details
        if args.debug:
            import traceback

            traceback.print_exc(file=err)
        err.write(f"internal error: {exc.__class__.__name__}: {exc} (please report; rerun with --debug)\n")
        return EXIT_INTERNAL
    finally:
        close_bars(args)
        root.removeHandler(handler)


#: whether the one line "interrupted" is out (a second Ctrl-C may come before main() wrote it)
_INTERRUPT = {"said": False}


def _second_interrupt(_signum: int, _frame: Any) -> None:
    """A Ctrl-C while the first one is being handled: leave at once, the line
    "interrupted" said once (here, if the first one had not got to it yet)."""
    if not _INTERRUPT["said"]:
        with contextlib.suppress(OSError):
            os.write(2, b"interrupted\n")
    os._exit(EXIT_INTERRUPTED)


def _on_interrupt(_signum: int, _frame: Any) -> None:
    """The first Ctrl-C: ``KeyboardInterrupt`` (main() prints one line, exit 130);
    a second one ends the process without a traceback."""
    signal.signal(signal.SIGINT, _second_interrupt)
    raise KeyboardInterrupt


def _stdout_gone() -> None:
    """Point stdout at /dev/null, so that Python's final flush of what is left
    does not fail again (what the Python docs advise for SIGPIPE)."""
    with contextlib.suppress(OSError, ValueError):
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        os.close(devnull)


def main_entry() -> None:
    """Console-script entry point (``cpm-nlp``).

    Ctrl-C: one line "interrupted", exit 130 at once (threads still finishing a
    piece of work are not waited for); a second Ctrl-C exits without a
    traceback.  A closed stdout (``cpm-nlp describe | head``): a quiet exit
    (status 141, as a Unix tool killed by SIGPIPE)."""
    if signal.getsignal(signal.SIGINT) is signal.default_int_handler:  # not when started with SIGINT ignored
        signal.signal(signal.SIGINT, _on_interrupt)
    try:
        code = main()
        sys.stdout.flush()
    except BrokenPipeError:
        _stdout_gone()
        code = EXIT_BROKEN_PIPE
    except KeyboardInterrupt:  # between main()'s own handlers
        code = EXIT_INTERRUPTED
    if code == EXIT_BROKEN_PIPE:
        _stdout_gone()
    if code == EXIT_INTERRUPTED:
        for stream in (sys.stderr, sys.stdout):
            with contextlib.suppress(Exception):
                stream.flush()
        os._exit(code)
    _exit_without_teardown(code)


def _exit_without_teardown(code: int) -> None:
    """Exit with ``code`` once the command is done, without tearing the interpreter down.

    Tearing down the modules and the objects of a solve (CasADi's graphs and solvers, the
    numpy and CasADi extension modules) took 30 to 90 ms of CPU, a quarter of a whole
    ``cpm-nlp solve`` (issue 23, start-up), to free memory the process returns at once.
    What an exit must do is still done: the ``atexit`` functions run (logging's flush, a
    coverage run's save), stdout and stderr are flushed; every output file was written
    and closed by the command.  Where a thread of ours is still alive (a sweep's cluster),
    the ordinary exit joins it."""
    import atexit
    import threading

    if threading.active_count() > 1:
        sys.exit(code)
    atexit._run_exitfuncs()
    for stream in (sys.stdout, sys.stderr):
        with contextlib.suppress(Exception):
            stream.flush()
    os._exit(code)


if __name__ == "__main__":  # pragma: no cover
    main_entry()
