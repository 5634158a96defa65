"""``cpm-nlp solve`` and ``cpm-nlp check``: solve a problem file, or only load and check it."""

from __future__ import annotations

import argparse
import copy
from dataclasses import replace

from ..core import blas, progress
from ..io.atomic import check_output_path, write_atomic
from .bars import progress_bars
from .exits import EXIT_FAILED, EXIT_OK
from .plot import check_plot_args, result_figure, save_figure
from .render import render_result
from .streams import solver_output

TYPE_CHECKING = False  # typing itself is not imported at start-up; the annotations are strings
if TYPE_CHECKING:
    from typing import Any, TextIO


def cmd_solve(args: argparse.Namespace, out: TextIO) -> int:
    # small dense algebra only: BLAS threads cost more than they give (core/blas.py); first,
    # so that the cap is the libraries' environment, set before numpy loads them
    blas.cap_process()
    from ..mechanisms.registry import mechanism_type
    from ..problems.file import load_problem, solve

    check_output_path(args.output, [args.file])
    check_plot_args(args, [args.file, args.output])
    with progress.reporting(progress_bars(args)):
        with solver_output(args):
            problem = load_problem(args.file, args.set or [])
        with solver_output(args, problem.solver):
            # with --plot and an outputs selection: solved whole, the figure drawn from every value,
            # the selection printed and written (it limits what is recorded, not what is drawn)
            whole = solve(replace(problem, outputs=None)) if args.plot and problem.outputs is not None else None
            result = solve(problem) if whole is None else copy.copy(whole).keep(problem.outputs)
    # the result first: a plot that cannot be drawn never takes it away
    if args.json:
        out.write(result.to_json() + "\n")
    elif not args.quiet:
        mech = problem.model.mechanism  # a problem's own mechanism file is not registered
        mech = mech if mech is not None else mechanism_type(problem.model.name)
        dims = {o.name: o.kind for o in mech.parameters if o.kind in ("length", "angle")}
        tol = problem.solver.tolerance
        out.write(render_result(result, mech.title, tol, _length_scale(mech, problem), dims) + "\n")
    if args.output:
        write_atomic(args.output, result.to_json() + "\n", inputs=[args.file])
    status = EXIT_OK if result.ok else EXIT_FAILED
    if args.plot:
        fig = result_figure(args, result if whole is None else whole, problem)
        if fig is None:
            return EXIT_FAILED
        save_figure(args, fig, out)
    return status


def _length_scale(mech: Any, problem: Any) -> float | None:
    """The mechanism's largest length parameter (SI), the scale of its pose: None if it has none."""
    lengths = [
        abs(float(problem.model.parameters[o.name]))
        for o in mech.parameters
        if o.kind == "length" and isinstance(problem.model.parameters.get(o.name), (int, float))
    ]
    return max(lengths) if lengths else None


def cmd_check(args: argparse.Namespace, out: TextIO) -> int:
    from ..problems.file import load_problem

    with solver_output(args):
        problem = load_problem(args.file, args.set or [])
    out.write(f"{args.file}: ok ({problem.kind.name} on {problem.model.name}, solver {problem.solver.method})\n")
    return EXIT_OK
