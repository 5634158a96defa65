"""The ``cpm-nlp`` command line: a map of subcommands.

Exit status: 0 solved, 1 a solve that did not succeed (the result says why),
2 bad input (one message naming the file, the key path and what was
expected), 70 an internal error (a bug: please report it).

Start-up is kept short on purpose: this module imports only the standard
library and the light :mod:`cpm_nlp.core.errors`; each subcommand and
renderer imports what it needs when it runs (units, numpy, CasADi, the
problem kinds, Matplotlib, Dask), so ``cpm-nlp --help`` loads none of them.
"""

from __future__ import annotations

import argparse
import contextlib
import ctypes
import io
import json
import logging
import os
import signal
import sys
from collections import Counter
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path

from ..core import blas, progress
from ..core.errors import CpmError, InputError
from ..core.version import __version__
from ..io.atomic import check_output_path, write_atomic
from ..io.inputs import check_input_file, inputs_scope

TYPE_CHECKING = False  # typing itself is not imported at start-up; the annotations are strings
if TYPE_CHECKING:
    from typing import Any, TextIO

    from ..core.result import Result

EXIT_OK, EXIT_FAILED, EXIT_INPUT, EXIT_INTERNAL = 0, 1, 2, 70
#: Ctrl-C (128 + SIGINT), and a reader that closed our stdout (128 + SIGPIPE)
EXIT_INTERRUPTED, EXIT_BROKEN_PIPE = 130, 141


# -- output helpers -------------------------------------------------------------------------------


def _fmt_scalar(value: Any, dim: str | None) -> tuple[str, str]:
    from ..core.units import DIMENSIONS, format_quantity, si_unit

    if value is None:
        return "—", ""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return str(value), ""
    unit = si_unit(dim)
    si = f"{value:.10g}" + (f" {unit}" if unit else "")
    friendly = format_quantity(value, dim) if dim in DIMENSIONS and DIMENSIONS[dim].display != unit else ""
    return si, friendly


def _fmt_words(flat: list) -> str:
    """A long list of words (statuses, names): how many of each, or the first few."""
    counts = Counter(str(v) for v in flat)
    if len(counts) <= 6:
        return f"{len(flat)} values: " + ", ".join(f"{n} {w}" for w, n in counts.items())
    return f"{len(flat)} values: " + ", ".join(str(v) for v in flat[:6]) + ", ..."


def _fmt_list(value: list, dim: str | None) -> str:
    flat = value
    if flat and all(isinstance(v, list) for v in flat):
        cells = [x for row in flat for x in row]
        if len(cells) > 36:  # a grid: its size and range (the values are in --json / -o)
            nums = [x for x in cells if isinstance(x, (int, float)) and not isinstance(x, bool)]
            text = f"matrix {len(flat)} x {max(len(row) for row in flat)}"
            if nums:
                text += f", from {min(nums):.6g} to {max(nums):.6g}"
            nulls = sum(1 for x in cells if x is None)
            return text + (f", {nulls} null" if nulls else "")

        def cell(x: Any) -> str:
            if isinstance(x, list):  # a batch of matrices: one row per point
                return "[" + ", ".join(cell(v) for v in x) + "]"
            return "—" if x is None else str(x) if isinstance(x, bool) else f"{x:.6g}"

        return "matrix " + "; ".join("[" + ", ".join(cell(x) for x in row) + "]" for row in flat)
    nums = [v for v in flat if isinstance(v, (int, float))]
    nulls = len(flat) - len(nums)
    if len(flat) > 4 and all(isinstance(v, (str, bool)) for v in flat):
        return _fmt_words(flat)
    if len(flat) <= 4:
        return "[" + ", ".join(_fmt_scalar(v, dim)[1] or _fmt_scalar(v, dim)[0] for v in flat) + "]"
    text = f"{len(flat)} values"
    if nums:
        text += (
            f", from {_fmt_scalar(min(nums), dim)[1] or _fmt_scalar(min(nums), dim)[0]}"
            f" to {_fmt_scalar(max(nums), dim)[1] or _fmt_scalar(max(nums), dim)[0]}"
        )
    if nulls:
        text += f", {nulls} not solved"
    return text


