"""``cpm-nlp sweep``: a problem at every point of its sweep section, on Dask."""

from __future__ import annotations

import argparse
from pathlib import Path

from ..core.errors import InputError
from ..io.atomic import check_output_path
from .bars import close_bars, progress_bars
from .exits import EXIT_FAILED, EXIT_OK
from .plot import check_plot_args, interactive, plot_options, save_figure

TYPE_CHECKING = False  # typing itself is not imported at start-up; the annotations are strings
if TYPE_CHECKING:
    from typing import Any, TextIO


def render_sweep(summary: Any, args: argparse.Namespace, problem: Any) -> str:
    counts = ", ".join(f"{n} {s}" for s, n in sorted(summary.statuses.items(), key=lambda kv: -kv[1]))
    where = args.scheduler or f"a local cluster of {summary.workers} worker processes"
    lines = [
        f"sweep   : {args.file} ({problem.kind.name} on {problem.model.name})",
        f"points  : {summary.total} ({counts or 'none yet'})",
        f"this run: {summary.solved_now} points in {summary.seconds:.1f} s"
        + (f" on {where}" if summary.solved_now else " (all points were already in the results file)"),
        f"results : {summary.output}",
    ]
    return "\n".join(lines)


def cmd_sweep(args: argparse.Namespace, out: TextIO) -> int:
    from ..io.results import results_format
    from ..problems.file import load_problem
    from ..sweep.run import job_of, run_sweep

    output = args.output or f"{Path(args.file).stem}.parquet"
    results_format(output)
    check_output_path(output, [args.file])
    check_plot_args(args, [args.file, output])
    if args.workers is not None and args.workers < 1:
        raise InputError(f"expected a positive number of workers, got {args.workers}", path=("--workers",))
    if args.chunk is not None and args.chunk < 1:
        raise InputError(f"expected a positive number of points per task, got {args.chunk}", path=("--chunk",))
    problem = load_problem(args.file, args.set or [])
    job_of(problem)  # a file without a sweep section is bad input, before any cluster starts
    bars = progress_bars(args)
    try:
        summary = run_sweep(
            problem,
            output,
            scheduler=args.scheduler,
            workers=args.workers,
            chunk_size=args.chunk,
            overwrite=args.overwrite,
            progress=None if bars is None else lambda done, total: bars("sweep", done, total),
        )
    except KeyboardInterrupt:
        close_bars(args)
        args.err.write("\n" + _interrupted_message(output) + "\n")
        return 130
    if not args.quiet:
        out.write(render_sweep(summary, args, problem) + "\n")
    if args.plot:  # the sweep ran: a plot that cannot be drawn is a failure (exit 1), not bad input
        from ..plot.figures import figure, load

        try:
            drawn = figure(load(output), args.type, plot_options(args), interactive=interactive(args.plot))
        except InputError as exc:  # the results file is written: a plot that cannot be drawn is a failure, exit 1
            args.err.write(f"error: no plot written: {exc.at(prefix=('--plot',))}\n")
            return EXIT_FAILED
        save_figure(args, drawn, out)
    return EXIT_OK if summary.ok else EXIT_FAILED


def _interrupted_message(output: str) -> str:
    """What a Ctrl-C during a sweep leaves: the results so far, or nothing."""
    from ..io.results import journal_path

    if Path(output).exists() or journal_path(Path(output)).exists():
        return f"interrupted: the points solved so far are in {output}; run the same command to resume"
    return f"interrupted before any point was solved; nothing was written ({output} does not exist)"
