"""``cpm-nlp plot``, and the figure ``--plot`` of ``solve`` and ``sweep`` draw."""

from __future__ import annotations

import argparse
from collections.abc import Sequence

from ..core.errors import InputError
from .exits import EXIT_OK

TYPE_CHECKING = False  # typing itself is not imported at start-up; the annotations are strings
if TYPE_CHECKING:
    from typing import Any, TextIO

    from ..core.result import Result


def plot_options(args: argparse.Namespace) -> Any:
    from ..plot.figures import PlotOptions

    return PlotOptions(value=args.value, x=getattr(args, "x", None), y=getattr(args, "y", None), best=args.best)


def check_plot_args(args: argparse.Namespace, inputs: Sequence[str | None] = ()) -> None:
    """Before solving: the plot type is known, the figure can be written (not
    over an input or the results), and its plotting library is there."""
    if getattr(args, "type", None) is not None:
        from ..plot.figures import check_plot_type

        check_plot_type(args.type)
    if getattr(args, "plot", None):
        from ..plot.draw import check_figure_path, require_backend

        check_figure_path(args.plot, "--plot", inputs=[f for f in inputs if f])
        require_backend(args.plot)


def result_figure(args: argparse.Namespace, result: Result, problem: Any) -> Any:
    """The figure of a solved result, or None (with a message on stderr) if it
    cannot be drawn: no point solved, or no plot fits the result."""
    from ..plot.figures import figure
    from ..plot.results import from_solved

    data = from_solved(result, problem)
    try:
        return figure(data, args.type, plot_options(args), interactive=interactive(args.plot))
    except InputError as exc:  # the result is out already: a plot that cannot be drawn is a failure, exit 1
        args.err.write(f"error: --plot: no plot written: {exc.message}\n")
        return None


def interactive(path: str) -> bool:
    return str(path).lower().endswith(".html")


def save_figure(args: argparse.Namespace, fig_and_type: tuple[Any, str], out: TextIO) -> None:
    from ..plot.draw import save

    fig, kind = fig_and_type
    save(fig, args.plot, option="--plot")
    if not args.quiet and not getattr(args, "json", False):
        out.write(f"plot    : {args.plot} ({kind})\n")


def _check_axes_used(args: argparse.Namespace, kind: str) -> None:
    """--x and --y choose a map's axes; given to any other plot they would be
    ignored without a word, so they are refused (exit 2, nothing written)."""
    given = [flag for flag, v in (("--x", args.x), ("--y", args.y)) if v is not None]
    if given and kind != "map":
        verb, them = ("choose", "them") if len(given) > 1 else ("chooses", "it")
        raise InputError(
            f"{' and '.join(given)} {verb} the axes of a map plot; {args.result} was drawn as a {kind} plot, "
            f"which has its own axes: leave {them} out, or ask for the map with --type map",
            path=(given[0],),
        )


def cmd_plot(args: argparse.Namespace, out: TextIO) -> int:
    from ..plot.draw import check_figure_path, require_backend, save
    from ..plot.figures import check_plot_type, figure, load

    check_plot_type(args.type)
    check_figure_path(args.output, inputs=[args.result])
    require_backend(args.output)
    try:
        data = load(args.result)
        fig, kind = figure(data, args.type, plot_options(args), interactive=interactive(args.output))
    except InputError as exc:  # every message about the result names the file plotted
        about_a_flag = bool(exc.path) and str(exc.path[0]).startswith("-")
        raise (exc if exc.file or about_a_flag else exc.at(file=args.result)) from None
    _check_axes_used(args, kind)
    save(fig, args.output, inputs=[args.result])
    out.write(f"{args.output}: {kind} plot of {args.result}\n")
    return EXIT_OK