def render_result(result: Result, title: str = "") -> str:
    """A readable table of a result."""
    from ..core.result import STATUS_TEXT
    from ..core.units import DIMENSIONS

    lines = []
    lines.append(f"problem : {result.problem}" + (f"  ({title})" if title else ""))
    n = len(result.warnings)
    flagged = f", with {n} warning{'s' if n != 1 else ''} (below)" if n else ""
    lines.append(f"status  : {result.status.value}{flagged}  -- {result.message or STATUS_TEXT[result.status]}")
    s = result.solver
    lines.append(f"solver  : {s.name}, {s.iterations} iterations, {s.seconds * 1e3:.2f} ms")
    if result.model:
        parts = []
        for k, v in result.model.items():
            if k == "type":
                continue
            if isinstance(v, list) and all(isinstance(e, float) for e in v):  # a derived vector
                parts.append(f"{k} = [" + ", ".join(f"{e:.6g}" for e in v) + "]")
            else:
                parts.append(f"{k} = {v:.6g}" if isinstance(v, float) else f"{k} = {v}")
        shown = ": " + ", ".join(parts) + "  (SI)" if parts else " (no parameters)"
        lines.append("model   : " + result.model.get("type", "") + shown)
    if not result.values:
        lines.append("(no values: the solve did not succeed)" if not result.ok else "(no values)")
        return "\n".join(lines + _warning_lines(result))
    width = max(len(k) for k in result.values)
    lines.append("")
    for name, value in result.values.items():
        dim = result.dimensions.get(name)
        if isinstance(value, list):
            text = _fmt_list(value, dim)
            unit = result.units.get(name, "")
            if unit and dim not in DIMENSIONS:
                text += f"   ({unit})"
            lines.append(f"{name:<{width}}  {text}")
        else:
            si, friendly = _fmt_scalar(value, dim)
            lines.append(f"{name:<{width}}  {si:<22}" + (f"  {friendly}" if friendly else ""))
    return "\n".join(lines + _warning_lines(result))


def _warning_lines(result: Result) -> list[str]:
    """The result's warnings, one "warning: ..." line each, after a blank line."""
    if not result.warnings:
        return []
    return ["", *(f"warning: {w.message}" for w in result.warnings)]


# -- subcommands --------------------------------------------------------------------------------


def _flush_c_stdio() -> None:
    """Flush the C library's stdout buffer (IPOPT and CasADi print through it)."""
    with contextlib.suppress(OSError, AttributeError, TypeError):
        ctypes.CDLL(None).fflush(None)


@contextlib.contextmanager
def solver_output_to_stderr(active: bool) -> Iterator[None]:
    """While active: whatever is written to file descriptor 1 (IPOPT's log, its
    option documentation, CasADi's messages) goes to stderr, so that stdout
    carries exactly the one JSON document of ``--json``."""
    if not active:
        yield
        return
    try:
        sys.stdout.flush()
        saved = os.dup(1)
    except (OSError, ValueError):  # no file descriptor 1 (embedded use): nothing to protect
        yield
        return
    try:
        _flush_c_stdio()
        os.dup2(2, 1)
        yield
    finally:
        with contextlib.suppress(OSError, ValueError):
            sys.stdout.flush()
        _flush_c_stdio()
        os.dup2(saved, 1)
        os.close(saved)


@contextlib.contextmanager
def library_output_quiet() -> Iterator[None]:
    """While active: what the C libraries print (IPOPT through C stdio on file
    descriptor 1; CasADi's warnings and messages through Python's
    ``sys.stdout``/``sys.stderr``) is kept off the terminal, so that stderr
    carries only our one message.  CasADi's lines are logged at debug level
    (``-vv`` shows them); ``--debug`` or a solver preset that asks for its log
    (:func:`solver_log_asked`) shows everything instead."""
    saved_py = sys.stdout, sys.stderr
    sink = io.StringIO()
    try:
        sys.stdout.flush()
        saved = os.dup(1)
        devnull = os.open(os.devnull, os.O_WRONLY)
    except (OSError, ValueError, AttributeError):  # no file descriptor 1 (embedded use): Python's streams only
        saved = devnull = None
    try:
        if saved is not None:
            _flush_c_stdio()
            os.dup2(devnull, 1)
        sys.stdout = sys.stderr = sink
        yield
    finally:
        sys.stdout, sys.stderr = saved_py
        if saved is not None:
            _flush_c_stdio()
            os.dup2(saved, 1)
            os.close(saved)
            os.close(devnull)
        for line in sink.getvalue().splitlines()[:100]:
            if line.strip():
                logging.getLogger("cpm_nlp.solver").debug("%s", line)


def solver_log_asked(solver: Any) -> bool:
    """Whether a solver configuration asks for the solver's own log (a preset
    such as configs/ipopt_verbose.yaml: an IPOPT print level, CasADi's timings)."""
    options = getattr(solver, "options", None) or {}
    level = options.get("ipopt.print_level", 0)
    return bool(
        (isinstance(level, int) and level > 0)
        or options.get("print_time") is True
        or options.get("verbose") is True
        or options.get("print_iteration") is True
    )


def solver_output(args: argparse.Namespace, solver: Any = None) -> contextlib.AbstractContextManager[None]:
    """Where the libraries' output goes while ``args``'s command computes: nowhere
    (:func:`library_output_quiet`), or with ``--debug`` or a solver that asks for
    its log, on stdout (on stderr with ``--json``, which keeps stdout for the
    JSON document)."""
    if getattr(args, "debug", False) or solver_log_asked(solver):
        return solver_output_to_stderr(bool(getattr(args, "json", False)))
    return library_output_quiet()


def cmd_solve(args: argparse.Namespace, out: TextIO) -> int:
    from ..mechanisms.registry import mechanism_type
    from ..problems.file import load_problem, solve

    check_output_path(args.output, [args.file])
    _check_plot_args(args, [args.file, args.output])
    with progress.reporting(_progress_bars(args)):
        with solver_output(args):
            problem = load_problem(args.file, args.set or [])
        blas.cap_process()  # small dense algebra only: BLAS threads cost more than they give (core/blas.py)
        with solver_output(args, problem.solver):
            result = solve(problem)
    # the result first: a plot that cannot be drawn never takes it away
    if args.json:
        out.write(result.to_json() + "\n")
    elif not args.quiet:
        mech = problem.model.mechanism  # a problem's own mechanism file is not registered
        title = (mech if mech is not None else mechanism_type(problem.model.name)).title
        out.write(render_result(result, title) + "\n")
    if args.output:
        write_atomic(args.output, result.to_json() + "\n", inputs=[args.file])
    status = EXIT_OK if result.ok else EXIT_FAILED
    if args.plot:
        fig = _result_figure(args, result, problem)
        if fig is None:
            return EXIT_FAILED
        _save_figure(args, fig, out)
    return status


#: the unit a progress bar counts, by the name of the computation (default: items)
_UNITS = {
    "forward kinematics": "poses",
    "inverse kinematics": "poses",
    "assembly-mode search": "starts",
    "assembly-mode search, Newton": "starts",
    "certifying the assembly modes": "sub-boxes",
    "merging the converged starts": "poses",
    "sweep": "points",
}


def _progress_bars(args: argparse.Namespace) -> progress.Callback | None:
    """On a terminal (stderr), a tqdm progress bar per long computation
    (:mod:`cpm_nlp.core.progress` reports, the CLI draws); none with ``-q`` or
    when stderr is not a terminal (a log, a pipe)."""
    if getattr(args, "quiet", False) or not getattr(args.err, "isatty", lambda: False)():
        return None
    from tqdm import tqdm

    bars: dict[str, Any] = {}
    args.bars = bars  # closed by main() on Ctrl-C, so that "interrupted" starts a line

    def show(what: str, done: int, total: int) -> None:
        bar = bars.get(what)
        if bar is None:
            unit = _UNITS.get(what, "items")
            bar = bars[what] = tqdm(
                total=total or None,
                desc=what,
                unit=f" {unit}",
                file=args.err,
                dynamic_ncols=True,
                disable=False,
                leave=False,  # a finished bar is erased: the result follows on a clean screen
                mininterval=0,  # cpm_nlp.core.progress reports every 0.2 s at most already
            )
        bar.update(done - bar.n)
        if total and done >= total:
            bar.close()
            del bars[what]

    return show


# -- plots ------------------------------------------------------------------------------------


def _plot_options(args: argparse.Namespace) -> Any:
    from ..plot.figures import PlotOptions

    return PlotOptions(value=args.value, x=getattr(args, "x", None), y=getattr(args, "y", None), best=args.best)


def _check_plot_args(args: argparse.Namespace, inputs: Sequence[str | None] = ()) -> None:
    """Before solving: the plot type is known, the figure can be written (not
    over an input or the results), and its plotting library is there."""
    if getattr(args, "type", None) is not None:
        from ..plot.figures import check_plot_type

        check_plot_type(args.type)
    if getattr(args, "plot", None):
        from ..plot.draw import check_figure_path, require_backend

        check_figure_path(args.plot, "--plot", inputs=[f for f in inputs if f])
        require_backend(args.plot)


def _result_figure(args: argparse.Namespace, result: Result, problem: Any) -> Any:
    """The figure of a solved result, or None (with a message on stderr) if it
    cannot be drawn: no point solved, or no plot fits the result."""
    from ..plot.figures import figure, from_result

    data = from_result(result)
    data.live = problem.model
    if problem.reproduce is not None:
        data.published = [
            (row.value, row.published, f"published ({row.source})")
            for row in problem.reproduce.rows
            if row.value and row.published is not None
        ]
    try:
        return figure(data, args.type, _plot_options(args), interactive=_interactive(args.plot))
    except InputError as exc:  # the result is out already: a plot that cannot be drawn is a failure, exit 1
        args.err.write(f"error: --plot: no plot written: {exc.message}\n")
        return None


def _interactive(path: str) -> bool:
    return str(path).lower().endswith(".html")


def _save_figure(args: argparse.Namespace, fig_and_type: tuple[Any, str], out: TextIO) -> None:
    from ..plot.draw import save

    fig, kind = fig_and_type
    save(fig, args.plot, option="--plot")
    if not args.quiet and not getattr(args, "json", False):
        out.write(f"plot    : {args.plot} ({kind})\n")


def cmd_plot(args: argparse.Namespace, out: TextIO) -> int:
    from ..plot.draw import check_figure_path, require_backend, save
    from ..plot.figures import check_plot_type, figure, load

    check_plot_type(args.type)
    check_figure_path(args.output, inputs=[args.result])
    require_backend(args.output)
    try:
        data = load(args.result)
        fig, kind = figure(data, args.type, _plot_options(args), interactive=_interactive(args.output))
    except InputError as exc:  # every message about the result names the file plotted
        about_a_flag = bool(exc.path) and str(exc.path[0]).startswith("-")
        raise (exc if exc.file or about_a_flag else exc.at(file=args.result)) from None
    save(fig, args.output, inputs=[args.result])
    out.write(f"{args.output}: {kind} plot of {args.result}\n")
    return EXIT_OK


# -- sweeps -------------------------------------------------------------------------------------


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
    _check_plot_args(args, [args.file, output])
    if args.workers is not None and args.workers < 1:
        raise InputError(f"expected a positive number of workers, got {args.workers}", path=("--workers",))
    if args.chunk is not None and args.chunk < 1:
        raise InputError(f"expected a positive number of points per task, got {args.chunk}", path=("--chunk",))
    problem = load_problem(args.file, args.set or [])
    job_of(problem)  # a file without a sweep section is bad input, before any cluster starts
    bars = _progress_bars(args)
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
        _close_bars(args)
        args.err.write("\n" + _interrupted_message(output) + "\n")
        return 130
    if not args.quiet:
        out.write(render_sweep(summary, args, problem) + "\n")
    if args.plot:  # the sweep ran: a plot that cannot be drawn is a failure (exit 1), not bad input
        from ..plot.figures import figure, load

        try:
            drawn = figure(load(output), args.type, _plot_options(args), interactive=_interactive(args.plot))
        except InputError as exc:  # the results file is written: a plot that cannot be drawn is a failure, exit 1
            args.err.write(f"error: no plot written: {exc.at(prefix=('--plot',))}\n")
            return EXIT_FAILED
        _save_figure(args, drawn, out)
    return EXIT_OK if summary.ok else EXIT_FAILED


def _interrupted_message(output: str) -> str:
    """What a Ctrl-C during a sweep leaves: the results so far, or nothing."""
    from ..io.results import journal_path

    if Path(output).exists() or journal_path(Path(output)).exists():
        return f"interrupted: the points solved so far are in {output}; run the same command to resume"
    return f"interrupted before any point was solved; nothing was written ({output} does not exist)"


def cmd_check(args: argparse.Namespace, out: TextIO) -> int:
    from ..problems.file import load_problem

    with solver_output(args):
        problem = load_problem(args.file, args.set or [])
    out.write(f"{args.file}: ok ({problem.kind.name} on {problem.model.name}, solver {problem.solver.method})\n")
    return EXIT_OK


def _category_cell(r: Any) -> str:
    text = r.category.replace("_", " ")
    return text + (", echo" if r.echoes else "")


def render_reproduce(rows: Sequence[Any]) -> str:
    """The reproduction table, reasons numbered once below it.  The "what" column
    says what the published value is (its category) and ", echo" when the
    computed value is an input given back."""
    from ..core.units import format_quantity

    header = ("paper", "quantity", "source", "what", "published", "computed", "rel. error", "verdict")
    table = []
    reasons: dict[str, int] = {}

    def note(text: str) -> str:
        return f" [{reasons.setdefault(text, len(reasons) + 1)}]"

    for r in rows:
        comp = "—" if r.computed is None else format_quantity(r.computed, r.dimension, 5)
        rel = "—" if r.rel_error is None else f"{r.rel_error * 100:.2f} %"
        verdict = r.verdict + ("" if r.expected else "  [UNEXPECTED]")
        if r.reason:
            verdict += note(r.reason)
        if r.tolerance_reason:
            verdict += note("tolerance: " + r.tolerance_reason)
        if r.echoes:
            verdict += note("computed value echoes an input: " + r.echoes)
        table.append((r.paper, r.quantity, r.source, _category_cell(r), r.published_text, comp, rel, verdict))
    widths = [max(len(str(x)) for x in col) for col in zip(header, *table)]

    def line(cells: Sequence[Any]) -> str:
        return "  ".join(str(c).ljust(w) for c, w in zip(cells, widths)).rstrip()

    out = [line(header), line(["-" * w for w in widths])] + [line(t) for t in table]
    if reasons:
        out += ["", "reasons:"] + [f"  [{n}] {text}" for text, n in reasons.items()]
    return "\n".join(out)


def render_reproduce_summary(summary: dict[str, Any]) -> str:
    """Independent agreements apart from those that are not; the last line is
    "N figures, M unexpected"."""
    parts = [f"{n} {c.replace('_', ' ')}" for c, n in summary["agree_not_independent_by_category"].items()]
    if summary["agree_echoing_an_input"]:
        parts.append(f"{summary['agree_echoing_an_input']} echo an input")
    lines = [
        f"agree, independently: {summary['agree_independent']} (a printed figure, computed from other inputs)",
        f"agree, not independently: {summary['agree_not_independent']}" + (f" ({', '.join(parts)})" if parts else ""),
        f"differ, as explained: {summary['differ'] - summary['unexpected_differ']}; "
        f"not reproducible: {summary['not_reproducible']}",
        f"{summary['figures']} figures, {summary['unexpected']} unexpected",
    ]
    return "\n".join(lines)


def cmd_reproduce(args: argparse.Namespace, out: TextIO) -> int:
    from ..core.result import jsonable
    from ..problems.published import summarize
    from ..problems.reproduce import reproduce

    check_output_path(args.output, args.paths)
    blas.cap_process()
    with solver_output(args):
        rows = reproduce(args.paths or None)
    summary = summarize(rows)
    report = jsonable({"figures": [r.to_dict() for r in rows], "summary": summary})  # no NaN: null
    document = json.dumps(report, indent=2, allow_nan=False) + "\n"
    if args.json:
        out.write(document)
    else:
        out.write(render_reproduce(rows) + "\n\n" + render_reproduce_summary(summary) + "\n")
    if args.output:
        write_atomic(args.output, document, inputs=args.paths)
    return EXIT_OK if all(r.expected for r in rows) else EXIT_FAILED


def cmd_export(args: argparse.Namespace, out: TextIO) -> int:
    from ..io.export import check_format, check_out_dir, export_kinematics, parse_what
    from ..problems.file import load_problem

    what = parse_what(args.what)
    check_format(args.format)
    check_out_dir(args.out, inputs=[args.file])
    problem = load_problem(args.file, args.set or [])
    data = export_kinematics(
        problem.model, args.out, what, args.format, problem.solver, source=args.file, inputs=[args.file]
    )
    for f in [*data["files"], "manifest.json"]:
        out.write(f"{Path(args.out) / f}\n")
    return EXIT_OK


def cmd_examples(args: argparse.Namespace, out: TextIO) -> int:
    from ..problems.shipped import copy_examples

    written = copy_examples(args.dir, force=args.force)
    n_problems = sum(1 for f in written if f.parent.name != "configs")
    out.write(
        f"{args.dir}: {n_problems} problem files in problems/, {len(written) - n_problems} solver presets in "
        f"configs/\n(edit them, then e.g. cd {args.dir} && cpm-nlp solve problems/prs3_forward_kinematics.yaml "
        "or cpm-nlp reproduce)\n"
    )
    return EXIT_OK


def cmd_describe(args: argparse.Namespace, out: TextIO) -> int:  # noqa: C901 - one branch per thing described
    if args.name and _names_a_file(args.name) and not args.mechanism and args.name != "-":
        check_input_file(args.name, allow_pipe=True)  # a sparse file, a device: refused before the imports
    if args.plot:
        _check_graph_plot(args)
    from ..mechanisms.registry import mechanism_names, mechanism_type
    from ..problems.registry import kind_names, problem_kind

    if not args.name:
        out.write("mechanisms:\n")
        for name in mechanism_names():
            mt = mechanism_type(name)
            origin = "" if mt.origin.kind == "built-in" else f"  ({mt.origin})"
            out.write(f"  {name:<12} {mt.title}{origin}\n")
        out.write("problem kinds:\n")
        for name in kind_names():
            out.write(f"  {name:<20} {problem_kind(name).description}\n")
        return EXIT_OK
    if args.name in kind_names():
        return _describe_kind(args, out)
    if args.mechanism:
        problem_kind(args.name, path=("describe",))  # the unknown kind, with a "did you mean"
    description = None
    if _names_a_file(args.name) and not args.mechanism:  # a mechanism file: loaded and checked
        from ..mechanisms.described import load_file_description

        with solver_output(args):
            mt, description = load_file_description(args.name, allow_pipe=True)
    else:
        mt = mechanism_type(args.name, path=("describe",))
    out.write(f"{mt.name}: {mt.title}\n{mt.paper}\n[{mt.origin}]\n\nparameters:\n")
    for o in mt.parameters:
        default = "" if o.required or o.default is None else f" (default {o.format_value(o.default)})"
        out.write(f"  {o.name:<8} {o.expectation()}{default}\n           {o.description}\n")
    out.write("limits (optional, [low, high]):\n")
    for o in mt.limits:
        out.write(f"  {o.name:<8} {o.description}\n")
    caps = mt.capabilities()
    out.write("capabilities: " + (", ".join(caps) if caps else "none beyond the required parts") + "\n")
    from ..analysis.compliance import JointStiffness

    stiffness = mt.part(JointStiffness)
    if stiffness is not None:  # the default hinges of the compliance kinds
        out.write(f"joint stiffness ({stiffness.source}):\n")
        for hname, spec in stiffness.hinges.items():
            text = ", ".join(f"{k}: {v}" for k, v in spec.items())
            out.write(f"  {hname:<10} {text}\n")
    if mt.kinds:
        out.write("its own problem kinds: " + ", ".join(sorted(mt.kinds)) + "\n")
    if description is not None:  # a mechanism file: its derived values, legs, loops and mobility
        from ..mechanisms.described.summary import summary_text
        from ..problems.describe import model_of

        with solver_output(args):
            model, source = model_of(mt)
            text = summary_text(description, model, source)
        out.write(text)
        if args.plot:
            from ..mechanisms.described.summary import body_graph
            from ..plot.draw import save
            from ..plot.mechanism_graph import graph_figure

            nodes, edges = body_graph(description)
            note = "" if edges else "no legs: the loops are written as closures"
            save(graph_figure(f"{mt.name}: bodies and joints", nodes, edges, note), args.plot, "--plot", [args.name])
            out.write(f"body graph: {args.plot}\n")
    return EXIT_OK


def cmd_import(args: argparse.Namespace, out: TextIO) -> int:
    from ..io.import_urdf import import_urdf

    inputs = [args.file] + ([args.sidecar] if args.sidecar else [])
    for f in inputs:
        check_input_file(f)
    check_output_path(args.output, inputs)
    imported = import_urdf(
        args.file,
        args.sidecar,
        actuated=_comma_list(args.actuated, "--actuated"),
        name=args.name,
        platform=args.platform,
        task=_comma_list(args.task, "--task"),
        planar=False if args.spatial else None,
    )
    if args.output is None:
        out.write(imported.text)
        return EXIT_OK
    write_atomic(args.output, imported.text, inputs=inputs)
    kind = "planar" if imported.planar else "spatial"
    out.write(
        f"{args.output}: {len(imported.bodies)} bodies, {len(imported.joints)} joints ({kind}) from {args.file}\n"
    )
    return EXIT_OK


def _comma_list(text: str | None, option: str) -> list[str] | None:
    if text is None:
        return None
    items = [t.strip() for t in text.split(",")]
    if not all(items):
        raise InputError(f"expected names separated by commas, got {text!r}", path=(option,))
    return items


def _check_graph_plot(args: argparse.Namespace) -> None:
    """``describe FILE --plot FIGURE``: a mechanism file, and a .png, .svg or .pdf to write."""
    from ..plot.draw import check_figure_path, require_backend

    if not args.name or args.mechanism or not _names_a_file(args.name):
        raise InputError(
            f"expected a mechanism file to draw the body graph of (cpm-nlp describe FILE.yaml --plot graph.png), "
            f"got {args.name!r}" + (" with --mechanism" if args.mechanism else ""),
            path=("--plot",),
        )
    if Path(args.plot).suffix.lower() == ".html":
        raise InputError(f"expected a .png, .svg or .pdf figure, got {args.plot!r}", path=("--plot",))
    check_figure_path(args.plot, "--plot", [args.name])
    require_backend(args.plot)


def _names_a_file(name: str) -> bool:
    """Whether ``describe NAME`` names a mechanism file: ``.yaml``/``.yml``, ``-``
    (standard input), or a path with a folder (``/dev/fd/63`` of ``<(cat m.yaml)``)."""
    return name.endswith((".yaml", ".yml")) or name == "-" or ("/" in name or os.sep in name)


def _describe_kind(args: argparse.Namespace, out: TextIO) -> int:
    """The inputs (name, unit, default, meaning) and values of a kind: on the mechanism
    named by --mechanism, else on every mechanism it applies to."""
    from ..mechanisms.registry import mechanism_names
    from ..problems.describe import describe_kind, kind_text

    if args.mechanism:
        name = args.mechanism
        if _names_a_file(name):  # a mechanism file, wherever a mechanism name is taken
            from ..mechanisms.described import load_file
            from ..mechanisms.registry import resolve_described

            check_input_file(name, allow_pipe=True)
            with solver_output(args):  # described on its own model: the registry is not changed
                name = resolve_described(load_file(name, allow_pipe=True), ("--mechanism",))
        out.write(kind_text(describe_kind(args.name, name)))
        return EXIT_OK
    descriptions = [describe_kind(args.name, m) for m in mechanism_names()]
    applies = [d for d in descriptions if not d.unsupported]
    for k, desc in enumerate(applies or descriptions[:1]):
        out.write(("\n" if k else "") + kind_text(desc))
    skipped = [d.mechanism for d in descriptions if d.unsupported]
    if applies and skipped:
        out.write(f"\n(does not apply to: {', '.join(skipped)})\n")
    return EXIT_OK


# -- entry point ------------------------------------------------------------------------------------


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="cpm-nlp",
        description="Kinematics and design of compliant parallel mechanisms (CasADi + IPOPT).",
        epilog="Exit status: 0 solved, 1 solve failed, 2 bad input.",
    )
    parser.add_argument("--version", action="store_true", help="print the version of cpm_nlp and exit")
    parser.add_argument("--debug", action="store_true", help="show tracebacks of internal errors")
    parser.add_argument("-v", "--verbose", action="count", default=0, help="log progress to stderr (-vv: debug)")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")

    p = sub.add_parser(
        "solve",
        help="solve a problem file and print the result",
        epilog=PLOT_TYPES,
        formatter_class=_PlotTypesFormatter,
    )
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
    p.set_defaults(func=cmd_solve)

    p = sub.add_parser(
        "sweep",
        help="solve a problem at every point of its sweep section, on Dask",
        description="Solve the problem of FILE at every point of its 'sweep' section (each point as "
        "'cpm-nlp solve FILE --set KEY=VALUE' would), on a local Dask cluster or an existing one, "
        "streaming one row per point to a Parquet or CSV file; a sweep run again resumes.",
        epilog=PLOT_TYPES,
        formatter_class=_PlotTypesFormatter,
    )
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
    p.set_defaults(func=cmd_sweep)

    p = sub.add_parser(
        "plot",
        help="plot a result (JSON of solve -o) or a sweep results file",
        epilog=PLOT_TYPES,
        formatter_class=_PlotTypesFormatter,
    )
    p.add_argument("result", help="JSON result of 'cpm-nlp solve -o', or a sweep results file (.parquet, .csv)")
    p.add_argument("-o", "--output", metavar="FIGURE", required=True, help="figure file: .png, .svg or .pdf")
    p.add_argument("--x", metavar="NAME", help="map: parameter (or value) on the horizontal axis")
    p.add_argument("--y", metavar="NAME", help="map: parameter (or value) on the vertical axis")
    _add_plot_arguments(p, None)
    p.set_defaults(func=cmd_plot)

    p = sub.add_parser("check", help="validate a problem file without solving it")
    p.add_argument("file")
    p.add_argument("--set", action="append", metavar="KEY=VALUE")
    p.set_defaults(func=cmd_check)

    p = sub.add_parser("reproduce", help="solve every problem file that reproduces a published figure")
    p.add_argument("paths", nargs="*", help="problem files or directories (default: problems/)")
    p.add_argument("--json", action="store_true", help="print the table as JSON")
    p.add_argument("-o", "--output", metavar="FILE", help="write the table as JSON to FILE")
    p.set_defaults(func=cmd_reproduce)

    p = sub.add_parser(
        "export",
        help="write the mechanism's FK, IK and Jacobian as CasADi files or C code, with a manifest",
        description="Export the kinematics of the mechanism of a problem file (its parameters, limits and "
        "solver tolerance built in) as serialized CasADi Functions or as C source and header.",
    )
    p.add_argument("file", help="problem file (YAML); its mechanism and solver section are used")
    p.add_argument("--what", default="fk,ik,jacobian", help="comma-separated: fk, ik, jacobian (default: all)")
    p.add_argument("--format", default="casadi", help="casadi (.casadi files) or c (source + header)")
    p.add_argument("--out", required=True, metavar="DIR", help="output directory (created if missing)")
    p.add_argument("--set", action="append", metavar="KEY=VALUE", help="override a value of the file")
    p.set_defaults(func=cmd_export)

    p = sub.add_parser(
        "examples",
        help="copy the shipped problem files and solver presets into a directory, to edit",
        description="Copy the shipped problem files into DIR/problems and the solver presets into DIR/configs "
        "(where cpm-nlp looks for them when run in DIR). Existing files are left alone unless --force.",
    )
    p.add_argument("dir", metavar="DIR", help="directory to copy into (created if missing)")
    p.add_argument("--force", action="store_true", help="overwrite files of the same name")
    p.set_defaults(func=cmd_examples)

    p = sub.add_parser(
        "describe", help="list mechanisms and problem kinds, or describe one (a mechanism file: load, check, describe)"
    )
    p.add_argument("name", nargs="?", help="a mechanism, a problem kind or a mechanism file (.yaml)")
    p.add_argument(
        "--mechanism",
        metavar="NAME",
        help="with a problem kind: its inputs and values for this mechanism (a name or a mechanism file)",
    )
    p.add_argument(
        "--plot", metavar="FIGURE", help="with a mechanism file: also draw its body graph (.png, .svg, .pdf)"
    )
    p.set_defaults(func=cmd_describe)

    p = sub.add_parser(
        "import",
        help="write a mechanism file (bodies and joints) from a URDF and its Extended URDF sidecar",
        description="Read a URDF (its links, joints and zero configuration) and the loop closures and actuated "
        "joints of its Extended URDF sidecar (robot.yaml: closed_loop, type, name_mot, joint_name, joint_type); "
        "write a mechanism file of bodies and joints. Nothing the URDF names (meshes, includes) is opened.",
    )
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
    p.set_defaults(func=cmd_import)
    return parser


class _Deferred(str):
    """Help text made only when the help is printed (it reads a registry: a subcommand
    that runs never pays for it)."""


#: the epilog of the commands that plot: the registered plot types, listed by :func:`_plot_types_text`
PLOT_TYPES = _Deferred("plot types")


class _PlotTypesFormatter(argparse.HelpFormatter):
    """Lists the registered plot types (:mod:`cpm_nlp.plot.registry`) under the help, one a line."""

    def _format_text(self, text: str) -> str:
        if isinstance(text, _Deferred):
            return _plot_types_text(self._width) + "\n\n"
        return super()._format_text(text)


def _plot_types_text(width: int) -> str:
    import textwrap

    from ..plot.registry import plot_type_names, plot_types

    try:
        types = plot_types()
    except CpmError as exc:  # a broken plugin: the names, and what is wrong (the help is still printed)
        return f"plot types (--type): {', '.join(plot_type_names())}\n(error: {exc})"
    column = max(len(t.name) for t in types) + 4
    lines = ["plot types (--type):"]
    for t in types:
        text = t.description + ("" if t.origin == "built-in" else f" [{t.origin}]")
        lines += textwrap.wrap(
            text,
            max(width, column + 30),
            initial_indent=f"  {t.name:<{column - 2}}",
            subsequent_indent=" " * column,
        )
    return "\n".join(lines)


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
    parser = build_parser()
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
    handler = logging.StreamHandler(err)
    handler.setFormatter(logging.Formatter("%(levelname)s %(name)s: %(message)s"))
    root = logging.getLogger("cpm_nlp")
    root.addHandler(handler)
    root.setLevel(logging.WARNING - 10 * min(args.verbose, 2))
    func: Callable[[argparse.Namespace, TextIO], int] = args.func
    args.err = err
    try:
        with inputs_scope():
            return func(args, out)
    except InputError as exc:
        err.write(f"error: {exc}\n")
        return EXIT_INPUT
    except CpmError as exc:
        err.write(f"error: {exc}\n")
        return EXIT_FAILED
    except KeyboardInterrupt:
        _close_bars(args)
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
        _close_bars(args)
        root.removeHandler(handler)


def _close_bars(args: argparse.Namespace) -> None:
    """Close the progress bars left open by an interruption (each ends its line)."""
    for bar in list(getattr(args, "bars", {}).values()):
        with contextlib.suppress(Exception):
            bar.close()
    getattr(args, "bars", {}).clear()


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
    sys.exit(code)


if __name__ == "__main__":  # pragma: no cover
    main_entry()
